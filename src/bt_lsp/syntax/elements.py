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
from typing import Literal, NamedTuple, Protocol

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


# ``Element.extent`` of an empty-element tag: its end is its start tag's.
SELF_CLOSED = -2
# The children of an element that has none (shared).
NO_CHILDREN: tuple[int, ...] = ()


class Place(Protocol):
    """Where an element's children and content are kept: the columns of its section
    (:class:`bt_lsp.syntax.table.ElementTable`), or the element itself."""

    def children_of(self, local: int) -> Sequence[int]: ...

    def content_of(self, local: int) -> str | None: ...


class Own:
    """The children and content of an element made on its own (not read from a table)."""

    __slots__ = ("children", "content")

    def __init__(self, children: Sequence[int], content: str | None) -> None:
        self.children = children
        self.content = content

    def children_of(self, local: int) -> Sequence[int]:
        return self.children

    def content_of(self, local: int) -> str | None:
        return self.content


_ALONE = Own(NO_CHILDREN, None)


class _Fields(NamedTuple):
    tag: Token  # its start tag: name, attributes and flags (shared by equal tags)
    # Its start tag's name and attributes (read as often as the rules read an element).
    name: str
    attrs: tuple[Attr, ...]
    zone: Zone
    token_start: int
    token_index: int
    parent: int
    depth: int
    # Its end less its start; -1 if never closed, SELF_CLOSED for an empty element.
    extent: int
    # The start of its end tag's name less its start; -1 if none.
    end_name_at: int
    place: Place  # where its children and content are kept
    local: int  # its row there


class Element(_Fields):
    """One element.  A document may be made of a million ``<A/>``, so elements are not
    kept: a section keeps its elements as columns of machine integers
    (:class:`bt_lsp.syntax.table.ElementTable`) and an element is a tuple made when read.
    Its name, attributes and flags are those of its start tag (a token shared by equal
    tags); its end, its end tag's name, its children and its content are computed when
    read.  Equal elements compare equal however they were made."""

    __slots__ = ()

    def __new__(
        cls,
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
    ) -> Element:
        tag = Token(
            Kind.START, length, length + 1, name, 1, 1 + len(name), attrs, self_closing, closed
        )
        return of_row(
            tag,
            zone,
            token_start,
            token_index,
            parent,
            depth,
            SELF_CLOSED if self_closing else (end - token_start if end >= 0 else -1),
            end_name_start - token_start if end_name_start >= 0 else -1,
            Own(children, content) if children or content is not None else _ALONE,
            0,
        )

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
        x = self.extent
        if x >= 0:
            return self.token_start + x
        return self.token_start + self.tag.length if x == SELF_CLOSED else -1

    @property
    def end_name_start(self) -> int:
        """The start of its end tag's name, -1 if none."""
        x = self.end_name_at
        return self.token_start + x if x >= 0 else -1

    @property
    def end_name_end(self) -> int:
        """The end of the end tag's name (which is the element's), -1 if none."""
        x = self.end_name_at
        return self.token_start + x + len(self.tag.name) if x >= 0 else -1

    @property
    def children(self) -> Sequence[int]:
        """The indexes of its child elements (in the coordinates it was read in)."""
        return self.place.children_of(self.local)

    @property
    def content(self) -> str | None:
        """The text inside a port declaration; ``None`` for every other element."""
        return self.place.content_of(self.local)

    def _key(self) -> tuple[object, ...]:
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
            tuple(self.children),
            self.content,
        )

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Element):
            return NotImplemented
        return self._key() == other._key()

    def __ne__(self, other: object) -> bool:
        if not isinstance(other, Element):
            return NotImplemented
        return self._key() != other._key()

    __hash__ = None  # type: ignore[assignment]  # like the records it replaced

    def __repr__(self) -> str:
        return f"Element({', '.join(map(repr, self._key()))})"

    @property
    def name_start(self) -> int:
        return self.token_start + 1

    @property
    def name_end(self) -> int:
        return self.token_start + 1 + len(self.tag.name)

    def attr(self, name: str) -> Attr | None:
        for a in self.tag.attrs:
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
        name = self.tag.name
        if name in EXPLICIT_TAGS or name == "SubTree":
            return self.value("ID")
        return name


def of_row(
    tag: Token,
    zone: Zone,
    token_start: int,
    token_index: int,
    parent: int,
    depth: int,
    extent: int,
    end_name_at: int,
    place: Place,
    local: int,
) -> Element:
    """The element of these fields (as a table row holds them)."""
    return _new(
        Element,
        (
            tag,
            tag.name,
            tag.attrs,
            zone,
            token_start,
            token_index,
            parent,
            depth,
            extent,
            end_name_at,
            place,
            local,
        ),
    )


# Makes a tuple subclass from its fields without its constructor.
_new = tuple.__new__


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
