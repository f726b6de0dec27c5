"""What each Debug Adapter request does to a running tree, through a Groot2 link.

One session is one debugger attached to one executor.  The tree is the only thread.  A
breakpoint on a line of a tree file is a PRE ``BREAKPOINT`` hook on the uid of each
running node that line's element stands for (:mod:`bt_lsp.dap.nodemap`); it is verified
once the executor lists the hook (HOOKS_DUMP).  The publisher's BREAKPOINT_REACHED
notification is a ``stopped`` event; ``continue`` unlocks the hook (the node ticks), the
custom requests ``btLsp/succeedNode`` and ``btLsp/failNode`` unlock it with a result (the
node returns it without ticking).

The executor may not be running yet, may stop, and may be restarted.  Until it answers,
breakpoints are pending (unverified, with a message); the session probes it, and when it
answers (again), reads its tree, matches the files again and inserts the hooks.  A new
executor run is the client's ``generation`` changing (the tree UUID changed, or the
connection closed since the last answer: BehaviorTree.CPP 4.8.2 keeps the same UUID from
run to run).  While attached, a STATUS request goes out every second: the executor
disables every hook after 5 s without a request.

Replies are untrusted: a malformed one is an ``output`` event, and the session goes on.
Disconnecting (or the editor going away) removes every hook, so the tree is never left
waiting at a breakpoint nobody will release.
"""

from __future__ import annotations

import contextlib
import logging
import os
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any, Final, Protocol

from bt_lsp.dap.messages import Args, Channel, InvalidArguments, Request, parse_request
from bt_lsp.dap.nodemap import NodeAt, SourceMap
from bt_lsp.dap.values import References, children
from bt_lsp.live.protocol import (
    DEFAULT_HOST,
    DEFAULT_PORT,
    ExecutorError,
    Hook,
    HookMode,
    LiveError,
    NodeState,
    Position,
    ProtocolError,
    Resume,
)
from bt_lsp.live.tree import LiveNode, LiveTree

log = logging.getLogger(__name__)

THREAD_ID: Final = 1
KEEPALIVE: Final = 1.0  # seconds between STATUS requests (the executor waits 5 s)
PROBE_EVERY: Final = 0.5  # seconds between attempts to reach an absent executor
# Seconds to wait for the subscriber to be connected to the publisher before hooks go in
# (a breakpoint hit before would stop the tree unseen), then for the subscription to land.
PUBLISHER_WAIT: Final = 3.0
SETTLE: Final = 0.05
MAX_SOURCES: Final = 500
MAX_BREAKPOINTS: Final = 1000  # per file
HOOKS_PER_REQUEST: Final = 500
MAX_TIMEOUT: Final = 60.0

SUCCEED: Final = "btLsp/succeedNode"
FAIL: Final = "btLsp/failNode"

CAPABILITIES: Final = {
    "supportsConfigurationDoneRequest": True,
    "supportsFunctionBreakpoints": False,
    "supportsConditionalBreakpoints": False,
    "supportsHitConditionalBreakpoints": False,
    "supportsLogPoints": False,
    "supportsEvaluateForHovers": False,
    "supportsSetVariable": False,
    "supportsStepBack": False,
    "supportsRestartRequest": False,
    "supportsTerminateRequest": False,
    "supportTerminateDebuggee": False,
    "supportsExceptionInfoRequest": False,
    "supportsDelayedStackTraceLoading": True,
    "exceptionBreakpointFilters": [],
}


class Link(Protocol):
    """What the session uses of :class:`bt_lsp.live.client.Groot2Client`."""

    generation: int

    def read_tree(self) -> LiveTree: ...
    def status(self) -> dict[int, NodeState]: ...
    def blackboards(self, names: Sequence[str]) -> dict[str, Any]: ...
    def insert_hooks(self, hooks: Hook | Sequence[Hook]) -> None: ...
    def remove_hook(self, uid: int, position: Position = Position.PRE) -> None: ...
    def hooks(self) -> list[Hook]: ...
    def remove_all_hooks(self) -> None: ...
    def unlock(
        self,
        uid: int,
        result: Resume = Resume.CONTINUE,
        *,
        position: Position = Position.PRE,
        remove: bool = False,
    ) -> None: ...
    def subscribe(self) -> None: ...
    def publisher_connected(self) -> bool: ...
    def poll_breakpoint(self, timeout: float) -> int | None: ...
    def close(self) -> None: ...


Connect = Callable[[str, int, float], Link]
# Reads a tree file's text; raises OSError (with a reason) when it cannot.
ReadSource = Callable[[str], str]


@dataclass(slots=True, eq=False)
class Breakpoint:
    """One requested breakpoint; ``line``/``column`` as requested (0-based)."""

    id: int
    line: int
    column: int | None
    node: NodeAt | None = None
    uids: tuple[int, ...] = ()
    state: tuple[bool, str | None] = (False, None)
    announced: bool = False


@dataclass(slots=True, eq=False)
class Source:
    """A file with breakpoints: its text when it was last read, and its map."""

    path: str
    text: str | None = None
    error: str | None = None
    map: SourceMap | None = None
    breakpoints: list[Breakpoint] = field(default_factory=list)


@dataclass(frozen=True, slots=True)
class _Board:
    """A scope: one blackboard, by name."""

    name: str


_ALL_BOARDS: Final = "all blackboards"


def _key(path: str) -> str:
    return os.path.normcase(os.path.abspath(path))


def _check_host(host: str) -> str:
    if not host or len(host) > 253 or any(c.isspace() or c in "/@?#" for c in host):
        raise InvalidArguments(f"'host' is not a host name or address: {host[:60]!r}")
    return host.strip("[]")


class Session:
    """The adapter's state and its answer to each request (see the module docstring).

    ``send`` writes one DAP message; ``connect`` makes a link to ``host:port`` with a
    request timeout; ``read_source`` reads a tree file's text (raising OSError)."""

    def __init__(
        self,
        send: Callable[[dict[str, Any]], None],
        connect: Connect,
        read_source: ReadSource,
        *,
        clock: Callable[[], float] = time.monotonic,
        sleep: Callable[[float], None] = time.sleep,
    ) -> None:
        self.out = Channel(send)
        self._connect = connect
        self._read_source = read_source
        self._clock = clock
        self._sleep = sleep
        self.done = False
        self._line_base = 1
        self._column_base = 1
        self._sources: dict[str, Source] = {}
        self._next_id = 1
        self._link: Link | None = None
        self._address = ""
        self._port = DEFAULT_PORT
        self._blind = False  # connected, but not to the publisher: no hooks go in
        self._connected = False
        self._said_waiting = False
        self._last_trouble: str | None = None
        self._generation: int | None = None
        self._next_probe = 0.0
        self._next_ping = 0.0
        self._tree: LiveTree | None = None
        self._parents: dict[int, int] = {}
        self._running: frozenset[str] = frozenset()  # the IDs of the trees that run
        self._board_of: dict[int, str] = {}
        self._inserted: set[int] = set()
        self._present: set[int] = set()
        self._stopped: int | None = None
        self._dump: dict[str, Any] | None = None
        self._refs = References()
        # Stack frame ids, new at each stop (see _frame_id), and the node of each.
        self._frame_ids: dict[int, int] = {}
        self._frame_uids: dict[int, int] = {}
        self._next_frame = 1
        self._handlers: dict[str, Callable[[Request], None]] = {
            "initialize": self._initialize,
            "attach": self._attach,
            "launch": self._launch,
            "setBreakpoints": self._set_breakpoints,
            "setExceptionBreakpoints": self._no_exception_breakpoints,
            "configurationDone": self._configuration_done,
            "threads": self._threads,
            "stackTrace": self._stack_trace,
            "scopes": self._scopes,
            "variables": self._variables,
            "continue": self._continue,
            SUCCEED: self._succeed,
            FAIL: self._fail,
            "disconnect": self._disconnect,
        }

    # ------------------------------------------------------------------ dispatch

    def handle(self, message: dict[str, Any]) -> None:
        """Answer one message from the client (never raises)."""
        parsed = parse_request(message)
        if not isinstance(parsed, Request):
            seq, command, why = parsed
            if seq is not None:
                self.out.fail(seq, command, why)
            elif message.get("type") != "response":  # we send no requests to answer
                self.out.output(f"bt-lsp: ignored {why}", "stderr")
            return
        handler = self._handlers.get(parsed.command)
        if handler is None:
            self.out.fail(
                parsed.seq, parsed.command, f"{parsed.command!r} is not supported by bt-lsp"
            )
            return
        try:
            handler(parsed)
        except InvalidArguments as e:
            self.out.fail(parsed.seq, parsed.command, str(e))
        except LiveError as e:
            self.out.fail(parsed.seq, parsed.command, f"the executor: {e}")
            self._trouble(e)
        except Exception as e:  # a defect here must not end the debugging session
            log.exception("%s failed", parsed.command)
            self.out.fail(parsed.seq, parsed.command, f"internal error: {type(e).__name__}: {e}")

    def frame_error(self, text: str) -> None:
        """A message the framing could not read (skipped)."""
        self.out.output(f"bt-lsp: skipped a message: {text}", "stderr")

    def _trouble(self, e: LiveError) -> None:
        """An executor error seen while answering or polling (a malformed answer is said
        once while it repeats)."""
        if isinstance(e, ProtocolError):
            text = f"bt-lsp: malformed answer from the executor: {e}"
            if text != self._last_trouble:
                self._last_trouble = text
                self.out.output(text, "stderr")
        elif not isinstance(e, ExecutorError):
            self._lost(e)

    # ------------------------------------------------------------------ the executor

    def poll(self, wait: float) -> bool:
        """Watch the executor for up to ``wait`` seconds: breakpoint notifications, the
        keepalive, a lost or restarted executor.  Returns whether it waited (when it did
        not, the caller waits for client messages instead)."""
        link = self._link
        if link is None or self.done:
            return False
        if not self._connected:
            if self._clock() < self._next_probe:
                return False
            self._probe(link)
            return False
        try:
            try:
                uid = link.poll_breakpoint(wait)
            except ProtocolError as e:
                self._trouble(e)
                uid = None
            if uid is not None:
                self._hit(uid)
            if self._clock() >= self._next_ping:
                link.status()
                self._next_ping = self._clock() + KEEPALIVE
            if link.generation != self._generation:
                self._reconnect(link)
            elif self._blind and self._await_publisher(0):
                self._sync()
        except LiveError as e:
            self._trouble(e)
        return True

    def _probe(self, link: Link) -> None:
        try:
            link.status()
        except LiveError as e:
            self._next_probe = self._clock() + PROBE_EVERY
            if isinstance(e, ProtocolError):
                self._trouble(e)
            elif not self._said_waiting:
                self._said_waiting = True
                self.out.output(f"bt-lsp: waiting for the executor at {self._address} ({e})")
            return
        self._reconnect(link)

    def _reconnect(self, link: Link) -> None:
        """(Re)attach now that the executor answers; on failure, try again later."""
        try:
            self._connected_now()
        except LiveError as e:
            if isinstance(e, ProtocolError):
                self._connected = False  # its tree cannot be read: not attached
            self._trouble(e)
            if not self._connected:
                self._next_probe = self._clock() + PROBE_EVERY
                self._announce()

    def _connected_now(self) -> None:
        """The executor answers: read its tree if this is a new run, and set the hooks."""
        link = self._link
        assert link is not None
        restarted = self._generation is not None and link.generation != self._generation
        if self._generation is None or restarted:
            tree = link.read_tree()
            self._generation = link.generation
            if self._stopped is not None:
                self._stopped = None
                self.out.event("continued", {"threadId": THREAD_ID, "allThreadsContinued": True})
            self._new_tree(tree)
            what = "a new executor run" if restarted else "the executor"
            self.out.output(
                f"bt-lsp: attached to {what} at {self._address}: tree {tree.tree_id}, "
                f"{len(tree.nodes)} nodes"
            )
            self._await_publisher(PUBLISHER_WAIT)
        self._connected = True
        self._said_waiting = False
        self._next_ping = self._clock() + KEEPALIVE
        for source in self._sources.values():
            self._reread(source)
        self._sync()

    def _await_publisher(self, wait: float) -> bool:
        """Wait up to ``wait`` seconds for the subscriber to be connected; says so when
        it is not (no hook goes in meanwhile, see _sync)."""
        link = self._link
        assert link is not None
        end = self._clock() + wait
        while not link.publisher_connected():
            if self._clock() >= end:
                if not self._blind:
                    self.out.output(
                        f"bt-lsp: no connection to the executor's publisher (port "
                        f"{self._port + 1}): breakpoints wait until there is one, since "
                        "a stop would go unseen",
                        "important",
                    )
                self._blind = True
                return False
            self._sleep(0.02)
        if self._blind:
            self._blind = False
        self._sleep(SETTLE)
        return True

    def _new_tree(self, tree: LiveTree) -> None:
        self._tree = tree
        self._running = frozenset(
            {tree.tree_id} | {n.subtree for n in tree.nodes.values() if n.subtree is not None}
        )
        self._inserted = set()
        self._present = set()
        self._dump = None
        self._refs.clear()
        self._forget_frames()
        self._parents = {}
        self._board_of = {}
        stack: list[tuple[LiveNode, str]] = [(tree.root, tree.tree_id)]
        while stack:
            node, board = stack.pop()
            self._board_of[node.uid] = board
            inner = node.path if node.subtree is not None else board
            for child in node.children:
                self._parents[child.uid] = node.uid
                stack.append((child, inner))

    def _lost(self, e: LiveError) -> None:
        if not self._connected:
            return
        self._connected = False
        self._next_probe = self._clock() + PROBE_EVERY
        self.out.output(
            f"bt-lsp: lost the executor at {self._address} ({e}); waiting for it", "important"
        )
        self._said_waiting = True
        if self._stopped is not None:
            self._stopped = None
            self.out.event("continued", {"threadId": THREAD_ID, "allThreadsContinued": True})
        self._announce()

    def _hit(self, uid: int) -> None:
        """A breakpoint notification: the tree waits before ticking node ``uid``."""
        tree = self._tree
        if uid not in self._inserted:
            # Not ours: another client's hook. A REPLACE hook notifies too, but does not
            # stop the tree.
            link = self._link
            assert link is not None
            if not any(
                h.uid == uid and h.mode is HookMode.BREAKPOINT and h.enabled for h in link.hooks()
            ):
                return
        self._stopped = uid
        self._dump = None
        self._refs.clear()
        self._forget_frames()
        hit = [
            bp.id
            for source in self._sources.values()
            for bp in source.breakpoints
            if uid in bp.uids
        ]
        node = tree.nodes.get(uid) if tree is not None else None
        label = node.label if node is not None else f"node #{uid}"
        body: dict[str, Any] = {
            "reason": "breakpoint",
            "threadId": THREAD_ID,
            "allThreadsStopped": True,
            "description": f"before {label} ticks",
            "hitBreakpointIds": hit,
        }
        if not hit:
            body["text"] = "a hook this debugger did not set"
        self.out.event("stopped", body)

    # ------------------------------------------------------------------ breakpoints

    def _reread(self, source: Source) -> None:
        """Read a file again (it may have changed since), find each breakpoint's node in
        it, and match it with the running tree."""
        try:
            text: str | None = self._read_source(source.path)
        except OSError as e:
            source.error = f"cannot read {source.path}: {e.strerror or e}"
            text = source.text
        else:
            source.error = None
        if text is None:
            source.map = None
        elif text != source.text or source.map is None:
            source.text = text
            source.map = SourceMap(text)
        smap = source.map
        if smap is not None:
            smap.match(self._tree if self._connected else None)
        for bp in source.breakpoints:
            bp.node = smap.node_at(bp.line, bp.column) if smap is not None else None
            bp.uids = smap.uids(bp.node.element) if smap is not None and bp.node else ()

    def _sync(self) -> None:
        """Insert the hooks the breakpoints want, remove those they no longer do, and
        read back which are in place."""
        link = self._link
        if link is None or not self._connected or self._blind:
            self._announce()
            return
        wanted = {uid for s in self._sources.values() for bp in s.breakpoints for uid in bp.uids}
        add = sorted(wanted - self._inserted)
        for i in range(0, len(add), HOOKS_PER_REQUEST):
            link.insert_hooks([Hook(uid) for uid in add[i : i + HOOKS_PER_REQUEST]])
            self._inserted.update(add[i : i + HOOKS_PER_REQUEST])
        # The hook the tree waits at stays until it is released (removing it would
        # release the tree behind the user's back).
        for uid in sorted(self._inserted - wanted - {self._stopped}):
            # Already gone is fine (another client removed it).
            with contextlib.suppress(ExecutorError):
                link.remove_hook(uid)
            self._inserted.discard(uid)
        self._present = {
            h.uid
            for h in link.hooks()
            if h.position is Position.PRE and h.mode is HookMode.BREAKPOINT
        }
        self._announce()

    def _state(self, source: Source, bp: Breakpoint) -> tuple[bool, str | None]:
        line = bp.line + self._line_base
        if source.error is not None and source.map is None:
            return False, source.error
        if bp.node is None:
            return False, f"no node's start tag is on line {line}"
        if self._link is None:
            return False, "pending: it is set when the debugger attaches to an executor"
        if not self._connected or self._tree is None or source.map is None:
            return False, f"pending: waiting for the executor at {self._address}"
        if self._blind:
            return False, (
                f"pending: waiting for a connection to the executor's publisher (port "
                f"{self._port + 1}), without which a stop would go unseen"
            )
        if not bp.uids:
            tree_id = source.map.tree_of(bp.node.element)
            if tree_id not in self._running:
                return False, (
                    f"tree {tree_id} is not part of the running tree ({self._tree.tree_id})"
                )
            return False, (
                f"{bp.node.label} is not in the running tree: the file differs from the "
                "tree the executor loaded here"
            )
        placed = [uid for uid in bp.uids if uid in self._present]
        if not placed:
            return False, "the executor did not accept the breakpoint"
        if len(placed) < len(bp.uids):
            return True, f"set on {len(placed)} of the {len(bp.uids)} nodes of this line"
        if len(bp.uids) > 1:
            return True, f"set on {len(bp.uids)} nodes (the tree is called more than once)"
        return True, None

    def _json(self, source: Source, bp: Breakpoint) -> dict[str, Any]:
        verified, message = bp.state
        line = bp.node.line if bp.node is not None else bp.line
        out: dict[str, Any] = {
            "id": bp.id,
            "verified": verified,
            "line": line + self._line_base,
            "source": {"path": source.path, "name": os.path.basename(source.path)},
        }
        if bp.node is not None:
            out["column"] = bp.node.column + self._column_base
        if message is not None:
            out["message"] = message
        return out

    def _announce(self, quiet: Source | None = None) -> None:
        """Work out every breakpoint's state; send a ``breakpoint`` event for each one
        already made known whose state changed (``quiet``'s are in a response)."""
        for source in self._sources.values():
            for bp in source.breakpoints:
                state = self._state(source, bp)
                if state == bp.state and bp.announced:
                    continue
                bp.state = state
                if source is not quiet and bp.announced:
                    self.out.event(
                        "breakpoint", {"reason": "changed", "breakpoint": self._json(source, bp)}
                    )

    # ------------------------------------------------------------------ requests

    def _initialize(self, request: Request) -> None:
        args = request.arguments
        self._line_base = 1 if args.flag("linesStartAt1", True) else 0
        self._column_base = 1 if args.flag("columnsStartAt1", True) else 0
        self.out.respond(request, dict(CAPABILITIES))
        self.out.event("initialized")

    def _launch(self, request: Request) -> None:
        raise InvalidArguments(
            "bt-lsp does not start programs: use an 'attach' configuration with the host "
            "and port of the executor's Groot2Publisher"
        )

    def _attach(self, request: Request) -> None:
        args = request.arguments
        if self._link is not None:
            raise InvalidArguments("already attached")
        host = _check_host(args.text("host", DEFAULT_HOST) or DEFAULT_HOST)
        port = args.integer("port", DEFAULT_PORT)
        timeout = args.number("timeout", 1.0)
        if port is None or not 1 <= port <= 65534:
            raise InvalidArguments(
                f"'port' must be in 1..65534 (the publisher uses port + 1), not {port}"
            )
        if timeout is None or not 0.05 <= timeout <= MAX_TIMEOUT:
            raise InvalidArguments(f"'timeout' must be 0.05 to {MAX_TIMEOUT:g} seconds")
        try:
            link = self._connect(host, port, timeout)
        except ImportError:
            raise InvalidArguments("attaching needs pyzmq: pip install 'bt-lsp[live]'") from None
        except ValueError as e:
            raise InvalidArguments(str(e)) from None
        shown = f"[{host}]" if ":" in host else host
        self._address = f"{shown}:{port}"
        self._port = port
        self._link = link
        link.subscribe()
        self._next_probe = self._clock()
        self.out.respond(request)
        self.out.output(
            f"bt-lsp: connecting to the Groot2 publisher at {self._address} "
            f"(ports {port} and {port + 1})"
        )
        self._announce()

    def _set_breakpoints(self, request: Request) -> None:
        args = request.arguments
        src = args.mapping("source")
        path = src.text("path") if src is not None else None
        wanted = args.array("breakpoints")
        if wanted is None:
            lines = args.array("lines") or []
            wanted = [{"line": n} for n in lines]
        if not path:
            raise InvalidArguments("a breakpoint needs a source with a path (a tree file)")
        key = _key(path)
        if key not in self._sources and len(self._sources) >= MAX_SOURCES:
            raise InvalidArguments(f"breakpoints in more than {MAX_SOURCES} files")
        source = self._sources.get(key) or Source(path)
        source.path = path
        source.breakpoints = []
        for item in wanted[:MAX_BREAKPOINTS]:
            bp_args = Args(item) if isinstance(item, dict) else Args({})
            line = bp_args.integer("line")
            column = bp_args.integer("column")
            if line is None:
                raise InvalidArguments("each breakpoint needs an integer 'line'")
            bp = Breakpoint(
                self._next_id,
                line - self._line_base,
                None if column is None else column - self._column_base,
            )
            self._next_id += 1
            source.breakpoints.append(bp)
        self._sources[key] = source
        self._reread(source)
        if self._connected:
            try:
                self._sync()
            except LiveError as e:
                self._trouble(e)
        self._announce(quiet=source)
        out = [self._json(source, bp) for bp in source.breakpoints]
        for _ in wanted[MAX_BREAKPOINTS:]:
            out.append({"verified": False, "message": f"over {MAX_BREAKPOINTS} in one file"})
        self.out.respond(request, {"breakpoints": out})
        for bp in source.breakpoints:
            bp.announced = True

    def _no_exception_breakpoints(self, request: Request) -> None:
        self.out.respond(request, {"breakpoints": []})

    def _configuration_done(self, request: Request) -> None:
        self.out.respond(request)

    def _threads(self, request: Request) -> None:
        name = f"tree {self._tree.tree_id}" if self._tree is not None else "tree"
        self.out.respond(request, {"threads": [{"id": THREAD_ID, "name": name}]})

    def _forget_frames(self) -> None:
        self._frame_ids.clear()
        self._frame_uids.clear()

    def _frame_id(self, uid: int) -> int:
        """The id of node ``uid``'s frame in this stop.  Ids are never reused in a session:
        VS Code keeps the frames below the top one from the previous stop on screen while it
        fetches them again, and when they compare equal (same ids, names and lines) it does
        not redraw, leaving its "Load More Stack Frames" row under them."""
        found = self._frame_ids.get(uid)
        if found is None:
            found = self._frame_ids[uid] = self._next_frame
            self._frame_uids[found] = uid
            self._next_frame += 1
        return found

    def _frame(self, uid: int) -> dict[str, Any]:
        tree = self._tree
        node = tree.nodes.get(uid) if tree is not None else None
        name = f"{node.label} #{uid}" if node is not None else f"node #{uid}"
        frame: dict[str, Any] = {"id": self._frame_id(uid), "name": name, "line": 0, "column": 0}
        for source in self._sources.values():
            place = source.map.place(uid) if source.map is not None else None
            if place is not None:
                frame["source"] = {"path": source.path, "name": os.path.basename(source.path)}
                frame["line"] = place[0] + self._line_base
                frame["column"] = place[1] + self._column_base
                return frame
        frame["presentationHint"] = "subtle"
        return frame

    def _stack_trace(self, request: Request) -> None:
        uid = self._stopped
        if uid is None:
            self.out.respond(request, {"stackFrames": [], "totalFrames": 0})
            return
        chain = [uid]
        while chain[-1] in self._parents and len(chain) <= len(self._parents):
            chain.append(self._parents[chain[-1]])
        start = max(0, request.arguments.integer("startFrame", 0) or 0)
        levels = request.arguments.integer("levels", 0) or 0
        shown = chain[start : start + levels] if levels > 0 else chain[start:]
        self.out.respond(
            request,
            {"stackFrames": [self._frame(u) for u in shown], "totalFrames": len(chain)},
        )

    def _scopes(self, request: Request) -> None:
        frame = request.arguments.integer("frameId")
        if frame is None:
            raise InvalidArguments("'frameId' is required")
        uid = self._frame_uids.get(frame)
        board = self._board_of.get(uid) if uid is not None else None
        scopes = []
        if board is not None:
            scopes.append(
                {
                    "name": f"Blackboard {board}",
                    "presentationHint": "locals",
                    "variablesReference": self._refs.add(_Board(board)),
                    "expensive": False,
                }
            )
        scopes.append(
            {
                "name": "All blackboards",
                "variablesReference": self._refs.add(_ALL_BOARDS),
                "expensive": False,
            }
        )
        self.out.respond(request, {"scopes": scopes})

    def _blackboards(self) -> dict[str, Any]:
        """The blackboards' entries: read once per stop (the tree is still meanwhile)."""
        if self._dump is not None:
            return self._dump
        if self._link is None or self._tree is None or not self._connected:
            raise InvalidArguments("not connected to an executor")
        # A blackboard without entries of its own (a SubTree's with _autoremap) is nil.
        dump = {
            name: {} if entries is None else entries
            for name, entries in self._link.blackboards(self._tree.blackboards).items()
        }
        if self._stopped is not None:
            self._dump = dump
        return dump

    def _variables(self, request: Request) -> None:
        args = request.arguments
        ref = args.integer("variablesReference")
        if ref is None:
            raise InvalidArguments("'variablesReference' is required")
        item = self._refs.get(ref)
        start = args.integer("start", 0) or 0
        count = args.integer("count", 0) or 0
        if item is None:
            raise InvalidArguments("that variable is gone (the tree went on since)")
        if isinstance(item, _Board):
            entries = self._blackboards().get(item.name)
            variables = children(entries if isinstance(entries, dict) else {}, self._refs)
        elif item == _ALL_BOARDS:
            variables = children(self._blackboards(), self._refs)
        else:
            variables = children(item, self._refs, start, count)
        self.out.respond(request, {"variables": variables})

    def _release(self, result: Resume) -> LiveNode | None:
        """Unlock the breakpoint the tree waits at; the node it was at."""
        uid = self._stopped
        link = self._link
        if uid is None or link is None:
            raise InvalidArguments("the tree is not stopped at a breakpoint")
        wanted = any(uid in bp.uids for s in self._sources.values() for bp in s.breakpoints)
        remove = uid in self._inserted and not wanted
        link.unlock(uid, result, remove=remove)
        if remove:
            self._inserted.discard(uid)
        self._stopped = None
        self._dump = None
        self._refs.clear()
        self._forget_frames()
        return self._tree.nodes.get(uid) if self._tree is not None else None

    def _continue(self, request: Request) -> None:
        if self._stopped is not None:
            self._release(Resume.CONTINUE)
        self.out.respond(request, {"allThreadsContinued": True})

    def _force(self, request: Request, result: Resume) -> None:
        node = self._release(result)
        label = node.label if node is not None else "the node"
        self.out.respond(request, {"allThreadsContinued": True, "status": result.value})
        self.out.output(f"bt-lsp: {label} returns {result.value} without ticking")
        self.out.event("continued", {"threadId": THREAD_ID, "allThreadsContinued": True})

    def _succeed(self, request: Request) -> None:
        self._force(request, Resume.SUCCESS)

    def _fail(self, request: Request) -> None:
        self._force(request, Resume.FAILURE)

    def _disconnect(self, request: Request) -> None:
        self.shutdown()
        self.out.respond(request)

    def shutdown(self) -> None:
        """Remove every hook (releasing a waiting tree) and close the link; idempotent."""
        link = self._link
        self.done = True
        if link is None:
            return
        self._link = None
        try:
            if self._generation is not None:
                try:
                    link.remove_all_hooks()
                except LiveError as e:
                    if isinstance(e, ProtocolError):
                        raise
                    # Once more: a request cut short (by a signal) left the socket reset.
                    link.remove_all_hooks()
                left = link.hooks()
                if left:
                    self.out.output(
                        f"bt-lsp: {len(left)} hooks are still in the executor", "important"
                    )
                else:
                    self.out.output("bt-lsp: removed every hook; the tree runs on")
        except LiveError as e:
            self.out.output(
                f"bt-lsp: could not remove the hooks from {self._address}: {e}", "important"
            )
        finally:
            link.close()
