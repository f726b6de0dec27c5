"""A tree's picture as the workspace sees it: the CLI's ``render`` and the server's
``bt-lsp.renderTree`` both draw through here, so they agree with ``check`` on what the
tree's nodes are (the models of every workspace file) and what their problems are."""

from __future__ import annotations

from pathlib import Path

from bt_lsp.project.index import ProjectIndex
from bt_lsp.render import Format, Picture, render, workspace_resolver
from bt_lsp.rules.diagnostics import Diagnostic
from bt_lsp.syntax.document import Document
from bt_lsp.syntax.elements import Element
from bt_lsp.syntax.model import Model


def draw(
    workspace: ProjectIndex,
    path: Path,
    doc: Document,
    tree: Element,
    fmt: Format,
    *,
    ports: bool = False,
    expand_subtrees: bool = False,
    diagnostics: list[Diagnostic] | None = None,
) -> tuple[str, Picture]:
    """``tree`` of ``doc`` (at ``path``) drawn in ``fmt``, with the diagnostics
    ``check`` reports for it (``diagnostics`` when the caller has them, after its
    severity settings), SubTree calls resolved in its include closure and the workspace."""
    ctx = workspace.context_for(path, doc)
    if diagnostics is None:
        diagnostics = workspace.diagnostics(path, doc)
    others: dict[str, Model] = {}
    if expand_subtrees:
        for p in workspace.include_closure(path, doc):
            d = workspace.document(p)
            if d is not None:
                others[str(p)] = d.model
        for p, d in workspace.bt_documents():
            others.setdefault(str(p), d.model)
    return render(
        doc.model,
        tree,
        fmt,
        ctx=ctx,
        diagnostics=diagnostics,
        ports=ports,
        expand_subtrees=expand_subtrees,
        resolve=workspace_resolver(doc.model, ctx, others),
        text_length=len(doc.text),
    )
