"""A minimal LSP client over a subprocess's stdio, for timing a language server.

Only what a benchmark needs and with as little overhead as possible: JSON-RPC framing,
requests with futures, answers to the server's own requests, and the latest
``textDocument/publishDiagnostics`` per document, with the time each one arrived (taken
when its bytes are read, before they are decoded), so that a waiter can ask for the
diagnostics of one document version.

    client = await LspClient.start([sys.executable, "-m", "bt_lsp", "serve"])
    await client.initialize(root_uri, {"debounceMs": 0})
    t0 = client.notify("textDocument/didOpen", {...})
    diags, t1 = await client.diagnostics(uri, version=1)
"""

from __future__ import annotations

import asyncio
import contextlib
import json
import os
import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

__all__ = ["CAPABILITIES", "LspClient", "Published", "path_uri", "rss_kib"]

# What an editor like VS Code announces, reduced to what changes the server's behavior:
# pushed diagnostics with versions, code actions resolved lazily, versioned workspace
# edits, UTF-16 positions.  No workspace/configuration: the settings come as
# initializationOptions.
CAPABILITIES: dict[str, Any] = {
    "general": {"positionEncodings": ["utf-16"]},
    "textDocument": {
        "synchronization": {"didSave": True, "dynamicRegistration": False},
        "publishDiagnostics": {"versionSupport": True, "relatedInformation": True},
        "hover": {"contentFormat": ["markdown", "plaintext"]},
        "codeAction": {
            "codeActionLiteralSupport": {
                "codeActionKind": {"valueSet": ["quickfix", "source", "source.fixAll"]}
            },
            "resolveSupport": {"properties": ["edit"]},
            "dataSupport": True,
            "isPreferredSupport": True,
        },
    },
    "workspace": {"workspaceEdit": {"documentChanges": True}, "workspaceFolders": True},
}


def path_uri(path: str | os.PathLike[str]) -> str:
    return Path(path).resolve().as_uri()


def rss_kib(pid: int, field: str = "VmRSS") -> int:
    """A memory figure of a process from /proc/<pid>/status, in KiB (0 if unknown)."""
    try:
        with open(f"/proc/{pid}/status", encoding="ascii") as f:
            for line in f:
                if line.startswith(field + ":"):
                    return int(line.split()[1])
    except OSError:
        pass
    return 0


@dataclass(slots=True)
class Published:
    version: int | None
    diagnostics: list[dict[str, Any]]
    at: float  # time.perf_counter() when the notification's bytes were read


class LspClient:
    def __init__(self, proc: asyncio.subprocess.Process) -> None:
        self.proc = proc
        assert proc.stdin is not None and proc.stdout is not None
        self._stdin = proc.stdin
        self._stdout = proc.stdout
        self._next_id = 0
        self._pending: dict[int, asyncio.Future[tuple[Any, float]]] = {}
        self._published: dict[str, Published] = {}
        self._waiters: list[tuple[str, int | None, asyncio.Future[Published]]] = []
        self.log: list[str] = []  # window/logMessage and showMessage texts
        self.last_answer_at = 0.0  # when the latest answer to a request arrived
        self.counts: dict[str, int] = {}  # publishDiagnostics received, by URI
        # Other notifications asked for (watch): the wall-clock time each arrived, and its
        # params (wall clock, to compare with another process's timestamps).
        self.watched: dict[str, list[tuple[float, Any]]] = {}
        self._closing = False
        self._reader = asyncio.get_running_loop().create_task(self._read_loop())

    @property
    def pid(self) -> int:
        return self.proc.pid

    @classmethod
    async def start(
        cls, command: Sequence[str], cwd: str | None = None, env: dict[str, str] | None = None
    ) -> LspClient:
        proc = await asyncio.create_subprocess_exec(
            *command,
            stdin=asyncio.subprocess.PIPE,
            stdout=asyncio.subprocess.PIPE,
            stderr=asyncio.subprocess.DEVNULL,
            cwd=cwd,
            env=env,
            limit=1 << 26,
        )
        return cls(proc)

    # -- wire -----------------------------------------------------------------------------

    def _send(self, message: dict[str, Any]) -> float:
        body = json.dumps(message, ensure_ascii=False, separators=(",", ":")).encode()
        t = time.perf_counter()
        self._stdin.write(b"Content-Length: %d\r\n\r\n" % len(body) + body)
        return t

    async def _read_loop(self) -> None:
        stdout = self._stdout
        try:
            while True:
                header = await stdout.readuntil(b"\r\n\r\n")
                length = 0
                for line in header.split(b"\r\n"):
                    if line.lower().startswith(b"content-length:"):
                        length = int(line.split(b":", 1)[1])
                body = await stdout.readexactly(length)
                at = time.perf_counter()
                self._dispatch(json.loads(body), at)
        except (asyncio.IncompleteReadError, ConnectionError):
            pass
        finally:
            for fut in self._pending.values():  # requests: their senders await them
                if not fut.done():
                    fut.set_exception(ConnectionError("the server exited"))
            # Waiters for diagnostics fail too, unless the client itself closed the
            # connection: then nobody awaits them (diagnostics that never came), and a
            # failed future that nobody retrieves is logged at exit.
            for _, _, w in self._waiters:
                if w.done():
                    continue
                if self._closing:
                    w.cancel()
                else:
                    w.set_exception(ConnectionError("the server exited"))

    def _dispatch(self, msg: dict[str, Any], at: float) -> None:
        method = msg.get("method")
        if method is None:
            fut = self._pending.pop(msg.get("id", -1), None)
            if fut is not None and not fut.done():
                if "error" in msg:
                    fut.set_exception(RuntimeError(f"LSP error: {msg['error']}"))
                else:
                    fut.set_result((msg.get("result"), at))
            return
        if "id" in msg:  # a request from the server: answer what an editor would
            result: Any = None
            if method == "workspace/configuration":
                result = [None for _ in msg.get("params", {}).get("items", [])]
            self._send({"jsonrpc": "2.0", "id": msg["id"], "result": result})
            return
        params = msg.get("params") or {}
        if method == "textDocument/publishDiagnostics":
            pub = Published(params.get("version"), params.get("diagnostics", []), at)
            uri = params["uri"]
            self._published[uri] = pub
            self.counts[uri] = self.counts.get(uri, 0) + 1
            keep = []
            for w_uri, w_version, fut in self._waiters:
                if w_uri == uri and (w_version is None or w_version == pub.version):
                    if not fut.done():
                        fut.set_result(pub)
                else:
                    keep.append((w_uri, w_version, fut))
            self._waiters = keep
        elif method in ("window/logMessage", "window/showMessage"):
            self.log.append(str(params.get("message", "")))
        elif method in self.watched:
            self.watched[method].append((time.time(), params))

    # -- API ------------------------------------------------------------------------------

    def watch(self, method: str) -> list[tuple[float, Any]]:
        """Keep every ``method`` notification from now on, with the wall-clock time it
        arrived; the list fills as they come."""
        return self.watched.setdefault(method, [])

    def notify(self, method: str, params: Any) -> float:
        """Send a notification; returns the time just before it was written."""
        return self._send({"jsonrpc": "2.0", "method": method, "params": params})

    def open(self, uri: str, text: str) -> float:
        """Open ``uri`` as an XML document of ``text`` (version 1); see :meth:`notify`."""
        item = {"uri": uri, "languageId": "xml", "version": 1, "text": text}
        return self.notify("textDocument/didOpen", {"textDocument": item})

    async def request_timed(
        self, method: str, params: Any, timeout: float = 120.0
    ) -> tuple[Any, float]:
        """Send a request; returns its result and the seconds until the answer arrived."""
        self._next_id += 1
        rid = self._next_id
        fut: asyncio.Future[tuple[Any, float]] = asyncio.get_running_loop().create_future()
        self._pending[rid] = fut
        t0 = self._send({"jsonrpc": "2.0", "id": rid, "method": method, "params": params})
        await self._stdin.drain()
        result, at = await asyncio.wait_for(fut, timeout)
        self.last_answer_at = at
        return result, at - t0

    async def request(self, method: str, params: Any, timeout: float = 120.0) -> Any:
        return (await self.request_timed(method, params, timeout))[0]

    def expect_diagnostics(self, uri: str, version: int | None) -> asyncio.Future[Published]:
        """A future for the next diagnostics of ``uri`` with ``version`` (``None``: any);
        ask for it before sending the change that causes them."""
        fut: asyncio.Future[Published] = asyncio.get_running_loop().create_future()
        self._waiters.append((uri, version, fut))
        return fut

    def latest(self, uri: str) -> Published | None:
        return self._published.get(uri)

    async def complete(self, uri: str, code: str = "unknown-node") -> Published:
        """The first diagnostics of ``uri`` that hold ``code``: only the complete analysis
        reports ``unknown-node``, not the names published first."""
        while True:
            fut = self.expect_diagnostics(uri, 1)
            latest = self.latest(uri)
            if latest is not None and any(d.get("code") == code for d in latest.diagnostics):
                return latest
            await asyncio.wait_for(fut, 600)

    async def published_count(self, uri: str, count: int, timeout: float = 600.0) -> Published:
        """The latest diagnostics of ``uri`` once ``count`` publications of it arrived (a
        large document's name diagnostics come first, then the complete set); their
        ``at`` is when they were read, not when this noticed them."""
        loop = asyncio.get_running_loop()
        deadline = loop.time() + timeout
        while self.counts.get(uri, 0) < count:
            if loop.time() > deadline:
                raise TimeoutError(f"{count} publications of {uri}")
            if self._reader.done():
                raise ConnectionError("the server exited")
            await asyncio.sleep(0.005)
        return self._published[uri]

    async def initialize(
        self,
        root: str | None,
        options: Any = None,
        capabilities: dict[str, Any] | None = None,
    ) -> tuple[dict[str, Any], float]:
        """``initialize`` and ``initialized``; returns the result and its round trip."""
        params: dict[str, Any] = {
            "processId": os.getpid(),
            "rootUri": root,
            "workspaceFolders": [{"uri": root, "name": "bench"}] if root else None,
            "capabilities": capabilities if capabilities is not None else CAPABILITIES,
            "initializationOptions": options,
        }
        result, seconds = await self.request_timed("initialize", params)
        self.notify("initialized", {})
        await self._stdin.drain()
        return result, seconds

    async def drain(self) -> None:
        await self._stdin.drain()

    async def close(self, timeout: float = 10.0) -> None:
        """``shutdown`` and ``exit``; kills the server if it does not go."""
        self._closing = True
        with contextlib.suppress(Exception):
            await self.request("shutdown", None, timeout=timeout)
            self.notify("exit", None)
            await self._stdin.drain()
        try:
            await asyncio.wait_for(self.proc.wait(), timeout)
        except TimeoutError:
            self.proc.kill()
            await self.proc.wait()
        self._reader.cancel()
        with contextlib.suppress(asyncio.CancelledError, Exception):
            await self._reader
