// A `.btlog` (what BT::FileLogger2 writes, Groot2 replays) read for the replay timeline, and
// the nodes' statuses at any transition. Layout (bt_file_logger_v2.cpp, little-endian):
//   "BTCPP4-FileLogger2" | uint8 version (1) | int32 xml size | the tree's XML
//   | int64 first timestamp (microseconds since the epoch)
//   | 9-byte records: uint48 microseconds since the first timestamp | uint16 uid | uint8 status
// A log copied while the robot was writing it may end in a partial record: it is left out.

import { LIVE_STATUSES, LiveNodeStatus } from './liveProtocol';

const MAGIC = 'BTCPP4-FileLogger2';
const VERSION = 1;
const MAX_XML_BYTES = 64 * 1024 * 1024;
const RECORD = 9;
/** The statuses of every node are kept every CHECKPOINT transitions: a seek replays fewer. */
const CHECKPOINT = 4096;

export class BtLogError extends Error {}

export interface BtLog {
  version: number;
  xml: string;
  startUs: number;
  /** Per transition: microseconds since the start, the node's uid, its new status (0..4). */
  offsets: Float64Array;
  uids: Uint16Array;
  statuses: Uint8Array;
  partialBytes: number;
}

export function parseBtLog(data: Uint8Array): BtLog {
  const view = new DataView(data.buffer, data.byteOffset, data.byteLength);
  const magic = new TextDecoder('latin1').decode(data.subarray(0, MAGIC.length));
  if (magic !== MAGIC) {
    throw new BtLogError('not a FileLogger2 .btlog (no BTCPP4-FileLogger2 magic)');
  }
  if (data.length < MAGIC.length + 5) {
    throw new BtLogError('the file ends inside its header');
  }
  const version = data[MAGIC.length];
  if (version !== VERSION) {
    throw new BtLogError(`FileLogger2 version ${version}; this reader knows ${VERSION}`);
  }
  const size = view.getInt32(MAGIC.length + 1, true);
  if (size <= 0 || size > MAX_XML_BYTES) {
    throw new BtLogError(`the tree's XML size ${size} is not in 1..${MAX_XML_BYTES}`);
  }
  const xmlAt = MAGIC.length + 5;
  if (data.length < xmlAt + size) {
    throw new BtLogError("the file ends inside the tree's XML");
  }
  let xml: string;
  try {
    xml = new TextDecoder('utf-8', { fatal: true }).decode(data.subarray(xmlAt, xmlAt + size));
  } catch {
    throw new BtLogError("the tree's XML is not UTF-8");
  }
  const stampAt = xmlAt + size;
  if (data.length < stampAt + 8) {
    throw new BtLogError('the file ends before its first timestamp');
  }
  const startUs = Number(view.getBigInt64(stampAt, true));
  const first = stampAt + 8;
  const count = Math.floor((data.length - first) / RECORD);
  const offsets = new Float64Array(count);
  const uids = new Uint16Array(count);
  const statuses = new Uint8Array(count);
  for (let i = 0; i < count; i++) {
    const at = first + i * RECORD;
    offsets[i] = view.getUint32(at, true) + view.getUint16(at + 4, true) * 2 ** 32;
    uids[i] = view.getUint16(at + 6, true);
    const status = data[at + 8];
    if (status >= LIVE_STATUSES.length) {
      throw new BtLogError(`transition ${i + 1}: unknown node status ${status}`);
    }
    statuses[i] = status;
  }
  return { version, xml, startUs, offsets, uids, statuses, partialBytes: data.length - first - count * RECORD };
}

/** BT::NodeStatus as the log numbers it: IDLE, RUNNING, SUCCESS, FAILURE, SKIPPED. */
const BY_CODE: readonly LiveNodeStatus[] = ['idle', 'running', 'success', 'failure', 'skipped'];

/** The statuses of the log's nodes after any number of its transitions (every node starts idle). */
export class Timeline {
  private readonly size: number;
  private readonly checkpoints: Uint8Array[] = [];

  constructor(readonly log: BtLog) {
    let maxUid = 0;
    log.uids.forEach((uid) => (maxUid = Math.max(maxUid, uid)));
    this.size = maxUid + 1;
    const state = new Uint8Array(this.size);
    for (let i = 0; i < log.uids.length; i++) {
      if (i % CHECKPOINT === 0) {
        this.checkpoints.push(state.slice());
      }
      state[log.uids[i]] = log.statuses[i];
    }
  }

  get count(): number {
    return this.log.uids.length;
  }

  /** Each node's status after the first `applied` transitions, by uid (a node never seen: idle). */
  statusesAfter(applied: number): Map<number, LiveNodeStatus> {
    const n = Math.max(0, Math.min(applied, this.count));
    const mark = Math.min(Math.floor(n / CHECKPOINT), this.checkpoints.length - 1);
    const state = mark >= 0 ? this.checkpoints[mark].slice() : new Uint8Array(this.size);
    for (let i = Math.max(0, mark) * CHECKPOINT; i < n; i++) {
      state[this.log.uids[i]] = this.log.statuses[i];
    }
    const out = new Map<number, LiveNodeStatus>();
    state.forEach((code, uid) => out.set(uid, BY_CODE[code]));
    return out;
  }

  /** How many transitions happened by `offsetUs` microseconds after the start. */
  appliedAt(offsetUs: number): number {
    let lo = 0;
    let hi = this.count;
    while (lo < hi) {
      const mid = (lo + hi) >> 1;
      if (this.log.offsets[mid] <= offsetUs) {
        lo = mid + 1;
      } else {
        hi = mid;
      }
    }
    return lo;
  }

  /** Microseconds from the start to the last transition. */
  get durationUs(): number {
    return this.count ? this.log.offsets[this.count - 1] : 0;
  }
}
