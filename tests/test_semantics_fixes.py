"""Quick fixes of the semantic diagnostics: applied, then the document is analyzed again."""

from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st
from lxml import etree

from bt_lsp.ide import semantic_fixes
from bt_lsp.ide.fix_all import fix_document
from bt_lsp.ide.name_fixes import Fix
from bt_lsp.rules import semantics
from bt_lsp.rules.analysis import analyze
from bt_lsp.rules.codes import BT, Applicability, Code, FixEdits, Severity, safe, unsafe
from bt_lsp.rules.context import Context
from bt_lsp.rules.diagnostics import Diagnostic
from bt_lsp.rules.semantics.nodes import UnknownNodeData
from bt_lsp.syntax.document import Document
from bt_lsp.syntax.edits import TextEdit, apply_edits
from bt_lsp.syntax.values import decode_value, raw_offsets, raw_span
from tests.marks import unmark
from tests.pinned import pinned
from tests.test_semantics import CASES, TM, R, T


def fixes(doc: Document, code: str, ctx: Context | None = None) -> tuple[Diagnostic, list[Fix]]:
    ctx = ctx if ctx is not None else Context.from_document(doc)
    diags = [d for d in analyze(doc, ctx) if d.code == code]
    assert diags, f"no {code}"
    return diags[0], semantic_fixes.fixes_for_rule(doc, ctx, diags[0])


def applied(doc: Document, fix: Fix) -> Document:
    return Document(apply_edits(doc.text, fix.edits))


def codes(doc: Document) -> list[str]:
    """The codes ``doc`` gets, of those the tests were written against."""
    return [d.code for d in pinned(analyze(doc))]


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
    # No version detected: the file may be a version 3 one, so the fix is unsafe ...
    assert found[0].applicability is Applicability.UNSAFE and not found[0].preferred
    # ... and safe (the preferred fix) in a project known to build against version 4.
    ctx = Context.combine(doc, (), btcpp_version="4")
    _, found = fixes(doc, "missing-format", ctx)
    assert found[0].safe and found[0].preferred
    new = applied(doc, found[0])
    assert new.text.startswith('<root BTCPP_format="4">')
    assert codes(new) == []


def test_v3_rename_renames_start_and_end_tag() -> None:
    doc = Document(T("<SequenceStar>\n  <AlwaysSuccess/>\n</SequenceStar>"))
    _, found = fixes(doc, "unknown-node")
    assert found[0].title == "Rename 'SequenceStar' to 'SequenceWithMemory'"
    assert found[0].preferred  # the document says BTCPP_format="4"
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
    # One edit from a built-in, while C++ that bt-lsp did not read may register the name.
    assert found[0].applicability is Applicability.UNSAFE


def test_typo_rename_is_safe_when_every_registration_is_known() -> None:
    doc = Document(T("<Fallbak><AlwaysSuccess/></Fallbak>"))
    diag, found = fixes(doc, "unknown-node")
    assert diag.severity == Severity.WARNING
    assert found[0].title == "Rename 'Fallbak' to 'Fallback'"
    assert found[0].applicability is Applicability.UNSAFE and not found[0].preferred
    # With a node catalog BehaviorTree.CPP surely fails on it, and one name is nearest.
    ctx = Context.from_document(doc, workspace_has_custom_models=True)
    diag, found = fixes(doc, "unknown-node", ctx)
    assert diag.severity == Severity.ERROR
    assert found[0].safe and found[0].preferred
    assert codes(applied(doc, found[0])) == []
    # Two names equally near: which one is meant is a guess.
    doc = Document(
        R(
            '<BehaviorTree ID="Main"><MoveBaze/></BehaviorTree>\n'
            '<TreeNodesModel><Action ID="MoveBase"/><Action ID="MoveBaxe"/></TreeNodesModel>'
        )
    )
    ctx = Context.from_document(doc, workspace_has_custom_models=True)
    _, found = fixes(doc, "unknown-node", ctx)
    assert found[0].title.startswith("Rename 'MoveBaze' to 'MoveBa")
    assert found[0].applicability is Applicability.UNSAFE and not found[0].preferred


def test_a_preferred_fix_is_always_safe() -> None:
    diag = Diagnostic(0, 1, "unknown-node", "x", Severity.ERROR)
    with pytest.raises(ValueError, match="must be safe"):
        Fix("t", (), True, diag, applicability=Applicability.UNSAFE)


def test_unknown_attribute() -> None:
    doc = Document(T('<AlwaysSuccess _skipif="x"/>'))
    _, found = fixes(doc, "unknown-attribute")
    assert found[0].title == "Did you mean '_skipIf'? Rename '_skipif'"
    # The file loads today and ignores the attribute: the precondition would start to run.
    assert found[0].applicability is Applicability.UNSAFE and not found[0].preferred
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
    assert found[0].applicability is Applicability.DISPLAY_ONLY
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


# --- missing ports, missing trees, fix-all ---------------------------------------------------


def test_missing_required_port_of_a_builtin_gets_an_empty_value_to_fill_in() -> None:
    doc = Document(T('<Repeat name="r"><AlwaysSuccess/></Repeat>'))
    _, found = fixes(doc, "missing-required-port")
    assert [f.title for f in found] == ['Add num_cycles=""']
    assert found[0].applicability is Applicability.UNSAFE and not found[0].preferred
    new = applied(doc, found[0])
    assert '<Repeat name="r" num_cycles="">' in new.text
    assert "missing-required-port" not in codes(new)


def test_missing_subtree_port_is_remapped_to_the_key_of_its_name() -> None:
    doc = Document(
        R(
            '<BehaviorTree ID="Main"><SubTree ID="Dock"/></BehaviorTree>\n'
            '<BehaviorTree ID="Dock"><AlwaysSuccess/></BehaviorTree>\n'
            '<TreeNodesModel><SubTree ID="Dock"><input_port name="goal"/>'
            '<input_port name="speed" default=""/></SubTree></TreeNodesModel>',
            'BTCPP_format="4" main_tree_to_execute="Main"',
        )
    )
    _, found = fixes(doc, "missing-required-port")
    assert found[0].title == 'Add goal="{goal}", speed="{speed}"'
    new = applied(doc, found[0])
    assert '<SubTree ID="Dock" goal="{goal}" speed="{speed}"/>' in new.text
    assert codes(new) == []


def test_missing_custom_port_is_offered_in_the_editor_only() -> None:
    doc = Document(TM('<Count opt="2"/>'))
    _, found = fixes(doc, "missing-port-without-default")
    assert found[0].title == 'Add n=""'
    assert found[0].applicability is Applicability.DISPLAY_ONLY
    new = applied(doc, found[0])
    assert '<Count opt="2" n=""/>' in new.text
    assert "missing-port-without-default" not in codes(new)


CALLS_A_MISSING_TREE = """<root BTCPP_format="4" main_tree_to_execute="Main">
  <BehaviorTree ID="Main">
    <Sequence>
      <SubTree ID="Dokc"/>
      <SubTree ID="Charge"/>
    </Sequence>
  </BehaviorTree>
  <BehaviorTree ID="Dock">
    <AlwaysSuccess/>
  </BehaviorTree>
</root>
"""


def test_unknown_subtree_renamed_to_the_one_near_tree() -> None:
    doc = Document(CALLS_A_MISSING_TREE)
    diags = [d for d in analyze(doc) if d.code == "unknown-subtree"]
    found = semantic_fixes.fixes_for_rule(doc, Context.from_document(doc), diags[0])
    assert [f.title for f in found] == [
        "Rename 'Dokc' to 'Dock'",
        "Create the tree 'Dokc' that fails until it is written",
    ]
    assert all(f.applicability is Applicability.UNSAFE and not f.preferred for f in found)
    new = applied(doc, found[0])
    assert '<SubTree ID="Dock"/>' in new.text
    assert [d for d in analyze(new) if d.code == "unknown-subtree"] == [diags[1]]


def test_unknown_subtree_creates_a_tree_that_loads_and_fails() -> None:
    doc = Document(CALLS_A_MISSING_TREE.replace("\n", "\r\n"))
    diags = [d for d in analyze(doc) if d.code == "unknown-subtree"]
    found = semantic_fixes.fixes_for_rule(doc, Context.from_document(doc), diags[1])
    assert [f.title for f in found] == ["Create the tree 'Charge' that fails until it is written"]
    new = applied(doc, found[0])
    assert new.text.endswith(
        "  </BehaviorTree>\r\n"
        '  <BehaviorTree ID="Charge">\r\n'
        "    <!-- TODO: write this tree; until then it fails when it runs -->\r\n"
        "    <AlwaysFailure/>\r\n"
        "  </BehaviorTree>\r\n"
        "</root>\r\n"
    )
    assert well_formed(new.text)
    assert codes(new) == ["unknown-subtree"]  # 'Dokc' is left


def test_fix_all_applies_the_safe_fixes_and_the_unsafe_ones_when_asked() -> None:
    doc = Document(
        '<root>\n  <BehaviorTree ID="Main">\n    <Sequence>\n'
        '      <AlwaysSuccess ID="x" _skipif="a &amp; b" name="a&b"/>\n'
        "      <Sequense><Repeat><AlwaysSuccess/></Repeat></Sequense>\n"
        "    </Sequence>\n  </BehaviorTree>\n</root>\n"
    )
    ctx = Context.from_document(doc)
    diags = pinned(analyze(doc, ctx))  # the fixes of the codes this test knows
    safe_only = fix_document(doc, ctx, diags)
    assert sorted(f.diagnostic.code for f in safe_only.rules) == [
        "id-on-compact-node",
        "xml-unescaped-char",
    ]
    text = apply_edits(doc.text, safe_only.edits)
    assert '<AlwaysSuccess _skipif="a &amp; b" name="a&amp;b"/>' in text
    assert "<Sequense>" in text and "<root>" in text  # unsafe: left as they were
    every = fix_document(doc, ctx, diags, unsafe=True)
    text = apply_edits(doc.text, every.edits)
    assert '<root BTCPP_format="4">' in text
    assert '<AlwaysSuccess _skipIf="a &amp; b" name="a&amp;b"/>' in text
    assert '<Sequence><Repeat num_cycles=""><AlwaysSuccess/></Repeat></Sequence>' in text
    # Never in bulk, not even with unsafe fixes: declaring a model for a node.
    assert "TreeNodesModel" not in text


def test_a_fixer_defined_beside_its_rule_makes_titled_fixes_the_first_safe_preferred(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    doc = Document(T("<AlwaysSuccess/>"))
    edit = TextEdit(0, 0, "x")

    def fixer(d: Document, c: Context, diag: Diagnostic) -> list[FixEdits]:
        assert d is doc and diag.code == "demo"
        return [
            FixEdits("maybe", (edit,), {"what": "a"}),
            FixEdits("sure", (edit,), {"what": "b"}),
            FixEdits("sure", (edit,), {"what": "c"}),
        ]

    demo = Code(
        "demo",
        Severity.HINT,
        "a demonstration",
        BT,
        {"sure": safe("Do {what}"), "maybe": unsafe("Perhaps {what}")},
        fixer=fixer,
    )
    monkeypatch.setattr(semantic_fixes, "all_defined", lambda: {"demo": demo})
    diag = Diagnostic(1, 5, "demo", "m", Severity.HINT)
    found = semantic_fixes.fixes_for_rule(doc, Context.from_document(doc), diag)
    assert [(f.title, f.preferred, f.applicability) for f in found] == [
        ("Perhaps a", False, Applicability.UNSAFE),
        ("Do b", True, Applicability.SAFE),
        ("Do c", False, Applicability.SAFE),
    ]
    assert all(f.edits == (edit,) and f.diagnostic is diag for f in found)
