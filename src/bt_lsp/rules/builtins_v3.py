"""The node types a default ``BT::BehaviorTreeFactory`` of BehaviorTree.CPP 3.8 registers
(``behaviortree_cpp_v3``, what ROS 2 Humble builds against), with 3.8's own ports.

The factory constructor of 3.8 (``src/bt_factory.cpp``) registers: Fallback, Sequence,
SequenceStar, Parallel, ReactiveSequence, ReactiveFallback, IfThenElse, WhileDoElse;
Inverter, RetryUntilSuccessful (the ``RetryUntilSuccesful`` typo's registration is
commented out), KeepRunningUntilFailure, Repeat, Timeout, Delay, ForceSuccess,
ForceFailure; AlwaysSuccess, AlwaysFailure, SetBlackboard; SubTree, SubTreePlus;
BlackboardCheckInt/Double/String/Bool; Switch2 to Switch6 (and ManualSelector only when
built with ncurses: left out, like version 4's).  Version 4's Script, ScriptCondition,
Sleep, Precondition, RunOnce, TryCatch, UnsetBlackboard, the Loop and entry-update nodes,
SequenceWithMemory, the async controls and ParallelAll do not exist in 3.8.

Each model is 3.8's ``providedPorts()`` (``include/behaviortree_cpp_v3/...``):
``RetryUntilSuccessful`` ``num_attempts`` (int), ``Repeat`` ``num_cycles`` (int),
``Timeout`` ``msec`` and ``Delay`` ``delay_msec`` (unsigned), ``Parallel``
``success_threshold`` (int, no default) and ``failure_threshold`` (int, default 1),
``SetBlackboard`` ``value`` (input) and ``output_key`` (bidirectional), the
``BlackboardCheck*`` decorators ``value_A``, ``value_B`` and ``return_on_mismatch``,
``SwitchN`` ``variable`` and ``case_1`` .. ``case_N`` (strings).  ``SubTree`` and
``SubTreePlus`` declare no ports; their parser reads ``__shared_blackboard`` and
``__autoremap`` (a bool each) and takes every other attribute as a remapping.
"""

from __future__ import annotations

from collections.abc import Mapping
from types import MappingProxyType
from typing import Final

from bt_lsp.rules.builtins import BUILTINS, Category, NodeModel, PortModel


def _in(name: str, type_: str, default: str | None, description: str) -> PortModel:
    return PortModel(name, "input", type_, default, description)


def _node(
    id_: str,
    category: Category,
    description: str,
    *ports: PortModel,
    children: tuple[int, int | None] | None = None,
) -> NodeModel:
    """A 3.8 built-in; children as the category takes them unless ``children`` says."""
    if children is None:
        children = {"Control": (1, None), "Decorator": (1, 1)}.get(category, (0, 0))
    return NodeModel(id_, category, ports, children[0], children[1], False, description)


def _check(suffix: str, type_: str) -> NodeModel:
    return _node(
        f"BlackboardCheck{suffix}",
        "Decorator",
        f"Ticks the child only when value_A equals value_B (both read as {type_}); "
        "otherwise halts it and returns return_on_mismatch.",
        _in("value_A", "", None, f"First value to compare, as {type_}."),
        _in("value_B", "", None, f"Second value to compare, as {type_}."),
        _in(
            "return_on_mismatch",
            "NodeStatus",
            None,
            "Status returned when the values differ (FAILURE when not given).",
        ),
    )


def _switch(cases: int) -> NodeModel:
    ports = [_in("variable", "std::string", None, "Value compared with every case_N port.")]
    ports += [
        _in(f"case_{i}", "std::string", None, f"Value that selects child {i}.")
        for i in range(1, cases + 1)
    ]
    return _node(
        f"Switch{cases}",
        "Control",
        f"Ticks the child whose case_N equals `variable`, or the last (default) child; "
        f"needs exactly {cases + 1} children ({cases} cases + default).",
        *ports,
        children=(cases + 1, cases + 1),
    )


_TABLE: Final = (
    # Actions
    _node("AlwaysSuccess", "Action", "Returns SUCCESS without doing anything."),
    _node("AlwaysFailure", "Action", "Returns FAILURE without doing anything."),
    _node(
        "SetBlackboard",
        "Action",
        "Stores the string `value` into the blackboard entry `output_key`.",
        _in("value", "", None, "Value represented as a string (read through convertFromString)."),
        PortModel(
            "output_key",
            "inout",
            "",
            None,
            "Name of the blackboard entry where the value is written.",
        ),
    ),
    # Controls
    _node(
        "Sequence",
        "Control",
        "Ticks children in order until one fails or is running; SUCCESS if all succeed.",
    ),
    _node(
        "Fallback",
        "Control",
        "Ticks children in order until one succeeds or is running; FAILURE if all fail.",
    ),
    _node(
        "SequenceStar",
        "Control",
        "Like Sequence, but after a RUNNING or FAILURE it resumes from the same child "
        "(version 4 calls it SequenceWithMemory).",
    ),
    _node(
        "ReactiveSequence",
        "Control",
        "Sequence that re-ticks earlier children on every tick.",
    ),
    _node("ReactiveFallback", "Control", "Fallback that re-ticks earlier children on every tick."),
    _node(
        "Parallel",
        "Control",
        "Ticks all children every tick; finishes when success_threshold children succeed "
        "or failure_threshold fail.",
        _in(
            "success_threshold",
            "int",
            None,
            "Children that must succeed for SUCCESS (negative counts from the end).",
        ),
        _in("failure_threshold", "int", "1", "Children that must fail for FAILURE."),
    ),
    _node(
        "IfThenElse",
        "Control",
        "Ticks the first child as a condition, then the second (on SUCCESS) or the "
        "optional third (on FAILURE); needs 2 or 3 children.",
        children=(2, 3),
    ),
    _node(
        "WhileDoElse",
        "Control",
        "Reactive if-then-else: the first child is re-checked every tick, then the second "
        "or the optional third child runs; needs 2 or 3 children.",
        children=(2, 3),
    ),
    *(_switch(n) for n in range(2, 7)),
    # Decorators
    _node("Inverter", "Decorator", "Turns the child's SUCCESS into FAILURE and vice versa."),
    _node("ForceSuccess", "Decorator", "Returns SUCCESS whenever the child finishes."),
    _node("ForceFailure", "Decorator", "Returns FAILURE whenever the child finishes."),
    _node(
        "KeepRunningUntilFailure",
        "Decorator",
        "Ticks the child again and again, returning RUNNING, until it fails.",
    ),
    _node(
        "Repeat",
        "Decorator",
        "Ticks a successful child again, up to num_cycles times.",
        _in("num_cycles", "int", None, "Repeat a successful child up to N times (-1: forever)."),
    ),
    _node(
        "RetryUntilSuccessful",
        "Decorator",
        "Ticks a failing child again, up to num_attempts times.",
        _in("num_attempts", "int", None, "Tick a failing child up to N times (-1: forever)."),
    ),
    _node(
        "Timeout",
        "Decorator",
        "Halts the child and returns FAILURE if it is still running after msec milliseconds.",
        _in("msec", "unsigned int", None, "Time limit for the child, in milliseconds."),
    ),
    _node(
        "Delay",
        "Decorator",
        "Waits delay_msec milliseconds (returning RUNNING), then ticks the child.",
        _in("delay_msec", "unsigned int", None, "Wait before ticking the child, in milliseconds."),
    ),
    _check("Int", "int"),
    _check("Double", "double"),
    _check("String", "std::string"),
    _check("Bool", "bool"),
    # SubTrees
    _node(
        "SubTree",
        "SubTree",
        "Runs the <BehaviorTree> named by ID with a blackboard of its own; the other "
        "attributes remap its ports.",
        _in(
            "__shared_blackboard",
            "bool",
            "false",
            "Share the parent's blackboard with the subtree instead of remapping ports.",
        ),
    ),
    _node(
        "SubTreePlus",
        "SubTree",
        "Runs the <BehaviorTree> named by ID; the other attributes remap its ports "
        "({key}) or set them to a literal value.",
        _in(
            "__autoremap",
            "bool",
            "false",
            "Remap every port of the subtree to the parent's entry of the same name.",
        ),
    ),
)

V3_BUILTINS: Final[Mapping[str, NodeModel]] = MappingProxyType({m.id: m for m in _TABLE})
"""Registration ID -> model, for the types of a default 3.8 factory."""


def builtins_for(version: str | None) -> Mapping[str, NodeModel]:
    """The built-in nodes of a project's BehaviorTree.CPP major version (``"3"``: 3.8's;
    anything else: 4.x's)."""
    return V3_BUILTINS if version == "3" else BUILTINS


#: Ports of 3.8 built-ins that the node reads without failing when they are not given.
V3_OPTIONAL_PORTS: Final[frozenset[tuple[str, str]]] = frozenset(
    (f"BlackboardCheck{s}", p)
    for s in ("Int", "Double", "String", "Bool")
    for p in ("value_A", "value_B", "return_on_mismatch")
)

#: Version 3 call nodes: elements that call a tree by ``ID``.
V3_SUBTREE_TAGS: Final = frozenset({"SubTree", "SubTreePlus"})
