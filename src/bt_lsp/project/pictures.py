"""A tree's picture as the workspace sees it: the CLI's ``render`` and the server's
``bt-lsp.renderTree`` both draw through here, so they agree with ``check`` on what the
tree's nodes are (the models of every workspace file) and what their problems are.
:func:`tree_resolver` finds the trees SubTree calls name, for pictures and for mapping a
running tree onto its files."""

from __future__ import annotations

from pathlib import Path

from bt_lsp.project.index import ProjectIndex, normalize
from bt_lsp.render import Format, Picture, Resolver, render, workspace_resolver
from bt_lsp.rules.context import Context
from bt_lsp.rules.diagnostics import Diagnostic, with_severities
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
        # The file's configured severities, as `check` applies them ("off" drops a code).
        severities = workspace.settings_for(normalize(path)).severity
        diagnostics = with_severities(workspace.diagnostics(path, doc), severities)
    if expand_subtrees:
        resolve = tree_resolver(workspace, path, doc, ctx)
    else:
        resolve = workspace_resolver(doc.model, ctx, {})
    return render(
        doc.model,
        tree,
        fmt,
        ctx=ctx,
        diagnostics=diagnostics,
        ports=ports,
        expand_subtrees=expand_subtrees,
        resolve=resolve,
        text_length=len(doc.text),
    )


def tree_resolver(
    workspace: ProjectIndex, path: Path, doc: Document, ctx: Context | None = None
) -> Resolver:
    """The trees ``doc`` (at ``path``) can call, by ID: its own, then its include
    closure's (the last declaration wins, as in BehaviorTree.CPP), then the other
    workspace files'; each found with its file's path as its source."""
    ctx = ctx if ctx is not None else workspace.context_for(path, doc)
    others: dict[str, Model] = {}
    for p in workspace.includes.closure(path, doc):
        d = workspace.document(p)
        if d is not None:
            others[str(p)] = d.model
    for p, d in workspace.bt_documents():
        others.setdefault(str(p), d.model)
    return workspace_resolver(doc.model, ctx, others)
