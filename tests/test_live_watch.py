"""The live watcher's thread (``bt_lsp.live.watch``) against a scripted link: what it
reports when statuses change, when the executor is lost, restarted or answers garbage,
how it answers blackboard queries, and that it always ends and closes its link."""

from __future__ import annotations

import threading
import time
from collections.abc import Callable, Sequence
from typing import Any

import pytest

from bt_lsp.live.protocol import (
    ExecutorError,
    LiveError,
    NodeState,
    NodeStatus,
    ProtocolError,
    Transition,
)
from bt_lsp.live.tree import LiveTree, parse_tree_xml
from bt_lsp.live.watch import Update, Watcher, clamp_rate

XML = (
    '<root><BehaviorTree ID="Main" _fullpath=""><Sequence _uid="1">'
    '<AlwaysSuccess name="a" _uid="2"/></Sequence></BehaviorTree></root>'
)
OTHER = XML.replace('name="a"', 'name="b"')
RUNNING = {1: NodeState(NodeStatus.RUNNING), 2: NodeState(NodeStatus.RUNNING)}
DONE = {1: NodeState(NodeStatus.SUCCESS), 2: NodeState(NodeStatus.IDLE, NodeStatus.SUCCESS)}
WAIT = 5.0


class FakeLink:
    """A link whose answers the test changes while the watcher runs: ``down`` makes every
    request fail as a lost connection, ``bad`` every STATUS a malformed reply."""

    def __init__(self, xml: str = XML) -> None:
        self.xml = xml
        self.generation = 0
        self.timeout = 1.0
        self.states: dict[int, NodeState] = dict(RUNNING)
        self.pending: list[Transition] = []
        self.down = False
        self.bad: LiveError | None = None
        self.closed = False
        self.stopped_recording = False
        self.threads: set[threading.Thread] = set()
        self.boards: dict[str, Any] = {"Main": {"goal": 3}}

    def _ask(self) -> None:
        self.threads.add(threading.current_thread())
        if self.down:
            raise LiveError("the executor closed the connection")

    def read_tree(self) -> LiveTree:
        self._ask()
        return parse_tree_xml(self.xml)

    def status(self) -> dict[int, NodeState]:
        self._ask()
        if self.bad is not None:
            raise self.bad
        return dict(self.states)

    def blackboards(self, names: Sequence[str]) -> dict[str, Any]:
        self._ask()
        return {n: self.boards.get(n) for n in names}

    def start_recording(self) -> int:
        self._ask()
        return 1_000_000

    def stop_recording(self) -> None:
        self.stopped_recording = True

    def transitions(self) -> list[Transition]:
        self._ask()
        out, self.pending = self.pending, []
        return out

    def close(self) -> None:
        self.closed = True


class Seen:
    """The updates reported, with a bounded wait for one that passes a check."""

    def __init__(self) -> None:
        self.updates: list[Update] = []
        self.cond = threading.Condition()

    def __call__(self, update: Update) -> None:
        with self.cond:
            self.updates.append(update)
            self.cond.notify_all()

    def wait(self, check: Callable[[Update], bool], what: str) -> Update:
        end = time.monotonic() + WAIT
        with self.cond:
            while True:
                for u in self.updates:
                    if check(u):
                        return u
                left = end - time.monotonic()
                if left <= 0:
                    raise AssertionError(f"no update {what}: {self.updates}")
                self.cond.wait(left)


def _watch(link: FakeLink, seen: Seen) -> Watcher:
    return Watcher("127.0.0.1", 1667, 30, seen, connect=lambda h, p, t: link, retry_every=0.05)


def test_statuses_and_transitions_are_reported_from_the_watchers_thread_only() -> None:
    link, seen = FakeLink(), Seen()
    watcher = _watch(link, seen)
    first = watcher.start().result(WAIT)
    try:
        assert first.tree.tree_id == "Main" and first.states == RUNNING
        link.pending = [Transition(5, 2, NodeStatus.SUCCESS)]
        link.states = dict(DONE)
        update = seen.wait(lambda u: u.states == DONE, "with the new statuses")
        assert update.connected and update.tree is None
        change = next(c for u in seen.updates for c in u.changes)
        assert (change.uid, change.time_us) == (2, 1_000_005)
        assert (change.before, change.after) == (NodeStatus.RUNNING, NodeStatus.SUCCESS)
    finally:
        assert watcher.stop()
    assert link.threads == {watcher._thread}  # every request on the one thread
    assert link.closed and link.stopped_recording and not watcher.alive


def test_a_lost_executor_is_retried_and_a_restarted_one_read_again() -> None:
    link, seen = FakeLink(), Seen()
    watcher = _watch(link, seen)
    watcher.start().result(WAIT)
    try:
        link.down = True
        lost = seen.wait(lambda u: not u.connected, "of the loss")
        assert "connection lost" in (lost.message or "") and "retrying" in (lost.message or "")
        link.xml, link.generation, link.down = OTHER, 1, False
        back = seen.wait(lambda u: u.restarted, "of the restart")
        assert back.connected and back.tree is not None and back.tree.xml == OTHER
        assert "restarted (new tree); re-mapped" in (back.message or "")
        answer = watcher.blackboards(["Main"]).result(WAIT)
        assert answer == {"Main": {"goal": 3}}
    finally:
        watcher.stop()
    assert not watcher.alive and link.closed


@pytest.mark.parametrize(
    "error, words",
    [
        (ProtocolError("a status buffer is a multiple of 3 bytes, not 2"), "malformed reply"),
        (ExecutorError("busy"), "answered an error"),
    ],
)
def test_a_bad_reply_is_said_once_and_the_watcher_goes_on(error: LiveError, words: str) -> None:
    link, seen = FakeLink(), Seen()
    watcher = _watch(link, seen)
    watcher.start().result(WAIT)
    try:
        link.bad = error
        bad = seen.wait(lambda u: words in (u.message or ""), "of the bad reply")
        assert bad.connected and "127.0.0.1:1667" in (bad.message or "")
        time.sleep(0.3)  # about ten polls, all answered the same way
        assert sum(words in (u.message or "") for u in seen.updates) == 1
        link.bad = None
        link.states = dict(DONE)
        ok = seen.wait(lambda u: u.states == DONE, "once the replies are good again")
        assert ok.message == "connected to 127.0.0.1:1667"
    finally:
        watcher.stop()


def test_nothing_answering_ends_the_thread_with_the_error() -> None:
    link, seen = FakeLink(), Seen()
    link.down = True
    watcher = _watch(link, seen)
    with pytest.raises(LiveError, match="closed the connection"):
        watcher.start().result(WAIT)
    watcher.stop()
    assert not watcher.alive and link.closed and seen.updates == []
    with pytest.raises(LiveError, match="stopped"):
        watcher.blackboards(["Main"]).result(WAIT)


def test_a_query_while_lost_fails_at_once_and_rates_are_clamped() -> None:
    link, seen = FakeLink(), Seen()
    watcher = _watch(link, seen)
    watcher.start().result(WAIT)
    try:
        link.down = True
        seen.wait(lambda u: not u.connected, "of the loss")
        with pytest.raises(LiveError, match="not connected"):
            watcher.blackboards(["Main"]).result(WAIT)
    finally:
        watcher.stop()
    assert (clamp_rate(0), clamp_rate(10), clamp_rate(1e9)) == (1.0, 10.0, 30.0)
