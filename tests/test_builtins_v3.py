"""A project built against BehaviorTree.CPP 3.8 (``Context.btcpp_version == "3"``): its
built-in nodes and ports, its SubTree attributes, and no version 4 advice."""

from __future__ import annotations

import pytest

from bt_lsp.rules import semantics
from bt_lsp.rules.builtins import BUILTINS
from bt_lsp.rules.builtins_v3 import V3_BUILTINS
from bt_lsp.rules.codes import Severity
from bt_lsp.rules.context import Context
from bt_lsp.syntax.document import Document

E, W, H = Severity.ERROR, Severity.WARNING, Severity.HINT
SUB = '<BehaviorTree ID="Sub"><AlwaysSuccess/></BehaviorTree>'


def doc(body: str, fmt: str = "") -> Document:
    root = (
        f'<root {fmt} main_tree_to_execute="Main">' if fmt else '<root main_tree_to_execute="Main">'
    )
    return Document(f'{root}<BehaviorTree ID="Main">{body}</BehaviorTree>{SUB}</root>', "/w/t.xml")


def codes(body: str, version: str | None) -> list[tuple[str, Severity]]:
    d = doc(body, "" if version == "3" else 'BTCPP_format="4"')
    ctx = Context.combine(d, [], path="/w/t.xml", btcpp_version=version)
    return [(x.code, x.severity) for x in semantics.check(d, ctx)]


def test_the_v3_table() -> None:
    assert {"SequenceStar", "SubTreePlus", "BlackboardCheckInt", "Switch6"} <= set(V3_BUILTINS)
    for v4_only in ("Script", "ScriptCondition", "Sleep", "Precondition", "RunOnce", "TryCatch"):
        assert v4_only in BUILTINS and v4_only not in V3_BUILTINS
    assert V3_BUILTINS["Parallel"].port("success_threshold") is not None


@pytest.mark.parametrize(
    ("body", "v3", "v4"),
    [
        (
            "<SequenceStar><AlwaysSuccess/></SequenceStar>",
            [],
            [("unknown-node", E)],
        ),
        (
            '<Parallel success_threshold="1" failure_threshold="1"><AlwaysSuccess/></Parallel>',
            [],
            [("undeclared-port", E), ("undeclared-port", E)],
        ),
        (
            '<SubTree ID="Sub" __shared_blackboard="true"/>',
            [],
            [("unknown-attribute", W)],
        ),
        (
            '<SubTreePlus ID="Sub" __autoremap="1" goal="{g}"/>',
            [],
            [("unknown-node", E), ("unknown-attribute", W)],
        ),
        (
            '<BlackboardCheckInt value_A="{a}" value_B="1"><AlwaysSuccess/></BlackboardCheckInt>',
            [],
            [("unknown-node", H)],
        ),
        ('<Script code="x := 1"/>', [("unknown-node", W)], []),
    ],
)
def test_v3_and_v4_read_the_same_tree_differently(
    body: str, v3: list[tuple[str, Severity]], v4: list[tuple[str, Severity]]
) -> None:
    assert codes(body, "3") == v3
    assert codes(body, "4") == v4


def test_a_v3_subtree_plus_calls_a_tree() -> None:
    assert codes('<SubTreePlus ID="Nowhere"/>', "3") == [("unknown-subtree", E)]
    # A version 4 check: a warning for a version 3 project.
    assert codes('<SubTree ID="Sub" __shared_blackboard="maybe"/>', "3") == [
        ("invalid-port-value", W)
    ]
