"""A live session ends with the server: ``shutdown`` stops the thread watching the executor
(and says the session ended) and ``exit`` ends the process at once.  The thread's end is
seen in /proc (Linux): the ZeroMQ context it closes last has threads of its own, which are
gone.  The server runs as users start it, spoken to in raw JSON-RPC (the session fixture of
the other tests shuts its server down itself)."""

from __future__ import annotations

import json
import os
import selectors
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

import pytest

pytest.importorskip("behaviortreepy")
pytest.importorskip("zmq")

from tests.live.harness import Executor, free_port, thread_names
from tests.server.test_live_session_lsp import TREE

WAIT = 15.0


class RawServer:
    """``python -m bt_lsp serve`` and the messages it writes, read with bounded waits."""

    def __init__(self) -> None:
        self.proc = subprocess.Popen(
            [sys.executable, "-m", "bt_lsp", "serve"],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            stderr=subprocess.DEVNULL,
        )
        assert self.proc.stdout is not None
        self._sel = selectors.DefaultSelector()
        self._sel.register(self.proc.stdout, selectors.EVENT_READ)
        self._buf = b""
        self.seen: list[dict[str, Any]] = []
        self._id = 0

    def send(self, method: str, params: Any, *, request: bool = True) -> int | None:
        message: dict[str, Any] = {"jsonrpc": "2.0", "method": method, "params": params}
        msg_id = None
        if request:
            self._id += 1
            msg_id = message["id"] = self._id
        body = json.dumps(message).encode()
        assert self.proc.stdin is not None
        self.proc.stdin.write(b"Content-Length: %d\r\n\r\n" % len(body) + body)
        self.proc.stdin.flush()
        return msg_id

    def _read(self, timeout: float) -> None:
        assert self.proc.stdout is not None
        if self._sel.select(timeout):
            self._buf += os.read(self.proc.stdout.fileno(), 65536)
        while b"\r\n\r\n" in self._buf:
            head, rest = self._buf.split(b"\r\n\r\n", 1)
            length = next(
                int(line.split(b":")[1])
                for line in head.split(b"\r\n")
                if line.lower().startswith(b"content-length")
            )
            if len(rest) < length:
                return
            self.seen.append(json.loads(rest[:length]))
            self._buf = rest[length:]

    def wait(self, check: Any, what: str) -> dict[str, Any]:
        end = time.monotonic() + WAIT
        while True:
            for m in self.seen:
                if check(m):
                    return m
            left = end - time.monotonic()
            if left <= 0:
                raise AssertionError(f"no {what} within {WAIT}s: {self.seen[-5:]}")
            self._read(min(left, 0.2))

    def answer(self, msg_id: int | None, what: str) -> dict[str, Any]:
        return self.wait(lambda m: m.get("id") == msg_id and "method" not in m, what)

    def threads(self) -> list[str]:
        """The names of the server's threads now (ZeroMQ names its own)."""
        return thread_names(self.proc.pid)

    def close(self) -> None:
        if self.proc.poll() is None:
            self.proc.kill()
        self.proc.wait(5)
        self._sel.close()
        for stream in (self.proc.stdin, self.proc.stdout):
            if stream is not None:
                stream.close()


def test_shutdown_ends_the_session_and_its_thread(tmp_path: Path) -> None:
    path = tmp_path / "main.xml"
    path.write_text(TREE, encoding="utf-8")
    port = free_port()
    executor = Executor(port, tree=path)
    server = RawServer()
    try:
        init = server.send("initialize", {"processId": None, "rootUri": None, "capabilities": {}})
        server.answer(init, "initialize answer")
        server.send("initialized", {}, request=False)
        uri = path.as_uri()
        item = {"uri": uri, "languageId": "xml", "version": 1, "text": TREE}
        server.send("textDocument/didOpen", {"textDocument": item}, request=False)
        hover = {"textDocument": {"uri": uri}, "position": {"line": 0, "character": 1}}
        server.answer(server.send("textDocument/hover", hover), "hover answer")
        params = {"command": "bt-lsp.liveConnect", "arguments": [{"uri": uri, "port": port}]}
        connected = server.answer(server.send("workspace/executeCommand", params), "connect")
        assert connected["result"]["tree"] == "Main", connected
        running = server.threads()
        assert any(name.startswith("ZMQbg") for name in running), running
        done = server.answer(server.send("shutdown", None), "shutdown answer")
        assert "error" not in done, done
        final = server.wait(
            lambda m: (
                m.get("method") == "bt-lsp/liveStatus"
                and m["params"]["message"] == "the server shuts down"
            ),
            "final liveStatus",
        )
        assert final["params"]["connected"] is False and final["params"]["nodes"] == []
        # The watcher's thread ended: it closed its ZeroMQ context last, whose threads
        # are gone, and the process has one Python thread fewer.
        after = server.threads()
        assert not any(name.startswith("ZMQbg") for name in after), after
        assert after.count("python") < running.count("python"), (running, after)
        server.send("exit", None, request=False)
        assert server.proc.wait(WAIT) == 0
    finally:
        server.close()
        executor.kill()
