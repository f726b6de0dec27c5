"""The elements of a BT document: where each sits (its :class:`Zone`), what a name token
does there (its :class:`Role`), and the records a model is made of (:class:`Element`,
:class:`NameRef`, :class:`StructureProblem`).

A *symbol* identifies what a name denotes, so that renaming one occurrence can rename all:
a :class:`NameSymbol` (a tree or a node type, by ID) or a :class:`PortSymbol` (a port of
one).  They are tuples, so equal symbols are equal keys however they were made.
"""

from __future__ import annotations

from collections.abc import Sequence
from enum import IntEnum, StrEnum
from typing import Literal, NamedTuple

from bt_lsp.syntax.tokens import Attr, Kind, Token
from bt_lsp.syntax.vocabulary import NameKind


class NameSymbol(NamedTuple):
    """A tree (``kind == "tree"``: a ``<BehaviorTree>`` ID, a ``<SubTree>`` entry or call)
    or a node type (``kind == "model"``) called ``name``."""

    kind: Literal["tree", "model"]
    name: str


class PortSymbol(NamedTuple):
    """The port ``name`` of the tree or node type ``owner`` (of kind ``owner_kind``)."""

    kind: Literal["port"]
    owner_kind: Literal["tree", "model"]
    owner: str
    name: str

    @property
    def owner_symbol(self) -> NameSymbol:
        return NameSymbol(self.owner_kind, self.owner)


Symbol = NameSymbol | PortSymbol


def tree_symbol(tree_id: str) -> NameSymbol:
    return NameSymbol("tree", tree_id)


def model_symbol(model_id: str) -> NameSymbol:
    return NameSymbol("model", model_id)


def port_symbol(owner: NameSymbol, name: str) -> PortSymbol:
    return PortSymbol("port", owner.kind, owner.name, name)


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
_ZONE_MODELS = Zone.MODELS
_ZONE_MODEL_ENTRY = Zone.MODEL_ENTRY
_ZONE_INCLUDE = Zone.INCLUDE
_ZONE_NODE = Zone.NODE
_ZONE_OTHER = Zone.OTHER
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


# ``Element._end`` of an empty-element tag: its end is its start tag's (not kept: an int
# per element costs four times what ``<A/>`` does).
_SELF_CLOSED = -2
# The children of an element that has none (shared; the builder makes a list for the
# first child).
NO_CHILDREN: tuple[int, ...] = ()


class Element:
    """One element.  A document may be made of a hundred thousand ``<A/>``, so an element
    is one slotted object that keeps only what it cannot derive: its name, attributes and
    flags are those of its start tag (a token, shared by equal tags), the end of an empty
    element and the end of its end tag's name are computed when read, and its children
    are an array of ints (or a shared empty tuple)."""

    __slots__ = (
        "_end",
        "children",
        "content",
        "depth",
        "end_name_start",
        "parent",
        "tag",
        "token_index",
        "token_start",
        "zone",
    )

    tag: Token
    zone: Zone
    token_start: int
    token_index: int
    parent: int
    depth: int
    _end: int
    end_name_start: int
    children: Sequence[int]
    content: str | None

    def __init__(
        self,
        name: str,
        zone: Zone,
        token_start: int,
        token_index: int,
        parent: int,
        depth: int,
        attrs: tuple[Attr, ...],
        self_closing: bool,
        closed: bool,  # its start tag ends with '>' or '/>'
        end: int = -1,  # offset after its end tag (or its start tag when empty); -1 if never closed
        end_name_start: int = -1,  # absolute start of the end tag's name, if any
        children: Sequence[int] = NO_CHILDREN,
        # The text inside a port declaration (BehaviorTree.CPP writes a port's description
        # there); ``None`` for every other element.
        content: str | None = None,
        length: int = 0,  # the length of its start tag
    ) -> None:
        tag = Token(
            Kind.START, length, length + 1, name, 1, 1 + len(name), attrs, self_closing, closed
        )
        self._set(tag, zone, token_start, token_index, parent, depth)
        if not self_closing:
            self._end = end
        self.end_name_start = end_name_start
        self.children = children if children else NO_CHILDREN
        self.content = content

    @classmethod
    def of_tag(
        cls, tag: Token, zone: Zone, token_start: int, token_index: int, parent: int, depth: int
    ) -> Element:
        """The element that start tag ``tag`` (at ``token_start``, token ``token_index``)
        opens: no end or children yet."""
        el = cls.__new__(cls)
        el._set(tag, zone, token_start, token_index, parent, depth)
        el.end_name_start = -1
        el.children = NO_CHILDREN
        el.content = None
        return el

    def _set(
        self, tag: Token, zone: Zone, token_start: int, token_index: int, parent: int, depth: int
    ) -> None:
        self.tag = tag
        self.zone = zone
        self.token_start = token_start
        self.token_index = token_index
        self.parent = parent
        self.depth = depth
        self._end = _SELF_CLOSED if tag.self_closing else -1

    def moved(
        self, origin: int, token_origin: int, parent: int, children: Sequence[int]
    ) -> Element:
        """This element ``origin`` code points and ``token_origin`` tokens further on."""
        el = Element.__new__(Element)
        el.tag, el.zone, el.depth, el.content = self.tag, self.zone, self.depth, self.content
        el.token_start = self.token_start + origin
        el.token_index = self.token_index + token_origin
        el.parent = parent
        end = self._end
        el._end = end + origin if end >= 0 else end
        ens = self.end_name_start
        el.end_name_start = ens + origin if ens >= 0 else -1
        el.children = children if children else NO_CHILDREN
        return el

    @property
    def name(self) -> str:
        return self.tag.name

    @property
    def attrs(self) -> tuple[Attr, ...]:
        return self.tag.attrs

    @property
    def self_closing(self) -> bool:
        return self.tag.self_closing

    @property
    def closed(self) -> bool:
        """Whether its start tag ends with '>' or '/>'."""
        return self.tag.closed

    @property
    def length(self) -> int:
        """The length of its start tag."""
        return self.tag.length

    @property
    def end(self) -> int:
        """The offset after its end tag (or its start tag when empty); -1 if never closed."""
        end = self._end
        return self.token_start + self.length if end == _SELF_CLOSED else end

    @end.setter
    def end(self, value: int) -> None:
        self._end = value

    @property
    def end_name_end(self) -> int:
        """The end of the end tag's name (which is the element's), -1 if none."""
        ens = self.end_name_start
        return ens + len(self.name) if ens >= 0 else -1

    def _fields(self) -> tuple[object, ...]:
        return (
            self.name,
            self.zone,
            self.token_start,
            self.token_index,
            self.parent,
            self.depth,
            self.attrs,
            self.self_closing,
            self.closed,
            self.end,
            self.end_name_start,
            self.children,
            self.content,
        )

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Element):
            return NotImplemented
        return self._fields() == other._fields()

    __hash__ = None  # type: ignore[assignment]  # mutable while the builder runs

    def __repr__(self) -> str:
        return f"Element({', '.join(map(repr, self._fields()))})"

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
