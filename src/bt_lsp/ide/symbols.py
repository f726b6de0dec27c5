"""The document outline (trees with their nodes, the ``<TreeNodesModel>`` with its
entries and ports, the includes) and the workspace symbol search."""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, field
from enum import StrEnum

from bt_lsp.ide.places import element_end
from bt_lsp.ide.ports import builtins_in
from bt_lsp.rules.context import Context
from bt_lsp.syntax.document import Document
from bt_lsp.syntax.elements import EXPLICIT_TAGS, Element, Role, Zone


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
    b = builtins_in(ctx).get(node_id)
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
