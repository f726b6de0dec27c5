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
from itertools import islice
from typing import TYPE_CHECKING, Literal

from bt_lsp.rules.codes import defined
from bt_lsp.rules.context import Context
from bt_lsp.rules.diagnostics import Capped, capped
from bt_lsp.rules.semantics import document, models, nodes, ports, trees
from bt_lsp.rules.semantics.base import Finding, State, TagFindings, TreeScope
from bt_lsp.rules.semantics.sections import check_sections
from bt_lsp.syntax.elements import Element, Zone
from bt_lsp.syntax.table import ElementTable
from bt_lsp.syntax.tokens import Token

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
    :mod:`bt_lsp.rules.semantics.sections` for what they may read.

    What the node checks find in a start tag is the same wherever it is written, unless
    they read more than the tag and the number of children (a blackboard key's first use,
    a script's text, a ``<SubTree>`` call, the children of a ``ReactiveSequence``): equal
    tags are one token, so the findings of such a node are remembered by its token, for
    the run, or for every run of the check when they looked nothing up in the context
    (a built-in node): a document of a hundred thousand ``<Frob/>`` checks one, and one of
    twenty thousand trees its ``<Sequence>`` once.  A section's elements are read from its
    columns (:func:`_check_rows`): an element is made only where a rule reads it (but
    where its elements are kept, made once: they are read as they are)."""
    if isinstance(elements, ElementTable) and not elements.kept:
        _check_rows(st, elements)
        return
    scope = TreeScope(None)
    tags = st.tags
    shared = st.shared_tags
    # Members bound once: reading one from its enum class is slow in Python 3.11.
    node, tree, entry, port_decl = Zone.NODE, Zone.TREE, Zone.MODEL_ENTRY, Zone.PORT_DECL
    for el in elements:
        zone = el.zone
        if zone == node:
            document.check_depth(st, el, scope.depth_flagged)
            tag = el.tag
            n = len(el.children)
            key = id(tag)
            hit = tags.get(key)
            if hit is None and shared is not None:
                hit = shared.get(key)
            if hit is not None and hit[0] is tag and hit[1] == n:
                found = hit[2]
                if found:
                    _add_found(st, el.token_start, found)
                elif found is False:  # what it finds depends on more than its tag
                    res = nodes.check_node(st, el)
                    ports.check_attributes(st, el, res, scope, False)
                continue
            _check_node(st, el, scope, n, key)
        elif zone == tree:
            scope = TreeScope(el)
            trees.begin_tree(st, el)
        elif zone == entry:
            models.check_entry(st, el)
        elif zone == port_decl:
            models.check_port_decl(st, el)


def _check_rows(st: State, els: ElementTable) -> None:
    """:func:`check_elements` over the rows of a section's columns: a node whose tag and
    number of children are remembered is read from its row (its tag, its start, its
    depth), without an element; the others are made as the rules need them."""
    cols = els.columns
    rows = els.rows
    if not rows:
        return
    lo = rows.start
    origin = els.origin
    # Read once: the columns may be views made when read.
    tags, zones, starts, depths, child_n = (
        cols.tags,
        cols.zones,
        cols.starts,
        cols.depths,
        cols.child_n,
    )
    limit = document.DEPTH_LIMIT
    deep = max(islice(depths, rows.start, rows.stop)) > limit  # else no element is too deep
    scope = TreeScope(None)
    memo = st.tags.get
    shared = st.shared_tags.get if st.shared_tags is not None else None
    node, tree, entry, port_decl = (
        int(Zone.NODE),
        int(Zone.TREE),
        int(Zone.MODEL_ENTRY),
        int(Zone.PORT_DECL),
    )
    # The tag, number of children and findings of the last node read from the memo (or
    # None): a run of equal nodes reads it once, and once past the diagnostics kept only
    # counts their findings (``first``: the smallest offset of one, ``nf`` how many).
    last: Token | None = None
    last_n = 0
    found: tuple[Finding, ...] | Literal[False] = ()
    first = nf = 0
    for k in rows:
        zone = zones[k]
        if zone == node:
            if deep and depths[k] > limit and not scope.depth_flagged[0]:
                document.check_depth(st, els[k - lo], scope.depth_flagged)
            tag = tags[k]
            n = child_n[k]
            if tag is not last or n != last_n:
                key = id(tag)
                hit = memo(key)
                if hit is None and shared is not None:
                    hit = shared(key)
                # (a <SubTree> call is never remembered: see _check_node)
                if hit is None or hit[0] is not tag or hit[1] != n:
                    last = None
                    _check_node(st, els[k - lo], scope, n, key)
                    continue
                last, last_n, found = tag, n, hit[2]
                if found:
                    first, nf = min([f[0] for f in found]), len(found)
            if found:
                ts = starts[k] + origin
                cap = st.limit
                if cap is not None and ts + first > cap[0]:
                    st.more += nf  # past the diagnostics kept (see State.add)
                else:
                    _add_found(st, ts, found)
            elif found is False:  # what it finds depends on more than its tag
                el = els[k - lo]
                res = nodes.check_node(st, el)
                ports.check_attributes(st, el, res, scope, False)
        elif zone == tree:
            el = els[k - lo]
            scope = TreeScope(el)
            trees.begin_tree(st, el)
        elif zone == entry:
            models.check_entry(st, els[k - lo])
        elif zone == port_decl:
            models.check_port_decl(st, els[k - lo])


def _add_found(st: State, ts: int, found: tuple[Finding, ...]) -> None:
    """Add what a remembered tag's checks found, for the tag at ``ts``.  Past the
    :data:`~bt_lsp.rules.diagnostics.MAX_DIAGNOSTICS` kept (by severity, then position),
    a finding after them is counted without calling ``st.add`` (which would count it
    too: a document of a million equal findings keeps 2,000)."""
    add = st.add
    for s, e, code, message, severity, data in found:
        start = ts + s
        limit = st.limit
        if limit is not None:  # past the cap however st.add ranks it: counted here
            sev = defined(code).severity if severity is None else severity
            if (sev, start) > (
                limit[0],
                limit[1],
            ):  # (add may make an error a warning, never the reverse)
                st.more += 1
                continue
        add(start, ts + e, code, message, severity, data)


def _check_node(st: State, el: Element, scope: TreeScope, n: int, key: int) -> None:
    """The checks of node ``el`` (with ``n`` children; ``key`` is its tag's id) that is not
    remembered: its findings are remembered for its tag when they depend on nothing else."""
    tag = el.tag
    name = tag.name
    if name == "SubTree" or (st.v3 and name == "SubTreePlus"):
        res = nodes.check_node(st, el)
        trees.check_call(st, el, scope)
        ports.check_attributes(st, el, res, scope, True)
        return
    lookups = st.lookups
    shared = st.shared_tags
    recorded: list[Finding] = []
    st.record, st.pure = recorded, True
    before = lookups[0] if lookups is not None else -1
    res = nodes.check_node(st, el)
    ports.check_attributes(st, el, res, scope, False)
    st.record = None
    memo = st.tags
    if not st.pure:
        kept: TagFindings = (tag, n, False)
    else:
        ts = el.token_start
        kept = (
            tag,
            n,
            tuple([(s - ts, e - ts, c, m, sev, d) for s, e, c, m, sev, d in recorded]),
        )
        if (
            shared is not None
            and lookups is not None
            and lookups[0] == before
            and res is not None
            and res.origin == "builtin"
        ):  # a built-in, nothing read of the context (nor of what a run kept of
            # it, such as an unknown type's finding): valid for every run
            memo = shared
    if len(memo) >= _MAX_TAGS:
        memo.clear()
    memo[key] = kept


# How many tags a memo of check_elements holds at most (a document's tags are mostly
# unique: the memo is for those that repeat).
_MAX_TAGS = 4096
