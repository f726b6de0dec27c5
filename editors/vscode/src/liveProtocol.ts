// The live-tree protocol between the extension and the server (docs/live.md, "In the editor"),
// and what does not need VS Code: reading the user's host:port, and the status that stands for
// an element several running nodes map onto.

export const LIVE_CONNECT = 'bt-lsp.liveConnect';
export const LIVE_DISCONNECT = 'bt-lsp.liveDisconnect';
export const LIVE_STATUS = 'bt-lsp/liveStatus';

export const DEFAULT_ADDRESS = '127.0.0.1:1667';

export type LiveNodeStatus = 'idle' | 'running' | 'success' | 'failure' | 'skipped';
export const LIVE_STATUSES: readonly LiveNodeStatus[] = ['idle', 'running', 'success', 'failure', 'skipped'];

export interface LspPosition {
  line: number;
  character: number;
}
export interface LspRange {
  start: LspPosition;
  end: LspPosition;
}

/** One running node mapped onto the text: `range` is its start tag's name. */
export interface LiveNode {
  uid: number;
  uri: string;
  range: LspRange;
  status: LiveNodeStatus;
}

/** The `bt-lsp/liveStatus` notification's parameters. */
export interface LiveStatusParams {
  session: number;
  connected: boolean;
  message: string | null;
  tree: string | null;
  nodes: LiveNode[];
}

/** What `bt-lsp.liveConnect` answers. */
export interface LiveConnectResult {
  session: number;
  tree: string | null;
  nodes: number;
  mismatches: { message?: string }[];
}

/** The port the executor's Groot2Publisher answers on; it also binds port + 1. */
const MAX_PORT = 65534;

/**
 * `host:port` (an IPv6 host in brackets, `[::1]:1667`) as its parts, or the reason it is not
 * one. Spaces around it are ignored.
 */
export function parseAddress(text: string): { host: string; port: number } | { error: string } {
  const found = /^(?:\[([0-9A-Fa-f:.]+)\]|([A-Za-z0-9._-]+)):(\d{1,5})$/.exec(text.trim());
  if (!found) {
    return { error: 'host:port, for example 127.0.0.1:1667 (an IPv6 address in brackets: [::1]:1667)' };
  }
  const port = Number(found[3]);
  if (port < 1 || port > MAX_PORT) {
    return { error: `the port must be between 1 and ${MAX_PORT} (the executor also uses port + 1)` };
  }
  return { host: found[1] ?? found[2], port };
}

/**
 * Which status shows where several running nodes map onto one element (a tree called from two
 * places): the one a user most needs to see, running first.
 */
const PRECEDENCE: Record<LiveNodeStatus, number> = { running: 4, failure: 3, success: 2, idle: 1, skipped: 0 };

export function strongerStatus(a: LiveNodeStatus | undefined, b: LiveNodeStatus): LiveNodeStatus {
  return a === undefined || PRECEDENCE[b] > PRECEDENCE[a] ? b : a;
}

export function isLiveStatus(value: unknown): value is LiveNodeStatus {
  return typeof value === 'string' && (LIVE_STATUSES as readonly string[]).includes(value);
}
