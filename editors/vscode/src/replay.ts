// "bt-lsp: Replay a .btlog": the log BT::FileLogger2 wrote, on a timeline in the panel area. The
// server reads the log and maps its tree onto the XML in front (`bt-lsp.readLog`); moving along the
// timeline (a slider, steps, play at a chosen speed) shows each node's status at that moment
// as a live connection does (live.ts): after the tag names and in the Show Tree view.

import * as vscode from 'vscode';
import { ExecuteCommandRequest, type LanguageClient } from 'vscode-languageclient/node';
import { Timeline } from './btlog';
import { LiveView } from './live';
import { LiveNode, LspRange } from './liveProtocol';

const READ_LOG = 'bt-lsp.readLog';
const VIEW_ID = 'btLsp.replay';
const TICK_MS = 50;
const SPEEDS = [0.1, 0.25, 0.5, 1, 2, 5, 10];

/** What `bt-lsp.readLog` answers: `bt-lsp.mapRunningTree`'s answer for the log's tree, and the log. */
interface Mapped {
  tree: string | null;
  nodes: { uid: number; uri: string; range: LspRange }[];
  mismatches: { message?: string }[];
  startUs: number;
  transitions: unknown[];
  truncated: number;
  partialBytes: number;
}

type FromWebview =
  | { type: 'ready' }
  | { type: 'seek'; applied: number }
  | { type: 'step'; delta: number }
  | { type: 'play' }
  | { type: 'pause' }
  | { type: 'speed'; speed: number }
  | { type: 'stop' };

function nonce(): string {
  const chars = 'ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789';
  let out = '';
  for (let i = 0; i < 32; i++) {
    out += chars.charAt(Math.floor(Math.random() * chars.length));
  }
  return out;
}

/** Each mapped node's element as `Type (file:line)`, by uid, for the timeline's labels. */
function nodeLabels(mapped: Mapped, document: vscode.TextDocument): Map<number, string> {
  const own = document.uri.toString();
  const labels = new Map<number, string>();
  for (const node of mapped.nodes) {
    const uri = vscode.Uri.parse(node.uri);
    const { start, end } = node.range;
    const type =
      uri.toString() === own && start.line === end.line
        ? document.lineAt(Math.min(start.line, document.lineCount - 1)).text.slice(start.character, end.character)
        : '';
    const file = uri.path.split('/').pop() ?? '';
    labels.set(node.uid, `${type ? `${type} ` : ''}(${file}:${start.line + 1})`);
  }
  return labels;
}

function seconds(us: number): string {
  return `${(us / 1e6).toFixed(3)} s`;
}

/** One log being replayed: its clock, its position, and what it shows (through LiveView). */
class ReplaySession {
  private readonly labels: Map<number, string>;
  private applied = 0;
  private timeUs = 0;
  private speed = 1;
  private timer: ReturnType<typeof setInterval> | undefined;
  private ended = false;
  private readonly subscription: vscode.Disposable;

  constructor(
    readonly name: string,
    private readonly timeline: Timeline,
    private readonly mapped: Mapped,
    document: vscode.TextDocument,
    private readonly live: LiveView,
    private readonly post: (state: unknown) => void,
    private readonly onEnd: () => void,
  ) {
    this.labels = nodeLabels(mapped, document);
    this.subscription = live.onDidEndReplay(() => this.end());
  }

  start(): void {
    this.seek(0, 0);
  }

  onMessage(message: FromWebview): void {
    switch (message.type) {
      case 'ready':
        this.postState();
        break;
      case 'seek':
        this.pause();
        this.seekTo(message.applied);
        break;
      case 'step':
        this.pause();
        this.seekTo(this.applied + (message.delta < 0 ? -1 : 1));
        break;
      case 'play':
        this.play();
        break;
      case 'pause':
        this.pause();
        break;
      case 'speed':
        if (SPEEDS.includes(message.speed)) {
          this.speed = message.speed;
        }
        break;
      case 'stop':
        this.live.endReplay(); // ends this session too
        break;
    }
  }

  /** To just after the `applied`-th transition (its moment on the clock). */
  private seekTo(applied: number): void {
    const n = Math.max(0, Math.min(Math.trunc(applied) || 0, this.timeline.count));
    this.seek(n, n > 0 ? this.timeline.at(n - 1).offsetUs : 0);
  }

  private seek(applied: number, timeUs: number): void {
    if (this.ended) {
      return;
    }
    this.applied = applied;
    this.timeUs = timeUs;
    const statuses = this.timeline.statusesAfter(applied);
    const nodes: LiveNode[] = this.mapped.nodes.map((n) => ({ ...n, status: statuses.get(n.uid) ?? 'idle' }));
    const message =
      `replay of ${this.name} (tree ${this.mapped.tree ?? '?'}): ${seconds(timeUs)}, ` +
      `transition ${applied} of ${this.timeline.count}`;
    void this.live.showReplay(nodes, message);
    this.postState();
  }

  private play(): void {
    if (this.timer) {
      return;
    }
    if (this.applied >= this.timeline.count) {
      this.seek(0, 0); // from the start again
    }
    this.timer = setInterval(() => {
      const timeUs = Math.min(this.timeUs + TICK_MS * 1000 * this.speed, this.timeline.durationUs);
      this.seek(this.timeline.appliedAt(timeUs), timeUs);
      if (timeUs >= this.timeline.durationUs) {
        this.pause();
      }
    }, TICK_MS);
    this.postState();
  }

  private pause(): void {
    if (this.timer) {
      clearInterval(this.timer);
      this.timer = undefined;
      this.postState();
    }
  }

  postState(): void {
    if (this.ended) {
      return;
    }
    const i = this.applied - 1;
    const step = i >= 0 ? this.timeline.at(i) : undefined;
    const last = step
      ? `#${step.uid} ${this.labels.get(step.uid) ?? ''} → ${step.status.toUpperCase()}`
      : 'every node IDLE';
    this.post({
      type: 'state',
      name: this.name,
      applied: this.applied,
      count: this.timeline.count,
      time: `${seconds(this.timeUs)} of ${seconds(this.timeline.durationUs)}`,
      started: new Date(this.mapped.startUs / 1000).toISOString(),
      last,
      playing: this.timer !== undefined,
    });
  }

  /** The replay is over (stopped, replaced, or a connection took its place). */
  end(): void {
    if (this.ended) {
      return;
    }
    this.pause();
    this.ended = true;
    this.subscription.dispose();
    this.live.endReplay();
    this.onEnd();
  }
}

/** The timeline in the panel area (beside Terminal and Output), shown while a log replays. */
class ReplayViewProvider implements vscode.WebviewViewProvider {
  private view: vscode.WebviewView | undefined;
  session: ReplaySession | undefined;

  constructor(private readonly extensionUri: vscode.Uri) {}

  resolveWebviewView(view: vscode.WebviewView): void {
    this.view = view;
    const webview = view.webview;
    webview.options = { enableScripts: true, localResourceRoots: [vscode.Uri.joinPath(this.extensionUri, 'media')] };
    const scriptNonce = nonce();
    const media = (file: string) => webview.asWebviewUri(vscode.Uri.joinPath(this.extensionUri, 'media', file));
    const csp = ["default-src 'none'", `style-src ${webview.cspSource}`, `script-src 'nonce-${scriptNonce}'`].join('; ');
    const options = SPEEDS.map((s) => `<option value="${s}"${s === 1 ? ' selected' : ''}>${s}×</option>`).join('');
    webview.html = `<!DOCTYPE html>
<html lang="en">
<head>
<meta charset="UTF-8">
<meta http-equiv="Content-Security-Policy" content="${csp}">
<meta name="viewport" content="width=device-width, initial-scale=1.0">
<link rel="stylesheet" href="${media('replay.css')}">
<title>Replay</title>
</head>
<body>
<div id="controls">
<button id="start" title="To the start (Home)" aria-label="To the start">⇤</button>
<button id="back" title="One transition back (←)" aria-label="One transition back">←</button>
<button id="play" title="Play or pause (Space)" aria-label="Play">▶</button>
<button id="forward" title="One transition on (→)" aria-label="One transition on">→</button>
<button id="end" title="To the end (End)" aria-label="To the end">⇥</button>
<select id="speed" title="Speed" aria-label="Speed">${options}</select>
<input type="range" id="timeline" min="0" max="0" value="0" step="1" aria-label="Transitions">
<button id="stop" title="End the replay" aria-label="End the replay">■</button>
</div>
<div id="where"></div>
<div id="last"></div>
<script nonce="${scriptNonce}" src="${media('replay.js')}"></script>
</body>
</html>`;
    webview.onDidReceiveMessage((m: FromWebview) => this.session?.onMessage(m));
    view.onDidDispose(() => {
      if (this.view === view) {
        this.view = undefined;
      }
    });
  }

  post(message: unknown): void {
    void this.view?.webview.postMessage(message);
  }

  show(): void {
    if (this.view) {
      this.view.show(true);
    } else {
      void vscode.commands.executeCommand(`${VIEW_ID}.focus`);
    }
  }
}

/** The log to replay: the one given (the explorer's context menu), else one picked. */
async function pickLog(given: unknown): Promise<vscode.Uri | undefined> {
  if (given instanceof vscode.Uri) {
    return given;
  }
  const found = await vscode.workspace.findFiles('**/*.btlog', '**/node_modules/**', 500);
  const browse = 'Browse…';
  const items = [
    ...found
      .sort((a, b) => a.fsPath.localeCompare(b.fsPath))
      .map((uri) => ({ label: vscode.workspace.asRelativePath(uri), uri })),
    { label: browse, uri: undefined },
  ];
  const picked = await vscode.window.showQuickPick(items, {
    title: 'bt-lsp: Replay a .btlog',
    placeHolder: 'The log BT::FileLogger2 wrote for the tree of this file',
  });
  if (!picked) {
    return undefined;
  }
  if (picked.uri) {
    return picked.uri;
  }
  const chosen = await vscode.window.showOpenDialog({
    canSelectMany: false,
    filters: { 'BehaviorTree.CPP log': ['btlog'] },
    title: 'bt-lsp: Replay a .btlog',
  });
  return chosen?.[0];
}

/** Registers "bt-lsp: Replay a .btlog" and its timeline view. */
export function registerReplay(
  context: vscode.ExtensionContext,
  getClient: () => LanguageClient | undefined,
  log: vscode.LogOutputChannel,
  live: LiveView,
): void {
  const provider = new ReplayViewProvider(context.extensionUri);
  const setReplaying = (on: boolean) => void vscode.commands.executeCommand('setContext', 'btLsp.replaying', on);
  context.subscriptions.push(
    vscode.window.registerWebviewViewProvider(VIEW_ID, provider, { webviewOptions: { retainContextWhenHidden: true } }),
    vscode.commands.registerCommand('btLsp.replayLog', async (given?: unknown) => {
      const document =
        vscode.window.activeTextEditor?.document ??
        vscode.window.visibleTextEditors.find((e) => e.document.languageId === 'xml')?.document;
      if (!document || document.languageId !== 'xml' || !['file', 'untitled'].includes(document.uri.scheme)) {
        void vscode.window.showInformationMessage(
          'bt-lsp: open the BehaviorTree.CPP XML file of the logged tree, then replay its .btlog.',
        );
        return;
      }
      const client = getClient();
      if (!client) {
        void vscode.window.showErrorMessage('bt-lsp: the language server is not running (see the bt-lsp output).');
        return;
      }
      const uri = await pickLog(given);
      if (!uri) {
        return;
      }
      const name = uri.path.split('/').pop() ?? uri.path;
      let timeline: Timeline;
      let mapped: Mapped;
      try {
        mapped = (await client.sendRequest(ExecuteCommandRequest.type, {
          command: READ_LOG,
          arguments: [{ uri: client.code2ProtocolConverter.asUri(document.uri), log: uri.toString() }],
        })) as Mapped;
        timeline = new Timeline(Array.isArray(mapped.transitions) ? mapped.transitions : []);
        if (mapped.partialBytes) {
          log.info(`${name}: ends in a partial record (${mapped.partialBytes} bytes), left out`);
        }
        if (mapped.truncated) {
          void vscode.window.showWarningMessage(
            `bt-lsp: ${name} is replayed up to its ${timeline.count}th transition (${mapped.truncated} more left out).`,
          );
        }
      } catch (error) {
        const reason = error instanceof Error ? error.message : String(error);
        log.warn(`Replaying ${uri.toString()}: ${reason}`);
        void vscode.window.showErrorMessage(`bt-lsp: cannot replay ${name}: ${reason}`);
        return;
      }
      const mismatches = Array.isArray(mapped.mismatches) ? mapped.mismatches : [];
      log.info(
        `Replaying ${name}: tree ${mapped.tree ?? '(unknown)'}, ${timeline.count} transitions, ` +
          `${mismatches.length} differences from the text`,
      );
      mismatches.forEach((m) => log.info(`  ${m.message ?? JSON.stringify(m)}`));
      provider.session?.end();
      const session = new ReplaySession(
        name,
        timeline,
        mapped,
        document,
        live,
        (state) => provider.post(state),
        () => {
          if (provider.session === session) {
            provider.session = undefined;
            provider.post({ type: 'ended' });
            setReplaying(false);
          }
        },
      );
      provider.session = session;
      setReplaying(true);
      session.start();
      provider.show();
    }),
    { dispose: () => provider.session?.end() },
  );
}
