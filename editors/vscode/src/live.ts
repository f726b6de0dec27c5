// "bt-lsp: Connect to a Running Tree": the server connects to a BehaviorTree.CPP executor's
// Groot2Publisher, maps its tree onto the XML and sends each node's status as it changes
// (`bt-lsp/liveStatus`). Here: the commands, a status bar item (connected, lost, off), one
// decoration per status on the nodes' tag names in every visible editor of their files, and
// the statuses by place for the Show Tree view. A `.btlog` replay (replay.ts) shows its
// statuses the same way, in place of a connection.

import * as vscode from 'vscode';
import { ExecuteCommandRequest, type LanguageClient } from 'vscode-languageclient/node';
import {
  DEFAULT_ADDRESS,
  LIVE_CONNECT,
  LIVE_DISCONNECT,
  LIVE_STATUS,
  LIVE_STATUSES,
  LiveConnectResult,
  LiveNode,
  LiveNodeStatus,
  LiveStatusParams,
  LspRange,
  isLiveStatus,
  parseAddress,
  strongerStatus,
} from './liveProtocol';

type State = 'off' | 'connecting' | 'connected' | 'lost' | 'replay';

/** Colours from the theme (the Show Tree view uses the same `charts.*` ones). */
const STYLES: Record<LiveNodeStatus, { color: string; background?: string }> = {
  running: { color: 'charts.yellow', background: 'editor.findMatchHighlightBackground' },
  success: { color: 'charts.green', background: 'diffEditor.insertedTextBackground' },
  failure: { color: 'charts.red', background: 'diffEditor.removedTextBackground' },
  idle: { color: 'descriptionForeground' },
  skipped: { color: 'disabledForeground' },
};

const ADDRESS_KEY = 'btLsp.liveAddress';

function decorationType(status: LiveNodeStatus): vscode.TextEditorDecorationType {
  const style = STYLES[status];
  const color = new vscode.ThemeColor(style.color);
  return vscode.window.createTextEditorDecorationType({
    border: '1px solid',
    borderColor: color,
    borderRadius: '3px',
    backgroundColor: style.background ? new vscode.ThemeColor(style.background) : undefined,
    overviewRulerColor: status === 'running' || status === 'failure' ? color : undefined,
    overviewRulerLane: vscode.OverviewRulerLane.Left,
    rangeBehavior: vscode.DecorationRangeBehavior.ClosedClosed,
    after: { contentText: ` ● ${status}`, color, fontStyle: 'italic' },
  });
}

function isObject(value: unknown): value is Record<string, unknown> {
  return typeof value === 'object' && value !== null;
}

function isRange(value: unknown): value is LspRange {
  const isPosition = (p: unknown) =>
    isObject(p) && Number.isInteger(p.line) && Number.isInteger(p.character) && (p.line as number) >= 0 && (p.character as number) >= 0;
  return isObject(value) && isPosition(value.start) && isPosition(value.end);
}

/** A URI as one spelling, so that the server's and VS Code's compare equal. */
export function uriKey(uri: string | vscode.Uri): string {
  return (typeof uri === 'string' ? vscode.Uri.parse(uri) : uri).toString();
}

function placeKey(line: number, character: number): string {
  return `${line}:${character}`;
}

function errorText(error: unknown): string {
  return error instanceof Error ? error.message : String(error);
}

export class LiveView implements vscode.Disposable {
  private client: LanguageClient | undefined;
  private subscription: vscode.Disposable | undefined;
  private state: State = 'off';
  /** The session the server answered last (notifications of older ones are stale). */
  private session: number | undefined;
  /** The session just disconnected: its late notifications change nothing. */
  private closed: number | undefined;
  /** The session of the last notification applied. */
  private seen: number | undefined;
  /** Counts connects and disconnects: a connect's answer after a later one is stale. */
  private attempt = 0;
  /** uri -> status -> ranges, for the decorations. */
  private ranges = new Map<string, Map<LiveNodeStatus, vscode.Range[]>>();
  /** uri -> "line:character" of a tag name's start -> status, for the Show Tree view. */
  private places = new Map<string, Map<string, LiveNodeStatus>>();
  private readonly types = new Map<LiveNodeStatus, vscode.TextEditorDecorationType>(
    LIVE_STATUSES.map((s) => [s, decorationType(s)]),
  );
  private readonly item = vscode.window.createStatusBarItem('btLsp.live', vscode.StatusBarAlignment.Left, -1);
  private readonly changed = new vscode.EventEmitter<void>();
  private readonly disposables: vscode.Disposable[] = [];
  private disposed = false;
  /** Fired when the statuses change (the Show Tree view colours its nodes again). */
  readonly onDidChange = this.changed.event;
  private readonly replayEnded = new vscode.EventEmitter<void>();
  /** Fired when a replay ends because of a connection or the disconnect command. */
  readonly onDidEndReplay = this.replayEnded.event;

  constructor(
    private readonly context: vscode.ExtensionContext,
    private readonly log: vscode.LogOutputChannel,
  ) {
    this.item.name = 'bt-lsp live tree';
    this.disposables.push(
      this.item,
      this.changed,
      this.replayEnded,
      vscode.commands.registerCommand('btLsp.connectLive', () => this.connect()),
      vscode.commands.registerCommand('btLsp.disconnectLive', () => this.disconnect()),
      vscode.window.onDidChangeVisibleTextEditors((editors) => editors.forEach((e) => this.decorate(e))),
    );
    void vscode.commands.executeCommand('setContext', 'btLsp.liveState', this.state);
  }

  /** Listens to the notifications of a language client that has just started. */
  attach(client: LanguageClient): void {
    this.detach('the bt-lsp server restarted: connect again');
    this.client = client;
    this.subscription = client.onNotification(LIVE_STATUS, (params: unknown) => this.onStatus(params));
  }

  /** The client is stopped for good: its session, if any, is gone. */
  detach(reason = 'the bt-lsp server stopped'): void {
    this.subscription?.dispose();
    this.subscription = undefined;
    this.client = undefined;
    this.reset(reason);
  }

  /** The server stopped (perhaps to be started again by the client): its session is gone. */
  reset(reason: string): void {
    if (this.disposed) {
      return;
    }
    this.session = this.seen = this.closed = undefined;
    if (this.state === 'replay') {
      return; // a replay needs no server once it has the log's places
    }
    if (this.state !== 'off') {
      this.setState('off', reason);
    }
    this.clear();
  }

  /** The status of the running node whose tag name starts at ``line:character`` of ``uri``. */
  statusAt(uri: string, line: number, character: number): LiveNodeStatus | undefined {
    return this.places.get(uri)?.get(placeKey(line, character));
  }

  /** Whether any node has a status (to tell the Show Tree view to clear its colours). */
  get active(): boolean {
    return this.places.size > 0;
  }

  private async connect(): Promise<void> {
    const editor = vscode.window.activeTextEditor;
    const document = editor?.document;
    if (!document || document.languageId !== 'xml' || !['file', 'untitled'].includes(document.uri.scheme)) {
      void vscode.window.showInformationMessage(
        'bt-lsp: open the BehaviorTree.CPP XML file the executor loaded, then connect to the running tree.',
      );
      return;
    }
    const client = this.client;
    if (!client) {
      void vscode.window.showErrorMessage('bt-lsp: the language server is not running (see the bt-lsp output).');
      return;
    }
    this.endReplay();
    const value = await vscode.window.showInputBox({
      title: 'bt-lsp: Connect to a Running Tree',
      prompt: "host:port of the executor's Groot2Publisher (bt-lsp connects; it never listens)",
      value: this.context.workspaceState.get<string>(ADDRESS_KEY) ?? DEFAULT_ADDRESS,
      placeHolder: DEFAULT_ADDRESS,
      ignoreFocusOut: true,
      validateInput: (text) => {
        const parsed = parseAddress(text);
        return 'error' in parsed ? parsed.error : undefined;
      },
    });
    if (value === undefined) {
      return;
    }
    const address = parseAddress(value);
    if ('error' in address) {
      return; // the input box does not accept it
    }
    const where = value.trim();
    const attempt = ++this.attempt;
    void this.context.workspaceState.update(ADDRESS_KEY, where);
    this.closed = undefined;
    this.setState('connecting', `connecting to ${where}`);
    const uri = client.code2ProtocolConverter.asUri(document.uri);
    let result: LiveConnectResult;
    try {
      result = (await vscode.window.withProgress(
        { location: vscode.ProgressLocation.Window, title: `bt-lsp: connecting to ${where}` },
        () =>
          client.sendRequest(ExecuteCommandRequest.type, {
            command: LIVE_CONNECT,
            arguments: [{ uri, host: address.host, port: address.port }],
          }),
      )) as LiveConnectResult;
    } catch (error) {
      const reason = errorText(error);
      this.log.warn(`Connecting to the running tree at ${where}: ${reason}`);
      if (attempt !== this.attempt) {
        return; // disconnected or connected elsewhere meanwhile
      }
      if (this.state === 'connecting') {
        this.setState('off', `could not connect to ${where}: ${reason}`);
      }
      void vscode.window.showErrorMessage(`bt-lsp: could not connect to the running tree at ${where}: ${reason}`);
      return;
    }
    if (client !== this.client) {
      return; // the server restarted meanwhile
    }
    if (attempt !== this.attempt) {
      // Disconnected meanwhile: the session's word changes nothing.
      this.session = this.closed = result.session;
      return;
    }
    this.session = result.session;
    const mismatches = Array.isArray(result.mismatches) ? result.mismatches : [];
    this.log.info(
      `Connected to the running tree at ${where}: tree ${result.tree ?? '(unknown)'}, ${result.nodes} nodes, ` +
        `${mismatches.length} differences from the text`,
    );
    mismatches.forEach((m) => this.log.info(`  ${m.message ?? JSON.stringify(m)}`));
    if (this.state === 'connecting') {
      // No notification of this session yet (or only one saying it is lost): say what the
      // answer says until the next one comes.
      if (this.seen === result.session) {
        this.setState('lost', `the connection to ${where} is lost; retrying`);
      } else {
        this.setState('connected', `connected to ${where} (tree ${result.tree ?? '?'}, ${result.nodes} nodes)`);
      }
    }
    if (mismatches.length > 0) {
      const showOutput = 'Show Output';
      void vscode.window
        .showWarningMessage(
          `bt-lsp: the text differs from the running tree (${mismatches.length} ` +
            `${mismatches.length === 1 ? 'difference' : 'differences'}); those nodes show no status.`,
          showOutput,
        )
        .then((choice) => choice === showOutput && this.log.show());
    }
  }

  private async disconnect(): Promise<void> {
    if (this.state === 'replay') {
      this.endReplay();
      return;
    }
    const client = this.client;
    this.attempt++;
    this.closed = this.session ?? this.seen;
    this.setState('off', 'disconnected');
    this.clear();
    if (!client) {
      return;
    }
    try {
      await client.sendRequest(ExecuteCommandRequest.type, { command: LIVE_DISCONNECT, arguments: [{}] });
    } catch (error) {
      this.log.warn(`Disconnecting from the running tree: ${errorText(error)}`);
    }
  }

  private onStatus(params: unknown): void {
    if (!isObject(params) || typeof params.session !== 'number' || typeof params.connected !== 'boolean') {
      this.log.warn(`${LIVE_STATUS}: malformed parameters ignored`);
      return;
    }
    const status = params as unknown as LiveStatusParams;
    if ((this.session !== undefined && status.session < this.session) || status.session === this.closed) {
      return; // an older session's, or the one just disconnected
    }
    if (this.state === 'off' || this.state === 'replay') {
      return; // a late word of a session ended here (disconnected, or a log replayed since)
    }
    this.seen = status.session;
    const message = typeof status.message === 'string' ? status.message : '';
    if (status.connected) {
      this.setState('connected', message || `connected (tree ${status.tree ?? '?'})`);
    } else if (this.state !== 'connecting') {
      this.setState('lost', message || 'the connection to the executor is lost; retrying');
    }
    this.update(Array.isArray(status.nodes) ? status.nodes : []);
  }

  /**
   * Shows the statuses of a replayed log (`message` in the status bar's tooltip) in place of a
   * connection, which ends.
   */
  async showReplay(nodes: LiveNode[], message: string): Promise<void> {
    if (this.state !== 'replay' && this.state !== 'off') {
      await this.disconnect();
    }
    this.setState('replay', message);
    this.update(nodes);
  }

  /** Ends a replay: the statuses go, and its timeline closes. */
  endReplay(): void {
    if (this.state !== 'replay') {
      return;
    }
    this.setState('off', 'the replay ended');
    this.clear();
    this.replayEnded.fire();
  }

  /** The nodes' statuses by file and place; the decorations and the tree view follow. */
  private update(nodes: unknown[]): void {
    const places = new Map<string, Map<string, LiveNodeStatus>>();
    const spans = new Map<string, Map<string, { range: LspRange; status: LiveNodeStatus }>>();
    for (const node of nodes) {
      if (!isObject(node) || typeof node.uri !== 'string' || !isRange(node.range) || !isLiveStatus(node.status)) {
        continue;
      }
      const uri = uriKey(node.uri);
      const at = placeKey(node.range.start.line, node.range.start.character);
      const byPlace = places.get(uri) ?? new Map<string, LiveNodeStatus>();
      places.set(uri, byPlace);
      const status = strongerStatus(byPlace.get(at), node.status);
      byPlace.set(at, status);
      const bySpan = spans.get(uri) ?? new Map<string, { range: LspRange; status: LiveNodeStatus }>();
      spans.set(uri, bySpan);
      bySpan.set(at, { range: node.range, status });
    }
    this.places = places;
    this.ranges = new Map();
    for (const [uri, bySpan] of spans) {
      const byStatus = new Map<LiveNodeStatus, vscode.Range[]>();
      for (const { range, status } of bySpan.values()) {
        const list = byStatus.get(status) ?? [];
        list.push(new vscode.Range(range.start.line, range.start.character, range.end.line, range.end.character));
        byStatus.set(status, list);
      }
      this.ranges.set(uri, byStatus);
    }
    vscode.window.visibleTextEditors.forEach((e) => this.decorate(e));
    this.changed.fire();
  }

  private clear(): void {
    const had = this.places.size > 0 || this.ranges.size > 0;
    this.places = new Map();
    this.ranges = new Map();
    vscode.window.visibleTextEditors.forEach((e) => this.decorate(e));
    if (had) {
      this.changed.fire();
    }
  }

  private decorate(editor: vscode.TextEditor): void {
    const byStatus = this.ranges.get(uriKey(editor.document.uri));
    for (const [status, type] of this.types) {
      editor.setDecorations(type, byStatus?.get(status) ?? []);
    }
  }

  private setState(state: State, message: string): void {
    this.state = state;
    const icon = {
      off: '$(circle-slash)',
      connecting: '$(sync~spin)',
      connected: '$(pulse)',
      lost: '$(debug-disconnect)',
      replay: '$(history)',
    }[state];
    this.item.text = `${icon} BT live: ${state}`;
    const action =
      state === 'off'
        ? 'Click to connect to a running tree.'
        : state === 'replay'
          ? 'Click to end the replay.'
          : 'Click to disconnect from the running tree.';
    this.item.tooltip = `${message}\n\n${action}`;
    this.item.command = state === 'off' ? 'btLsp.connectLive' : 'btLsp.disconnectLive';
    this.item.backgroundColor =
      state === 'lost' ? new vscode.ThemeColor('statusBarItem.warningBackground') : undefined;
    this.item.show();
    void vscode.commands.executeCommand('setContext', 'btLsp.liveState', state);
  }

  dispose(): void {
    this.disposed = true;
    this.subscription?.dispose();
    this.types.forEach((t) => t.dispose());
    this.disposables.forEach((d) => d.dispose());
  }
}
