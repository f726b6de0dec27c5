"""The node types a default ``BT::BehaviorTreeFactory`` (BehaviorTree.CPP 4.x) registers.

Pure data plus two small helpers: no LSP imports and no I/O. The table mirrors the factory
constructor of BehaviorTree.CPP 4.10 (42 types) with the ports each type declares in
``providedPorts()``; see ``shared/spec/bt-xml.md`` section (d).

* :data:`BUILTINS` maps a registration ID to its :class:`NodeModel`.
* :data:`V3_RENAMES` maps names from BehaviorTree.CPP 3.x (and one well-known typo) to
  their 4.x spelling, for "did you mean" hints. None of the keys is registered in 4.x.
* :func:`convert_literal` tells whether a literal attribute value would survive the
  ``convertFromString<T>()`` call BehaviorTree.CPP makes for a typed input port.
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping
from dataclasses import dataclass
from types import MappingProxyType
from typing import Final, Literal

Category = Literal["Action", "Condition", "Control", "Decorator", "SubTree"]
Direction = Literal["input", "output", "inout"]


@dataclass(frozen=True, slots=True)
class PortModel:
    """One port of a node type.

    ``type`` is spelled the way BehaviorTree.CPP writes it in a ``<TreeNodesModel>``
    (``"unsigned int"``, ``"std::string"``, ``"NodeStatus"``, ``"any"``, ...).
    ``default`` is the default value as text, or ``None`` when the port has no default
    (so a missing value fails when the node reads it).
    """

    name: str
    direction: Direction
    type: str
    default: str | None
    description: str

    @property
    def required(self) -> bool:
        return self.default is None


@dataclass(frozen=True, slots=True)
class NodeModel:
    """A registered node type: category, ports and how many children it takes.

    ``max_children`` is ``None`` when there is no upper bound.
    """

    id: str
    category: Category
    ports: tuple[PortModel, ...]
    min_children: int
    max_children: int | None
    is_async: bool
    description: str

    def port(self, name: str) -> PortModel | None:
        """The port called ``name``, or ``None``."""
        for port in self.ports:
            if port.name == name:
                return port
        return None

    @property
    def port_names(self) -> tuple[str, ...]:
        return tuple(port.name for port in self.ports)

    def accepts_children(self, count: int) -> bool:
        """Whether ``count`` children satisfy this type's child rule."""
        if count < self.min_children:
            return False
        return self.max_children is None or count <= self.max_children


# --------------------------------------------------------------------------------------
# The table
# --------------------------------------------------------------------------------------


def _in(name: str, type_: str, default: str | None, description: str) -> PortModel:
    return PortModel(name, "input", type_, default, description)


def _out(name: str, type_: str, description: str) -> PortModel:
    return PortModel(name, "output", type_, None, description)


def _inout(name: str, type_: str, description: str) -> PortModel:
    return PortModel(name, "inout", type_, None, description)


def _leaf(id_: str, category: Category, description: str, *ports: PortModel) -> NodeModel:
    return NodeModel(id_, category, ports, 0, 0, False, description)


def _control(
    id_: str,
    description: str,
    *ports: PortModel,
    min_children: int = 1,
    max_children: int | None = None,
    is_async: bool = False,
) -> NodeModel:
    return NodeModel(id_, "Control", ports, min_children, max_children, is_async, description)


def _decorator(id_: str, description: str, *ports: PortModel) -> NodeModel:
    return NodeModel(id_, "Decorator", ports, 1, 1, False, description)


def _switch(cases: int) -> NodeModel:
    ports = [_in("variable", "std::string", None, "Value compared with every case_N port.")]
    ports += [
        _in(f"case_{i}", "std::string", None, f"Value that selects child {i}.")
        for i in range(1, cases + 1)
    ]
    return _control(
        f"Switch{cases}",
        f"Ticks the child whose case_N equals `variable`, or the last (default) child; "
        f"needs exactly {cases + 1} children ({cases} cases + default).",
        *ports,
        min_children=cases + 1,
        max_children=cases + 1,
    )


def _loop(suffix: str, value_type: str) -> NodeModel:
    return _decorator(
        f"Loop{suffix}",
        f"Pops {value_type} items from `queue` one at a time into `value` and ticks the "
        f"child once per item.",
        _inout("queue", "any", "Queue to pop items from: a blackboard entry or 'a;b;c'."),
        _in(
            "if_empty",
            "NodeStatus",
            "SUCCESS",
            "Status returned when the queue is empty: SUCCESS, FAILURE or SKIPPED.",
        ),
        _out("value", value_type, "The item popped for the current iteration."),
    )


_ENTRY_PORT = _in("entry", "BT::Any", None, "Blackboard entry to watch.")

_TABLE: tuple[NodeModel, ...] = (
    # Actions (7)
    _leaf("AlwaysSuccess", "Action", "Returns SUCCESS without doing anything."),
    _leaf("AlwaysFailure", "Action", "Returns FAILURE without doing anything."),
    _leaf(
        "Script",
        "Action",
        "Runs a script (assignments, expressions) on the blackboard, then returns SUCCESS.",
        _in("code", "std::string", None, "The script to run."),
    ),
    _leaf(
        "SetBlackboard",
        "Action",
        "Writes `value` (a literal or a {key}) into the blackboard entry `output_key`.",
        _in("value", "any", None, "Value to store: a literal string or a {key} to copy."),
        _inout("output_key", "any", "Blackboard entry that receives the value."),
    ),
    _leaf(
        "Sleep",
        "Action",
        "Returns RUNNING for `msec` milliseconds, then SUCCESS.",
        _in("msec", "unsigned int", None, "How long to wait, in milliseconds."),
    ),
    _leaf(
        "UnsetBlackboard",
        "Action",
        "Removes the entry `key` from the blackboard and returns SUCCESS.",
        _in("key", "std::string", None, "Name of the entry to remove."),
    ),
    _leaf(
        "WasEntryUpdated",
        "Action",
        "SUCCESS if the blackboard entry changed since the last tick, FAILURE otherwise.",
        _ENTRY_PORT,
    ),
    # Conditions (1)
    _leaf(
        "ScriptCondition",
        "Condition",
        "Evaluates a script: SUCCESS if the result is true, FAILURE otherwise.",
        _in("code", "any", None, "Script whose result is read as a boolean."),
    ),
    # Controls (17)
    _control(
        "Sequence",
        "Ticks children in order until one fails or is running; SUCCESS if all succeed.",
    ),
    _control(
        "Fallback",
        "Ticks children in order until one succeeds or is running; FAILURE if all fail.",
    ),
    _control(
        "SequenceWithMemory",
        "Like Sequence, but after a RUNNING or FAILURE it resumes from the same child "
        "instead of restarting.",
    ),
    _control(
        "AsyncSequence",
        "Like Sequence, but returns RUNNING between children so other nodes get a tick.",
        is_async=True,
    ),
    _control(
        "AsyncFallback",
        "Like Fallback, but returns RUNNING between children so other nodes get a tick.",
        is_async=True,
    ),
    _control(
        "ReactiveSequence",
        "Sequence that re-ticks earlier children on every tick; at most one async child.",
    ),
    _control(
        "ReactiveFallback",
        "Fallback that re-ticks earlier children on every tick.",
    ),
    _control(
        "Parallel",
        "Ticks all children every tick; finishes when `success_count` children succeed "
        "or `failure_count` fail.",
        _in(
            "success_count",
            "int",
            "-1",
            "Children that must succeed for SUCCESS (-1 means all of them).",
        ),
        _in("failure_count", "int", "1", "Children that must fail for FAILURE."),
    ),
    _control(
        "ParallelAll",
        "Ticks all children until every one has finished; FAILURE if more than "
        "`max_failures` failed.",
        _in(
            "max_failures",
            "int",
            "1",
            "FAILURE when more children than this fail (-1 means all of them).",
        ),
    ),
    _control(
        "IfThenElse",
        "Ticks the first child as a condition, then the second (on SUCCESS) or the "
        "optional third (on FAILURE); needs 2 or 3 children.",
        min_children=2,
        max_children=3,
    ),
    _control(
        "WhileDoElse",
        "Reactive if-then-else: the first child is re-checked every tick, then the second "
        "or the optional third child runs; needs 2 or 3 children.",
        min_children=2,
        max_children=3,
    ),
    _control(
        "TryCatch",
        "Runs children 1..N-1 as a sequence; if one fails, runs the last child as a "
        "cleanup and returns FAILURE; needs at least 2 children.",
        _in(
            "catch_on_halt",
            "bool",
            "false",
            "Also run the catch child when the node is halted during the try block.",
        ),
        min_children=2,
    ),
    *(_switch(n) for n in range(2, 7)),
    # Decorators (16)
    _decorator("Inverter", "Turns the child's SUCCESS into FAILURE and vice versa."),
    _decorator("ForceSuccess", "Returns SUCCESS whenever the child finishes."),
    _decorator("ForceFailure", "Returns FAILURE whenever the child finishes."),
    _decorator(
        "KeepRunningUntilFailure",
        "Ticks the child again and again, returning RUNNING, until it fails.",
    ),
    _decorator(
        "Repeat",
        "Ticks the child up to `num_cycles` times while it keeps succeeding.",
        _in(
            "num_cycles",
            "int",
            None,
            "How many successful runs to repeat (-1 repeats forever).",
        ),
    ),
    _decorator(
        "RetryUntilSuccessful",
        "Ticks a failing child again, up to `num_attempts` times.",
        _in(
            "num_attempts",
            "int",
            None,
            "How many attempts before giving up (-1 retries forever).",
        ),
    ),
    _decorator(
        "Timeout",
        "Halts the child and returns FAILURE if it runs longer than `msec` milliseconds.",
        _in("msec", "unsigned int", None, "Time limit for the child, in milliseconds."),
    ),
    _decorator(
        "Delay",
        "Waits `delay_msec` milliseconds (returning RUNNING), then ticks the child.",
        _in("delay_msec", "unsigned int", None, "Wait before the first tick, in milliseconds."),
    ),
    _decorator(
        "RunOnce",
        "Ticks the child only until it first finishes; afterwards skips or repeats that result.",
        _in(
            "then_skip",
            "bool",
            "true",
            "After the first run: true returns SKIPPED, false repeats the first result.",
        ),
    ),
    _decorator(
        "Precondition",
        "Ticks the child only if the script in `if` is true; otherwise returns `else`.",
        _in("if", "std::string", None, "Script that must evaluate to true."),
        _in(
            "else",
            "NodeStatus",
            "FAILURE",
            "Status returned when the condition is false.",
        ),
    ),
    _decorator(
        "SkipUnlessUpdated",
        "Ticks the child only if the blackboard entry changed; otherwise returns SKIPPED.",
        _ENTRY_PORT,
    ),
    _decorator(
        "WaitValueUpdate",
        "Returns RUNNING until the blackboard entry changes, then ticks the child.",
        _ENTRY_PORT,
    ),
    _loop("Int", "int"),
    _loop("Double", "double"),
    _loop("Bool", "bool"),
    _loop("String", "std::string"),
    # SubTree (1)
    NodeModel(
        "SubTree",
        "SubTree",
        (
            _in(
                "_autoremap",
                "bool",
                "false",
                "Expose every parent blackboard entry to the subtree under the same name.",
            ),
        ),
        0,
        0,
        False,
        "Runs the <BehaviorTree> named by ID; the other attributes remap its ports.",
    ),
)

BUILTINS: Final[Mapping[str, NodeModel]] = MappingProxyType({m.id: m for m in _TABLE})
"""Registration ID -> model, for the 42 types of a default 4.x factory."""

V3_RENAMES: Final[Mapping[str, str]] = MappingProxyType(
    {
        "SequenceStar": "SequenceWithMemory",
        "SubTreePlus": "SubTree",
        "RetryUntilSuccesful": "RetryUntilSuccessful",
    }
)
"""Names that fail with "Node not recognized" in a default 4.x build -> the 4.x name."""


def is_builtin(id_: str) -> bool:
    """Whether a default 4.x factory registers ``id_`` (exact, case-sensitive)."""
    return id_ in BUILTINS


# --------------------------------------------------------------------------------------
# Literal conversion (what convertFromString<T> accepts)
# --------------------------------------------------------------------------------------

_BOOL_WORDS: Final = frozenset({"1", "0", "true", "false", "True", "False", "TRUE", "FALSE"})
_NODE_STATUS_WORDS: Final = ("SUCCESS", "FAILURE", "RUNNING", "IDLE", "SKIPPED")

# (minimum, maximum, parsed like an unsigned 64-bit value). The narrower integer types go
# through a signed 64-bit parse plus a bound check, so "-1" is rejected by the bound check;
# the 64-bit unsigned type is parsed directly and rejects a leading "-" outright.
_INT_RANGES: Final[Mapping[str, tuple[int, int, bool]]] = MappingProxyType(
    {
        "int8": (-(2**7), 2**7 - 1, False),
        "uint8": (0, 2**8 - 1, False),
        "int16": (-(2**15), 2**15 - 1, False),
        "uint16": (0, 2**16 - 1, False),
        "int32": (-(2**31), 2**31 - 1, False),
        "uint32": (0, 2**32 - 1, False),
        "int64": (-(2**63), 2**63 - 1, False),
        "uint64": (0, 2**64 - 1, True),
    }
)

_TYPE_ALIASES: Final[Mapping[str, str]] = MappingProxyType(
    {
        "signed char": "int8",
        "int8_t": "int8",
        "unsigned char": "uint8",
        "uint8_t": "uint8",
        "short": "int16",
        "short int": "int16",
        "int16_t": "int16",
        "unsigned short": "uint16",
        "unsigned short int": "uint16",
        "uint16_t": "uint16",
        "int": "int32",
        "signed int": "int32",
        "int32_t": "int32",
        "unsigned": "uint32",
        "unsigned int": "uint32",
        "uint32_t": "uint32",
        "long": "int64",
        "long int": "int64",
        "long long": "int64",
        "long long int": "int64",
        "int64_t": "int64",
        "unsigned long": "uint64",
        "unsigned long int": "uint64",
        "unsigned long long": "uint64",
        "unsigned long long int": "uint64",
        "uint64_t": "uint64",
        "size_t": "uint64",
        "double": "double",
        "float": "float",
        "bool": "bool",
        "NodeStatus": "NodeStatus",
        "std::string": "string",
        "string": "string",
        "std::string_view": "string",
        "BT::StringView": "string",
        "StringView": "string",
        "any": "any",
        "Any": "any",
        "AnyTypeAllowed": "any",
    }
)

_FLOAT_MAX: Final = 3.4028234663852886e38
_FLOAT_MIN_NORMAL: Final = 1.1754943508222875e-38
_DOUBLE_MIN_NORMAL: Final = 2.2250738585072014e-308

# What strtod() reads (C locale), anchored at the start: optional sign, then a decimal
# float, a hexadecimal float, INF/INFINITY or NAN/NAN(chars). Leading white space is
# skipped separately.
_STRTOD_PREFIX: Final = re.compile(
    r"""
    [+-]?
    (?:
        0[xX](?:[0-9a-fA-F]+(?:\.[0-9a-fA-F]*)?|\.[0-9a-fA-F]+)(?:[pP][+-]?[0-9]+)?
      | (?:[0-9]+(?:\.[0-9]*)?|\.[0-9]+)(?:[eE][+-]?[0-9]+)?
      | [iI][nN][fF](?:[iI][nN][iI][tT][yY])?
      | [nN][aA][nN](?:\([0-9A-Za-z_]*\))?
    )
    """,
    re.VERBOSE,
)
_C_SPACE: Final = " \t\n\v\f\r"


def _normalize_type(type_: str) -> str | None:
    t = " ".join(type_.split())
    if t.startswith("BT::"):
        t = t[len("BT::") :]
    if t.startswith("std::") and t[len("std::") :] in _TYPE_ALIASES and t.endswith("_t"):
        t = t[len("std::") :]
    if t.startswith("std::vector<") and t.endswith(">"):
        inner = _normalize_type(t[len("std::vector<") : -1])
        if inner in ("int32", "double", "bool", "string"):
            return f"vector:{inner}"
        return None
    return _TYPE_ALIASES.get(t)


def is_blackboard_reference(value: str) -> bool:
    """Whether BehaviorTree.CPP reads ``value`` as a blackboard key rather than a literal.

    Mirrors ``TreeNode::isBlackboardPointer``: after trimming spaces the text has at least
    three characters and is wrapped in ``{`` ``}``. A bare ``=`` (same key as the port) also
    counts.
    """
    stripped = value.strip(" ")
    if stripped == "=":
        return True
    return len(stripped) >= 3 and stripped[0] == "{" and stripped[-1] == "}"


def _leading_int(value: str, unsigned_parse: bool) -> tuple[int | None, bool]:
    """Like ``std::from_chars`` (base 10): the leading integer and whether all was used."""
    i = 0
    negative = False
    if value.startswith("-") and not unsigned_parse:
        negative = True
        i = 1
    j = i
    while j < len(value) and "0" <= value[j] <= "9":
        j += 1
    if j == i:
        return None, False
    digits = value[i:j].lstrip("0") or "0"
    if len(digits) > 40:  # far outside any 64-bit range; avoids huge int() conversions
        digits = "9" * 40
    number = int(digits)
    return (-number if negative else number), j == len(value)


def _convert_int(value: str, kind: str, strict: bool) -> str | None:
    low, high, unsigned_parse = _INT_RANGES[kind]
    number, complete = _leading_int(value, unsigned_parse)
    if number is None:
        return f"'{value}' is not an integer"
    parse_low, parse_high = (0, 2**64 - 1) if unsigned_parse else (-(2**63), 2**63 - 1)
    if not parse_low <= number <= parse_high:
        return f"'{value}' is out of range for a 64-bit integer"
    if not low <= number <= high:
        return f"{number} is out of range [{low}, {high}]"
    if strict and not complete:
        return f"'{value}' has extra characters after the integer {number}"
    return None


def _convert_real(value: str, is_float: bool, strict: bool) -> str | None:
    text = value.lstrip(_C_SPACE)
    match = _STRTOD_PREFIX.match(text)
    if match is None:
        return f"'{value}' is not a number"
    token = match.group(0)
    lowered = token.lower().lstrip("+-")
    if not lowered.startswith(("inf", "nan")):
        try:
            number = float.fromhex(token) if lowered.startswith("0x") else float(token)
        except (ValueError, OverflowError):
            number = math.inf
        magnitude = abs(number)
        largest = _FLOAT_MAX if is_float else math.inf
        smallest = _FLOAT_MIN_NORMAL if is_float else _DOUBLE_MIN_NORMAL
        if math.isinf(number) or magnitude > largest or 0 < magnitude < smallest:
            return f"'{value}' is out of range for {'float' if is_float else 'double'}"
        if magnitude == 0 and _has_nonzero_digit(token):
            return f"'{value}' is out of range for {'float' if is_float else 'double'}"
    if strict and len(token) != len(text):
        return f"'{value}' has extra characters after the number {token}"
    return None


def _has_nonzero_digit(token: str) -> bool:
    mantissa = re.split(r"[eEpP]", token.lower().lstrip("+-"), maxsplit=1)[0]
    mantissa = mantissa.removeprefix("0x")
    return any(c not in "0." for c in mantissa)


def _convert_scalar(value: str, kind: str, strict: bool) -> str | None:
    if kind in _INT_RANGES:
        return _convert_int(value, kind, strict)
    if kind == "double":
        return _convert_real(value, False, strict)
    if kind == "float":
        return _convert_real(value, True, strict)
    if kind == "bool":
        if value in _BOOL_WORDS:
            return None
        return f"'{value}' is not a bool (use true/false, True/False, TRUE/FALSE, 1 or 0)"
    if kind == "NodeStatus":
        if value in _NODE_STATUS_WORDS:
            return None
        return f"'{value}' is not a NodeStatus (use one of {', '.join(_NODE_STATUS_WORDS)})"
    return None


def convert_literal(value: str, type: str, *, strict: bool = False) -> str | None:
    """Why a literal port value can't be converted to ``type``, or ``None`` if it can.

    Follows BehaviorTree.CPP's ``convertFromString<T>()``:

    * integers (``int``, ``unsigned int``, ``long``, ``int8_t`` ...): base 10 only, an
      optional ``-`` (no ``+``, no leading space, no ``0x``), then the type's range. Like
      ``std::from_chars``, only a leading integer has to be present: ``"12abc"`` and
      ``"1.5"`` are accepted (as 12 and 1) unless ``strict`` is true;
    * ``double`` / ``float``: what ``strtod`` reads after leading white space (decimal or
      hexadecimal float, ``inf``, ``nan``); overflow and underflow are errors; trailing
      text is accepted unless ``strict``;
    * ``bool``: exactly ``true false True False TRUE FALSE 1 0``;
    * ``NodeStatus``: exactly ``SUCCESS FAILURE RUNNING IDLE SKIPPED``;
    * ``std::vector<int|double|bool|std::string>``: each ``;``-separated item as above;
    * ``std::string``, ``any`` and every type not listed: always fine.

    Values that are blackboard references (``{key}``, ``{=}``, ``=``) and ``json:`` values
    are not literals and give ``None``.
    """
    if is_blackboard_reference(value) or value.startswith("json:"):
        return None
    kind = _normalize_type(type)
    if kind is None or kind in ("string", "any"):
        return None
    if kind.startswith("vector:"):
        item_kind = kind.removeprefix("vector:")
        for item in _split_items(value):
            problem = _convert_scalar(item, item_kind, strict)
            if problem is not None:
                return f"item {problem}"
        return None
    return _convert_scalar(value, kind, strict)


def _split_items(value: str) -> list[str]:
    """``splitString(value, ';')``: no item for an empty tail, so "1;2;" has two items."""
    items: list[str] = []
    pos = 0
    while pos < len(value):
        end = value.find(";", pos)
        if end < 0:
            end = len(value)
        items.append(value[pos:end])
        pos = end + 1
    return items
