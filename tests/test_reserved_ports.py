"""A port declared in ``<TreeNodesModel>`` with a reserved name: reported as the project's
BehaviorTree.CPP version reads the entry (an error only where it throws), with the name
fixes where the code is a name rule, and the same in hover."""

from __future__ import annotations

from bt_lsp.ide.hover import hover_at
from bt_lsp.ide.name_fixes import fix_all, fixes_for_name
from bt_lsp.rules.analysis import analyze
from bt_lsp.rules.codes import Severity
from bt_lsp.rules.context import Context
from bt_lsp.rules.diagnostics import Diagnostic
from bt_lsp.rules.early_names import early_name_diagnostics
from bt_lsp.syntax.document import Document
from bt_lsp.syntax.edits import apply_edits

# Groot 2's palette entry for the built-in <SubTree> (MoveIt.BT's test_mtc_groot2.xml) and
# Groot 1's for a v3 tree (aerostack2, Sigyn): with {fmt} the <root>'s attributes.
PALETTE = (
    "<root{fmt}>\n"
    '  <BehaviorTree ID="Main">\n'
    '    <SubTree ID="Grasp" target="{{goal}}"/>\n'
    "  </BehaviorTree>\n"
    '  <BehaviorTree ID="Grasp">\n'
    "    <AlwaysSuccess/>\n"
    "  </BehaviorTree>\n"
    "  <TreeNodesModel>\n"
    '    <SubTree ID="Grasp">\n'
    '      <input_port name="target"/>\n'
    '      <input_port name="_autoremap" type="bool" default="false"/>\n'
    '      <input_port name="__shared_blackboard" default="false"/>\n'
    "    </SubTree>\n"
    "  </TreeNodesModel>\n"
    "</root>\n"
)
V4 = PALETTE.format(fmt=' BTCPP_format="4" main_tree_to_execute="Main"')
UNVERSIONED = PALETTE.format(fmt=' main_tree_to_execute="Main"')


def _reserved(doc: Document, ctx: Context | None = None) -> dict[str, Diagnostic]:
    """The reserved-name findings of ``doc``, by the name they are on."""
    found = analyze(doc, ctx) if ctx is not None else analyze(doc)
    names = {"_autoremap", "__shared_blackboard"}
    return {doc.text[d.start : d.end]: d for d in found if doc.text[d.start : d.end] in names}


def _v3(doc: Document) -> Context:
    return Context.combine(doc, [], btcpp_version="3")


def test_version_4_throws_only_for_what_it_reserves() -> None:
    found = _reserved(Document(V4))
    autoremap, shared = found["_autoremap"], found["__shared_blackboard"]
    assert (autoremap.code, autoremap.severity) == ("port-name-reserved", Severity.ERROR)
    assert "4.8.4 and later throw" in autoremap.message
    assert "4.0 to 4.8.3 accepted it" in autoremap.message
    assert (shared.code, shared.severity) == ("port-name-reserved-groot2", Severity.WARNING)
    assert "BehaviorTree.CPP 4 accepts it" in shared.message and "_autoremap" in shared.message


def test_version_3_reads_no_model() -> None:
    doc = Document(UNVERSIONED)
    found = _reserved(doc, _v3(doc))
    autoremap, shared = found["_autoremap"], found["__shared_blackboard"]
    assert (autoremap.code, autoremap.severity) == ("port-name-reserved-groot2", Severity.WARNING)
    assert "BehaviorTree.CPP 3, which this project builds against" in autoremap.message
    assert (shared.code, shared.severity) == ("port-name-groot1", Severity.HINT)
    assert "Groot 1" in shared.message and "builds against BehaviorTree.CPP 3" in shared.message


def test_a_file_not_known_to_be_for_version_4() -> None:
    # No BTCPP_format and no build: checked as 4, so BehaviorTree.CPP 4's load-time throw
    # is a warning that says so, and Groot 1's palette is the hint.
    found = _reserved(Document(UNVERSIONED))
    autoremap, shared = found["_autoremap"], found["__shared_blackboard"]
    assert (autoremap.code, autoremap.severity) == ("port-name-reserved", Severity.WARNING)
    assert autoremap.message.endswith("this document has no BTCPP_format)")
    assert (shared.code, shared.severity) == ("port-name-groot1", Severity.HINT)
    assert "no BTCPP_format or build" in shared.message


def test_the_rename_fix_applies_to_the_name_rule_codes_only() -> None:
    doc = Document(V4)
    found = _reserved(doc)
    fix = fixes_for_name(doc, found["_autoremap"])[0]
    assert fix.title == "Rename '_autoremap' to 'autoremap' (1 place)"
    assert 'name="autoremap"' in apply_edits(V4, fix.edits)
    assert fixes_for_name(doc, found["__shared_blackboard"])[0].title == (
        "Rename '__shared_blackboard' to 'shared_blackboard' (1 place)"
    )
    # Groot 1's palette of a version 3 project is right as it is: nothing renames it.
    v3 = Document(UNVERSIONED)
    ctx = _v3(v3)
    hint = _reserved(v3, ctx)["__shared_blackboard"]
    assert fixes_for_name(v3, hint) == []
    fixed = apply_edits(UNVERSIONED, fix_all(v3, analyze(v3, ctx)).edits)
    assert '"__shared_blackboard"' in fixed and 'name="autoremap"' in fixed


def test_the_early_pass_leaves_them_to_the_full_analysis() -> None:
    assert early_name_diagnostics(V4) == []


def test_hover_says_what_the_diagnostic_says() -> None:
    doc = Document(V4)
    at = V4.index('"_autoremap"') + 2
    hover = hover_at(doc, at, Context.from_document(doc))
    assert hover is not None and "port-name-reserved" in hover.text
    assert "4.8.4" in hover.text and "groot2" not in hover.text
    shared = hover_at(doc, V4.index('"__shared_blackboard"') + 2, Context.from_document(doc))
    assert shared is not None and "port-name-reserved-groot2" in shared.text
    # The hint is no broken name rule: the hover describes the port.
    v3 = Document(UNVERSIONED)
    plain = hover_at(v3, UNVERSIONED.index('"__shared_blackboard"') + 2, _v3(v3))
    assert plain is not None and "port-name" not in plain.text
