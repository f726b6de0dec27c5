"""A bounded MessagePack decoder for the executor's blackboard dumps.

BehaviorTree.CPP answers BLACKBOARD with ``nlohmann::json::to_msgpack``.  The input is
untrusted, so every length is checked against what is left of the buffer, nesting and the
count of values are capped, and anything malformed raises :class:`MsgPackError` (never
another exception).  Extension and binary values decode to ``bytes`` (ext: its data only).
"""

from __future__ import annotations

import struct
from typing import Any, Final

MAX_DEPTH: Final = 64
MAX_ITEMS: Final = 1_000_000


class MsgPackError(ValueError):
    """Not valid MessagePack, or over a bound."""


_FIXED: Final = {
    0xCC: struct.Struct(">B"),
    0xCD: struct.Struct(">H"),
    0xCE: struct.Struct(">I"),
    0xCF: struct.Struct(">Q"),
    0xD0: struct.Struct(">b"),
    0xD1: struct.Struct(">h"),
    0xD2: struct.Struct(">i"),
    0xD3: struct.Struct(">q"),
    0xCA: struct.Struct(">f"),
    0xCB: struct.Struct(">d"),
}
_LENGTHS: Final = {1: struct.Struct(">B"), 2: struct.Struct(">H"), 4: struct.Struct(">I")}


class _Reader:
    __slots__ = ("data", "items", "pos")

    def __init__(self, data: bytes) -> None:
        self.data = data
        self.pos = 0
        self.items = 0

    def take(self, n: int) -> bytes:
        end = self.pos + n
        if end > len(self.data):
            raise MsgPackError(f"truncated at byte {self.pos} (needs {n} more)")
        chunk = self.data[self.pos : end]
        self.pos = end
        return chunk

    def length(self, size: int) -> int:
        value: int = _LENGTHS[size].unpack(self.take(size))[0]
        return value

    def count(self, n: int) -> int:
        # Each element takes at least one byte: a count larger than what is left is a lie.
        self.items += n
        if n > len(self.data) - self.pos or self.items > MAX_ITEMS:
            raise MsgPackError(f"a container of {n} elements cannot fit")
        return n

    def value(self, depth: int) -> Any:
        if depth > MAX_DEPTH:
            raise MsgPackError("nested too deep")
        b = self.take(1)[0]
        if b <= 0x7F:
            return b
        if b >= 0xE0:
            return b - 0x100
        if 0xA0 <= b <= 0xBF:
            return self.text(b & 0x1F)
        if 0x90 <= b <= 0x9F:
            return self.array(b & 0x0F, depth)
        if 0x80 <= b <= 0x8F:
            return self.map(b & 0x0F, depth)
        if b == 0xC0:
            return None
        if b == 0xC2:
            return False
        if b == 0xC3:
            return True
        fixed = _FIXED.get(b)
        if fixed is not None:
            return fixed.unpack(self.take(fixed.size))[0]
        if b in (0xD9, 0xDA, 0xDB):
            return self.text(self.length(1 << (b - 0xD9)))
        if b in (0xC4, 0xC5, 0xC6):
            return self.take(self.length(1 << (b - 0xC4)))
        if b in (0xDC, 0xDD):
            return self.array(self.length(2 if b == 0xDC else 4), depth)
        if b in (0xDE, 0xDF):
            return self.map(self.length(2 if b == 0xDE else 4), depth)
        if b in (0xD4, 0xD5, 0xD6, 0xD7, 0xD8):  # fixext 1..16: type, data
            self.take(1)
            return self.take(1 << (b - 0xD4))
        if b in (0xC7, 0xC8, 0xC9):  # ext 8/16/32: length, type, data
            n = self.length(1 << (b - 0xC7))
            self.take(1)
            return self.take(n)
        raise MsgPackError(f"byte 0x{b:02x} starts no value")

    def text(self, n: int) -> str:
        try:
            return self.take(n).decode("utf-8")
        except UnicodeDecodeError:
            raise MsgPackError("a string is not UTF-8") from None

    def array(self, n: int, depth: int) -> list[Any]:
        return [self.value(depth + 1) for _ in range(self.count(n))]

    def map(self, n: int, depth: int) -> dict[Any, Any]:
        out: dict[Any, Any] = {}
        for _ in range(self.count(n)):
            key = self.value(depth + 1)
            if isinstance(key, (list, dict)):
                raise MsgPackError("a map key is a container")
            out[key] = self.value(depth + 1)
        return out


def unpackb(data: bytes) -> Any:
    """Decode exactly one value that fills ``data``."""
    reader = _Reader(bytes(data))
    value = reader.value(0)
    if reader.pos != len(reader.data):
        raise MsgPackError(f"{len(reader.data) - reader.pos} bytes after the value")
    return value
