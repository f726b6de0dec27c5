"""Name fixes: renames reach every reference, stay unique, keep XML well-formed."""

from __future__ import annotations

from hypothesis import given, settings
from hypothesis import strategies as st
from lxml import etree

from bt_lsp.document import Document
from bt_lsp.edits import apply_edits
from bt_lsp.fixes import escape_value, fix_all, fixes_for

DOC = (
    '<root BTCPP_format="4" main_tree_to_execute="Main Tree">\n'
    '  <BehaviorTree ID="Main Tree">\n'
    "    <Sequence>\n"
    '      <Open.Door door.id="{d}"></Open.Door>\n'
    '      <Action ID="Open.Door" door.id="x"/>\n'
    '      <SubTree ID="Main Tree"/>\n'
    '      <SubTree ID="Sub" 1st="{a}"/>\n'
    "    </Sequence>\n"
    "  </BehaviorTree>\n"
    '  <BehaviorTree ID="Sub"><AlwaysSuccess name="a&#7;b"/></BehaviorTree>\n'
    "  <TreeNodesModel>\n"
    '    <Action ID="Open.Door"><input_port name="door.id"/></Action>\n'
    '    <SubTree ID="Sub"><input_port name="1st"/></SubTree>\n'
    "  </TreeNodesModel>\n"
    "</root>\n"
)


def name_diags(doc: Document) -> list[str]:
    return [d.code for d in doc.diagnostics if d.is_name_rule]


def preferred_fix(doc: Document, name: str) -> tuple[str, str]:
    for d in doc.diagnostics:
        if d.is_name_rule and doc.text[d.start : d.end] == name:
            fixes = fixes_for(doc.model, d)
            assert fixes[0].preferred and not any(f.preferred for f in fixes[1:])
            return fixes[0].title, apply_edits(doc.text, fixes[0].edits)
    raise AssertionError(f"no diagnostic on {name!r}")


def test_tree_rename_reaches_subtree_calls_and_main_tree() -> None:
    title, text = preferred_fix(Document(DOC), "Main Tree")
    assert title == "Rename 'Main Tree' to 'Main_Tree' (3 places)"
    assert text.count("Main_Tree") == 3 and "Main Tree" not in text


def test_model_rename_reaches_compact_end_tag_explicit_id_and_model_entry() -> None:
    title, text = preferred_fix(Document(DOC), "Open.Door")
    assert title == "Rename 'Open.Door' to 'Open_Door' (4 places)"
    assert text.count("Open_Door") == 4 and "Open.Door" not in text


def test_port_rename_reaches_declaration_and_uses_of_that_model_only() -> None:
    title, _ = preferred_fix(Document(DOC), "door.id")
    assert title == "Rename 'door.id' to 'door_id' (3 places)"
    title, _ = preferred_fix(Document(DOC), "1st")
    assert title == "Rename '1st' to 'p_1st' (2 places)"


def test_instance_fix_is_local_and_visible_in_title() -> None:
    title, text = preferred_fix(Document(DOC), "a&#7;b")
    assert title.startswith("Rename 'aU+0007b'")
    assert 'name="a b"' in text or 'name="ab"' in text


def test_replacement_is_unique() -> None:
    doc = Document(
        '<root><BehaviorTree ID="A B"><SubTree ID="A_B"/></BehaviorTree>'
        '<BehaviorTree ID="A_B"><AlwaysSuccess/></BehaviorTree></root>'
    )
    title, _ = preferred_fix(doc, "A B")
    assert title == "Rename 'A B' to 'A_B_2' (1 place)"


def test_fix_all_is_consistent_and_leaves_no_name_errors() -> None:
    doc = Document(DOC)
    fixed = apply_edits(doc.text, fix_all(doc.model, doc.diagnostics))
    etree.fromstring(fixed.encode())  # still well-formed
    assert name_diags(Document(fixed)) == []
    assert fixed.count("Main_Tree") == 3 and fixed.count("Open_Door") == 4


def test_fix_all_gives_distinct_names_to_distinct_symbols() -> None:
    doc = Document(
        '<root><BehaviorTree ID="A B"><SubTree ID="A.B"/></BehaviorTree>'
        '<BehaviorTree ID="A.B"><AlwaysSuccess/></BehaviorTree></root>'
    )
    fixed = Document(apply_edits(doc.text, fix_all(doc.model, doc.diagnostics)))
    ids = [r.text for r in fixed.model.refs if r.role == "tree ID"]
    assert len(set(ids)) == 2 and name_diags(fixed) == []


def test_escape_value() -> None:
    assert escape_value("a&b<c\"d'", '"') == "a&amp;b&lt;c&quot;d'"
    assert escape_value("it's", "'") == "it&apos;s"


bad_name = st.text(
    alphabet=st.sampled_from(list("ab .:/\\*?|<>&\"'\t-_1é检😋()#")), min_size=0, max_size=8
)


@given(tree=bad_name, node=bad_name.filter(lambda s: s.strip() != ""), port=bad_name)
@settings(max_examples=150, deadline=None)
def test_fix_all_on_random_names_keeps_xml_well_formed(tree: str, node: str, port: str) -> None:
    q = lambda s: escape_value(s, '"')  # noqa: E731
    text = (
        f'<root main_tree_to_execute="{q(tree)}"><BehaviorTree ID="{q(tree)}">'
        f'<Action ID="{q(node)}"/></BehaviorTree><TreeNodesModel>'
        f'<Action ID="{q(node)}"><input_port name="{q(port)}"/></Action>'
        "</TreeNodesModel></root>"
    )
    doc = Document(text)
    fixed = apply_edits(text, fix_all(doc.model, doc.diagnostics))
    etree.fromstring(fixed.encode())
    assert name_diags(Document(fixed)) == []
