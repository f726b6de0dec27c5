"""The base protocol's framing, read so that one bad message costs only that message.

pygls's reader matches ``Content-Length: N\\r\\n`` exactly and, on anything else, waits for
a header it will never see again, so one miscounted length made the server deaf; a length
of 100 GB was allocated.  Here header names are case-insensitive (they are HTTP-style
headers), lines may end in LF alone, and after a framing error the reader says what it saw
and resynchronises on the next ``Content-Length`` header.  A length above
:data:`MAX_BODY` is refused without reading the body into memory.

A body that is not one JSON value (or one nested too deeply for the decoder, whose
RecursionError ended the server) is answered as JSON-RPC asks (see
:func:`bt_lsp.server.jsonrpc.check_message`); a length a few bytes off is recovered when
the bytes around the body show where the message really ends.
"""

from __future__ import annotations

import json
import re
from collections.abc import Awaitable, Callable
from dataclasses import dataclass

MAX_BODY = 1 << 30  # bytes; far above any document bt-lsp analyses (maxDocumentBytes)
MAX_HEADER_LINE = 8192  # bytes; real headers are a few dozen
CHUNK = 1 << 16
MARKER = re.compile(rb"content-length[ \t]*:", re.IGNORECASE)
TOKEN = re.compile(rb"[!#$%&'*+\-.^_`|~0-9A-Za-z]+")
_SHOWN = 120  # bytes of what was seen quoted in a log message


def shown(data: bytes) -> str:
    """A short printable quotation of raw bytes for the log."""
    text = repr(bytes(data[:_SHOWN]))
    return text + ("..." if len(data) > _SHOWN else "")


class Stream:
    """A byte stream read in chunks, with lines, exact reads, a pushback and resync."""

    def __init__(
        self,
        read: Callable[[int], Awaitable[bytes]],
        read_exact: Callable[[int], Awaitable[bytes]] | None = None,
    ) -> None:
        self._read = read
        # Reads that many bytes unless the input ends first: a large body in one call,
        # not a chunk of the pipe's size per call (each a hop to a reading thread).
        self._read_exact = read_exact
        self._buf = bytearray()
        self.eof = False

    async def _fill(self) -> bool:
        if self.eof:
            return False
        chunk = await self._read(CHUNK)
        if not chunk:
            self.eof = True
            return False
        self._buf += chunk
        return True

    @property
    def buffered(self) -> bytes:
        return bytes(self._buf)

    def peek(self, n: int) -> bytes:
        """The next ``n`` bytes read but not taken (fewer if fewer are)."""
        return bytes(self._buf[:n])

    def drop(self, n: int) -> None:
        del self._buf[:n]

    def unread(self, data: bytes) -> None:
        self._buf[:0] = data

    async def line(self, limit: int) -> bytes | None:
        """The next line with its end; ``None`` at the end of input.  A line longer than
        ``limit`` is returned cut at ``limit`` without its end (the caller resyncs)."""
        start = 0
        while True:
            end = self._buf.find(b"\n", start)
            if end >= 0:
                out = bytes(self._buf[: end + 1])
                del self._buf[: end + 1]
                return out
            if len(self._buf) > limit:
                out = bytes(self._buf[:limit])
                del self._buf[:limit]
                return out
            start = len(self._buf)
            if not await self._fill():
                if not self._buf:
                    return None
                out = bytes(self._buf)
                self._buf.clear()
                return out

    async def exactly(self, n: int) -> bytes | None:
        """``n`` bytes, or ``None`` if the input ends first."""
        missing = n - len(self._buf)
        if missing > CHUNK and self._read_exact is not None and not self.eof:
            chunk = await self._read_exact(missing)
            self._buf += chunk
            if len(chunk) < missing:
                self.eof = True
        while len(self._buf) < n:
            if not await self._fill():
                return None
        out = bytes(self._buf[:n])
        del self._buf[:n]
        return out

    async def skip_to_header(self, keep: int = MAX_BODY) -> bytes:
        """Drop everything before the next ``Content-Length`` header (or to the end of
        input) and return what was dropped, its first ``keep`` bytes only."""
        skipped = bytearray()
        while True:
            found = MARKER.search(self._buf)
            if found is not None:
                cut = found.start()
            elif self.eof:
                cut = len(self._buf)
            else:
                # Keep a tail that may be the start of a header cut by the chunk.
                cut = max(0, len(self._buf) - 32)
            if len(skipped) < keep:
                skipped += self._buf[: min(cut, keep - len(skipped))]
            del self._buf[:cut]
            if found is not None or self.eof:
                return bytes(skipped)
            await self._fill()


@dataclass(slots=True)
class Body:
    """One message read from the stream: its JSON value, or why there is none."""

    value: object = None
    error: str | None = None  # set when the body is not JSON (-32700)


Log = Callable[[str], None]


class Framer:
    """Reads message bodies from a :class:`Stream`, recovering from framing errors."""

    def __init__(self, stream: Stream, log: Log) -> None:
        self.stream = stream
        self.log = log

    def _framing_error(self, what: str, seen: bytes) -> None:
        self.log(f"bt-lsp: framing error: {what}; saw {shown(seen)}; looking for the next header")

    async def next(self) -> Body | None:
        """The next message, ``None`` at the end of input."""
        while True:
            headers = await self._headers()
            if headers is None:
                return None
            fields, seen = headers
            length = fields.get(b"content-length")
            if length is None:
                body = await self._without_length(seen)
                if body is not None:
                    return body
                continue
            if not length.isdigit() or len(length) > 12:
                self._framing_error("Content-Length is not a number", seen)
                await self.stream.skip_to_header(0)
                continue
            n = int(length)
            if n > MAX_BODY:
                self._framing_error(f"Content-Length {n} is above {MAX_BODY}, refused", seen)
                await self.stream.skip_to_header(0)
                continue
            raw = await self.stream.exactly(n)
            if raw is None:
                return None
            body = await self._decode(raw, n, seen)
            if body is not None:
                return body

    async def _headers(self) -> tuple[dict[bytes, bytes], bytes] | None:
        fields: dict[bytes, bytes] = {}
        seen = bytearray()
        while True:
            line = await self.stream.line(MAX_HEADER_LINE)
            if line is None:
                return None
            text = line.rstrip(b"\r\n")
            if not text.strip():
                if not seen:
                    continue  # blank lines between messages
                return fields, bytes(seen)
            seen += line
            name, sep, value = text.partition(b":")
            if not sep or not TOKEN.fullmatch(name.strip()) or not line.endswith(b"\n"):
                self._framing_error("not a header line", bytes(seen))
                found = MARKER.search(line, 1)
                if found is not None:
                    self.stream.unread(line[found.start() :])
                else:
                    await self.stream.skip_to_header(0)
                fields.clear()
                seen.clear()
                continue
            fields[name.strip().lower()] = value.strip()

    async def _without_length(self, seen: bytes) -> Body | None:
        """Headers without Content-Length: the JSON value that follows, if it is whole
        in what has been read, else nothing up to the next header."""
        self._framing_error("no Content-Length header", seen)
        pending = self.stream.buffered
        lead = len(pending) - len(pending.lstrip())
        try:
            text = pending[lead:].decode("utf-8")
            value, end = json.JSONDecoder().raw_decode(text)
        except (ValueError, UnicodeDecodeError, RecursionError):
            await self.stream.skip_to_header(0)
            return None
        self.stream.drop(lead + len(text[:end].encode("utf-8")))
        return Body(value)

    async def _decode(self, raw: bytes, n: int, seen: bytes) -> Body | None:
        """The message whose body is ``raw``, as far as it can be told from the bytes
        around it; ``None`` if there is no body (the caller reads the next message)."""
        try:
            return Body(json.loads(raw))
        except (ValueError, UnicodeDecodeError):
            pass
        except RecursionError:  # valid JSON, perhaps, but nested past Python's stack
            return Body(error=f"JSON nested too deeply to be read: {shown(raw)}")
        if MARKER.match((raw[:64] + self.stream.peek(32)).lstrip()):
            # No body at all: the length ran into the next message's header (after a
            # repeated Content-Length, say), which is read as the next message.
            self._framing_error(f"Content-Length {n} but no body", seen)
            self.stream.unread(raw)
            return None
        text = raw.decode("utf-8", "replace")
        stripped = text.lstrip()
        try:
            value, end = json.JSONDecoder().raw_decode(stripped)
        except (ValueError, RecursionError):
            value, end = None, -1
        if end >= 0:
            # The body holds a whole value and then more: the length was too long, and
            # the extra bytes are the start of the next message.
            extra = stripped[end:].encode("utf-8")
            self.log(f"bt-lsp: framing error: Content-Length {n} is {len(extra)} bytes too long")
            self.stream.unread(extra)
            return Body(value)
        pending = self.stream.buffered.lstrip()
        if not pending or MARKER.match(pending):
            return Body(error=f"invalid JSON: {shown(raw)}")
        # More of this message follows before the next header: the length was short.
        tail = await self.stream.skip_to_header(MAX_HEADER_LINE)
        try:
            value = json.loads(raw + tail)
        except (ValueError, UnicodeDecodeError, RecursionError):
            self._framing_error(f"Content-Length {n} does not end a JSON value", raw + tail)
            return Body(error=f"invalid JSON: {shown(raw)}")
        self.log(f"bt-lsp: framing error: Content-Length {n} is {len(tail.rstrip())} bytes short")
        return Body(value)
