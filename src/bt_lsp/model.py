"""The BT document model: elements, and every name token with its kind and symbol.

Built from the scanner's tokens in one loop with an explicit element stack (no
recursion).  It decides, exactly as the contract lists, which token is a model name, a
port name, an instance name or a reference, and what it refers to; everywhere else
(comments, CDATA, ``<include path>``, attributes of ``<root>`` and ``<BehaviorTree>``,
reserved attributes of nodes) nothing is a name.

A *symbol* identifies what a name denotes, so that renaming one occurrence can rename all:
``("tree", id)``, ``("model", id)`` and ``("port", "tree"|"model", owner_id, port)``.
"""

from __future__ import annotations

import re
from bisect import bisect_right
from dataclasses import dataclass, field
from enum import IntEnum, StrEnum

from bt_lsp.names import RESERVED_PORT_NAMES, NameKind
from bt_lsp.scanner import XML_SYNTAX, Attr, Kind, Scan, Token

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


@dataclass(frozen=True, slots=True)
class NameRef:
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
        return self.zone == Zone.NODE

    @property
    def node_id(self) -> str | None:
        """The node type: the ``ID`` of an explicit node or SubTree, else the tag name."""
        if self.name in EXPLICIT_TAGS or self.name == "SubTree":
            return self.value("ID")
        return self.name


@dataclass(frozen=True, slots=True)
class StructureProblem:
    start: int
    end: int
    code: str
    message: str


@dataclass(slots=True)
class Model:
    elements: list[Element]
    refs: list[NameRef]
    problems: list[StructureProblem]
    ref_starts: list[int]
    _by_symbol: dict[Symbol, list[NameRef]] | None = None

    @property
    def root(self) -> Element | None:
        return self.elements[0] if self.elements and self.elements[0].zone == Zone.ROOT else None

    def ref_at(self, offset: int) -> NameRef | None:
        """The name token containing ``offset`` (its end counts: a cursor after a name)."""
        i = bisect_right(self.ref_starts, offset) - 1
        if i >= 0 and self.refs[i].start <= offset <= self.refs[i].end:
            return self.refs[i]
        return None

    def refs_to(self, symbol: Symbol) -> list[NameRef]:
        return self.by_symbol.get(symbol, [])

    @property
    def by_symbol(self) -> dict[Symbol, list[NameRef]]:
        """Every symbol's references in document order (built once, on first use)."""
        if self._by_symbol is None:
            index: dict[Symbol, list[NameRef]] = {}
            for r in self.refs:
                if r.symbol is not None:
                    index.setdefault(r.symbol, []).append(r)
            self._by_symbol = index
        return self._by_symbol

    def trees(self) -> list[Element]:
        return [e for e in self.elements if e.zone == Zone.TREE]


# An XML 1.0 (5th edition) Name.
_NAME_START = (
    ":A-Z_a-z\u00c0-\u00d6\u00d8-\u00f6\u00f8-\u02ff\u0370-\u037d\u037f-\u1fff\u200c-\u200d"
    "\u2070-\u218f\u2c00-\u2fef\u3001-\ud7ff\uf900-\ufdcf\ufdf0-\ufffd\U00010000-\U000effff"
)
_NAME_CHAR = _NAME_START + r"\-.0-9\u00b7\u0300-\u036f\u203f-\u2040"
XML_NAME_RE = re.compile(f"[{_NAME_START}][{_NAME_CHAR}]*")
_NOT_NAME_CHAR = re.compile(f"[^{_NAME_CHAR}]")
# Characters the name rules already report (so an XML-name error would only repeat it).
_RULE_FORBIDDEN = set(" \t\n\r<>&\"'/\\:*?|.") | {chr(c) for c in range(32)} | {"\x7f"}


def xml_name_problem(name: str, checked: bool, port: bool = False) -> tuple[int, str] | None:
    """First character that makes ``name`` an invalid XML name, unless the name rules
    already report it (``checked``; for a ``port``, a leading digit too): (index, message)."""
    if XML_NAME_RE.fullmatch(name):
        return None
    if name and not XML_NAME_RE.match(name[0]) and _NOT_NAME_CHAR.match(name[0]) is None:
        if port and checked and name[0] in "0123456789":
            return None
        if not checked or name[0] not in _RULE_FORBIDDEN:
            return 0, f"An XML name cannot start with {name[0]!r}"
        return None
    for m in _NOT_NAME_CHAR.finditer(name):
        ch = m.group(0)
        if checked and ch in _RULE_FORBIDDEN:
            continue
        shown = repr(ch) if ch.isprintable() else f"U+{ord(ch):04X}"
        return m.start(), f"{shown} is not allowed in an XML name ('{name}')"
    return None


def _zone_of(name: str, parent: Element | None, has_root: bool) -> Zone:
    if parent is None:
        return Zone.OUTSIDE if has_root else Zone.ROOT
    pz = parent.zone
    if pz == Zone.ROOT:
        if name == "BehaviorTree":
            return Zone.TREE
        if name == "TreeNodesModel":
            return Zone.MODELS
        if name == "include":
            return Zone.INCLUDE
        return Zone.OTHER
    if pz in (Zone.TREE, Zone.NODE):
        return Zone.NODE
    if pz == Zone.MODELS:
        return Zone.MODEL_ENTRY
    if pz == Zone.MODEL_ENTRY and name in PORT_TAGS:
        return Zone.PORT_DECL
    return Zone.OTHER


def _owner(el: Element) -> Symbol:
    """The symbol whose ports an element's attributes (or port declarations) are."""
    if el.name == "SubTree":
        return ("tree", el.value("ID") or "")
    if el.zone == Zone.NODE and el.name not in EXPLICIT_TAGS:
        return ("model", el.name)
    return ("model", el.value("ID") or "")


def _value_ref(
    el: Element, idx: int, a: Attr, kind: NameKind | None, role: Role, symbol: Symbol | None
) -> NameRef | None:
    if a.value is None:
        return None
    return NameRef(
        el.token_start + a.value_start,
        el.token_start + a.value_end,
        a.value,
        kind,
        role,
        symbol,
        idx,
        a.quote,
    )


def _name_refs(el: Element, idx: int, parent: Element | None) -> list[NameRef]:
    """The name tokens of one element, by where it sits (the contract's positions)."""
    zone = el.zone
    ts = el.token_start
    out: list[NameRef | None] = []
    if zone == Zone.ROOT:
        a = el.attr("main_tree_to_execute")
        if a is not None:
            out.append(_value_ref(el, idx, a, None, Role.MAIN_TREE, ("tree", a.value or "")))
    elif zone == Zone.TREE:
        a = el.attr("ID")
        if a is not None:
            out.append(
                _value_ref(el, idx, a, NameKind.MODEL, Role.TREE_DEF, ("tree", a.value or ""))
            )
    elif zone == Zone.NODE:
        name = el.name
        if name in EXPLICIT_TAGS or name == "SubTree":
            a = el.attr("ID")
            if a is not None:
                role, sym = (
                    (Role.SUBTREE_CALL, "tree") if name == "SubTree" else (Role.NODE_ID, "model")
                )
                out.append(_value_ref(el, idx, a, NameKind.MODEL, role, (sym, a.value or "")))
        else:
            out.append(
                NameRef(
                    ts + 1,
                    ts + 1 + len(name),
                    name,
                    NameKind.MODEL,
                    Role.NODE_TYPE,
                    ("model", name),
                    idx,
                )
            )
        owner = _owner(el)
        for a in el.attrs:
            an = a.name
            if an == "name":
                out.append(_value_ref(el, idx, a, NameKind.INSTANCE, Role.INSTANCE, None))
            elif an not in RESERVED_PORT_NAMES:
                out.append(
                    NameRef(
                        ts + a.name_start,
                        ts + a.name_end,
                        an,
                        NameKind.PORT,
                        Role.PORT_USE,
                        ("port", *owner, an),
                        idx,
                    )
                )
    elif zone == Zone.MODEL_ENTRY:
        a = el.attr("ID")
        if a is not None:
            entry: Symbol = ("tree" if el.name == "SubTree" else "model", a.value or "")
            out.append(_value_ref(el, idx, a, NameKind.MODEL, Role.MODEL_DEF, entry))
    elif zone == Zone.PORT_DECL and parent is not None:
        a = el.attr("name")
        if a is not None:
            out.append(
                _value_ref(
                    el,
                    idx,
                    a,
                    NameKind.PORT,
                    Role.PORT_DECL,
                    ("port", *_owner(parent), a.value or ""),
                )
            )
    return [r for r in out if r is not None]


def _check_xml_names(
    tstart: int, tok: Token, checked: bool, problems: list[StructureProblem]
) -> None:
    xp = xml_name_problem(tok.name, checked and tok.name not in EXPLICIT_TAGS)
    if xp is not None:
        at = tstart + 1 + xp[0]
        problems.append(StructureProblem(at, at + 1, XML_SYNTAX, xp[1]))
    for a in tok.attrs:
        xp = xml_name_problem(a.name, checked, port=True)
        if xp is not None:
            at = tstart + a.name_start + xp[0]
            problems.append(StructureProblem(at, at + 1, XML_SYNTAX, xp[1]))


def build(scan: Scan, text: str) -> Model:
    """The model of a scanned text.  One pass, an explicit stack, no recursion."""
    elements: list[Element] = []
    refs: list[NameRef] = []
    problems: list[StructureProblem] = []
    stack: list[int] = []
    has_root = False
    for ti, (tstart, tok) in enumerate(zip(scan.starts, scan.tokens, strict=True)):
        kind = tok.kind
        if kind == Kind.TEXT:
            if not stack and not text[tstart : tstart + tok.length].isspace():
                m = _NON_SPACE.search(text, tstart, tstart + tok.length)
                at = m.start() if m else tstart
                problems.append(
                    StructureProblem(
                        at,
                        tstart + tok.length,
                        XML_SYNTAX,
                        "Text outside the root element"
                        if has_root
                        else "Text before the root element",
                    )
                )
            continue
        if kind == Kind.START:
            parent = elements[stack[-1]] if stack else None
            zone = _zone_of(tok.name, parent, has_root)
            if parent is None:
                if has_root:
                    problems.append(
                        StructureProblem(
                            tstart + 1,
                            tstart + 1 + len(tok.name),
                            XML_SYNTAX,
                            f"Extra top-level element '<{tok.name}>'; a document has one root",
                        )
                    )
                has_root = True
            idx = len(elements)
            el = Element(
                tok.name,
                zone,
                tstart,
                ti,
                stack[-1] if stack else -1,
                len(stack),
                tok.attrs,
                tok.self_closing,
                tok.closed,
            )
            elements.append(el)
            if parent is not None:
                parent.children.append(idx)
            refs.extend(_name_refs(el, idx, parent))
            _check_xml_names(tstart, tok, zone == Zone.NODE, problems)
            if tok.self_closing:
                el.end = tstart + tok.length
            else:
                stack.append(idx)
        elif kind == Kind.END:
            _close(tstart, tok, elements, stack, refs, problems)
    while stack:
        _report_unclosed(elements[stack.pop()], problems, closed_by=None)
    refs.sort(key=lambda r: r.start)
    return Model(elements, refs, problems, [r.start for r in refs])


_NON_SPACE = re.compile(r"[^ \t\r\n]")


def _close(
    tstart: int,
    tok: Token,
    elements: list[Element],
    stack: list[int],
    refs: list[NameRef],
    problems: list[StructureProblem],
) -> None:
    """Match an end tag to an open element, tolerating a few missing end tags."""
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
        return
    while len(stack) > match + 1:
        _report_unclosed(elements[stack.pop()], problems, closed_by=tok.name)
    idx = stack.pop()
    el = elements[idx]
    el.end = tstart + tok.length
    el.end_name_start, el.end_name_end = name_s, name_e
    if el.zone == Zone.NODE and el.name not in EXPLICIT_TAGS and el.name != "SubTree":
        refs.append(
            NameRef(name_s, name_e, tok.name, None, Role.NODE_TYPE_END, ("model", tok.name), idx)
        )


def _report_unclosed(el: Element, problems: list[StructureProblem], closed_by: str | None) -> None:
    if not el.closed:
        return  # its start tag already has an error; do not cascade
    where = f" before '</{closed_by}>'" if closed_by is not None else ""
    problems.append(
        StructureProblem(
            el.name_start, el.name_end, XML_SYNTAX, f"Element '<{el.name}>' is not closed{where}"
        )
    )
