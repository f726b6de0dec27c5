"""The base protocol's framing and JSON-RPC's error answers, through a raw stdio client.

Each case writes bytes to ``bt-lsp serve`` as they are (no client library that would
refuse to write them) and then checks that a well-formed request right after is still
answered: after a framing error the server resynchronises on the next header.
"""

from __future__ import annotations

import json
import queue
import subprocess
import sys
import threading
from collections.abc import Iterator
from typing import Any

import pytest

SERVER = [sys.executable, "-m", "bt_lsp", "serve"]
TIMEOUT = 60.0  # generous: the server may start slowly on a busy machine
INIT_PARAMS: dict[str, Any] = {"capabilities": {}, "processId": None, "rootUri": None}
DOC = '<root BTCPP_format="4"><BehaviorTree ID="Main"><AlwaysSuccess/></BehaviorTree></root>'


def frame(obj: Any, header: bytes = b"Content-Length: %d\r\n\r\n") -> bytes:
    body = json.dumps(obj).encode()
    return header % len(body) + body if b"%d" in header else header + body


def msg(method: str, params: Any = None, msg_id: Any = None) -> dict[str, Any]:
    out: dict[str, Any] = {"jsonrpc": "2.0", "method": method, "params": params}
    if msg_id is not None:
        out["id"] = msg_id
    return out


class RawServer:
    """``bt-lsp serve`` with a thread that splits its output into messages."""

    def __init__(self) -> None:
        self.proc = subprocess.Popen(
            SERVER, stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL
        )
        self.inbox: queue.Queue[dict[str, Any]] = queue.Queue()
        self.seen: list[dict[str, Any]] = []
        threading.Thread(target=self._read, daemon=True).start()

    def _read(self) -> None:
        out = self.proc.stdout
        assert out is not None
        while True:
            length = None
            while True:
                line = out.readline()
                if not line:
                    return
                if not line.strip():
                    break
                name, _, value = line.partition(b":")
                if name.strip().lower() == b"content-length":
                    length = int(value)
            assert length is not None
            self.inbox.put(json.loads(out.read(length)))

    def write(self, data: bytes) -> None:
        assert self.proc.stdin is not None
        self.proc.stdin.write(data)
        self.proc.stdin.flush()

    def answer(self, msg_id: Any) -> dict[str, Any]:
        """The response with ``msg_id`` (read within the timeout)."""
        for m in self.seen:
            if "method" not in m and m.get("id") == msg_id:
                self.seen.remove(m)
                return m
        while True:
            try:
                m = self.inbox.get(timeout=TIMEOUT)
            except queue.Empty:
                raise AssertionError(f"no answer with id {msg_id!r} within {TIMEOUT}s") from None
            if "method" not in m and m.get("id") == msg_id:
                return m
            self.seen.append(m)

    def logs(self) -> list[str]:
        while not self.inbox.empty():
            self.seen.append(self.inbox.get())
        return [m["params"]["message"] for m in self.seen if m.get("method") == "window/logMessage"]

    def initialize(self) -> None:
        self.write(frame(msg("initialize", INIT_PARAMS, 0)))
        assert "result" in self.answer(0)
        self.write(frame(msg("initialized", {})))

    def still_serving(self, msg_id: int) -> None:
        """A request right after is answered (a hover on an opened document)."""
        uri = f"untitled:alive-{msg_id}.xml"
        item = {"uri": uri, "languageId": "xml", "version": 1, "text": DOC}
        self.write(frame(msg("textDocument/didOpen", {"textDocument": item})))
        params = {"textDocument": {"uri": uri}, "position": {"line": 0, "character": 50}}
        answer = self.answer_to(msg("textDocument/hover", params, msg_id))
        assert "result" in answer, answer

    def answer_to(self, message: dict[str, Any]) -> dict[str, Any]:
        self.write(frame(message))
        return self.answer(message["id"])

    def close(self) -> None:
        self.proc.kill()
        self.proc.wait(TIMEOUT)


@pytest.fixture(scope="module")
def server() -> Iterator[RawServer]:
    """One server for the module: each case leaves the stream in step again (that is
    what is tested), so the next case starts clean."""
    s = RawServer()
    try:
        s.initialize()
        yield s
    finally:
        s.close()


@pytest.fixture
def fresh() -> Iterator[RawServer]:
    s = RawServer()
    try:
        s.initialize()
        yield s
    finally:
        s.close()


def body_of(obj: Any) -> bytes:
    return json.dumps(obj).encode()


# -- framing -----------------------------------------------------------------------------


@pytest.mark.parametrize("off", [-3, -1, 2, 7])
def test_a_content_length_a_few_bytes_off(server: RawServer, off: int) -> None:
    before = len(server.logs())
    body = body_of(msg("textDocument/hover", {"nonsense": 1}, 90))
    server.write(b"Content-Length: %d\r\n\r\n" % (len(body) + off) + body)
    server.still_serving(91)
    assert any("framing error" in m or "parse error" in m for m in server.logs()[before:])


def test_a_shorter_length_is_recovered(fresh: RawServer) -> None:
    """The bytes up to the next header complete the message: it is handled."""
    server = fresh
    request = body_of(msg("shutdown", None, 92))
    hover = frame(msg("bt-lsp/noSuchRequest", {}, 93))
    server.write(b"Content-Length: %d\r\n\r\n" % (len(request) - 2) + request + hover)
    assert server.answer(92).get("result", "missing") is None
    assert server.answer(93)["error"]["code"] == -32600  # after shutdown: InvalidRequest


def test_a_longer_length_is_recovered(server: RawServer) -> None:
    """The body holds a whole message and the start of the next: both are handled."""
    first = body_of(msg("bt-lsp/noSuchRequest", {}, 94))
    second = frame(msg("bt-lsp/noSuchRequest", {}, 95))
    server.write(b"Content-Length: %d\r\n\r\n" % (len(first) + 5) + first + second)
    assert server.answer(94)["error"]["code"] == -32601
    assert server.answer(95)["error"]["code"] == -32601


@pytest.mark.parametrize(
    "header",
    [
        b"\r\n",  # no header at all
        b"Content-Type: application/vscode-jsonrpc\r\n\r\n",  # no Content-Length
        b"Content-Length: lots\r\n\r\n",  # not a number
        b"Content-Length: -5\r\n\r\n",
        b"Content-Length: 12345678901234567890123456789\r\n\r\n",  # would overflow
        b"Content-Length: 100000000000\r\n\r\n",  # 100 GB: refused, never allocated
        b"garbage line\r\n\r\n",
    ],
)
def test_broken_headers_then_serving_on(server: RawServer, header: bytes) -> None:
    server.write(header + body_of(msg("bt-lsp/noSuchRequest", {}, 96)))
    server.still_serving(97)
    assert server.proc.poll() is None


def test_a_length_without_a_body_leaves_the_next_message_whole(fresh: RawServer) -> None:
    """A repeated Content-Length whose body never came: the bytes it counts are the next
    message's header, which is read as such, so the message after is answered too."""
    server = fresh
    nxt = frame(msg("bt-lsp/noSuchRequest", {}, 102), b"content-LENGTH: %d\r\n\r\n")
    server.write(b"Content-Length: 5\r\nContent-Length: 7\r\n\r\n" + nxt)
    assert server.answer(102)["error"]["code"] == -32601
    assert any("but no body" in m for m in server.logs())
    assert not any(m.get("id", 0) is None for m in server.seen)  # no parse error answered


def test_a_message_without_content_length_is_still_read(server: RawServer) -> None:
    before = len(server.logs())
    server.write(b"Content-Type: x\r\n\r\n" + body_of(msg("bt-lsp/noSuchRequest", {}, 98)))
    assert server.answer(98)["error"]["code"] == -32601
    assert any("no Content-Length" in m for m in server.logs()[before:])


@pytest.mark.parametrize(
    "header",
    [
        b"content-length: %d\r\n\r\n",  # header names are case-insensitive
        b"CONTENT-LENGTH:%d\r\n\r\n",
        b"Content-Length: %d\n\n",  # LF-only line ends
        b"Content-Length: %d\r\nContent-Type: application/vscode-jsonrpc; charset=utf-8\n\r\n",
    ],
)
def test_header_variants_are_accepted(server: RawServer, header: bytes) -> None:
    before = len(server.logs())
    server.write(frame(msg("bt-lsp/noSuchRequest", {}, 99), header))
    assert server.answer(99)["error"]["code"] == -32601
    assert not any("framing error" in m for m in server.logs()[before:])


def test_messages_split_across_writes(server: RawServer) -> None:
    data = frame(msg("bt-lsp/noSuchRequest", {}, 100))
    for i in range(0, len(data), 7):
        server.write(data[i : i + 7])
    assert server.answer(100)["error"]["code"] == -32601


# -- JSON-RPC error answers ------------------------------------------------------------------


@pytest.mark.parametrize(
    ("body", "code"),
    [
        (b"{not json", -32700),
        (b'{"jsonrpc": "2.0", "id": 1, "method": "x"', -32700),
        (b"[]", -32600),  # a batch
        (b'[{"jsonrpc": "2.0", "id": 1, "method": "shutdown"}]', -32600),
        (b"42", -32600),
        (b"null", -32600),
        (b'"x"', -32600),
        (b'{"jsonrpc": "2.0", "id": 5}', -32600),  # no method
        (b'{"jsonrpc": "2.0", "id": {"a": 1}, "method": "shutdown"}', -32600),
        (b'{"jsonrpc": "2.0", "id": [1], "method": "shutdown"}', -32600),
        # Nested past the decoder's recursion limit: its RecursionError ended the server.
        (b"[" * 900 + b"]" * 900, -32600),
        (b"[" * 1000 + b"]" * 1000, -32700),
        (b"[" * 20000, -32700),
        (b'{"jsonrpc": "2.0", "id": 7, "method": "x", "params": ' + b'{"a": ' * 3000, -32700),
        (
            b'{"jsonrpc": "2.0", "method": "x", "params": ' + b"[" * 3000 + b"]" * 3000 + b"}",
            -32700,
        ),
    ],
)
def test_json_rpc_errors(server: RawServer, body: bytes, code: int) -> None:
    server.logs()  # everything earlier cases were answered is read by now ...
    server.seen = [m for m in server.seen if "method" in m]  # ... and forgotten
    server.write(b"Content-Length: %d\r\n\r\n" % len(body) + body)
    answer = server.answer(None if b'id": 5' not in body else 5)
    assert answer["error"]["code"] == code
    assert "id" in answer
    server.still_serving(101)


def test_before_initialize() -> None:
    s = RawServer()
    try:
        hover = {"textDocument": {"uri": "untitled:a.xml"}, "position": {"line": 0, "character": 0}}
        s.write(
            frame(
                msg(
                    "textDocument/didOpen",
                    {
                        "textDocument": {
                            "uri": "untitled:a.xml",
                            "languageId": "xml",
                            "version": 1,
                            "text": "<root",
                        }
                    },
                )
            )
        )
        assert s.answer_to(msg("textDocument/hover", hover, 1))["error"]["code"] == -32002
        assert s.answer_to(msg("shutdown", None, 2))["error"]["code"] == -32002
        # Whatever its params: the lifecycle answers before their shape is checked.
        assert s.answer_to(msg("textDocument/hover", {}, 6))["error"]["code"] == -32002
        s.initialize()
        # The didOpen before initialize was dropped: the document is unknown, no diagnostics.
        answer = s.answer_to(msg("textDocument/hover", hover, 3))
        assert answer.get("result", "missing") is None
        assert not any(m.get("method") == "textDocument/publishDiagnostics" for m in s.seen)
        second = s.answer_to(msg("initialize", INIT_PARAMS, 4))
        assert second["error"]["code"] == -32600
        assert s.answer_to(msg("initialize", {}, 7))["error"]["code"] == -32600
        s.still_serving(5)
    finally:
        s.close()


def test_a_large_body_is_read_in_one_exact_read() -> None:
    """A body larger than a chunk is asked of the input in one read of what is missing
    (one hop to the reading thread, not one per pipe-full); the input ending early
    ends the stream, as chunked reads do."""
    import asyncio

    from bt_lsp.server.framing import CHUNK, Framer, Stream

    body = json.dumps({"jsonrpc": "2.0", "method": "x", "params": {"t": "a" * (4 * CHUNK)}})
    data = f"Content-Length: {len(body)}\r\n\r\n{body}".encode()

    def run(data: bytes) -> tuple[object, list[tuple[str, int]]]:
        calls: list[tuple[str, int]] = []
        pos = 0

        async def read(n: int) -> bytes:
            nonlocal pos
            chunk = data[pos : pos + min(n, 1000)]
            pos += len(chunk)
            calls.append(("read", len(chunk)))
            return chunk

        async def read_exact(n: int) -> bytes:
            nonlocal pos
            chunk = data[pos : pos + n]
            pos += len(chunk)
            calls.append(("exact", len(chunk)))
            return chunk

        async def main() -> object:
            found = await Framer(Stream(read, read_exact), lambda _: None).next()
            return None if found is None else found.value

        return asyncio.run(main()), calls

    value, calls = run(data)
    assert value == json.loads(body)
    assert [c for c in calls if c[0] == "exact"] == [("exact", len(data) - 1000)]
    value, calls = run(data[:-10])  # cut short: no message
    assert value is None
