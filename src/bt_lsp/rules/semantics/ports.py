"""Ports and attributes of nodes.

An attribute is a port exactly when :func:`bt_lsp.rules.names.is_allowed_port_name` holds (as in
BehaviorTree.CPP); ``ID``, ``name``, ``_autoremap`` and the pre/post-condition scripts are
reserved; everything else is silently ignored by BehaviorTree.CPP.

A model is exact when it is a built-in's or comes from an authoritative catalog (see
:data:`bt_lsp.rules.context.AUTHORITATIVE`); a ``<TreeNodesModel>`` entry of a tree file is
advisory (BehaviorTree.CPP reads the C++ registration, not it).

* ``undeclared-port``: a port attribute the node's model does not declare.  An error for
  an exact model (BehaviorTree.CPP 4 throws at tree creation: "a port with name … is found
  in the XML but not in the providedPorts()"); a hint for an advisory one (a
  ``<TreeNodesModel>`` entry, a palette, a C++ port list not all read: BehaviorTree.CPP
  reads the C++ registration, which bt-lsp did not see whole); a warning for a
  ``<SubTree>`` call whose tree has a ``<SubTree>`` model listing ports (BehaviorTree.CPP
  passes any attribute on as a remapping, so an undeclared one is only suspicious), a
  hint when that model lists none.  Nothing is
  reported when the model is unknown, or for a ``<SubTree>`` call without a model.
  Range: the attribute name.
* ``missing-required-port`` (error): a port without a default that is not given, where
  BehaviorTree.CPP fails for it.  Built-ins: input and inout ports (the node fails when it
  reads it); the ``SwitchN`` ports are a warning (it reads them as optional).
  ``<SubTree>`` models: every port whose ``default`` is absent or empty, unless
  ``_autoremap`` is true ("is defining a mandatory port … but you are not remapping it").
  Range: the element name.
* ``missing-port-without-default`` (hint): a port of a custom node's model without a
  default that is not given.  BehaviorTree.CPP never checks ports when it loads or
  creates a tree, and a node's code often reads a port without a default as optional
  (``getInput`` returning an error, Nav2's fallbacks to parameters).  Range: the element
  name.
* ``invalid-port-value``: a literal that does not convert to the declared type; an error
  for an exact model (BehaviorTree.CPP 4 converts the literal at tree creation for a
  strongly typed port with a converter), a warning for an advisory one.  Only a value
  that is exactly ``{…}`` (three characters at least) is left to the blackboard there:
  ``" {a} "`` and ``"="`` are keys to ``getInput`` but literals to that conversion, so
  they fail for an ``int`` port; ``{}`` is a literal.  An enum port (``NodeStatus``) is
  converted only when the node reads it (the message says so).  Built-ins whose
  constructor reads a port itself: the literal ``queue`` of ``LoopInt``/``LoopDouble``/
  ``LoopBool`` is converted item by item (``" {q} "`` is a warning: a literal before
  4.10, the key in 4.10), an empty ``entry`` of ``WaitValueUpdate``/
  ``SkipUnlessUpdated``/``WasEntryUpdated`` fails ("Missing port 'entry'");
  ``_autoremap`` on ``<SubTree>`` must be a bool literal.  Range: the value.
* ``blackboard-type-mismatch``: within one tree, a key used by ports of two different strong
  types (the key as ``getRemappedKey`` reads it: spaces inside the braces belong to it, ``{
  a }`` is the entry ``" a "``; the first use fixes the entry's type; a ``std::string``
  entry accepts anything).  Types are compared as C++ types (:mod:`bt_lsp.rules.port_types`:
  spellings of one built-in type, ``std::`` forms, top-level ``const`` and references are
  one; a type read from C++ with the project's own aliases followed,
  :mod:`bt_lsp.cpp.types`), and only when every name in both is known not to be an alias
  (built-in, standard library, ROS interface types, classes the project's C++ defines): any
  other name may be a ``using`` from a header bt-lsp did not read, so it proves nothing.  An
  error when both models are exact, else a warning.  Shared pointers of two classes read by
  an input port are a hint: BehaviorTree.CPP accepts the connection when the application
  registers a polymorphic cast between them (input ports only; an inout or output port must
  match exactly).  Range: the later value.
* ``port-name-not-remappable`` (warning): an attribute that passes the name rules but
  not ``is_allowed_port_name`` and does not start with ``_`` (``检查``, ``-x``): never a
  port.  Range: the attribute name.
* ``unknown-attribute``: an attribute starting with ``_`` that is not reserved
  (``_skipif``); ``_description``, ``_uid`` and ``_fullpath`` (written by BehaviorTree.CPP
  itself) are allowed.  BehaviorTree.CPP keeps such an attribute in the node's
  ``NodeConfig::other_attributes``, where only the node's C++ can read it.  A warning when
  it is close to a reserved name (then very likely a misspelling), else a hint.  Fix: the
  reserved name it most likely means (``__shared_blackboard`` and ``__autoremap`` are
  version 3 spellings of ``_autoremap``).  Range: the name.
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from dataclasses import dataclass
from functools import lru_cache
from types import MappingProxyType
from typing import Final

from bt_lsp.rules import port_types
from bt_lsp.rules.builtins import PortModel
from bt_lsp.rules.codes import BT, FixData, Severity, define, display_only, unsafe
from bt_lsp.rules.conversions import (
    blackboard_key,
    convert_literal,
    convert_queue,
    converted_at_creation,
    is_blackboard_reference,
    is_converted_as_reference,
)
from bt_lsp.rules.names import (
    POSTCONDITIONS,
    PRECONDITIONS,
    NameKind,
    check_name,
    is_allowed_port_name,
)
from bt_lsp.rules.script import CONDITION_ATTRS, SCRIPT_PORTS
from bt_lsp.rules.semantics import scripts
from bt_lsp.rules.semantics.base import (
    BlackboardUse,
    Resolved,
    State,
    TreeScope,
    edit_distance,
    quoted,
)
from bt_lsp.syntax.elements import Element
from bt_lsp.syntax.tokens import Attr

# A placeholder that something replaces before BehaviorTree.CPP reads the text: `${name}`
# (PlanSys2 fills its action trees' `${arg1}`), `$(arg name)` (ROS launch substitution).
_TEMPLATE: Final = re.compile(r"\$\{[^}]*\}|\$\([^)]*\)")


@dataclass(frozen=True, slots=True)
class MissingPorts(FixData):
    """The ports ``missing-required-port`` or ``missing-port-without-default`` found
    missing, in their declared order."""

    ports: tuple[str, ...]

    def as_json(self) -> dict[str, object]:
        return {"ports": list(self.ports)}


@dataclass(frozen=True, slots=True)
class AttributeSuggestion(FixData):
    """What ``unknown-attribute`` tells its fix: the reserved attribute most likely meant,
    and whether it is surely meant (``preferred``)."""

    suggestion: str
    preferred: bool

    def as_json(self) -> dict[str, object]:
        return {"suggestion": self.suggestion, "preferred": self.preferred}


# The codes of these rules (see bt_lsp.rules.registry).
UNDECLARED_PORT: Final = define(
    "undeclared-port",
    Severity.ERROR,
    "an attribute the node's model does not declare",
    BT,
    doc="""
        An attribute whose name is a valid port name is a port, and the node's type must declare
        it in `providedPorts()`. BehaviorTree.CPP 4 throws when it creates the tree: `a port with
        name [speed] is found in the XML (<MoveBase>, line 3) but not in the providedPorts() of
        its registered node type`. bt-lsp knows a node's ports from the built-ins, a node
        catalog (`models`), the project's C++ or a `<TreeNodesModel>`; against a catalog or the
        C++ it is an error, against a tree file's own `<TreeNodesModel>` (which BehaviorTree.CPP
        does not read for nodes) a hint. A `<SubTree>` call passes any attribute on as a
        remapping, so there it is a warning at most.
        """,
    why="""
        The tree is not created; most often the port is misspelt (`goal_pose` for `goal`), and
        bt-lsp suggests the closest declared name.
        """,
    bad='<Sleep msec="500" duration="1"/>',
    good='<Sleep msec="500"/>',
    since="""
        BehaviorTree.CPP 4 (3.x ignores an attribute that is not a declared port).
        """,
)
MISSING_REQUIRED_PORT: Final = define(
    "missing-required-port",
    Severity.ERROR,
    "a built-in's or a `<SubTree>` model's port without a default that is not given "
    "(BehaviorTree.CPP fails)",
    BT,
    doc="""
        BehaviorTree.CPP does not check, when it loads or creates a tree, that a port without a
        default is given. A built-in node reads it when it is ticked and fails then (`Missing
        parameter [num_cycles] in RepeatNode`). For a `<SubTree>` whose model declares a port
        without a default, creating the tree fails unless the call remaps it or sets
        `_autoremap="true"`. Both are errors. (A custom node's port without a default is
        `missing-port-without-default`, a hint.)
        """,
    why="""
        The node fails on its first tick, on the robot, long after the tree loaded without
        complaint.
        """,
    bad="<Repeat><AlwaysSuccess/></Repeat>",
    good='<Repeat num_cycles="3"><AlwaysSuccess/></Repeat>',
    # No value is right without the author: an input gets an empty value to fill in (which
    # a typed port rejects until it is), a <SubTree> port the key of its name.
    fixes={"add": unsafe("Add {ports}")},
    since="""
        Every version (the built-ins' ports are those of the detected version).
        """,
)
MISSING_PORT_WITHOUT_DEFAULT: Final = define(
    "missing-port-without-default",
    Severity.HINT,
    "a custom node's port without a default that is not given (BehaviorTree.CPP does not "
    "check it; the node's code may read it as optional)",
    BT,
    doc="""
        A custom node's model (its C++ `providedPorts()`, a catalog or a `<TreeNodesModel>`)
        declares a port without a default, and the node is used without it. BehaviorTree.CPP
        checks nothing here: the node's code decides, and code often reads such a port as
        optional (`getInput` returns an error the node handles, as Nav2's nodes do), so this is
        a hint. Silence it with `severity = { missing-port-without-default = "off" }` without
        losing the built-ins' `missing-required-port` errors.
        """,
    # The port may well be optional in the node's code: giving it changes what it does.
    fixes={"add": display_only("Add {ports}")},
    why="""
        When the node's code does need the port, the node fails at its first tick.
        """,
    since="""
        Every version.
        """,
)
INVALID_PORT_VALUE: Final = define(
    "invalid-port-value",
    Severity.ERROR,
    "a literal that does not convert to the port's type",
    BT,
    doc="""
        A literal value (not a `{blackboard}` reference) of a strongly typed port must convert to
        the port's type. BehaviorTree.CPP 4 converts it when it creates the tree and throws: `The
        port with name "msec" and value "abc" can not be converted to unsigned int`. bt-lsp
        converts numbers, booleans, enums it knows and the built-in types as BehaviorTree.CPP's
        `convertFromString` does: like `std::from_chars`, an integer only needs a leading number
        (`"12abc"` reads as 12). Against a model from a tree file's `<TreeNodesModel>` it is a
        warning.
        """,
    why="""
        The tree is not created; a wrong unit or a typo in a number is caught before the robot runs.
        """,
    bad='<Sleep msec="half"/>',
    good='<Sleep msec="500"/>',
    since="""
        BehaviorTree.CPP 4. Version 3 converts a literal only when the node reads the port, so
        for a 3.x project it is a warning for a built-in and a hint for a custom node.
        """,
)
BLACKBOARD_TYPE_MISMATCH: Final = define(
    "blackboard-type-mismatch",
    Severity.ERROR,
    "one blackboard key used by ports of different types",
    BT,
    doc="""
        Within one tree, a blackboard entry gets its type from the first port that uses it; a
        port of another type using the same `{key}` makes BehaviorTree.CPP throw when it creates
        the tree: `The creation of the tree failed because the port [count] was initially
        created with type [int] and, later type [unsigned int] was used somewhere else`. A
        `std::string` entry accepts anything, and two shared pointers of different classes are
        accepted when the application registers a polymorphic cast (a hint then, since only
        the C++ knows).
        """,
    why="""
        The tree is not created; when it is (an untyped port in between), the node reading the
        key gets a value it cannot use.
        """,
    bad="""
        <Sequence>
          <Repeat num_cycles="{count}">  <!-- num_cycles: int -->
            <AlwaysSuccess/>
          </Repeat>
          <Sleep msec="{count}"/>        <!-- msec: unsigned int -->
        </Sequence>
        """,
    good="""
        <Sequence>
          <Repeat num_cycles="{count}">
            <AlwaysSuccess/>
          </Repeat>
          <Sleep msec="{wait_ms}"/>
        </Sequence>
        """,
    since="BehaviorTree.CPP 4 (and 3.8, whose ports are typed the same way).",
)
PORT_NAME_NOT_REMAPPABLE: Final = define(
    "port-name-not-remappable",
    Severity.WARNING,
    "a port name that does not start with an ASCII letter, so XML cannot set it",
    BT,
    doc="""
        BehaviorTree.CPP treats an attribute as a port only when its name starts with an ASCII
        letter (`IsAllowedPortName`). A name that passes the name rules but starts otherwise
        (`检查`, `-x`) is silently ignored on a node, is never passed on as a remapping by a
        `<SubTree>` call (its model's port then only takes its default or comes from
        `_autoremap`), and cannot be declared by a C++ node at all (`CreatePort` throws).
        """,
    why="""
        The node never gets the value written for it, and nothing says so at run time.
        """,
    bad='<Sleep msec="500" 检查="1"/>',
    good='<Sleep msec="500" name="检查"/>',
    since="BehaviorTree.CPP 4.",
)
UNKNOWN_ATTRIBUTE: Final = define(
    "unknown-attribute",
    Severity.WARNING,
    "an underscore attribute that is neither a port nor reserved (kept in the node's "
    "`other_attributes`; a hint unless it looks like a misspelled reserved name)",
    BT,
    fixes={
        # BehaviorTree.CPP loads the file and ignores the attribute today; the reserved one
        # takes effect (a precondition starts to run): a change of behaviour.
        "rename": unsafe(
            "Did you mean '{suggestion}'? Rename '{old}'", "surely a misspelling of it"
        ),
        "guess": display_only("Did you mean '{suggestion}'? Rename '{old}'", "a guess"),
    },
    doc="""
        An attribute starting with `_` is never a port, and BehaviorTree.CPP reads only the
        reserved ones itself (`_autoremap`, the pre- and post-conditions `_skipIf`,
        `_successIf`, `_failureIf`, `_while`, `_onSuccess`, `_onFailure`, `_onHalted`,
        `_post`; `_description`, `_uid` and `_fullpath` are allowed too). Any other is kept
        in the node's `other_attributes`, which only the node's own C++ reads. A warning when
        it looks like a misspelled reserved name (`_skipif`: the fix renames it), else a
        hint. `__shared_blackboard` and `__autoremap` are version 3 spellings of
        `_autoremap`.
        """,
    why="""
        A misspelt precondition never runs: the node is ticked when it should have been
        skipped, with no error.
        """,
    bad='<Sleep msec="500" _skipif="done"/>',
    good='<Sleep msec="500" _skipIf="done"/>',
    since="BehaviorTree.CPP 4 (the pre- and post-conditions are version 4 attributes).",
)


# Underscore attributes that editors and BehaviorTree.CPP itself write on purpose:
# descriptions, WriteTreeToXML's metadata, and the editors' collapsed-node flag.
SILENT_ATTRIBUTES: Final[frozenset[str]] = frozenset(
    {"_description", "_uid", "_fullpath", "_collapsed"}
)
_UNDERSCORE_RESERVED: Final[tuple[str, ...]] = (*PRECONDITIONS, *POSTCONDITIONS, "_autoremap")
_RESERVED_LOWER: Final[Mapping[str, str]] = MappingProxyType(
    {n.lower(): n for n in _UNDERSCORE_RESERVED}
)
V3_ATTRIBUTES: Final[Mapping[str, str]] = MappingProxyType(
    {
        "__shared_blackboard": "_autoremap",
        "__autoremap": "_autoremap",
    }
)
_BOOL_WORDS: Final = frozenset({"1", "0", "true", "false", "True", "False", "TRUE", "FALSE"})
_TRUE_WORDS: Final = frozenset({"1", "true", "True", "TRUE"})

_allowed = lru_cache(maxsize=4096)(is_allowed_port_name)


@lru_cache(maxsize=16384)
def _convert(value: str, type_: str) -> str | None:
    return convert_literal(value, type_)


def canonical_type(type_: str) -> str | None:
    """A port type for comparison, or ``None`` when it is not strongly typed."""
    return port_types.canonical(type_)


_SHARED_POINTER: Final = re.compile(
    r"(?:std::)?shared_ptr<\s*(?P<a>.+?)\s*>|(?P<b>.+?)::(?:Ptr|SharedPtr|ConstPtr)"
)


def pointee(type_: str) -> str | None:
    """The class a shared pointer type points to (``std::shared_ptr<Cat>``, ``Cat::Ptr``),
    or ``None`` for any other type."""
    m = _SHARED_POINTER.fullmatch(type_)
    if m is None:
        return None
    return m.group("a") or m.group("b")


def suggest_attribute(name: str) -> tuple[str, bool] | None:
    """The reserved attribute ``name`` probably means, and whether that is a sure match."""
    if name in V3_ATTRIBUTES:
        return V3_ATTRIBUTES[name], True
    lowered = _RESERVED_LOWER.get(name.lower())
    if lowered is not None:
        return lowered, True
    best: tuple[int, str] | None = None
    for cand in _UNDERSCORE_RESERVED:
        d = edit_distance(name, cand, 2)
        if d <= 2 and (best is None or d < best[0]):
            best = (d, cand)
    return (best[1], False) if best is not None else None


def check_attributes(
    st: State, el: Element, res: Resolved | None, scope: TreeScope, is_subtree: bool
) -> None:
    """Every attribute of one node element, then the ports it leaves out."""
    given: set[str] = set()
    autoremap = False
    for a in el.attrs:
        an = a.name
        value = a.value
        if value is None or an == "ID" or an == "name":
            continue
        # Present counts as given even when the name breaks a rule: the name rules say why
        # BehaviorTree.CPP would not read it, and saying "missing" too would mislead.
        given.add(an)
        if an in CONDITION_ATTRS:
            scripts.check(st, el, a)
            continue
        if an == "_autoremap" or (st.v3 and is_subtree and an in V3_ATTRIBUTES):
            # Version 3 spells it __shared_blackboard (SubTree) or __autoremap (SubTreePlus).
            if is_subtree:
                autoremap = _check_autoremap(st, el, a, value)
            continue
        if _allowed(an):
            if res is not None:
                _check_port(st, el, a, value, res, scope)
            continue
        if an in SILENT_ATTRIBUTES or check_name(an, NameKind.PORT):
            continue  # allowed, or reported by the name rules
        s, e = el.span_of_name(a)
        if an.startswith("_"):
            _unknown_attribute(st, an, s, e)
        else:
            st.add(
                s,
                e,
                "port-name-not-remappable",
                f"{quoted(an)} does not start with an ASCII letter, so BehaviorTree.CPP does not "
                "treat it as a port and silently ignores it",
            )
    if res is not None:
        _missing(st, el, res, given, autoremap)


def _unknown_attribute(st: State, an: str, s: int, e: int) -> None:
    message = (
        f"{quoted(an)} is neither a port (ports start with a letter) nor a reserved "
        "attribute: BehaviorTree.CPP only keeps it in the node's other_attributes, which "
        "nothing but the node's own C++ code reads"
    )
    sug = suggest_attribute(an)
    data: AttributeSuggestion | None = None
    severity: Severity | None = Severity.HINT
    if sug is not None:
        message += f"; did you mean {quoted(sug[0])}?"
        data = AttributeSuggestion(sug[0], sug[1])
        severity = None
    st.add(s, e, "unknown-attribute", message, severity, data)


def _check_autoremap(st: State, el: Element, a: Attr, value: str) -> bool:
    if value not in _BOOL_WORDS:
        s, e = el.span_of_value(a)
        st.add(
            s,
            e,
            "invalid-port-value",
            f"{a.name} must be a bool literal (true/false, 1/0), not {quoted(value)}; "
            "BehaviorTree.CPP fails with 'invalid bool conversion'",
        )
        return False
    return value in _TRUE_WORDS


def _owner(res: Resolved) -> str:
    if res.origin == "subtree":
        return f"The <SubTree> model of tree {quoted(res.id)}"
    if res.origin == "custom":
        if res.where:  # learned from the C++
            return f"The C++ node {quoted(res.id)} (registered in {res.where})"
        if res.authoritative:
            return f"The node catalog's model of {quoted(res.id)}"
        return f"The <TreeNodesModel> entry of {quoted(res.id)}"
    return f"The built-in node {quoted(res.id)}"


def _check_port(
    st: State, el: Element, a: Attr, value: str, res: Resolved, scope: TreeScope
) -> None:
    port = res.ports.get(a.name)
    if port is None:
        _undeclared(st, el, a, res)
        return
    if res.origin == "subtree":
        return  # a literal remapping of a subtree port is stored as text, never converted
    if (res.id, a.name) in SCRIPT_PORTS and res.origin == "builtin":
        # An empty Script is no script: its constructor parses the code only when it
        # differs from the last one parsed, which starts empty (script_node.h).
        if not is_blackboard_reference(value) and (value or res.id != "Script"):
            scripts.check(st, el, a)
        return
    if res.origin == "builtin" and not st.v3 and _check_builtin_value(st, el, a, value, res):
        return
    if is_blackboard_reference(value):
        # The tree's entry is made with the port's type either way (getRemappedKey); but
        # version 4 also converts a typed port's value at tree creation unless it is
        # exactly {key}: " {key} " and "=" are keys only for a port that takes any text.
        _blackboard_use(st, el, a, value, port, res, scope)
        if (
            st.v3
            or is_converted_as_reference(value)
            or not converted_at_creation(port.type)
            or _convert(value, port.type) is None
        ):
            return
    if not port.type or (st.v3 and not value):
        # BehaviorTree.CPP 3.8 reads an empty value as not given (the default applies).
        return
    if _TEMPLATE.search(value):
        # A `${name}` or `$(arg x)` placeholder: the application (PlanSys2's action trees) or
        # a launch file replaces it before BehaviorTree.CPP reads the text.
        return
    problem = _convert(value, port.type)
    if problem is not None:
        s, e = el.span_of_value(a)
        message = (
            f"The value of port {quoted(a.name)} cannot be converted to {port.type}: {problem}"
            + (f" (a port of {quoted(res.id)}, registered in {res.where})" if res.where else "")
        )
        severity: Severity | None = None if res.exact else Severity.WARNING
        if st.v3:
            # 3.8 converts a literal only when the node reads the port: a built-in then
            # throws, a custom node's getInput returns an error its code may handle.
            message += "; BehaviorTree.CPP 3 converts it only when the node reads the port " + (
                "(the node then fails)" if res.origin == "builtin" else "(getInput fails)"
            )
            severity = Severity.WARNING if res.origin == "builtin" else Severity.HINT
        elif not converted_at_creation(port.type):
            message += (
                "; BehaviorTree.CPP converts an enum port only when the node reads it "
                "(the node then fails)"
            )
        else:
            message += "; BehaviorTree.CPP 4 converts it when it creates the tree"
            if is_blackboard_reference(value):
                message += (
                    ", and only a value that is exactly {key}, without spaces around the "
                    "braces, is left to the blackboard there"
                    if value != "="
                    else ", where only {=} stands for the key named like the port"
                )
        st.add(s, e, "invalid-port-value", message, severity)


# The item type of the literal queue of a Loop node (LoopString takes any text).
_LOOP_ITEMS: Final = MappingProxyType(
    {"LoopInt": "int", "LoopDouble": "double", "LoopBool": "bool"}
)
# The built-ins that read port ``entry`` in their constructor.
_ENTRY_NODES: Final = frozenset({"WaitValueUpdate", "SkipUnlessUpdated", "WasEntryUpdated"})


def _check_builtin_value(st: State, el: Element, a: Attr, value: str, res: Resolved) -> bool:
    """The values of version 4 built-ins that their constructor reads itself (the port's
    type says nothing of them); whether the value was checked here."""
    if a.name == "queue" and res.id in _LOOP_ITEMS:
        # Before 4.10 the port is typed (SharedQueue<T>): the tree's creation converts
        # all but an exact {key}.  4.10's port takes anything, and the node's constructor
        # converts what isBlackboardPointer does not take for a key (" {q} " is one).
        if is_converted_as_reference(value):
            return False
        problem = convert_queue(value, _LOOP_ITEMS[res.id])
        reference = is_blackboard_reference(value) and value != "="
        if problem is not None:
            s, e = el.span_of_value(a)
            message = (
                f"The value of port 'queue' cannot be converted to a queue of "
                f"{_LOOP_ITEMS[res.id]}: {problem}; BehaviorTree.CPP converts a literal queue "
                f"('1;2;3') item by item when it creates {quoted(res.id)}"
            )
            if reference:
                message += (
                    " (before 4.10, where only an exact {key} is left to the blackboard; "
                    "4.10 reads a key with spaces around the braces as the key)"
                )
            st.add(s, e, "invalid-port-value", message, Severity.WARNING if reference else None)
        return not reference
    if a.name == "entry" and res.id in _ENTRY_NODES and not value:
        s, e = el.span_of_value(a)
        st.add(
            s,
            e,
            "invalid-port-value",
            f"Port 'entry' of {quoted(res.id)} is empty; BehaviorTree.CPP fails when it "
            f"creates the node: \"Missing port 'entry'\" (give the blackboard entry to "
            "watch, as {key} or key)",
        )
        return True
    return False


def _undeclared(st: State, el: Element, a: Attr, res: Resolved) -> None:
    s, e = el.span_of_name(a)
    names = sorted(res.ports)
    close = [n for n in names if edit_distance(a.name, n, 2) <= 2]
    hint = f"; did you mean {quoted(close[0])}?" if close else ""
    declared = ", ".join(names[:12]) + (" …" if len(names) > 12 else "") if names else "none"
    if res.origin == "subtree":
        message = (
            f"{_owner(res)} declares no port {quoted(a.name)} (ports: {declared}){hint}; "
            "BehaviorTree.CPP passes it on as a remapping anyway"
        )
        # A model without any port (an editor's bare <SubTree ID="X"/>) says nothing of
        # the tree's ports: only a model that lists some makes another one suspicious.
        # BehaviorTree.CPP 3 reads no <SubTree> model at all: an editor's note only.
        if st.v3:
            message += " (BehaviorTree.CPP 3 does not read <SubTree> models)"
        loud = names and not st.v3
        st.add(s, e, "undeclared-port", message, Severity.WARNING if loud else Severity.HINT)
        return
    if res.where:
        message = (
            f"{quoted(res.id)} declares no port {quoted(a.name)} (registered in {res.where}; "
            f"ports{'' if res.exact else ' read'}: {declared}){hint}"
        )
    else:
        message = f"{_owner(res)} has no port {quoted(a.name)} (ports: {declared}){hint}"
    if res.exact:
        message += (
            "; BehaviorTree.CPP refuses to create the tree: the attribute is not in the "
            "node's providedPorts()"
        )
        st.add(s, e, "undeclared-port", message)
    else:
        # BehaviorTree.CPP reads the C++ registration, never an author's model: what the
        # node really declares is not known, so this is a hint.
        message += (
            "; BehaviorTree.CPP rejects it unless the C++ node declares it (its port list "
            "could not all be read statically: the hover on the node says what was not)"
            if res.where
            else "; BehaviorTree.CPP rejects it only if the C++ node does not declare it "
            "(BehaviorTree.CPP reads the C++ registration, not this model)"
        )
        st.add(s, e, "undeclared-port", message, Severity.HINT)


def _is_switch(type_id: str) -> bool:
    return type_id.startswith("Switch") and type_id[6:].isdigit()


def _missing(st: State, el: Element, res: Resolved, given: set[str], autoremap: bool) -> None:
    if not res.required or (res.origin == "subtree" and (autoremap or st.v3)):
        return  # BehaviorTree.CPP 3 does not check a SubTree model's ports
    missing = [p for p in res.required if p not in given]
    if not missing:
        return
    shown = ", ".join(quoted(m) for m in missing)
    plural = "s" if len(missing) > 1 else ""
    if res.origin == "subtree":
        message = (
            f"{_owner(res)} declares mandatory port{plural} {shown} without a default, and "
            'this call neither remaps it nor sets _autoremap="true"'
        )
        severity = None
    elif res.origin == "builtin" and _is_switch(res.id):
        # SwitchN reads its ports with getInput and goes on: no variable ticks the default
        # child, a case without a value never matches (both versions' switch_node.h).
        effect = (
            "so it always ticks the default (last) child"
            if "variable" in missing
            else f"and {'those cases' if plural else 'that case'} never match"
        )
        message = (
            f"{quoted(res.id)} is not given port{plural} {shown}; BehaviorTree.CPP reads "
            f"{'them' if plural else 'it'} as optional, {effect}"
        )
        severity = Severity.WARNING
    elif res.origin == "builtin":
        message = f"{quoted(res.id)} needs port{plural} {shown} (no default); " + _missing_effect(
            res.id, missing[0]
        )
        severity = None
    else:
        message = (
            f"{_owner(res)} declares port{plural} {shown} without a default, and "
            f"{'they are' if plural else 'it is'} not given here; BehaviorTree.CPP does not "
            "check ports when it loads or creates the tree, and a port without a default may "
            "be optional in the node's code"
        )
        st.add(
            el.name_start,
            el.name_end,
            "missing-port-without-default",
            message,
            None,
            MissingPorts(tuple(missing)),
        )
        return
    st.add(
        el.name_start,
        el.name_end,
        "missing-required-port",
        message,
        severity,
        MissingPorts(tuple(missing)),
    )


# When a built-in reads a port it was not given, and what BehaviorTree.CPP then says
# (4.8.2 and 4.10): True when it is read as the node is created, else at its first tick.
_MISSING_WORDS: Final[Mapping[tuple[str, str], tuple[bool, str]]] = MappingProxyType(
    {
        ("Script", "code"): (True, "Missing port [code]"),
        ("ScriptCondition", "code"): (True, "Missing port [code]"),
        ("Precondition", "if"): (True, "Missing parameter [if]"),
        **{(n, "entry"): (True, "Missing port 'entry'") for n in sorted(_ENTRY_NODES)},
        **{(f"Loop{t}", "queue"): (True, "[queue] not found") for t in ("Int", "Double", "Bool")},
        ("LoopString", "queue"): (True, "[queue] not found"),
        ("Sleep", "msec"): (False, "Missing parameter [msec]"),
        ("Timeout", "msec"): (False, "Missing parameter [msec]"),
        ("Delay", "delay_msec"): (False, "Missing parameter [delay_msec]"),
        ("Repeat", "num_cycles"): (False, "Missing parameter [num_cycles]"),
        ("RetryUntilSuccessful", "num_attempts"): (False, "Missing parameter [num_attempts]"),
        ("SetBlackboard", "output_key"): (False, "missing port [output_key]"),
        ("UnsetBlackboard", "key"): (False, "missing input port [key]"),
    }
)


def _missing_effect(node: str, port: str) -> str:
    """What BehaviorTree.CPP does with a built-in that misses ``port``, in its words."""
    known = _MISSING_WORDS.get((node, port))
    if known is None:
        return "the node fails when it reads a missing port"
    at_creation, words = known
    if at_creation:
        return f"BehaviorTree.CPP fails when it creates the node: '{words}'"
    return f"BehaviorTree.CPP creates the tree, and the node throws at its first tick: '{words}'"


def _closed(canon: str, res: Resolved, port: PortModel) -> bool:
    """Whether a port type proves what it names: a built-in's, one a BehaviorTree.CPP
    catalog wrote (``writeTreeNodesModelXML`` demangles the C++ type, so aliases are
    resolved), or one whose every name is known not to be an alias (the project's
    classes among them, for a type read from its C++)."""
    if res.origin == "builtin" or (res.authoritative and not res.where):
        return True
    return port_types.is_closed(canon, port.classes)


def _port_type(port: PortModel) -> tuple[str | None, str]:
    """The type to compare (the C++'s aliases followed) and the type as shown: as written,
    with what it resolves to when that is another spelling."""
    if port.resolved is None or canonical_type(port.type) is None:
        return canonical_type(port.type), port.type
    canon = canonical_type(port.resolved)
    if canon is None or canon == canonical_type(port.type):
        return canon, port.type
    return canon, f"{port.type} (that is, {port.resolved})"


def _blackboard_use(
    st: State,
    el: Element,
    a: Attr,
    value: str,
    port: PortModel,
    res: Resolved,
    scope: TreeScope,
) -> None:
    st.pure = False  # the first use of a key in the tree counts
    canon, shown = _port_type(port)
    if canon is None:
        return
    key = blackboard_key(a.name, value)
    if key is None:
        return
    first = scope.keys.get(key)
    if first is None:
        scope.keys[key] = BlackboardUse(
            canon, shown, res.exact, a.name, res.id, _closed(canon, res, port)
        )
        return
    if first.type == canon or first.type == "std::string":
        return
    if not (first.closed and _closed(canon, res, port)):
        # A name bt-lsp cannot resolve may be an alias of the other type (``TaskPtr`` of
        # ``std::shared_ptr<Task>``, from a header outside the project): nothing proven.
        return
    s, e = el.span_of_value(a)
    held, wanted = pointee(first.type), pointee(canon)
    if held is not None and wanted is not None and port.direction == "input":
        st.add(
            s,
            e,
            "blackboard-type-mismatch",
            f"Blackboard key {quoted(key)} holds a {first.shown} (port {quoted(first.port)} "
            f"of {quoted(first.node)}) and is read as {shown} here; BehaviorTree.CPP "
            "creates the tree only if the application registers a polymorphic cast between "
            f"{held} and {wanted} (registerPolymorphicCast)",
            Severity.HINT,
        )
        return
    st.add(
        s,
        e,
        "blackboard-type-mismatch",
        f"Blackboard key {quoted(key)} was first used as {first.shown} (port "
        f"{quoted(first.port)} of {quoted(first.node)}) and is {shown} here; "
        "BehaviorTree.CPP refuses to create the tree",
        None if (first.exact and res.exact) else Severity.WARNING,
    )
