"""Nodes: is the type known, is it written right, does it have the right children.

* ``missing-id`` (error): ``<Action|Condition|Control|Decorator>`` without ``ID``.  Range:
  the element name.  (An empty ``ID=""`` is the name rule ``model-name-empty``.)
* ``id-on-compact-node`` (error): ``ID`` on a node written in compact form
  ("Attribute [ID] is not allowed").  Range: the attribute name.  Fix: remove it.
* ``unknown-node``: a compact element name or explicit ``ID`` that is neither a built-in
  nor declared in a ``<TreeNodesModel>`` of the context ("Node not recognized").  An error
  when a catalog of the custom nodes is configured (``ctx.workspace_has_custom_models``)
  or the C++ registrations are all known (``ctx.registered``: see
  :mod:`bt_lsp.project.cpp_models`), and then also for a type that only advisory models
  declare (a tree file's own ``<TreeNodesModel>``, a palette: BehaviorTree.CPP registers
  from C++ alone); else a warning when the type is one edit away from a known model (very
  likely a typo), and a hint otherwise: nodes registered only in C++ are
  normal.  BehaviorTree.CPP 3 names (``SequenceStar``, ``SubTreePlus``), the
  ``RetryUntilSuccesful`` typo and tree IDs used as node types are errors in a document
  with ``BTCPP_format`` and warnings without; a case-insensitive match of a built-in is an
  error; the version 3 built-ins ``BlackboardCheck*`` follow the general rule (version 4
  still ships the class for users to register).  Range: the element name (compact) or the
  ``ID`` value (explicit). Fixes: rename to the suggested type, call a tree with
  ``<SubTree>``, declare the node in ``<TreeNodesModel>``.  Names that break the name rules
  are left to those.
* ``child-count`` (error): built-in child rules (decorators 1, controls 1 or more, leaves
  and ``<SubTree>`` 0, ``TryCatch`` 2 or more, ``IfThenElse``/``WhileDoElse`` 2 or 3,
  ``SwitchN`` N+1); for declared custom nodes the rule of their category.  Range: the
  element name.
* ``reactive-async-children`` (error): a ``ReactiveSequence`` with more than one
  ``AsyncSequence`` child (the only registered type BehaviorTree.CPP counts).  Range: the
  ``ReactiveSequence`` element name.
* ``reactive-explicit-child`` (error): a child of a ``ReactiveSequence`` written in
  explicit form: BehaviorTree.CPP looks the child's element name up as a node type and
  fails with "Unknown node type: Action".  Range: the child's element name.
* ``parallel-threshold`` (error): a literal ``success_count``/``failure_count`` of a
  ``Parallel``, or ``max_failures`` of a ``ParallelAll``, larger than its number of
  children (negative values count from the end and never exceed it): the node throws at
  its first tick.  Range: the value.
"""

from __future__ import annotations

import os
import re
from dataclasses import dataclass
from typing import Final, cast

from bt_lsp.rules.builtins import BUILTINS, V3_RENAMES
from bt_lsp.rules.codes import BT, FixData, Severity, define
from bt_lsp.rules.context import Context
from bt_lsp.rules.conversions import is_blackboard_reference
from bt_lsp.rules.names import NameKind, check_name
from bt_lsp.rules.semantics.base import Resolved, State, edit_distance, quoted
from bt_lsp.syntax.elements import EXPLICIT_TAGS, Element


@dataclass(frozen=True, slots=True)
class UnknownNodeData(FixData):
    """What ``unknown-node`` tells its fixes: the type as written, whether the node is in
    explicit form, and the type to rename it to (``preferred`` when that is surely
    meant: a version 3 name or a built-in spelled in another case)."""

    type: str
    explicit: bool
    rename: str | None = None
    preferred: bool = False

    def as_json(self) -> dict[str, object]:
        out: dict[str, object] = {"type": self.type, "explicit": self.explicit}
        if self.rename is not None:
            out |= {"rename": self.rename, "preferred": self.preferred}
        return out


# The codes of these rules (see bt_lsp.rules.registry).
ID_ON_COMPACT_NODE: Final = define(
    "id-on-compact-node",
    Severity.ERROR,
    "`ID` on a node written in compact form",
    BT,
    fixes={"remove": "Remove ID from <{element}>"},
)
UNKNOWN_NODE: Final = define(
    "unknown-node",
    Severity.ERROR,
    (
        "a node type that is neither built in nor registered (an error with a node "
        "catalog; else a warning one typo away from a known node, a hint otherwise)"
    ),
    BT,
    fixes={
        "rename": "Rename '{type}' to '{new}'",
        "subtree": "Call tree '{type}' with <SubTree>",
        "declare": "Declare '{type}' in <TreeNodesModel>",
    },
)
CHILD_COUNT: Final = define(
    "child-count", Severity.ERROR, "a node with the wrong number of children", BT
)
REACTIVE_ASYNC_CHILDREN: Final = define(
    "reactive-async-children",
    Severity.ERROR,
    "a `ReactiveSequence` with more than one `AsyncSequence` child",
    BT,
)
REACTIVE_EXPLICIT_CHILD: Final = define(
    "reactive-explicit-child",
    Severity.ERROR,
    "a `ReactiveSequence` child written in explicit form (`<Action ID=…>`)",
    BT,
)
PARALLEL_THRESHOLD: Final = define(
    "parallel-threshold",
    Severity.ERROR,
    "a `Parallel`/`ParallelAll` threshold larger than its number of children",
    BT,
)


_BUILTIN_LOWER: Final[dict[str, str]] = {k.lower(): k for k in BUILTINS}
_LEADING_INT: Final = re.compile(r"-?[0-9]+")
# Entries of V3_RENAMES that are typos rather than version 3 names.
_MISSPELLINGS: Final = frozenset({"RetryUntilSuccesful"})
# Built-ins of BehaviorTree.CPP 3 that version 4 dropped.
V3_ONLY: Final[dict[str, str]] = {
    "BlackboardCheckInt": "ScriptCondition or a _skipIf/_successIf precondition",
    "BlackboardCheckDouble": "ScriptCondition or a _skipIf/_successIf precondition",
    "BlackboardCheckString": "ScriptCondition or a _skipIf/_successIf precondition",
    "BlackboardCheckBool": "ScriptCondition or a _skipIf/_successIf precondition",
}


def check_node(st: State, el: Element) -> Resolved | None:
    """The checks of one node element; returns its model when known."""
    name = el.name
    if name == "SubTree" or (st.v3 and name == "SubTreePlus"):
        if el.children:
            st.add(
                el.name_start,
                el.name_end,
                "child-count",
                f"<SubTree> with ID {quoted(el.value('ID') or '')} has "
                f"{_count(len(el.children))}; it must not have any",
            )
        tid = el.value("ID")
        return st.resolve_subtree(tid) if tid else None
    if name in EXPLICIT_TAGS:
        a = el.attr("ID")
        if a is None:
            st.add(
                el.name_start,
                el.name_end,
                "missing-id",
                f"<{name}> has no ID attribute naming its node type",
            )
            return None
        if not a.value:
            return None
        type_id = a.value
        start, end = el.span_of_value(a)
    else:
        type_id = name
        start, end = el.name_start, el.name_end
        id_attr = el.attr("ID")
        if id_attr is not None and name not in V3_RENAMES:
            s, e = el.span_of_name(id_attr)
            st.add(
                s,
                e,
                "id-on-compact-node",
                f"Attribute ID is not allowed on <{name}>: the element name already is the "
                f"node type (write <Action ID=…> for the explicit form)",
            )
    res = st.resolve(type_id)
    if res is None:
        _unknown(st, el, type_id, start, end, name in EXPLICIT_TAGS)
        return None
    if res.origin == "custom" and not res.authoritative and _unregistered_here(st.ctx, res.id):
        _unregistered(st, type_id, start, end, name in EXPLICIT_TAGS)
        return None
    _children(st, el, res)
    if res.id == "ReactiveSequence":
        _reactive(st, el)
    elif res.id == "Parallel":
        _parallel(st, el)
    elif res.id == "ParallelAll":
        _parallel_all(st, el)
    return res


def _count(n: int) -> str:
    return "1 child" if n == 1 else f"{n} children"


# What ``unknown-node`` says of a type: its message, severity and data.
_Finding = tuple[str, Severity | None, UnknownNodeData]


def _unknown(st: State, el: Element, type_id: str, start: int, end: int, explicit: bool) -> None:
    key = ("unknown-node", type_id, explicit)
    if key in st.memo:  # a name repeated all over a document is looked at once
        found = cast(_Finding | None, st.memo[key])
    else:
        found = st.memo[key] = _unknown_finding(st, type_id, explicit)
    if found is not None:
        st.add(start, end, "unknown-node", *found)


def _unknown_finding(st: State, type_id: str, explicit: bool) -> _Finding | None:
    if not explicit and check_name(type_id, NameKind.MODEL):
        return None  # the name rules report it (BehaviorTree.CPP checks the name first)
    data = UnknownNodeData(type_id, explicit)
    ctx = st.ctx
    if type_id in V3_RENAMES:
        new = V3_RENAMES[type_id]
        data = UnknownNodeData(type_id, explicit, new, preferred=True)
        why = (
            "a misspelling that BehaviorTree.CPP does not register"
            if type_id in _MISSPELLINGS
            else "the BehaviorTree.CPP 3 name of a node"
        )
        return (
            f"{quoted(type_id)} is {why}; BehaviorTree.CPP 4 calls it {quoted(new)}",
            Severity.ERROR if st.v4 else Severity.WARNING,
            data,
        )
    if st.v3 and type_id in BUILTINS:
        return (
            f"{quoted(type_id)} is a built-in node of BehaviorTree.CPP 4; this project builds "
            "against BehaviorTree.CPP 3, which does not register it (register it in C++)",
            Severity.WARNING,
            data,
        )
    if type_id in V3_ONLY:
        return (
            f"{quoted(type_id)} was a built-in node of BehaviorTree.CPP 3; version 4 does not "
            f"register it by default (register it in C++, or use {V3_ONLY[type_id]})",
            None if _complete(ctx) else Severity.HINT,
            data,
        )
    if type_id in ctx.trees or type_id in ctx.workspace_trees:
        return (
            f'{quoted(type_id)} is a tree, not a node type; call it with <SubTree ID="{type_id}"/>',
            Severity.ERROR if st.v4 else Severity.WARNING,
            data,
        )
    known = _BUILTIN_LOWER.get(type_id.lower())
    if known is not None:
        data = UnknownNodeData(type_id, explicit, known, preferred=True)
        return (
            f"Node type {quoted(type_id)} is not registered; did you mean {quoted(known)}? "
            "(names are case-sensitive)",
            Severity.ERROR,
            data,
        )
    if ctx.registered is not None and type_id in ctx.registered:
        return (
            f"Node type {quoted(type_id)} is registered in the project's C++, but its base "
            "class is not among the sources read: its kind and ports are unknown",
            Severity.HINT,
            data,
        )
    suggestion = _closest(st, type_id)
    if _complete(ctx):
        severity = None
    elif suggestion is not None and edit_distance(type_id, suggestion, 1) <= 1:
        severity = Severity.WARNING  # one typo away from a known model: very likely wrong
    else:
        severity = Severity.HINT
    if suggestion is not None:
        data = UnknownNodeData(type_id, explicit, suggestion)
    if ctx.workspace_has_custom_models:
        message = (
            f"Node type {quoted(type_id)} is not a built-in node and is not declared in any "
            "<TreeNodesModel> of the workspace"
        )
    elif ctx.registered is not None:
        message = (
            f"Node type {quoted(type_id)} is not registered: it is not a built-in node, and "
            "the C++ of this package and of its dependencies registers no such node "
            "(BehaviorTree.CPP fails with 'Node not recognized')"
        )
    elif ctx.incomplete:
        message = (
            f"Node type {quoted(type_id)} is not a built-in node and not registered in the "
            f"C++ that was read; it may be registered where bt-lsp cannot see ({ctx.incomplete})"
        )
    else:
        message = (
            f"Node type {quoted(type_id)} is not a built-in node; it must be registered in "
            "C++ (declare it in a <TreeNodesModel> to have its ports checked)"
        )
    if suggestion is not None:
        message += f"; did you mean {quoted(suggestion)}?"
    return message, severity, data


def _unregistered(st: State, type_id: str, start: int, end: int, explicit: bool) -> None:
    """A node type that only advisory models declare, while a catalog of what the
    application registers is known: BehaviorTree.CPP registers nodes from C++ alone and
    fails with 'Node not recognized'."""
    decl = st.ctx.models.get(type_id)
    where = "this document" if decl is None or st.ctx.is_own(decl) else _base(decl.path)
    catalog = (
        "the node catalog"
        if st.ctx.workspace_has_custom_models
        else "the C++ of this package and of its dependencies"
    )
    st.add(
        start,
        end,
        "unknown-node",
        f"Node type {quoted(type_id)} is not in {catalog}; only the <TreeNodesModel> "
        f"of {where} declares it, and BehaviorTree.CPP registers nodes from C++ alone, so it "
        "fails with 'Node not recognized'",
        Severity.ERROR,
        UnknownNodeData(type_id, explicit),
    )


def _complete(ctx: Context) -> bool:
    """Whether every node the application registers is known: a catalog is named, or the
    C++ of every package that can register nodes was read."""
    return ctx.workspace_has_custom_models or ctx.registered is not None


def _unregistered_here(ctx: Context, type_id: str) -> bool:
    """Whether a type that only advisory models declare is known not to be registered."""
    if ctx.workspace_has_custom_models:
        return True
    return ctx.registered is not None and type_id not in ctx.registered


def _base(path: str | None) -> str:
    return os.path.basename(path) if path else "another document"


def _closest(st: State, type_id: str) -> str | None:
    """A known node type that ``type_id`` is probably a typo of (edit distance 1-2)."""
    if len(type_id) < 5:
        return None
    n = len(type_id)
    limit = 1 if n < 8 else 2
    best: tuple[int, str] | None = None
    for cand in (*BUILTINS, *st.ctx.models):
        if abs(len(cand) - n) > limit:
            continue
        d = edit_distance(type_id, cand, limit)
        if d <= limit and (best is None or d < best[0]):
            best = (d, cand)
    return best[1] if best is not None else None


def _children(st: State, el: Element, res: Resolved) -> None:
    n = len(el.children)
    lo, hi = res.min_children, res.max_children
    if lo <= n and (hi is None or n <= hi):
        return
    if hi == 0:
        need = "must not have any child"
    elif hi == lo:
        need = f"must have exactly {_count(lo)}"
        if res.id.startswith("Switch") and res.origin == "builtin":
            need += f" ({lo - 1} cases + default)"
    elif hi is None:
        need = (
            f"must have {lo} or more children" if lo <= 1 else f"must have at least {lo} children"
        )
    else:
        need = (
            f"must have {lo} or {hi} children" if hi == lo + 1 else f"must have {lo}-{hi} children"
        )
    what = {"custom": f"a {res.category} declared in <TreeNodesModel>"}.get(res.origin, "")
    message = (
        f"The node {quoted(res.id)}{' (' + what + ')' if what else ''} {need}; it has "
        f"{_count(n) if n else 'none'}"
    )
    words = _TICK_CHILD_COUNT.get("Switch" if _is_switch(res.id) else res.id)
    if res.origin == "builtin" and words is not None and n:
        # Loading checks only that a control node has children; these count them at tick.
        message += (
            f"; BehaviorTree.CPP creates the tree, and the node throws at its first tick: '{words}'"
        )
    st.add(el.name_start, el.name_end, "child-count", message)


# The controls that count their children only when they tick, in BehaviorTree.CPP's words.
_TICK_CHILD_COUNT: Final = {
    "IfThenElse": "IfThenElseNode must have either 2 or 3 children",
    "WhileDoElse": "WhileDoElseNode must have either 2 or 3 children",
    "Switch": "Wrong number of children in SwitchNode; must be (num_cases + default)",
}


def _is_switch(type_id: str) -> bool:
    return type_id.startswith("Switch") and type_id[6:].isdigit()


def _reactive(st: State, el: Element) -> None:
    st.pure = False  # reads the children
    elements = st.model.elements
    asyncs = 0
    for ci in el.children:
        child = elements[ci]
        if child.name == "AsyncSequence":
            asyncs += 1
        elif child.name in EXPLICIT_TAGS:
            st.add(
                child.name_start,
                child.name_end,
                "reactive-explicit-child",
                f"BehaviorTree.CPP looks up the element name of each ReactiveSequence child "
                f"as a node type and fails with 'Unknown node type: {child.name}'; write this "
                "child in compact form",
            )
    if asyncs > 1:
        st.add(
            el.name_start,
            el.name_end,
            "reactive-async-children",
            f"A ReactiveSequence cannot have more than one async child; this one has {asyncs} "
            "AsyncSequence children",
        )


def _parallel(st: State, el: Element) -> None:
    n = len(el.children)
    for port, outcome in (("success_count", "succeed"), ("failure_count", "fail")):
        a = el.attr(port)
        if a is None or a.value is None or is_blackboard_reference(a.value):
            continue
        m = _LEADING_INT.match(a.value)
        if m is None:
            continue  # invalid-port-value reports it
        value = int(m.group(0))
        if value > n:
            s, e = el.span_of_value(a)
            st.add(
                s,
                e,
                "parallel-threshold",
                f"{port} is {value} but the Parallel has {_count(n)}, so it can never "
                f"{outcome} (BehaviorTree.CPP: Number of children is less than threshold)",
            )


def _parallel_all(st: State, el: Element) -> None:
    """ParallelAll checks ``max_failures`` against its children at every tick
    (``ParallelAllNode::tick``), and throws when it could never fail."""
    n = len(el.children)
    a = el.attr("max_failures")
    if a is None or a.value is None or is_blackboard_reference(a.value):
        return
    m = _LEADING_INT.match(a.value)
    if m is None:
        return  # invalid-port-value reports it
    value = int(m.group(0))
    if value > n:
        s, e = el.span_of_value(a)
        st.add(
            s,
            e,
            "parallel-threshold",
            f"max_failures is {value} but the ParallelAll has {_count(n)}, so it can never "
            "fail; BehaviorTree.CPP throws at its first tick: Number of children is less "
            "than threshold. Can never fail.",
        )
