"""``bt-lsp.liveConnect`` / ``bt-lsp.liveDisconnect``: a running tree's statuses shown on
the open document, as ``bt-lsp/liveStatus`` notifications (docs/live.md).

The executor is watched by a :class:`~bt_lsp.live.watch.Watcher` on a thread of its own;
what it sees is handed to the event loop (``call_soon_threadsafe``), which owns the
session: the tree's mapping onto the documents (as ``bt-lsp.mapRunningTree`` makes it,
made again when a document changed), the statuses and the recent transitions.  One
session per server: a new connect replaces the old one.  While connected, a hover on a
blackboard key adds the key's live value (asked on the watcher's thread, waited for at
most :data:`HOVER_WAIT`), and a hover on a node's tag its last transitions.
"""

from __future__ import annotations

import asyncio
import contextlib
import json
from bisect import bisect_right
from collections import deque
from collections.abc import Mapping
from concurrent.futures import TimeoutError as FutureTimeout
from dataclasses import dataclass, field
from datetime import datetime
from typing import Any, Final

from lsprotocol import types
from pygls.exceptions import JsonRpcInvalidParams

from bt_lsp.ide.blackboard import key_at
from bt_lsp.live.mapping import TreeMap
from bt_lsp.live.protocol import DEFAULT_HOST, DEFAULT_PORT, LiveError, NodeState, NodeStatus
from bt_lsp.live.tree import LiveTree
from bt_lsp.live.watch import CONNECT_TIMEOUT, Change, First, Update, Watcher, clamp_rate
from bt_lsp.server.app import BtServer
from bt_lsp.server.live import locator, map_onto, mismatch_json
from bt_lsp.server.navigation import RequestFailed
from bt_lsp.server.state import OpenDocument

CONNECT: Final = "bt-lsp.liveConnect"
DISCONNECT: Final = "bt-lsp.liveDisconnect"
NOTIFICATION: Final = "bt-lsp/liveStatus"
HOVER_WAIT: Final = 0.5  # seconds a hover waits at most for a blackboard value
VALUE_CHARS: Final = 200  # characters of a live value shown
TRANSITIONS_SHOWN: Final = 5
STOP_WAIT: Final = 2.0  # seconds to wait for the watcher's thread to end
DEFAULT_RATE: Final = 10.0


@dataclass(frozen=True, slots=True)
class _Options:
    uri: str
    host: str
    port: int
    rate: float


def _options(args: tuple[Any, ...]) -> _Options:
    if len(args) != 1 or not isinstance(args[0], Mapping):
        raise JsonRpcInvalidParams(f"{CONNECT} takes one object: {{uri, host?, port?, rateHz?}}")
    raw = args[0]
    # (An option given as null is the default, as one left out.)
    uri = raw.get("uri")
    host = DEFAULT_HOST if raw.get("host") is None else raw["host"]
    port = DEFAULT_PORT if raw.get("port") is None else raw["port"]
    rate = DEFAULT_RATE if raw.get("rateHz") is None else raw["rateHz"]
    if not isinstance(uri, str):
        raise JsonRpcInvalidParams(f"{CONNECT}: 'uri' must be a string")
    if (
        not isinstance(host, str)
        or not host
        or len(host) > 253
        or any(c.isspace() or c in "/@?#" for c in host)
    ):
        raise JsonRpcInvalidParams(f"{CONNECT}: 'host' is not a host name or address")
    if not isinstance(port, int) or isinstance(port, bool) or not 1 <= port <= 65534:
        raise JsonRpcInvalidParams(f"{CONNECT}: 'port' must be an integer in 1..65534")
    if not isinstance(rate, int | float) or isinstance(rate, bool) or rate != rate:
        raise JsonRpcInvalidParams(f"{CONNECT}: 'rateHz' must be a number")
    return _Options(uri, host.strip("[]"), port, clamp_rate(float(rate)))


def status_name(state: NodeState | None) -> str:
    """The protocol's status word: a node back to IDLE (whatever it was) is ``idle``."""
    if state is None or state.status is NodeStatus.IDLE:
        return "idle"
    return state.status.name.lower()


def _boards(tree: LiveTree) -> dict[int, str]:
    """The blackboard of each node: its tree instance's (the main tree's ID, or the
    SubTree instance's path), as the executor names them in ``LiveTree.blackboards``."""
    out: dict[int, str] = {}
    stack = [(tree.root, tree.tree_id)]
    while stack:
        node, board = stack.pop()
        out[node.uid] = board
        inner = node.path if node.subtree is not None else board
        stack.extend((child, inner) for child in node.children)
    return out


@dataclass(slots=True, eq=False)
class _Node:
    uri: str
    start: int  # the start tag name's code-point offsets in its document
    end: int
    range: dict[str, Any]


@dataclass(slots=True, eq=False)
class _Session:
    """One live session, owned by the event loop."""

    id: int
    uri: str
    watcher: Watcher
    tree: LiveTree | None = None
    connected: bool = False
    message: str | None = None
    states: Mapping[int, NodeState] = field(default_factory=dict)
    boards: dict[int, str] = field(default_factory=dict)
    nodes: dict[int, _Node] = field(default_factory=dict)
    at: dict[tuple[str, int], int] = field(default_factory=dict)  # (uri, name start) -> uid
    stamp: tuple[int, int] | None = None  # what the mapping was made from
    changes: dict[int, deque[Change]] = field(default_factory=dict)
    sent: str | None = None  # the last notification's nodes, as JSON
    mapped: TreeMap | None = None


class LiveMonitor:
    """The server's live session, if any (see the module docstring)."""

    def __init__(self, ls: BtServer) -> None:
        self._ls = ls
        self._session: _Session | None = None
        self._count = 0

    # ------------------------------------------------------------------ commands

    async def connect(self, *args: Any) -> dict[str, Any]:
        opts = _options(args)
        if self._ls.get(opts.uri) is None:
            raise RequestFailed(f"{opts.uri} is not an open document")
        await self._end("replaced by a new connection")
        loop = asyncio.get_running_loop()
        self._count += 1
        session_id = self._count
        holder: list[_Session] = []

        def report(update: Update) -> None:  # on the watcher's thread
            with contextlib.suppress(RuntimeError):  # the loop is closed: shutting down
                loop.call_soon_threadsafe(self._updated, holder[0], update)

        watcher = Watcher(opts.host, opts.port, opts.rate, report)
        session = _Session(session_id, opts.uri, watcher)
        holder.append(session)
        self._session = session
        try:
            first: First = await asyncio.wait_for(
                asyncio.wrap_future(watcher.start()), CONNECT_TIMEOUT + 5
            )
        except asyncio.CancelledError:  # the client cancelled the request
            if self._session is session:
                self._session = None
            watcher.stop(0)
            raise
        except (LiveError, TimeoutError) as e:
            if self._session is session:
                self._session = None
            await _stopped(watcher)
            why = str(e) or "no answer"
            raise RequestFailed(f"cannot watch the executor at {watcher.address}: {why}") from None
        if self._session is not session:  # replaced or disconnected meanwhile
            raise RequestFailed(f"the connection to {watcher.address} was cancelled")
        session.connected = True
        od = self._ls.get(opts.uri)
        if od is None:
            await self._end("the document was closed")
            raise RequestFailed(f"{opts.uri} is not an open document")
        self._new_tree(session, first.tree)
        if not session.states:
            session.states = first.states
        tm = session.mapped
        assert tm is not None
        tree = first.tree
        message = f"connected to {watcher.address} (tree {tree.tree_id}, {len(tree.nodes)} nodes)"
        if first.message:
            message += f"; {first.message}"
        session.message = message
        self._notify(session, force=True)
        location = locator(self._ls, od)
        return {
            "session": session.id,
            "tree": first.tree.tree_id,
            "nodes": len(session.nodes),
            "mismatches": [mismatch_json(m, location) for m in tm.mismatches],
        }

    async def disconnect(self, *args: Any) -> None:
        if len(args) > 1 or (args and args[0] is not None and not isinstance(args[0], Mapping)):
            raise JsonRpcInvalidParams(f"{DISCONNECT} takes no argument (or {{}})")
        await self._end("disconnected")

    async def _end(self, why: str) -> None:
        """Stop the session (its thread ended off the loop), then say so."""
        session = self._session
        if session is None:
            return
        self._session = None
        await _stopped(session.watcher)
        self._final(session, why)

    def stop(self) -> None:
        """The server shuts down: end the session's thread (waits for it)."""
        session, self._session = self._session, None
        if session is not None:
            session.watcher.stop(STOP_WAIT)
            self._final(session, "the server shuts down")

    def _final(self, session: _Session, why: str) -> None:
        payload = {
            "session": session.id,
            "connected": False,
            "message": why,
            "tree": session.tree.tree_id if session.tree is not None else None,
            "nodes": [],
        }
        with contextlib.suppress(Exception):  # (no client any more)
            self._ls.bt_protocol.notify_json(NOTIFICATION, json.dumps(payload))

    # ------------------------------------------------------------------ updates

    def _updated(self, session: _Session, update: Update) -> None:
        """On the loop: what the watcher saw."""
        if session is not self._session:
            return  # a stopped session's last words
        try:
            self._update(session, update)
        except Exception:  # a defect must not stop the loop
            self._ls.log_error("handling the live session's update")

    def _update(self, session: _Session, update: Update) -> None:
        changed = update.connected != session.connected or update.message is not None
        session.connected = update.connected
        if update.message is not None:
            session.message = update.message
        if update.tree is not None:
            session.changes.clear()
            self._new_tree(session, update.tree)
            changed = True
        if update.states is not None:
            session.states = update.states
        elif not update.connected:
            session.states = {}
        for change in update.changes:
            kept = session.changes.get(change.uid)
            if kept is None:
                kept = session.changes[change.uid] = deque(maxlen=TRANSITIONS_SHOWN)
            kept.append(change)
        if session.tree is None:  # the connect command maps it and sends the first
            return
        self._notify(session, force=changed)

    def _new_tree(self, session: _Session, tree: LiveTree) -> None:
        session.tree = tree
        session.boards = _boards(tree)
        session.stamp = None
        self._remap(session)

    def _remap(self, session: _Session) -> None:
        """Map the tree onto the document again if any document changed since."""
        ls = self._ls
        stamp = (ls.edits, ls.project.generation)
        od = ls.get(session.uri)
        if session.tree is None or od is None or session.stamp == stamp:
            return
        session.stamp = stamp
        tm = map_onto(ls, od, session.tree)
        session.mapped = tm
        location = locator(ls, od)
        session.nodes.clear()
        session.at.clear()
        for uid in sorted(tm.places):
            place = tm.places[uid]
            loc = location(place)
            if loc is None:
                continue
            session.nodes[uid] = _Node(loc["uri"], place.start, place.end, loc["range"])
            session.at[(loc["uri"], place.start)] = uid

    def _notify(self, session: _Session, *, force: bool) -> None:
        if session.connected:
            self._remap(session)
            nodes = [
                {
                    "uid": uid,
                    "uri": n.uri,
                    "range": n.range,
                    "status": status_name(session.states.get(uid)),
                }
                for uid, n in session.nodes.items()
            ]
        else:
            nodes = []
        text = json.dumps(nodes)
        if text == session.sent and not force:
            return
        session.sent = text
        payload = json.dumps(
            {
                "session": session.id,
                "connected": session.connected,
                "message": session.message,
                "tree": session.tree.tree_id if session.tree is not None else None,
                "nodes": nodes,
            }
        )
        self._ls.bt_protocol.notify_json(NOTIFICATION, payload)

    # ------------------------------------------------------------------ hover

    def hover(self, od: OpenDocument, offset: int, markdown: bool) -> tuple[str, int, int] | None:
        """What a hover at ``offset`` of ``od`` adds while connected: a key's live value,
        or a node's last transitions; ``(text, start, end)``."""
        session = self._session
        if session is None or not session.connected or session.tree is None or not od.is_bt:
            return None
        self._remap(session)
        doc = od.doc
        key = key_at(doc, offset)
        els = doc.model.elements
        if key is not None:
            uid = session.at.get((od.uri, els[key.element].name_start))
            if uid is None:
                return None
            return self._value(session, uid, key.key, markdown), key.start, key.end
        i = bisect_right(els, offset, key=lambda e: e.token_start) - 1
        if i < 0 or not els[i].name_start <= offset <= els[i].name_end:
            return None
        uid = session.at.get((od.uri, els[i].name_start))
        if uid is None:
            return None
        return self._transitions(session, uid, markdown), els[i].name_start, els[i].name_end

    def _value(self, session: _Session, uid: int, key: str, markdown: bool) -> str:
        title = f"Live value (running tree): {_code(key, markdown)}"
        tree = session.tree
        assert tree is not None
        answer = session.watcher.blackboards(tree.blackboards)
        try:
            boards = answer.result(HOVER_WAIT)
        except FutureTimeout:
            answer.cancel()
            return f"{title}: no answer from the executor within {HOVER_WAIT:g} s"
        except LiveError as e:
            return f"{title}: not read ({_clip(str(e))})"
        own = session.boards.get(uid)
        order = [own] if own is not None else []
        order += [b for b in boards if b != own]
        for board in order:
            entries = boards.get(board)
            if isinstance(entries, Mapping) and key in entries:
                try:
                    shown = json.dumps(entries[key], ensure_ascii=False, default=repr)
                except (ValueError, RecursionError):
                    shown = repr(entries[key])
                where = "" if board == own else f" (blackboard {_code(board, markdown)})"
                return f"{title} = {_code(_clip(shown), markdown)}{where}"
        return f"{title}: unknown (not on the executor's blackboards)"

    def _transitions(self, session: _Session, uid: int, markdown: bool) -> str:
        kept = session.changes.get(uid)
        node = session.tree.nodes.get(uid) if session.tree is not None else None
        label = f"#{uid}" if node is None else f"{node.label} #{uid}"
        title = f"Last transitions (running tree, {_code(label, markdown)}):"
        state = status_name(session.states.get(uid)).upper()
        if not kept:
            return f"{title}\n\nnone since connecting (now {state})"
        lines = []
        for c in reversed(kept):
            when = datetime.fromtimestamp(c.time_us / 1e6).strftime("%H:%M:%S.%f")[:-3]
            before = c.before.name if c.before is not None else "?"
            lines.append(f"{when} {before} -> {c.after.name}")
        if markdown:
            return title + "\n\n" + "\n".join(f"- {line}" for line in lines)
        return title + "\n" + "\n".join(lines)


async def _stopped(watcher: Watcher) -> None:
    """Stop ``watcher`` and wait (without holding the loop, nor taking a thread for it)
    until its thread has ended, at most :data:`STOP_WAIT` seconds."""
    watcher.stop(0)
    loop = asyncio.get_running_loop()
    deadline = loop.time() + STOP_WAIT
    while watcher.alive and loop.time() < deadline:
        await asyncio.sleep(0.02)


def _clip(text: str) -> str:
    return text if len(text) <= VALUE_CHARS else text[: VALUE_CHARS - 1] + "…"


def _code(text: str, markdown: bool) -> str:
    """``text`` as inline code (Markdown: fenced with more backticks than it holds)."""
    if not markdown:
        return f"'{text}'"
    run = longest = 0
    for c in text:
        run = run + 1 if c == "`" else 0
        longest = max(longest, run)
    fence = "`" * (longest + 1)
    pad = " " if text.startswith("`") or text.endswith("`") else ""
    return f"{fence}{pad}{text}{pad}{fence}"


def register(server: BtServer) -> None:
    monitor = LiveMonitor(server)
    server.live = monitor

    @server.command(CONNECT)
    async def _connect(ls: BtServer, *args: Any) -> dict[str, Any]:
        return await monitor.connect(*args)

    @server.command(DISCONNECT)
    async def _disconnect(ls: BtServer, *args: Any) -> None:
        await monitor.disconnect(*args)

    @server.feature(types.SHUTDOWN)
    def _shutdown(ls: BtServer, params: None) -> None:
        monitor.stop()
