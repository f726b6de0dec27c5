"""The node types a default ``BT::BehaviorTreeFactory`` of BehaviorTree.CPP 3.8 registers
(``behaviortree_cpp_v3``, what ROS 2 Humble builds against).

The factory constructor of 3.8 registers: Fallback, Sequence, SequenceStar, Parallel,
ReactiveSequence, ReactiveFallback, IfThenElse, WhileDoElse; Inverter,
RetryUntilSuccessful, KeepRunningUntilFailure, Repeat, Timeout, Delay, ForceSuccess,
ForceFailure; AlwaysSuccess, AlwaysFailure, SetBlackboard; SubTree, SubTreePlus;
BlackboardCheckInt/Double/String/Bool; Switch2 to Switch6.  Version 4's Script,
ScriptCondition, Sleep, Precondition, RunOnce, TryCatch, the Loop and entry-update nodes,
SequenceWithMemory, the async controls and ParallelAll do not exist in 3.8.

The types both versions share keep version 4's model (same ports); the others are here:
``Parallel`` reads ``success_threshold``/``failure_threshold``, ``SubTree`` takes
``__shared_blackboard`` and ``SubTreePlus`` ``__autoremap`` (both remap every other
attribute), and the ``BlackboardCheck*`` decorators compare ``value_A`` with ``value_B``.
"""

from __future__ import annotations

from collections.abc import Mapping
from types import MappingProxyType
from typing import Final

from bt_lsp.rules.builtins import BUILTINS, NodeModel, PortModel

_SHARED: Final = (
    "AlwaysSuccess",
    "AlwaysFailure",
    "SetBlackboard",
    "Sequence",
    "Fallback",
    "ReactiveSequence",
    "ReactiveFallback",
    "IfThenElse",
    "WhileDoElse",
    "Inverter",
    "ForceSuccess",
    "ForceFailure",
    "KeepRunningUntilFailure",
    "Repeat",
    "RetryUntilSuccessful",
    "Timeout",
    "Delay",
    *(f"Switch{n}" for n in range(2, 7)),
)


def _check(suffix: str, type_: str) -> NodeModel:
    return NodeModel(
        f"BlackboardCheck{suffix}",
        "Decorator",
        (
            PortModel("value_A", "input", "", None, f"First {type_} to compare."),
            PortModel("value_B", "input", "", None, f"Second {type_} to compare."),
            PortModel(
                "return_on_mismatch",
                "input",
                "NodeStatus",
                None,
                "Status returned when the values differ (FAILURE when not given).",
            ),
        ),
        1,
        1,
        False,
        f"Ticks the child when value_A equals value_B (as {type_}); otherwise returns "
        "return_on_mismatch.",
    )


_OWN: Final = (
    NodeModel(
        "SequenceStar",
        "Control",
        (),
        1,
        None,
        False,
        "Like Sequence, but after a RUNNING or FAILURE it resumes from the same child "
        "(version 4 calls it SequenceWithMemory).",
    ),
    NodeModel(
        "Parallel",
        "Control",
        (
            PortModel(
                "success_threshold",
                "input",
                "int",
                None,
                "Children that must succeed for SUCCESS (negative counts from the end).",
            ),
            PortModel("failure_threshold", "input", "int", "1", "Children that must fail."),
        ),
        1,
        None,
        False,
        "Ticks all children every tick; finishes when success_threshold children succeed "
        "or failure_threshold fail.",
    ),
    NodeModel(
        "SubTree",
        "SubTree",
        (
            PortModel(
                "__shared_blackboard",
                "input",
                "bool",
                "false",
                "Share the parent's blackboard with the subtree instead of remapping ports.",
            ),
        ),
        0,
        0,
        False,
        "Runs the <BehaviorTree> named by ID; the other attributes remap its ports.",
    ),
    NodeModel(
        "SubTreePlus",
        "SubTree",
        (
            PortModel(
                "__autoremap",
                "input",
                "bool",
                "false",
                "Expose every parent blackboard entry to the subtree under the same name.",
            ),
        ),
        0,
        0,
        False,
        "Runs the <BehaviorTree> named by ID; the other attributes remap its ports or set "
        "literal values.",
    ),
    _check("Int", "int"),
    _check("Double", "double"),
    _check("String", "std::string"),
    _check("Bool", "bool"),
)

V3_BUILTINS: Final[Mapping[str, NodeModel]] = MappingProxyType(
    {**{k: BUILTINS[k] for k in _SHARED}, **{m.id: m for m in _OWN}}
)
"""Registration ID -> model, for the types of a default 3.8 factory."""

#: Ports of 3.8 built-ins that the node reads without failing when they are not given.
V3_OPTIONAL_PORTS: Final[frozenset[tuple[str, str]]] = frozenset(
    (f"BlackboardCheck{s}", p)
    for s in ("Int", "Double", "String", "Bool")
    for p in ("value_A", "value_B", "return_on_mismatch")
)

#: Version 3 call nodes: elements that call a tree by ``ID``.
V3_SUBTREE_TAGS: Final = frozenset({"SubTree", "SubTreePlus"})
