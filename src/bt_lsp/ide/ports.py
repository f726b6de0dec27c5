"""The declared ports of a node element, shared by completion and hover."""

from __future__ import annotations

from bt_lsp.rules.builtins import BUILTINS, PortModel
from bt_lsp.rules.context import Context
from bt_lsp.syntax.elements import Element


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
