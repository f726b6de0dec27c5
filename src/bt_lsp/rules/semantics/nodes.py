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
  fails with "Unknown node type: Action".  Not reported in a BehaviorTree.CPP 3 project:
  3.8's parser does not look the children up.  Range: the child's element name.
* ``parallel-threshold`` (error): a literal ``success_count``/``failure_count`` of a
  ``Parallel``, or ``max_failures`` of a ``ParallelAll``, larger than its number of
  children (negative values count from the end and never exceed it): the node throws at
  its first tick.  Range: the value.
* ``single-child-control`` (hint): a ``Sequence``, ``Fallback`` or another control node
  that only passes its one child's status on; not reported when the control carries a
  ``_``-attribute (a pre- or postcondition hung on it) or has no end tag (being typed).
  Range: the element name.  Fix: replace the control with its child (offered in the
  editor only: the author may rather add the missing siblings).
"""

from __future__ import annotations

import os
import re
from collections.abc import Mapping
from dataclasses import dataclass
from types import MappingProxyType
from typing import Final, cast

from bt_lsp.rules.builtins import BUILTINS, V3_RENAMES
from bt_lsp.rules.codes import (
    BT,
    Applicability,
    FixData,
    FixEdits,
    Severity,
    define,
    display_only,
    safe,
    unsafe,
)
from bt_lsp.rules.context import Context
from bt_lsp.rules.conversions import is_blackboard_reference
from bt_lsp.rules.diagnostics import Diagnostic
from bt_lsp.rules.names import NameKind, check_name
from bt_lsp.rules.semantics.base import Resolved, State, edit_distance, quoted
from bt_lsp.syntax.document import Document
from bt_lsp.syntax.edits import TextEdit
from bt_lsp.syntax.elements import EXPLICIT_TAGS, Element


@dataclass(frozen=True, slots=True)
class UnknownNodeData(FixData):
    """What ``unknown-node`` tells its fixes: the type as written, whether the node is in
    explicit form, the type to rename it to, and which of the code's rename fixes that is
    (``rename``, safe: surely meant; ``rename-likely``; ``rename-maybe``)."""

    type: str
    explicit: bool
    rename: str | None = None
    fix: str = "rename-maybe"

    @property
    def preferred(self) -> bool:
        return self.rename is not None and UNKNOWN_NODE.applicability(self.fix) is SAFE

    def as_json(self) -> dict[str, object]:
        out: dict[str, object] = {"type": self.type, "explicit": self.explicit}
        if self.rename is not None:
            out |= {"rename": self.rename, "preferred": self.preferred}
        return out


SAFE: Final = Applicability.SAFE

# The codes of these rules (see bt_lsp.rules.registry).
ID_ON_COMPACT_NODE: Final = define(
    "id-on-compact-node",
    Severity.ERROR,
    "`ID` on a node written in compact form",
    BT,
    # The element name is the node type either way: only the refused attribute goes.
    fixes={"remove": safe("Remove ID from <{element}>")},
    doc="""
        In compact form the element name is the node type, so an `ID` attribute is refused:
        BehaviorTree.CPP throws when it creates the tree (`Attribute [ID] is not allowed in
        <Sleep>`). The fix removes the attribute; write `<Action ID="Sleep"/>` for the
        explicit form.
        """,
    why="The tree is not created.",
    bad='<Sleep ID="Sleep" msec="500"/>',
    good='<Sleep msec="500"/>',
    since="BehaviorTree.CPP 4 (the message quoted); bt-lsp reports it for every version.",
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
        # BehaviorTree.CPP surely fails on the name and surely means the new one.
        "rename": safe(
            "Rename '{type}' to '{new}'",
            "a version 3 name in a version 4 project, a built-in in another case, or the "
            "one nearest name while every registration is known",
        ),
        # C++ that bt-lsp did not read may register the name as written.
        "rename-likely": unsafe(
            "Rename '{type}' to '{new}'",
            "a name one edit from a known one, or one of several nearest names",
        ),
        # The diagnostic is a hint: the name is most likely registered in C++.
        "rename-maybe": display_only("Rename '{type}' to '{new}'", "a farther guess"),
        "subtree": unsafe("Call tree '{type}' with <SubTree>"),
        # A model written for the node hides the problem without making it load.
        "declare": display_only("Declare '{type}' in <TreeNodesModel>"),
    },
    doc="""
        Every node type must be registered with the factory (a built-in, or a custom node
        registered in C++): BehaviorTree.CPP fails to load the XML with `Node not recognized:
        MoveBse`. bt-lsp knows the built-ins, the node catalogs named in the configuration, the
        nodes registered in the project's C++ and the `<TreeNodesModel>` entries. When it knows
        every registration (a catalog, or all of the C++ read) an unknown type is an error;
        otherwise a type one edit away from a known one is a warning (a typo), and any other a
        hint, since it is most likely registered in C++ that bt-lsp did not see.
        """,
    why="""
        The file does not load. A typo in a node type is the most common reason a tree that
        looked right fails on the robot.
        """,
    bad="""
        <RetryUntilSuccesful num_attempts="3"><Sleep msec="100"/></RetryUntilSuccesful>
        """,
    good="""
        <RetryUntilSuccessful num_attempts="3"><Sleep msec="100"/></RetryUntilSuccessful>
        """,
    since="""
        Every version; the built-ins are those of BehaviorTree.CPP 4.10 (3.8's for a 3.x
        project: `SequenceStar`, `SubTreePlus` and the `RetryUntilSuccesful` spelling are 3.x
        names).
        """,
)
CHILD_COUNT: Final = define(
    "child-count",
    Severity.ERROR,
    "a node with the wrong number of children",
    BT,
    doc="""
        Each kind of node takes a fixed number of children: a decorator exactly one, a control
        node one or more, an action, a condition and a `<SubTree>` none; `TryCatch` two or more,
        `IfThenElse` and `WhileDoElse` two or three, `SwitchN` N+1. BehaviorTree.CPP checks most
        of these when it loads the XML (`The node 'Inverter' must have exactly 1 child`), the
        last three when the node is ticked. A custom node declared in a `<TreeNodesModel>` follows
        the rule of its category.
        """,
    why="The file does not load, or the node fails the first time it runs.",
    bad="""
        <Inverter>
          <IsBatteryLow/>
          <Charge/>
        </Inverter>
        """,
    good="""
        <Inverter>
          <Sequence>
            <IsBatteryLow/>
            <Charge/>
          </Sequence>
        </Inverter>
        """,
    since="Every version (the node kinds of the detected version).",
)
REACTIVE_ASYNC_CHILDREN: Final = define(
    "reactive-async-children",
    Severity.ERROR,
    "a `ReactiveSequence` with more than one `AsyncSequence` child",
    BT,
    doc="""
        A `ReactiveSequence` ticks all its children again on every tick, so it allows at most
        one asynchronous child. BehaviorTree.CPP counts the `AsyncSequence` children when it
        loads the XML and refuses more than one: `A ReactiveSequence cannot have more than one
        async child.`
        """,
    why="The file does not load.",
    bad="""
        <ReactiveSequence>
          <AsyncSequence><AlwaysSuccess/></AsyncSequence>
          <AsyncSequence><AlwaysSuccess/></AsyncSequence>
        </ReactiveSequence>
        """,
    good="""
        <ReactiveSequence>
          <AsyncSequence><AlwaysSuccess/></AsyncSequence>
          <Sequence><AlwaysSuccess/></Sequence>
        </ReactiveSequence>
        """,
    since="BehaviorTree.CPP 4 (`AsyncSequence` is a version 4 node).",
)
REACTIVE_EXPLICIT_CHILD: Final = define(
    "reactive-explicit-child",
    Severity.ERROR,
    "a `ReactiveSequence` child written in explicit form (`<Action ID=…>`)",
    BT,
    doc="""
        When it checks a `ReactiveSequence`'s children, BehaviorTree.CPP looks up each child's
        element name as a node type, so a child in explicit form fails when the XML is loaded:
        `Unknown node type: Action`. Write the child in compact form. Not reported for a
        version 3 project, whose parser does not look the children up.
        """,
    why="The file does not load, though the same child is fine under any other node.",
    bad="""
        <ReactiveSequence>
          <Condition ID="AlwaysSuccess"/>
          <Action ID="AlwaysSuccess"/>
        </ReactiveSequence>
        """,
    good="""
        <ReactiveSequence>
          <AlwaysSuccess/>
          <AlwaysSuccess/>
        </ReactiveSequence>
        """,
    since="BehaviorTree.CPP 4.",
)
PARALLEL_THRESHOLD: Final = define(
    "parallel-threshold",
    Severity.ERROR,
    "a `Parallel`/`ParallelAll` threshold larger than its number of children",
    BT,
    doc="""
        A `Parallel` succeeds when `success_count` children succeed and fails when
        `failure_count` fail; a literal count larger than its number of children can never
        be reached. BehaviorTree.CPP fails when the node is ticked: `Number of children is
        less than threshold. Can never succeed.` (or `fail`). Negative counts count from the
        end and are never too large.
        """,
    why="The node fails on its first tick, on the robot.",
    bad="""
        <Parallel success_count="3" failure_count="1">
          <AlwaysSuccess/>
          <AlwaysSuccess/>
        </Parallel>
        """,
    good="""
        <Parallel success_count="2" failure_count="1">
          <AlwaysSuccess/>
          <AlwaysSuccess/>
        </Parallel>
        """,
    since="Every version.",
)


def _unwrap(doc: Document, ctx: Context, diag: Diagnostic) -> list[FixEdits]:
    """``single-child-control``'s fix: the control replaced with its child, whose lines
    move left by the depth the control gave them.  Not offered when anything but blanks
    surrounds the child (a comment there would be lost)."""
    model = doc.model
    el = next((e for e in model.elements if e.name_start == diag.start), None)
    if el is None or len(el.children) != 1 or el.end_name_start < 0:
        return []
    child = model.elements[el.children[0]]
    text = doc.text
    end_tag = el.end_name_start - 2  # its '</'
    around = text[el.token_start + el.length : child.token_start] + text[child.end : end_tag]
    if child.end < 0 or around.strip():
        return []
    body = text[child.token_start : child.end]
    outer, inner = _indent(text, el.token_start), _indent(text, child.token_start)
    if outer is not None and inner is not None and inner.startswith(outer):
        extra = inner[len(outer) :]
        first, *rest = body.splitlines(keepends=True)
        body = first + "".join(line.removeprefix(extra) for line in rest)
    edit = TextEdit(el.token_start, el.end, body)
    return [FixEdits("unwrap", (edit,), {"element": el.name})]


def _indent(text: str, offset: int) -> str | None:
    """The blanks between the start of ``offset``'s line and it (``None``: not blanks)."""
    start = max(text.rfind("\n", 0, offset), text.rfind("\r", 0, offset)) + 1
    lead = text[start:offset]
    return lead if lead.strip(" \t") == "" else None


SINGLE_CHILD_CONTROL: Final = define(
    "single-child-control",
    Severity.HINT,
    "a `Sequence`, `Fallback` or similar control node with exactly one child",
    BT,
    # Never in bulk: whether the control goes or gets its siblings is the author's call.
    fixes={"unwrap": display_only("Replace <{element}> with its child")},
    doc="""
        A `Sequence`, `Fallback`, `SequenceWithMemory`, `ReactiveSequence`,
        `ReactiveFallback`, `AsyncSequence` or `AsyncFallback` with exactly one child ticks
        that child and returns its status (`SUCCESS`, `FAILURE`, `RUNNING`, or `SKIPPED` when
        the child was skipped): it behaves like the child alone. BehaviorTree.CPP loads and
        runs it; it is usually a leftover of an edit, or a node whose siblings were never
        written. Not reported when the control has a `_`-attribute (a precondition such as
        `_skipIf`, or a postcondition): that is then a place to hang it.
        """,
    why="The extra node adds depth to the tree and its logs without doing anything.",
    bad="""
        <Sequence>
          <MoveBase goal="{goal}"/>
        </Sequence>
        """,
    good="""
        <MoveBase goal="{goal}"/>
        """,
    since="Every version.",
    fixer=_unwrap,
)


_BUILTIN_LOWER: Final[Mapping[str, str]] = MappingProxyType({k.lower(): k for k in BUILTINS})
_LEADING_INT: Final = re.compile(r"-?[0-9]+")
# Entries of V3_RENAMES that are typos rather than version 3 names.
_MISSPELLINGS: Final = frozenset({"RetryUntilSuccesful"})
# Built-ins of BehaviorTree.CPP 3 that version 4 dropped.
V3_ONLY: Final[Mapping[str, str]] = MappingProxyType(
    {
        "BlackboardCheckInt": "ScriptCondition or a _skipIf/_successIf precondition",
        "BlackboardCheckDouble": "ScriptCondition or a _skipIf/_successIf precondition",
        "BlackboardCheckString": "ScriptCondition or a _skipIf/_successIf precondition",
        "BlackboardCheckBool": "ScriptCondition or a _skipIf/_successIf precondition",
    }
)


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
    if res.origin == "builtin" and res.id in _PASS_THROUGH:
        st.pure = False  # reads the children and the end tag, not the start tag alone
        if len(el.children) == 1:
            _single_child(st, el, res.id)
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
        # Safe where the project is known to build against version 4 (or says so).
        data = UnknownNodeData(type_id, explicit, new, "rename" if st.v4 else "rename-likely")
        if st.v3:  # only the misspelling: 3.8 registers the other version 3 names
            message = (
                f"{quoted(type_id)} is a misspelling that BehaviorTree.CPP 3.8 does not "
                f"register (its factory's registration of it is commented out); the node is "
                f"{quoted(new)}"
            )
        else:
            why = (
                "a misspelling that BehaviorTree.CPP does not register"
                if type_id in _MISSPELLINGS
                else "the BehaviorTree.CPP 3 name of a node"
            )
            message = f"{quoted(type_id)} is {why}; BehaviorTree.CPP 4 calls it {quoted(new)}"
            if ctx.btcpp_unclear:
                message += (
                    " (the project's build names both BehaviorTree.CPP 3 and 4, so its "
                    "version is unclear)"
                )
        return message, Severity.ERROR if st.v4 else Severity.WARNING, data
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
        data = UnknownNodeData(type_id, explicit, known, "rename")
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
    suggestion, unique = _closest(st, type_id)
    fix = "rename-maybe"
    if _complete(ctx):
        severity = None
        # Every registration is known: the name fails to load, and one name is nearest.
        fix = "rename" if unique else "rename-likely"
    elif suggestion is not None and edit_distance(type_id, suggestion, 1) <= 1:
        severity = Severity.WARNING  # one typo away from a known model: very likely wrong
        fix = "rename-likely"
    else:
        severity = Severity.HINT
    if suggestion is not None:
        data = UnknownNodeData(type_id, explicit, suggestion, fix)
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


def _closest(st: State, type_id: str) -> tuple[str | None, bool]:
    """A known node type that ``type_id`` is probably a typo of (edit distance 1-2), and
    whether it is the only one that near."""
    if len(type_id) < 5:
        return None, False
    n = len(type_id)
    limit = 1 if n < 8 else 2
    best: tuple[int, str] | None = None
    unique = False
    for cand in dict.fromkeys((*BUILTINS, *st.ctx.models)):
        if abs(len(cand) - n) > limit:
            continue
        d = edit_distance(type_id, cand, limit)
        if d > limit:
            continue
        if best is None or d < best[0]:
            best, unique = (d, cand), True
        elif d == best[0]:
            unique = False
    return (best[1], unique) if best is not None else (None, False)


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
_TICK_CHILD_COUNT: Final = MappingProxyType(
    {
        "IfThenElse": "IfThenElseNode must have either 2 or 3 children",
        "WhileDoElse": "WhileDoElseNode must have either 2 or 3 children",
        "Switch": "Wrong number of children in SwitchNode; must be (num_cases + default)",
    }
)


def _is_switch(type_id: str) -> bool:
    return type_id.startswith("Switch") and type_id[6:].isdigit()


# The controls that, with one child, tick it and return its status unchanged.
_PASS_THROUGH: Final = frozenset(
    {
        "Sequence",
        "Fallback",
        "SequenceWithMemory",
        "ReactiveSequence",
        "ReactiveFallback",
        "AsyncSequence",
        "AsyncFallback",
        "SequenceStar",  # version 3's SequenceWithMemory
    }
)


def _single_child(st: State, el: Element, type_id: str) -> None:
    if el.end_name_start < 0:
        return  # not closed: its other children may not be typed yet
    if any(a.name.startswith("_") for a in el.attrs):
        return  # a pre- or postcondition hangs on the control
    st.add(
        el.name_start,
        el.name_end,
        "single-child-control",
        f"This {type_id} has one child, so it returns what its child returns; replace it "
        "with its child, or add the siblings it was meant for",
    )


def _reactive(st: State, el: Element) -> None:
    st.pure = False  # reads the children
    elements = st.model.elements
    asyncs = 0
    for ci in el.children:
        child = elements[ci]
        if child.name == "AsyncSequence":
            asyncs += 1
        elif child.name in EXPLICIT_TAGS and not st.v3:
            # Version 4's VerifyXML looks each child's element name up; 3.8 does not.
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
