"""A small Debug Adapter Protocol client for the tests: ``bt-lsp debug-adapter`` in a
subprocess, frames over its pipes, every wait bounded."""

from __future__ import annotations

import json
import os
import selectors
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

SRC = Path(__file__).resolve().parents[2] / "src"


class DapClient:
    def __init__(self) -> None:
        env = dict(os.environ, PYTHONPATH=str(SRC))
        self.stderr = tempfile.TemporaryFile()  # noqa: SIM115  (closed by close())
        self.proc = subprocess.Popen(
            [sys.executable, "-m", "bt_lsp", "debug-adapter"],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            stderr=self.stderr,
            env=env,
        )
        self.eof = False
        assert self.proc.stdout is not None
        self._fd = self.proc.stdout.fileno()
        self._sel = selectors.DefaultSelector()
        self._sel.register(self._fd, selectors.EVENT_READ)
        self._buf = b""
        self._seq = 0
        self.messages: list[dict[str, Any]] = []  # read, not yet consumed
        self.seen: list[dict[str, Any]] = []  # every message read

    # ---------------------------------------------------------------- wire

    def send_raw(self, data: bytes) -> None:
        assert self.proc.stdin is not None
        self.proc.stdin.write(data)
        self.proc.stdin.flush()

    def send(self, command: str, **arguments: Any) -> int:
        self._seq += 1
        body = json.dumps(
            {"seq": self._seq, "type": "request", "command": command, "arguments": arguments}
        ).encode()
        self.send_raw(b"Content-Length: %d\r\n\r\n" % len(body) + body)
        return self._seq

    def _frame(self) -> dict[str, Any] | None:
        head, sep, rest = self._buf.partition(b"\r\n\r\n")
        if not sep:
            return None
        length = int(head.split(b":", 1)[1])
        if len(rest) < length:
            return None
        self._buf = rest[length:]
        message: dict[str, Any] = json.loads(rest[:length])
        self.seen.append(message)
        return message

    def _read(self, timeout: float) -> bool:
        if not self._sel.select(timeout):
            return False
        chunk = os.read(self._fd, 65536)
        if not chunk:
            self.eof = True
            return False
        self._buf += chunk
        while (message := self._frame()) is not None:
            self.messages.append(message)
        return True

    def wait(self, match: Any, timeout: float = 10.0) -> dict[str, Any]:
        """The first message (read since, or already waiting) that ``match`` accepts."""
        end = time.monotonic() + timeout
        while True:
            for i, message in enumerate(self.messages):
                if match(message):
                    return self.messages.pop(i)
            left = end - time.monotonic()
            if left <= 0 or self.eof:
                raise AssertionError(
                    f"no such message within {timeout} s; seen: {self.seen[-8:]}; "
                    f"stderr: {self.errors()[-2000:]}"
                )
            self._read(left)

    def request(self, command: str, timeout: float = 10.0, **arguments: Any) -> dict[str, Any]:
        seq = self.send(command, **arguments)
        return self.wait(
            lambda m: m.get("type") == "response" and m.get("request_seq") == seq, timeout
        )

    def event(self, name: str, timeout: float = 10.0, **fields: Any) -> dict[str, Any]:
        def match(m: dict[str, Any]) -> bool:
            body = m.get("body") or {}
            return (
                m.get("type") == "event"
                and m.get("event") == name
                and all(body.get(k) == v for k, v in fields.items())
            )

        return self.wait(match, timeout)

    def no_event(self, name: str, within: float) -> bool:
        try:
            self.event(name, within)
        except AssertionError:
            return True
        return False

    def output(self) -> str:
        return "".join(m["body"]["output"] for m in self.seen if m.get("event") == "output")

    def errors(self) -> str:
        self.stderr.seek(0)
        return self.stderr.read().decode(errors="replace")

    # ---------------------------------------------------------------- session

    def start(self, port: int) -> None:
        init = self.request("initialize", adapterID="bt", linesStartAt1=True)
        assert init["success"], init
        self.event("initialized")
        attach = self.request("attach", host="127.0.0.1", port=port)
        assert attach["success"], attach

    def close(self) -> None:
        if self.proc.poll() is None:
            try:
                assert self.proc.stdin is not None
                self.proc.stdin.close()
                self.proc.wait(5)
            except (OSError, subprocess.TimeoutExpired):
                self.proc.kill()
                self.proc.wait(5)
        self._sel.close()
        if self.proc.stdout is not None:
            self.proc.stdout.close()
        self.stderr.close()
