"""Pictures of behavior trees: one renderer for the CLI, the server and the editors.

Pure: it reads a document model (and the context and diagnostics the caller computed)
and returns text; no protocol, no files.  :func:`render` is the entry point;
:mod:`~bt_lsp.render.picture` decides what is drawn, :mod:`~bt_lsp.render.layout` where,
:mod:`~bt_lsp.render.svg` and :mod:`~bt_lsp.render.graph_text` how.
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import Literal

from bt_lsp.render.graph_text import to_dot, to_mermaid
from bt_lsp.render.layout import Layout, layout
from bt_lsp.render.picture import (
    Node,
    Picture,
    Port,
    Resolver,
    TreeSource,
    build_picture,
    changed_node,
    document_trees,
    find_tree,
    main_tree,
    tree_at,
    tree_id_of,
    workspace_resolver,
)
from bt_lsp.render.svg import to_svg
from bt_lsp.rules.context import Context
from bt_lsp.rules.diagnostics import Diagnostic
from bt_lsp.syntax.elements import Element
from bt_lsp.syntax.model import Model

Format = Literal["svg", "mermaid", "dot"]
FORMATS: tuple[Format, ...] = ("svg", "mermaid", "dot")


def render(
    model: Model,
    tree: Element,
    fmt: Format = "svg",
    *,
    ctx: Context | None = None,
    diagnostics: Iterable[Diagnostic] = (),
    ports: bool = False,
    expand_subtrees: bool = False,
    resolve: Resolver | None = None,
    text_length: int | None = None,
) -> tuple[str, Picture]:
    """``tree`` of ``model`` drawn in ``fmt``, and the picture it was drawn from."""
    picture = build_picture(
        model,
        tree,
        ctx=ctx,
        diagnostics=diagnostics,
        ports=ports,
        expand_subtrees=expand_subtrees,
        resolve=resolve,
        text_length=text_length,
    )
    if fmt == "svg":
        return to_svg(picture), picture
    if fmt == "mermaid":
        return to_mermaid(picture), picture
    return to_dot(picture), picture


__all__ = [
    "FORMATS",
    "Format",
    "Layout",
    "Node",
    "Picture",
    "Port",
    "Resolver",
    "TreeSource",
    "build_picture",
    "changed_node",
    "document_trees",
    "find_tree",
    "layout",
    "main_tree",
    "render",
    "to_dot",
    "to_mermaid",
    "to_svg",
    "tree_at",
    "tree_id_of",
    "workspace_resolver",
]
