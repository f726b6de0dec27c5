"""The Groot2 client against a real BehaviorTree.CPP 4.8.2 executor (behaviortreepy).

Each test starts ``tests/live/executor.py`` in a subprocess with a Groot2Publisher on a free
loopback port; every wait is bounded, and the executor stops by itself after a while."""

from __future__ import annotations

import contextlib
import io
import time
from collections.abc import Iterator
from typing import Any

import pytest

pytest.importorskip("behaviortreepy")
pytest.importorskip("zmq")

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from bt_lsp.cli.main import main
from bt_lsp.live.client import ConnectionLost, Groot2Client, Timeout
from bt_lsp.live.protocol import (
    ExecutorError,
    Hook,
    HookMode,
    NodeState,
    NodeStatus,
    Position,
    ProtocolError,
    RequestType,
    Resume,
    hook_insert_payload,
    hook_remove_payload,
    unlock_payload,
)
from tests.live.harness import Executor, free_port


@pytest.fixture
def port() -> int:
    return free_port()


@pytest.fixture
def executor(port: int) -> Iterator[Executor]:
    ex = Executor(port)
    yield ex
    ex.kill()


@pytest.fixture
def client(port: int, executor: Executor) -> Iterator[Groot2Client]:
    c = Groot2Client("127.0.0.1", port, timeout=2.0)
    yield c
    c.close()


def test_fulltree_has_every_node_with_its_uid(client: Groot2Client) -> None:
    tree = client.read_tree()
    assert tree.tree_id == "Main"
    paths = {n.path: n for n in tree.nodes.values()}
    assert set(paths) == {"seq", "Script", "sub1", "sub1/Sequence", "sub1/Sleep",
                          "sub1/SetBlackboard", "ok"}  # fmt: skip
    assert paths["sub1"].subtree == "Sub"
    assert paths["sub1"].children[0] is paths["sub1/Sequence"]
    assert tree.blackboards == ("Main", "sub1")
    # The status buffer names exactly the same uids.
    assert set(client.status()) == set(tree.nodes)
    assert client.uuid is not None and len(client.uuid) == 16
    assert client.generation == 1


def test_status_changes_as_the_tree_ticks(client: Groot2Client) -> None:
    tree = client.read_tree()
    sleep = tree.find("sub1/Sleep")[0].uid
    seen: set[str] = set()
    end = time.monotonic() + 5
    while time.monotonic() < end and not {"RUNNING", "IDLE (was SUCCESS)"} <= seen:
        seen.add(str(client.status()[sleep]))
        time.sleep(0.005)
    assert {"RUNNING", "IDLE (was SUCCESS)"} <= seen


def test_blackboard_values(client: Groot2Client) -> None:
    tree = client.read_tree()
    first = client.blackboards(tree.blackboards)
    time.sleep(0.3)
    later = client.blackboards(["Main", "no-such-blackboard"])
    assert isinstance(first["Main"]["counter"], int)
    assert later["Main"]["counter"] > first["Main"]["counter"]
    assert later["Main"]["msg"] == "hello"  # written in the subtree, remapped
    assert "no-such-blackboard" not in later


def test_breakpoint_stops_the_tree_and_force_failure_changes_the_result(
    client: Groot2Client, executor: Executor
) -> None:
    tree = client.read_tree()
    ok = tree.find("ok")[0].uid
    client.subscribe()
    time.sleep(0.2)  # the subscription reaches the publisher
    client.set_breakpoint(ok)
    assert client.hooks() == [Hook(ok)]
    assert client.wait_breakpoint(5.0) == ok
    # Stopped before "ok": the Sequence waits, "ok" has not run.
    time.sleep(0.2)
    states = client.status()
    assert states[tree.find("seq")[0].uid].status is NodeStatus.RUNNING
    assert states[ok].status is NodeStatus.IDLE
    # Results printed before the stop, then none while stopped.
    assert set(executor.drain()) <= {"result SUCCESS"}
    assert executor.line(0.3) is None
    client.unlock(ok, Resume.FAILURE, remove=True)
    assert executor.wait_for("result", 5.0) == "result FAILURE"
    assert client.hooks() == []
    assert executor.wait_for("result", 5.0) == "result SUCCESS"


def test_publisher_connection_is_known(port: int) -> None:
    with Groot2Client("127.0.0.1", port, timeout=1.0) as c:
        time.sleep(0.3)
        assert not c.publisher_connected()  # nothing listens yet
        ex = Executor(port)
        try:
            end = time.monotonic() + 5
            while not c.publisher_connected():
                assert time.monotonic() < end
                time.sleep(0.02)
            ex.kill()
            end = time.monotonic() + 5
            while c.publisher_connected():
                assert time.monotonic() < end
                time.sleep(0.02)
        finally:
            ex.kill()


def test_continue_and_replace_hooks(client: Groot2Client, executor: Executor) -> None:
    tree = client.read_tree()
    ok = tree.find("ok")[0].uid
    client.subscribe()
    time.sleep(0.2)
    client.set_breakpoint(ok, once=True)
    assert client.wait_breakpoint(5.0) == ok
    executor.drain()
    client.unlock(ok, Resume.CONTINUE)
    assert executor.wait_for("result", 5.0) == "result SUCCESS"
    client.replace(ok, NodeStatus.FAILURE)
    assert executor.wait_for("result FAILURE", 5.0) == "result FAILURE"
    assert executor.line(1.0) == "result FAILURE"  # again: the hook stays
    client.remove_hook(ok)
    with pytest.raises(ExecutorError, match="Node ID not found"):
        client.remove_hook(ok)
    client.remove_all_hooks()


def test_restarted_executor_is_detected_and_the_client_reconnects(port: int) -> None:
    first = Executor(port)
    try:
        with Groot2Client("127.0.0.1", port, timeout=1.0) as c:
            c.read_tree()
            assert c.generation == 1
            uuid = c.uuid
            first.kill()
            with pytest.raises((Timeout, ConnectionLost)):
                c.status()
            second = Executor(port)
            try:
                end = time.monotonic() + 10
                while True:
                    try:
                        states = c.status()
                        break
                    except (Timeout, ConnectionLost):
                        assert time.monotonic() < end
                assert c.generation == 2
                assert len(states) == 7
                assert len(c.read_tree().nodes) == 7
                # BehaviorTree.CPP 4.8.2 seeds the UUID's generator with a constant, so
                # both runs have the same UUID there: the closed connection is what told.
                assert c.uuid is not None and (c.uuid == uuid) in (True, False)
            finally:
                second.kill()
    finally:
        first.kill()


def test_restart_between_two_polls_is_detected(port: int) -> None:
    first = Executor(port)
    with Groot2Client("127.0.0.1", port, timeout=3.0) as c:
        c.status()
        first.kill()
        second = Executor(port)
        try:
            c.status()  # queued until the new executor is up, then answered
            assert c.generation == 2
        finally:
            second.kill()


def test_timeout_is_clean_and_the_socket_recovers(port: int) -> None:
    with Groot2Client("127.0.0.1", port, timeout=0.3) as c:
        start = time.monotonic()
        with pytest.raises(Timeout):
            c.status()
        assert time.monotonic() - start < 1.5
        with pytest.raises(Timeout):
            c.read_tree()  # a REQ socket that had not been reset could not send again
        ex = Executor(port)
        try:
            c.timeout = 3.0
            assert len(c.status()) == 7
        finally:
            ex.kill()


def test_recording_transitions(client: Groot2Client) -> None:
    tree = client.read_tree()
    assert client.start_recording() > 1_500_000_000_000_000
    time.sleep(0.3)
    got = client.transitions()
    client.stop_recording()
    assert got and {t.uid for t in got} <= set(tree.nodes)
    assert [t.offset_us for t in got] == sorted(t.offset_us for t in got)


hooks = st.builds(
    Hook,
    uid=st.integers(0, 0xFFFF),
    position=st.just(Position.PRE),
    mode=st.sampled_from(HookMode),
    once=st.booleans(),
    enabled=st.booleans(),
    desired_status=st.sampled_from([NodeStatus.SUCCESS, NodeStatus.FAILURE, NodeStatus.SKIPPED]),
)


def test_every_payload_the_client_builds_is_accepted(client: Groot2Client) -> None:
    """Payloads from any typed values: the executor answers each (4.8.2 would abort on one
    it cannot parse), and is still ticking after all of them."""
    tree = client.read_tree()
    uids = st.one_of(st.sampled_from(sorted(tree.nodes)), st.integers(0, 0xFFFF))

    @settings(max_examples=40, deadline=None, suppress_health_check=list(HealthCheck))
    @given(
        st.one_of(
            st.tuples(st.just(RequestType.HOOK_INSERT), st.lists(hooks, min_size=1, max_size=3)),
            st.tuples(st.just(RequestType.HOOK_REMOVE), uids),
            st.tuples(
                st.just(RequestType.BREAKPOINT_UNLOCK),
                st.tuples(uids, st.sampled_from(Resume), st.booleans()),
            ),
        )
    )
    def send(case: tuple[RequestType, object]) -> None:
        kind, value = case
        if kind is RequestType.HOOK_INSERT:
            payload = hook_insert_payload(value)  # type: ignore[arg-type]
        elif kind is RequestType.HOOK_REMOVE:
            payload = hook_remove_payload(value)  # type: ignore[arg-type]
        else:
            assert isinstance(value, tuple)
            payload = unlock_payload(value[0], value[1], Position.PRE, value[2])
        # "Node ID not found" is an answer too: parsed, and refused.
        with contextlib.suppress(ExecutorError):
            client._request(kind, payload)
        client.remove_all_hooks()

    send()
    assert len(client.status()) == len(tree.nodes)
    with pytest.raises(ValueError):
        client._request(RequestType.BREAKPOINT_UNLOCK)  # never without its payload
    with pytest.raises(ValueError):
        client._request(RequestType.STATUS, b"x")


def test_monitor_once_prints_the_tree_with_statuses(
    port: int, executor: Executor, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["monitor", f"127.0.0.1:{port}", "--once", "--blackboard"]) == 0
    out = capsys.readouterr().out
    assert out.startswith(f"Main at 127.0.0.1:{port}")
    assert 'SubTree "sub1" -> Sub #' in out
    assert "blackboard Main:" in out and "counter = " in out
    line = next(x for x in out.splitlines() if "Sleep #" in x)
    assert line.split("  ")[-1].strip() in {"IDLE", "RUNNING", "IDLE (was SUCCESS)"}


def test_monitor_plain_watch_redraws_until_its_duration(port: int, executor: Executor) -> None:
    from bt_lsp.cli import live

    out = io.StringIO()
    start = time.monotonic()
    assert live.monitor(f"127.0.0.1:{port}", rate=20, plain=True, duration=1.0, out=out) == 0
    assert time.monotonic() - start < 3
    frames = out.getvalue().split("\n\n")
    assert len(frames) > 3  # the statuses changed several times


def test_monitor_once_without_an_executor_fails_cleanly(
    capsys: pytest.CaptureFixture[str],
) -> None:
    port = free_port()
    assert main(["monitor", f"127.0.0.1:{port}", "--once", "--timeout", "0.3"]) == 1
    assert "no answer" in capsys.readouterr().err


class FakeExecutor:
    """A hostile Groot2 server on 127.0.0.1: each request gets the next canned answer,
    built from the request's own header (so only the body is wrong)."""

    def __init__(self, port: int, answers: list[Any]) -> None:
        import threading

        import zmq

        self.ctx = zmq.Context()
        self.sock = self.ctx.socket(zmq.REP)
        self.sock.setsockopt(zmq.LINGER, 0)
        self.sock.bind(f"tcp://127.0.0.1:{port}")
        self.answers = answers
        self.thread = threading.Thread(target=self.serve, daemon=True)
        self.thread.start()

    def serve(self) -> None:
        import zmq

        for answer in self.answers:
            if not self.sock.poll(5000):
                return
            [head, *_] = self.sock.recv_multipart()
            try:
                self.sock.send_multipart(answer(head))
            except zmq.ZMQError:
                return

    def close(self) -> None:
        self.thread.join(6)
        self.sock.close(0)
        self.ctx.term()


def test_hostile_replies_are_errors_and_the_client_goes_on(port: int) -> None:
    uuid = b"u" * 16
    good_status = b"\x01\x00\x02"
    answers = [
        lambda h: [h + uuid, b"\x01\x00"],  # a status buffer cut short
        lambda h: [h[:2] + b"\x00\x00\x00\x00" + uuid, good_status],  # another request's id
        lambda h: [h + uuid, b"a", b"b", b"c"],  # too many parts
        lambda h: [h + uuid, b"<root><BehaviorTree"],  # FULLTREE: broken XML
        lambda h: [h + uuid, b"x" * 5000],  # over the client's size cap: dropped by ZeroMQ
        lambda h: [h + uuid, good_status],
    ]
    fake = FakeExecutor(port, answers)
    try:
        with Groot2Client("127.0.0.1", port, timeout=1.0, max_message_bytes=4096) as c:
            for _ in range(3):
                with pytest.raises(ProtocolError):
                    c.status()
            with pytest.raises(ProtocolError):
                c.read_tree()
            with pytest.raises((ConnectionLost, Timeout)):
                c.status()
            assert c.status() == {1: NodeState(NodeStatus.SUCCESS)}
    finally:
        fake.close()
