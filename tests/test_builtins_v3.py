"""A project built against BehaviorTree.CPP 3.8 (``Context.btcpp_version == "3"``): its
built-in nodes and ports, its SubTree attributes, and no version 4 advice."""

from __future__ import annotations

import pytest

from bt_lsp.ide.catalog import BUILTIN_CATALOG_V3, builtin_catalog
from bt_lsp.ide.completion import complete
from bt_lsp.ide.definition import definition
from bt_lsp.ide.hover import hover_at
from bt_lsp.ide.rename import RenameRefused, rename
from bt_lsp.rules import semantics
from bt_lsp.rules.analysis import analyze
from bt_lsp.rules.builtins import BUILTINS
from bt_lsp.rules.builtins_v3 import V3_BUILTINS
from bt_lsp.rules.codes import Severity
from bt_lsp.rules.context import Context
from bt_lsp.syntax.document import Document
from tests.pinned import pinned

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
    return [(x.code, x.severity) for x in pinned(semantics.check(d, ctx))]


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


def test_the_v3_ports_are_3_8s() -> None:
    """The 3.8 ports, as its providedPorts() declare them (not version 4's table)."""
    ports = {
        nid: [(p.name, p.direction, p.type, p.default) for p in m.ports]
        for nid, m in V3_BUILTINS.items()
    }
    assert ports["RetryUntilSuccessful"] == [("num_attempts", "input", "int", None)]
    assert ports["Repeat"] == [("num_cycles", "input", "int", None)]
    assert ports["Timeout"] == [("msec", "input", "unsigned int", None)]
    assert ports["Delay"] == [("delay_msec", "input", "unsigned int", None)]
    assert ports["SetBlackboard"] == [
        ("value", "input", "", None),
        ("output_key", "inout", "", None),
    ]
    assert ports["Parallel"] == [
        ("success_threshold", "input", "int", None),
        ("failure_threshold", "input", "int", "1"),
    ]
    assert ports["BlackboardCheckDouble"] == [
        ("value_A", "input", "", None),
        ("value_B", "input", "", None),
        ("return_on_mismatch", "input", "NodeStatus", None),
    ]
    assert [p[0] for p in ports["Switch3"]] == ["variable", "case_1", "case_2", "case_3"]
    assert "RetryUntilSuccesful" not in V3_BUILTINS  # 3.8 comments that registration out
    assert len(V3_BUILTINS) == 30
    # Nothing of the table is version 4's object.
    assert all(m is not BUILTINS.get(k) for k, m in V3_BUILTINS.items())


V3_DOC = (
    '<root main_tree_to_execute="Main">\n'
    '  <BehaviorTree ID="Main">\n'
    "    <SequenceStar>\n"
    '      <Parallel success_threshold="1"><AlwaysSuccess/></Parallel>\n'
    "      \n"
    "    </SequenceStar>\n"
    "  </BehaviorTree>\n"
    "</root>\n"
)


def v3_context(d: Document, version: str | None = "3") -> Context:
    return Context.combine(d, [], path="/w/t.xml", btcpp_version=version)


def test_completion_in_a_v3_document_offers_3_8s_nodes() -> None:
    d = Document(V3_DOC, "/w/t.xml")
    at = V3_DOC.index("      \n") + 6
    found = complete(d, at, v3_context(d))
    assert found is not None
    labels = {i.label for i in found.items}
    assert {"SequenceStar", "BlackboardCheckInt", "RetryUntilSuccessful"} <= labels
    assert not labels & {"Script", "Sleep", "SequenceWithMemory", "Precondition", "RunOnce"}
    setbb = next(i for i in found.items if i.label == "SetBlackboard")
    assert "Stores the string" in setbb.documentation
    # The same place in a version 4 project offers version 4's.
    found = complete(d, at, v3_context(d, "4"))
    assert found is not None
    labels = {i.label for i in found.items}
    assert "Script" in labels and "SequenceStar" not in labels


def test_hover_on_a_v3_builtin_shows_its_3_8_ports() -> None:
    d = Document(V3_DOC, "/w/t.xml")
    found = hover_at(d, V3_DOC.index("Parallel") + 2, v3_context(d))
    assert found is not None
    assert "Built-in Control of BehaviorTree.CPP 3.8" in found.text
    assert "success_threshold" in found.text and "failure_threshold" in found.text
    assert "success_count" not in found.text
    found = hover_at(d, V3_DOC.index("SequenceStar") + 2, v3_context(d))
    assert found is not None and "SequenceWithMemory" in found.text  # its description
    found = hover_at(d, V3_DOC.index("success_threshold") + 2, v3_context(d))
    assert found is not None and "input port, type `int`, no default" in found.text


def test_a_v3_project_may_declare_a_node_named_like_a_4_x_builtin() -> None:
    """A Humble application registering its own ``Sleep`` (3.8 has none): its model is
    the one the rules and completion see."""
    text = V3_DOC.replace("      \n", '      <Sleep seconds="1"/>\n').replace(
        "</root>",
        '<TreeNodesModel><Action ID="Sleep"><input_port name="seconds"/></Action>'
        "</TreeNodesModel></root>",
    )
    d = Document(text, "/w/t.xml")
    ctx = v3_context(d)
    assert ctx.models["Sleep"].port("seconds") is not None
    assert [x.code for x in pinned(semantics.check(d, ctx))] == []


@pytest.mark.parametrize("fmt", ["", 'BTCPP_format="3"', 'BTCPP_format="4"'])
def test_what_3_8_fails_on_is_an_error_in_a_v3_project(fmt: str) -> None:
    def found(body: str) -> list[tuple[str, Severity]]:
        d = doc(body, fmt)
        ctx = Context.combine(d, [], path="/w/t.xml", btcpp_version="3")
        return [(x.code, x.severity) for x in pinned(semantics.check(d, ctx))]

    # 3.8's XMLParser throws for an attribute that is not a port ("Possible typo?").
    assert found('<Delay delay_msec="1" dleay="2"><AlwaysSuccess/></Delay>') == [
        ("undeclared-port", E)
    ]
    # DelayNode throws "Missing parameter [delay_msec]" when it is ticked.
    assert found("<Delay><AlwaysSuccess/></Delay>") == [("missing-required-port", E)]
    # A Switch without its variable ticks its default child: likely wrong, not a failure.
    assert found("<Switch2><AlwaysSuccess/><AlwaysSuccess/><AlwaysSuccess/></Switch2>") == [
        ("missing-required-port", W)
    ]
    # Literals are converted when the node reads them, not at creation: a warning.
    assert found('<Delay delay_msec="soon"><AlwaysSuccess/></Delay>') == [("invalid-port-value", W)]


def test_definition_in_a_v3_document_leads_to_the_3_8_catalog() -> None:
    d = Document(V3_DOC, "/w/t.xml")
    cat = builtin_catalog("3")
    assert pinned(analyze(Document(cat.text))) == []
    assert "BehaviorTree.CPP 3.8" in cat.text and 'ID="Script"' not in cat.text
    (place,) = definition(d, V3_DOC.index("SequenceStar") + 3, ctx=v3_context(d))
    assert place.path == BUILTIN_CATALOG_V3
    assert cat.text[place.start : place.end] == "SequenceStar"
    (place,) = definition(d, V3_DOC.index("success_threshold") + 3, ctx=v3_context(d))
    assert place.path == BUILTIN_CATALOG_V3
    assert cat.text[place.start : place.end] == "success_threshold"
    # Version 4 has neither.
    assert definition(d, V3_DOC.index("SequenceStar") + 3, ctx=v3_context(d, "4")) == []


def _rename(body: str, at: str, new: str, version: str | None) -> str:
    """The refusal of renaming the name at ``at`` in a document of ``version``, or ``ok``."""
    d = doc(body)
    try:
        plan = rename(d, d.text.index(at) + 1, new, version=version)
    except RenameRefused as e:
        return e.message
    assert plan is not None
    return "ok"


def test_rename_keeps_the_built_ins_of_the_projects_version() -> None:
    star = "<SequenceStar><AlwaysSuccess/></SequenceStar>"
    # 3.8 registers SequenceStar; 4.x does not, so there it is the project's own node.
    assert "built-in node type" in _rename(star, "SequenceStar", "Seq", "3")
    assert _rename(star, "SequenceStar", "Seq", "4") == "ok"
    # Sleep is 4.x's built-in only: a v3 project's Sleep is its own.
    sleep = '<Sleep msec="5"/>'
    assert "built-in node type" in _rename(sleep, "Sleep", "Nap", "4")
    assert _rename(sleep, "Sleep", "Nap", "3") == "ok"
    # A 3.8 built-in's port is 3.8's to name.
    check = '<BlackboardCheckInt value_A="1" value_B="1"><AlwaysSuccess/></BlackboardCheckInt>'
    assert "port of the built-in node" in _rename(check, "value_A", "a", "3")
    # A new name may not be one of the version's built-ins.
    mine = "<MyNode/>"
    assert "built-in node type" in _rename(mine, "MyNode", "SequenceStar", "3")
    assert _rename(mine, "MyNode", "SequenceStar", "4") == "ok"
    assert _rename(mine, "MyNode", "Sleep", "3") == "ok"
