"""The BT document model: elements, and every name token with its kind and symbol.

Built from the scanner's tokens in one loop with an explicit element stack (no
recursion).  It decides, exactly as the contract lists, which token is a model name, a
port name, an instance name or a reference, and what it refers to; everywhere else
(comments, CDATA, ``<include path>``, attributes of ``<root>`` and ``<BehaviorTree>``,
reserved attributes of nodes) nothing is a name.

A *symbol* identifies what a name denotes, so that renaming one occurrence can rename all:
``("tree", id)``, ``("model", id)`` and ``("port", "tree"|"model", owner_id, port)``.

Sections keep an edit cheap.  Each child of the root element, with everything inside it
and the root-level tokens after it (whitespace, comments, stray end tags), is a
:class:`Section` built on its own, in coordinates relative to its first token: offsets
from its start, token indexes from its first token, element indexes local to it (0 is the
root).  After an edit, :func:`build` re-runs only the sections from the first changed
token until a section boundary lines up with an old one again; the other sections are the
same objects as before, and so is everything derived from them and cached on them
(diagnostics, declarations, semantic checks).  The whole-document views (``elements``,
``refs``, ``problems``) are made of absolute copies, built when first asked for.  Name
tokens are not kept at all: a section makes them from its elements when asked (they
outnumber the elements), and keeps only the set of symbols they refer to.
"""

from __future__ import annotations

import re
from bisect import bisect_left, bisect_right
from collections import OrderedDict
from collections.abc import Callable, Collection, Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from enum import IntEnum, StrEnum
from itertools import accumulate, compress, count
from typing import Any, NamedTuple, overload

from bt_lsp.syntax.gcpause import gc_paused
from bt_lsp.syntax.lazyre import LazyPattern
from bt_lsp.syntax.scanner import (
    XML_SYNTAX,
    Attr,
    Kind,
    Rescan,
    Scan,
    Token,
    decode_value,
    scan_token,
)
from bt_lsp.syntax.vocabulary import CONTROL_CHARS, FORBIDDEN, RESERVED_PORT_NAMES, NameKind

Symbol = tuple[str, ...]

EXPLICIT_TAGS = frozenset({"Action", "Condition", "Control", "Decorator"})
PORT_TAGS = frozenset({"input_port", "output_port", "inout_port"})


class Zone(IntEnum):
    """Where an element sits in a BT document."""

    ROOT = 0  # the document element
    TREE = 1  # <BehaviorTree>
    NODE = 2  # an element inside a tree
    MODELS = 3  # <TreeNodesModel>
    MODEL_ENTRY = 4  # an entry of <TreeNodesModel>
    PORT_DECL = 5  # <input_port|output_port|inout_port> of an entry
    INCLUDE = 6  # <include>
    OTHER = 7  # anything else (ignored by BehaviorTree.CPP)
    OUTSIDE = 8  # a second top-level element


class Role(StrEnum):
    TREE_DEF = "tree ID"
    SUBTREE_CALL = "SubTree call"
    MAIN_TREE = "main tree reference"
    NODE_TYPE = "node type"
    NODE_TYPE_END = "node type (end tag)"
    NODE_ID = "node ID"
    MODEL_DEF = "TreeNodesModel entry"
    PORT_DECL = "port declaration"
    PORT_USE = "port"
    INSTANCE = "instance name"


# Roles whose occurrence declares the symbol (used by hover and navigation).
DECLARING_ROLES = frozenset({Role.TREE_DEF, Role.MODEL_DEF, Role.PORT_DECL})

# Members read in the hot loops below, as module globals: in Python 3.11 reading a member
# from an enum class costs about 0.2 µs (EnumType has a __getattr__ hook), a global a
# tenth of that, and a first analysis reads them hundreds of thousands of times.
_KIND_INSTANCE = NameKind.INSTANCE
_KIND_MODEL = NameKind.MODEL
_KIND_PORT = NameKind.PORT
_ROLE_INSTANCE = Role.INSTANCE
_ROLE_MAIN_TREE = Role.MAIN_TREE
_ROLE_MODEL_DEF = Role.MODEL_DEF
_ROLE_NODE_ID = Role.NODE_ID
_ROLE_NODE_TYPE = Role.NODE_TYPE
_ROLE_NODE_TYPE_END = Role.NODE_TYPE_END
_ROLE_PORT_DECL = Role.PORT_DECL
_ROLE_PORT_USE = Role.PORT_USE
_ROLE_SUBTREE_CALL = Role.SUBTREE_CALL
_ROLE_TREE_DEF = Role.TREE_DEF
_ZONE_INCLUDE = Zone.INCLUDE
_ZONE_MODELS = Zone.MODELS
_ZONE_MODEL_ENTRY = Zone.MODEL_ENTRY
_ZONE_NODE = Zone.NODE
_ZONE_OTHER = Zone.OTHER
_ZONE_OUTSIDE = Zone.OUTSIDE
_ZONE_PORT_DECL = Zone.PORT_DECL
_ZONE_ROOT = Zone.ROOT
_ZONE_TREE = Zone.TREE


class NameRef(NamedTuple):
    """One name token.  ``start``/``end`` are absolute code-point offsets of the name as
    written: an element or attribute name, or a value between its quotes (entity
    references included).  ``kind`` is ``None`` for references that the name rules do
    not check (``main_tree_to_execute``, an end tag)."""

    start: int
    end: int
    text: str
    kind: NameKind | None
    role: Role
    symbol: Symbol | None
    element: int
    quote: str = ""

    @property
    def declaration(self) -> bool:
        return self.role in DECLARING_ROLES


@dataclass(slots=True)
class Element:
    name: str
    zone: Zone
    token_start: int
    token_index: int
    parent: int
    depth: int
    attrs: tuple[Attr, ...]
    self_closing: bool
    closed: bool  # its start tag ends with '>' or '/>'
    end: int = -1  # offset after its end tag (or its start tag when empty); -1 if never closed
    end_name_start: int = -1  # absolute span of the end tag's name, if any
    end_name_end: int = -1
    children: list[int] = field(default_factory=list)
    # The text inside a port declaration (BehaviorTree.CPP writes a port's description
    # there); ``None`` for every other element.
    content: str | None = None

    @property
    def name_start(self) -> int:
        return self.token_start + 1

    @property
    def name_end(self) -> int:
        return self.token_start + 1 + len(self.name)

    def attr(self, name: str) -> Attr | None:
        for a in self.attrs:
            if a.name == name:
                return a
        return None

    def value(self, name: str) -> str | None:
        a = self.attr(name)
        return a.value if a is not None else None

    def span_of_value(self, a: Attr) -> tuple[int, int]:
        return self.token_start + a.value_start, self.token_start + a.value_end

    def span_of_name(self, a: Attr) -> tuple[int, int]:
        return self.token_start + a.name_start, self.token_start + a.name_end

    @property
    def is_node(self) -> bool:
        return self.zone == _ZONE_NODE

    @property
    def node_id(self) -> str | None:
        """The node type: the ``ID`` of an explicit node or SubTree, else the tag name."""
        if self.name in EXPLICIT_TAGS or self.name == "SubTree":
            return self.value("ID")
        return self.name


class StructureProblem(NamedTuple):
    start: int
    end: int
    code: str
    message: str


# --- sections -------------------------------------------------------------------------------

OPEN, CLOSED, EOF = 0, 1, 2  # how a section ends: at root level, closing the root, at the end


class Section:
    """One child of the root element and the root-level tokens after it, relative to its
    first token (see the module docstring).  ``elements`` are local element ``1..n``
    (local element 0 is the root); ``lexical`` are the problems of its tokens.

    ``cache`` holds what the layers above derive from the section alone (or validate
    themselves), by their own keys; a section is immutable otherwise, so that it can be
    shared by the models of successive versions of a document.
    """

    __slots__ = (
        "cache",
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
        elements: list[Element],
        problems: list[StructureProblem],
        lexical: list[StructureProblem],
        end: int,
        root_end: tuple[int, int, int] | None,
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
        self.cache: dict[str, Any] = {}

    @property
    def top(self) -> Element:
        """The root's child that starts the section (local element 1)."""
        return self.elements[0]

    def local_model(self, root: Element | None) -> Model:
        """The section as a model of its own, in its coordinates; element 0 is ``root``
        (the document's, in document coordinates: only its attributes and its number of
        children mean anything here)."""
        model = Model([root or _STAND_IN, *self.elements], (), self.problems)
        model._refs = None  # made when asked for (see Model.refs)
        model.local = self
        return model

    @property
    def refs(self) -> list[NameRef]:
        """The section's name tokens, in order.  Made from its elements when asked for,
        and kept for the few sections asked about last only: a document has more names
        than elements."""
        refs = _RECENT_REFS.get(self)
        if refs is not None:
            _RECENT_REFS.move_to_end(self)
            return refs
        refs = self._make_refs()
        if "symbols" not in self.cache:  # small, kept: see symbols()
            self.cache["symbols"] = tuple(
                dict.fromkeys(r.symbol for r in refs if r.symbol is not None)
            )
        _RECENT_REFS[self] = refs
        if len(_RECENT_REFS) > 64:
            _RECENT_REFS.popitem(last=False)
        return refs

    def _make_refs(self) -> list[NameRef]:
        refs: list[NameRef] = []
        root = self.root
        if root is not None:
            _name_refs(root, 0, None, refs)
        els = self.elements
        for i, el in enumerate(els, 1):
            p = el.parent
            _name_refs(el, i, els[p - 1] if p > 0 else None, refs)
            if (
                el.end_name_start >= 0
                and el.zone == _ZONE_NODE
                and el.name not in EXPLICIT_TAGS
                and el.name != "SubTree"
            ):  # the end tag of a compact node names its type too
                refs.append(
                    NameRef(
                        el.end_name_start,
                        el.end_name_end,
                        el.name,
                        None,
                        _ROLE_NODE_TYPE_END,
                        _symbol(("model", el.name)),
                        i,
                    )
                )
        refs.sort(key=_start)
        return refs

    def ref_at(self, offset: int) -> NameRef | None:
        """The name token containing local ``offset`` (see :meth:`Model.ref_at`)."""
        refs = self.refs
        i = bisect_right([r.start for r in refs], offset) - 1
        if i >= 0 and refs[i].start <= offset <= refs[i].end:
            return refs[i]
        return None

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


_RECENT_REFS: OrderedDict[Section, list[NameRef]] = OrderedDict()


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

    def element(self, el: Element) -> Element:
        """An element of the section in document coordinates."""
        o = self.origin
        g = self.element_index
        return Element(
            el.name,
            el.zone,
            el.token_start + o,
            el.token_index + self.tok_origin,
            g(el.parent),
            el.depth,
            el.attrs,
            el.self_closing,
            el.closed,
            el.end + o if el.end >= 0 else -1,
            el.end_name_start + o if el.end_name_start >= 0 else -1,
            el.end_name_end + o if el.end_name_end >= 0 else -1,
            # Children are never the root (local 0): a top element may have thousands.
            list(map((self.elem_base - 1).__add__, el.children)),
            el.content,
        )

    def top(self) -> Element:
        """The section's top element in document coordinates."""
        return _top(self.section, self.origin, self.tok_origin, self.elem_base)

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


def _top(sec: Section, origin: int, tok_origin: int, elem_base: int) -> Element:
    """A section's top element in document coordinates (kept on the section while it
    stays where it is)."""
    hit: tuple[int, int, int, Element] | None = sec.cache.get("top")
    if hit is not None and hit[0] == origin and hit[1] == tok_origin and hit[2] == elem_base:
        return hit[3]
    el = Part(sec, origin, tok_origin, elem_base).element(sec.elements[0])
    sec.cache["top"] = (origin, tok_origin, elem_base, el)
    return el


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

    __slots__ = ("_cache", "_chunks", "_keys")

    def __init__(self, chunks: list[tuple[Part, tuple[Symbol, ...]]]) -> None:
        self._chunks = chunks
        keys: set[Symbol] = set()
        for _, symbols in chunks:
            keys.update(symbols)
        self._keys = keys
        self._cache: dict[Symbol, list[NameRef]] = {}

    def __getitem__(self, symbol: Symbol) -> list[NameRef]:
        refs = self._cache.get(symbol)
        if refs is None:
            if symbol not in self._keys:
                raise KeyError(symbol)
            refs = [
                part.ref(r)
                for part, symbols in self._chunks
                if symbol in symbols
                for r in part.section.refs
                if r.symbol == symbol
            ]
            self._cache[symbol] = refs
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
        "_cache",
        "_elements",
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
        self._cache: dict[Zone | None, list[Element]] = {}
        self.root_element: Element | None = None
        self.local: Section | None = None  # the section a section's own model is of
        self.head: Section | None = None  # None for a model that is not made of sections
        self.head_ntokens = 0
        self.sections: list[Section] = []
        self.origins: list[int] = []
        self.firsts: list[int] = []
        self.bases: list[int] = []
        self.top_names: list[str] = []  # the name of each section's top element
        self.sections_end = 0
        self.tail: Section | None = None
        self.tail_base = 0
        self.tail_start = 0

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
            with gc_paused():
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
            local = part.section.ref_at(offset - part.origin)
            return part.ref(local) if local is not None else None
        i = bisect_right(self.ref_starts, offset) - 1
        if i >= 0 and self.refs[i].start <= offset <= self.refs[i].end:
            return self.refs[i]
        return None

    def refs_to(self, symbol: Symbol) -> list[NameRef]:
        return self.by_symbol.get(symbol, [])

    @property
    def by_symbol(self) -> Mapping[Symbol, list[NameRef]]:
        """Every symbol's references in document order (built once, on first use)."""
        if self._by_symbol is None:
            if self.head is not None:
                with gc_paused():
                    chunks = [(p, p.section.symbols()) for p in self.parts()]
                    self._by_symbol = _SymbolIndex(chunks)
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
            found: list[Element] | None = self._cache.get(zone)
            if found is None:
                found = self._cache[zone] = [
                    _top(sec, o, f, b)
                    for sec, o, f, b in zip(
                        self.sections, self.origins, self.firsts, self.bases, strict=True
                    )
                    if zone is None or sec.elements[0].zone == zone
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
                _top(self.sections[k], self.origins[k], self.firsts[k], self.bases[k])
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
        # Chunk 0 is the head (from element 1 on), then the sections, then the tail.
        bases = [1, *self.bases]
        nsec = len(self.sections)
        if self.tail is not None:
            bases.append(self.tail_base)
            n = self.tail_base + len(self.tail.elements)
        else:
            assert self.head is not None
            n = 1 + len(self.head.elements)
        head, tail, tail_base = self.head, self.tail, self.tail_base
        sections, origins, firsts, elem_bases = self.sections, self.origins, self.firsts, self.bases

        # (Not a method: the view must not refer back to the model, a cycle that only the
        # cyclic collector could free.)
        def make(c: int, j: int) -> Element:
            if c == 0:
                assert head is not None
                return head.elements[j]  # already in document coordinates
            if c > nsec:
                assert tail is not None
                return Part(tail, 0, 0, tail_base).element(tail.elements[j])
            k = c - 1
            part = Part(sections[k], origins[k], firsts[k], elem_bases[k])
            return part.top() if j == 0 else part.element(sections[k].elements[j])

        lazy = _Lazy(n, bases, make)
        if n:
            lazy._items[0] = root
        return lazy


# The root of a section's own model when the document's is not at hand.
_STAND_IN = Element("", Zone.ROOT, 0, 0, -1, 0, (), False, True)


# --- XML names --------------------------------------------------------------------------------


# --- XML names --------------------------------------------------------------------------------

# An XML 1.0 (5th edition) Name.
_NAME_START = (
    ":A-Z_a-z\u00c0-\u00d6\u00d8-\u00f6\u00f8-\u02ff\u0370-\u037d\u037f-\u1fff\u200c-\u200d"
    "\u2070-\u218f\u2c00-\u2fef\u3001-\ud7ff\uf900-\ufdcf\ufdf0-\ufffd\U00010000-\U000effff"
)
_NAME_CHAR = _NAME_START + r"\-.0-9\u00b7\u0300-\u036f\u203f-\u2040"


# Compiled on first use: these character classes take tens of milliseconds to compile.
XML_NAME_RE = LazyPattern(f"[{_NAME_START}][{_NAME_CHAR}]*")
_NOT_NAME_CHAR = LazyPattern(f"[^{_NAME_CHAR}]")
# The same for ASCII names (the common case), cheap to compile.
_ASCII_NAME_RE = re.compile(r"[:A-Z_a-z][-.0-9:A-Z_a-z]*")
_ASCII_NOT_NAME_CHAR = re.compile(r"[^-.0-9:A-Z_a-z]")
# Characters the name rules already report (so an XML-name error would only repeat it).
_RULE_FORBIDDEN = FORBIDDEN | CONTROL_CHARS


def xml_name_problem(name: str, checked: bool, port: bool = False) -> tuple[int, str] | None:
    """First character that makes ``name`` an invalid XML name, unless the name rules
    already report it (``checked``; for a ``port``, a leading digit too): (index, message)."""
    if name.isascii():
        if _ASCII_NAME_RE.fullmatch(name):
            return None
        name_re: Any = _ASCII_NAME_RE
        not_name: Any = _ASCII_NOT_NAME_CHAR
    else:
        name_re, not_name = XML_NAME_RE, _NOT_NAME_CHAR
        if name_re.fullmatch(name):
            return None
    if name and not name_re.match(name[0]) and not_name.match(name[0]) is None:
        if port and checked and name[0] in "0123456789":
            return None
        if not checked or name[0] not in _RULE_FORBIDDEN:
            return 0, f"An XML name cannot start with {name[0]!r}"
        return None
    for m in not_name.finditer(name):
        ch = m.group(0)
        if checked and ch in _RULE_FORBIDDEN:
            continue
        shown = repr(ch) if ch.isprintable() else f"U+{ord(ch):04X}"
        return m.start(), f"{shown} is not allowed in an XML name ('{name}')"
    return None


# Names repeat: their XML-name check is remembered (bounded; cleared when full).
_XML_NAME_CACHE: dict[tuple[str, bool, bool], tuple[int, str] | None] = {}


def _xml_name_problem(name: str, checked: bool, port: bool) -> tuple[int, str] | None:
    key = (name, checked, port)
    try:
        return _XML_NAME_CACHE[key]
    except KeyError:
        pass
    if len(_XML_NAME_CACHE) >= 65536:
        _XML_NAME_CACHE.clear()
    found = _XML_NAME_CACHE[key] = xml_name_problem(name, checked, port)
    return found


def _zone_of(name: str, parent: Element | None, has_root: bool) -> Zone:
    if parent is None:
        return _ZONE_OUTSIDE if has_root else _ZONE_ROOT
    return zone_in(name, parent.zone)


def zone_in(name: str, pz: Zone) -> Zone:
    """The zone of an element named ``name`` whose parent's zone is ``pz``."""
    if pz == _ZONE_ROOT:
        if name == "BehaviorTree":
            return _ZONE_TREE
        if name == "TreeNodesModel":
            return _ZONE_MODELS
        if name == "include":
            return _ZONE_INCLUDE
        return _ZONE_OTHER
    if pz in (_ZONE_TREE, _ZONE_NODE):
        return _ZONE_NODE
    if pz == _ZONE_MODELS:
        return _ZONE_MODEL_ENTRY
    if pz == _ZONE_MODEL_ENTRY and name in PORT_TAGS:
        return _ZONE_PORT_DECL
    return _ZONE_OTHER


def _owner(el: Element) -> Symbol:
    """The symbol whose ports an element's attributes (or port declarations) are."""
    if el.name == "SubTree":
        return ("tree", el.value("ID") or "")
    if el.zone == _ZONE_NODE and el.name not in EXPLICIT_TAGS:
        return ("model", el.name)
    return ("model", el.value("ID") or "")


# A named tuple from all its fields, without the (slower) Python-level constructor.
_new = tuple.__new__

# Symbols repeat (every use of a node type or port): they are shared (bounded).
_SYMBOLS: dict[Symbol, Symbol] = {}


def _symbol(symbol: Symbol) -> Symbol:
    shared = _SYMBOLS.get(symbol)
    if shared is None:
        if len(_SYMBOLS) >= 65536:
            _SYMBOLS.clear()
        shared = _SYMBOLS[symbol] = symbol
    return shared


# The port symbols of each owner, by port name (bounded).
_PORTS: dict[Symbol, dict[str, Symbol]] = {}


def _port_symbols(owner: Symbol) -> dict[str, Symbol]:
    ports = _PORTS.get(owner)
    if ports is None:
        if len(_PORTS) >= 4096:
            _PORTS.clear()
        ports = _PORTS[owner] = {}
    return ports


def _value_ref(
    out: list[NameRef],
    el: Element,
    idx: int,
    a: Attr,
    kind: NameKind | None,
    role: Role,
    symbol: Symbol | None,
) -> None:
    if a.value is not None:
        out.append(
            _new(
                NameRef,
                (
                    el.token_start + a.value_start,
                    el.token_start + a.value_end,
                    a.value,
                    kind,
                    role,
                    _symbol(symbol) if symbol is not None else None,
                    idx,
                    a.quote,
                ),
            )
        )


# The symbol of each node type and the symbols of its ports, by type (bounded): every
# element of a document looks them up.
_MODEL_SYMBOLS: dict[str, tuple[Symbol, dict[str, Symbol]]] = {}


def _model_symbols(name: str) -> tuple[Symbol, dict[str, Symbol]]:
    found = _MODEL_SYMBOLS.get(name)
    if found is None:
        if len(_MODEL_SYMBOLS) >= 4096:
            _MODEL_SYMBOLS.clear()
        owner: Symbol = ("model", name)
        found = _MODEL_SYMBOLS[name] = (_symbol(owner), _port_symbols(owner))
    return found


def _name_refs(el: Element, idx: int, parent: Element | None, out: list[NameRef]) -> None:
    """Append the name tokens of one element to ``out``, by where the element sits (the
    contract's positions)."""
    zone = el.zone
    ts = el.token_start
    if zone == _ZONE_NODE:
        name = el.name
        if name in EXPLICIT_TAGS or name == "SubTree":
            a = el.attr("ID")
            if a is not None:
                role, sym = (
                    (_ROLE_SUBTREE_CALL, "tree") if name == "SubTree" else (_ROLE_NODE_ID, "model")
                )
                _value_ref(out, el, idx, a, _KIND_MODEL, role, (sym, a.value or ""))
            owner = _owner(el)
            ports = _port_symbols(owner)
        else:
            model_symbol, ports = _model_symbols(name)
            owner = model_symbol
            out.append(
                _new(
                    NameRef,
                    (
                        ts + 1,
                        ts + 1 + len(name),
                        name,
                        _KIND_MODEL,
                        _ROLE_NODE_TYPE,
                        model_symbol,
                        idx,
                        "",
                    ),
                )
            )
        # Unpacked rather than read by field: this runs for every attribute of every node.
        for an, ns, ne, value, vs, ve, quote in el.attrs:
            if an == "name":
                if value is not None:
                    out.append(
                        _new(
                            NameRef,
                            (
                                ts + vs,
                                ts + ve,
                                value,
                                _KIND_INSTANCE,
                                _ROLE_INSTANCE,
                                None,
                                idx,
                                quote,
                            ),
                        )
                    )
            elif an not in RESERVED_PORT_NAMES:
                psym = ports.get(an)
                if psym is None:
                    psym = ports[an] = _symbol(("port", *owner, an))
                out.append(
                    _new(
                        NameRef,
                        (ts + ns, ts + ne, an, _KIND_PORT, _ROLE_PORT_USE, psym, idx, ""),
                    )
                )
    elif zone == _ZONE_ROOT:
        a = el.attr("main_tree_to_execute")
        if a is not None:
            _value_ref(out, el, idx, a, None, _ROLE_MAIN_TREE, ("tree", a.value or ""))
    elif zone == _ZONE_TREE:
        a = el.attr("ID")
        if a is not None:
            _value_ref(out, el, idx, a, _KIND_MODEL, _ROLE_TREE_DEF, ("tree", a.value or ""))
    elif zone == _ZONE_MODEL_ENTRY:
        a = el.attr("ID")
        if a is not None:
            entry: Symbol = ("tree" if el.name == "SubTree" else "model", a.value or "")
            _value_ref(out, el, idx, a, _KIND_MODEL, _ROLE_MODEL_DEF, entry)
    elif zone == _ZONE_PORT_DECL and parent is not None:
        a = el.attr("name")
        if a is not None:
            _value_ref(
                out,
                el,
                idx,
                a,
                _KIND_PORT,
                _ROLE_PORT_DECL,
                ("port", *_owner(parent), a.value or ""),
            )


def start_tag_refs(text: str, at: int, zone: Zone, parent: Element | None) -> list[NameRef]:
    """The name tokens of the start tag at offset ``at``, exactly as a model of ``text``
    makes them, for a caller that knows the element's zone and parent without a model
    (:mod:`bt_lsp.rules.early_names`).  Element indexes in the result are 0."""
    out: list[NameRef] = []
    _name_refs(start_tag_element(text, at, zone), 0, parent, out)
    return out


def start_tag_element(text: str, at: int, zone: Zone) -> Element:
    """The element whose start tag is at offset ``at``, alone (no parent or children)."""
    tok = scan_token(text, at)
    return Element(tok.name, zone, at, 0, -1, 0, tok.attrs, tok.self_closing, tok.closed)


def _check_xml_names(
    tstart: int, tok: Token, checked: bool, problems: list[StructureProblem]
) -> None:
    xp = _xml_name_problem(tok.name, checked and tok.name not in EXPLICIT_TAGS, False)
    if xp is not None:
        at = tstart + 1 + xp[0]
        problems.append(StructureProblem(at, at + 1, XML_SYNTAX, xp[1]))
    for a in tok.attrs:
        xp = _xml_name_problem(a.name, checked, True)
        if xp is not None:
            at = tstart + a.name_start + xp[0]
            problems.append(StructureProblem(at, at + 1, XML_SYNTAX, xp[1]))


_NON_SPACE = re.compile(r"[^ \t\r\n]")

_HEAD, _SECTION, _TAIL = 0, 1, 2


class _Builder:
    """Runs the element stack over tokens.  Offsets are stored relative to ``origin``,
    token indexes relative to ``tok_origin``; elements are numbered in ``els`` (where,
    for a section or the tail, element 0 is the root)."""

    __slots__ = (
        "els",
        "has_root",
        "lexical",
        "origin",
        "problems",
        "stack",
        "text",
        "tok_origin",
    )

    def __init__(
        self,
        text: str,
        origin: int,
        tok_origin: int,
        els: list[Element],
        stack: list[int],
        has_root: bool,
    ) -> None:
        self.text = text
        self.origin = origin
        self.tok_origin = tok_origin
        self.els = els
        self.stack = stack
        self.has_root = has_root
        self.problems: list[StructureProblem] = []
        self.lexical: list[StructureProblem] = []

    def run(self, tokens: list[Token], starts: Sequence[int], i: int, mode: int) -> tuple[int, int]:
        """Process tokens from ``i``; returns where it stopped and how (``OPEN``: at a
        start tag with only the root open, or, for a section, at the root's end tag;
        ``CLOSED``: a section closed the root; ``EOF``)."""
        n = len(tokens)
        text, origin = self.text, self.origin
        els, stack, problems, lexical = self.els, self.stack, self.problems, self.lexical
        first = i
        start_kind, end_kind, text_kind = Kind.START, Kind.END, Kind.TEXT
        node_zone = Zone.NODE
        while i < n:
            tok = tokens[i]
            kind = tok.kind
            at_root = len(stack) == 1 and stack[0] == 0
            if at_root and mode != _TAIL:
                if kind == start_kind and (mode == _HEAD or i != first):
                    return i, OPEN
                if mode == _SECTION and kind == end_kind and tok.name == els[0].name:
                    return i, OPEN
            tstart = starts[i] - origin
            if tok.problems:
                for p in tok.problems:
                    lexical.append(
                        StructureProblem(tstart + p.start, tstart + p.end, p.code, p.message)
                    )
            if kind == text_kind:
                if not stack:
                    a = starts[i]
                    if not text[a : a + tok.length].isspace():
                        m = _NON_SPACE.search(text, a, a + tok.length)
                        at = (m.start() if m else a) - origin
                        problems.append(
                            StructureProblem(
                                at,
                                tstart + tok.length,
                                XML_SYNTAX,
                                "Text outside the root element"
                                if self.has_root
                                else "Text before the root element",
                            )
                        )
            elif kind == start_kind:
                parent = els[stack[-1]] if stack else None
                zone = _zone_of(tok.name, parent, self.has_root)
                if parent is None:
                    if self.has_root:
                        problems.append(
                            StructureProblem(
                                tstart + 1,
                                tstart + 1 + len(tok.name),
                                XML_SYNTAX,
                                f"Extra top-level element '<{tok.name}>'; a document has one root",
                            )
                        )
                    self.has_root = True
                idx = len(els)
                el = Element(
                    tok.name,
                    zone,
                    tstart,
                    i - self.tok_origin,
                    stack[-1] if stack else -1,
                    len(stack),
                    tok.attrs,
                    tok.self_closing,
                    tok.closed,
                )
                els.append(el)
                if parent is not None:
                    parent.children.append(idx)
                _check_xml_names(tstart, tok, zone == node_zone, problems)
                if tok.self_closing:
                    el.end = tstart + tok.length
                else:
                    stack.append(idx)
            elif kind == end_kind:
                closed = _close(tstart, tok, els, stack, problems)
                if closed >= 0 and els[closed].zone == _ZONE_PORT_DECL:
                    el = els[closed]
                    el.content = _content(tokens, starts, text, el.token_index + self.tok_origin, i)
                if mode == _SECTION and not stack:
                    return i + 1, CLOSED
            i += 1
        return i, EOF

    def finish(self, keep_root: bool) -> None:
        """Report the elements left open at the end (the root too unless ``keep_root``)."""
        stack = self.stack
        while len(stack) > (1 if keep_root else 0):
            _report_unclosed(self.els[stack.pop()], self.problems, closed_by=None)

    def section(self, ntokens: int, length: int, end: int, head: bool = False) -> Section:
        root_end = None
        if end == CLOSED:
            root = self.els[0]
            root_end = (root.end, root.end_name_start, root.end_name_end)
        return Section(
            ntokens,
            length,
            self.els[1:],
            self.problems,
            self.lexical,
            end,
            root_end,
            self.els[0] if head and self.els else None,
        )


def _start(r: NameRef) -> int:
    return r.start


def _section(
    tokens: list[Token], starts: Sequence[int], text: str, i: int, root_name: str
) -> tuple[Section, int, int]:
    """The section that starts at token ``i`` (a start tag with only the root open)."""
    origin = starts[i]
    stand_in = Element(root_name, Zone.ROOT, -origin, -i, -1, 0, (), False, True)
    b = _Builder(text, origin, i, [stand_in], [0], True)
    j, end = b.run(tokens, starts, i, _SECTION)
    if end == EOF:
        b.finish(keep_root=True)
    length = (starts[j] if j < len(starts) else len(text)) - origin
    return b.section(j - i, length, end), j, end


def build(scan: Scan, text: str, old: Model | None = None, change: Rescan | None = None) -> Model:
    """The model of a scanned text.  One pass, an explicit stack, no recursion.

    With the model ``old`` of the previous text and ``change``, the tokens an edit
    replaced since (see :func:`bt_lsp.syntax.scanner.rescan`), the sections that the edit cannot
    have changed are reused.
    """
    tokens = scan.tokens
    # A full build reads every start: as a list; an update reads a few.
    starts: Sequence[int] = scan.starts if change is not None else scan.starts.tolist()
    n = len(tokens)
    hb = _Builder(text, 0, 0, [], [], False)
    i, state = hb.run(tokens, starts, 0, _HEAD)
    root = hb.els[0] if hb.els else None
    model = Model([], [], [])
    model._elements = model._refs = model._problems = None
    model.root_element = root
    model.head_ntokens = i
    sections: list[Section] = []
    origins: list[int] = []
    firsts: list[int] = []
    bases: list[int] = []
    names: list[str] = []
    if state == OPEN and root is not None:
        base = 1
        shift = 0
        reuse = (
            old is not None
            and change is not None
            and bool(old.sections)
            and change.first >= old.head_ntokens
        )
        if reuse:
            assert old is not None and change is not None
            ends = old.firsts[1:]
            ends.append(old.sections_end)
            k = bisect_left(ends, change.first)
            if k:
                sections = old.sections[:k]
                origins = old.origins[:k]
                firsts = old.firsts[:k]
                bases = old.bases[:k]
                names = old.top_names[:k]
                i = ends[k - 1]
                state = sections[-1].end
                base = bases[-1] + len(sections[-1].elements)
            shift = change.new_stop - change.old_stop
        while state == OPEN and i < n and tokens[i].kind == Kind.START:
            if reuse and i >= change.new_stop:  # type: ignore[union-attr]
                assert old is not None
                m = bisect_left(old.firsts, i - shift)
                if m < len(old.firsts) and old.firsts[m] == i - shift:
                    # The rest lines up with the old sections again.
                    dchar = starts[i] - old.origins[m]
                    dbase = base - old.bases[m]
                    sections.extend(old.sections[m:])
                    origins.extend(map(dchar.__add__, old.origins[m:]))
                    firsts.extend(map(shift.__add__, old.firsts[m:]))
                    bases.extend(map(dbase.__add__, old.bases[m:]))
                    names.extend(old.top_names[m:])
                    i = old.sections_end + shift
                    state = old.sections[-1].end
                    base = bases[-1] + len(sections[-1].elements)
                    break
            sec, j, state = _section(tokens, starts, text, i, root.name)
            sections.append(sec)
            origins.append(starts[i])
            firsts.append(i)
            bases.append(base)
            names.append(sec.elements[0].name)
            base += len(sec.elements)
            i = j
        model.sections, model.origins, model.firsts, model.bases = sections, origins, firsts, bases
        model.top_names = names
        model.sections_end = i
        root.children = list(bases)
        if state == CLOSED:
            re_ = sections[-1].root_end
            assert re_ is not None
            o = origins[-1]
            root.end, root.end_name_start, root.end_name_end = (
                re_[0] + o,
                re_[1] + o if re_[1] >= 0 else -1,
                re_[2] + o if re_[2] >= 0 else -1,
            )
        tb = _Builder(text, 0, 0, [root], [0] if state != CLOSED else [], True)
        tb.run(tokens, starts, i, _TAIL)
        tb.finish(keep_root=False)
        model.tail_start = starts[i] if i < n else len(text)
        model.tail = tb.section(n - i, len(text) - model.tail_start, EOF)
        model.tail_base = base
    else:
        hb.finish(keep_root=False)
    model.head = hb.section(i if sections else n, 0, EOF, head=True)
    return model


def _close(
    tstart: int,
    tok: Token,
    elements: list[Element],
    stack: list[int],
    problems: list[StructureProblem],
) -> int:
    """Match an end tag to an open element, tolerating a few missing end tags; the index
    of the element it closed, -1 if none."""
    name_s, name_e = tstart + tok.name_start, tstart + tok.name_end
    match = -1
    for depth in range(len(stack) - 1, max(-1, len(stack) - 65), -1):
        if elements[stack[depth]].name == tok.name:
            match = depth
            break
    if match == -1:
        expected = f"; expected '</{elements[stack[-1]].name}>'" if stack else ""
        problems.append(
            StructureProblem(
                name_s if tok.name else tstart,
                name_e if tok.name else tstart + 2,
                XML_SYNTAX,
                f"Unexpected end tag '</{tok.name}>'{expected}",
            )
        )
        return -1
    while len(stack) > match + 1:
        _report_unclosed(elements[stack.pop()], problems, closed_by=tok.name)
    idx = stack.pop()
    el = elements[idx]
    el.end = tstart + tok.length
    el.end_name_start, el.end_name_end = name_s, name_e  # its ref: see Section.refs
    return idx


def _content(tokens: list[Token], starts: Sequence[int], text: str, first: int, stop: int) -> str:
    """The text of tokens ``first + 1 .. stop - 1`` (an element's content): its text runs
    with references decoded and its CDATA sections, whitespace runs made single spaces."""
    parts: list[str] = []
    for k in range(first + 1, stop):
        tok = tokens[k]
        s = starts[k]
        if tok.kind == Kind.TEXT:
            parts.append(decode_value(text[s : s + tok.length], 0, None))
        elif tok.kind == Kind.CDATA and tok.closed:
            parts.append(text[s + 9 : s + tok.length - 3])
    return " ".join("".join(parts).split())


def _report_unclosed(el: Element, problems: list[StructureProblem], closed_by: str | None) -> None:
    if not el.closed:
        return  # its start tag already has an error; do not cascade
    where = f" before '</{closed_by}>'" if closed_by is not None else ""
    problems.append(
        StructureProblem(
            el.name_start, el.name_end, XML_SYNTAX, f"Element '<{el.name}>' is not closed{where}"
        )
    )
