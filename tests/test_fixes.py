"""Name fixes: renames reach every reference, stay unique, keep XML well-formed."""

from __future__ import annotations

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from lxml import etree

from bt_lsp.ide.hover import hover_at
from bt_lsp.ide.name_fixes import Fix, escape_value, fix_all, fixes_for_name
from bt_lsp.ide.rename import RenamePlan, RenameRefused, rename
from bt_lsp.rules.analysis import analyze
from bt_lsp.rules.diagnostics import Diagnostic
from bt_lsp.syntax.document import Document
from bt_lsp.syntax.edits import apply_edits
from tests.pinned import pinned

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
    return [d.code for d in analyze(doc) if d.is_name_rule]


def preferred_fix(doc: Document, name: str) -> tuple[str, str]:
    for d in analyze(doc):
        if d.is_name_rule and doc.text[d.start : d.end] == name:
            fixes = fixes_for_name(doc, d)
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
    fixed = apply_edits(doc.text, fix_all(doc, analyze(doc)).edits)
    etree.fromstring(fixed.encode())  # still well-formed
    assert name_diags(Document(fixed)) == []
    assert fixed.count("Main_Tree") == 3 and fixed.count("Open_Door") == 4


def test_fix_all_gives_distinct_names_to_distinct_symbols() -> None:
    doc = Document(
        '<root><BehaviorTree ID="A B"><SubTree ID="A.B"/></BehaviorTree>'
        '<BehaviorTree ID="A.B"><AlwaysSuccess/></BehaviorTree></root>'
    )
    fixed = Document(apply_edits(doc.text, fix_all(doc, analyze(doc)).edits))
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

    def q(s: str) -> str:
        return escape_value(s, '"')

    text = (
        f'<root main_tree_to_execute="{q(tree)}"><BehaviorTree ID="{q(tree)}">'
        f'<Action ID="{q(node)}"/></BehaviorTree><TreeNodesModel>'
        f'<Action ID="{q(node)}"><input_port name="{q(port)}"/></Action>'
        "</TreeNodesModel></root>"
    )
    doc = Document(text)
    fixed = apply_edits(text, fix_all(doc, analyze(doc)).edits)
    etree.fromstring(fixed.encode())
    assert name_diags(Document(fixed)) == []


# --- ports of trees: renamed with their keys, as a rename renames them ----------------------

# Tree "Greet" has two bad ports: "bad.port" (a '.'), used as {bad.port} inside the tree and
# passed on to "Leaf" with {=}, and "name" (reserved), used in scripts.  Before the fixes,
# the only problems are the name problems.
PORTS = (
    '<root BTCPP_format="4" main_tree_to_execute="Main">\n'
    '  <BehaviorTree ID="Main">\n'
    "    <Sequence>\n"
    "      <Script code=\"who := 'you'\"/>\n"
    '      <SubTree ID="Greet" bad.port="{who}"/>\n'
    "    </Sequence>\n"
    "  </BehaviorTree>\n"
    '  <BehaviorTree ID="Greet">\n'
    "    <Sequence>\n"
    '      <SetBlackboard output_key="greeting" value="{bad.port}"/>\n'
    "      <Script code=\"greeting := 'hi ' .. name\" _skipIf=\"name == ''\"/>\n"
    '      <SubTree ID="Leaf" bad.port="{=}"/>\n'
    "    </Sequence>\n"
    "  </BehaviorTree>\n"
    '  <BehaviorTree ID="Leaf">\n'
    '    <SetBlackboard output_key="out" value="{bad.port}"/>\n'
    "  </BehaviorTree>\n"
    "  <TreeNodesModel>\n"
    '    <SubTree ID="Greet">\n'
    '      <input_port name="bad.port"/>\n'
    '      <input_port name="name" default="world"/>\n'
    "    </SubTree>\n"
    '    <SubTree ID="Leaf">\n'
    '      <input_port name="bad.port"/>\n'
    "    </SubTree>\n"
    "  </TreeNodesModel>\n"
    "</root>\n"
)

PORTS_FIXED = (
    '<root BTCPP_format="4" main_tree_to_execute="Main">\n'
    '  <BehaviorTree ID="Main">\n'
    "    <Sequence>\n"
    "      <Script code=\"who := 'you'\"/>\n"
    '      <SubTree ID="Greet" bad_port="{who}"/>\n'
    "    </Sequence>\n"
    "  </BehaviorTree>\n"
    '  <BehaviorTree ID="Greet">\n'
    "    <Sequence>\n"
    '      <SetBlackboard output_key="greeting" value="{bad_port}"/>\n'
    "      <Script code=\"greeting := 'hi ' .. name_\" _skipIf=\"name_ == ''\"/>\n"
    '      <SubTree ID="Leaf" bad_port="{bad_port}"/>\n'
    "    </Sequence>\n"
    "  </BehaviorTree>\n"
    '  <BehaviorTree ID="Leaf">\n'
    '    <SetBlackboard output_key="out" value="{bad_port}"/>\n'
    "  </BehaviorTree>\n"
    "  <TreeNodesModel>\n"
    '    <SubTree ID="Greet">\n'
    '      <input_port name="bad_port"/>\n'
    '      <input_port name="name_" default="world"/>\n'
    "    </SubTree>\n"
    '    <SubTree ID="Leaf">\n'
    '      <input_port name="bad_port"/>\n'
    "    </SubTree>\n"
    "  </TreeNodesModel>\n"
    "</root>\n"
)


def _diag_at(doc: Document, needle: str, nth: int = 0) -> Diagnostic:
    """The name diagnostic inside the ``nth`` occurrence of ``needle``."""
    start = -1
    for _ in range(nth + 1):
        start = doc.text.index(needle, start + 1)
    for d in analyze(doc):
        if d.is_name_rule and start <= d.start and d.end <= start + len(needle):
            return d
    raise AssertionError(f"no name diagnostic in {needle!r} #{nth}")


def _quick_fixes(doc: Document, needle: str, nth: int = 0) -> list[Fix]:
    found = fixes_for_name(doc, _diag_at(doc, needle, nth))
    assert found and found[0].preferred and not any(f.preferred for f in found[1:])
    return found


def _semantic(doc: Document) -> list[str]:
    return sorted(d.code for d in pinned(analyze(doc)) if not d.is_name_rule)


def _renamed(doc: Document, needle: str, nth: int, new: str) -> RenamePlan:
    """A rename of the name that the name diagnostic in ``needle`` is about."""
    plan = rename(doc, _diag_at(doc, needle, nth).start, new)
    assert plan is not None
    return plan


def test_ports_fixture_has_only_name_problems() -> None:
    doc = Document(PORTS)
    assert _semantic(doc) == []
    assert sorted(name_diags(doc)) == ["port-name-forbidden-char"] * 4 + ["port-name-reserved"]


def test_tree_port_fix_renames_its_keys_inside_the_tree() -> None:
    doc = Document(PORTS)
    # The declaration of Greet's port: the call's attribute, the declaration and the key
    # uses in Greet, {bad.port} and the {=} passed on to Leaf.
    fix = _quick_fixes(doc, 'name="bad.port"')[0]
    assert fix.title == "Rename 'bad.port' to 'bad_port' (4 places)"
    assert fix.other_edits == {}
    assert apply_edits(PORTS, fix.edits) == (
        PORTS.replace('"Greet" bad.port=', '"Greet" bad_port=')
        .replace('value="{bad.port}"/>\n      <Script', 'value="{bad_port}"/>\n      <Script')
        .replace('bad.port="{=}"', 'bad.port="{bad_port}"')
        .replace(
            '"Greet">\n      <input_port name="bad.port"/>',
            '"Greet">\n      <input_port name="bad_port"/>',
        )
    )
    # Exactly the edits of a rename to the same name, from any of the port's names.
    assert fix.edits == _renamed(doc, 'name="bad.port"', 0, "bad_port").edits
    assert fix.edits == _renamed(doc, 'Greet" bad.port', 0, "bad_port").edits
    fixed = Document(apply_edits(PORTS, fix.edits))
    assert _semantic(fixed) == []
    assert sorted(name_diags(fixed)) == ["port-name-forbidden-char"] * 2 + ["port-name-reserved"]


def test_tree_port_fix_renames_the_key_in_scripts() -> None:
    doc = Document(PORTS)
    fix = _quick_fixes(doc, 'name="name"')[0]
    # The declaration and the two script identifiers; never the text inside the string.
    assert fix.title == "Rename 'name' to 'name_' (3 places)"
    assert apply_edits(PORTS, fix.edits) == PORTS.replace(
        "'hi ' .. name\" _skipIf=\"name ==", "'hi ' .. name_\" _skipIf=\"name_ =="
    ).replace('input_port name="name"', 'input_port name="name_"')
    assert fix.edits == _renamed(doc, 'name="name"', 0, "name_").edits
    assert _semantic(Document(apply_edits(PORTS, fix.edits))) == []


def test_renaming_a_port_attribute_writes_its_same_named_key_out() -> None:
    doc = Document(PORTS)
    # Leaf's port, renamed on the <SubTree ID="Leaf"> call in Greet: the attribute's
    # "{=}" is Greet's key "bad.port", written out so that it stays that key.
    fix = _quick_fixes(doc, 'bad.port="{=}"')[0]
    assert fix.title == "Rename 'bad.port' to 'bad_port' (4 places)"
    assert apply_edits(PORTS, fix.edits) == (
        PORTS.replace('bad.port="{=}"', 'bad_port="{bad.port}"')
        .replace(
            'value="{bad.port}"/>\n  </BehaviorTree>', 'value="{bad_port}"/>\n  </BehaviorTree>'
        )
        .replace(
            '"Leaf">\n      <input_port name="bad.port"/>',
            '"Leaf">\n      <input_port name="bad_port"/>',
        )
    )
    assert fix.edits == _renamed(doc, 'bad.port="{=}"', 0, "bad_port").edits
    assert _semantic(Document(apply_edits(PORTS, fix.edits))) == []


def test_bare_same_key_is_written_out_with_braces() -> None:
    text = PORTS.replace('bad.port="{=}"', 'bad.port="="')
    doc = Document(text)
    fix = _quick_fixes(doc, 'bad.port="="')[0]
    assert 'bad_port="{bad.port}"' in apply_edits(text, fix.edits)


def test_fix_all_renames_tree_ports_with_their_keys() -> None:
    doc = Document(PORTS)
    result = fix_all(doc, analyze(doc))
    assert result.notes == []
    fixed = apply_edits(PORTS, result.edits)
    # Greet's key "bad.port" is renamed, so the {=} passed on to Leaf becomes that new key
    # rather than the old one written out.
    assert fixed == PORTS_FIXED
    assert name_diags(Document(fixed)) == []
    assert _semantic(Document(fixed)) == []


def test_fix_all_is_the_same_as_the_quick_fixes_one_after_the_other() -> None:
    text = PORTS
    while True:
        doc = Document(text)
        diags = [d for d in analyze(doc) if d.is_name_rule]
        if not diags:
            break
        text = apply_edits(text, fixes_for_name(doc, diags[0])[0].edits)
    assert text == PORTS_FIXED


# Tree "Main" calls "Sub" with _autoremap and uses its key "bad.port" too: renaming the key
# in Sub alone would disconnect the two, so a rename of the port is refused.
AUTOREMAP = (
    '<root BTCPP_format="4" main_tree_to_execute="Main">\n'
    '  <BehaviorTree ID="Main">\n'
    "    <Sequence>\n"
    '      <SetBlackboard output_key="copy" value="{bad.port}"/>\n'
    '      <SubTree ID="Sub" _autoremap="true"/>\n'
    "    </Sequence>\n"
    "  </BehaviorTree>\n"
    '  <BehaviorTree ID="Sub">\n'
    '    <SetBlackboard output_key="out" value="{bad.port}"/>\n'
    "  </BehaviorTree>\n"
    "  <TreeNodesModel>\n"
    '    <SubTree ID="Sub">\n'
    '      <input_port name="bad.port" default="0"/>\n'
    "    </SubTree>\n"
    "  </TreeNodesModel>\n"
    "</root>\n"
)

AUTOREMAP_WHY = (
    "Cannot rename 'bad.port': tree 'Main' shares it with tree 'Sub' through "
    '<SubTree _autoremap="true">, and renaming it in one tree would disconnect them'
)


def test_refused_key_rename_falls_back_to_the_port_and_says_so() -> None:
    doc = Document(AUTOREMAP)
    with pytest.raises(RenameRefused) as refused:
        _renamed(doc, "bad.port", 2, "bad_port")
    assert refused.value.message == AUTOREMAP_WHY and not refused.value.new_name
    found = _quick_fixes(doc, "bad.port", 2)
    assert [f.title for f in found] == [
        f"Rename 'bad.port' to '{new}' (1 place); key 'bad.port' in tree 'Sub' left as it is"
        for new in ("bad_port", "badPort", "bad-port")
    ]
    expected = AUTOREMAP.replace('name="bad.port"', 'name="bad_port"')
    assert apply_edits(AUTOREMAP, found[0].edits) == expected
    result = fix_all(doc, analyze(doc))
    assert apply_edits(AUTOREMAP, result.edits) == expected
    assert result.notes == [
        "renamed 'bad.port' to 'bad_port' and left the key 'bad.port' in tree 'Sub' as it "
        f"is: {AUTOREMAP_WHY}"
    ]
    assert name_diags(Document(expected)) == []
    assert _semantic(Document(expected)) == _semantic(doc)


def test_hover_tells_what_the_fix_renames_and_leaves() -> None:
    doc = Document(AUTOREMAP)
    found = hover_at(doc, _diag_at(doc, "bad.port", 2).start)
    assert found is not None
    assert "Suggested replacement: `bad_port` (the quick fix renames 1 place)" in found.text
    assert (
        f"The quick fix leaves the key 'bad.port' in tree 'Sub' as it is: {AUTOREMAP_WHY}"
        in found.text
    )
    doc = Document(PORTS)
    found = hover_at(doc, _diag_at(doc, 'name="bad.port"').start + len('name="'))
    assert found is not None
    assert "Suggested replacement: `bad_port` (the quick fix renames 4 places)" in found.text


def test_a_new_name_that_would_merge_two_keys_is_passed_over() -> None:
    # Sub already uses a key "bad_port" in a script: the rename to that name is refused
    # (the two keys would become one), so the fix takes the next candidate.
    text = AUTOREMAP.replace(' _autoremap="true"', "").replace(
        '<SetBlackboard output_key="out" value="{bad.port}"/>',
        '<Sequence><Script code="bad_port := 2"/>'
        '<SetBlackboard output_key="out" value="{bad.port}"/></Sequence>',
    )
    doc = Document(text)
    with pytest.raises(RenameRefused) as refused:
        _renamed(doc, "bad.port", 2, "bad_port")
    assert refused.value.new_name
    found = _quick_fixes(doc, "bad.port", 2)
    assert [f.title for f in found] == [
        "Rename 'bad.port' to 'badPort' (2 places)",
        "Rename 'bad.port' to 'bad-port' (2 places)",
    ]
    expected = text.replace('name="bad.port"', 'name="badPort"').replace(
        'value="{bad.port}"/></Sequence>', 'value="{badPort}"/></Sequence>'
    )
    assert apply_edits(text, found[0].edits) == expected
    assert apply_edits(text, fix_all(doc, analyze(doc)).edits) == expected
    assert _semantic(Document(expected)) == _semantic(doc)


def test_numbered_name_when_no_candidate_will_do() -> None:
    # "Sequence" is a built-in node type: a tree cannot take that name.
    doc = Document(
        '<root BTCPP_format="4"><BehaviorTree ID="Sequence "><AlwaysSuccess/></BehaviorTree></root>'
    )
    found = _quick_fixes(doc, "Sequence ")
    assert [f.title for f in found] == ["Rename 'Sequence ' to 'Sequence_2' (1 place)"]


def test_fixes_reach_tree_port_keys_in_other_documents() -> None:
    models = Document(
        '<root BTCPP_format="4"><TreeNodesModel><SubTree ID="Sub">'
        '<input_port name="bad.port"/></SubTree></TreeNodesModel></root>',
        "/ws/models.xml",
    )
    tree = Document(
        '<root BTCPP_format="4"><BehaviorTree ID="Sub">'
        '<SetBlackboard output_key="out" value="{bad.port}"/></BehaviorTree></root>',
        "/ws/sub.xml",
    )
    (fix, *_) = fixes_for_name(models, _diag_at(models, "bad.port"), {"/ws/sub.xml": tree})
    assert fix.title == "Rename 'bad.port' to 'bad_port' (2 places, 1 other file)"
    assert apply_edits(tree.text, fix.other_edits["/ws/sub.xml"]) == tree.text.replace(
        "{bad.port}", "{bad_port}"
    )
    # fix_all makes the same edits, in both documents.
    both = fix_all(models, analyze(models), {"/ws/sub.xml": tree})
    assert both.edits == list(fix.edits)
    assert both.other_edits == fix.other_edits
    # Without the document defining the tree, the port is left as it is: renaming the
    # declaration alone would disconnect it from the tree's key.
    alone = fix_all(models, analyze(models))
    assert alone.edits == [] and alone.other_edits == {}
    assert alone.notes == [
        "left 'bad.port' as it is: the tree 'Sub' is not defined in the workspace (it comes "
        "from elsewhere, such as an installed package, and keeps its ID there); rename it "
        "where it is defined first, then this reference"
    ]
    assert fixes_for_name(models, _diag_at(models, "bad.port")) == []
