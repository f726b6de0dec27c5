"""BehaviorTree.CPP's semantic rules over one document and its workspace context.

:func:`check` runs every rule family in one pass over the document's elements (the
context, which holds what the document itself declares, is built before it), section by
section with each section's results remembered (:mod:`~bt_lsp.rules.semantics.sections`):

* :mod:`~bt_lsp.rules.semantics.document`: ``<root>``, sections, includes, nesting depth;
* :mod:`~bt_lsp.rules.semantics.trees`: tree IDs, ``<SubTree>`` calls, the main tree, cycles;
* :mod:`~bt_lsp.rules.semantics.nodes`: node types, compact/explicit form, children;
* :mod:`~bt_lsp.rules.semantics.ports`: ports, attribute values, blackboard types;
* :mod:`~bt_lsp.rules.semantics.scripts`: script syntax;
* :mod:`~bt_lsp.rules.semantics.models`: ``<TreeNodesModel>`` entries.

Their quick fixes are made in :mod:`bt_lsp.ide.semantic_fixes`.
Each module's docstring lists its codes with their severity and range.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

from bt_lsp.rules.context import Context
from bt_lsp.rules.diagnostics import Capped, capped
from bt_lsp.rules.semantics import document, models, nodes, ports, trees
from bt_lsp.rules.semantics.base import State, TreeScope
from bt_lsp.rules.semantics.sections import check_sections
from bt_lsp.syntax.elements import Element, Zone

if TYPE_CHECKING:
    from bt_lsp.syntax.document import Document

__all__ = ["check"]


def check(doc: Document, ctx: Context) -> Capped:
    """Every semantic diagnostic of ``doc`` seen through ``ctx``, sorted by position: the
    first :data:`~bt_lsp.rules.diagnostics.MAX_DIAGNOSTICS`, with how many more."""
    model = doc.model
    st = State(doc, ctx, model, doc.text)
    document.check_root(st)
    if model.head is not None:
        check_sections(st, check_elements)  # each child of <root>, remembered
    else:
        check_elements(st, model.elements)
    trees.check_duplicate_ids(st)
    trees.check_main_tree(st)
    trees.check_recursion(st)
    return capped(st.out, st.more)


def check_elements(st: State, elements: Sequence[Element]) -> None:
    """The rules of single elements, in document order (``<BehaviorTree>`` elements start
    the scope of the nodes that follow).  They run section by section: see
    :mod:`bt_lsp.rules.semantics.sections` for what they may read."""
    scope = TreeScope(None)
    # Members bound once: reading one from its enum class is slow in Python 3.11.
    node, tree, entry, port_decl = Zone.NODE, Zone.TREE, Zone.MODEL_ENTRY, Zone.PORT_DECL
    for el in elements:
        zone = el.zone
        if zone == node:
            document.check_depth(st, el, scope.depth_flagged)
            res = nodes.check_node(st, el)
            is_subtree = el.name == "SubTree" or (st.v3 and el.name == "SubTreePlus")
            if is_subtree:
                trees.check_call(st, el, scope)
            ports.check_attributes(st, el, res, scope, is_subtree)
        elif zone == tree:
            scope = TreeScope(el)
            trees.begin_tree(st, el)
        elif zone == entry:
            models.check_entry(st, el)
        elif zone == port_decl:
            models.check_port_decl(st, el)
