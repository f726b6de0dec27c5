"""The elements of a section as columns (:class:`Columns`) and the sequence that reads
them (:class:`ElementTable`).

A document may be made of a million ``<A/>`` (7 bytes each): one object per element,
with an ``int`` object for its offset and another for its token index, costs 25 times the
text.  A row of the columns costs about 45 bytes: the start tag (a token shared by equal
tags), machine integers for the offsets and indexes, a byte for the zone; children are one
flat array with each element's slice of it.  An :class:`~bt_lsp.syntax.elements.Element`
is made when read, many at a time in C when the rows are iterated, and not kept.

A document may also be made of 20,000 small trees, each a section of a few rows: there
the columns' objects cost more than their rows (nine arrays of 80 bytes or more, 14 MB
for 2 MB of text), so a small section's columns are packed into one array once built
(:class:`Packed`, about 270 bytes for a tree of four elements instead of 1,300).
"""

from __future__ import annotations

from array import array
from collections.abc import Iterator, Mapping, Sequence
from itertools import chain, repeat
from operator import itemgetter
from types import MappingProxyType
from typing import TypeAlias, overload

from bt_lsp.syntax.elements import NO_CHILDREN, Element, Zone, of_row
from bt_lsp.syntax.tokens import Token

ZONES: tuple[Zone, ...] = tuple(Zone)
_new = tuple.__new__
_NAME = itemgetter(3)  # Token.name
_ATTRS = itemgetter(6)  # Token.attrs
# Machine integers of 4 bytes hold the offsets of any text below 2 GiB.
_SMALL = 2**31 - 1
# Rows made at a time when the elements are iterated.
_CHUNK = 512
# Sections of at most this many rows are packed (a column read of them copies its slice).
PACKED_ROWS = 64
# The contents of columns without port declarations (shared).
_NO_CONTENTS: Mapping[int, str] = MappingProxyType({})

# A row's values as :meth:`Columns.row` gives them (seven).
_Row: TypeAlias = Sequence[int]
# Rows ``a .. b - 1`` as :meth:`Columns.window` gives them: zones, starts, token indexes,
# parents, depths, extents and end tags' names.
_Window: TypeAlias = (
    "tuple[Sequence[int], array[int], array[int], array[int], array[int], array[int], array[int]]"
)


def offsets_code(length: int) -> str:
    """The array type code that holds the offsets of a text of ``length`` code points."""
    return "i" if length < _SMALL else "q"


class Columns:
    """The elements of a section, one row each (row 0 is the root, or the stand-in for
    it that a section is built with).  Offsets are relative to the section's origin; an
    element's end and its end tag's name are relative to its own start, so that they do
    not move with it.

    Read as columns by name (``tags``, ``zones``, ``starts``, ``tindex``, ``parents``,
    ``depths``, ``extents``, ``names_at``, ``child_at``, ``child_n``, ``flat``,
    ``contents``) from either kind: :class:`Growing` as the builder writes them, or
    :class:`Packed`.  Row ``k``'s children are
    ``flat[child_at[k] : child_at[k] + child_n[k]]``.

    Columns are also where the elements of their own table find their children and
    content (a place with no shift: see :class:`_Placement`), which saves an object per
    section."""

    __slots__ = ()

    # As a place: at the origin (see _Placement).
    origin = 0
    tok_origin = 0
    base = 1

    @property
    def cols(self) -> Columns:
        return self

    @property
    def tags(self) -> Sequence[Token]:
        raise NotImplementedError

    @property
    def zones(self) -> bytearray:
        raise NotImplementedError

    @property
    def starts(self) -> array[int]:
        raise NotImplementedError

    @property
    def tindex(self) -> array[int]:
        raise NotImplementedError

    @property
    def parents(self) -> array[int]:
        raise NotImplementedError

    @property
    def depths(self) -> array[int]:
        raise NotImplementedError

    @property
    def extents(self) -> array[int]:
        raise NotImplementedError

    @property
    def names_at(self) -> array[int]:
        raise NotImplementedError

    @property
    def child_at(self) -> array[int]:
        raise NotImplementedError

    @property
    def child_n(self) -> array[int]:
        raise NotImplementedError

    @property
    def flat(self) -> array[int]:
        raise NotImplementedError

    @property
    def contents(self) -> Mapping[int, str]:
        """Port declarations' text, by row."""
        raise NotImplementedError

    def __len__(self) -> int:
        return len(self.tags)

    def row(self, k: int) -> _Row:
        """Row ``k``: zone, start, token index, parent, depth, extent, end tag's name."""
        raise NotImplementedError

    def window(self, a: int, b: int) -> _Window:
        """Rows ``a .. b - 1`` by column (see ``_Window``)."""
        raise NotImplementedError

    def children_of(self, local: int) -> Sequence[int]:
        """Row ``local``'s children (rows)."""
        raise NotImplementedError

    def content_of(self, local: int) -> str | None:
        return self.contents.get(local)

    def element(self, k: int) -> Element:
        """Row ``k`` as an element of these coordinates."""
        return ElementTable(self, 0, 0, 1, k, k + 1)[0]


class Growing(Columns):
    """Columns as the builder writes them: one array (or list) each."""

    __slots__ = (
        "child_at",
        "child_n",
        "contents",
        "depths",
        "extents",
        "flat",
        "names_at",
        "parents",
        "starts",
        "tags",
        "tindex",
        "zones",
    )

    def __init__(self, code: str) -> None:
        self.tags: list[Token] = []
        self.zones: bytearray = bytearray()
        self.starts: array[int] = array(code)
        self.tindex: array[int] = array("i")
        self.parents: array[int] = array("i")
        self.depths: array[int] = array("i")
        self.extents: array[int] = array(code)
        self.names_at: array[int] = array(code)
        self.child_at: array[int] = array("i")
        self.child_n: array[int] = array("i")
        self.flat: array[int] = array("i")
        self.contents: dict[int, str] = {}

    def row(self, k: int) -> _Row:
        return (
            self.zones[k],
            self.starts[k],
            self.tindex[k],
            self.parents[k],
            self.depths[k],
            self.extents[k],
            self.names_at[k],
        )

    def window(self, a: int, b: int) -> _Window:
        return (
            self.zones[a:b],
            self.starts[a:b],
            self.tindex[a:b],
            self.parents[a:b],
            self.depths[a:b],
            self.extents[a:b],
            self.names_at[a:b],
        )

    def children_of(self, local: int) -> Sequence[int]:
        n = self.child_n[local]
        if not n:
            return NO_CHILDREN
        at = self.child_at[local]
        return self.flat[at : at + n]

    def packs(self) -> bool:
        """Whether these columns are better packed: few rows, offsets of 4 bytes."""
        return len(self.tags) <= PACKED_ROWS and self.starts.typecode == "i"

    def packed(self) -> Packed:
        """The same columns in one array (see :class:`Packed`)."""
        return Packed(self)


# Where each column starts in a packed array, in rows (the flat children follow them):
# the columns of a row as Columns.row gives them first, so that a row is one slice.
_ZONE, _STARTS, _TINDEX, _PARENTS, _DEPTHS, _EXTENTS, _NAMES_AT, _CHILD_AT, _CHILD_N = range(9)
_ROW = 7
_FLAT = 9
_SHORT = 1 << 15  # what an array("h") holds: -_SHORT to _SHORT - 1


def _low(v: int) -> int:
    """The low 16 bits of ``v`` as a signed short (``v >> 16`` is the high ones)."""
    return ((v & 0xFFFF) ^ 0x8000) - 0x8000


class Packed(Columns):
    """Columns of a few rows, finished, in one array of machine integers (of two bytes
    each where they fit, four otherwise): column ``j`` is ``ints[j * n : (j + 1) * n]``
    for ``n`` rows (zones too), then the flat children.
    A column read by name is a copy of its slice (of a few rows: cheap); the table reads
    rows and windows from the one array."""

    __slots__ = ("_contents", "_ints", "_tags")

    def __init__(self, cols: Growing) -> None:
        self._tags = tuple(cols.tags)  # exactly as long (a list's items are one more block)
        ints = array("i")
        ints.frombytes(
            b"".join(
                (
                    array("i", iter(cols.zones)),
                    cols.starts,
                    cols.tindex,
                    cols.parents,
                    cols.depths,
                    cols.extents,
                    cols.names_at,
                    cols.child_at,
                    cols.child_n,
                    cols.flat,
                )
            )
        )
        # Two bytes an integer where every one fits (a section of under 32 KiB): a small
        # section's columns are then half as large.  The root's start and token index
        # (row 0: where the document's root is, before the section) grow with the
        # document: they follow the rest, two halves each (see _root).
        n = len(self._tags)
        root = (ints[_STARTS * n], ints[_TINDEX * n]) if n else (0, 0)
        if n:
            ints[_STARTS * n] = ints[_TINDEX * n] = 0
        if n and min(ints) >= -_SHORT and max(ints) < _SHORT:
            ints.extend(half for v in root for half in (_low(v), v >> 16))
            self._ints = array("h", ints.tolist())  # exactly as long
        else:
            if n:
                ints[_STARTS * n], ints[_TINDEX * n] = root
            self._ints = ints[:]  # exactly as long
        self._contents: Mapping[int, str] = cols.contents or _NO_CONTENTS

    def _root(self) -> tuple[int, int] | None:
        """The root row's start and token index when kept apart (a short array)."""
        ints = self._ints
        if ints.typecode != "h":
            return None
        s_lo, s_hi, t_lo, t_hi = ints[-4:]
        return (s_hi << 16) + (s_lo & 0xFFFF), (t_hi << 16) + (t_lo & 0xFFFF)

    def _column(self, j: int) -> array[int]:
        n = len(self._tags)
        col = self._ints[j * n : (j + 1) * n]
        if j in (_STARTS, _TINDEX):
            root = self._root()
            if root is not None:
                col = array("i", col)
                col[0] = root[j - _STARTS]
        return col

    @property
    def tags(self) -> Sequence[Token]:
        return self._tags

    @property
    def zones(self) -> bytearray:
        return bytearray(self._column(_ZONE).tolist())

    @property
    def starts(self) -> array[int]:
        return self._column(_STARTS)

    @property
    def tindex(self) -> array[int]:
        return self._column(_TINDEX)

    @property
    def parents(self) -> array[int]:
        return self._column(_PARENTS)

    @property
    def depths(self) -> array[int]:
        return self._column(_DEPTHS)

    @property
    def extents(self) -> array[int]:
        return self._column(_EXTENTS)

    @property
    def names_at(self) -> array[int]:
        return self._column(_NAMES_AT)

    @property
    def child_at(self) -> array[int]:
        return self._column(_CHILD_AT)

    @property
    def child_n(self) -> array[int]:
        return self._column(_CHILD_N)

    @property
    def flat(self) -> array[int]:
        ints = self._ints
        return ints[_FLAT * len(self._tags) : len(ints) - 4 if ints.typecode == "h" else None]

    @property
    def contents(self) -> Mapping[int, str]:
        return self._contents

    def row(self, k: int) -> _Row:
        n = len(self._tags)
        found = self._ints[k : _ROW * n : n]
        root = None if k else self._root()
        if root is None:
            return found
        row = array("i", found)
        row[_STARTS], row[_TINDEX] = root
        return row

    def window(self, a: int, b: int) -> _Window:
        ints = self._ints
        n = len(self._tags)
        starts = ints[n + a : n + b]
        tindex = ints[2 * n + a : 2 * n + b]
        root = self._root() if a == 0 and b > 0 else None
        if root is not None:
            starts, tindex = array("i", starts), array("i", tindex)
            starts[0], tindex[0] = root
        return (
            ints[a:b],
            starts,
            tindex,
            ints[3 * n + a : 3 * n + b],
            ints[4 * n + a : 4 * n + b],
            ints[5 * n + a : 5 * n + b],
            ints[6 * n + a : 6 * n + b],
        )

    def children_of(self, local: int) -> Sequence[int]:
        ints = self._ints
        n = len(self._tags)
        count = ints[_CHILD_N * n + local]
        if not count:
            return NO_CHILDREN
        at = _FLAT * n + ints[_CHILD_AT * n + local]
        return ints[at : at + count]


class _Placement:
    """Where the rows of some columns sit: ``origin`` code points, ``tok_origin`` tokens
    and ``base - 1`` elements further on (a local row ``k > 0`` is element
    ``base - 1 + k`` there; row 0, the root, stays element 0).  An element read from
    them finds its children and content here (it refers to this, not to the table that
    may keep it: no cycle).  Columns are their own placement at their origin."""

    __slots__ = ("base", "cols", "origin", "tok_origin")

    def __init__(self, cols: Columns, origin: int, tok_origin: int, base: int) -> None:
        self.cols = cols
        self.origin = origin
        self.tok_origin = tok_origin
        self.base = base

    def children_of(self, local: int) -> Sequence[int]:
        kids = self.cols.children_of(local)
        shift = self.base - 1
        return array("i", map(shift.__add__, kids)) if shift and kids else kids

    def content_of(self, local: int) -> str | None:
        return self.cols.contents.get(local)


def _placement(cols: Columns, origin: int, tok_origin: int, base: int) -> _Placement | Columns:
    if origin == 0 and tok_origin == 0 and base == 1:
        return cols
    return _Placement(cols, origin, tok_origin, base)


class ElementTable(Sequence[Element]):
    """Rows ``lo .. hi - 1`` of some columns as elements, placed ``origin`` code points,
    ``tok_origin`` tokens and ``base - 1`` elements further on (see :class:`_Placement`).

    With ``keep``, the elements are made once and kept: for rows that stand for enough
    text (:func:`keeps`), where keeping them costs a small part of the text and saves
    making them again at every pass of the rules and requests."""

    __slots__ = ("_hi", "_items", "_keep", "_lo", "_place")

    def __init__(
        self,
        cols: Columns,
        origin: int,
        tok_origin: int,
        base: int,
        lo: int = 1,
        hi: int = -1,
        keep: bool = False,
    ) -> None:
        self._place = _placement(cols, origin, tok_origin, base)
        self._lo = lo
        # Columns without a row 0 (a section or head with no root: the text before a
        # ``<root>`` that a stray ``<!`` swallowed) have no rows from 1 on: empty, not -1.
        self._hi = max(lo, len(cols.tags) if hi < 0 else hi)
        self._keep = keep
        self._items: list[Element] | None = None

    @property
    def columns(self) -> Columns:
        return self._place.cols

    @property
    def kept(self) -> bool:
        """Whether its elements are kept once made (see :func:`keeps`)."""
        return self._keep

    @property
    def rows(self) -> range:
        """The rows of :attr:`columns` it reads (element ``i`` is row ``rows[i]``)."""
        return range(self._lo, self._hi)

    @property
    def origin(self) -> int:
        """What a row's start is moved by: element ``i`` starts at
        ``columns.starts[rows[i]] + origin``."""
        return self._place.origin

    def placed(
        self, origin: int, tok_origin: int, base: int, keep: bool | None = None
    ) -> ElementTable:
        """The same rows placed elsewhere (their elements kept once made as here, or as
        ``keep`` says: ``False`` for a table read once, whose kept elements would all be
        made to read one)."""
        return ElementTable(
            self._place.cols,
            origin,
            tok_origin,
            base,
            self._lo,
            self._hi,
            self._keep if keep is None else keep,
        )

    def __len__(self) -> int:
        return self._hi - self._lo

    @overload
    def __getitem__(self, i: int) -> Element: ...
    @overload
    def __getitem__(self, i: slice) -> Sequence[Element]: ...
    def __getitem__(self, i: int | slice) -> Element | Sequence[Element]:
        n = self._hi - self._lo
        if isinstance(i, slice):
            start, stop, step = i.indices(n)
            if step != 1:
                return [self[j] for j in range(start, stop, step)]
            if start == 0 and stop >= n:
                return self
            pl = self._place
            lo = self._lo
            return ElementTable(
                pl.cols, pl.origin, pl.tok_origin, pl.base, lo + start, lo + max(start, stop)
            )
        if i < 0:
            i += n
        if not 0 <= i < n:
            raise IndexError(i)
        if self._keep:
            return self._kept()[i]
        k = self._lo + i
        pl = self._place
        c = pl.cols
        z, s, t, p, d, e, na = c.row(k)
        return of_row(
            c.tags[k],
            ZONES[z],
            s + pl.origin,
            t + pl.tok_origin,
            p + pl.base - 1 if p > 0 else p,
            d,
            e,
            na,
            pl,
            k,
        )

    def __iter__(self) -> Iterator[Element]:
        if self._keep:
            return iter(self._kept())
        lo, hi = self._lo, self._hi
        return chain.from_iterable(
            self._rows(a, min(hi, a + _CHUNK)) for a in range(lo, hi, _CHUNK)
        )

    def _kept(self) -> list[Element]:
        items = self._items
        if items is None:
            items = self._items = list(self._rows(self._lo, self._hi))
        return items

    def _rows(self, a: int, b: int) -> Iterator[Element]:
        """Rows ``a .. b - 1``, made in C."""
        pl = self._place
        c = pl.cols
        origin, tok_origin, shift = pl.origin, pl.tok_origin, pl.base - 1
        tags = c.tags[a:b]
        zones, starts, tindex, parents_, depths, extents, names_at = c.window(a, b)
        parents: Iterator[int] | array[int] = parents_
        if shift and min(parents, default=1) <= 0:  # the root's children: not moved
            parents = (p + shift if p > 0 else p for p in parents)
        elif shift:
            parents = map(shift.__add__, parents)
        return map(
            _new,
            repeat(Element),
            zip(
                tags,
                map(_NAME, tags),
                map(_ATTRS, tags),
                map(ZONES.__getitem__, zones),
                map(origin.__add__, starts) if origin else starts,
                map(tok_origin.__add__, tindex) if tok_origin else tindex,
                parents,
                depths,
                extents,
                names_at,
                repeat(pl),
                range(a, b),
            ),
        )


def keeps(length: int, elements: int) -> bool:
    """Whether the elements of a text of ``length`` code points are kept once made: when
    they stand for 40 code points or more each (a kept element costs about 230 bytes;
    rows of tiny elements are read again instead)."""
    return length >= _KEPT_LENGTH * elements


_KEPT_LENGTH = 40


class Prefixed(Sequence[Element]):
    """``first`` followed by ``rest`` (a section's elements after the document's root),
    without copying them."""

    __slots__ = ("_first", "_rest")

    def __init__(self, first: Element, rest: Sequence[Element]) -> None:
        self._first = first
        self._rest = rest

    def __len__(self) -> int:
        return 1 + len(self._rest)

    @overload
    def __getitem__(self, i: int) -> Element: ...
    @overload
    def __getitem__(self, i: slice) -> Sequence[Element]: ...
    def __getitem__(self, i: int | slice) -> Element | Sequence[Element]:
        if isinstance(i, slice):
            start, stop, step = i.indices(len(self))
            if step == 1 and start >= 1:
                return self._rest[start - 1 : max(start, stop) - 1]
            return [self[j] for j in range(start, stop, step)]
        if i < 0:
            i += len(self)
        if i == 0:
            return self._first
        if not 0 < i <= len(self._rest):
            raise IndexError(i)
        return self._rest[i - 1]

    def __iter__(self) -> Iterator[Element]:
        yield self._first
        yield from self._rest
