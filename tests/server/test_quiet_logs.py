"""Quiet, exact logs: ``bt-lsp serve`` driven over raw stdio, as an editor does, with its
stderr read.  A refused rename is an ordinary error answer (no traceback on stderr, no
error-level logMessage); VS Code's didChangeConfiguration right after ``initialized``
causes no second workspace/configuration request; ``codeDescription`` goes only to
clients that declare ``codeDescriptionSupport``."""

from __future__ import annotations

import asyncio
import json
import os
import sys
import tempfile
from typing import Any

import pytest

pytestmark = pytest.mark.asyncio(loop_scope="function")

URI = "file:///ws/pick.xml"
TEXT = (
    '<root BTCPP_format="4" main_tree_to_execute="Main">\n'
    '  <BehaviorTree ID="Main">\n'
    '    <SubTree ID="Open Right Gripper"/>\n'
    "  </BehaviorTree>\n"
    "</root>\n"
)
TIMEOUT = 30.0


class Session:
    """A server process and what it sent: answers by id, requests and notifications."""

    def __init__(self, proc: asyncio.subprocess.Process) -> None:
        self.proc = proc
        self.answers: dict[int, dict[str, Any]] = {}
        self.requests: list[dict[str, Any]] = []
        self.notifications: list[dict[str, Any]] = []
        self._next = 0
        self._reader = asyncio.create_task(self._read())
        self._changed = asyncio.Event()

    def send(self, message: dict[str, Any]) -> None:
        body = json.dumps({"jsonrpc": "2.0", **message}).encode()
        assert self.proc.stdin is not None
        self.proc.stdin.write(b"Content-Length: %d\r\n\r\n" % len(body) + body)

    def request(self, method: str, params: Any) -> int:
        self._next += 1
        self.send({"id": self._next, "method": method, "params": params})
        return self._next

    def notify(self, method: str, params: Any) -> None:
        self.send({"method": method, "params": params})

    async def _read(self) -> None:
        out = self.proc.stdout
        assert out is not None
        while True:
            header = await out.readuntil(b"\r\n\r\n")
            length = next(
                int(line.split(b":")[1])
                for line in header.split(b"\r\n")
                if line.lower().startswith(b"content-length")
            )
            msg = json.loads(await out.readexactly(length))
            if "method" in msg and "id" in msg:
                self.requests.append(msg)
            elif "method" in msg:
                self.notifications.append(msg)
            else:
                self.answers[msg["id"]] = msg
            self._changed.set()

    async def until(self, check: Any) -> Any:
        async def wait() -> Any:
            while True:
                found = check()
                if found:
                    return found
                self._changed.clear()
                await self._changed.wait()

        return await asyncio.wait_for(wait(), TIMEOUT)

    async def answer(self, msg_id: int) -> dict[str, Any]:
        return await self.until(lambda: self.answers.get(msg_id))

    async def close(self) -> str:
        """Shut down and exit; the server's stderr."""
        await self.answer(self.request("shutdown", None))
        self.notify("exit", None)
        self._reader.cancel()
        assert self.proc.stderr is not None
        err = await asyncio.wait_for(self.proc.stderr.read(), TIMEOUT)
        await asyncio.wait_for(self.proc.wait(), TIMEOUT)
        return err.decode("utf-8", "replace")


async def start(capabilities: dict[str, Any]) -> Session:
    cache = tempfile.mkdtemp(prefix="bt-lsp-quiet-cache-")
    proc = await asyncio.create_subprocess_exec(
        sys.executable,
        "-m",
        "bt_lsp",
        "serve",
        stdin=asyncio.subprocess.PIPE,
        stdout=asyncio.subprocess.PIPE,
        stderr=asyncio.subprocess.PIPE,
        env={**os.environ, "XDG_CACHE_HOME": cache},
    )
    s = Session(proc)
    await s.answer(
        s.request(
            "initialize",
            {
                "processId": None,
                "rootUri": None,
                "capabilities": capabilities,
                "initializationOptions": {"debounceMs": 0},
            },
        )
    )
    return s


def _open(s: Session) -> None:
    s.notify(
        "textDocument/didOpen",
        {"textDocument": {"uri": URI, "languageId": "xml", "version": 1, "text": TEXT}},
    )


async def _diagnostics(s: Session) -> list[dict[str, Any]]:
    def published() -> list[dict[str, Any]] | None:
        for n in reversed(s.notifications):
            if n["method"] == "textDocument/publishDiagnostics" and n["params"]["uri"] == URI:
                return n["params"]["diagnostics"]
        return None

    return await s.until(published)


async def test_a_refused_rename_is_a_quiet_error_answer() -> None:
    # No codeDescriptionSupport declared: the diagnostics carry no codeDescription.
    s = await start({"textDocument": {"rename": {"prepareSupport": True}}})
    s.notify("initialized", {})
    _open(s)
    diags = await _diagnostics(s)
    assert diags and all("codeDescription" not in d for d in diags), diags
    col = TEXT.splitlines()[2].index("Open") + 2
    answer = await s.answer(
        s.request(
            "textDocument/rename",
            {
                "textDocument": {"uri": URI},
                "position": {"line": 2, "character": col},
                "newName": "X",
            },
        )
    )
    assert answer.get("result") is None
    assert answer["error"]["code"] == -32803  # RequestFailed
    assert answer["error"]["message"].startswith(
        "Cannot rename the tree 'Open Right Gripper': the tree 'Open Right Gripper' is not "
        "defined in the workspace"
    )
    # Still serving.
    hover = await s.answer(
        s.request(
            "textDocument/hover",
            {"textDocument": {"uri": URI}, "position": {"line": 2, "character": col}},
        )
    )
    assert hover["result"] is not None
    err = await s.close()
    assert "Traceback" not in err and "RequestFailed" not in err, err
    levels = [n["params"]["type"] for n in s.notifications if n["method"] == "window/logMessage"]
    assert 1 not in levels  # no error-level log message
    assert not any(n["method"] == "window/showMessage" for n in s.notifications)


async def test_one_configuration_request_after_initialized() -> None:
    s = await start(
        {
            "workspace": {"configuration": True, "didChangeConfiguration": {}},
            "textDocument": {"publishDiagnostics": {"codeDescriptionSupport": True}},
        }
    )
    s.notify("initialized", {})
    # VS Code's language client says the configuration changed right after initialized,
    # before it answers the server's request.
    s.notify("workspace/didChangeConfiguration", {"settings": None})

    def asked(n: int) -> list[dict[str, Any]] | None:
        found = [r for r in s.requests if r["method"] == "workspace/configuration"]
        return found if len(found) >= n else None

    (first,) = await s.until(lambda: asked(1))
    await asyncio.sleep(0.5)  # a second request would have been sent by now
    assert len(asked(1) or []) == 1
    s.send({"id": first["id"], "result": [{"debounceMs": 0}]})
    _open(s)
    diags = await _diagnostics(s)
    # The client declared codeDescriptionSupport: each diagnostic links to its code.
    assert diags
    for d in diags:
        assert d["codeDescription"]["href"].endswith(f"/rules/{d['code']}/"), d
    assert len(asked(1) or []) == 1
    # A change after the answer asks again.
    s.notify("workspace/didChangeConfiguration", {"settings": None})
    second = (await s.until(lambda: asked(2)))[1]
    s.send({"id": second["id"], "result": [{}]})
    await s.close()
