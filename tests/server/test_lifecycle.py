"""Process lifecycle over raw stdio: shutdown + exit ends with 0 promptly, requests after
shutdown get InvalidRequest, exit without shutdown ends with 1, EOF ends the server."""

from __future__ import annotations

import json
import subprocess
import sys
import time
from typing import Any

SERVER = [sys.executable, "-m", "bt_lsp", "serve"]
INIT = {
    "jsonrpc": "2.0",
    "id": 1,
    "method": "initialize",
    "params": {"capabilities": {}, "processId": None, "rootUri": None},
}


def frame(obj: dict[str, Any]) -> bytes:
    body = json.dumps(obj).encode()
    return b"Content-Length: %d\r\n\r\n" % len(body) + body


def responses(stdout: bytes) -> dict[int, dict[str, Any]]:
    out: dict[int, dict[str, Any]] = {}
    while stdout:
        head, _, rest = stdout.partition(b"\r\n\r\n")
        length = int(head.split(b"Content-Length:")[1].split(b"\r\n")[0])
        msg = json.loads(rest[:length])
        stdout = rest[length:]
        if "id" in msg and "method" not in msg:
            out[msg["id"]] = msg
    return out


def run(messages: list[dict[str, Any]]) -> tuple[int, dict[int, dict[str, Any]], float]:
    start = time.monotonic()
    proc = subprocess.run(
        SERVER, input=b"".join(frame(m) for m in messages), capture_output=True, timeout=60
    )
    return proc.returncode, responses(proc.stdout), time.monotonic() - start


def test_shutdown_then_exit_and_requests_after_shutdown() -> None:
    rc, res, _ = run(
        [
            INIT,
            {"jsonrpc": "2.0", "id": 2, "method": "shutdown"},
            {
                "jsonrpc": "2.0",
                "id": 3,
                "method": "textDocument/hover",
                "params": {
                    "textDocument": {"uri": "file:///x.xml"},
                    "position": {"line": 0, "character": 0},
                },
            },
            {"jsonrpc": "2.0", "method": "exit"},
        ]
    )
    assert rc == 0
    assert res[2]["result"] is None
    assert res[3]["error"]["code"] == -32600


def test_exit_without_shutdown_is_status_1() -> None:
    rc, res, _ = run([INIT, {"jsonrpc": "2.0", "method": "exit"}])
    assert rc == 1 and 1 in res


def test_end_of_input_ends_the_server() -> None:
    rc, res, _ = run([INIT])
    assert 1 in res and rc in (0, 1)
