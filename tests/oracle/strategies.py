"""Hypothesis strategies for BehaviorTree.CPP XML that exercises what bt-lsp's rules check.

A generated :class:`Generated` is a :class:`~tests.oracle.adapter.Case` (one to two files,
the custom nodes the application registers) and whether it breaks a name rule on purpose
(BehaviorTree.CPP 4.8.2 predates those rules: bt-lsp's own rules are the reference there,
so the differential test compares only the other errors of such a case).

What varies: the built-in controls, decorators and actions with valid and invalid child
counts; their ports with valid, invalid, empty and blackboard values; Script,
ScriptCondition, preconditions and postconditions with valid and broken scripts; SubTree
calls with remappings, ``_autoremap``, missing and recursive trees; several trees,
``main_tree_to_execute``, an included file; port-less custom nodes with and without
attributes, registered or not; entity references; names that break the name rules.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from functools import lru_cache
from typing import Final
from xml.sax.saxutils import quoteattr

from hypothesis import strategies as st

from bt_lsp.rules.builtins import BUILTINS, NodeModel, PortModel
from tests.oracle.adapter import Case

ACTIONS: Final = ("OpenDoor", "Pick", "SayHello")
CONDITIONS: Final = ("IsReady", "BatteryOk")
UNREGISTERED: Final = ("CloseDoor",)
TREE_IDS: Final = ("Main", "Sub", "Other")
KEYS: Final = ("a", "b", "msg")
BAD_NODE_NAMES: Final = ("Open-Door", "Do.It", "Pick2Go_")  # names a rule forbids
BAD_TREE_IDS: Final = ("Main Tree", "Sub.Tree", "1Sub")

VALID_SCRIPTS: Final = (
    "a := 1",
    "b := 2; a := b + 1",
    "msg := 'hello'",
    "a == 1",
    "a &gt; 0 &amp;&amp; a &lt; 10",
    "a := 3 * (2 + 1)",
    "msg := 'x' .. 'y'",
    "a += 1",
    "b := a != 2",
)
BROKEN_SCRIPTS: Final = (
    "a :=",
    "a == ",
    "1 +",
    "msg := 'open",
    "a := (1",
    "a = = 1",
    "&amp;&amp; a",
    ";",
    "a := b c",
)
CONDITION_SCRIPTS: Final = ("a == 1", "true", "a &gt; 0", "msg == 'x'", "false")
PRE_POST: Final = (
    "_skipIf",
    "_successIf",
    "_failureIf",
    "_while",
    "_onSuccess",
    "_onFailure",
    "_post",
    "_onHalted",
)

# Values by port type: (valid, invalid).
VALUES: Final[dict[str, tuple[tuple[str, ...], tuple[str, ...]]]] = {
    "int": (("3", "-1", "0", "1"), ("abc", "1.5", "3x")),
    "unsigned int": (("0", "10", "100"), ("-5", "ten", "1e3")),
    "double": (("1.5", "-2", "0.0"), ("x1", "1,5")),
    "bool": (("true", "false", "1", "0", "True"), ("maybe", "yes", "2")),
    "NodeStatus": (("SUCCESS", "FAILURE", "RUNNING", "SKIPPED"), ("WIN", "success", "IDLE")),
    "std::string": (("hello", "1", "a b"), ()),
    "any": (("1", "x"), ()),
    "BT::Any": (("1",), ()),
}
# A strategy is built once for each set of arguments: building one (``one_of`` of fresh
# composites) costs more than drawing from it, and the draws, hence the documents of a
# seed, are the same either way.
_shared: Final = lru_cache(maxsize=None)
_ints: Final = _shared(st.integers)
_pick: Final = _shared(st.sampled_from)
_LEAVES: Final = tuple(m for m in BUILTINS.values() if m.category in ("Action", "Condition"))
_INNER: Final = tuple(m for m in BUILTINS.values() if m.category in ("Control", "Decorator"))

ENTITIES: Final = ("&lt;", "&amp;", "&#65;", "&#x42;", "&quot;", "&apos;", "&gt;")


@dataclass(frozen=True, slots=True)
class Generated:
    case: Case
    bad_names: bool = False


def _blackboard(draw: st.DrawFn) -> str:
    key = draw(_pick(KEYS))
    return draw(_pick((f"{{{key}}}", "{=}", f"{{ {key} }}", "{}")))


@_shared
@st.composite
def port_value(draw: st.DrawFn, node: str, port: PortModel, names: Names) -> str | None:
    """A value for ``port`` of the built-in ``node``: ``None`` leaves it out."""
    if fault(draw, names):
        kind = draw(_pick(("omit", "invalid", "empty")))
    else:
        kind = draw(_pick(("valid", "valid", "valid", "blackboard")))
        if not port.required and draw(st.booleans()):
            kind = "omit"
    if kind == "omit":
        return None
    if kind == "empty":
        return ""
    if kind == "blackboard":
        return _blackboard(draw)
    if port.name == "code":
        pool = VALID_SCRIPTS if node == "Script" else CONDITION_SCRIPTS
        return draw(_pick(pool if kind == "valid" else BROKEN_SCRIPTS))
    if port.name == "if":
        return draw(_pick(CONDITION_SCRIPTS if kind == "valid" else BROKEN_SCRIPTS))
    if port.name in ("output_key", "key", "entry", "queue", "value") and kind == "valid":
        if port.name == "queue":
            return draw(_pick(("{q}", "1;2;3")))
        if port.name == "value" and node == "SetBlackboard":
            return draw(_pick(("1", "hello", "{a}")))
        if port.name == "value":
            return _blackboard(draw)
        key = draw(_pick(KEYS))
        return draw(_pick((key, f"{{{key}}}")))
    valid, invalid = VALUES.get(port.type, (("1",), ()))
    if kind == "invalid" and invalid:
        return draw(_pick(invalid))
    return draw(_pick(valid))


@_shared
@st.composite
def extra_attributes(draw: st.DrawFn, custom: bool, names: Names) -> list[tuple[str, str]]:
    """An instance name, pre/postconditions, an attribute no port declares."""
    out: list[tuple[str, str]] = []
    if draw(_ints(0, 4)) == 0:
        text = draw(_pick(("step", "open the door", "a&amp;b", "x&#65;y", "")))
        out.append(("name", text))
    if draw(_ints(0, 5)) == 0:
        attr = draw(_pick(PRE_POST))
        pool = CONDITION_SCRIPTS if attr.endswith("If") or attr == "_while" else VALID_SCRIPTS
        script = draw(_pick(BROKEN_SCRIPTS if fault(draw, names) else pool))
        out.append((attr, script))
    if fault(draw, names, 1 if custom else 0) or draw(_ints(0, 30)) == 0:
        value = draw(_pick(("1", "{a}", "x", "&lt;1&gt;", *ENTITIES)))
        out.append((draw(_pick(("speed", "target", "_unknown"))), value))
    return out


def _element(tag: str, attrs: list[tuple[str, str]], children: list[str]) -> str:
    text = "".join(f" {k}={_quote(v)}" for k, v in attrs)
    if not children:
        return f"<{tag}{text}/>"
    return f"<{tag}{text}>{''.join(children)}</{tag}>"


def _quote(value: str) -> str:
    """An attribute value whose entity references stay as written."""
    return '"' + value.replace('"', "&quot;") + '"' if "&" in value else quoteattr(value)


@dataclass(frozen=True, slots=True)
class Names:
    """The names one document draws from."""

    actions: tuple[str, ...]
    conditions: tuple[str, ...]
    trees: tuple[str, ...]
    callees: tuple[str, ...] = ()  # the trees the current tree calls without recursion
    faults: int = 10  # the chance, in percent, of each deliberate mistake


def fault(draw: st.DrawFn, names: Names, scale: int = 1) -> bool:
    """Whether to make a deliberate mistake here."""
    return draw(_ints(0, 99)) < names.faults * scale


@_shared
@st.composite
def builtin_node(draw: st.DrawFn, names: Names, depth: int, copy: int = 0) -> str:
    """A built-in node with drawn ports and a drawn number of children (``copy`` makes
    a distinct strategy object of the same thing)."""
    model: NodeModel = draw(_pick(_INNER if depth > 0 else _LEAVES))
    if model.category in ("Control", "Decorator") and depth > 0:
        low = max(model.min_children - 1, 0)
        high = min((model.max_children or model.min_children + 2) + 1, 7)
        if fault(draw, names):
            count = draw(_ints(low, high))
        else:
            top = max(min(model.max_children or 3, 3), model.min_children)
            count = draw(_ints(model.min_children, top))
        count = min(max(count, 0), 7)
        children = [draw(node(names, depth - 1)) for _ in range(count)]
    else:
        children = []
    attrs: list[tuple[str, str]] = []
    for port in model.ports:
        value = draw(port_value(model.id, port, names))
        if value is not None:
            attrs.append((port.name, value))
    attrs += draw(extra_attributes(False, names))
    return _element(model.id, attrs, children)


@_shared
@st.composite
def custom_node(draw: st.DrawFn, names: Names) -> str:
    """A port-less custom node, registered or not, compact or ``<Action ID>``."""
    known = (*names.actions, *names.conditions)
    unknown = not known or fault(draw, names, 0) or draw(_ints(0, 30)) == 0
    tag = draw(_pick(UNREGISTERED if unknown else known))
    attrs = draw(extra_attributes(True, names))
    if draw(_ints(0, 6)) == 0:
        kind = "Condition" if tag in names.conditions else "Action"
        return _element(kind, [("ID", tag), *attrs], [])
    children = [draw(leaf(names))] if draw(_ints(0, 40)) == 0 else []
    return _element(tag, attrs, children)


@_shared
@st.composite
def subtree_call(draw: st.DrawFn, names: Names) -> str:
    attrs: list[tuple[str, str]] = []
    pick = draw(_ints(0, 39))
    if pick == 0:
        pass  # no ID
    elif pick == 1 or not names.callees:
        attrs.append(("ID", draw(_pick(("Missing", *names.trees)))))  # maybe recursive
    else:
        attrs.append(("ID", draw(_pick(names.callees))))
    if draw(_ints(0, 2)) == 0:
        attrs.append(("_autoremap", draw(_pick(("true", "false", "1", "maybe")))))
    for _ in range(draw(_ints(0, 2))):
        port = draw(_pick(KEYS))
        if port not in (k for k, _ in attrs):
            attrs.append((port, draw(_pick(("{a}", "{b}", "42", "{=}", "", "{}")))))
    attrs += draw(extra_attributes(False, names))
    return _element("SubTree", attrs, [])


@_shared
def leaf(names: Names) -> st.SearchStrategy[str]:
    calls = [subtree_call(names)] if names.callees else []
    return st.one_of(
        custom_node(names),
        builtin_node(names, 0),
        *calls,
        _pick(("<AlwaysSuccess/>", "<AlwaysFailure/>")),
    )


@_shared
def node(names: Names, depth: int) -> st.SearchStrategy[str]:
    if depth <= 0:
        return leaf(names)
    # A built-in node twice as likely as a leaf.  one_of drops a repeated strategy
    # object, so the second one is a distinct copy (``copy`` only tells them apart).
    return st.one_of(leaf(names), builtin_node(names, depth), builtin_node(names, depth, 1))


@_shared
@st.composite
def tree(draw: st.DrawFn, tree_id: str | None, names: Names) -> str:
    count = draw(_pick((0, 2))) if fault(draw, names, 0) else 1
    if draw(_ints(0, 60)) == 0:
        count = draw(_pick((0, 2)))
    children = [draw(node(names, draw(_ints(0, 3)))) for _ in range(count)]
    attrs = [("ID", tree_id)] if tree_id is not None else []
    return _element("BehaviorTree", attrs, children)


@st.composite
def documents(draw: st.DrawFn) -> Generated:
    """A main document (and maybe a file it includes) and the nodes the application
    registers."""
    bad_names = draw(_ints(0, 9)) == 0
    actions = tuple(a for a in ACTIONS if draw(_ints(0, 5)))
    conditions = tuple(c for c in CONDITIONS if draw(_ints(0, 5)))
    ids = list(TREE_IDS[: draw(_ints(1, 3))])
    if bad_names:
        if draw(st.booleans()):
            actions = (*actions, draw(_pick(BAD_NODE_NAMES)))
        else:
            ids[-1] = draw(_pick(BAD_TREE_IDS))
    included = len(ids) > 1 and draw(_ints(0, 3)) == 0
    faults = draw(_pick((0, 0, 3, 10)))
    names = Names(actions, conditions, tuple(ids), faults=faults)
    main_ids, other_ids = (ids[:1], ids[1:]) if included else (ids, [])
    root_attrs: list[tuple[str, str]] = []
    if draw(_ints(0, 10)):
        root_attrs.append(("BTCPP_format", "4"))
    if draw(_ints(0, 40)) == 0:
        root_attrs.append(("main_tree_to_execute", "Nope"))
    elif (len(ids) > 1 and draw(_ints(0, 9))) or draw(_ints(0, 3)) == 0:
        root_attrs.append(("main_tree_to_execute", ids[0]))
    body: list[str] = []
    if included:
        body.append(_element("include", [("path", draw(_pick(("sub.xml", "none.xml"))))], []))
    single = len(main_ids) == 1 and draw(_ints(0, 15)) == 0
    for i, tid in enumerate(main_ids):
        body.append(
            draw(tree(None if single else tid, replace(names, callees=tuple(ids[i + 1 :]))))
        )
    files = [("main.xml", _element("root", root_attrs, body))]
    if included:
        sub = [
            draw(tree(tid, replace(names, callees=tuple(ids[i + 2 :]))))
            for i, tid in enumerate(other_ids)
        ]
        files.append(("sub.xml", _element("root", [("BTCPP_format", "4")], sub)))
    case = Case(tuple(files), actions, conditions, ticks=3)
    return Generated(case, bad_names)
