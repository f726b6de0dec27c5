"""Starting ``executor.py`` for the live tests: a free pair of loopback ports and the
executor subprocess, whose printed lines are read with bounded waits."""

from __future__ import annotations

import contextlib
import os
import selectors
import socket
import subprocess
import sys
import time
from pathlib import Path

EXECUTOR = Path(__file__).parent / "executor.py"
LIFETIME = 25.0  # seconds an executor runs at most


def thread_names(pid: int) -> list[str]:
    """The names of process ``pid``'s threads now (Linux's /proc; ZeroMQ names its own
    ``ZMQbg/...``, Python's are the program's name)."""
    names = []
    for task in Path(f"/proc/{pid}/task").iterdir():
        with contextlib.suppress(OSError):  # (a thread that ended meanwhile)
            names.append((task / "comm").read_text().strip())
    return names


def free_port() -> int:
    """A port p with p and p + 1 free on 127.0.0.1 (the publisher binds both)."""
    for _ in range(50):
        with socket.socket() as a:
            a.bind(("127.0.0.1", 0))
            port = int(a.getsockname()[1])
            if port >= 65534:
                continue
            with socket.socket() as b:
                try:
                    b.bind(("127.0.0.1", port + 1))
                except OSError:
                    continue
        return port
    raise RuntimeError("no two free ports in a row")


class Executor:
    """The executor subprocess and the lines it prints (read unbuffered, so that a
    select on the pipe never misses lines already read into a buffer)."""

    def __init__(
        self, port: int, nodes: int = 0, lifetime: float = LIFETIME, tree: Path | None = None
    ) -> None:
        """``nodes``: a flat tree of that many nodes; ``tree``: the main tree of that file;
        else the small tree of ``executor.py``."""
        args = [sys.executable, str(EXECUTOR), str(port), str(lifetime)]
        if tree is not None:
            args.append(str(tree))
        elif nodes:
            args.append(str(nodes))
        self.proc = subprocess.Popen(args, stdout=subprocess.PIPE)
        assert self.proc.stdout is not None
        self._fd = self.proc.stdout.fileno()
        self._sel = selectors.DefaultSelector()
        self._sel.register(self._fd, selectors.EVENT_READ)
        self._lines: list[str] = []
        self._rest = b""
        assert self.line(10.0) == "ready"

    def _read(self, timeout: float) -> bool:
        if not self._sel.select(timeout):
            return False
        chunk = os.read(self._fd, 65536)
        if not chunk:
            return False
        *whole, self._rest = (self._rest + chunk).split(b"\n")
        self._lines += [w.decode().strip() for w in whole]
        return True

    def line(self, timeout: float) -> str | None:
        """The next line printed within ``timeout`` seconds, or None."""
        end = time.monotonic() + timeout
        while not self._lines:
            left = end - time.monotonic()
            if left <= 0 or not self._read(left):
                return None
        return self._lines.pop(0)

    def drain(self) -> list[str]:
        """Every line printed so far."""
        while self._read(0):
            pass
        lines, self._lines = self._lines, []
        return lines

    def wait_for(self, prefix: str, timeout: float) -> str | None:
        end = time.monotonic() + timeout
        while (left := end - time.monotonic()) > 0:
            line = self.line(left)
            if line is None:
                return None
            if line.startswith(prefix):
                return line
        return None

    def kill(self) -> None:
        if self.proc.poll() is None:
            self.proc.kill()
        self.proc.wait(5)
        self._sel.close()
        if self.proc.stdout is not None:
            self.proc.stdout.close()
