"""``bt-lsp debug-adapter``: the session over stdio.

A reader thread turns stdin into frames and queues them (bounded); the main thread owns
the session and the ZeroMQ link (which is not thread-safe), handling what is queued and,
in between, watching the executor for up to :data:`TICK` seconds.  Nothing but DAP
frames goes to stdout.  When stdin ends, the process is told to stop (SIGTERM) or the
client disconnects, the hooks are removed before exiting.
"""

from __future__ import annotations

import logging
import os
import queue
import signal
import sys
import threading
from collections.abc import Callable
from types import FrameType
from typing import Any, BinaryIO, Final

from bt_lsp.dap.framing import FrameError, FrameReader, FrameWriter, decode
from bt_lsp.dap.session import Connect, Link, ReadSource, Session
from bt_lsp.project.fileio import FileError, read_text

log = logging.getLogger(__name__)

TICK: Final = 0.05  # seconds: the longest a request waits while the executor is watched
INBOX: Final = 256  # frames queued at most (the reader waits when the loop is behind)


def groot2(host: str, port: int, timeout: float) -> Link:
    """A ZeroMQ link to an executor's Groot2 publisher (ImportError without pyzmq)."""
    from bt_lsp.live.client import Groot2Client

    return Groot2Client(host, port, timeout=timeout)


def read_file(path: str) -> str:
    try:
        return read_text(path).text
    except FileError as e:
        raise OSError(e.reason) from None


class _Output:
    """The frame writer, quiet once the client has gone (a broken pipe ends the loop)."""

    def __init__(self, stream: BinaryIO) -> None:
        self._writer = FrameWriter(stream)
        self.closed = False

    def send(self, message: dict[str, Any]) -> None:
        if self.closed:
            return
        try:
            self._writer.write(message)
        except (OSError, ValueError) as e:
            if isinstance(e, ValueError) and not isinstance(e, UnicodeError):
                log.error("a message that is not JSON was not sent: %s", e)
                return
            self.closed = True


def _read(reader: FrameReader, inbox: queue.Queue[bytes | FrameError | None]) -> None:
    try:
        while True:
            item = reader.next()
            inbox.put(item)
            if item is None:
                return
    except (OSError, ValueError) as e:  # stdin closed under us
        log.debug("stdin: %s", e)
        inbox.put(None)


def run(
    read: Callable[[int], bytes],
    stdout: BinaryIO,
    *,
    connect: Connect = groot2,
    read_source: ReadSource = read_file,
) -> int:
    """Serve one debugging session on ``read`` (see FrameReader) and ``stdout``;
    returns the exit status (0)."""
    output = _Output(stdout)
    session = Session(output.send, connect, read_source)
    inbox: queue.Queue[bytes | FrameError | None] = queue.Queue(INBOX)
    reader = threading.Thread(
        target=_read, args=(FrameReader(read), inbox), name="dap-stdin", daemon=True
    )
    reader.start()

    def stop(signum: int, frame: FrameType | None) -> None:
        raise SystemExit(0)

    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGTERM, stop)
    try:
        while not session.done and not output.closed:
            waited = session.poll(TICK)
            try:
                item = inbox.get_nowait() if waited else inbox.get(timeout=TICK)
            except queue.Empty:
                continue
            while True:
                if item is None:
                    return 0
                if isinstance(item, FrameError):
                    session.frame_error(item.message)
                else:
                    message = decode(item)
                    if isinstance(message, FrameError):
                        session.frame_error(message.message)
                    else:
                        session.handle(message)
                if session.done:
                    break
                try:
                    item = inbox.get_nowait()
                except queue.Empty:
                    break
        return 0
    finally:
        session.shutdown()


def main() -> int:
    """Run on this process's stdin and stdout (stdout carries the frames only)."""
    fd, stdout = sys.stdin.fileno(), sys.stdout.buffer
    sys.stdout = sys.stderr  # a stray print must not corrupt the protocol
    logging.basicConfig(stream=sys.stderr, level=logging.WARNING)
    return run(lambda n: os.read(fd, n), stdout)
