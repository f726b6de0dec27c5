"""``bt-lsp debug-adapter`` end to end: a DAP client (tests/live/dap_client.py) drives the
adapter in a subprocess, attached to a real BehaviorTree.CPP 4.8.2 executor running a
tree file; every wait is bounded."""

from __future__ import annotations

import signal
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

pytest.importorskip("behaviortreepy")
pytest.importorskip("zmq")

from bt_lsp.live.client import Groot2Client
from tests.live.dap_client import DapClient
from tests.live.harness import Executor, free_port

# The result is SUCCESS unless a node is forced: "no" made to succeed makes the Inverter,
# and so the tree, fail.
TREE = """\
<root BTCPP_format="4" main_tree_to_execute="Main">
  <BehaviorTree ID="Main">
    <Sequence name="seq">
      <Script code="counter := counter + 1"/>
      <SubTree ID="Sub" name="sub1" _autoremap="true"/>
      <Inverter name="inv">
        <AlwaysFailure name="no"/>
      </Inverter>
      <AlwaysSuccess name="ok"/>
    </Sequence>
  </BehaviorTree>
  <BehaviorTree ID="Sub">
    <Sequence>
      <Sleep msec="30"/>
      <SetBlackboard output_key="msg" value="hello"/>
    </Sequence>
  </BehaviorTree>
</root>
"""
LINE = {"seq": 3, "no": 7, "ok": 9, "end": 10, "sleep": 14, "sub_seq": 13, "sub1": 5}


@pytest.fixture
def tree_file(tmp_path: Path) -> Path:
    path = tmp_path / "tree.xml"
    path.write_text(TREE, encoding="utf-8")
    return path


@pytest.fixture
def port() -> int:
    return free_port()


@pytest.fixture
def executor(port: int, tree_file: Path) -> Iterator[Executor]:
    ex = Executor(port, tree=tree_file)
    yield ex
    ex.kill()


@pytest.fixture
def dap() -> Iterator[DapClient]:
    client = DapClient()
    yield client
    client.close()


def set_breakpoints(dap: DapClient, path: Path, *lines: int) -> list[dict[str, Any]]:
    reply = dap.request(
        "setBreakpoints", source={"path": str(path)}, breakpoints=[{"line": n} for n in lines]
    )
    assert reply["success"], reply
    breakpoints: list[dict[str, Any]] = reply["body"]["breakpoints"]
    return breakpoints


def verified(dap: DapClient, bp: dict[str, Any]) -> None:
    """Wait until the breakpoint is verified (in its response, or by a later event)."""
    if not bp["verified"]:
        event = dap.wait(
            lambda m: (
                m.get("event") == "breakpoint"
                and m["body"]["breakpoint"]["id"] == bp["id"]
                and m["body"]["breakpoint"]["verified"]
            )
        )
        assert event["body"]["breakpoint"]["line"] == bp["line"]


def hooks(port: int) -> list[Any]:
    with Groot2Client("127.0.0.1", port, timeout=2.0) as client:
        return list(client.hooks())


def test_breakpoint_stops_the_tree_at_its_line(
    dap: DapClient, executor: Executor, tree_file: Path, port: int
) -> None:
    dap.start(port)
    ok, none = set_breakpoints(dap, tree_file, LINE["ok"], LINE["end"])
    assert not none["verified"] and "no node" in none["message"]
    assert dap.request("configurationDone")["success"]
    verified(dap, ok)
    stopped = dap.event("stopped", reason="breakpoint")
    assert stopped["body"]["hitBreakpointIds"] == [ok["id"]]
    frames = dap.request("stackTrace", threadId=1)["body"]["stackFrames"]
    assert frames[0]["source"]["path"] == str(tree_file)
    assert frames[0]["line"] == LINE["ok"] and frames[0]["column"] == 7
    assert frames[0]["name"].startswith('AlwaysSuccess "ok"')
    assert [f["line"] for f in frames] == [LINE["ok"], LINE["seq"]]
    threads = dap.request("threads")["body"]["threads"]
    assert threads == [{"id": 1, "name": "tree Main"}]
    # Stopped: no result while the tree waits before "ok".
    executor.drain()
    assert executor.line(0.5) is None

    scopes = dap.request("scopes", frameId=frames[0]["id"])["body"]["scopes"]
    assert scopes[0]["name"] == "Blackboard Main"
    entries = dap.request("variables", variablesReference=scopes[0]["variablesReference"])
    values = {v["name"]: v["value"] for v in entries["body"]["variables"]}
    assert int(values["counter"]) > 0
    assert values["msg"] == '"hello"'  # written in the subtree, remapped

    assert dap.request("continue", threadId=1)["body"]["allThreadsContinued"]
    assert executor.wait_for("result", 5.0) == "result SUCCESS"
    dap.event("stopped", reason="breakpoint")  # the next run reaches "ok" again
    counter = int(values["counter"])
    entries = dap.request("variables", variablesReference=scopes[0]["variablesReference"])
    assert not entries["success"]  # a reference of the last stop
    frames = dap.request("stackTrace", threadId=1)["body"]["stackFrames"]
    scopes = dap.request("scopes", frameId=frames[0]["id"])["body"]["scopes"]
    entries = dap.request("variables", variablesReference=scopes[0]["variablesReference"])
    later = {v["name"]: v["value"] for v in entries["body"]["variables"]}
    assert int(later["counter"]) > counter

    executor.drain()
    assert dap.request("btLsp/failNode", threadId=1)["success"]
    assert executor.wait_for("result", 5.0) == "result FAILURE"
    dap.event("stopped", reason="breakpoint")

    assert dap.request("disconnect")["success"]
    assert hooks(port) == []
    # Released: the tree runs on.
    assert executor.wait_for("result SUCCESS", 5.0) == "result SUCCESS"
    dap.proc.wait(5)
    assert dap.proc.returncode == 0


def test_succeed_node_and_a_breakpoint_inside_a_subtree(
    dap: DapClient, executor: Executor, tree_file: Path, port: int
) -> None:
    dap.start(port)
    (no,) = set_breakpoints(dap, tree_file, LINE["no"])
    verified(dap, no)
    dap.event("stopped", reason="breakpoint")
    executor.drain()
    reply = dap.request("btLsp/succeedNode", threadId=1)
    assert reply["success"] and reply["body"]["status"] == "SUCCESS"
    dap.event("continued")
    # "no" succeeded without ticking, so the Inverter failed, and the tree.
    assert executor.wait_for("result", 5.0) == "result FAILURE"
    dap.event("stopped", reason="breakpoint")

    # Breakpoints move to the Sleep of the subtree: the stop there has the SubTree call
    # and the main tree's Sequence as frames below it.
    set_breakpoints(dap, tree_file, LINE["sleep"])
    assert dap.request("continue", threadId=1)["success"]
    stopped = dap.event("stopped", reason="breakpoint")
    assert "Sleep" in stopped["body"]["description"]
    frames = dap.request("stackTrace", threadId=1)["body"]["stackFrames"]
    assert [f["line"] for f in frames] == [LINE["sleep"], LINE["sub_seq"], LINE["sub1"],
                                          LINE["seq"]]  # fmt: skip
    scopes = dap.request("scopes", frameId=frames[0]["id"])["body"]["scopes"]
    assert scopes[0]["name"] == "Blackboard sub1"
    assert scopes[-1]["name"] == "All blackboards"
    boards = dap.request("variables", variablesReference=scopes[-1]["variablesReference"])
    names = {v["name"]: v for v in boards["body"]["variables"]}
    assert set(names) == {"Main", "sub1"}
    main = dap.request("variables", variablesReference=names["Main"]["variablesReference"])
    assert "counter" in {v["name"] for v in main["body"]["variables"]}
    # The hook at "no" went when its breakpoint did; only the Sleep's is left.
    assert len(hooks(port)) == 1
    dap.request("disconnect")
    assert hooks(port) == []


def test_breakpoint_set_before_the_executor_starts(
    dap: DapClient, tree_file: Path, port: int
) -> None:
    dap.start(port)
    (ok,) = set_breakpoints(dap, tree_file, LINE["ok"])
    assert not ok["verified"] and ok["message"].startswith("pending")
    assert ok["line"] == LINE["ok"]
    dap.request("configurationDone")
    ex = Executor(port, tree=tree_file)
    try:
        verified(dap, ok)
        stopped = dap.event("stopped", reason="breakpoint")
        assert stopped["body"]["hitBreakpointIds"] == [ok["id"]]
        frames = dap.request("stackTrace", threadId=1)["body"]["stackFrames"]
        assert (frames[0]["source"]["path"], frames[0]["line"]) == (str(tree_file), LINE["ok"])

        # The executor is restarted: the stop is over, and the breakpoint is set again in
        # the new run (4.8.2 keeps the tree UUID, the closed connection tells).
        ex.kill()
        dap.event("continued")
        ex = Executor(port, tree=tree_file)
        dap.event("stopped", timeout=15.0, reason="breakpoint")
        assert "a new executor run" in dap.output()
        dap.request("disconnect")
        assert hooks(port) == []
        assert ex.wait_for("result", 5.0) == "result SUCCESS"
    finally:
        ex.kill()


@pytest.mark.parametrize("how", ["stdin closed", "SIGTERM"])
def test_ending_the_adapter_while_stopped_releases_the_tree(
    dap: DapClient, executor: Executor, tree_file: Path, port: int, how: str
) -> None:
    """The editor went away without a disconnect, or stopped the adapter: no hook is left."""
    dap.start(port)
    (ok,) = set_breakpoints(dap, tree_file, LINE["ok"])
    verified(dap, ok)
    dap.event("stopped")
    executor.drain()
    assert executor.line(0.3) is None
    if how == "SIGTERM":
        dap.proc.send_signal(signal.SIGTERM)
        dap.proc.wait(10)
    dap.close()
    assert dap.proc.returncode == 0
    assert hooks(port) == []
    assert executor.wait_for("result", 5.0) == "result SUCCESS"


def test_garbage_on_stdin_is_reported_and_the_session_goes_on(
    dap: DapClient, executor: Executor, tree_file: Path, port: int
) -> None:
    dap.send_raw(b"Content-Length: 5\r\n\r\n[1,2]")
    dap.send_raw(b"Content-Length: 3\r\n\r\n{x}")
    dap.send_raw(b"this is no header\r\n\r\n")
    dap.start(port)
    (ok,) = set_breakpoints(dap, tree_file, LINE["ok"])
    verified(dap, ok)
    dap.event("stopped")
    assert "not an object" in dap.output() and "not JSON" in dap.output()
    reply = dap.request("stepIn", threadId=1)
    assert not reply["success"] and "not supported" in reply["message"]
    reply = dap.request("attach", host="127.0.0.1", port=port)
    assert not reply["success"] and "already attached" in reply["message"]
    dap.request("disconnect")
    assert hooks(port) == []


class HostileExecutor:
    """A Groot2 server on 127.0.0.1 (requests only: no publisher) answering each request
    type with its scripted answers first, then its usual one."""

    def __init__(self, port: int, script: dict[str, list[bytes]], usual: dict[str, bytes]):
        import threading

        import zmq

        self.script = script
        self.usual = usual
        self.ctx = zmq.Context()
        self.sock = self.ctx.socket(zmq.REP)
        self.sock.setsockopt(zmq.LINGER, 0)
        self.sock.bind(f"tcp://127.0.0.1:{port}")
        self.stop = threading.Event()
        self.thread = threading.Thread(target=self.serve, daemon=True)
        self.thread.start()

    def serve(self) -> None:
        import zmq

        uuid = b"u" * 16
        while not self.stop.is_set():
            if not self.sock.poll(100):
                continue
            head, *_ = self.sock.recv_multipart()
            kind = chr(head[1]) if len(head) > 1 else "?"
            queue = self.script.get(kind, [])
            body = queue.pop(0) if queue else self.usual.get(kind)
            try:
                if body is None:
                    self.sock.send_multipart([b"error", b"not here"])
                else:
                    self.sock.send_multipart([head + uuid, body])
            except zmq.ZMQError:
                return

    def close(self) -> None:
        self.stop.set()
        self.thread.join(5)
        self.sock.close(0)
        self.ctx.term()


def test_malformed_answers_are_reported_and_the_adapter_goes_on(
    dap: DapClient, tree_file: Path, port: int
) -> None:
    tree = b'<root><BehaviorTree ID="Main" _fullpath=""><Sequence name="seq" _uid="1"/>'
    hostile = HostileExecutor(
        port,
        script={"S": [b"\x01\x00"], "T": [b"<root><BehaviorTree"]},
        usual={
            "S": b"\x01\x00\x02",
            "T": tree + b"</BehaviorTree></root>",
            "A": b"",
            "D": b"[]",
        },
    )
    try:
        dap.start(port)
        (seq,) = set_breakpoints(dap, tree_file, LINE["seq"])
        assert not seq["verified"]
        dap.wait(
            lambda m: (
                m.get("event") == "breakpoint"
                and "publisher" in m["body"]["breakpoint"].get("message", "")
            ),
            timeout=15.0,
        )
        text = dap.output()
        assert "malformed answer from the executor: a status buffer" in text
        assert "malformed answer from the executor: the tree is not XML" in text
        assert "no connection to the executor's publisher" in text
        assert dap.request("threads")["body"]["threads"] == [{"id": 1, "name": "tree Main"}]
        assert dap.request("disconnect")["success"]
        dap.proc.wait(10)
        assert dap.proc.returncode == 0
        assert "Traceback" not in dap.errors()
    finally:
        hostile.close()
