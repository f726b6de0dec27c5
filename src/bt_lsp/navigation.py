"""Navigation over BT XML: definitions, references, highlights, rename, symbols, folding and
linked editing.

Pure: everything here works on :class:`~bt_lsp.document.Document` values and returns
code-point offsets (or lines, for folding); the server converts them to LSP positions.
The rest of the workspace comes in as plain data: ``others`` are the other BT documents
by path, ``ctx`` is the document's :class:`~bt_lsp.context.Context` and ``includes`` its
resolved ``<include>`` elements.

A :class:`Place` names a span in some document: ``path=None`` is the document asked about,
:data:`BUILTIN_CATALOG` is the generated catalog of BehaviorTree.CPP's built-in nodes
(:func:`builtin_catalog`), anything else a workspace path.
"""

from __future__ import annotations

import re
from collections.abc import Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from enum import StrEnum
from functools import cache

from bt_lsp.builtins import BUILTINS, PortModel
from bt_lsp.context import Context
from bt_lsp.document import Document
from bt_lsp.edits import TextEdit
from bt_lsp.fixes import escape_value, other_file_edits, rename_edits, shown, taken_names
from bt_lsp.model import (
    EXPLICIT_TAGS,
    XML_NAME_RE,
    Element,
    Model,
    NameRef,
    Role,
    Symbol,
    Zone,
)
from bt_lsp.names import RESERVED_PORT_NAMES, NameKind, check_name, is_allowed_port_name
from bt_lsp.scanner import Kind
from bt_lsp.workspace import Include

__all__ = [
    "BUILTIN_CATALOG",
    "Catalog",
    "DocSymbol",
    "Fold",
    "Highlight",
    "KeyRef",
    "Place",
    "RenamePlan",
    "RenameRefused",
    "RenameTarget",
    "SymbolKind",
    "WorkspaceSymbol",
    "blackboard_keys",
    "builtin_catalog",
    "definition",
    "document_symbols",
    "element_end",
    "enclosing_tree",
    "folding_ranges",
    "highlights",
    "key_at",
    "linked_editing_ranges",
    "ports_of",
    "prepare_rename",
    "references",
    "rename",
    "workspace_symbols",
]

BUILTIN_CATALOG = "bt-lsp:builtins.xml"
"""The ``path`` of places in the built-in node catalog (see :func:`builtin_catalog`)."""


@dataclass(frozen=True, slots=True, order=True)
class Place:
    """A span in a document: ``None`` for the document asked about, else a path (or
    :data:`BUILTIN_CATALOG`)."""

    path: str | None
    start: int
    end: int


# --- elements and blackboard keys ---------------------------------------------------------


def element_end(doc: Document, el: Element) -> int:
    """Offset after an element: after its end tag, or after its start tag when it was
    never closed."""
    if el.end >= 0:
        return el.end
    return el.token_start + doc.scan.tokens[el.token_index].length


def _element_at_tag(model: Model, offset: int) -> tuple[int, bool] | None:
    """The element whose start-tag name (``False``) or end-tag name (``True``) holds
    ``offset`` (its end counts)."""
    for i, el in enumerate(model.elements):
        if el.name_start <= offset <= el.name_end:
            return i, False
        if el.end_name_start >= 0 and el.end_name_start <= offset <= el.end_name_end:
            return i, True
    return None


def enclosing_tree(model: Model, index: int) -> int:
    """Index of the ``<BehaviorTree>`` holding element ``index`` (itself included), or -1."""
    els = model.elements
    while index >= 0:
        if els[index].zone == Zone.TREE:
            return index
        index = els[index].parent
    return -1


def _subtree(model: Model, index: int) -> range:
    """Indexes of element ``index`` and its descendants (elements are in document order)."""
    els = model.elements
    depth = els[index].depth
    stop = index + 1
    while stop < len(els) and els[stop].depth > depth:
        stop += 1
    return range(index, stop)


@dataclass(frozen=True, slots=True)
class KeyRef:
    """A blackboard key written ``{key}`` in a port value; ``start``/``end`` span the key
    (without braces and surrounding spaces).  ``tree`` is the element index of its tree."""

    key: str
    start: int
    end: int
    element: int
    tree: int


_KEY_RE = re.compile(r"\{([^{}]*)\}")


def _keys_of(doc: Document, idx: int, tree: int) -> Iterator[KeyRef]:
    el = doc.model.elements[idx]
    if el.zone != Zone.NODE:
        return
    text = doc.text
    for a in el.attrs:
        if a.value is None or a.name in RESERVED_PORT_NAMES or "{" not in a.value:
            continue
        vs, ve = el.span_of_value(a)
        for m in _KEY_RE.finditer(text, vs, ve):
            raw = m.group(1)
            key = raw.strip()
            if not key or key == "=":
                continue
            s = m.start(1) + (len(raw) - len(raw.lstrip()))
            yield KeyRef(key, s, s + len(key), idx, tree)


def blackboard_keys(doc: Document, tree: int) -> list[KeyRef]:
    """Every ``{key}`` written in the ports of the nodes of one tree (by element index)."""
    model = doc.model
    if not 0 <= tree < len(model.elements):
        return []
    return [k for i in _subtree(model, tree) for k in _keys_of(doc, i, tree)]


def key_at(doc: Document, offset: int) -> KeyRef | None:
    """The blackboard key under ``offset`` (its end counts)."""
    model = doc.model
    for i, el in enumerate(model.elements):
        if el.token_start > offset:
            break
        if el.zone != Zone.NODE:
            continue
        for k in _keys_of(doc, i, enclosing_tree(model, i)):
            if k.start <= offset <= k.end:
                return k
    return None


# --- the built-in catalog -----------------------------------------------------------------


@dataclass(frozen=True, slots=True)
class Catalog:
    """A ``<TreeNodesModel>`` of BehaviorTree.CPP's built-in nodes, and where each node's
    ``ID`` (symbol ``("model", id)``) and each port's ``name`` (``("port", "model", id,
    port)``) are written in it."""

    text: str
    spans: Mapping[Symbol, tuple[int, int]]


def _xml_text(text: str) -> str:
    return text.replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;")


def _comment(text: str) -> str:
    text = " ".join(text.split())
    while "--" in text:
        text = text.replace("--", "- -")
    return text.rstrip("-")


@cache
def builtin_catalog() -> Catalog:
    """The built-in nodes written as a ``<TreeNodesModel>``, each with its description, for
    "go to definition" on a built-in node or port."""
    parts: list[str] = [
        '<?xml version="1.0" encoding="UTF-8"?>\n',
        "<!-- The node types that a default BehaviorTree.CPP 4.x factory registers, "
        "with their ports.\n     Generated by bt-lsp for reference; editing it changes "
        "nothing. -->\n",
        '<root BTCPP_format="4">\n  <TreeNodesModel>\n',
    ]
    spans: dict[Symbol, tuple[int, int]] = {}
    pos = sum(len(p) for p in parts)

    def add(s: str) -> None:
        nonlocal pos
        parts.append(s)
        pos += len(s)

    for node in sorted(BUILTINS.values(), key=lambda n: (n.category, n.id)):
        if node.category == "SubTree":
            continue  # <SubTree> is a call of a tree, never a node type of its own
        add(f"    <!-- {_comment(node.description)} -->\n")
        add(f'    <{node.category} ID="')
        spans[("model", node.id)] = (pos, pos + len(node.id))
        add(node.id)
        if not node.ports:
            add('"/>\n')
            continue
        add('">\n')
        for p in node.ports:
            add(f'      <{p.direction}_port name="')
            spans[("port", "model", node.id, p.name)] = (pos, pos + len(p.name))
            add(p.name)
            add(f'" type="{escape_value(p.type, chr(34))}"')
            if p.default is not None:
                add(f' default="{escape_value(p.default, chr(34))}"')
            add(f">{_xml_text(p.description)}</{p.direction}_port>\n")
        add(f"    </{node.category}>\n")
    add("  </TreeNodesModel>\n</root>\n")
    return Catalog("".join(parts), spans)


# --- definition ---------------------------------------------------------------------------


def _declarations(
    doc: Document, others: Mapping[str, Document], symbol: Symbol, role: Role
) -> list[Place]:
    """Occurrences of ``symbol`` in the ``role`` that declares it: this document's first."""
    own = [Place(None, r.start, r.end) for r in doc.model.refs_to(symbol) if r.role == role]
    if own:
        return own
    return [
        Place(path, r.start, r.end)
        for path, d in others.items()
        for r in d.model.refs_to(symbol)
        if r.role == role
    ]


def _place(ctx: Context, path: str | None, start: int, end: int) -> Place:
    return Place(None if path == ctx.path else path, start, end)


def _tree_definition(
    doc: Document, others: Mapping[str, Document], ctx: Context | None, tree_id: str
) -> list[Place]:
    sym: Symbol = ("tree", tree_id)
    own = [Place(None, r.start, r.end) for r in doc.model.refs_to(sym) if r.role == Role.TREE_DEF]
    if own:
        return own
    if ctx is not None:
        decls = ctx.trees.get(tree_id) or ctx.workspace_trees.get(tree_id)
        if decls:
            return [_place(ctx, t.path, t.start, t.end) for t in decls]
    found = _declarations(doc, others, sym, Role.TREE_DEF)
    return found or _declarations(doc, others, sym, Role.MODEL_DEF)


def _model_definition(
    doc: Document, others: Mapping[str, Document], ctx: Context | None, model_id: str
) -> list[Place]:
    sym: Symbol = ("model", model_id)
    own = [Place(None, r.start, r.end) for r in doc.model.refs_to(sym) if r.role == Role.MODEL_DEF]
    if own:
        return own
    if ctx is not None:
        decl = ctx.models.get(model_id)
        if decl is not None:
            return [_place(ctx, decl.path, decl.start, decl.end)]
    found = _declarations(doc, others, sym, Role.MODEL_DEF)
    if found:
        return found
    span = builtin_catalog().spans.get(sym)
    return [Place(BUILTIN_CATALOG, *span)] if span is not None else []


def _port_definition(doc: Document, others: Mapping[str, Document], sym: Symbol) -> list[Place]:
    found = _declarations(doc, others, sym, Role.PORT_DECL)
    if found:
        return found
    span = builtin_catalog().spans.get(sym)
    return [Place(BUILTIN_CATALOG, *span)] if span is not None else []


def definition(
    doc: Document,
    offset: int,
    others: Mapping[str, Document] | None = None,
    *,
    ctx: Context | None = None,
    includes: Sequence[Include] = (),
) -> list[Place]:
    """Where the name under ``offset`` is declared.

    A ``<SubTree ID>`` or ``main_tree_to_execute`` leads to its ``<BehaviorTree>``, a node
    to its ``<TreeNodesModel>`` entry (a built-in to the built-in catalog), a port
    attribute to its port declaration, an ``<include path>`` to the start of that file.
    A declaration leads to itself.
    """
    others = others or {}
    for inc in includes:
        if inc.start <= offset <= inc.end and inc.target is not None:
            return [Place(str(inc.target), 0, 0)]
    ref = doc.model.ref_at(offset)
    if ref is None or ref.symbol is None:
        return []
    if ref.declaration:
        return [Place(None, ref.start, ref.end)]
    sym = ref.symbol
    if sym[0] == "tree":
        return _tree_definition(doc, others, ctx, sym[1])
    if sym[0] == "model":
        return _model_definition(doc, others, ctx, sym[1])
    if sym[0] == "port":
        return _port_definition(doc, others, sym)
    return []


# --- references and highlights ------------------------------------------------------------


def references(
    doc: Document,
    offset: int,
    others: Mapping[str, Document] | None = None,
    *,
    include_declaration: bool = True,
) -> list[Place]:
    """Every occurrence of the name under ``offset`` in this document and the others (end
    tags left out: they repeat their start tag).  A blackboard key's references are the
    uses of that key in its tree."""
    ref = doc.model.ref_at(offset)
    if ref is None:
        key = key_at(doc, offset)
        if key is None:
            return []
        return [
            Place(None, k.start, k.end) for k in blackboard_keys(doc, key.tree) if k.key == key.key
        ]
    if ref.symbol is None:
        return [Place(None, ref.start, ref.end)]

    def keep(r: NameRef) -> bool:
        return r.role != Role.NODE_TYPE_END and (include_declaration or not r.declaration)

    out = [Place(None, r.start, r.end) for r in doc.model.refs_to(ref.symbol) if keep(r)]
    for path, other in (others or {}).items():
        out.extend(Place(path, r.start, r.end) for r in other.model.refs_to(ref.symbol) if keep(r))
    return out


@dataclass(frozen=True, slots=True, order=True)
class Highlight:
    """An occurrence in the document: ``write`` for a declaration, else a read (or plain
    text, ``text``, for tag names that are not names of the BT model)."""

    start: int
    end: int
    write: bool = False
    text: bool = False


def highlights(doc: Document, offset: int) -> list[Highlight]:
    """The occurrences, in this document, of the name under ``offset``: a tree, node type,
    port or instance name, a blackboard key in its tree, or an element's start and end
    tag names."""
    model = doc.model
    ref = model.ref_at(offset)
    if ref is not None:
        if ref.symbol is None:
            return [Highlight(ref.start, ref.end)]
        return sorted(Highlight(r.start, r.end, r.declaration) for r in model.refs_to(ref.symbol))
    key = key_at(doc, offset)
    if key is not None:
        return [
            Highlight(k.start, k.end) for k in blackboard_keys(doc, key.tree) if k.key == key.key
        ]
    hit = _element_at_tag(model, offset)
    if hit is None:
        return []
    el = model.elements[hit[0]]
    out = [Highlight(el.name_start, el.name_end, text=True)]
    if el.end_name_start >= 0:
        out.append(Highlight(el.end_name_start, el.end_name_end, text=True))
    return out


# --- rename -------------------------------------------------------------------------------


class RenameRefused(Exception):
    """A rename that cannot be done; the message says why."""

    def __init__(self, message: str) -> None:
        super().__init__(message)
        self.message = message


@dataclass(frozen=True, slots=True)
class RenameTarget:
    """What a rename at a position changes: the span of the name and its current text."""

    start: int
    end: int
    placeholder: str
    ref: NameRef


@dataclass(frozen=True, slots=True)
class RenamePlan:
    """Edits to the document, and to the other documents by path."""

    edits: tuple[TextEdit, ...]
    other_edits: Mapping[str, tuple[TextEdit, ...]] = field(default_factory=dict)

    @property
    def places(self) -> int:
        return len(self.edits) + sum(len(e) for e in self.other_edits.values())


def prepare_rename(doc: Document, offset: int) -> RenameTarget | None:
    """The name a rename at ``offset`` would change, ``None`` when there is none there.

    Raises :class:`RenameRefused` for names that cannot be renamed from XML (the built-in
    nodes of BehaviorTree.CPP and their ports)."""
    ref = doc.model.ref_at(offset)
    if ref is None:
        return None
    sym = ref.symbol
    if sym is not None and sym[0] == "model" and sym[1] in BUILTINS:
        raise RenameRefused(
            f"'{shown(sym[1])}' is a built-in node type of BehaviorTree.CPP; it cannot be renamed"
        )
    if (
        sym is not None
        and sym[:2] == ("port", "model")
        and sym[2] in BUILTINS
        and BUILTINS[sym[2]].port(sym[3]) is not None
    ):
        raise RenameRefused(
            f"'{shown(sym[3])}' is a port of the built-in node '{sym[2]}'; "
            "BehaviorTree.CPP declares it, so it cannot be renamed"
        )
    return RenameTarget(ref.start, ref.end, ref.text, ref)


def _kind_of(ref: NameRef) -> NameKind:
    if ref.kind is not None:
        return ref.kind
    return NameKind.MODEL  # main_tree_to_execute, end tags


def _check_new_name(
    ref: NameRef, new_name: str, model: Model, others: Mapping[str, Document]
) -> None:
    kind = _kind_of(ref)
    sym = ref.symbol
    violations = check_name(new_name, kind, declaration=kind is NameKind.PORT)
    if violations:
        raise RenameRefused(f"Cannot rename to '{shown(new_name)}': {violations[0].message}")
    if kind is NameKind.INSTANCE or sym is None:
        return
    all_refs = [r for m in (model, *(d.model for d in others.values())) for r in m.refs_to(sym)]
    if kind is NameKind.PORT:
        if not is_allowed_port_name(new_name):
            raise RenameRefused(
                f"Cannot rename to '{shown(new_name)}': a port name must start with an "
                "ASCII letter, or BehaviorTree.CPP does not read the attribute as a port"
            )
        if any(r.role == Role.PORT_USE for r in all_refs) and not XML_NAME_RE.fullmatch(new_name):
            raise RenameRefused(
                f"Cannot rename to '{shown(new_name)}': the port is written as an attribute "
                "name, and this is not a valid XML name"
            )
    elif not XML_NAME_RE.fullmatch(new_name) and any(
        r.role in (Role.NODE_TYPE, Role.NODE_TYPE_END) for r in all_refs
    ):
        raise RenameRefused(
            f"Cannot rename to '{shown(new_name)}': the node type is written as an "
            "element name, and this is not a valid XML name"
        )
    if new_name == sym[-1]:
        return
    if sym[0] != "port" and new_name in BUILTINS:
        raise RenameRefused(
            f"Cannot rename to '{shown(new_name)}': it is a built-in node type of "
            "BehaviorTree.CPP, and trees and node types share one namespace"
        )
    if new_name in taken_names(model, sym, (d.model for d in others.values())):
        if sym[0] == "port":
            owner = f"tree '{sym[2]}'" if sym[1] == "tree" else f"node type '{sym[2]}'"
            raise RenameRefused(
                f"Cannot rename to '{shown(new_name)}': the {owner} already has a port "
                "with that name"
            )
        raise RenameRefused(
            f"Cannot rename to '{shown(new_name)}': a tree or node type with that name "
            "already exists (trees and node types share one namespace)"
        )


def rename(
    doc: Document, offset: int, new_name: str, others: Mapping[str, Document] | None = None
) -> RenamePlan | None:
    """Rename the name under ``offset`` and every reference to it in the workspace.

    ``None`` when there is no name there; raises :class:`RenameRefused` when the name cannot
    be renamed or ``new_name`` breaks a rule (the message gives the rule's reason)."""
    others = others or {}
    target = prepare_rename(doc, offset)
    if target is None:
        return None
    ref = target.ref
    model = doc.model
    _check_new_name(ref, new_name, model, others)
    if ref.symbol is None:
        return RenamePlan(tuple(rename_edits([ref], new_name)))
    return RenamePlan(
        tuple(rename_edits(model.refs_to(ref.symbol), new_name)),
        other_file_edits(ref.symbol, new_name, {p: d.model for p, d in others.items()}),
    )


# --- document symbols ---------------------------------------------------------------------


class SymbolKind(StrEnum):
    TREE = "tree"
    NODE = "node"
    SUBTREE = "subtree call"
    MODELS = "TreeNodesModel"
    MODEL = "model"
    PORT = "port"
    INCLUDE = "include"


@dataclass(slots=True)
class DocSymbol:
    """A symbol of the outline: ``start``/``end`` span its element, ``sel_start``/
    ``sel_end`` its name."""

    name: str
    detail: str
    kind: SymbolKind
    start: int
    end: int
    sel_start: int
    sel_end: int
    children: list[DocSymbol] = field(default_factory=list)


def _category(node_id: str | None, ctx: Context | None) -> str:
    if node_id is None:
        return ""
    b = BUILTINS.get(node_id)
    if b is not None:
        return b.category
    if ctx is not None:
        decl = ctx.models.get(node_id)
        if decl is not None:
            return decl.category
    return ""


def _id_span(el: Element) -> tuple[str, int, int]:
    a = el.attr("ID")
    if a is not None and a.value is not None:
        s, e = el.span_of_value(a)
        return a.value, s, e
    return "", el.name_start, el.name_end


def _symbol_of(el: Element, ctx: Context | None) -> DocSymbol | None:
    zone = el.zone
    if zone == Zone.TREE:
        tid, s, e = _id_span(el)
        return DocSymbol(tid or "(no ID)", "BehaviorTree", SymbolKind.TREE, 0, 0, s, e)
    if zone == Zone.NODE:
        label = el.value("name")
        if el.name == "SubTree":
            tid, s, e = _id_span(el)
            return DocSymbol(
                label or tid or "SubTree", f"SubTree {tid}".strip(), SymbolKind.SUBTREE, 0, 0, s, e
            )
        if el.name in EXPLICIT_TAGS:
            nid, s, e = _id_span(el)
            detail = f"{el.name} {nid}".strip()
        else:
            nid, s, e = el.name, el.name_start, el.name_end
            detail = _category(nid, ctx)
            detail = f"{detail} {nid}".strip() if label else detail
        return DocSymbol(label or nid or el.name, detail, SymbolKind.NODE, 0, 0, s, e)
    if zone == Zone.MODELS:
        return DocSymbol(el.name, "", SymbolKind.MODELS, 0, 0, el.name_start, el.name_end)
    if zone == Zone.MODEL_ENTRY:
        mid, s, e = _id_span(el)
        return DocSymbol(mid or el.name, el.name, SymbolKind.MODEL, 0, 0, s, e)
    if zone == Zone.PORT_DECL:
        a = el.attr("name")
        if a is not None and a.value is not None:
            s, e = el.span_of_value(a)
            pname = a.value
        else:
            pname, s, e = "", el.name_start, el.name_end
        ptype = el.value("type")
        detail = el.name.replace("_", " ") + (f": {ptype}" if ptype else "")
        return DocSymbol(pname or "(no name)", detail, SymbolKind.PORT, 0, 0, s, e)
    if zone == Zone.INCLUDE:
        a = el.attr("path")
        if a is not None and a.value is not None:
            s, e = el.span_of_value(a)
            return DocSymbol(a.value or "(no path)", "include", SymbolKind.INCLUDE, 0, 0, s, e)
        return DocSymbol(
            "(no path)", "include", SymbolKind.INCLUDE, 0, 0, el.name_start, el.name_end
        )
    return None


def document_symbols(doc: Document, ctx: Context | None = None) -> list[DocSymbol]:
    """The outline: the trees with their nodes as a hierarchy, the ``<TreeNodesModel>``
    with its entries and their ports, and the includes.  A symbol's range holds its
    children's ranges; names are never empty."""
    model = doc.model
    if ctx is None:
        ctx = Context.from_document(doc)
    made: dict[int, DocSymbol] = {}
    top: list[DocSymbol] = []
    for i, el in enumerate(model.elements):
        sym = _symbol_of(el, ctx)
        if sym is None:
            continue
        sym.start, sym.end = el.token_start, element_end(doc, el)
        made[i] = sym
        parent = made.get(el.parent)
        (parent.children if parent is not None else top).append(sym)
    # A parent's range must hold its children's (an unclosed element ends at its tag).
    for i in sorted(made, reverse=True):
        sym = made[i]
        for c in sym.children:
            sym.end = max(sym.end, c.end)
    return top


@dataclass(frozen=True, slots=True)
class WorkspaceSymbol:
    """A tree or a ``<TreeNodesModel>`` entry somewhere in the workspace."""

    name: str
    kind: SymbolKind
    detail: str
    path: str
    start: int
    end: int


def _matches(query: str, name: str) -> bool:
    """Case-insensitive subsequence match (what editors expect of a symbol search)."""
    if not query:
        return True
    it = iter(name.lower())
    return all(c in it for c in query.lower())


def workspace_symbols(
    docs: Iterable[tuple[str, Document]], query: str = "", limit: int = 1000
) -> list[WorkspaceSymbol]:
    """The trees and model entries of ``docs`` (by key, usually a path or URI) whose name
    matches ``query``, at most ``limit``."""
    out: list[WorkspaceSymbol] = []
    for key, doc in docs:
        for r in doc.model.refs:
            if r.role == Role.TREE_DEF:
                kind, detail = SymbolKind.TREE, "BehaviorTree"
            elif r.role == Role.MODEL_DEF:
                kind = SymbolKind.MODEL
                detail = doc.model.elements[r.element].name
            else:
                continue
            if not r.text or not _matches(query, r.text):
                continue
            out.append(WorkspaceSymbol(r.text, kind, detail, key, r.start, r.end))
            if len(out) >= limit:
                return out
    return out


# --- folding and linked editing -----------------------------------------------------------


@dataclass(frozen=True, slots=True, order=True)
class Fold:
    """Lines to fold (0-based, both included); ``comment`` for comments."""

    start_line: int
    end_line: int
    comment: bool = False


def folding_ranges(doc: Document) -> list[Fold]:
    """Elements that span several lines (the line of their end tag stays visible when the
    end tag starts its line), and comments that span several lines."""
    lines = doc.lines
    text = doc.text
    out: set[Fold] = set()
    for el in doc.model.elements:
        first = lines.line_of(el.token_start)
        end = element_end(doc, el)
        last = lines.line_of(max(end - 1, el.token_start))
        if el.end_name_start >= 0:
            tag = el.end_name_start - 2  # '</'
            line_start = lines.line_start(last)
            if text[line_start:tag].strip() == "" and last > first:
                last -= 1
        if last > first:
            out.add(Fold(first, last))
    for start, tok in zip(doc.scan.starts, doc.scan.tokens, strict=True):
        if tok.kind == Kind.COMMENT:
            first = lines.line_of(start)
            last = lines.line_of(start + tok.length - 1)
            if last > first:
                out.add(Fold(first, last, comment=True))
    return sorted(out)


def linked_editing_ranges(doc: Document, offset: int) -> list[tuple[int, int]] | None:
    """The start-tag and end-tag names of the element whose tag name holds ``offset``, so
    that editing one edits the other; ``None`` outside a tag name or without an end tag."""
    model = doc.model
    hit = _element_at_tag(model, offset)
    if hit is None:
        return None
    el = model.elements[hit[0]]
    if el.end_name_start < 0:
        return None
    return [(el.name_start, el.name_end), (el.end_name_start, el.end_name_end)]


# --- shared by completion and hover -------------------------------------------------------


def ports_of(el: Element, ctx: Context | None) -> tuple[PortModel, ...] | None:
    """The declared ports of a node element, ``None`` when its model is unknown."""
    node_id = el.node_id
    if node_id is None:
        return None
    if el.name == "SubTree":
        decl = ctx.subtree_models.get(node_id) if ctx is not None else None
        return decl.ports if decl is not None else None
    b = BUILTINS.get(node_id)
    if b is not None:
        return b.ports
    decl = ctx.models.get(node_id) if ctx is not None else None
    return decl.ports if decl is not None else None
