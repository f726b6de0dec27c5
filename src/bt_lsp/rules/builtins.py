"""The node types a default ``BT::BehaviorTreeFactory`` (BehaviorTree.CPP 4.x) registers.

Pure data: no LSP imports and no I/O. The table mirrors the factory
constructor of BehaviorTree.CPP 4.10 (42 types) with the ports each type declares in
``providedPorts()``; see ``tests/data/spec/bt-xml.md`` section (d).

* :data:`BUILTINS` maps a registration ID to its :class:`NodeModel`.
* :data:`V3_RENAMES` maps names from BehaviorTree.CPP 3.x (and one well-known typo) to
  their 4.x spelling, for "did you mean" hints. None of the keys is registered in 4.x.
"""

from __future__ import annotations

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
    ``resolved`` is the type with the aliases of the project's C++ followed and its
    classes qualified (``None`` when not read from C++); ``classes`` the class
    definitions read that it names (see :mod:`bt_lsp.cpp.types`).
    """

    name: str
    direction: Direction
    type: str
    default: str | None
    description: str
    resolved: str | None = None
    classes: frozenset[str] = frozenset()

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
