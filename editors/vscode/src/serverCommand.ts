// Finding the command line that starts the bt-lsp language server.
//
// The `btLsp.server.command` setting always wins. Otherwise `btLsp.importStrategy` orders two
// ways: "bundled" (the default) runs the server this package brings (see bundled.ts) and
// falls back to the environment; "fromEnvironment" looks for `bt-lsp` on PATH, then for the
// bt_lsp module in the Python extension's selected interpreter, and falls back to the bundled
// server. A package without a bundled server (the one built without a target) only has the
// environment.

import { spawnSync } from 'node:child_process';
import * as vscode from 'vscode';
import { Bundle, bundledServer } from './bundled';
import { PYTHON_EXTENSION_ID, findOnPath, pythonExtensionInterpreter } from './pythonInterpreter';

export interface ServerCommand {
  command: string;
  args: string[];
  /** Where the command came from, for the log and error messages. */
  origin: string;
}

export interface Resolution {
  server?: ServerCommand;
  /** What was tried, one line each, for the log and the "not found" notification. */
  tried: string[];
}

export type ImportStrategy = 'bundled' | 'fromEnvironment';

export function importStrategy(resource: vscode.Uri | undefined): ImportStrategy {
  const value = vscode.workspace.getConfiguration('btLsp', resource).get<string>('importStrategy');
  return value === 'fromEnvironment' ? 'fromEnvironment' : 'bundled';
}

export async function resolveServerCommand(
  resource: vscode.Uri | undefined,
  log: vscode.LogOutputChannel,
  bundle: Bundle | undefined,
): Promise<Resolution> {
  const tried: string[] = [];
  const config = vscode.workspace.getConfiguration('btLsp', resource);

  const configured = config.get<unknown>('server.command');
  if (Array.isArray(configured) && configured.length > 0) {
    if (!configured.every((a): a is string => typeof a === 'string') || configured[0] === '') {
      tried.push('setting btLsp.server.command: must be an array of strings, e.g. ["bt-lsp", "serve"]');
      return { tried };
    }
    const [command, ...args] = configured;
    return { server: { command, args, origin: 'setting btLsp.server.command' }, tried };
  }
  tried.push('setting btLsp.server.command: not set');

  const fromBundle = async (): Promise<ServerCommand | undefined> =>
    bundle ? bundledServer(bundle, resource, log, tried) : undefined;
  const fromEnv = (): Promise<ServerCommand | undefined> => environmentServer(resource, log, tried);
  const order = importStrategy(resource) === 'fromEnvironment' ? [fromEnv, fromBundle] : [fromBundle, fromEnv];
  if (!bundle) {
    tried.push('bundled server: not in this package (it is in the platform-specific packages)');
  }
  for (const find of order) {
    const server = await find();
    if (server) {
      return { server, tried };
    }
  }
  return { tried };
}

/** `bt-lsp` on PATH, else `<python> -m bt_lsp serve` with the Python extension's interpreter. */
async function environmentServer(
  resource: vscode.Uri | undefined,
  log: vscode.LogOutputChannel,
  tried: string[],
): Promise<ServerCommand | undefined> {
  const onPath = findOnPath('bt-lsp');
  if (onPath) {
    return { command: onPath, args: ['serve'], origin: 'bt-lsp on PATH' };
  }
  tried.push('bt-lsp on PATH: not found');

  const python = await pythonExtensionInterpreter(resource, log);
  if (python === undefined) {
    tried.push(`Python extension (${PYTHON_EXTENSION_ID}): not installed or no interpreter selected`);
  } else if (!canImportBtLsp(python)) {
    tried.push(`Python extension interpreter ${python.join(' ')}: the bt_lsp module is not installed there`);
  } else {
    const [command, ...args] = python;
    return {
      command,
      args: [...args, '-m', 'bt_lsp', 'serve'],
      origin: `Python extension interpreter ${python.join(' ')}`,
    };
  }
  return undefined;
}

function canImportBtLsp(python: string[]): boolean {
  const [command, ...args] = python;
  const result = spawnSync(command, [...args, '-c', 'import bt_lsp'], { timeout: 15000, stdio: 'ignore' });
  return result.status === 0;
}
