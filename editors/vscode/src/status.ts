// Whether the server runs, where a user looks: a status bar item (red while no server runs)
// and, while none runs, one warning on each open BehaviorTree.CPP file in the Problems panel,
// so that "No problems have been detected" never stands for "nothing was checked".

import * as vscode from 'vscode';

const NOT_RUNNING_CODE = 'server-not-running';

/** An XML document that BehaviorTree.CPP would read (not any XML file: pom.xml stays quiet). */
export function looksLikeBehaviorTree(document: vscode.TextDocument): boolean {
  if (document.languageId !== 'xml') {
    return false;
  }
  const head = document.getText(new vscode.Range(0, 0, Math.min(document.lineCount, 2000), 0));
  return /<BehaviorTree\b|\bBTCPP_format\b|<TreeNodesModel\b/.test(head);
}

export class ServerStatus implements vscode.Disposable {
  private readonly item = vscode.window.createStatusBarItem('btLsp.status', vscode.StatusBarAlignment.Left, 0);
  private readonly problems = vscode.languages.createDiagnosticCollection('bt-lsp-status');
  private onOpen: vscode.Disposable | undefined;
  private message = '';

  constructor() {
    this.item.name = 'bt-lsp';
    this.item.command = 'btLsp.showOutput';
    this.starting();
    this.item.show();
  }

  starting(): void {
    this.item.text = '$(sync~spin) bt-lsp';
    this.item.tooltip = 'bt-lsp: starting the language server';
    this.item.backgroundColor = undefined;
    this.item.color = undefined;
  }

  running(origin: string): void {
    this.item.text = '$(check) bt-lsp';
    this.item.tooltip = `bt-lsp is running (${origin}). Click for its output.`;
    this.item.backgroundColor = undefined;
    this.item.color = undefined;
    this.onOpen?.dispose();
    this.onOpen = undefined;
    this.problems.clear();
  }

  /** No server: red in the status bar, and a warning on every open BehaviorTree.CPP file. */
  notRunning(reason: string, help: string): void {
    this.item.text = '$(error) bt-lsp: not running';
    this.item.tooltip = new vscode.MarkdownString(`**bt-lsp is not running**: ${reason}.\n\n${help}\n\nClick for the output.`);
    this.item.backgroundColor = new vscode.ThemeColor('statusBarItem.errorBackground');
    this.item.color = new vscode.ThemeColor('statusBarItem.errorForeground');
    this.message = `bt-lsp did not check this file: ${reason}. ${help}`;
    this.problems.clear();
    vscode.workspace.textDocuments.forEach((document) => this.mark(document));
    this.onOpen ??= vscode.workspace.onDidOpenTextDocument((document) => this.mark(document));
  }

  private mark(document: vscode.TextDocument): void {
    if (!looksLikeBehaviorTree(document)) {
      return;
    }
    const diagnostic = new vscode.Diagnostic(document.lineAt(0).range, this.message, vscode.DiagnosticSeverity.Warning);
    diagnostic.source = 'bt-lsp';
    diagnostic.code = NOT_RUNNING_CODE;
    this.problems.set(document.uri, [diagnostic]);
  }

  dispose(): void {
    this.onOpen?.dispose();
    this.problems.dispose();
    this.item.dispose();
  }
}
