"""``bt-lsp.liveConnect`` / ``bt-lsp.liveDisconnect`` end to end: the real server watches a
real BehaviorTree.CPP 4.8.2 executor (``tests/live/executor.py``) and sends
``bt-lsp/liveStatus`` notifications with the nodes mapped onto the open document; a hover
shows a blackboard key's live value and a node's last transitions; a killed executor is
reported lost, one restarted on the same port is mapped again; a peer that answers garbage
is reported and the server keeps serving."""

from __future__ import annotations

import asyncio
import contextlib
import re
import struct
import threading
import time
from collections.abc import AsyncIterator, Callable, Iterator
from pathlib import Path
from typing import Any

import pytest
from lsprotocol import types
from pygls.exceptions import JsonRpcException

pytest.importorskip("behaviortreepy")
zmq = pytest.importorskip("zmq")

from tests.live.harness import Executor, free_port, thread_names  # noqa: E402
from tests.server.conftest import TIMEOUT, BtClient, clients  # noqa: E402

pytestmark = [pytest.mark.asyncio(loop_scope="module")]

CONNECT = "bt-lsp.liveConnect"
DISCONNECT = "bt-lsp.liveDisconnect"
NOTIFICATION = "bt-lsp/liveStatus"

# The executor's tree: a Sleep in a SubTree keeps nodes RUNNING for a while; the script
# counts the runs in `counter` (an int the executor sets first), which a port reads.
TREE = """\
<root BTCPP_format="4" main_tree_to_execute="Main">
  <BehaviorTree ID="Main">
    <Sequence name="seq">
      <Script code="counter := counter + 1"/>
      <SubTree ID="Sub" name="sub1" _autoremap="true"/>
      <SetBlackboard output_key="copy" value="{counter}"/>
      <AlwaysSuccess name="ok"/>
    </Sequence>
  </BehaviorTree>
  <BehaviorTree ID="Sub">
    <Sequence>
      <Sleep msec="80"/>
      <SetBlackboard output_key="msg" value="hello"/>
    </Sequence>
  </BehaviorTree>
</root>
"""
# Each node's start tag, in document order.
TAGS = [
    '<Sequence name="seq"',
    "<Script",
    "<SubTree",
    '<SetBlackboard output_key="copy"',
    "<AlwaysSuccess",
    "<Sequence>",
    "<Sleep",
    '<SetBlackboard output_key="msg"',
]
STATUSES = {"idle", "running", "success", "failure", "skipped"}
TRANSITION = re.compile(r"^(- )?\d\d:\d\d:\d\d\.\d{3} (\?|[A-Z]+) -> [A-Z]+$", re.M)


# -- helpers --------------------------------------------------------------------------------


def _statuses(client: BtClient) -> list[dict[str, Any]]:
    """The liveStatus notifications received so far (handler registered once a client)."""
    found: list[dict[str, Any]] | None = getattr(client, "live_statuses", None)
    if found is None:
        found = []
        client.live_statuses = found  # type: ignore[attr-defined]

        @client.feature(NOTIFICATION)
        def _on_status(params: Any) -> None:
            found.append(_plain(params))
            client._notify_waiters()

    return found


def _plain(value: Any) -> Any:
    """pygls's params of an unknown notification (named tuples, lists) as JSON values."""
    if hasattr(value, "_asdict"):
        return {k: _plain(v) for k, v in value._asdict().items()}
    if isinstance(value, dict):
        return {k: _plain(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_plain(v) for v in value]
    return value


async def _command(client: BtClient, command: str, *args: Any) -> Any:
    return await asyncio.wait_for(
        client.workspace_execute_command_async(
            types.ExecuteCommandParams(command=command, arguments=list(args))
        ),
        TIMEOUT,
    )


async def _next(
    client: BtClient, seen: int, check: Callable[[dict[str, Any]], bool], what: str
) -> tuple[int, dict[str, Any]]:
    """The first notification after the first ``seen`` that passes ``check``."""
    statuses = _statuses(client)

    def found() -> tuple[int, dict[str, Any]] | None:
        for i in range(seen, len(statuses)):
            if check(statuses[i]):
                return i + 1, statuses[i]
        return None

    return await client.wait_until(found, what)


@contextlib.asynccontextmanager
async def _connected(client: BtClient, args: dict[str, Any]) -> AsyncIterator[dict[str, Any]]:
    """A session for the test's length (its liveStatus notifications recorded)."""
    _statuses(client)
    result = await _command(client, CONNECT, args)
    try:
        yield result
    finally:
        if client.error is None:
            await _command(client, DISCONNECT)


def _name_range(client: BtClient, text: str, tag: str) -> dict[str, Any]:
    assert text.count(tag) == 1, tag
    start = text.index(tag) + 1
    end = start
    while text[end].isalnum():
        end += 1
    r = client.range(text, start, end)
    return {
        "start": {"line": r.start.line, "character": r.start.character},
        "end": {"line": r.end.line, "character": r.end.character},
    }


def _threads(client: BtClient) -> list[str]:
    """The names of the server's threads now (ZeroMQ names its own; Linux)."""
    server = client._server
    assert server is not None
    return thread_names(server.pid)


@pytest.fixture
def tree_file(tmp_path: Path) -> Path:
    path = tmp_path / "main.xml"
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


# -- the tests ------------------------------------------------------------------------------


@clients("vscode")
async def test_commands_are_declared(client: BtClient) -> None:
    provider = client.init_result.capabilities.execute_command_provider
    assert provider is not None
    assert {CONNECT, DISCONNECT} <= set(provider.commands)


@clients("vscode", "nvim-0.11")  # utf-16 and utf-8 ranges
async def test_statuses_arrive_mapped_onto_the_document_and_change(
    client: BtClient, port: int, executor: Executor
) -> None:
    text = TREE.replace("<Sleep", "<!-- 😋 ü --><Sleep")  # columns differ by encoding
    uri = client.open(text, name="live")
    seen = len(_statuses(client))
    async with _connected(client, {"uri": uri, "port": port, "rateHz": 30}) as result:
        await _follow(client, uri, text, seen, result, port)


async def _follow(
    client: BtClient, uri: str, text: str, seen: int, result: dict[str, Any], port: int
) -> None:
    assert result["tree"] == "Main" and result["nodes"] == 8 and result["mismatches"] == []
    session = result["session"]
    seen, first = await _next(
        client, seen, lambda s: s["session"] == session, "the first liveStatus"
    )
    assert first["connected"] is True and first["tree"] == "Main"
    assert f"connected to 127.0.0.1:{port}" in first["message"]
    want = sorted(
        (str(n["range"]["start"]), str(n["range"]["end"]))
        for n in ({"range": _name_range(client, text, tag)} for tag in TAGS)
    )
    got = sorted((str(n["range"]["start"]), str(n["range"]["end"])) for n in first["nodes"])
    assert got == want
    assert {n["uri"] for n in first["nodes"]} == {uri}
    assert all(n["status"] in STATUSES for n in first["nodes"])
    sleep = _name_range(client, text, "<Sleep")
    (sleep_uid,) = [n["uid"] for n in first["nodes"] if n["range"] == sleep]

    # The Sleep node is seen running, then not: the notifications follow the tree.
    def sleep_is(pred: Callable[[str], bool]) -> Callable[[dict[str, Any]], bool]:
        def check(s: dict[str, Any]) -> bool:
            return s["session"] == session and any(
                n["uid"] == sleep_uid and pred(n["status"]) for n in s["nodes"]
            )

        return check

    seen, _ = await _next(client, seen, sleep_is(lambda st: st == "running"), "Sleep running")
    seen, _ = await _next(client, seen, sleep_is(lambda st: st != "running"), "Sleep done")
    seen, _ = await _next(client, seen, sleep_is(lambda st: st == "running"), "Sleep again")


@clients("vscode")
async def test_hover_shows_a_live_value_and_transitions(
    client: BtClient, port: int, executor: Executor
) -> None:
    uri = client.open(TREE, name="live")
    async with _connected(client, {"uri": uri, "port": port}):
        await asyncio.sleep(0.5)  # the script has run; transitions recorded
        await _hovers(client, uri)


async def _hovers(client: BtClient, uri: str) -> None:
    for at in (TREE.index("{counter}") + 2, TREE.index("counter :=") + 2):  # port, script
        hover = await client.hover(uri, client.pos(TREE, at))
        assert hover is not None and isinstance(hover.contents, types.MarkupContent)
        text = hover.contents.value
        value = re.search(r"Live value \(running tree\): `counter` = `(\d+)`", text)
        assert value is not None and int(value[1]) >= 1, text
    sleep = TREE.index("<Sleep") + 2
    hover = await client.hover(uri, client.pos(TREE, sleep))
    assert hover is not None and isinstance(hover.contents, types.MarkupContent)
    text = hover.contents.value
    assert "Last transitions (running tree" in text, text
    lines = TRANSITION.findall(text)
    assert 1 <= len(lines) <= 5, text
    assert "RUNNING" in text, text


@clients("vscode")
async def test_a_lost_executor_is_reported_and_a_restarted_one_mapped_again(
    client: BtClient, port: int, tree_file: Path
) -> None:
    uri = client.open(TREE, name="live")
    seen = len(_statuses(client))
    running = [Executor(port, tree=tree_file)]
    try:
        async with _connected(client, {"uri": uri, "port": port}) as result:
            session = result["session"]
            seen, _ = await _next(client, seen, lambda s: s["session"] == session, "connected")
            running[-1].kill()
            seen, lost = await _next(
                client, seen, lambda s: not s["connected"], "a connected:false notification"
            )
            assert lost["session"] == session and lost["nodes"] == []
            assert "connection lost" in lost["message"] and "retrying" in lost["message"]
            running.append(Executor(port, tree=tree_file))
            seen, back = await _next(client, seen, lambda s: s["connected"], "connected again")
    finally:
        for ex in running:
            ex.kill()
    assert back["session"] == session
    assert "restarted" in back["message"] and "re-mapped" in back["message"]
    assert len(back["nodes"]) == 8
    assert {n["range"]["start"]["line"] for n in back["nodes"]} == {
        TREE[: TREE.index(tag)].count("\n") for tag in TAGS
    }


@clients("vscode")
async def test_disconnect_sends_a_final_notification_and_ends_the_thread(
    client: BtClient, port: int, executor: Executor
) -> None:
    uri = client.open(TREE, name="live")
    await client.barrier()
    seen = len(_statuses(client))
    result = await _command(client, CONNECT, {"uri": uri, "port": port})
    running = _threads(client)
    assert any(name.startswith("ZMQbg") for name in running), running
    assert await _command(client, DISCONNECT) is None
    seen, final = await _next(client, seen, lambda s: not s["connected"], "the final notification")
    assert final["session"] == result["session"] and final["nodes"] == []
    # The watcher's thread ended: it closed its ZeroMQ context last (whose threads are
    # gone) and the server has one Python thread fewer.
    after = _threads(client)
    assert not any(name.startswith("ZMQbg") for name in after), after
    assert after.count("python") < running.count("python"), (running, after)
    await asyncio.sleep(0.3)  # nothing more about that session
    await client.barrier()
    assert [s for s in _statuses(client)[seen:] if s["session"] == result["session"]] == []
    # Nothing listening, bad arguments, a document that is not open: clear errors.
    with pytest.raises(JsonRpcException, match="cannot watch the executor"):
        await _command(client, CONNECT, {"uri": uri, "port": free_port()})
    for bad in ({"uri": uri, "port": "x"}, {"uri": uri, "port": 70000}, {"port": port}):
        with pytest.raises(JsonRpcException):
            await _command(client, CONNECT, bad)
    with pytest.raises(JsonRpcException, match="not an open document"):
        await _command(client, CONNECT, {"uri": "file:///nowhere/x.xml", "port": port})


# -- a peer that is not an executor ---------------------------------------------------------

FAKE_TREE = (
    b'<root><BehaviorTree ID="Main" _fullpath="">'
    b'<AlwaysSuccess name="ok" _uid="1"/></BehaviorTree></root>'
)
FAKE_DOC = """\
<root BTCPP_format="4">
  <BehaviorTree ID="Main">
    <AlwaysSuccess name="ok"/>
  </BehaviorTree>
</root>
"""


class FakePeer:
    """A ZeroMQ REP socket on ``port``: answers FULLTREE with a tree (unless
    ``tree_too``), a recording start with a timestamp, and garbage to the rest."""

    def __init__(
        self, port: int, *, tree_too: bool = False, tree: bytes | None = None, slow: float = 0
    ) -> None:
        self.context = zmq.Context()
        self.sock = self.context.socket(zmq.REP)
        self.sock.setsockopt(zmq.LINGER, 0)
        self.sock.bind(f"tcp://127.0.0.1:{port}")
        self.tree_too = tree_too
        self.tree = tree
        self.slow = slow  # seconds before answering BLACKBOARD (with a good STATUS)
        self.requests = 0
        self.stop = threading.Event()
        self.thread = threading.Thread(target=self._serve, daemon=True)
        self.thread.start()

    def _serve(self) -> None:
        while not self.stop.is_set():
            if not self.sock.poll(50):
                continue
            parts = self.sock.recv_multipart()
            self.requests += 1
            head = parts[0]
            if len(head) != 6:
                self.sock.send(b"?")
                continue
            _, kind, _ = struct.unpack("<BBI", head)
            reply = head + b"\x07" * 16
            if kind == ord("T") and not self.tree_too:
                self.sock.send_multipart([reply, self.tree or FAKE_TREE])
            elif kind == ord("S") and self.slow:
                self.sock.send_multipart([reply, b"\x01\x00\x01"])  # uid 1 RUNNING
            elif kind == ord("t") and self.slow:
                self.sock.send_multipart([reply, b""])
            elif kind == ord("B") and self.slow:
                time.sleep(self.slow)  # the answer goes to a socket given up on
                self.sock.send_multipart([reply, b"\xc0"])
            elif kind == ord("r"):
                self.sock.send_multipart([reply, b"1700000000000000"])
            else:
                self.sock.send_multipart([reply, b"\xff\xfe"])  # not 3-byte records

    def close(self) -> None:
        self.stop.set()
        self.thread.join(5)
        self.sock.close(0)
        self.context.term()


@clients("vscode")
async def test_a_peer_answering_garbage_is_reported_and_the_server_keeps_serving(
    client: BtClient,
) -> None:
    uri = client.open(FAKE_DOC, name="fake")
    port = free_port()
    peer = FakePeer(port, tree_too=True)
    try:
        with pytest.raises(JsonRpcException, match=r"cannot watch the executor.*not XML"):
            await _command(client, CONNECT, {"uri": uri, "port": port})
    finally:
        peer.close()
    port = free_port()
    peer = FakePeer(port)
    seen = len(_statuses(client))
    try:
        async with _connected(client, {"uri": uri, "port": port, "rateHz": 20}) as result:
            assert result["tree"] == "Main" and result["nodes"] == 1
            seen, bad = await _next(
                client,
                seen,
                lambda s: "malformed reply" in (s["message"] or ""),
                "a notification of the malformed reply",
            )
            assert f"127.0.0.1:{port}" in bad["message"] and "multiple of 3" in bad["message"]
            at = FAKE_DOC.index("AlwaysSuccess") + 1
            hover = await client.hover(uri, client.pos(FAKE_DOC, at))
            assert hover is not None  # the server keeps serving, the session too
            asked = peer.requests
            await asyncio.sleep(0.5)
            assert peer.requests > asked  # still polling, though every answer is bad
    finally:
        peer.close()


SCRIPT_TREE = (
    b'<root><BehaviorTree ID="Main" _fullpath="">'
    b'<Script code="k := 1" _uid="1"/></BehaviorTree></root>'
)
SCRIPT_DOC = """\
<root BTCPP_format="4">
  <BehaviorTree ID="Main">
    <Script code="k := 1"/>
  </BehaviorTree>
</root>
"""


@clients("vscode")
async def test_a_hover_waits_half_a_second_at_most_for_a_value(client: BtClient) -> None:
    uri = client.open(SCRIPT_DOC, name="slow")
    port = free_port()
    peer = FakePeer(port, tree=SCRIPT_TREE, slow=1.2)
    try:
        async with _connected(client, {"uri": uri, "port": port}) as result:
            assert result["nodes"] == 1
            pos = client.pos(SCRIPT_DOC, SCRIPT_DOC.index("k :="))
            loop = asyncio.get_running_loop()
            start = loop.time()
            hover = await client.hover(uri, pos)
            took = loop.time() - start
    finally:
        peer.close()
    assert hover is not None and isinstance(hover.contents, types.MarkupContent)
    assert "`k`: no answer from the executor within 0.5 s" in hover.contents.value
    assert 0.4 < took < 1.5, took
