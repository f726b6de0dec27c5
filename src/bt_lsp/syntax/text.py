"""Line index and LSP position conversion over Python strings.

Offsets are code-point indices into a ``str``. Positions are ``(line, character)`` pairs
where ``character`` counts code units of the negotiated position encoding: UTF-8 bytes,
UTF-16 code units (a character outside the Basic Multilingual Plane counts 2) or UTF-32
code units (code points).

Only LSP's line ends are line ends: ``\\n``, ``\\r\\n`` and ``\\r``. ``str.splitlines``
also splits on U+2028, U+2029, U+0085, ``\\x0b``, ``\\x0c`` and ``\\x1c``-``\\x1e``; here
those are ordinary characters.

Conversions clamp instead of raising, so positions sent by a client never crash a caller.
This module is pure: it does not import any LSP library.
"""

from __future__ import annotations

from array import array
from bisect import bisect_left, bisect_right
from collections.abc import Iterable, Iterator, Mapping, Sequence
from itertools import accumulate, count
from operator import add
from types import MappingProxyType
from typing import Final, Literal, overload

__all__ = ["Encoding", "LineIndex", "Offsets", "normalize_encoding", "positions_of"]

Encoding = Literal["utf-8", "utf-16", "utf-32"]

_ENCODINGS: Final[Mapping[str, Encoding]] = MappingProxyType(
    {
        "utf-8": "utf-8",
        "utf8": "utf-8",
        "utf-16": "utf-16",
        "utf16": "utf-16",
        "utf-32": "utf-32",
        "utf32": "utf-32",
    }
)

# Codec name (no byte-order mark) and bytes per code unit, per encoding.
_CODECS: Final[Mapping[str, tuple[str, int]]] = MappingProxyType(
    {
        "utf-8": ("utf-8", 1),
        "utf-16": ("utf-16-le", 2),
        "utf-32": ("utf-32-le", 4),
    }
)


def normalize_encoding(value: object) -> Encoding:
    """Map a position encoding to an :data:`Encoding`.

    Accepts lsprotocol's ``PositionEncodingKind`` members (a ``str`` enum) and plain
    strings such as ``"utf-8"``, case-insensitively. Anything else means ``"utf-16"``,
    LSP's default.
    """
    raw = getattr(value, "value", value)
    if isinstance(raw, str):
        return _ENCODINGS.get(raw.strip().lower(), "utf-16")
    return "utf-16"


def _line_starts(text: str) -> list[int]:
    """Offsets of every line start after the first (which is always 0), in C-level loops."""
    if "\r" in text:
        # Same length, and every line end becomes one "\n" at its last character.
        text = text.replace("\r\n", " \n").replace("\r", "\n")
    pieces = text.split("\n")
    pieces.pop()
    # Line k + 1 starts after k + 1 pieces and k + 1 "\n"s.
    return list(map(add, accumulate(map(len, pieces)), count(1)))


def _column(text: str, start: int, offset: int, encoding: Encoding) -> int:
    """The character of ``offset`` on the line that starts at ``start``."""
    if encoding == "utf-32":
        return offset - start
    segment = text[start:offset]
    if segment.isascii():
        return offset - start
    codec, unit = _CODECS[encoding]
    return len(segment.encode(codec, "surrogatepass")) // unit


def positions_of(
    text: str, offsets: Iterable[int], encoding: Encoding
) -> dict[int, tuple[int, int]]:
    """``LineIndex(text).position(offset, encoding)`` of each of ``offsets``, without
    making the index: for a few offsets of a long text, C-level counts of the line ends
    from one offset to the next cost less."""
    if "\r" in text:  # line ends of every kind: the index knows them
        lines = LineIndex(text)
        return {o: lines.position(o, encoding) for o in offsets}
    out: dict[int, tuple[int, int]] = {}
    line = previous = 0
    n = len(text)
    for o in sorted(set(offsets)):
        at = min(max(o, 0), n)
        line += text.count("\n", previous, at)
        previous = at
        out[o] = (line, _column(text, text.rfind("\n", 0, at) + 1, at, encoding))
    return out


def _unit_width(char: str, encoding: Encoding) -> int:
    """Code units of one code point (a lone surrogate counts as one code point)."""
    code = ord(char)
    if encoding == "utf-16":
        return 2 if code > 0xFFFF else 1
    if encoding == "utf-8":
        if code < 0x80:
            return 1
        if code < 0x800:
            return 2
        return 3 if code < 0x10000 else 4
    return 1


class Offsets(Sequence[int]):
    """A sorted list of offsets (the starts of a scan's tokens, of a text's lines), in
    blocks: each block holds a run of offsets relative to its first one, as an array of
    machine integers.  After an edit only the blocks around it are made again
    (:meth:`replaced`); the others are shared with the old list, only their base offsets
    and first indexes move.  So an edit does not touch every offset after it, and an
    offset takes 8 bytes, not an ``int`` object."""

    __slots__ = ("_bases", "_blocks", "_firsts", "_n")

    BLOCK = 512

    def __init__(self, bases: list[int], firsts: list[int], blocks: list[array[int]]) -> None:
        self._bases = bases  # the offset of each block's first token
        self._firsts = firsts  # the index of each block's first token
        self._blocks = blocks
        self._n = firsts[-1] + len(blocks[-1]) if blocks else 0

    @classmethod
    def of(cls, starts: Sequence[int]) -> Offsets:
        bases: list[int] = []
        firsts: list[int] = []
        blocks: list[array[int]] = []
        size = cls.BLOCK
        for i in range(0, len(starts), size):
            base = starts[i]
            bases.append(base)
            firsts.append(i)
            blocks.append(array("q", map((-base).__add__, starts[i : i + size])))
        return cls(bases, firsts, blocks)

    def __len__(self) -> int:
        return self._n

    @overload
    def __getitem__(self, i: int) -> int: ...
    @overload
    def __getitem__(self, i: slice) -> list[int]: ...
    def __getitem__(self, i: int | slice) -> int | list[int]:
        if isinstance(i, slice):
            return self.tolist()[i]
        if i < 0:
            i += self._n
        if not 0 <= i < self._n:
            raise IndexError(i)
        b = bisect_right(self._firsts, i) - 1
        return self._bases[b] + self._blocks[b][i - self._firsts[b]]

    def __iter__(self) -> Iterator[int]:
        for base, block in zip(self._bases, self._blocks, strict=True):
            yield from map(base.__add__, block)

    def __eq__(self, other: object) -> bool:
        if isinstance(other, Offsets | list | tuple):
            return self.tolist() == list(other)
        return NotImplemented

    __hash__ = None  # type: ignore[assignment]

    def __repr__(self) -> str:
        return f"Offsets({self.tolist()!r})"

    def tolist(self) -> list[int]:
        out: list[int] = []
        for base, block in zip(self._bases, self._blocks, strict=True):
            out.extend(map(base.__add__, block))
        return out

    def toarray(self) -> array[int]:
        """The offsets in one array of machine integers (made block by block, in C)."""
        out = array("q")
        for base, block in zip(self._bases, self._blocks, strict=True):
            out.extend(map(base.__add__, block) if base else block)
        return out

    def bisect_right(self, offset: int) -> int:
        """The number of offsets at or before ``offset`` (as :func:`bisect.bisect_right`)."""
        b = bisect_right(self._bases, offset) - 1
        if b < 0:
            return 0
        return self._firsts[b] + bisect_right(self._blocks[b], offset - self._bases[b])

    def bisect_left(self, offset: int) -> int:
        """The number of offsets before ``offset`` (as :func:`bisect.bisect_left`)."""
        b = bisect_left(self._bases, offset) - 1
        if b < 0:
            return 0
        return self._firsts[b] + bisect_left(self._blocks[b], offset - self._bases[b])

    def floor(self, offset: int) -> tuple[int, int]:
        """The index and value of the last offset at or before ``offset`` (which must not
        be before the first): both found by C searches, over the blocks' bases and then
        in one block."""
        b = bisect_right(self._bases, offset) - 1
        base, block = self._bases[b], self._blocks[b]
        j = bisect_right(block, offset - base) - 1
        return self._firsts[b] + j, base + block[j]

    def floors(self, offsets: Sequence[int]) -> list[tuple[int, int]]:
        """:meth:`floor` of each of ``offsets`` (sorted, none before the first offset),
        in one sweep: the block is searched for only when an offset passes its end."""
        bases, firsts, blocks = self._bases, self._firsts, self._blocks
        out: list[tuple[int, int]] = []
        add = out.append
        nxt = -1  # the base of the block after the current one (none yet)
        base = first = 0
        block = blocks[0] if blocks else array("q")
        for o in offsets:
            if o >= nxt:
                b = bisect_right(bases, o) - 1
                base, first, block = bases[b], firsts[b], blocks[b]
                nxt = bases[b + 1] if b + 1 < len(bases) else o + (1 << 62)
            j = bisect_right(block, o - base) - 1
            add((first + j, base + block[j]))
        return out

    def between(self, first: int, stop: int) -> list[int]:
        """The offsets of indexes ``first`` to ``stop`` (excluded), from their blocks only."""
        firsts, n = self._firsts, self._n
        out: list[int] = []
        stop = min(stop, n)
        if first >= stop:
            return out
        b = bisect_right(firsts, first) - 1
        while b < len(firsts) and firsts[b] < stop:
            lo, block = firsts[b], self._blocks[b]
            out.extend(map(self._bases[b].__add__, block[max(first - lo, 0) : stop - lo]))
            b += 1
        return out

    def index_at(self, offset: int) -> int:
        """Index of the last offset at or before ``offset`` (-1 if none)."""
        return self.bisect_right(offset) - 1

    def replaced(self, first: int, stop: int, new: list[int], delta: int) -> Offsets:
        """These starts with ``[first, stop)`` replaced by ``new`` (absolute offsets) and
        every start from ``stop`` on moved by ``delta``."""
        bases, firsts, blocks, n = self._bases, self._firsts, self._blocks, self._n
        if not blocks:
            return Offsets.of(new)
        bf = bisect_right(firsts, first) - 1 if first < n else len(blocks) - 1
        bk = bisect_right(firsts, stop) - 1 if stop < n else len(blocks) - 1
        middle: list[int] = list(map(bases[bf].__add__, blocks[bf][: first - firsts[bf]]))
        middle.extend(new)
        if stop < n:
            middle.extend(map((bases[bk] + delta).__add__, blocks[bk][stop - firsts[bk] :]))
        mid = Offsets.of(middle)
        dtok = len(new) - (stop - first)
        start_index = firsts[bf]
        out_firsts = firsts[:bf]
        out_firsts.extend(map(start_index.__add__, mid._firsts))
        out_firsts.extend(map(dtok.__add__, firsts[bk + 1 :]))
        out_bases = bases[:bf]
        out_bases.extend(mid._bases)
        out_bases.extend(map(delta.__add__, bases[bk + 1 :]))
        out_blocks = blocks[:bf]
        out_blocks.extend(mid._blocks)
        out_blocks.extend(blocks[bk + 1 :])
        return Offsets(out_bases, out_firsts, out_blocks)


class LineIndex:
    """Line starts of a text, and conversions between offsets and LSP positions.

    Lines are numbered from 0. A text with ``n`` line ends has ``n + 1`` lines; the last
    one is empty when the text ends with a line end. A ``\\r\\n`` pair is one line end.
    """

    __slots__ = ("_plain", "_starts", "_text")

    _text: str
    _starts: Offsets  # an edit moves blocks of them, not each of them
    _plain: bool | None  # no CR and only ASCII (found when first asked)

    def __init__(self, text: str) -> None:
        self._text = text
        self._plain = None
        starts = [0]
        starts.extend(_line_starts(text))
        self._starts = Offsets.of(starts)

    @classmethod
    def _from_parts(cls, text: str, starts: Offsets) -> LineIndex:
        index = cls.__new__(cls)
        index._text = text
        index._starts = starts
        index._plain = None
        return index

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, LineIndex):
            return NotImplemented
        return self._text == other._text and self._starts == other._starts

    __hash__ = None  # type: ignore[assignment]

    def __repr__(self) -> str:
        return f"LineIndex(<{len(self._text)} chars, {len(self._starts)} lines>)"

    # -- lines -------------------------------------------------------------------------

    @property
    def text(self) -> str:
        return self._text

    @property
    def line_count(self) -> int:
        return len(self._starts)

    @property
    def line_starts(self) -> tuple[int, ...]:
        """Offset of the first character of every line."""
        return tuple(self._starts)

    def line_start(self, line: int) -> int:
        """Offset where ``line`` starts; clamped to the first and last line."""
        starts = self._starts
        if line <= 0:
            return 0
        if line >= len(starts):
            return starts[-1]
        return starts[line]

    def line_end(self, line: int) -> int:
        """Offset of ``line``'s terminator (``len(text)`` for the last line).

        The line's content is ``text[line_start(line):line_end(line)]``. ``line`` is
        clamped to the first and last line.
        """
        starts = self._starts
        if line < 0:
            line = 0
        if line >= len(starts) - 1:
            return len(self._text)
        nxt = starts[line + 1]
        if self._text[nxt - 1] == "\n" and nxt >= 2 and self._text[nxt - 2] == "\r":
            return nxt - 2
        return nxt - 1

    def line_text(self, line: int) -> str:
        """The content of ``line`` without its terminator."""
        return self._text[self.line_start(line) : self.line_end(line)]

    def line_of(self, offset: int) -> int:
        """The line holding ``offset`` (clamped to ``[0, len(text)]``)."""
        offset = min(max(offset, 0), len(self._text))
        return self._starts.bisect_right(offset) - 1

    # -- conversions -------------------------------------------------------------------

    def position(self, offset: int, encoding: Encoding) -> tuple[int, int]:
        """``(line, character)`` of ``offset``, clamped to ``[0, len(text)]``.

        An offset on a line terminator, including between the ``\\r`` and ``\\n`` of a
        pair, is the end of its line. The end of the text is on the last line, which is
        the empty line after a trailing line end.
        """
        text = self._text
        offset = min(max(offset, 0), len(text))
        line = self._starts.bisect_right(offset) - 1
        start = self._starts[line]
        if offset > start and text[offset - 1] == "\r" and text[offset : offset + 1] == "\n":
            offset -= 1  # between "\r" and "\n": the end of the line
        return line, _column(text, start, offset, encoding)

    def plain_columns(self, encoding: Encoding) -> bool:
        """Whether every column is its distance from the line start in ``encoding`` (no
        CR, and only ASCII or UTF-32), so that a caller may count columns itself."""
        text = self._text
        if self._plain is None:
            self._plain = text.isascii() and "\r" not in text
        return self._plain or (encoding == "utf-32" and "\r" not in text)

    def starts_between(self, start: int, end: int) -> tuple[int, list[int]]:
        """The line holding offset ``start``, and the starts of it and of the lines after
        it that start at or before ``end``: what the positions of a span need."""
        starts = self._starts
        first = max(starts.bisect_right(start) - 1, 0)
        return first, starts.between(first, starts.bisect_right(end))

    def positions(self, offsets: Iterable[int], encoding: Encoding) -> dict[int, tuple[int, int]]:
        """:meth:`position` of each of ``offsets``, in one pass over them sorted: the line
        starts are searched in C, and on one line each column is counted on from the
        previous offset's, so that many positions on a long line (a minified document)
        cost the line once, not once each.  A publication converts thousands of offsets
        per edit; this is most of what it costs."""
        text = self._text
        n = len(text)
        offs = sorted(set(offsets))
        out: dict[int, tuple[int, int]] = {}
        if not offs:
            return out
        floor = self._starts.floor  # line starts are in blocks: no list of them is made
        nlines = len(self._starts)
        if self._plain is None:
            self._plain = text.isascii() and "\r" not in text
        if self._plain or (encoding == "utf-32" and "\r" not in text):
            # A column is the distance from the line start.
            ats = [n if o > n else max(o, 0) for o in offs]
            for o, at, (line, start) in zip(offs, ats, self._starts.floors(ats), strict=True):
                out[o] = (line, at - start)
            return out
        at = column = line = 0
        limit = -1  # where the current line's successor starts
        for o in offs:
            clamped = min(max(o, 0), n)
            if 0 < clamped < n and text[clamped - 1] == "\r" and text[clamped] == "\n":
                clamped -= 1  # between "\r" and "\n": the end of the line
            if clamped >= limit:
                line, start = floor(clamped)
                limit = self._starts[line + 1] if line + 1 < nlines else n + 1
                column = _column(text, start, clamped, encoding)
            else:
                column += _column(text, at, clamped, encoding)
            at = clamped
            out[o] = (line, column)
        return out

    def offset(self, line: int, character: int, encoding: Encoding) -> int:
        """The offset of a position; the inverse of :meth:`position`.

        Never raises: a negative line is the start of the text, a line past the last is
        the end of the text, a negative character is the start of the line, a character
        past the end of the line is the line's end (before its terminator), and a
        character inside a code point (half of a UTF-16 surrogate pair, inside a UTF-8
        multi-byte sequence) rounds down to the start of that code point.
        """
        if line < 0:
            return 0
        if line >= len(self._starts):
            return len(self._text)
        start = self._starts[line]
        if character <= 0:
            return start
        end = self.line_end(line)
        if encoding == "utf-32":
            return min(start + character, end)
        # A code point is at least one code unit, so `character` units span at most
        # `character` code points.
        segment = self._text[start : min(start + character, end)]
        if segment.isascii():
            return start + len(segment)
        codec, unit = _CODECS[encoding]
        try:
            data = segment.encode(codec)
        except UnicodeEncodeError:
            return start + self._count_code_points(segment, character, encoding)
        # Decoding drops a code point cut in half at the end, which rounds down.
        return start + len(data[: character * unit].decode(codec, "ignore"))

    @staticmethod
    def _count_code_points(segment: str, character: int, encoding: Encoding) -> int:
        """How many whole code points of ``segment`` fit in ``character`` code units.

        The slow path, for text holding lone surrogates (which strict codecs reject).
        """
        units = 0
        for taken, char in enumerate(segment):
            units += _unit_width(char, encoding)
            if units > character:
                return taken
        return len(segment)

    def range_to_offsets(
        self,
        start_line: int,
        start_char: int,
        end_line: int,
        end_char: int,
        encoding: Encoding,
    ) -> tuple[int, int]:
        """``(start, end)`` offsets of a range, each clamped like :meth:`offset`."""
        return (
            self.offset(start_line, start_char, encoding),
            self.offset(end_line, end_char, encoding),
        )

    def offsets_to_range(
        self, start: int, end: int, encoding: Encoding
    ) -> tuple[int, int, int, int]:
        """``(start_line, start_char, end_line, end_char)`` of two offsets."""
        start_line, start_char = self.position(start, encoding)
        end_line, end_char = self.position(end, encoding)
        return start_line, start_char, end_line, end_char

    # -- incremental update ------------------------------------------------------------

    def edited(self, start: int, end: int, new_text: str, new_full_text: str) -> LineIndex:
        """The index of ``new_full_text``: this text with ``[start:end)`` replaced.

        Line starts before and after the edit are reused; only the replaced span and the
        characters next to it are scanned again (a ``\\r`` before the edit and a ``\\n``
        after it may now form one line end, and an edit may split a ``\\r\\n``).
        Raises ``ValueError`` if the arguments do not describe such an edit.
        """
        old = self._text
        if not 0 <= start <= end <= len(old):
            raise ValueError(f"edit [{start}:{end}) outside a text of length {len(old)}")
        new_end = start + len(new_text)
        if len(new_full_text) != len(old) - (end - start) + len(new_text) or (
            new_full_text[start:new_end] != new_text
        ):
            raise ValueError("new_full_text is not the text with the edit applied")

        starts = self._starts
        # A line start p depends only on the characters at p - 1 and p. Those are unchanged
        # for old starts p < start and p > end, so only [start, new_end] is rescanned, from
        # one character before it to one character after it.
        keep_before = starts.bisect_left(start)
        keep_after = starts.bisect_right(end)
        lo = max(start - 1, 0)
        hi = min(new_end + 1, len(new_full_text))
        rescanned = [lo + rel for rel in _line_starts(new_full_text[lo:hi]) if lo + rel <= new_end]
        # Line 0 always starts at 0; the starts in [keep_before, keep_after) are replaced,
        # the later ones move.
        result = starts.replaced(max(keep_before, 1), keep_after, rescanned, new_end - end)
        return LineIndex._from_parts(new_full_text, result)
