"""Go to definition: where the name under the cursor is declared, in this document, the
workspace (through the document's :class:`~bt_lsp.rules.context.Context`), the built-in
catalog, or the file an ``<include>`` names.

Pure: it works on :class:`~bt_lsp.syntax.document.Document` values and returns
code-point offsets; the server converts them to LSP positions.  The rest of the workspace
comes in as plain data: ``others`` are the other BT documents by path, ``ctx`` is the
document's context and ``includes`` its resolved ``<include>`` elements."""

from __future__ import annotations

from collections.abc import Mapping, Sequence

from bt_lsp.ide.catalog import builtin_catalog, catalog_path
from bt_lsp.ide.places import IncludeLink, Place
from bt_lsp.rules.context import Context
from bt_lsp.syntax.document import Document
from bt_lsp.syntax.elements import PortSymbol, Role, Symbol, model_symbol, tree_symbol


def _declarations(
    doc: Document, others: Mapping[str, Document], symbol: Symbol, role: Role
) -> list[Place]:
    """Occurrences of ``symbol`` in the ``role`` that declares it: this document's first
    (read from the declaring elements only, not from every use of the name)."""
    own = [Place(None, r.start, r.end) for r in doc.model.declarations_of(symbol) if r.role == role]
    if own:
        return own
    return [
        Place(path, r.start, r.end)
        for path, d in others.items()
        for r in d.model.declarations_of(symbol)
        if r.role == role
    ]


def _place(ctx: Context, path: str | None, start: int, end: int) -> Place:
    return Place(None if path == ctx.path else path, start, end)


def _tree_definition(
    doc: Document, others: Mapping[str, Document], ctx: Context | None, tree_id: str
) -> list[Place]:
    sym = tree_symbol(tree_id)
    own = [
        Place(None, r.start, r.end)
        for r in doc.model.declarations_of(sym)
        if r.role == Role.TREE_DEF
    ]
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
    sym = model_symbol(model_id)
    own = [
        Place(None, r.start, r.end)
        for r in doc.model.declarations_of(sym)
        if r.role == Role.MODEL_DEF
    ]
    if own:
        return own
    if ctx is not None:
        decl = ctx.models.get(model_id)
        if decl is not None:
            return [_place(ctx, decl.path, decl.start, decl.end)]
    found = _declarations(doc, others, sym, Role.MODEL_DEF)
    if found:
        return found
    return _builtin_place(ctx, sym)


def _builtin_place(ctx: Context | None, sym: Symbol) -> list[Place]:
    """The symbol in the built-in catalog of the document's BehaviorTree.CPP version."""
    version = ctx.btcpp_version if ctx is not None else None
    span = builtin_catalog(version).spans.get(sym)
    return [Place(catalog_path(version), *span)] if span is not None else []


def _port_definition(
    doc: Document, others: Mapping[str, Document], ctx: Context | None, sym: PortSymbol
) -> list[Place]:
    found = _declarations(doc, others, sym, Role.PORT_DECL)
    if found:
        return found
    return _builtin_place(ctx, sym)


def definition(
    doc: Document,
    offset: int,
    others: Mapping[str, Document] | None = None,
    *,
    ctx: Context | None = None,
    includes: Sequence[IncludeLink] = (),
) -> list[Place]:
    """Where the name under ``offset`` is declared.

    A ``<SubTree ID>`` or ``main_tree_to_execute`` leads to its ``<BehaviorTree>``, a node
    to its ``<TreeNodesModel>`` entry (a built-in to the built-in catalog), a port
    attribute to its port declaration, an ``<include path>`` to the start of that file.
    A declaration leads to itself.
    """
    others = others or {}
    for start, end, target in includes:
        if start <= offset <= end:
            return [Place(target, 0, 0)]
    ref = doc.model.ref_at(offset)
    if ref is None or ref.symbol is None:
        return []
    if ref.declaration:
        return [Place(None, ref.start, ref.end)]
    sym = ref.symbol
    if sym.kind == "port":
        return _port_definition(doc, others, ctx, sym)
    if sym.kind == "tree":
        return _tree_definition(doc, others, ctx, sym.name)
    return _model_definition(doc, others, ctx, sym.name)
