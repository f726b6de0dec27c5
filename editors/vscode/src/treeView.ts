// "bt-lsp: Show Tree": a webview beside the editor with the picture of the behavior tree under
// the cursor, drawn by the server (`bt-lsp.renderTree`). It follows the text as the user types
// (after the diagnostics' debounce), keeping the node the typing made or changed in view (the
// server names it from the range the edits replaced), highlights the node under the cursor, and a
// click on a node selects its element in the XML; a double click on a SubTree node opens the tree
// it calls. While the server watches a running tree (live.ts), each node drawn has the colour of
// its running node's status.

import * as vscode from 'vscode';
import type { LanguageClient } from 'vscode-languageclient/node';
import { LiveView, uriKey } from './live';
import type { LiveNodeStatus } from './liveProtocol';

const COMMAND = 'bt-lsp.renderTree';
const VIEW_TYPE = 'btLsp.tree';

interface LspPosition {
  line: number;
  character: number;
}
interface LspRange {
  start: LspPosition;
  end: LspPosition;
}
interface TreeNode {
  id: string;
  kind: string;
  type: string;
  name: string | null;
  range?: LspRange;
  uri?: string;
  subtree?: string;
  target?: { uri: string; range: LspRange };
}
interface Rendered {
  tree: string;
  svg: string;
  trees: string[];
  nodes: TreeNode[];
  changed?: string | null;
}

/** A span of the text in UTF-16 offsets, as VS Code counts them. */
interface Span {
  start: number;
  end: number;
}

/**
 * ``edited`` (a span of the text before ``change``) as a span of the text after it, joined with
 * the text ``change`` wrote: what the edits so far replaced, in the text as it is now.
 */
function addEdit(edited: Span | undefined, change: { rangeOffset: number; rangeLength: number; text: string }): Span {
  const start = change.rangeOffset;
  const oldEnd = start + change.rangeLength;
  const newEnd = start + change.text.length;
  if (!edited) {
    return { start, end: newEnd };
  }
  const moved = (offset: number): number =>
    offset <= start ? offset : offset >= oldEnd ? offset + newEnd - oldEnd : newEnd;
  return { start: Math.min(start, moved(edited.start)), end: Math.max(newEnd, moved(edited.end)) };
}

type FromWebview =
  | { type: 'ready' }
  | { type: 'reveal'; id: string }
  | { type: 'open'; id: string }
  | { type: 'options'; ports: boolean; expandSubtrees: boolean };

function toRange(r: LspRange): vscode.Range {
  return new vscode.Range(r.start.line, r.start.character, r.end.line, r.end.character);
}

function nonce(): string {
  const chars = 'ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789';
  let out = '';
  for (let i = 0; i < 32; i++) {
    out += chars.charAt(Math.floor(Math.random() * chars.length));
  }
  return out;
}

function isXml(doc: vscode.TextDocument | undefined): doc is vscode.TextDocument {
  return doc !== undefined && doc.languageId === 'xml' && (doc.uri.scheme === 'file' || doc.uri.scheme === 'untitled');
}

class TreePanel {
  private readonly panel: vscode.WebviewPanel;
  private readonly nonce = nonce();
  private readonly disposables: vscode.Disposable[] = [];
  private document: vscode.TextDocument | undefined;
  private position: vscode.Position | undefined;
  private rendered: Rendered | undefined;
  private timer: ReturnType<typeof setTimeout> | undefined;
  private generation = 0;
  private ready = false;
  /** What the edits since the last picture replaced, for the server to name the node changed. */
  private edited: Span | undefined;
  private options = { ports: false, expandSubtrees: false };

  constructor(
    private readonly extensionUri: vscode.Uri,
    private readonly getClient: () => LanguageClient | undefined,
    private readonly log: vscode.LogOutputChannel,
    private readonly live: LiveView,
    private readonly onDispose: () => void,
  ) {
    this.panel = vscode.window.createWebviewPanel(
      VIEW_TYPE,
      'Behavior tree',
      { viewColumn: vscode.ViewColumn.Beside, preserveFocus: true },
      {
        enableScripts: true,
        retainContextWhenHidden: true,
        localResourceRoots: [vscode.Uri.joinPath(extensionUri, 'media')],
      },
    );
    this.panel.webview.html = this.html();
    this.disposables.push(
      this.panel.onDidDispose(() => this.dispose()),
      this.panel.webview.onDidReceiveMessage((m: FromWebview) => void this.onMessage(m)),
      this.live.onDidChange(() => this.postLive()),
      vscode.workspace.onDidChangeTextDocument((e) => {
        if (e.document === this.document && e.contentChanges.length > 0) {
          for (const change of e.contentChanges) {
            this.edited = addEdit(this.edited, change);
          }
          this.schedule();
        }
      }),
      vscode.window.onDidChangeActiveTextEditor((editor) => {
        if (editor && isXml(editor.document) && editor.document !== this.document) {
          this.follow(editor);
        }
      }),
      vscode.window.onDidChangeTextEditorSelection((e) => {
        if (e.textEditor.document === this.document) {
          this.cursorMoved(e.selections[0].active);
        }
      }),
    );
  }

  reveal(): void {
    this.panel.reveal(vscode.ViewColumn.Beside, true);
  }

  follow(editor: vscode.TextEditor): void {
    this.document = editor.document;
    this.edited = undefined;
    this.position = editor.selection.active;
    this.panel.title = `Tree: ${editor.document.uri.path.split('/').pop() ?? ''}`;
    void this.refresh();
  }

  private html(): string {
    const webview = this.panel.webview;
    const media = (name: string) => webview.asWebviewUri(vscode.Uri.joinPath(this.extensionUri, 'media', name));
    const csp = [
      "default-src 'none'",
      `style-src ${webview.cspSource} 'nonce-${this.nonce}'`,
      `script-src 'nonce-${this.nonce}'`,
      `img-src ${webview.cspSource} data:`,
    ].join('; ');
    return `<!DOCTYPE html>
<html lang="en">
<head>
<meta charset="UTF-8">
<meta http-equiv="Content-Security-Policy" content="${csp}">
<meta name="viewport" content="width=device-width, initial-scale=1.0">
<link rel="stylesheet" href="${media('treeView.css')}">
<title>Behavior tree</title>
</head>
<body>
<div id="bar"><span id="title"></span><span id="status"></span>
<label><input type="checkbox" id="ports"> ports</label>
<label><input type="checkbox" id="expand"> expand SubTrees</label>
<span id="help">drag: pan · wheel or +/−: zoom · 0: fit · click: select in the XML · double click a SubTree: open its tree</span></div>
<div id="view" tabindex="0" aria-label="Behavior tree"><div id="canvas" data-nonce="${this.nonce}"></div></div>
<script nonce="${this.nonce}" src="${media('treeView.js')}"></script>
</body>
</html>`;
  }

  /** Re-render after the same delay the server waits before recomputing diagnostics. */
  private schedule(): void {
    if (this.timer) {
      clearTimeout(this.timer);
    }
    const delay = Math.max(0, vscode.workspace.getConfiguration('btLsp').get<number>('debounceMs') ?? 200);
    this.timer = setTimeout(() => void this.refresh(), delay);
  }

  private async refresh(): Promise<void> {
    this.timer = undefined;
    const client = this.getClient();
    const doc = this.document;
    if (!doc) {
      return;
    }
    if (!client) {
      this.post({ type: 'message', text: 'The bt-lsp server is not running (see the bt-lsp output).' });
      return;
    }
    const generation = ++this.generation;
    const position = this.position ?? new vscode.Position(0, 0);
    const version = doc.version;
    const edited = this.edited;
    const at = (offset: number) => {
      const p = doc.positionAt(offset);
      return { line: p.line, character: p.character };
    };
    try {
      const result = (await client.sendRequest('workspace/executeCommand', {
        command: COMMAND,
        arguments: [
          {
            uri: client.code2ProtocolConverter.asUri(doc.uri),
            position: { line: position.line, character: position.character },
            ports: this.options.ports,
            expandSubtrees: this.options.expandSubtrees,
            ...(edited ? { edited: { start: at(edited.start), end: at(edited.end) } } : {}),
          },
        ],
      })) as Rendered | null;
      if (generation !== this.generation) {
        return; // a newer request is on its way
      }
      if (doc.version === version) {
        this.edited = undefined; // drawn: later edits start a new span
      }
      this.rendered = result ?? undefined;
      if (!result) {
        this.post({ type: 'message', text: 'No <BehaviorTree> in this document.' });
        return;
      }
      this.post({
        type: 'render',
        svg: result.svg,
        tree: result.tree,
        trees: result.trees,
        nodes: result.nodes.map((n) => ({ id: n.id, kind: n.kind, subtree: n.subtree ?? null })),
        // The cursor now, not when the request left: it may have moved while the server drew.
        selected: this.nodeAt(this.position ?? position)?.id ?? null,
        changed: result.changed ?? null,
        // The statuses of these nodes come with them: none of the last picture's is shown on
        // a node of another tree with the same id.
        live: this.liveStatuses(),
      });
    } catch (error) {
      this.log.warn(`bt-lsp: drawing the tree: ${error instanceof Error ? error.message : String(error)}`);
      this.post({ type: 'message', text: 'The tree could not be drawn (see the bt-lsp output).' });
    }
  }

  /** Sends the statuses again when they change (the picture's nodes stay). */
  private postLive(): void {
    if (this.document && this.rendered) {
      this.post({ type: 'live', statuses: this.liveStatuses() });
    }
  }

  /**
   * The live status of each node drawn, by its SVG id: a node drawn stands for the running node
   * whose tag name starts where its element starts (the name follows the element's `<`), in the
   * same file. Sent with each picture and on each change of the statuses.
   */
  private liveStatuses(): Record<string, LiveNodeStatus> {
    const doc = this.document;
    const nodes = this.rendered?.nodes;
    const statuses: Record<string, LiveNodeStatus> = {};
    if (!doc || !nodes) {
      return statuses;
    }
    const own = uriKey(doc.uri);
    if (this.live.active) {
      for (const node of nodes) {
        if (!node.range) {
          continue;
        }
        const uri = node.uri ? uriKey(node.uri) : own;
        const { line, character } = node.range.start;
        const status = this.live.statusAt(uri, line, character) ?? this.live.statusAt(uri, line, character + 1);
        if (status) {
          statuses[node.id] = status;
        }
      }
    }
    return statuses;
  }

  private post(message: unknown): void {
    if (this.ready) {
      void this.panel.webview.postMessage(message);
    } else {
      // Until the page listens: the last picture or message, and the last statuses.
      const live = (message as { type?: string }).type === 'live';
      this.pending = [...this.pending.filter((m) => ((m as { type?: string }).type === 'live') !== live), message];
    }
  }
  private pending: unknown[] = [];

  /** The innermost node of the picture whose element holds ``pos`` (nodes of this document). */
  private nodeAt(pos: vscode.Position): TreeNode | undefined {
    let best: TreeNode | undefined;
    for (const node of this.rendered?.nodes ?? []) {
      if (node.uri || !node.range) {
        continue;
      }
      const r = toRange(node.range);
      if (r.contains(pos) && (!best || (best.range && toRange(best.range).contains(r)))) {
        best = node;
      }
    }
    return best;
  }

  private cursorMoved(pos: vscode.Position): void {
    this.position = pos;
    const root = this.rendered?.nodes[0];
    const inTree = root?.range ? toRange(root.range).contains(pos) : false;
    if (!inTree) {
      // Perhaps another tree of the document: draw the one under the cursor.
      if (this.rendered && !this.timer) {
        this.schedule();
      }
      return;
    }
    this.post({ type: 'highlight', id: this.nodeAt(pos)?.id ?? null });
  }

  private async onMessage(message: FromWebview): Promise<void> {
    if (message.type === 'ready') {
      this.ready = true;
      this.pending.forEach((m) => void this.panel.webview.postMessage(m));
      this.pending = [];
      return;
    }
    if (message.type === 'options') {
      this.options = { ports: message.ports === true, expandSubtrees: message.expandSubtrees === true };
      await this.refresh();
      return;
    }
    const node = this.rendered?.nodes.find((n) => n.id === message.id);
    if (!node) {
      return;
    }
    if (message.type === 'open' && node.target) {
      await this.show(vscode.Uri.parse(node.target.uri), toRange(node.target.range));
      return;
    }
    if (node.range) {
      const uri = node.uri ? vscode.Uri.parse(node.uri) : this.document?.uri;
      if (uri) {
        await this.show(uri, toRange(node.range));
      }
    }
  }

  /** Opens ``uri`` in the editor column of the document shown and selects ``range``. */
  private async show(uri: vscode.Uri, range: vscode.Range): Promise<void> {
    const column =
      vscode.window.visibleTextEditors.find((e) => e.document === this.document)?.viewColumn ?? vscode.ViewColumn.One;
    const editor = await vscode.window.showTextDocument(uri, { viewColumn: column, preserveFocus: false });
    // The cursor at the element's start (its tag in view), the element selected.
    editor.selection = new vscode.Selection(range.end, range.start);
    editor.revealRange(range, vscode.TextEditorRevealType.InCenterIfOutsideViewport);
  }

  dispose(): void {
    if (this.timer) {
      clearTimeout(this.timer);
    }
    this.disposables.forEach((d) => d.dispose());
    this.disposables.length = 0;
    this.panel.dispose();
    this.onDispose();
  }
}

/** Registers "bt-lsp: Show Tree". ``getClient`` gives the running language client, if any. */
export function registerTreeView(
  context: vscode.ExtensionContext,
  getClient: () => LanguageClient | undefined,
  log: vscode.LogOutputChannel,
  live: LiveView,
): void {
  let panel: TreePanel | undefined;
  context.subscriptions.push(
    vscode.commands.registerCommand('btLsp.showTree', () => {
      const editor = vscode.window.activeTextEditor;
      if (!editor || !isXml(editor.document)) {
        void vscode.window.showInformationMessage('bt-lsp: open a BehaviorTree.CPP XML file to show its tree.');
        return;
      }
      if (!panel) {
        panel = new TreePanel(context.extensionUri, getClient, log, live, () => (panel = undefined));
      } else {
        panel.reveal();
      }
      panel.follow(editor);
    }),
    { dispose: () => panel?.dispose() },
  );
}
