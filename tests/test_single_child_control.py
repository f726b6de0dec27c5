"""``single-child-control``: a pass-through control with one child, and its unwrap fix."""

from __future__ import annotations

from bt_lsp.ide.fix_all import fix_document
from bt_lsp.rules import semantics
from bt_lsp.rules.analysis import analyze
from bt_lsp.rules.context import Context
from bt_lsp.syntax.document import Document
from tests.annotated import check_fix, fixes
from tests.pinned import pinned
from tests.rulecheck import check, marks

HEAD = '<root BTCPP_format="4">\n<BehaviorTree ID="T">\n<Sequence>\n'
TAIL = "<AlwaysSuccess/>\n</Sequence>\n</BehaviorTree>\n</root>\n"
CODE = "single-child-control"


def test_each_pass_through_control_with_one_child() -> None:
    text = (
        HEAD
        + "<⟦Fallback⟧><AlwaysSuccess/></Fallback>"
        + "<⟦AsyncSequence⟧><AlwaysSuccess/></AsyncSequence>"
        + "<⟦ReactiveFallback⟧><AlwaysSuccess/></ReactiveFallback>"
        + '<Control ID="Sequence"><AlwaysSuccess/></Control>'.replace("Control", "⟦Control⟧", 1)
        + TAIL
    )
    assert check(text, only=CODE) == marks(text, CODE)


def test_not_with_two_children_a_condition_or_another_kind_of_node() -> None:
    text = (
        HEAD
        + "<Fallback><AlwaysSuccess/><AlwaysFailure/></Fallback>"
        + '<Sequence _while="go"><AlwaysSuccess/></Sequence>'
        + '<Fallback _onSuccess="done := true"><AlwaysSuccess/></Fallback>'
        + "<Parallel><AlwaysSuccess/></Parallel>"
        + "<Inverter><AlwaysSuccess/></Inverter>"
        + "<TryCatch><AlwaysSuccess/><AlwaysSuccess/></TryCatch>"
        + TAIL
    )
    assert check(text, only=CODE) == []


def test_not_while_the_control_is_being_typed() -> None:
    typed = '<root BTCPP_format="4"><BehaviorTree ID="A"><⟦Sequence⟧><AlwaysSuccess/>'
    assert check(typed + "</Sequence></BehaviorTree></root>", only=CODE) == marks(typed, CODE)
    # No end tag yet: the parser closes the control at the tree's end tag.
    assert check(typed + "</BehaviorTree></root>", only=CODE) == []


def test_version_3_sequence_star() -> None:
    text = (
        '<root><BehaviorTree ID="T">'
        "<SequenceStar><AlwaysSuccess/></SequenceStar></BehaviorTree></root>"
    )
    d = Document(text, "/w/t.xml")
    ctx = Context.combine(d, [], path="/w/t.xml", btcpp_version="3")
    at = text.index("SequenceStar")
    found = [(x.start, x.end) for x in semantics.check(d, ctx) if x.code == CODE]
    assert found == [(at, at + len("SequenceStar"))]


def test_unwrap_moves_the_child_left() -> None:
    before = (
        '<root BTCPP_format="4">\n'
        '  <BehaviorTree ID="T">\n'
        "    <Sequence>\n"
        "      <Fallback>\n"
        "        <AlwaysSuccess/>\n"
        "      </Fallback>\n"
        "    </Sequence>\n"
        "  </BehaviorTree>\n"
        "</root>\n"
    )
    after = (
        '<root BTCPP_format="4">\n'
        '  <BehaviorTree ID="T">\n'
        "    <Fallback>\n"
        "      <AlwaysSuccess/>\n"
        "    </Fallback>\n"
        "  </BehaviorTree>\n"
        "</root>\n"
    )
    # Both controls have one child: the outer one's fix comes first.
    check_fix(before, after, "Replace <Sequence> with its child", CODE)


def test_no_unwrap_that_would_lose_a_comment() -> None:
    def offered(inside: str) -> list[str]:
        text = (
            '<root BTCPP_format="4"><BehaviorTree ID="T">'
            f"<Sequence>{inside}</Sequence></BehaviorTree></root>"
        )
        assert check(text, only=CODE), "the control is reported either way"
        return [f.title for f in fixes(Document(text), [CODE])]

    assert offered("<AlwaysSuccess/>") == ["Replace <Sequence> with its child"]
    assert offered("<!-- later: Dock --><AlwaysSuccess/>") == []


def test_unwrap_is_never_applied_in_bulk() -> None:
    doc = Document(
        '<root BTCPP_format="4"><BehaviorTree ID="T">'
        "<Sequence><AlwaysSuccess/></Sequence></BehaviorTree></root>"
    )
    ctx = Context.from_document(doc)
    diags = pinned(analyze(doc, ctx), also=[CODE])
    assert [d.code for d in diags] == [CODE]
    assert fix_document(doc, ctx, diags, unsafe=True).edits == []
