// The server bundled in a platform-specific package: bt-lsp and its dependencies as wheels
// (bundled/wheels, listed per Python version in bundled/manifest.json), unpacked at first start
// into the extension's storage by python/bootstrap.py and run with a Python found here.

import { execFile } from 'node:child_process';
import * as fs from 'node:fs';
import * as path from 'node:path';
import * as vscode from 'vscode';
import { findOnPath, pythonExtensionInterpreter } from './pythonInterpreter';

export interface Bundle {
  bootstrap: string;
  /** Where the wheels are unpacked, one folder per bundle and Python version. */
  storage: string;
  /** The Python versions it has wheels for, e.g. ["3.11", "3.12", "3.13"]. */
  pythons: string[];
  btLsp: string;
}

export interface BundledServer {
  command: string;
  args: string[];
  origin: string;
}

/** The bundle in this package, or undefined in the package without a server. */
export function findBundle(context: vscode.ExtensionContext): Bundle | undefined {
  const manifestPath = path.join(context.extensionPath, 'bundled', 'manifest.json');
  try {
    const manifest = JSON.parse(fs.readFileSync(manifestPath, 'utf8')) as { pythons: string[]; btLsp: string };
    return {
      bootstrap: path.join(context.extensionPath, 'python', 'bootstrap.py'),
      storage: path.join(context.globalStorageUri.fsPath, 'server'),
      pythons: manifest.pythons,
      btLsp: manifest.btLsp,
    };
  } catch {
    return undefined;
  }
}

interface Candidate {
  argv: string[];
  origin: string;
}

/** The Pythons to try, in order: the `btLsp.interpreter` setting alone when it is set; else the
 * Python extension's selected interpreter, then `python3` and `python` on PATH (`py -3` first on
 * Windows). */
async function candidates(
  resource: vscode.Uri | undefined,
  log: vscode.LogOutputChannel,
  tried: string[],
): Promise<Candidate[]> {
  const configured = vscode.workspace.getConfiguration('btLsp', resource).get<unknown>('interpreter');
  if (Array.isArray(configured) && configured.length > 0) {
    if (!configured.every((a): a is string => typeof a === 'string') || configured[0] === '') {
      tried.push('setting btLsp.interpreter: must be an array of strings, e.g. ["/usr/bin/python3.12"]');
      return [];
    }
    return [{ argv: configured, origin: 'setting btLsp.interpreter' }];
  }
  const out: Candidate[] = [];
  const selected = await pythonExtensionInterpreter(resource, log);
  if (selected) {
    out.push({ argv: selected, origin: 'the Python extension' });
  } else {
    tried.push('Python extension: not installed or no interpreter selected');
  }
  const names = process.platform === 'win32' ? ['py', 'python3', 'python'] : ['python3', 'python'];
  for (const name of names) {
    const found = findOnPath(name);
    if (found) {
      out.push({ argv: name === 'py' ? [found, '-3'] : [found], origin: `${name} on PATH` });
    } else {
      tried.push(`${name} on PATH: not found`);
    }
  }
  return out;
}

interface InstallAnswer {
  ok: boolean;
  path?: string;
  python?: string;
  reason?: string;
}

/** Runs `bootstrap.py install` with `argv`: the folder to run from, or why this Python cannot. */
function install(argv: string[], bundle: Bundle): Promise<InstallAnswer> {
  const [command, ...args] = argv;
  return new Promise((resolve) => {
    execFile(
      command,
      [...args, '-I', bundle.bootstrap, 'install', bundle.storage],
      { timeout: 120000, windowsHide: true },
      (error, stdout, stderr) => {
        const last = stdout.trim().split('\n').pop() ?? '';
        try {
          const answer = JSON.parse(last) as InstallAnswer;
          if (typeof answer.ok === 'boolean') {
            resolve(answer);
            return;
          }
        } catch {
          // not our answer: the interpreter failed before or while running the script
        }
        const code = (error as NodeJS.ErrnoException | null)?.code;
        const why =
          code === 'ENOENT'
            ? 'not found'
            : code === 'EACCES'
              ? 'not executable'
              : [error?.message.split('\n', 1)[0], stderr.trim().split('\n').pop()].filter(Boolean).join(': ') ||
                'no answer';
        resolve({ ok: false, reason: why });
      },
    );
  });
}

/** The command that runs the bundled server with the first Python that can, or undefined
 * (with what was tried, one line each, in `tried`). */
export async function bundledServer(
  bundle: Bundle,
  resource: vscode.Uri | undefined,
  log: vscode.LogOutputChannel,
  tried: string[],
): Promise<BundledServer | undefined> {
  for (const candidate of await candidates(resource, log, tried)) {
    const answer = await install(candidate.argv, bundle);
    const shown = candidate.argv.join(' ');
    if (!answer.ok || !answer.path) {
      tried.push(`bundled server with ${shown} (${candidate.origin}): ${answer.reason ?? 'failed'}`);
      continue;
    }
    log.info(`Bundled bt-lsp ${bundle.btLsp} for Python ${answer.python} is in ${answer.path}`);
    const [command, ...args] = candidate.argv;
    return {
      command,
      args: [...args, '-I', bundle.bootstrap, 'serve', answer.path],
      origin: `bundled bt-lsp ${bundle.btLsp}, Python ${answer.python} from ${candidate.origin}`,
    };
  }
  return undefined;
}
