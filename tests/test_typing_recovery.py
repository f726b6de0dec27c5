"""Typing recovery: what a half-typed document means while it is being written.

A ``<BehaviorTree`` typed while the tree above is not closed yet starts a new tree (it can
only be a child of ``<root>``), so its ID is checked as a tree ID; a character reference to
NUL inside a name gives that name's own diagnostic as well as the XML one."""

from __future__ import annotations

from bt_lsp.rules.analysis import analyze
from bt_lsp.syntax.document import Document
from bt_lsp.syntax.elements import Zone
from tests.annotated import check, parse

# The diagnostics: the open elements above are reported where they start, once each; the
# new tree's ID is a tree ID, with the tree ID's rule (no unknown node "BehaviorTree").
OPEN_TREE_REPORTS = """<root BTCPP_format="4" main_tree_to_execute="A">
  <BehaviorTree ID="A">
<!-- @3-15 error xml-syntax: Element '<BehaviorTree>' is not closed before the next '<BehaviorTree>' -->
    <Sequence>
<!-- ^^^^^^^^ error xml-syntax: Element '<Sequence>' is not closed before the next '<BehaviorTree>' -->
      <AlwaysSuccess/>
  <BehaviorTree ID="Bad Tree">
<!--                ^^^^^^^^ error model-name-forbidden-char -->
    <AlwaysSuccess/>
  </BehaviorTree>
</root>
"""  # noqa: E501
OPEN_TREE = parse(OPEN_TREE_REPORTS).text


def test_a_tree_typed_below_an_open_tree_starts_a_new_tree() -> None:
    doc = Document(OPEN_TREE)
    trees = [e for e in doc.model.elements if e.name == "BehaviorTree"]
    assert [t.zone for t in trees] == [Zone.TREE, Zone.TREE]
    assert trees[1].parent == 0  # a child of <root>
    check(OPEN_TREE_REPORTS)


def test_typing_the_tree_gives_the_model_of_the_whole_text() -> None:
    # The second tree typed character by character below the open one: each edit's
    # incremental model is the model of its whole text.
    typed = '  <BehaviorTree ID="Bad Tree">\n    <AlwaysSuccess/>\n  </BehaviorTree>\n'
    at = OPEN_TREE.index(typed)
    doc = Document(OPEN_TREE.replace(typed, ""))
    for k, ch in enumerate(typed):
        doc.model  # noqa: B018 - built, so that the next one is built from it
        doc.edit(at + k, at + k, ch)
        fresh = Document(doc.text)
        assert [(e.name, e.zone, e.parent, e.token_start) for e in doc.model.elements] == [
            (e.name, e.zone, e.parent, e.token_start) for e in fresh.model.elements
        ], doc.text
        assert [(d.code, d.start, d.end, d.message) for d in analyze(doc)] == [
            (d.code, d.start, d.end, d.message) for d in analyze(fresh)
        ], doc.text
    assert doc.text == OPEN_TREE


def test_a_tree_inside_an_unknown_element_is_left_alone() -> None:
    # BehaviorTree.CPP reads only the children of <root>: a <BehaviorTree> in another
    # element is ignored there, and not taken for a new tree here.
    text = (
        '<root BTCPP_format="4"><BehaviorTree ID="A"><AlwaysSuccess/></BehaviorTree>'
        '<Extra><BehaviorTree ID="B"/></Extra></root>'
    )
    zones = [e.zone for e in Document(text).model.elements if e.name == "BehaviorTree"]
    assert zones == [Zone.TREE, Zone.OTHER]


def test_a_nul_reference_in_a_name_gives_the_name_its_own_diagnostic() -> None:
    for ref in ("&#0;", "&#x0;", "&#x00;"):
        text = (
            f'<root BTCPP_format="4"><BehaviorTree ID="A{ref}B">'
            f'<AlwaysSuccess name="x{ref}"/></BehaviorTree></root>'
        )
        doc = Document(text)
        diags = analyze(doc)
        found = [(d.code, text[d.start : d.end]) for d in diags]
        assert ("model-name-forbidden-char", f"A{ref}B") in found, found
        assert ("instance-name-control-char", f"x{ref}") in found, found
        assert found.count(("xml-syntax", ref)) == 2, found
        model = next(d for d in diags if d.code == "model-name-forbidden-char")
        assert "U+0000 (control character) at column 2" in model.message
        # As '&#1;' is.
        one = Document(text.replace(ref, "&#1;"))
        assert [d.code for d in analyze(one) if d.code != "xml-syntax"] == [
            d.code for d in diags if d.code != "xml-syntax"
        ]
