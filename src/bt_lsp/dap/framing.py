"""The Debug Adapter Protocol's base framing: ``Content-Length: N`` headers, then N bytes.

The peer is an editor, but the bytes are still untrusted: a header line, the headers of
one message and a body are bounded; a frame that breaks the rules is reported as a
:class:`FrameError` and the reader goes on with the next ``Content-Length`` header, so
one bad message costs that message only.  A body over the limit is read past in chunks
(never held), which keeps the stream in step.
"""

from __future__ import annotations

import json
import re
import threading
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, BinaryIO, Final

MAX_BODY: Final = 16 * 1024 * 1024  # a setBreakpoints of a few thousand lines is ~100 KB
MAX_HEADER_LINE: Final = 1024
MAX_HEADERS: Final = 32
_CHUNK: Final = 1 << 16
_LENGTH: Final = re.compile(rb"content-length[ \t]*:[ \t]*([0-9]{1,12})[ \t]*", re.IGNORECASE)
_HEADER: Final = re.compile(rb"[!#$%&'*+\-.^_`|~0-9A-Za-z]+[ \t]*:.*")


@dataclass(frozen=True, slots=True)
class FrameError:
    """A frame that could not be read (it is skipped): what was wrong."""

    message: str


def _shown(data: bytes) -> str:
    text = repr(bytes(data[:60]))
    return text + ("..." if len(data) > 60 else "")


class FrameReader:
    """Reads frames through ``read(n)`` (blocking, up to n bytes, b"" at the end):
    :meth:`next` returns a body, a :class:`FrameError` for a frame it skipped, or None at
    the end of the input.  It keeps its own buffer, so ``read`` may be ``os.read`` on a
    descriptor (no lock a daemon thread could hold while the interpreter exits)."""

    def __init__(self, read: Callable[[int], bytes], max_body: int = MAX_BODY) -> None:
        self._read = read
        self._max_body = max_body
        self._buf = bytearray()
        self._eof = False
        self._held: bytes | None = None  # a whole message read after a reported error

    def _fill(self) -> bool:
        if self._eof:
            return False
        chunk = self._read(_CHUNK)
        if not chunk:
            self._eof = True
            return False
        self._buf += chunk
        return True

    def _line(self) -> bytes | None:
        """One header line without its end; None at the end of the input."""
        while True:
            i = self._buf.find(b"\n", 0, MAX_HEADER_LINE + 1)
            if i >= 0:
                line = bytes(self._buf[:i])
                del self._buf[: i + 1]
                return line.rstrip(b"\r")
            if len(self._buf) > MAX_HEADER_LINE:
                # Over the limit: drop the rest of the line, and call it an error.
                while (i := self._buf.find(b"\n")) < 0:
                    self._buf.clear()
                    if not self._fill():
                        return None
                del self._buf[: i + 1]
                return b"\xff"  # matches no header
            if not self._fill():
                return None

    def _take(self, n: int) -> bytes:
        while len(self._buf) < n and self._fill():
            pass
        data = bytes(self._buf[:n])
        del self._buf[:n]
        return data

    def _skip(self, n: int) -> None:
        while n > 0:
            if not self._buf and not self._fill():
                return
            k = min(n, len(self._buf))
            del self._buf[:k]
            n -= k

    def next(self) -> bytes | FrameError | None:
        if self._held is not None:
            body, self._held = self._held, None
            return body
        length: int | None = None
        problems: list[str] = []
        count = 0
        while True:
            line = self._line()
            if line is None:
                if problems or length is not None:
                    return FrameError("the input ended inside a message's headers")
                return None
            if line == b"":
                if length is None:
                    if count == 0 and not problems:
                        continue  # blank lines between messages
                    return FrameError("a message without a Content-Length header")
                break
            count += 1
            m = _LENGTH.fullmatch(line)
            if m is not None:
                length = int(m.group(1))
            elif not _HEADER.fullmatch(line) or count > MAX_HEADERS:
                problems.append(f"not a header: {_shown(line)}")
                length = None
                count = 0
                continue  # resynchronise on the next Content-Length
        if length > self._max_body:
            self._skip(length)
            return FrameError(f"a message of {length} bytes is over the {self._max_body} limit")
        body = self._take(length)
        if len(body) < length:
            return FrameError(f"the input ended {length - len(body)} bytes into a message")
        if problems:
            # What came before the message is reported first, then the message itself.
            self._held = body
            return FrameError("; ".join(problems[:3]) + " (skipped)")
        return body


def decode(body: bytes) -> dict[str, Any] | FrameError:
    """A body as a JSON object, or a FrameError saying why it is not one."""
    try:
        value = json.loads(body.decode("utf-8"))
    except (UnicodeDecodeError, ValueError, RecursionError) as e:
        return FrameError(f"a message that is not JSON: {e}"[:200])
    if not isinstance(value, dict):
        return FrameError(f"a message that is a JSON {type(value).__name__}, not an object")
    return value


def encode(message: dict[str, Any]) -> bytes:
    """One frame: the header and the UTF-8 JSON body (no NaN: DAP is strict JSON)."""
    body = json.dumps(message, ensure_ascii=False, allow_nan=False, separators=(",", ":"))
    data = body.encode("utf-8")
    return b"Content-Length: %d\r\n\r\n" % len(data) + data


class FrameWriter:
    """Writes frames to a binary stream, one whole frame at a time (thread-safe)."""

    def __init__(self, stream: BinaryIO) -> None:
        self._stream = stream
        self._lock = threading.Lock()

    def write(self, message: dict[str, Any]) -> None:
        data = encode(message)
        with self._lock:
            self._stream.write(data)
            self._stream.flush()
