"""The debug adapter's session against a fake executor link: what each request answers,
pending breakpoints, stops, a lost or restarted executor, malformed answers, and the
hooks removed at the end.  (tests/test_dap_executor.py does the same against a real
BehaviorTree.CPP executor.)"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import pytest

from bt_lsp.dap.session import FAIL, SUCCEED, Session
from bt_lsp.live.client import ConnectionLost, Timeout
from bt_lsp.live.protocol import (
    ExecutorError,
    Hook,
    HookMode,
    NodeState,
    NodeStatus,
    Position,
    ProtocolError,
    Resume,
)
from bt_lsp.live.tree import LiveTree, parse_tree_xml
from tests.test_dap_nodemap import FULLTREE, TEXT

# Lines (1-based, as a client sends them) of TEXT's elements.
SEQ, SCRIPT, SUB1, WORK, SLEEP, OTHER = 3, 4, 5, 7, 14, 17
UID = {"seq": 1, "script": 2, "sub1": 3, "sleep1": 4, "sleep2": 6, "work": 7, "ok": 8}


class FakeLink:
    """An executor as the session sees it: up or down, hooks, notifications to deliver."""

    def __init__(self, xml: str = FULLTREE) -> None:
        self.tree: LiveTree = parse_tree_xml(xml)
        self.up = False
        self.publisher = True
        self.generation = 0
        self.installed: dict[int, Hook] = {}
        self.notes: list[int | Exception] = []
        self.unlocks: list[tuple[int, Resume, bool]] = []
        self.boards: dict[str, Any] = {"Main": {"counter": 3, "pose": {"x": 1}}, "sub1": None}
        self.fail_next: dict[str, Exception] = {}
        self.broken_tree = False
        self.closed = False
        self.requests: list[str] = []

    def _call(self, name: str) -> None:
        self.requests.append(name)
        if name in self.fail_next:
            raise self.fail_next.pop(name)
        if not self.up:
            raise Timeout("no answer from tcp://127.0.0.1:1667 within 1 s")
        if self.generation == 0:
            self.generation = 1

    def restart(self) -> None:
        self.installed.clear()
        self.generation += 1

    def read_tree(self) -> LiveTree:
        self._call("read_tree")
        if self.broken_tree:
            raise ProtocolError("two nodes have _uid 3")
        return self.tree

    def status(self) -> dict[int, NodeState]:
        self._call("status")
        return {uid: NodeState(NodeStatus.IDLE) for uid in self.tree.nodes}

    def blackboards(self, names: Sequence[str]) -> dict[str, Any]:
        self._call("blackboards")
        return {n: self.boards[n] for n in names if n in self.boards}

    def insert_hooks(self, hooks: Hook | Sequence[Hook]) -> None:
        self._call("insert_hooks")
        for hook in [hooks] if isinstance(hooks, Hook) else hooks:
            if hook.uid in self.tree.nodes:
                self.installed[hook.uid] = hook

    def remove_hook(self, uid: int, position: Position = Position.PRE) -> None:
        self._call("remove_hook")
        if self.installed.pop(uid, None) is None:
            raise ExecutorError("Node ID not found")

    def hooks(self) -> list[Hook]:
        self._call("hooks")
        return list(self.installed.values())

    def remove_all_hooks(self) -> None:
        self._call("remove_all_hooks")
        self.installed.clear()

    def unlock(
        self,
        uid: int,
        result: Resume = Resume.CONTINUE,
        *,
        position: Position = Position.PRE,
        remove: bool = False,
    ) -> None:
        self._call("unlock")
        self.unlocks.append((uid, result, remove))
        if remove:
            self.installed.pop(uid, None)

    def subscribe(self) -> None:
        pass

    def publisher_connected(self) -> bool:
        return self.up and self.publisher

    def poll_breakpoint(self, timeout: float) -> int | None:
        if not self.notes:
            return None
        note = self.notes.pop(0)
        if isinstance(note, Exception):
            raise note
        return note

    def close(self) -> None:
        self.closed = True


class Clock:
    def __init__(self) -> None:
        self.now = 100.0

    def __call__(self) -> float:
        return self.now

    def sleep(self, seconds: float) -> None:
        self.now += seconds


class Harness:
    def __init__(self, tmp_path: Path, link: FakeLink | None = None) -> None:
        self.link = link or FakeLink()
        self.path = tmp_path / "tree.xml"
        self.path.write_text(TEXT, encoding="utf-8")
        self.sent: list[dict[str, Any]] = []
        self.clock = Clock()
        self.connects: list[tuple[str, int, float]] = []
        self.seq = 0

        def connect(host: str, port: int, timeout: float) -> FakeLink:
            self.connects.append((host, port, timeout))
            return self.link

        def read(path: str) -> str:
            return Path(path).read_text(encoding="utf-8")

        self.session = Session(
            self.sent.append, connect, read, clock=self.clock, sleep=self.clock.sleep
        )

    def request(self, command: str, **arguments: Any) -> dict[str, Any]:
        self.seq += 1
        self.session.handle(
            {"seq": self.seq, "type": "request", "command": command, "arguments": arguments}
        )
        replies = [m for m in self.sent if m.get("request_seq") == self.seq]
        assert len(replies) == 1, self.sent[-5:]
        return replies[0]

    def ok(self, command: str, **arguments: Any) -> dict[str, Any]:
        reply = self.request(command, **arguments)
        assert reply["success"], reply
        body: dict[str, Any] = reply.get("body", {})
        return body

    def events(self, name: str) -> list[dict[str, Any]]:
        return [m["body"] for m in self.sent if m.get("event") == name]

    def output(self) -> str:
        return "".join(b["output"] for b in self.events("output"))

    def tick(self, n: int = 1, step: float = 0.6) -> None:
        for _ in range(n):
            self.session.poll(0.0)
            self.clock.now += step

    def breakpoints(self, *lines: int | tuple[int, int]) -> list[dict[str, Any]]:
        items = [
            {"line": n} if isinstance(n, int) else {"line": n[0], "column": n[1]} for n in lines
        ]
        body = self.ok("setBreakpoints", source={"path": str(self.path)}, breakpoints=items)
        bps: list[dict[str, Any]] = body["breakpoints"]
        return bps

    def attached(self) -> None:
        self.ok("initialize", adapterID="bt")
        self.ok("attach", port=1667)
        self.link.up = True
        self.tick()


@pytest.fixture
def h(tmp_path: Path) -> Harness:
    return Harness(tmp_path)


def test_initialize_answers_capabilities_then_initialized(h: Harness) -> None:
    body = h.ok("initialize", adapterID="bt", linesStartAt1=True)
    assert body["supportsConfigurationDoneRequest"] is True
    assert body["supportsConditionalBreakpoints"] is False
    assert [m.get("command") or m.get("event") for m in h.sent] == ["initialize", "initialized"]


def test_breakpoints_pending_until_the_executor_answers(h: Harness) -> None:
    h.ok("initialize")
    (bp,) = h.breakpoints(WORK)
    assert bp["verified"] is False and "when the debugger attaches" in bp["message"]
    assert (bp["line"], bp["column"]) == (WORK, 7)
    h.ok("attach", host="127.0.0.1", port=1667)
    assert h.connects == [("127.0.0.1", 1667, 1.0)]
    changed = h.events("breakpoint")[-1]["breakpoint"]
    assert (
        changed["id"] == bp["id"]
        and "waiting for the executor at 127.0.0.1:1667" in (changed["message"])
    )
    h.tick(3)
    assert "waiting for the executor" in h.output()
    assert h.link.installed == {}
    h.link.up = True
    h.tick()
    assert set(h.link.installed) == {UID["work"]}
    assert h.link.installed[UID["work"]] == Hook(UID["work"])
    changed = h.events("breakpoint")[-1]["breakpoint"]
    assert changed["verified"] is True and "message" not in changed
    assert changed["line"] == WORK and changed["source"]["path"] == str(h.path)
    assert "attached to the executor at 127.0.0.1:1667: tree Main, 9 nodes" in h.output()
    assert h.ok("threads") == {"threads": [{"id": 1, "name": "tree Main"}]}


def test_lines_without_a_running_node_are_unverified_with_the_reason(h: Harness) -> None:
    h.attached()
    on_close, other, work, sleep, missing = h.breakpoints(11, OTHER, WORK, SLEEP, 500)
    assert on_close["verified"] is False and on_close["message"] == (
        "no node's start tag is on line 11"
    )
    assert (
        other["verified"] is False
        and "tree Other is not part of the running tree" in (other["message"])
    )
    assert work["verified"] is True
    assert sleep["verified"] is True and "2 nodes" in sleep["message"]
    assert missing["verified"] is False
    assert set(h.link.installed) == {UID["work"], UID["sleep1"], UID["sleep2"]}
    # Edited since the executor started: the node is no longer matched, the hook goes.
    h.path.write_text(TEXT.replace('name="work"', 'name="job"'), encoding="utf-8")
    (work,) = h.breakpoints(WORK)
    assert work["verified"] is False and "differs" in work["message"]
    assert set(h.link.installed) == set()


def test_a_stop_its_frames_variables_and_continue(h: Harness) -> None:
    h.attached()
    (bp,) = h.breakpoints(SLEEP)
    h.link.notes = [UID["sleep1"]]
    h.tick()
    (stopped,) = h.events("stopped")
    assert stopped["reason"] == "breakpoint" and stopped["hitBreakpointIds"] == [bp["id"]]
    assert stopped["threadId"] == 1 and stopped["description"] == "before Sleep ticks"
    trace = h.ok("stackTrace", threadId=1)
    frames = trace["stackFrames"]
    assert trace["totalFrames"] == 3
    assert [(f["name"], f["line"]) for f in frames] == [
        ("Sleep #4", SLEEP),
        ('SubTree "sub1" -> Sub #3', SUB1),
        ('Sequence "seq" #1', SEQ),
    ]
    assert frames[0]["source"] == {"path": str(h.path), "name": "tree.xml"}
    assert h.ok("stackTrace", threadId=1, startFrame=1, levels=1)["stackFrames"] == frames[1:2]

    scopes = h.ok("scopes", frameId=frames[0]["id"])["scopes"]
    assert [s["name"] for s in scopes] == ["Blackboard sub1", "All blackboards"]
    assert h.ok("variables", variablesReference=scopes[0]["variablesReference"]) == {
        "variables": []  # an _autoremap subtree's own blackboard is empty (nil)
    }
    main_scope = h.ok("scopes", frameId=frames[2]["id"])["scopes"][0]
    assert main_scope["name"] == "Blackboard Main"
    entries = h.ok("variables", variablesReference=main_scope["variablesReference"])
    counter, pose = entries["variables"]
    assert (counter["name"], counter["value"], counter["type"]) == ("counter", "3", "int")
    inner = h.ok("variables", variablesReference=pose["variablesReference"])["variables"]
    assert inner[0]["name"] == "x" and inner[0]["value"] == "1"
    assert h.link.requests.count("blackboards") == 1  # read once per stop

    assert h.ok("continue", threadId=1) == {"allThreadsContinued": True}
    assert h.link.unlocks == [(UID["sleep1"], Resume.CONTINUE, False)]
    assert h.ok("stackTrace", threadId=1) == {"stackFrames": [], "totalFrames": 0}
    reply = h.request("variables", variablesReference=pose["variablesReference"])
    assert not reply["success"] and "gone" in reply["message"]
    # Not stopped: continue does nothing, forcing a result is an error.
    h.ok("continue", threadId=1)
    reply = h.request(SUCCEED, threadId=1)
    assert not reply["success"] and "not stopped" in reply["message"]
    assert len(h.link.unlocks) == 1


def test_each_stop_has_new_frame_ids(h: Harness) -> None:
    # VS Code keeps the previous stop's lower frames on screen while it fetches them again,
    # and does not redraw the Call Stack when they compare equal: with the same ids at the
    # next stop at the same node, its "Load More Stack Frames" row stayed under them.
    h.attached()
    h.breakpoints(SLEEP)
    h.link.notes = [UID["sleep1"]]
    h.tick()
    first = h.ok("stackTrace", threadId=1)["stackFrames"]
    h.ok("continue", threadId=1)
    h.link.notes = [UID["sleep1"]]
    h.tick()
    top = h.ok("stackTrace", threadId=1, startFrame=0, levels=1)["stackFrames"]
    rest = h.ok("stackTrace", threadId=1, startFrame=1, levels=19)["stackFrames"]
    second = top + rest
    assert [f["name"] for f in second] == [f["name"] for f in first]
    assert not {f["id"] for f in first} & {f["id"] for f in second}
    assert len({f["id"] for f in second}) == len(second)
    # The same frame asked for again keeps its id within the stop.
    assert h.ok("stackTrace", threadId=1)["stackFrames"] == second
    # A frame of this stop has its tree's blackboard; one of the previous stop does not.
    scopes = h.ok("scopes", frameId=second[-1]["id"])["scopes"]
    assert [s["name"] for s in scopes] == ["Blackboard Main", "All blackboards"]
    stale = h.ok("scopes", frameId=first[-1]["id"])["scopes"]
    assert [s["name"] for s in stale] == ["All blackboards"]


@pytest.mark.parametrize(("command", "result"), [(SUCCEED, Resume.SUCCESS), (FAIL, Resume.FAILURE)])
def test_succeed_and_fail_node(h: Harness, command: str, result: Resume) -> None:
    h.attached()
    h.breakpoints(WORK)
    h.link.notes = [UID["work"]]
    h.tick()
    body = h.ok(command, threadId=1)
    assert body["status"] == result.value
    assert h.link.unlocks == [(UID["work"], result, False)]
    assert h.events("continued") == [{"threadId": 1, "allThreadsContinued": True}]
    assert f'Work "work" returns {result.value}' in h.output()


def test_a_breakpoint_removed_while_stopped_there_goes_when_released(h: Harness) -> None:
    h.attached()
    h.breakpoints(WORK, SCRIPT)
    h.link.notes = [UID["work"]]
    h.tick()
    h.breakpoints(SCRIPT)
    assert set(h.link.installed) == {UID["work"], UID["script"]}  # the tree waits there
    h.ok("continue", threadId=1)
    assert h.link.unlocks == [(UID["work"], Resume.CONTINUE, True)]
    assert set(h.link.installed) == {UID["script"]}


def test_notifications_of_hooks_set_by_others(h: Harness) -> None:
    h.attached()
    h.link.installed[UID["ok"]] = Hook(UID["ok"], mode=HookMode.REPLACE)
    h.link.notes = [UID["ok"]]  # a REPLACE hook notifies too, but the tree goes on
    h.tick()
    assert h.events("stopped") == []
    h.link.installed[UID["script"]] = Hook(UID["script"])
    h.link.notes = [UID["script"]]
    h.tick()
    (stopped,) = h.events("stopped")
    assert stopped["hitBreakpointIds"] == [] and "did not set" in stopped["text"]
    h.ok("continue", threadId=1)
    assert h.link.unlocks == [(UID["script"], Resume.CONTINUE, False)]  # not ours to remove


def test_malformed_answers_are_reported_and_the_session_goes_on(h: Harness) -> None:
    h.ok("initialize")
    h.breakpoints(WORK)
    h.ok("attach")
    h.link.up = True
    h.link.fail_next["read_tree"] = ProtocolError("the tree is not XML: oops")
    h.tick()
    assert "malformed answer from the executor: the tree is not XML" in h.output()
    h.tick()
    assert set(h.link.installed) == {UID["work"]}
    h.link.notes = [ProtocolError("a notification names node b'x'"), UID["work"]]
    h.tick()
    assert "a notification names node" in h.output()
    h.tick()
    assert len(h.events("stopped")) == 1
    frames = h.ok("stackTrace", threadId=1)["stackFrames"]
    scope = h.ok("scopes", frameId=frames[0]["id"])["scopes"][0]
    h.link.fail_next["blackboards"] = ProtocolError("blackboard dump: truncated")
    reply = h.request("variables", variablesReference=scope["variablesReference"])
    assert not reply["success"] and "truncated" in reply["message"]
    assert h.ok("variables", variablesReference=scope["variablesReference"])["variables"]


def test_a_tree_that_cannot_be_read_is_said_once_and_tried_again(h: Harness) -> None:
    h.attached()
    (bp,) = h.breakpoints(WORK)
    assert bp["verified"]
    h.link.restart()
    h.link.broken_tree = True
    h.tick(6, step=0.2)
    assert h.output().count("two nodes have _uid 3") == 1
    assert 2 <= h.link.requests.count("read_tree") - 1 <= 4  # every 0.5 s, not every poll
    last = h.events("breakpoint")[-1]["breakpoint"]
    assert not last["verified"] and "waiting" in last["message"]
    h.link.broken_tree = False
    h.tick(2)
    assert h.events("breakpoint")[-1]["breakpoint"]["verified"]
    assert set(h.link.installed) == {UID["work"]}


def test_a_lost_executor_and_a_restarted_one(h: Harness) -> None:
    h.attached()
    (bp,) = h.breakpoints(WORK)
    h.link.notes = [UID["work"]]
    h.tick()
    assert len(h.events("stopped")) == 1
    # It stops answering: the stop is over, the breakpoint pending again.
    h.link.up = False
    h.link.fail_next["status"] = ConnectionLost("tcp://127.0.0.1:1667 closed the connection")
    h.tick(2)
    assert h.events("continued") == [{"threadId": 1, "allThreadsContinued": True}]
    assert "lost the executor at 127.0.0.1:1667" in h.output()
    last = h.events("breakpoint")[-1]["breakpoint"]
    assert last["id"] == bp["id"] and not last["verified"] and "waiting" in last["message"]
    # A new run of it (no hooks in it): read again, the hook inserted again.
    h.link.restart()
    h.link.up = True
    h.tick(2)
    assert "attached to a new executor run" in h.output()
    assert set(h.link.installed) == {UID["work"]}
    assert h.events("breakpoint")[-1]["breakpoint"]["verified"] is True
    # A restart seen between two polls while stopped: continued, then set again.
    h.link.notes = [UID["work"]]
    h.tick()
    h.link.restart()
    h.tick()
    assert len(h.events("continued")) == 2
    assert set(h.link.installed) == {UID["work"]}


def test_no_hooks_without_the_publisher(h: Harness) -> None:
    h.link.publisher = False
    h.ok("initialize")
    h.breakpoints(WORK)
    h.ok("attach")
    h.link.up = True
    h.tick()
    assert h.link.installed == {}
    assert "no connection to the executor's publisher (port 1668)" in h.output()
    assert "publisher" in h.events("breakpoint")[-1]["breakpoint"]["message"]
    h.link.publisher = True
    h.tick()
    assert set(h.link.installed) == {UID["work"]}
    assert h.events("breakpoint")[-1]["breakpoint"]["verified"] is True


def test_disconnect_removes_every_hook(h: Harness) -> None:
    h.attached()
    h.breakpoints(WORK, SLEEP)
    h.link.installed[UID["ok"]] = Hook(UID["ok"])  # another client's: removed too
    h.link.notes = [UID["work"]]
    h.tick()
    h.ok("disconnect")
    assert h.link.installed == {} and h.link.closed and h.session.done
    assert "removed every hook" in h.output()
    h.session.shutdown()  # again: nothing more
    assert h.link.requests.count("remove_all_hooks") == 1


def test_disconnect_says_when_the_hooks_could_not_be_removed(h: Harness) -> None:
    h.attached()
    h.breakpoints(WORK)
    h.link.up = False
    h.ok("disconnect")
    assert "could not remove the hooks" in h.output()
    assert h.link.closed


def test_bad_requests_are_answered_and_the_session_goes_on(h: Harness) -> None:
    h.ok("initialize")
    cases: list[tuple[dict[str, Any], str]] = [
        ({"port": "x"}, "'port' must be an integer"),
        ({"port": 65535}, "1..65534"),
        ({"host": "a b"}, "not a host"),
        ({"timeout": 0}, "'timeout'"),
    ]
    for arguments, text in cases:
        reply = h.request("attach", **arguments)
        assert not reply["success"] and text in reply["message"], reply
    assert not h.request("launch")["success"]
    reply = h.request("setBreakpoints", breakpoints=[{"line": 1}])
    assert not reply["success"] and "path" in reply["message"]
    reply = h.request("setBreakpoints", source={"path": str(h.path)}, breakpoints=[{"x": 1}])
    assert not reply["success"] and "'line'" in reply["message"]
    reply = h.request("stepIn", threadId=1)
    assert not reply["success"] and "'stepIn' is not supported" in reply["message"]
    h.session.handle({"seq": 90, "type": "request", "command": "threads", "arguments": 3})
    assert h.sent[-1]["success"] is False and h.sent[-1]["request_seq"] == 90
    h.session.handle({"type": "request"})
    assert "ignored a message without an integer seq" in h.output()
    h.session.handle({"seq": 1, "type": "response", "request_seq": 1})  # not answered
    assert h.sent[-1]["event"] == "output"
    h.session.frame_error("not a header: b'x'")
    assert "skipped a message: not a header" in h.output()
    assert h.ok("threads")["threads"] == [{"id": 1, "name": "tree"}]


def test_an_unreadable_file_and_zero_based_lines(h: Harness, tmp_path: Path) -> None:
    h.ok("initialize", linesStartAt1=False, columnsStartAt1=False)
    body = h.ok("setBreakpoints", source={"path": str(tmp_path / "nope.xml")},
                breakpoints=[{"line": 3}])  # fmt: skip
    (bp,) = body["breakpoints"]
    assert not bp["verified"] and bp["message"].startswith("cannot read")
    h.ok("attach")
    h.link.up = True
    h.tick()
    (bp,) = h.breakpoints(WORK - 1)
    assert bp["verified"] and (bp["line"], bp["column"]) == (WORK - 1, 6)
    (bp,) = h.breakpoints((WORK - 1, 37))  # the second node on that line
    assert bp["verified"] and bp["column"] == 37
    assert set(h.link.installed) == {UID["ok"]}


def test_an_internal_error_is_an_error_response(
    h: Harness, monkeypatch: pytest.MonkeyPatch
) -> None:
    h.attached()

    def broken(request: object) -> None:
        raise KeyError("boom")

    monkeypatch.setitem(h.session._handlers, "threads", broken)
    reply = h.request("threads")
    assert not reply["success"] and "internal error: KeyError" in reply["message"]
    assert h.ok("configurationDone") == {}
