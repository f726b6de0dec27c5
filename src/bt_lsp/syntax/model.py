"""The BT document model: its elements, and every name token with its kind and symbol.

A model made of sections (:func:`bt_lsp.syntax.builder.build`) holds the document's head
(the root element), its sections (:mod:`bt_lsp.syntax.sections`) and its tail; after an
edit the sections the edit cannot have changed are the same objects as before, and so is
everything derived from them and cached on them (diagnostics, declarations, semantic
checks).  The whole-document views (``elements``, ``refs``, ``problems``) are in document
coordinates, made when first asked for; the elements are read from the sections' columns
(:mod:`bt_lsp.syntax.table`) each time, not kept.
"""

from __future__ import annotations

from array import array
from bisect import bisect_right
from collections.abc import Callable, Collection, Iterator, Mapping, Sequence
from itertools import accumulate, compress, count
from typing import Any, overload

from bt_lsp.syntax.elements import (
    DECLARING_ROLES,
    Element,
    NameRef,
    StructureProblem,
    Symbol,
    Zone,
)
from bt_lsp.syntax.sections import Part, Section, SectionRefs, section_top
from bt_lsp.syntax.table import ElementTable, Prefixed


class _Lazy(Sequence[Any]):
    """A read-only list whose items are made on first access."""

    __slots__ = ("_bases", "_items", "_make", "_n")

    def __init__(self, n: int, bases: list[int], make: Callable[[int, int], Any]) -> None:
        self._n = n
        self._bases = bases  # first index of each chunk
        self._make = make  # (chunk, index in chunk) -> item
        self._items: list[Any] = [None] * n

    def __len__(self) -> int:
        return self._n

    @overload
    def __getitem__(self, i: int) -> Any: ...
    @overload
    def __getitem__(self, i: slice) -> list[Any]: ...
    def __getitem__(self, i: int | slice) -> Any:
        if isinstance(i, slice):
            return [self[j] for j in range(*i.indices(self._n))]
        if i < 0:
            i += self._n
        if not 0 <= i < self._n:
            raise IndexError(i)
        item = self._items[i]
        if item is None:
            chunk = bisect_right(self._bases, i) - 1
            item = self._items[i] = self._make(chunk, i - self._bases[chunk])
        return item

    def __iter__(self) -> Iterator[Any]:
        for i in range(self._n):
            yield self[i]


class _SymbolIndex(Mapping[Symbol, list[NameRef]]):
    """Every symbol's references in document order, made from the sections' sets of
    symbols; the references of a symbol are made (in document coordinates) when asked for,
    from the sections that have it."""

    __slots__ = ("_chunks", "_held", "_keys", "_refs")

    def __init__(
        self, chunks: list[tuple[Part, tuple[Symbol, ...]]], held: list[SectionRefs]
    ) -> None:
        self._chunks = chunks
        self._held = held  # the sections' names made here, kept by the model
        keys: set[Symbol] = set()
        for _, symbols in chunks:
            keys.update(symbols)
        self._keys = keys
        self._refs: dict[Symbol, list[NameRef]] = {}

    def __getitem__(self, symbol: Symbol) -> list[NameRef]:
        refs = self._refs.get(symbol)
        if refs is None:
            if symbol not in self._keys:
                raise KeyError(symbol)
            refs = [
                part.ref(r)
                for part, symbols in self._chunks
                if symbol in symbols
                for r in _held_refs(part.section, self._held)
                if r.symbol == symbol
            ]
            self._refs[symbol] = refs
        return refs

    def __contains__(self, symbol: object) -> bool:
        return symbol in self._keys

    def __iter__(self) -> Iterator[Symbol]:
        return iter(self._keys)

    def __len__(self) -> int:
        return len(self._keys)


class Model:
    """The model of a document, or of one section (in its coordinates).

    ``elements``, ``refs`` and ``problems`` are in document order; a model made of
    sections (:func:`build`) makes them on first use from its ``head`` (the root element,
    and everything when the root has no child), its ``sections`` and its ``tail`` (from
    the root's end tag on).  Section ``k`` starts at offset ``origins[k]`` and token
    ``firsts[k]``; its top element is element ``bases[k]`` of the document.
    """

    __slots__ = (
        "_by_symbol",
        "_by_zone",
        "_elements",
        "_held",
        "_problems",
        "_ref_starts",
        "_refs",
        "bases",
        "firsts",
        "head",
        "head_ntokens",
        "local",
        "origins",
        "root_element",
        "sections",
        "sections_end",
        "tail",
        "tail_base",
        "tail_start",
        "top_names",
    )

    def __init__(
        self,
        elements: Sequence[Element],
        refs: Sequence[NameRef],
        problems: Sequence[StructureProblem],
        ref_starts: Sequence[int] | None = None,
    ) -> None:
        self._elements: Sequence[Element] | None = elements
        self._refs: Sequence[NameRef] | None = refs
        self._problems: Sequence[StructureProblem] | None = problems
        self._ref_starts = ref_starts
        self._by_symbol: Mapping[Symbol, list[NameRef]] | None = None
        self._by_zone: dict[Zone | None, list[Element]] = {}
        # The sections' names this model asked for, kept while it lives (Section.refs).
        self._held: list[SectionRefs] = []
        self.root_element: Element | None = None
        self.local: Section | None = None  # the section a section's own model is of
        self.head: Section | None = None  # None for a model that is not made of sections
        self.head_ntokens = 0
        self.sections: list[Section] = []
        # Machine integers: a list's cost 40 bytes each, and there may be 20,000 sections.
        self.origins: array[int] = array("q")
        self.firsts: array[int] = array("q")
        self.bases: array[int] = array("q")
        self.top_names: list[str] = []  # the name of each section's top element
        self.sections_end = 0
        self.tail: Section | None = None
        self.tail_base = 0
        self.tail_start = 0

    @classmethod
    def of_section(cls, section: Section, root: Element | None) -> Model:
        """The section as a model of its own, in its coordinates; element 0 is ``root``
        (the document's, in document coordinates: only its attributes and its number of
        children mean anything here)."""
        model = cls(Prefixed(root or _STAND_IN, section.elements), (), section.problems)
        model._refs = None  # made when asked for (see Model.refs)
        model.local = section
        return model

    # -- the whole document -----------------------------------------------------------------

    @property
    def elements(self) -> Sequence[Element]:
        if self._elements is None:
            self._elements = self._make_elements()
        return self._elements

    @property
    def refs(self) -> Sequence[NameRef]:
        if self._refs is None and self.local is not None:
            self._refs = self.local.refs
        if self._refs is None:
            parts = self.parts()
            local = [p.section.refs for p in parts]
            bases = [0, *accumulate(map(len, local))]
            self._refs = _Lazy(bases[-1], bases[:-1], lambda c, j: parts[c].ref(local[c][j]))
        return self._refs

    @property
    def problems(self) -> Sequence[StructureProblem]:
        if self._problems is None:
            self._problems = [p.problem(x) for p in self.parts() for x in p.section.problems]
        return self._problems

    @property
    def ref_starts(self) -> Sequence[int]:
        if self._ref_starts is None:
            self._ref_starts = [r.start for r in self.refs]
        return self._ref_starts

    @property
    def root(self) -> Element | None:
        if self.head is not None:
            return self.root_element
        els = self.elements
        return els[0] if len(els) and els[0].zone == Zone.ROOT else None

    def ref_at(self, offset: int) -> NameRef | None:
        """The name token containing ``offset`` (its end counts: a cursor after a name)."""
        if self.head is not None:
            part = self.part_at(offset)
            local = part.section.ref_at(offset - part.origin, self._held)
            return part.ref(local) if local is not None else None
        i = bisect_right(self.ref_starts, offset) - 1
        if i >= 0 and self.refs[i].start <= offset <= self.refs[i].end:
            return self.refs[i]
        return None

    def refs_to(self, symbol: Symbol) -> list[NameRef]:
        return self.by_symbol.get(symbol, [])

    def declarations_of(self, symbol: Symbol) -> list[NameRef]:
        """The names that declare ``symbol`` (:data:`DECLARING_ROLES`), in document order:
        those of :meth:`refs_to` that declare, read from the declaring elements of each
        section only (:meth:`Section.declaring_refs`), not from every use."""
        if self.head is None:
            return [r for r in self.refs_to(symbol) if r.role in DECLARING_ROLES]
        out: list[NameRef] = []
        for part in self.parts():
            sec = part.section
            known: tuple[Symbol, ...] | None = sec.cache.get("symbols")
            if known is not None and symbol not in known:
                continue
            out.extend(part.ref(r) for r in sec.declaring_refs() if r.symbol == symbol)
        return out

    @property
    def by_symbol(self) -> Mapping[Symbol, list[NameRef]]:
        """Every symbol's references in document order (built once, on first use)."""
        if self._by_symbol is None:
            if self.head is not None:
                chunks = [(p, p.section.symbols()) for p in self.parts()]
                self._by_symbol = _SymbolIndex(chunks, self._held)
            else:
                index: dict[Symbol, list[NameRef]] = {}
                for r in self.refs:
                    if r.symbol is not None:
                        index.setdefault(r.symbol, []).append(r)
                self._by_symbol = index
        return self._by_symbol

    def trees(self) -> list[Element]:
        return [e for e in self.root_children() if e.zone == Zone.TREE]

    def root_children(self, zone: Zone | None = None) -> list[Element]:
        """The root's child elements (in document coordinates); only those in ``zone``
        when given (cheap for a model made of sections: the others are not made)."""
        root = self.root
        if root is None:
            return []
        if self.head is not None:
            found: list[Element] | None = self._by_zone.get(zone)
            if found is None:
                found = self._by_zone[zone] = [
                    section_top(sec, o, f, b)
                    for sec, o, f, b in zip(
                        self.sections, self.origins, self.firsts, self.bases, strict=True
                    )
                    if zone is None or sec.top_zone == zone
                ]
            return found
        els = self.elements
        return [els[i] for i in root.children if zone is None or els[i].zone == zone]

    def root_child_names(self) -> Sequence[str]:
        """The names of the root's children."""
        if self.head is not None:
            return self.top_names
        return [e.name for e in self.root_children()]

    def root_children_named(self, names: Collection[str]) -> list[Element]:
        """The root's children (in document coordinates) with one of ``names``; only
        those are made."""
        if self.head is not None:
            tops = self.top_names
            if not any(name in tops for name in names):  # a search in C
                return []
            wanted = frozenset(names)  # looked up in C, over thousands of trees
            return [
                section_top(self.sections[k], self.origins[k], self.firsts[k], self.bases[k])
                for k in compress(count(), map(wanted.__contains__, tops))
            ]
        return [c for c in self.root_children() if c.name in names]

    # -- sections ---------------------------------------------------------------------------

    def part(self, k: int) -> Part:
        """Section ``k`` and where it sits."""
        return Part(self.sections[k], self.origins[k], self.firsts[k], self.bases[k])

    def parts(self) -> list[Part]:
        """The head, every section and the tail, with where they sit."""
        if self.head is None:
            return []
        out = [Part(self.head, 0, 0, 1)]
        out.extend(map(Part, self.sections, self.origins, self.firsts, self.bases))
        if self.tail is not None:
            out.append(Part(self.tail, 0, 0, self.tail_base))
        return out

    def part_at(self, offset: int) -> Part:
        """The part (head, section or tail) that holds ``offset``."""
        assert self.head is not None
        if self.tail is not None and offset >= self.tail_start:
            return Part(self.tail, 0, 0, self.tail_base)
        k = bisect_right(self.origins, offset) - 1
        if k < 0:
            return Part(self.head, 0, 0, 1)
        return self.part(k)

    def _make_elements(self) -> Sequence[Element]:
        root = self.root_element
        if root is None:
            return []
        head = self.head
        assert head is not None
        tables = [head.elements]  # already in document coordinates
        tables.extend(
            sec.elements.placed(o, f, b)
            for sec, o, f, b in zip(
                self.sections, self.origins, self.firsts, self.bases, strict=True
            )
        )
        if self.tail is not None:
            tables.append(self.tail.elements.placed(0, 0, self.tail_base))
        return _Chain(root, tables)


class _Chain(Sequence[Element]):
    """The root followed by the elements of each table in turn (the head's, each
    section's and the tail's, in document coordinates); made when read, not kept."""

    __slots__ = ("_bases", "_n", "_root", "_tables")

    def __init__(self, root: Element, tables: list[ElementTable]) -> None:
        self._root = root
        self._tables = tables
        self._bases = list(accumulate(map(len, tables), initial=1))[:-1]  # first of each
        self._n = 1 + sum(map(len, tables))

    def __len__(self) -> int:
        return self._n

    @overload
    def __getitem__(self, i: int) -> Element: ...
    @overload
    def __getitem__(self, i: slice) -> Sequence[Element]: ...
    def __getitem__(self, i: int | slice) -> Element | Sequence[Element]:
        if isinstance(i, slice):
            return [self[j] for j in range(*i.indices(self._n))]
        if i < 0:
            i += self._n
        if not 0 <= i < self._n:
            raise IndexError(i)
        if i == 0:
            return self._root
        k = bisect_right(self._bases, i) - 1
        return self._tables[k][i - self._bases[k]]

    def __iter__(self) -> Iterator[Element]:
        yield self._root
        for table in self._tables:
            yield from table


# The root of a section's own model when the document's is not at hand.
_STAND_IN = Element("", Zone.ROOT, 0, 0, -1, 0, (), False, True)


def _held_refs(section: Section, held: list[SectionRefs]) -> SectionRefs:
    """``section``'s names, kept in ``held`` when made here (see :attr:`Section.refs`)."""
    refs = section.kept_refs()
    if refs is None:
        refs = section.refs
        held.append(refs)
    return refs
