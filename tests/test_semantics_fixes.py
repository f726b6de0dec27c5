"""Quick fixes of the semantic diagnostics: applied, then the document is analyzed again."""

from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st
from lxml import etree

from bt_lsp.ide import semantic_fixes
from bt_lsp.ide.name_fixes import Fix
from bt_lsp.rules import semantics
from bt_lsp.rules.analysis import analyze
from bt_lsp.rules.context import Context
from bt_lsp.rules.diagnostics import Diagnostic
from bt_lsp.rules.semantics.nodes import UnknownNodeData
from bt_lsp.syntax.document import Document
from bt_lsp.syntax.edits import TextEdit, apply_edits
from bt_lsp.syntax.values import decode_value, raw_offsets, raw_span
from tests.marks import unmark
from tests.test_semantics import CASES, R, T


def fixes(doc: Document, code: str, ctx: Context | None = None) -> tuple[Diagnostic, list[Fix]]:
    ctx = ctx if ctx is not None else Context.from_document(doc)
    diags = [d for d in analyze(doc, ctx) if d.code == code]
    assert diags, f"no {code}"
    return diags[0], semantic_fixes.fixes_for_rule(doc, ctx, diags[0])


def applied(doc: Document, fix: Fix) -> Document:
    return Document(apply_edits(doc.text, fix.edits))


def codes(doc: Document) -> list[str]:
    return [d.code for d in analyze(doc)]


def well_formed(text: str) -> bool:
    try:
        etree.fromstring(text.encode("utf-8"))
    except etree.XMLSyntaxError:
        return False
    return True


def test_missing_format() -> None:
    doc = Document('<root>\n<BehaviorTree ID="Main"><AlwaysSuccess/></BehaviorTree>\n</root>')
    _, found = fixes(doc, "missing-format")
    assert [f.title for f in found] == ['Add BTCPP_format="4" to <root>']
    assert found[0].preferred
    new = applied(doc, found[0])
    assert new.text.startswith('<root BTCPP_format="4">')
    assert codes(new) == []


def test_v3_rename_renames_start_and_end_tag() -> None:
    doc = Document(T("<SequenceStar>\n  <AlwaysSuccess/>\n</SequenceStar>"))
    _, found = fixes(doc, "unknown-node")
    assert found[0].title == "Rename 'SequenceStar' to 'SequenceWithMemory'"
    assert found[0].preferred
    new = applied(doc, found[0])
    assert "<SequenceWithMemory>" in new.text and "</SequenceWithMemory>" in new.text
    assert codes(new) == []


def test_explicit_rename_edits_the_id() -> None:
    doc = Document(T('<Control ID="SequenceStar"><AlwaysSuccess/></Control>'))
    _, found = fixes(doc, "unknown-node")
    new = applied(doc, found[0])
    assert '<Control ID="SequenceWithMemory">' in new.text
    assert codes(new) == []


def test_case_mismatch_rename_is_preferred_typo_guess_is_not() -> None:
    doc = Document(T("<inverter><AlwaysSuccess/></inverter>"))
    _, found = fixes(doc, "unknown-node")
    assert found[0].title == "Rename 'inverter' to 'Inverter'" and found[0].preferred
    assert codes(applied(doc, found[0])) == []
    doc = Document(T("<Sequense><AlwaysSuccess/></Sequense>"))
    diag, found = fixes(doc, "unknown-node")
    assert "did you mean 'Sequence'" in diag.message
    assert found[0].title == "Rename 'Sequense' to 'Sequence'" and not found[0].preferred


def test_tree_used_as_node_becomes_a_subtree_call() -> None:
    doc = Document(
        R(
            '<BehaviorTree ID="Main"><Sub/></BehaviorTree>\n'
            '<BehaviorTree ID="Sub"><AlwaysSuccess/></BehaviorTree>',
            'BTCPP_format="4" main_tree_to_execute="Main"',
        )
    )
    _, found = fixes(doc, "unknown-node")
    call = next(f for f in found if f.title.startswith("Call tree"))
    new = applied(doc, call)
    assert '<SubTree ID="Sub"/>' in new.text
    assert codes(new) == []


DECLARE_INTO_SECTION = """<root BTCPP_format="4">
    <BehaviorTree ID="Main">
        <Sequence>
            <MoveBase goal="{g}" speed="0.5" _skipIf="done"/>
            <MoveBase goal="{h}" timeout="3"/>
        </Sequence>
    </BehaviorTree>
    <TreeNodesModel>
        <Action ID="Other"/>
    </TreeNodesModel>
</root>
"""


def declare(doc: Document) -> Document:
    _, found = fixes(doc, "unknown-node")
    fix = next(f for f in found if f.title == "Declare 'MoveBase' in <TreeNodesModel>")
    assert not fix.preferred
    new = applied(doc, fix)
    assert well_formed(new.text), new.text
    return new


def test_declare_into_an_existing_section() -> None:
    new = declare(Document(DECLARE_INTO_SECTION))
    assert new.text == DECLARE_INTO_SECTION.replace(
        '        <Action ID="Other"/>\n',
        '        <Action ID="Other"/>\n'
        '        <Action ID="MoveBase">\n'
        '            <input_port name="goal"/>\n'
        '            <input_port name="speed"/>\n'
        '            <input_port name="timeout"/>\n'
        "        </Action>\n",
    )
    # Both uses give 'goal'; each lacks one of the others, which have no default.
    assert codes(new) == ["missing-port-without-default"] * 2


def test_declare_creates_the_section() -> None:
    text = (
        '<root BTCPP_format="4">\n\t<BehaviorTree ID="Main">\n\t\t<Check/>\n'
        "\t</BehaviorTree>\n</root>"
    )
    doc = Document(text)
    _, found = fixes(doc, "unknown-node")
    new = applied(doc, found[-1])
    assert new.text == (
        '<root BTCPP_format="4">\n\t<BehaviorTree ID="Main">\n\t\t<Check/>\n\t</BehaviorTree>\n'
        '\t<TreeNodesModel>\n\t\t<Action ID="Check"/>\n\t</TreeNodesModel>\n</root>'
    )
    assert codes(new) == []


def test_declare_into_a_self_closing_section_and_guess_the_category() -> None:
    text = R(
        '<BehaviorTree ID="Main"><Repeater n="2"><AlwaysSuccess/></Repeater></BehaviorTree>\n'
        "<TreeNodesModel/>"
    )
    doc = Document(text)
    new = applied(doc, fixes(doc, "unknown-node")[1][-1])
    assert '<Decorator ID="Repeater">' in new.text
    assert well_formed(new.text)
    assert codes(new) == []


def test_declare_explicit_node_keeps_its_category() -> None:
    doc = Document(R('<BehaviorTree ID="Main"><Condition ID="IsOk"/></BehaviorTree>'))
    new = applied(doc, fixes(doc, "unknown-node")[1][-1])
    assert '<Condition ID="IsOk"/>' in new.text.split("<TreeNodesModel>")[1]
    assert codes(new) == []


def test_unknown_attribute() -> None:
    doc = Document(T('<AlwaysSuccess _skipif="x"/>'))
    _, found = fixes(doc, "unknown-attribute")
    assert found[0].title == "Did you mean '_skipIf'? Rename '_skipif'" and found[0].preferred
    assert codes(applied(doc, found[0])) == []
    doc = Document(
        R(
            '<BehaviorTree ID="Main"><SubTree ID="Sub" __shared_blackboard="true"/>'
            "</BehaviorTree>\n"
            '<BehaviorTree ID="Sub"><AlwaysSuccess/></BehaviorTree>',
            'BTCPP_format="4" main_tree_to_execute="Main"',
        )
    )
    _, found = fixes(doc, "unknown-attribute")
    new = applied(doc, found[0])
    assert '_autoremap="true"' in new.text and codes(new) == []
    doc = Document(T('<AlwaysSuccess _onSucess="x := 1"/>'))
    _, found = fixes(doc, "unknown-attribute")
    assert found[0].title.startswith("Did you mean '_onSuccess'?") and not found[0].preferred
    assert fixes(Document(T('<AlwaysSuccess _color="red"/>')), "unknown-attribute")[1] == []


def test_id_on_compact_node() -> None:
    doc = Document(T('<AlwaysSuccess name="a"  ID="AlwaysSuccess" />'))
    _, found = fixes(doc, "id-on-compact-node")
    assert found[0].preferred
    new = applied(doc, found[0])
    assert '<AlwaysSuccess name="a" />' in new.text
    assert codes(new) == []


def test_unescaped_chars() -> None:
    doc = Document(T('<AlwaysSuccess _while="a && b &lt; 3 || c<2"/>'))
    ctx = Context.from_document(doc)
    diags = [d for d in analyze(doc, ctx) if d.code == "xml-unescaped-char"]
    assert len(diags) == 3
    edits: list[TextEdit] = []
    for d in diags:
        found = semantic_fixes.fixes_for_rule(doc, ctx, d)
        assert len(found) == 1 and found[0].preferred
        edits.extend(found[0].edits)
    new = Document(apply_edits(doc.text, edits))
    assert '_while="a &amp;&amp; b &lt; 3 || c&lt;2"' in new.text
    assert codes(new) == [] and well_formed(new.text)


def test_no_fix_for_other_codes() -> None:
    doc = Document(T("<Inverter/>"))
    _, found = fixes(doc, "child-count")
    assert found == []


# --- every fix of every fixture -------------------------------------------------------------


@pytest.mark.parametrize("marked", [c[1] for c in CASES], ids=[c[0] for c in CASES])
def test_every_fix_removes_its_diagnostic(marked: str) -> None:
    doc = Document(unmark(marked)[0])
    ctx = Context.from_document(doc)
    for diag in semantics.check(doc, ctx):
        for fix in semantic_fixes.fixes_for_rule(doc, ctx, diag):
            new = Document(apply_edits(doc.text, fix.edits))
            after = analyze(new)
            assert not any(d.code == "xml-syntax" for d in after) or any(
                d.code == "xml-syntax" for d in analyze(doc)
            ), fix.title
            if fix.title.startswith("Declare"):
                still = [d for d in after if d.code == diag.code]
                assert isinstance(diag.data, UnknownNodeData)
                assert all(
                    isinstance(d.data, UnknownNodeData) and d.data.type != diag.data.type
                    for d in still
                )
            else:
                assert not any(d.code == diag.code and d.start == diag.start for d in after), (
                    fix.title
                )


# --- decoded -> raw offsets -------------------------------------------------------------------

PLAIN = ("a", "b", " ", "=", ";", "#", "é", "😀", "&", "<")
REFS = ("&amp;", "&lt;", "&gt;", "&quot;", "&apos;", "&#65;", "&#x42;", "&foo;", "&#0;", "&#xD800;")
PIECES = st.sampled_from((*PLAIN, *REFS))


@given(st.lists(PIECES, max_size=30))
def test_raw_offsets_follow_the_decoder(pieces: list[str]) -> None:
    raw = "".join(pieces)
    decoded = decode_value(raw, 0, None)
    offs = raw_offsets(raw)
    assert len(offs) == len(decoded) + 1
    assert offs[0] == 0 and offs[-1] == len(raw)
    for i, ch in enumerate(decoded):
        assert decode_value(raw[offs[i] : offs[i + 1]], 0, None) == ch
    assert raw_span(raw, 0, len(decoded)) == (0, len(raw))


# --- never crash ------------------------------------------------------------------------------

TOKENS = (
    "<root", '<root BTCPP_format="4"', "<BehaviorTree", ' ID="A"', ' ID="B"', " ID=''",
    "<SubTree", "<Sequence", "<Action", "<Inverter", "<Parallel", ' success_count="3"',
    "<TreeNodesModel", "<input_port", ' name="x"', ' name="_y"', "<include", ' ros_pkg="p"',
    ' _skipIf="a &amp;&amp; (b"', ' code="x :="', "<Script", "<ReactiveSequence", "<AsyncSequence",
    ' _autoremap="maybe"', ' msec="-1"', "<Sleep", "<SequenceStar", " _skipif='1'", ' ID="Sleep"',
    ">", "/>", "</BehaviorTree>", "</Sequence>", "</root>", "</TreeNodesModel>", "</SubTree>",
    "</Inverter>", "<!-- c -->", " ", "\n", "&", "<", '"', "=",
)  # fmt: skip


@given(st.lists(st.sampled_from(TOKENS), max_size=60))
def test_check_and_fixes_never_raise(tokens: list[str]) -> None:
    doc = Document("".join(tokens))
    ctx = Context.from_document(doc)
    for diag in analyze(doc, ctx):
        assert 0 <= diag.start <= diag.end <= len(doc.text)
        for fix in semantic_fixes.fixes_for_rule(doc, ctx, diag):
            apply_edits(doc.text, fix.edits)
