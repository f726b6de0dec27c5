"""The elements of a section as columns (:class:`Columns`) and the sequence that reads
them (:class:`ElementTable`).

A document may be made of a million ``<A/>`` (7 bytes each): one object per element,
with an ``int`` object for its offset and another for its token index, costs 25 times the
text.  A row of the columns costs about 45 bytes: the start tag (a token shared by equal
tags), machine integers for the offsets and indexes, a byte for the zone; children are one
flat array with each element's slice of it.  An :class:`~bt_lsp.syntax.elements.Element`
is made when read, many at a time in C when the rows are iterated, and not kept.
"""

from __future__ import annotations

from array import array
from collections.abc import Iterator, Sequence
from itertools import chain, repeat
from operator import itemgetter
from typing import overload

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


def offsets_code(length: int) -> str:
    """The array type code that holds the offsets of a text of ``length`` code points."""
    return "i" if length < _SMALL else "q"


class Columns:
    """The elements a builder made, one row each (row 0 is the root, or the stand-in for
    it that a section is built with).  Offsets are relative to the builder's origin; an
    element's end and its end tag's name are relative to its own start, so that they do
    not move with it."""

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
        self.zones = bytearray()
        self.starts: array[int] = array(code)
        self.tindex: array[int] = array("i")
        self.parents: array[int] = array("i")
        self.depths: array[int] = array("i")
        self.extents: array[int] = array(code)
        self.names_at: array[int] = array(code)
        # Row k's children are flat[child_at[k] : child_at[k] + child_n[k]].
        self.child_at: array[int] = array("i")
        self.child_n: array[int] = array("i")
        self.flat: array[int] = array("i")
        self.contents: dict[int, str] = {}  # port declarations' text, by row

    def __len__(self) -> int:
        return len(self.tags)

    def element(self, k: int) -> Element:
        """Row ``k`` as an element of these coordinates."""
        return ElementTable(self, 0, 0, 1, k, k + 1)[0]


class _Placement:
    """Where the rows of some columns sit: ``origin`` code points, ``tok_origin`` tokens
    and ``base - 1`` elements further on (a local row ``k > 0`` is element
    ``base - 1 + k`` there; row 0, the root, stays element 0).  An element read from
    them finds its children and content here (it refers to this, not to the table that
    may keep it: no cycle)."""

    __slots__ = ("base", "cols", "origin", "tok_origin")

    def __init__(self, cols: Columns, origin: int, tok_origin: int, base: int) -> None:
        self.cols = cols
        self.origin = origin
        self.tok_origin = tok_origin
        self.base = base

    def children_of(self, local: int) -> Sequence[int]:
        c = self.cols
        n = c.child_n[local]
        if not n:
            return NO_CHILDREN
        at = c.child_at[local]
        kids = c.flat[at : at + n]
        shift = self.base - 1
        return array("i", map(shift.__add__, kids)) if shift else kids

    def content_of(self, local: int) -> str | None:
        return self.cols.contents.get(local)


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
        self._place = _Placement(cols, origin, tok_origin, base)
        self._lo = lo
        self._hi = len(cols.tags) if hi < 0 else hi
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

    def placed(self, origin: int, tok_origin: int, base: int) -> ElementTable:
        """The same rows placed elsewhere."""
        return ElementTable(
            self._place.cols, origin, tok_origin, base, self._lo, self._hi, self._keep
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
        p = c.parents[k]
        return of_row(
            c.tags[k],
            ZONES[c.zones[k]],
            c.starts[k] + pl.origin,
            c.tindex[k] + pl.tok_origin,
            p + pl.base - 1 if p > 0 else p,
            c.depths[k],
            c.extents[k],
            c.names_at[k],
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
        parents: Iterator[int] | array[int] = c.parents[a:b]
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
                map(ZONES.__getitem__, c.zones[a:b]),
                map(origin.__add__, c.starts[a:b]) if origin else c.starts[a:b],
                map(tok_origin.__add__, c.tindex[a:b]) if tok_origin else c.tindex[a:b],
                parents,
                c.depths[a:b],
                c.extents[a:b],
                c.names_at[a:b],
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
