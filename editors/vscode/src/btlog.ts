// A `.btlog` replay's timeline: the transitions the server read from the log (`bt-lsp.readLog`)
// and the nodes' statuses after any number of them (every node starts idle).

import { LIVE_STATUSES, LiveNodeStatus, isLiveStatus } from './liveProtocol';

/** The statuses of every node are kept every CHECKPOINT transitions: a seek replays fewer. */
const CHECKPOINT = 4096;
const MAX_UID = 0xffff;

export class Timeline {
  /** Per transition: microseconds since the logger started, the node's uid, its new status. */
  private readonly offsets: Float64Array;
  private readonly uids: Uint16Array;
  private readonly codes: Uint8Array;
  private readonly size: number;
  private readonly checkpoints: Uint8Array[] = [];

  /** `transitions` as readLog answers them: `[offsetUs, uid, status]` in order (others skipped). */
  constructor(transitions: unknown[]) {
    const valid = transitions.filter(
      (t): t is [number, number, LiveNodeStatus] =>
        Array.isArray(t) &&
        typeof t[0] === 'number' &&
        t[0] >= 0 &&
        Number.isInteger(t[1]) &&
        t[1] >= 0 &&
        t[1] <= MAX_UID &&
        isLiveStatus(t[2]),
    );
    this.offsets = Float64Array.from(valid, (t) => t[0]);
    this.uids = Uint16Array.from(valid, (t) => t[1]);
    this.codes = Uint8Array.from(valid, (t) => LIVE_STATUSES.indexOf(t[2]));
    let maxUid = 0;
    this.uids.forEach((uid) => (maxUid = Math.max(maxUid, uid)));
    this.size = maxUid + 1;
    const idle = LIVE_STATUSES.indexOf('idle');
    const state = new Uint8Array(this.size).fill(idle);
    for (let i = 0; i < this.uids.length; i++) {
      if (i % CHECKPOINT === 0) {
        this.checkpoints.push(state.slice());
      }
      state[this.uids[i]] = this.codes[i];
    }
  }

  get count(): number {
    return this.uids.length;
  }

  /** Microseconds from the start to the last transition. */
  get durationUs(): number {
    return this.count ? this.offsets[this.count - 1] : 0;
  }

  /** The `i`-th transition (from 0): when, which node, to which status. */
  at(i: number): { offsetUs: number; uid: number; status: LiveNodeStatus } {
    return { offsetUs: this.offsets[i], uid: this.uids[i], status: LIVE_STATUSES[this.codes[i]] };
  }

  /** Each node's status after the first `applied` transitions, by uid (a node never seen: idle). */
  statusesAfter(applied: number): Map<number, LiveNodeStatus> {
    const n = Math.max(0, Math.min(applied, this.count));
    const mark = Math.min(Math.floor(n / CHECKPOINT), this.checkpoints.length - 1);
    const state =
      mark >= 0 ? this.checkpoints[mark].slice() : new Uint8Array(this.size).fill(LIVE_STATUSES.indexOf('idle'));
    for (let i = Math.max(0, mark) * CHECKPOINT; i < n; i++) {
      state[this.uids[i]] = this.codes[i];
    }
    const out = new Map<number, LiveNodeStatus>();
    state.forEach((code, uid) => out.set(uid, LIVE_STATUSES[code]));
    return out;
  }

  /** How many transitions happened by `offsetUs` microseconds after the start. */
  appliedAt(offsetUs: number): number {
    let lo = 0;
    let hi = this.count;
    while (lo < hi) {
      const mid = (lo + hi) >> 1;
      if (this.offsets[mid] <= offsetUs) {
        lo = mid + 1;
      } else {
        hi = mid;
      }
    }
    return lo;
  }
}
