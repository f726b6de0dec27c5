"""Sections keep an edit cheap.  Each child of the root element, with everything inside it
and the root-level tokens after it (whitespace, comments, stray end tags), is a
:class:`Section` built on its own, in coordinates relative to its first token: offsets
from its start, token indexes from its first token, element indexes local to it (0 is the
root).  A :class:`Part` says where a section sits in a document.  Name tokens are not kept
at all: a section makes them from its elements when asked (they outnumber the elements),
and keeps only the set of symbols they refer to.
"""

from __future__ import annotations

from bisect import bisect_right
from collections.abc import Iterator, Sequence
from types import MappingProxyType
from typing import Any, Final
from weakref import ref as weak_ref

from bt_lsp.syntax.elements import (
    DECLARING_ROLES,
    EXPLICIT_TAGS,
    Element,
    NameRef,
    Role,
    StructureProblem,
    Symbol,
    Zone,
    model_symbol,
)
from bt_lsp.syntax.nametokens import SymbolPool, name_refs
from bt_lsp.syntax.table import ZONES, ElementTable
from bt_lsp.syntax.tokens import Token

_ROLE_NODE_TYPE_END = Role.NODE_TYPE_END
_ZONE_NODE = Zone.NODE
_ZONE_PORT_DECL = Zone.PORT_DECL
# The zones of the elements whose names may declare (see nametokens.name_refs).
_DECLARING_ZONES: Final = (Zone.TREE, Zone.MODEL_ENTRY, Zone.PORT_DECL)

_new = tuple.__new__

OPEN, CLOSED, EOF = 0, 1, 2  # how a section ends: at root level, closing the root, at the end


# The memo's keys and the slots that hold them (named apart from a section's own).
_MEMO_SLOTS: Final = MappingProxyType(
    {
        key: "_memo_" + key.replace("-", "_")
        for key in ("diagnostics", "outline", "outline-json", "semantics", "symbols", "top")
    }
)


class SectionMemo:
    """What the layers above keep of one section, by key, read and written like a dict
    (``section.cache``: a section is its own memo).

    The keys are fixed and kept in the section's slots: a dict per section (with the three
    to six keys it gets) cost about 230 to 400 bytes, a memo object of its own 80, more
    than a small section's columns, and a document of 20,000 small trees has 20,000
    sections.  A key that is not listed here is refused, so that a new one is added (and
    named) here.
    """

    __slots__ = tuple(_MEMO_SLOTS.values())

    def get(self, key: str, default: Any = None) -> Any:
        return getattr(self, _MEMO_SLOTS[key], default)

    def __getitem__(self, key: str) -> Any:
        try:
            return getattr(self, _MEMO_SLOTS[key])
        except AttributeError:
            raise KeyError(key) from None

    def __setitem__(self, key: str, value: Any) -> None:
        setattr(self, _MEMO_SLOTS[key], value)

    def __contains__(self, key: str) -> bool:
        return hasattr(self, _MEMO_SLOTS[key])


class Section(SectionMemo):
    """One child of the root element and the root-level tokens after it, relative to its
    first token (see the module docstring).  ``elements`` are local element ``1..n``
    (local element 0 is the root); ``lexical`` are the problems of its tokens.

    ``cache`` holds what the layers above derive from the section alone (or validate
    themselves), by their own keys (:class:`SectionMemo`); a section is immutable
    otherwise, so that it can be shared by the models of successive versions of a
    document.
    """

    __slots__ = (
        "_refs",
        "elements",
        "end",
        "length",
        "lexical",
        "ntokens",
        "problems",
        "root",
        "root_end",
    )

    def __init__(
        self,
        ntokens: int,
        length: int,
        elements: ElementTable,
        problems: Sequence[StructureProblem],
        lexical: Sequence[StructureProblem],
        end: int,
        root_end: tuple[int, int] | None,
        root: Element | None = None,
    ) -> None:
        self.ntokens = ntokens
        self.length = length
        self.elements = elements
        self.root = root  # the root element, for the head of a document (its refs)
        self.problems = problems
        self.lexical = lexical
        self.end = end
        self.root_end = root_end
        self._refs: weak_ref[SectionRefs] | None = None  # see refs

    @property
    def cache(self) -> SectionMemo:
        """What the layers above keep of this section (see :class:`SectionMemo`)."""
        return self

    @property
    def top(self) -> Element:
        """The root's child that starts the section (local element 1)."""
        return self.elements[0]

    @property
    def top_name(self) -> str:
        """The name of its top element."""
        return self.elements.columns.tags[1].name

    @property
    def top_zone(self) -> Zone:
        """The zone of its top element (read from its row, without making it)."""
        return ZONES[self.elements.columns.zones[1]]

    @property
    def refs(self) -> SectionRefs:
        """The section's name tokens, in order.  Made from its elements when asked for,
        and not kept by the section: a document has more names than elements.  The section
        finds them again (a weak reference) while someone keeps them: the model that asked
        (:meth:`Model.refs`, :meth:`Model.ref_at`) keeps those it asked for, so that they
        live as long as the version of the document that needs them.  Reading and setting
        the reference are single steps, so two threads asking at once at worst make them
        twice."""
        refs = self.kept_refs()
        if refs is not None:
            return refs
        refs = SectionRefs(self._make_refs())
        if "symbols" not in self.cache:  # small, kept: see symbols()
            self.cache["symbols"] = tuple(
                dict.fromkeys(r.symbol for r in refs if r.symbol is not None)
            )
        self._refs = weak_ref(refs)
        return refs

    def kept_refs(self) -> SectionRefs | None:
        """The section's name tokens if someone keeps them (see :attr:`refs`)."""
        kept = self._refs
        return kept() if kept is not None else None

    def _make_refs(self) -> list[NameRef]:
        refs = list(self._element_refs())
        refs.sort(key=_start)
        return refs

    def iter_refs(self) -> Iterator[NameRef]:
        """The section's name tokens, not in order, without keeping them (for a pass
        over all of them, such as the name rules: a list of them all costs more memory
        than the text they are in); notes the section's symbols on the way."""
        refs = self.kept_refs()
        if refs is not None:
            yield from refs
            return
        if "symbols" in self.cache:
            yield from self._element_refs()
            return
        symbols: dict[Symbol, None] = {}
        for r in self._element_refs():
            if r.symbol is not None:
                symbols[r.symbol] = None
            yield r
        self.cache["symbols"] = tuple(symbols)

    def _element_refs(self) -> Iterator[NameRef]:
        """The name tokens of each element in turn."""
        refs: list[NameRef] = []
        pool = SymbolPool()  # for this pass
        root = self.root
        if root is not None:
            name_refs(root, 0, None, refs, pool)
            yield from refs
            refs.clear()
        els = self.elements
        if els.kept:  # made already, or to be made once anyway
            yield from self._kept_refs(els, pool)
            return
        cols = els.columns
        tags, zones, starts, names_at = cols.tags, cols.zones, cols.starts, cols.names_at
        # An element with the same start tag and zone as the one before has the same
        # names moved: made from those (a document may be a million equal tags), without
        # making the element.
        last_tag: Token | None = None
        last_zone = -1
        first_ts = 0
        first: list[NameRef] = []
        for i in range(1, len(tags)):
            tag, zone, ts = tags[i], zones[i], starts[i]
            if tag is last_tag and zone == last_zone:
                d = ts - first_ts
                for r in first:
                    yield _new(NameRef, (r[0] + d, r[1] + d, r[2], r[3], r[4], r[5], i, r[7]))
            else:
                el = els[i - 1]
                # Only a port declaration's names depend on its parent (made only for it).
                p = el.parent
                parent = els[p - 1] if p > 0 and zone == _ZONE_PORT_DECL else None
                refs = []
                name_refs(el, i, parent, refs, pool)
                if zone != _ZONE_PORT_DECL:
                    last_tag, last_zone, first_ts, first = tag, zone, ts, refs
                yield from refs
            at = names_at[i]
            if at >= 0 and zone == _ZONE_NODE:
                end_ref = _end_ref(tag.name, ts + at, i, pool)
                if end_ref is not None:
                    yield end_ref

    @staticmethod
    def _kept_refs(els: ElementTable, pool: SymbolPool) -> Iterator[NameRef]:
        refs: list[NameRef] = []
        for i, el in enumerate(els, 1):
            zone = el.zone
            p = el.parent
            parent = els[p - 1] if p > 0 and zone == _ZONE_PORT_DECL else None
            name_refs(el, i, parent, refs, pool)
            if zone == _ZONE_NODE and el.end_name_at >= 0:
                end_ref = _end_ref(el.name, el.token_start + el.end_name_at, i, pool)
                if end_ref is not None:
                    refs.append(end_ref)
            if refs:
                yield from refs
                refs.clear()

    def ref_at(self, offset: int, held: list[SectionRefs] | None = None) -> NameRef | None:
        """The name token containing local ``offset`` (see :meth:`Model.ref_at`).  In a
        large section whose names are not made yet, read from the one tag that holds it:
        making them all to find one took seconds in a tree of a million elements, at the
        first hover after each edit.  Names made to find it are added to ``held``."""
        refs = self.kept_refs()
        if refs is None and len(self.elements.rows) > _FEW:
            found = self.ref_in_tag(offset)
            if not isinstance(found, _Unsure):
                return found
        if refs is None:
            refs = self.refs
            if held is not None:  # the caller keeps them (see refs)
                held.append(refs)
        i = bisect_right([r.start for r in refs], offset) - 1
        if i >= 0 and refs[i].start <= offset <= refs[i].end:
            return refs[i]
        return None

    def ref_in_tag(self, offset: int) -> NameRef | _Unsure | None:
        """The name token at local ``offset``, as :meth:`ref_at` finds it among all the
        section's names, read from the tag that holds ``offset``; :data:`UNSURE` where that
        tag alone cannot tell (a tag's first character, which an unterminated name
        before it may end at; a name-less end tag or text that one may end at).

        Names lie inside their tags and tags do not overlap, so the names of the start
        tag holding ``offset`` (found by its start, in C) or of the end tag holding it
        (that of the innermost element around it, found up its ancestors) are the only
        candidates."""
        els = self.elements
        root = self.root
        if root is not None and root.token_start <= offset <= root.token_start + root.length:
            return self._in_start_tag(root, 0, None, offset)
        rows = els.rows
        r = bisect_right(els.columns.starts, offset - els.origin, rows.start, rows.stop) - 1
        if r < rows.start:
            return UNSURE
        k = r - rows.start
        el = els[k]
        if offset <= el.token_start + el.length:
            p = el.parent
            parent = els[p - 1] if p > 0 and el.zone == _ZONE_PORT_DECL else None
            return self._in_start_tag(el, k + 1, parent, offset)
        # Up from the last element started before ``offset``: its end tag, or an
        # ancestor's, is the one that can hold ``offset``.
        i = k + 1
        while True:
            ens = el.end_name_start
            if ens >= 0 and ens <= offset <= ens + len(el.name):
                if el.zone != _ZONE_NODE:
                    return UNSURE
                return _end_ref(el.name, ens, i, SymbolPool())
            end = el.end  # (-1: never closed, so an ancestor's end tag may hold it)
            if end > offset or el.parent <= 0:
                return UNSURE if end == offset else None
            i = el.parent
            el = els[i - 1]

    @staticmethod
    def _in_start_tag(
        el: Element, i: int, parent: Element | None, offset: int
    ) -> NameRef | _Unsure | None:
        if offset == el.token_start:
            return UNSURE
        refs: list[NameRef] = []
        name_refs(el, i, parent, refs)
        best: NameRef | None = None
        for r in refs:  # the last to start at or before ``offset``, as ref_at's bisect
            if r.start <= offset and (best is None or r.start >= best.start):
                best = r
        return best if best is not None and offset <= best.end else None

    def declaring_refs(self) -> list[NameRef]:
        """The section's names that declare (tree IDs, model entries, port declarations:
        :data:`DECLARING_ROLES`), in order, made from the elements of the zones that hold
        them only (found in its zones column, in C): a tree of a million node uses
        declares nothing, and a hover asks what declares a name."""
        refs = self.kept_refs()
        if refs is not None:
            return [r for r in refs if r.role in DECLARING_ROLES]
        els = self.elements
        rows = els.rows
        zones = els.columns.zones
        found: list[int] = []
        for zone in _DECLARING_ZONES:
            at = zones.find(zone, rows.start, rows.stop)
            while at >= 0:
                found.append(at)
                at = zones.find(zone, at + 1, rows.stop)
        out: list[NameRef] = []
        pool = SymbolPool()
        for r in sorted(found):
            k = r - rows.start
            el = els[k]
            p = el.parent
            parent = els[p - 1] if p > 0 and el.zone == _ZONE_PORT_DECL else None
            name_refs(el, k + 1, parent, out, pool)
        out.sort(key=_start)
        return [r for r in out if r.role in DECLARING_ROLES]

    def symbols(self) -> tuple[Symbol, ...]:
        """The symbols the section's names refer to (found when its names are first made,
        as for its diagnostics)."""
        found: tuple[Symbol, ...] | None = self.cache.get("symbols")
        if found is None:
            refs = self.refs
            found = self.cache.get("symbols")
            if found is None:
                found = self.cache["symbols"] = tuple(
                    dict.fromkeys(r.symbol for r in refs if r.symbol is not None)
                )
        return found


class SectionRefs(list[NameRef]):
    """A section's name tokens (:attr:`Section.refs`): a list that the section can refer
    to weakly."""

    __slots__ = ("__weakref__",)


# A section of more elements finds the name at an offset from its tag (Section.ref_at).
_FEW: Final = 256


class _Unsure:
    """What :meth:`Section.ref_in_tag` answers where one tag cannot tell."""

    __slots__ = ()


UNSURE: Final = _Unsure()


class Part:
    """Where a section (or the head or tail of a document) sits in a document: its offset,
    its first token and its first element there."""

    __slots__ = ("elem_base", "origin", "section", "tok_origin")

    def __init__(self, section: Section, origin: int, tok_origin: int, elem_base: int) -> None:
        self.section = section
        self.origin = origin
        self.tok_origin = tok_origin
        self.elem_base = elem_base

    def element_index(self, local: int) -> int:
        """The document index of local element ``local`` (0 is the root, -1 none)."""
        if local <= 0:
            return local
        return self.elem_base + local - 1

    def elements(self) -> ElementTable:
        """The section's elements in document coordinates."""
        return self.section.elements.placed(self.origin, self.tok_origin, self.elem_base)

    def top(self) -> Element:
        """The section's top element in document coordinates."""
        return section_top(self.section, self.origin, self.tok_origin, self.elem_base)

    def ref(self, r: NameRef) -> NameRef:
        o = self.origin
        return NameRef(
            r.start + o,
            r.end + o,
            r.text,
            r.kind,
            r.role,
            r.symbol,
            self.element_index(r.element),
            r.quote,
        )

    def problem(self, p: StructureProblem) -> StructureProblem:
        return StructureProblem(p.start + self.origin, p.end + self.origin, p.code, p.message)


def section_top(sec: Section, origin: int, tok_origin: int, elem_base: int) -> Element:
    """A section's top element in document coordinates (kept on the section while it
    stays where it is).  Made alone: the elements of a section that keeps them would all
    be made to read the first (at every edit before a large ``<TreeNodesModel>``, which
    the edit moves)."""
    hit: tuple[int, int, int, Element] | None = sec.cache.get("top")
    if hit is not None and hit[0] == origin and hit[1] == tok_origin and hit[2] == elem_base:
        return hit[3]
    el = sec.elements.placed(origin, tok_origin, elem_base, keep=False)[0]
    sec.cache["top"] = (origin, tok_origin, elem_base, el)
    return el


def _end_ref(name: str, at: int, i: int, pool: SymbolPool) -> NameRef | None:
    """The name token of the end tag at ``at`` of compact node ``i``: it names the node's
    type too."""
    if name in EXPLICIT_TAGS or name == "SubTree":
        return None
    return NameRef(
        at, at + len(name), name, None, _ROLE_NODE_TYPE_END, pool.shared(model_symbol(name)), i
    )


def _start(r: NameRef) -> int:
    return r.start
