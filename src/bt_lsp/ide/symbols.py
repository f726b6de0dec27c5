"""The document outline (trees with their nodes, the ``<TreeNodesModel>`` with its
entries and ports, the includes) and the workspace symbol search."""

from __future__ import annotations

from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass, field
from enum import StrEnum
from operator import attrgetter

from bt_lsp.ide.places import element_end
from bt_lsp.ide.ports import builtins_in
from bt_lsp.rules.context import Context
from bt_lsp.syntax.document import Document
from bt_lsp.syntax.elements import EXPLICIT_TAGS, Element, Role, Zone
from bt_lsp.syntax.sections import Section


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


def _category(node_id: str | None, ctx: Context | None, used: dict[str, str] | None = None) -> str:
    """The category of a node type; a custom type's is recorded in ``used`` (what an
    outline kept for later versions depends on in the context)."""
    if node_id is None:
        return ""
    b = builtins_in(ctx).get(node_id)
    if b is not None:
        return b.category
    found = ""
    if ctx is not None:
        decl = ctx.models.get(node_id)
        if decl is not None:
            found = decl.category
    if used is not None:
        used[node_id] = found
    return found


def _id_span(el: Element) -> tuple[str, int, int]:
    a = el.attr("ID")
    if a is not None and a.value is not None:
        s, e = el.span_of_value(a)
        return a.value, s, e
    return "", el.name_start, el.name_end


def _label(el: Element) -> str | None:
    """The ``name`` attribute's value (``Element.value`` inlined: it is asked of every
    node of the outline)."""
    for a in el.attrs:
        if a.name == "name":
            return a.value
    return None


# Enum members as module constants: reading ``Zone.NODE`` costs a lookup through the
# enum class (most of a symbol's time in Python 3.11), a module global does not.
_Z_NODE, _Z_TREE, _Z_MODELS = Zone.NODE, Zone.TREE, Zone.MODELS
_Z_MODEL_ENTRY, _Z_PORT_DECL, _Z_INCLUDE = Zone.MODEL_ENTRY, Zone.PORT_DECL, Zone.INCLUDE
_K_TREE, _K_NODE, _K_SUBTREE = SymbolKind.TREE, SymbolKind.NODE, SymbolKind.SUBTREE
_K_MODELS, _K_MODEL, _K_PORT = SymbolKind.MODELS, SymbolKind.MODEL, SymbolKind.PORT
_K_INCLUDE = SymbolKind.INCLUDE


def _symbol_of(el: Element, category: Callable[[str], str]) -> DocSymbol | None:
    zone = el.zone
    if zone == _Z_NODE:
        label = _label(el)
        name = el.name
        if name == "SubTree":
            tid, s, e = _id_span(el)
            return DocSymbol(
                label or tid or "SubTree", f"SubTree {tid}".strip(), _K_SUBTREE, 0, 0, s, e
            )
        if name in EXPLICIT_TAGS:
            nid, s, e = _id_span(el)
            detail = f"{name} {nid}".strip()
        else:
            nid, s, e = name, el.name_start, el.name_end
            detail = category(nid)
            detail = f"{detail} {nid}".strip() if label else detail
        return DocSymbol(label or nid or name, detail, _K_NODE, 0, 0, s, e)
    if zone == _Z_TREE:
        tid, s, e = _id_span(el)
        return DocSymbol(tid or "(no ID)", "BehaviorTree", _K_TREE, 0, 0, s, e)
    if zone == _Z_MODELS:
        return DocSymbol(el.name, "", _K_MODELS, 0, 0, el.name_start, el.name_end)
    if zone == _Z_MODEL_ENTRY:
        mid, s, e = _id_span(el)
        return DocSymbol(mid or el.name, el.name, _K_MODEL, 0, 0, s, e)
    if zone == _Z_PORT_DECL:
        a = el.attr("name")
        if a is not None and a.value is not None:
            s, e = el.span_of_value(a)
            pname = a.value
        else:
            pname, s, e = "", el.name_start, el.name_end
        ptype = el.value("type")
        detail = el.name.replace("_", " ") + (f": {ptype}" if ptype else "")
        return DocSymbol(pname or "(no name)", detail, _K_PORT, 0, 0, s, e)
    if zone == _Z_INCLUDE:
        a = el.attr("path")
        if a is not None and a.value is not None:
            s, e = el.span_of_value(a)
            return DocSymbol(a.value or "(no path)", "include", _K_INCLUDE, 0, 0, s, e)
        return DocSymbol("(no path)", "include", _K_INCLUDE, 0, 0, el.name_start, el.name_end)
    return None


def _outline(
    items: Iterable[tuple[int, Element]],
    ctx: Context | None,
    end_of: Callable[[Element], int],
    used: dict[str, str] | None = None,
) -> list[DocSymbol]:
    """The symbols of ``items`` (index, element) as a hierarchy; an element whose parent
    is not among them (or is no symbol) is at the top."""
    made: dict[int, DocSymbol] = {}
    top: list[DocSymbol] = []
    known: dict[str, str] = {}  # node type -> category, each looked up once

    def category(node_id: str) -> str:
        found = known.get(node_id)
        if found is None:
            found = known[node_id] = _category(node_id, ctx, used)
        return found

    parents: list[DocSymbol] = []  # the symbols with children, in document order
    for i, el in items:
        sym = _symbol_of(el, category)
        if sym is None:
            continue
        sym.start, sym.end = el.token_start, end_of(el)
        made[i] = sym
        parent = made.get(el.parent)
        if parent is None:
            top.append(sym)
        else:
            if not parent.children:
                parents.append(parent)
            parent.children.append(sym)
    # A parent's range must hold its children's (an unclosed element ends at its tag);
    # the deepest first, so that a child's end is final when its parent's is taken.
    for sym in reversed(parents):
        sym.end = max(sym.end, *map(_END, sym.children))
    return top


_END = attrgetter("end")


def document_symbols(doc: Document, ctx: Context | None = None) -> list[DocSymbol]:
    """The outline: the trees with their nodes as a hierarchy, the ``<TreeNodesModel>``
    with its entries and their ports, and the includes.  A symbol's range holds its
    children's ranges; names are never empty."""
    if ctx is None:
        ctx = Context.from_document(doc)
    return _outline(enumerate(doc.model.elements), ctx, lambda el: element_end(doc, el))


@dataclass(slots=True)
class SectionOutline:
    """The outline of one section, in its coordinates (offsets from its start), and the
    categories of the custom node types it shows (looked up in the context)."""

    symbols: list[DocSymbol]
    categories: dict[str, str]


@dataclass(slots=True)
class OutlinePart:
    """A piece of the outline in document order: the symbols of one section (``section``
    set, offsets from ``origin``) or of the document's head or tail (in document
    coordinates, ``origin`` 0)."""

    origin: int
    section: Section | None
    outline: SectionOutline


def categories_hold(categories: dict[str, str], ctx: Context) -> bool:
    """Whether the custom node types' categories an outline showed are still ``ctx``'s."""
    return all(_category(n, ctx) == c for n, c in categories.items())


# The outline of a section its caller keeps in another form (see :func:`outline_parts`).
KEPT = SectionOutline([], {})


def section_outline(doc: Document, k: int, ctx: Context, *, keep: bool = True) -> SectionOutline:
    """The outline of section ``k`` of ``doc``'s model, kept on the section (which later
    versions share while it is unchanged) for as long as the categories it shows are the
    context's: an outline after an edit costs the sections the edit changed.  With
    ``keep`` false it is made without keeping it (a caller that keeps its JSON only)."""
    model = doc.model
    sec = model.sections[k]
    found: SectionOutline | None = sec.cache.get("outline")
    if found is not None and categories_hold(found.categories, ctx):
        return found
    tokens = doc.scan.tokens
    tok_origin = model.firsts[k]

    def end_of(el: Element) -> int:
        if el.end >= 0:
            return el.end
        return el.token_start + tokens[el.token_index + tok_origin].length

    used: dict[str, str] = {}
    # Local element j + 1 is sec.elements[j]; local 0 (the root) is never a symbol.
    symbols = _outline(enumerate(sec.elements, 1), ctx, end_of, used)
    found = SectionOutline(symbols, used)
    if keep:
        sec.cache["outline"] = found
    return found


def outline_parts(
    doc: Document, ctx: Context | None = None, kept: Callable[[Section], bool] | None = None
) -> list[OutlinePart]:
    """:func:`iter_outline_parts` as a list."""
    return list(iter_outline_parts(doc, ctx, kept))


def iter_outline_parts(
    doc: Document, ctx: Context | None = None, kept: Callable[[Section], bool] | None = None
) -> Iterator[OutlinePart]:
    """:func:`document_symbols` in pieces: the head's symbols, each section's (kept
    between versions, see :func:`section_outline`) and the tail's.  A model that is not
    made of sections is one piece.  With ``kept``, a section it says the caller keeps
    in its own form gets :data:`KEPT`, and the others' outlines are not kept."""
    if ctx is None:
        ctx = Context.from_document(doc)
    model = doc.model
    if model.head is None:
        yield OutlinePart(0, None, SectionOutline(document_symbols(doc, ctx), {}))
        return
    els = model.elements

    def end_of(el: Element) -> int:
        return element_end(doc, el)

    def loose(first: int, stop: int) -> OutlinePart | None:
        found = _outline(((i, els[i]) for i in range(first, stop)), ctx, end_of)
        return OutlinePart(0, None, SectionOutline(found, {})) if found else None

    head = loose(1, 1 + len(model.head.elements))
    if head is not None:
        yield head
    for k, (sec, origin) in enumerate(zip(model.sections, model.origins, strict=True)):
        if kept is None:
            yield OutlinePart(origin, sec, section_outline(doc, k, ctx))
        elif kept(sec):
            yield OutlinePart(origin, sec, KEPT)
        else:
            yield OutlinePart(origin, sec, section_outline(doc, k, ctx, keep=False))
    if model.tail is not None:
        tail = loose(model.tail_base, model.tail_base + len(model.tail.elements))
        if tail is not None:
            yield tail


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
