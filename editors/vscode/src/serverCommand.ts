// Finding the command line that starts the bt-lsp language server.
//
// Order: the `btLsp.server.command` setting, then `bt-lsp` on PATH, then the interpreter
// selected in the Python extension (`<python> -m bt_lsp serve`) if bt_lsp imports there.

import { spawnSync } from 'node:child_process';
import * as fs from 'node:fs';
import * as path from 'node:path';
import * as vscode from 'vscode';

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

export const PYTHON_EXTENSION_ID = 'ms-python.python';

export async function resolveServerCommand(
  resource: vscode.Uri | undefined,
  log: vscode.LogOutputChannel,
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

  const onPath = findOnPath('bt-lsp');
  if (onPath) {
    return { server: { command: onPath, args: ['serve'], origin: 'bt-lsp on PATH' }, tried };
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
      server: {
        command,
        args: [...args, '-m', 'bt_lsp', 'serve'],
        origin: `Python extension interpreter ${python.join(' ')}`,
      },
      tried,
    };
  }
  return { tried };
}

/** The full path of an executable named `name` on PATH, or undefined. */
export function findOnPath(name: string, env: NodeJS.ProcessEnv = process.env): string | undefined {
  const dirs = (env.PATH ?? env.Path ?? '').split(path.delimiter).filter((d) => d !== '');
  const exts = process.platform === 'win32' ? (env.PATHEXT ?? '.EXE;.CMD;.BAT').split(';') : [''];
  for (const dir of dirs) {
    for (const ext of exts) {
      const candidate = path.join(dir, name + ext);
      try {
        fs.accessSync(candidate, fs.constants.X_OK);
        if (fs.statSync(candidate).isFile()) {
          return candidate;
        }
      } catch {
        // not here
      }
    }
  }
  return undefined;
}

function canImportBtLsp(python: string[]): boolean {
  const [command, ...args] = python;
  const result = spawnSync(command, [...args, '-c', 'import bt_lsp'], { timeout: 15000, stdio: 'ignore' });
  return result.status === 0;
}

// The parts of the Python extension's API that are used here.
interface PythonExtensionApi {
  environments?: {
    getActiveEnvironmentPath(resource?: vscode.Uri): { id: string; path: string };
    resolveEnvironment(
      env: { id: string; path: string } | string,
    ): Promise<{ executable: { uri?: vscode.Uri } } | undefined>;
  };
  settings?: {
    getExecutionDetails?(resource?: vscode.Uri): { execCommand: string[] | undefined };
  };
}

/** The argv that runs the Python extension's selected interpreter, or undefined. */
async function pythonExtensionInterpreter(
  resource: vscode.Uri | undefined,
  log: vscode.LogOutputChannel,
): Promise<string[] | undefined> {
  const extension = vscode.extensions.getExtension<PythonExtensionApi>(PYTHON_EXTENSION_ID);
  if (!extension) {
    return undefined;
  }
  try {
    const api = extension.isActive ? extension.exports : await extension.activate();
    if (api.environments) {
      const env = await api.environments.resolveEnvironment(api.environments.getActiveEnvironmentPath(resource));
      const executable = env?.executable.uri?.fsPath;
      if (executable) {
        return [executable];
      }
    }
    // Older API; its argv may be a wrapper such as `conda run -n env python`.
    const execCommand = api.settings?.getExecutionDetails?.(resource).execCommand;
    return execCommand && execCommand.length > 0 ? execCommand : undefined;
  } catch (error) {
    log.warn(`Could not ask the Python extension for its interpreter: ${String(error)}`);
    return undefined;
  }
}
