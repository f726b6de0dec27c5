"""The declared ports of a node element, shared by completion and hover."""

from __future__ import annotations

from collections.abc import Mapping

from bt_lsp.rules.builtins import NodeModel, PortModel
from bt_lsp.rules.builtins_v3 import builtins_for
from bt_lsp.rules.context import Context
from bt_lsp.syntax.elements import Element


def builtins_in(ctx: Context | None) -> Mapping[str, NodeModel]:
    """The built-in nodes of the document's BehaviorTree.CPP version (3.8's for a
    project that builds against version 3, else 4.x's)."""
    return builtins_for(ctx.btcpp_version if ctx is not None else None)


def ports_of(el: Element, ctx: Context | None) -> tuple[PortModel, ...] | None:
    """The declared ports of a node element, ``None`` when its model is unknown."""
    node_id = el.node_id
    if node_id is None:
        return None
    if el.name == "SubTree":
        decl = ctx.subtree_models.get(node_id) if ctx is not None else None
        return decl.ports if decl is not None else None
    b = builtins_in(ctx).get(node_id)
    if b is not None:
        return b.ports
    decl = ctx.models.get(node_id) if ctx is not None else None
    return decl.ports if decl is not None else None
