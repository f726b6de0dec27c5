// The `bt` debugger: VS Code runs `bt-lsp debug-adapter`, found the way the language server
// is (serverCommand.ts), and speaks the Debug Adapter Protocol to it over stdio. The adapter
// attaches to a running tree's Groot2 publisher (host and port in launch.json); it needs the
// `live` extra (pyzmq) of the bt-lsp it runs.

import * as vscode from 'vscode';
import { Bundle } from './bundled';
import { ServerCommand, resolveServerCommand } from './serverCommand';

export const DEBUG_TYPE = 'bt';

/** The server's arguments with `serve` made `debug-adapter`; what follows stays (the bundled
 * bootstrap's folder, or `--stdio`, which debug-adapter accepts too). */
export function debugAdapterArgs(server: ServerCommand): string[] {
  const args = [...server.args];
  const at = args.lastIndexOf('serve');
  if (at >= 0) {
    args[at] = 'debug-adapter';
  } else {
    args.push('debug-adapter');
  }
  return args;
}

/** Forces the result of the node the tree is stopped at (the adapter's custom requests). */
async function forceNode(request: 'btLsp/succeedNode' | 'btLsp/failNode'): Promise<void> {
  const session = vscode.debug.activeDebugSession;
  if (!session || session.type !== DEBUG_TYPE) {
    void vscode.window.showWarningMessage('bt-lsp: no BehaviorTree.CPP debugging session is active.');
    return;
  }
  try {
    await session.customRequest(request, { threadId: 1 });
  } catch (error) {
    void vscode.window.showErrorMessage(`bt-lsp: ${error instanceof Error ? error.message : String(error)}`);
  }
}

export function registerDebugAdapter(
  context: vscode.ExtensionContext,
  log: vscode.LogOutputChannel,
  bundle: () => Bundle | undefined,
): void {
  const factory: vscode.DebugAdapterDescriptorFactory = {
    async createDebugAdapterDescriptor(session: vscode.DebugSession): Promise<vscode.DebugAdapterDescriptor> {
      const { server, tried } = await resolveServerCommand(session.workspaceFolder?.uri, log, bundle());
      if (!server) {
        tried.forEach((line) => log.info(line));
        throw new Error('bt-lsp was not found to run its debug adapter (what was tried is in the bt-lsp output)');
      }
      const args = debugAdapterArgs(server);
      log.info(`Starting the debug adapter (${server.origin}): ${JSON.stringify([server.command, ...args])}`);
      return new vscode.DebugAdapterExecutable(server.command, args);
    },
  };
  const provider: vscode.DebugConfigurationProvider = {
    resolveDebugConfiguration(_folder, config) {
      // F5 without a launch.json: attach to the default address.
      if (!config.type && !config.request && !config.name) {
        return { type: DEBUG_TYPE, request: 'attach', name: 'Attach to a running tree', host: '127.0.0.1', port: 1667 };
      }
      return config;
    },
  };
  context.subscriptions.push(
    vscode.debug.registerDebugAdapterDescriptorFactory(DEBUG_TYPE, factory),
    vscode.debug.registerDebugConfigurationProvider(DEBUG_TYPE, provider),
    vscode.commands.registerCommand('btLsp.succeedNode', () => forceNode('btLsp/succeedNode')),
    vscode.commands.registerCommand('btLsp.failNode', () => forceNode('btLsp/failNode')),
  );
}
