// VS Code client for the bt-lsp language server (BehaviorTree.CPP XML).

import * as vscode from 'vscode';
import {
  CloseAction,
  ErrorAction,
  ErrorHandler,
  Executable,
  LanguageClient,
  LanguageClientOptions,
  ServerOptions,
  State,
} from 'vscode-languageclient/node';
import { Bundle, findBundle } from './bundled';
import { registerDebugAdapter } from './debugAdapter';
import { LiveView } from './live';
import { registerReplay } from './replay';
import { resolveServerCommand } from './serverCommand';
import { ServerStatus } from './status';
import { registerTreeView } from './treeView';

const CLIENT_ID = 'btLsp'; // also the settings section; vscode-languageclient reads `btLsp.trace.server`
const CLIENT_NAME = 'bt-lsp';

let log: vscode.LogOutputChannel;
let client: LanguageClient | undefined;
let status: ServerStatus;
let live: LiveView;
let bundle: Bundle | undefined;
/** The settings that decide which server runs: a change restarts it. */
const SERVER_CHOICE = ['btLsp.server.command', 'btLsp.importStrategy', 'btLsp.interpreter'];
// Start, stop and restart run one after another, in the order they were asked for.
let queue: Promise<void> = Promise.resolve();

/**
 * A LanguageClient whose errors go to the output with their details, and to a notification
 * only as one sentence. Until the server has started it only logs them: if the start fails, one
 * notification that says how to install the server replaces the client's own three or four. A
 * notification that could not be sent (the connection is down) is only logged: the client says
 * itself when the server stopped, and a stack trace would stay on screen after it recovered.
 */
class BtLspClient extends LanguageClient {
  starting = true;

  override error(message: string, data?: unknown, showNotification: boolean | 'force' = true): void {
    super.error(message, data, false);
    if (this.starting || showNotification === false || /^Sending notification /.test(message)) {
      return;
    }
    const showOutput = 'Show Output';
    const restartServer = 'Restart server';
    void vscode.window.showErrorMessage(`bt-lsp: ${firstLine(message)}`, showOutput, restartServer).then((choice) => {
      if (choice === showOutput) {
        log.show();
      } else if (choice === restartServer) {
        void vscode.commands.executeCommand('btLsp.restartServer');
      }
    });
  }
}

/** The first line of a message, without what a stack trace or JSON dump adds below it. */
function firstLine(message: string): string {
  return message.split('\n', 1)[0].trim();
}

function enqueue(work: () => Promise<void>): Promise<void> {
  queue = queue.then(work, work);
  return queue;
}

export function activate(context: vscode.ExtensionContext): Promise<void> {
  log = vscode.window.createOutputChannel(CLIENT_NAME, { log: true });
  bundle = findBundle(context);
  status = new ServerStatus();
  live = new LiveView(context, log);
  context.subscriptions.push(
    log,
    status,
    live,
    vscode.commands.registerCommand('btLsp.restartServer', () => restart()),
    vscode.commands.registerCommand('btLsp.showOutput', () => log.show()),
    vscode.workspace.onDidChangeConfiguration((event) => {
      const changed = SERVER_CHOICE.find((key) => event.affectsConfiguration(key));
      if (changed) {
        log.info(`${changed} changed: restarting the server`);
        void restart();
      }
    }),
  );
  registerTreeView(context, () => client, log, live);
  registerReplay(context, () => client, log, live);
  registerDebugAdapter(context, log, () => bundle);
  return enqueue(startClient);
}

export function deactivate(): Promise<void> {
  return enqueue(stopClient);
}

function restart(): Promise<void> {
  return enqueue(async () => {
    await stopClient();
    await startClient();
  });
}

/** The `btLsp` settings the server understands (every one declared in package.json but the
 * extension's own `server.command` and `trace.server`), also sent as initializationOptions. */
const SERVER_SETTINGS = [
  'debounceMs',
  'severity',
  'maxDocumentBytes',
  'rosPackages',
  'modelFiles',
  'btcpp',
  'minSeverity',
];

function serverSettings(): Record<string, unknown> {
  const config = vscode.workspace.getConfiguration('btLsp');
  const out: Record<string, unknown> = {};
  for (const key of SERVER_SETTINGS) {
    out[key] = config.get(key);
  }
  return out;
}

async function startClient(): Promise<void> {
  // The settings of the file in front (its folder's), unless that is not a file of the
  // workspace (say, the settings.json just edited to fix the command).
  const active = vscode.window.activeTextEditor?.document.uri;
  const resource =
    active && (active.scheme === 'file' || active.scheme === 'untitled') ? active : vscode.workspace.workspaceFolders?.[0]?.uri;
  status.starting();
  const { server, tried } = await resolveServerCommand(resource, log, bundle);
  tried.forEach((line) => log.info(line));
  if (!server) {
    const prefix = 'bundled server with ';
    const attempts = tried.filter((line) => line.startsWith(prefix)).map((line) => line.slice(prefix.length));
    showInstallHelp(
      !bundle
        ? 'the bt-lsp language server was not found'
        : attempts.length > 0
          ? `no Python could run the bundled bt-lsp language server (${attempts.join('; ')})`
          : `no Python ${bundle.pythons.join(', ')} was found to run the bundled bt-lsp language server`,
      tried,
    );
    return;
  }

  const argv = [server.command, ...server.args];
  log.info(`Starting the server (${server.origin}): ${JSON.stringify(argv)}`);
  // No `transport` here: with TransportKind.stdio the client would append `--stdio` to argv.
  const executable: Executable = { command: server.command, args: server.args };
  const serverOptions: ServerOptions = { run: executable, debug: executable };
  let candidate: BtLspClient | undefined = undefined;
  let defaultErrorHandler: ErrorHandler | undefined;
  // Until the first start has succeeded, a failure is reported once (below) and not retried.
  const errorHandler: ErrorHandler = {
    error: (error, message, count) =>
      candidate?.starting !== false
        ? { action: ErrorAction.Shutdown, handled: true }
        : (defaultErrorHandler ??= candidate.createDefaultErrorHandler()).error(error, message, count),
    closed: () =>
      candidate?.starting !== false
        ? { action: CloseAction.DoNotRestart, handled: true }
        : (defaultErrorHandler ??= candidate.createDefaultErrorHandler()).closed(),
  };
  const clientOptions: LanguageClientOptions = {
    documentSelector: [
      { scheme: 'file', language: 'xml' },
      { scheme: 'untitled', language: 'xml' },
      // C++ sources: the node catalog is learned from them, and their registered IDs and
      // port names are checked where they are written.
      { scheme: 'file', language: 'cpp' },
    ],
    outputChannel: log,
    traceOutputChannel: log,
    initializationOptions: serverSettings,
    // The server reads the `btLsp` section through workspace/configuration; this makes the
    // client send workspace/didChangeConfiguration when it changes.
    synchronize: { configurationSection: CLIENT_ID },
    errorHandler,
    initializationFailedHandler: () => false,
  };

  candidate = new BtLspClient(CLIENT_ID, CLIENT_NAME, serverOptions, clientOptions);
  try {
    await candidate.start();
    candidate.starting = false;
    client = candidate;
    // A new client after each restart: its notifications need a listener of their own.
    live.attach(candidate);
    log.info('The server is running.');
    status.running(server.origin);
    const running = candidate;
    running.onDidChangeState((event) => {
      if (event.newState === State.Stopped && client === running) {
        live.reset('the bt-lsp server stopped');
      }
      // Stopped for good (it crashed too often), not stopped to restart.
      if (event.newState === State.Stopped && client === running) {
        status.notRunning('the bt-lsp server stopped', 'Run "bt-lsp: Restart server"; its messages are in the bt-lsp output.');
      }
    });
  } catch (error) {
    log.error(`The server did not start: ${errorText(error)}`);
    try {
      await candidate.dispose(2000);
    } catch {
      // it never ran
    }
    // When the process exits during startup (say, `No module named bt_lsp`), the client only
    // knows that its pending request was dropped; what the process said is in the log.
    // Node's own wording (`Error: spawn /x ENOENT`) says in code what one word says plainly.
    const text = errorText(error);
    const why = /connection got disposed/.test(text)
      ? 'the server process exited before it answered (its messages are in the bt-lsp output)'
      : /\bENOENT\b/.test(text)
        ? `${server.command} does not exist`
        : /\bEACCES\b/.test(text)
          ? `${server.command} is not executable`
          : firstLine(text);
    showInstallHelp(`could not start ${JSON.stringify(argv)} (${server.origin}): ${why}`, []);
  }
}

async function stopClient(): Promise<void> {
  const running = client;
  client = undefined;
  live.detach();
  if (running) {
    try {
      await running.stop(2000);
    } catch (error) {
      log.warn(`Stopping the server: ${errorText(error)}`);
    }
  }
}

function errorText(error: unknown): string {
  return error instanceof Error ? error.message : String(error);
}

/** Opens the settings where `btLsp.server.command` belongs. It is machine-overridable, so in a
 * remote window (SSH, WSL, container) VS Code ignores it in the local user settings: there it
 * goes in the remote machine's settings, where the server runs; elsewhere in the user settings. */
function openServerCommandSetting(): Thenable<unknown> {
  const command = vscode.env.remoteName ? 'workbench.action.openRemoteSettings' : 'workbench.action.openGlobalSettings';
  return vscode.commands.executeCommand(command, { query: bundle ? 'btLsp.interpreter' : 'btLsp.server.command' });
}

/** Logs why the server is not running and shows a notification saying how to install it. */
function showInstallHelp(reason: string, tried: string[]): void {
  const help = bundle
    ? `The extension brings bt-lsp but needs Python ${bundle.pythons.join(', ')} to run it: install one ` +
      'so that `python3` is on PATH (`py` on Windows), select it in the Python extension, or set ' +
      '`btLsp.interpreter`, e.g. ["/usr/bin/python3.12"]. Or set `btLsp.server.command` to the command ' +
      'that starts your own bt-lsp. Then run "bt-lsp: Restart server".'
    : 'Install the server with `pip install bt-lsp` (or from a checkout of its repository: ' +
      '`pip install /path/to/bt-lsp`) into a Python whose scripts folder is on PATH or that is ' +
      'selected in the Python extension, or set `btLsp.server.command` to the command that starts it, ' +
      'e.g. ["/path/to/python", "-m", "bt_lsp", "serve"]. Then run "bt-lsp: Restart server".';
  log.error(`${reason}. ${help}`);
  status.notRunning(reason, help);
  if (tried.length > 0) {
    log.error(`Tried:\n  ${tried.join('\n  ')}`);
  }
  const openSettings = 'Open Settings';
  const showOutput = 'Show Output';
  const restartServer = 'Restart server';
  // Not awaited: the notification stays until the user closes it, and a restart must not wait for that.
  void vscode.window
    .showErrorMessage(`bt-lsp: ${reason}. ${help}`, openSettings, showOutput, restartServer)
    .then((choice) => {
      if (choice === openSettings) {
        void openServerCommandSetting();
      } else if (choice === showOutput) {
        log.show();
      } else if (choice === restartServer) {
        void vscode.commands.executeCommand('btLsp.restartServer');
      }
    });
}
