"""Watching a running tree from a thread of its own, for an editor's live view.

A :class:`Watcher` owns one :class:`~bt_lsp.live.client.Groot2Client`, made and used only
on its thread (ZeroMQ sockets are not thread-safe).  It reads the tree (FULLTREE), starts
the executor's recording, then polls STATUS and GET_TRANSITIONS at a fixed rate and
reports what changed through a callback (called on its thread: the caller hands it to
its own loop).  Between polls it answers BLACKBOARD queries put to it from other threads
(:meth:`Watcher.blackboards`), which the caller waits for with a timeout.

The executor may stop and come back: a request that times out or a closed connection is
reported as lost, and the watcher asks again each second; once it answers, the tree is
read again (BehaviorTree.CPP 4.8.2 keeps the same tree UUID from run to run, so every
reconnection is a new run: :attr:`Groot2Client.generation`).  Replies are untrusted: a
malformed one is reported in the update's message, and the watcher goes on.
"""

from __future__ import annotations

import contextlib
import queue
import threading
import time
from collections.abc import Callable, Mapping, Sequence
from concurrent.futures import Future
from dataclasses import dataclass, field
from typing import Any, Final, Protocol

from bt_lsp.live.protocol import (
    ExecutorError,
    LiveError,
    NodeState,
    NodeStatus,
    ProtocolError,
)
from bt_lsp.live.tree import LiveTree

MIN_RATE: Final = 1.0
MAX_RATE: Final = 30.0
RETRY_EVERY: Final = 1.0  # seconds between attempts to reach a lost executor
CONNECT_TIMEOUT: Final = 3.0  # seconds the first FULLTREE may take
POLL_TIMEOUT: Final = 1.0  # seconds each later request may take
STOP_TIMEOUT: Final = 0.3  # seconds the last request (stop recording) may take
MAX_MESSAGE: Final = 300  # characters of an executor's text quoted in a message


class Link(Protocol):
    """What the watcher uses of :class:`bt_lsp.live.client.Groot2Client`."""

    generation: int
    timeout: float

    def read_tree(self) -> LiveTree: ...
    def status(self) -> dict[int, NodeState]: ...
    def blackboards(self, names: Sequence[str]) -> dict[str, Any]: ...
    def start_recording(self) -> int: ...
    def stop_recording(self) -> None: ...
    def transitions(self) -> list[Any]: ...
    def close(self) -> None: ...


Connect = Callable[[str, int, float], Link]


def groot2_link(host: str, port: int, timeout: float) -> Link:
    """A Groot2 client (pyzmq imported only now: the ``live`` extra)."""
    from bt_lsp.live.client import Groot2Client

    return Groot2Client(host, port, timeout=timeout)


def clamp_rate(rate: float) -> float:
    return min(MAX_RATE, max(MIN_RATE, rate))


@dataclass(frozen=True, slots=True)
class Change:
    """One status change of a node: when (microseconds since the epoch, the executor's
    clock), from what, to what."""

    uid: int
    time_us: int
    before: NodeStatus | None
    after: NodeStatus


@dataclass(frozen=True, slots=True)
class Update:
    """What the watcher saw, reported from its thread.

    ``tree`` is set when the tree was (re)read (a new mapping is due; ``restarted`` when
    it is not the first); ``states`` when the statuses were read; ``message`` says what
    happened in words (a connection, a loss, a malformed reply)."""

    connected: bool
    message: str | None = None
    tree: LiveTree | None = None
    restarted: bool = False
    states: Mapping[int, NodeState] | None = None
    changes: tuple[Change, ...] = ()


@dataclass(frozen=True, slots=True)
class First:
    """The first reading: the tree and its statuses (the connection is made)."""

    tree: LiveTree
    states: Mapping[int, NodeState] = field(default_factory=dict)
    message: str | None = None


_STOP: Final = object()


def _short(error: BaseException) -> str:
    text = str(error) or type(error).__name__
    return text if len(text) <= MAX_MESSAGE else text[: MAX_MESSAGE - 1] + "…"


class Watcher:
    """One executor at ``host:port``, watched at ``rate`` polls a second; ``report`` is
    called on the watcher's thread with each :class:`Update`."""

    def __init__(
        self,
        host: str,
        port: int,
        rate: float,
        report: Callable[[Update], None],
        *,
        connect: Connect = groot2_link,
        connect_timeout: float = CONNECT_TIMEOUT,
        poll_timeout: float = POLL_TIMEOUT,
        retry_every: float = RETRY_EVERY,
    ) -> None:
        self.host = host
        self.port = port
        self.interval = 1.0 / clamp_rate(rate)
        self._report = report
        self._connect = connect
        self._connect_timeout = connect_timeout
        self._poll_timeout = poll_timeout
        self._retry_every = retry_every
        self._stop = threading.Event()
        self._queries: queue.SimpleQueue[Any] = queue.SimpleQueue()
        self._first: Future[First] = Future()
        self._thread: threading.Thread | None = None
        # Only the watcher's thread touches these.
        self._connected = False
        self._generation = -1
        self._recording_us: int | None = None
        self._last: dict[int, NodeStatus] = {}
        self._states: dict[int, NodeState] | None = None
        self._xml = ""
        self._trouble: str | None = None

    @property
    def address(self) -> str:
        return f"[{self.host}]:{self.port}" if ":" in self.host else f"{self.host}:{self.port}"

    # ------------------------------------------------------------------ other threads

    def start(self) -> Future[First]:
        """Start the thread; the future is its first reading, or the error that ended it."""
        if self._thread is None:
            self._thread = threading.Thread(
                target=self._run, name=f"bt-lsp-live {self.address}", daemon=True
            )
            self._thread.start()
        return self._first

    def stop(self, wait: float = 2.0) -> bool:
        """Stop the thread and wait for it (at most ``wait`` seconds); whether it ended."""
        self._stop.set()
        self._queries.put(_STOP)
        thread = self._thread
        if thread is None or thread is threading.current_thread():
            return True
        thread.join(wait)
        return not thread.is_alive()

    @property
    def alive(self) -> bool:
        return self._thread is not None and self._thread.is_alive()

    def blackboards(self, names: Sequence[str]) -> Future[dict[str, Any]]:
        """BLACKBOARD of ``names``, asked on the watcher's thread between two polls (an
        error in the future when the executor is not connected or the reply is bad)."""
        answer: Future[dict[str, Any]] = Future()
        if self._stop.is_set():
            answer.set_exception(LiveError("the live session is stopped"))
        else:
            self._queries.put((tuple(names), answer))
        return answer

    # ------------------------------------------------------------------ the thread

    def _run(self) -> None:
        link: Link | None = None
        try:
            link = self._connect(self.host, self.port, self._connect_timeout)
            first = self._attach(link)
        except Exception as e:  # nothing listening, a malformed tree, a bad address
            if not self._first.done():
                self._first.set_exception(e if isinstance(e, LiveError) else LiveError(_short(e)))
            if link is not None:
                link.close()
            self._fail_queries()
            return
        self._first.set_result(first)
        try:
            link.timeout = self._poll_timeout
            self._loop(link)
        except Exception as e:  # a defect: say so, and end cleanly
            self._send(Update(False, f"the live session stopped: {_short(e)}"))
        finally:
            if self._connected:
                link.timeout = STOP_TIMEOUT
                with contextlib.suppress(Exception):
                    link.stop_recording()
            link.close()
            self._fail_queries()

    def _send(self, update: Update) -> None:
        if not self._stop.is_set():
            self._report(update)

    def _fail_queries(self) -> None:
        while True:
            try:
                item = self._queries.get_nowait()
            except queue.Empty:
                return
            if item is not _STOP and item[1].set_running_or_notify_cancel():
                item[1].set_exception(LiveError("the live session is stopped"))

    def _attach(self, link: Link) -> First:
        """Read the tree, start recording and read the statuses (raises LiveError)."""
        tree = link.read_tree()
        self._generation = link.generation
        self._xml = tree.xml
        note = None
        try:
            self._recording_us = link.start_recording()
        except (ExecutorError, ProtocolError) as e:
            self._recording_us = None
            note = f"no transitions: the executor refused to record ({_short(e)})"
        trouble = None
        try:
            states = link.status()
        except (ExecutorError, ProtocolError) as e:  # the tree is known: go on, and say so
            states = {}
            trouble = self._trouble_text(e)
            note = f"{note}; {trouble}" if note else trouble
        self._last = {uid: s.status for uid, s in states.items()}
        self._states = states
        self._connected = True
        self._trouble = trouble
        return First(tree, states, note)

    def _loop(self, link: Link) -> None:
        next_tick = time.monotonic() + self.interval
        while not self._stop.is_set():
            wait = next_tick - time.monotonic()
            if wait > 0:
                try:
                    item = self._queries.get(timeout=wait)
                except queue.Empty:
                    item = None
                if item is _STOP or self._stop.is_set():
                    return
                if item is not None:
                    self._answer(link, *item)
                    continue
            if self._connected:
                self._poll(link)
                next_tick = time.monotonic() + self.interval
            else:
                self._retry(link)
                next_tick = time.monotonic() + (
                    self.interval if self._connected else self._retry_every
                )

    def _answer(self, link: Link, names: Sequence[str], answer: Future[dict[str, Any]]) -> None:
        if not answer.set_running_or_notify_cancel():  # the hover gave up
            return
        if not self._connected:
            answer.set_exception(LiveError(f"the executor at {self.address} is not connected"))
            return
        try:
            answer.set_result(link.blackboards(names))
        except LiveError as e:
            answer.set_exception(e)
            self._failed(link, e)

    def _poll(self, link: Link) -> None:
        try:
            states = link.status()
            if link.generation != self._generation:
                self._reattach(link)
                return
            changes = self._transitions(link)
        except LiveError as e:
            self._failed(link, e)
            return
        message = None
        if self._trouble is not None:  # the malformed replies stopped
            self._trouble = None
            message = f"connected to {self.address}"
        if states != self._states or changes or message is not None:
            self._states = states
            self._send(Update(True, message, states=states, changes=changes))

    def _transitions(self, link: Link) -> tuple[Change, ...]:
        start = self._recording_us
        if start is None:
            return ()
        out = []
        for t in link.transitions():
            out.append(Change(t.uid, start + t.offset_us, self._last.get(t.uid), t.status))
            self._last[t.uid] = t.status
        return tuple(out)

    def _failed(self, link: Link, error: LiveError) -> None:
        """A request failed: the executor is lost (no answer, connection closed), or its
        reply is malformed or an error (said once, the session goes on)."""
        if isinstance(error, ProtocolError | ExecutorError):
            text = self._trouble_text(error)
            if text != self._trouble:
                self._trouble = text
                self._send(Update(self._connected, text))
            return
        self._connected = False
        self._states = None
        self._send(Update(False, f"connection lost: {_short(error)}; retrying"))

    def _trouble_text(self, error: LiveError) -> str:
        if isinstance(error, ExecutorError):
            return f"the executor at {self.address} answered an error: {_short(error)}"
        return f"malformed reply from {self.address}: {_short(error)}"

    def _retry(self, link: Link) -> None:
        try:
            link.status()
        except ProtocolError as e:
            self._failed(link, e)
            return
        except LiveError:
            return
        self._reattach(link)

    def _reattach(self, link: Link) -> None:
        """The executor answers again (or another run answers): read its tree again."""
        before = self._xml
        try:
            first = self._attach(link)
        except LiveError as e:
            self._connected = False
            if isinstance(e, ProtocolError | ExecutorError):
                self._failed(link, e)
            return
        what = "same tree" if first.tree.xml == before else "new tree"
        message = f"the executor at {self.address} restarted ({what}); re-mapped"
        if first.message:
            message += f"; {first.message}"
        self._send(Update(True, message, tree=first.tree, restarted=True, states=first.states))
