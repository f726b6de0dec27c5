"""A fix never breaks a working reference: names whose target is not in the workspace.

A MoveIt Pro objective calls trees of the MoveIt Pro installation (``<SubTree
ID="Open Right Gripper">``), which keep their IDs there, and uses node types registered in
C++.  The quick fix, fix-all, rename and ``bt-lsp check --fix`` rename such a name only
together with its target: a call of a tree defined elsewhere keeps its ID, and a node type
that no ``<TreeNodesModel>`` of the workspace declares gets no preferred fix."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path
from typing import Any, cast

import pytest

from bt_lsp.ide.name_fixes import fix_all, fixes_for_name
from bt_lsp.ide.name_targets import with_targets
from bt_lsp.ide.rename import RenameRefused, rename
from bt_lsp.rules.context import ModelDecl
from bt_lsp.rules.diagnostics import Diagnostic, own_diagnostics
from bt_lsp.syntax.document import Document
from bt_lsp.syntax.edits import apply_edits
from tests.pinned import main  # bt-lsp as the tests know it (tests/pinned.py)

OBJECTIVE = (
    '<root BTCPP_format="4" main_tree_to_execute="Pick Object">\n'
    '  <BehaviorTree ID="Pick Object">\n'
    "    <Sequence>\n"
    '      <SubTree ID="Open Right Gripper"/>\n'
    '      <SubTree ID="Move To Pose" target.pose="{pose}"/>\n'
    '      <Say.Hi text="hello"/>\n'
    '      <SubTree ID="Pick Object Helper"/>\n'
    "    </Sequence>\n"
    "  </BehaviorTree>\n"
    "</root>\n"
)

# The workspace's own subtree, in another file: it can be renamed with its call.
HELPER = (
    '<root BTCPP_format="4">\n'
    '  <BehaviorTree ID="Pick Object Helper">\n'
    "    <AlwaysSuccess/>\n"
    "  </BehaviorTree>\n"
    "</root>\n"
)

# What the fixes make of OBJECTIVE: the workspace's own trees renamed, nothing else.
FIXED = OBJECTIVE.replace("Pick Object Helper", "Pick_Object_Helper").replace(
    '"Pick Object"', '"Pick_Object"'
)

OUTSIDE_TREE = (
    "the tree 'Open Right Gripper' is not defined in the workspace (it comes from "
    "elsewhere, such as an installed package, and keeps its ID there); rename it where it "
    "is defined first, then this reference"
)


def _diag(doc: Document, needle: str) -> Diagnostic:
    start = doc.text.index(needle)
    for d in own_diagnostics(doc):
        if d.is_name_rule and start <= d.start and d.end <= start + len(needle):
            return d
    raise AssertionError(f"no name diagnostic in {needle!r}")


def _docs() -> tuple[Document, dict[str, Document]]:
    return Document(OBJECTIVE, "/ws/pick.xml"), {
        "/ws/helper.xml": Document(HELPER, "/ws/helper.xml")
    }


def test_a_call_of_a_tree_defined_elsewhere_gets_no_fix() -> None:
    doc, others = _docs()
    assert fixes_for_name(doc, _diag(doc, "Open Right Gripper"), others) == []
    # Nor does a port of that call: renaming it would disconnect it from the tree's port.
    assert fixes_for_name(doc, _diag(doc, "target.pose"), others) == []


def test_rename_refuses_a_call_of_a_tree_defined_elsewhere() -> None:
    doc, others = _docs()
    at = OBJECTIVE.index("Open Right Gripper") + 2
    with pytest.raises(RenameRefused) as refused:
        rename(doc, at, "Open_Right_Gripper", others)
    assert refused.value.message == f"Cannot rename the tree 'Open Right Gripper': {OUTSIDE_TREE}"
    assert not refused.value.new_name
    at = OBJECTIVE.index("target.pose") + 2
    with pytest.raises(RenameRefused) as refused:
        rename(doc, at, "target_pose", others)
    assert refused.value.message.startswith(
        "Cannot rename the port 'target.pose' of the tree 'Move To Pose': "
    )


def test_a_tree_in_another_file_is_renamed_with_its_call() -> None:
    doc, others = _docs()
    (fix, *_) = fixes_for_name(doc, _diag(doc, "Pick Object Helper"), others)
    assert fix.preferred
    assert fix.title == (
        "Rename 'Pick Object Helper' to 'Pick_Object_Helper' (2 places, 1 other file)"
    )
    assert apply_edits(HELPER, fix.other_edits["/ws/helper.xml"]) == HELPER.replace(
        "Pick Object Helper", "Pick_Object_Helper"
    )
    # Without the other file the tree is elsewhere: no fix.
    assert fixes_for_name(doc, _diag(doc, "Pick Object Helper")) == []


def test_a_node_type_registered_elsewhere_gets_no_preferred_fix() -> None:
    doc, others = _docs()
    found = fixes_for_name(doc, _diag(doc, "Say.Hi"), others)
    assert found and not any(f.preferred for f in found)
    assert found[0].title == (
        "Rename 'Say.Hi' to 'Say_Hi' (1 place); the node type 'Say.Hi' is registered outside "
        "the workspace: rename it there too"
    )
    # Declared in a <TreeNodesModel> of the workspace: renamed with its declaration.
    models = Document(
        '<root BTCPP_format="4"><TreeNodesModel><Action ID="Say.Hi">'
        '<input_port name="text"/></Action></TreeNodesModel></root>',
        "/ws/models.xml",
    )
    (fix, *_) = fixes_for_name(doc, _diag(doc, "Say.Hi"), {**others, "/ws/models.xml": models})
    assert fix.preferred
    assert fix.title == "Rename 'Say.Hi' to 'Say_Hi' (2 places, 1 other file)"


def test_a_port_of_a_node_type_registered_elsewhere_gets_no_preferred_fix() -> None:
    doc = Document(
        '<root BTCPP_format="4"><BehaviorTree ID="T"><Spin spin.dist="1.57"/></BehaviorTree></root>'
    )
    found = fixes_for_name(doc, _diag(doc, "spin.dist"))
    assert found and not any(f.preferred for f in found)
    assert found[0].title.endswith(
        "; the port 'spin.dist' of the node type 'Spin' is registered outside the workspace: "
        "rename it there too"
    )


def test_fix_all_renames_only_names_with_their_targets() -> None:
    doc, others = _docs()
    fixed = fix_all(doc, own_diagnostics(doc), others)
    assert apply_edits(OBJECTIVE, fixed.edits) == FIXED
    assert apply_edits(HELPER, fixed.other_edits["/ws/helper.xml"]) == HELPER.replace(
        "Pick Object Helper", "Pick_Object_Helper"
    )
    assert fixed.notes == [
        f"left 'Open Right Gripper' as it is: {OUTSIDE_TREE}",
        "left 'Move To Pose' as it is: the tree 'Move To Pose' is not defined in the "
        "workspace (it comes from elsewhere, such as an installed package, and keeps its ID "
        "there); rename it where it is defined first, then this reference",
        "left 'target.pose' as it is: the tree 'Move To Pose' is not defined in the "
        "workspace (it comes from elsewhere, such as an installed package, and keeps its ID "
        "there); rename it where it is defined first, then this reference",
        "left 'Say.Hi' as it is: the node type 'Say.Hi' is registered in C++ that bt-lsp "
        "cannot see (no <TreeNodesModel> of the workspace declares it); its registration "
        "must be renamed too",
    ]


def test_an_empty_name_has_no_target_to_break() -> None:
    doc = Document(
        '<root BTCPP_format="4"><BehaviorTree ID="T"><SubTree ID=""/></BehaviorTree></root>'
    )
    # No tree can be defined under an empty ID, so no call that works can break.
    (fix,) = fixes_for_name(doc, _diag(doc, 'ID=""'))
    assert fix.preferred and fix.title == "Rename '' to 'Unnamed' (1 place)"


# -- bt-lsp check --fix --------------------------------------------------------------------


@pytest.fixture
def work(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Iterator[Path]:
    monkeypatch.chdir(tmp_path)
    yield tmp_path


def test_check_fix_keeps_calls_of_trees_defined_elsewhere(
    work: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    ws = work / "objectives"
    ws.mkdir()
    (ws / "pick.xml").write_text(OBJECTIVE, encoding="utf-8")
    (ws / "helper.xml").write_text(HELPER, encoding="utf-8")
    assert main(["check", "--fix", "objectives"]) == 1  # the outside tree stays unknown
    pick = (ws / "pick.xml").read_text(encoding="utf-8")
    helper = (ws / "helper.xml").read_text(encoding="utf-8")
    # The workspace's own trees are renamed in both files, the call included; the calls of
    # the installation's trees and the C++ node type keep their names.
    assert pick == FIXED
    assert helper == HELPER.replace("Pick Object Helper", "Pick_Object_Helper")
    err = capsys.readouterr().err
    left = f"bt-lsp: objectives/pick.xml: left 'Open Right Gripper' as it is: {OUTSIDE_TREE}\n"
    assert left in err
    assert "fixed 1 problem in objectives/helper.xml\n" in err
    # Counted as diagnostics that went away, with both files fixed: the bad ID of the
    # tree and that of the call (a hint still says the tree is in a file pick.xml does not
    # include).
    assert "fixed 2 problems in objectives/pick.xml\n" in err
    # A second run changes nothing more.
    assert main(["check", "--fix", "objectives"]) == 1
    assert (ws / "pick.xml").read_text(encoding="utf-8") == pick
    assert (ws / "helper.xml").read_text(encoding="utf-8") == helper


def test_check_fix_of_one_file_leaves_calls_into_files_not_checked(
    work: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    (work / "pick.xml").write_text(OBJECTIVE, encoding="utf-8")
    main(["check", "--fix", "pick.xml"])
    # helper.xml is not part of the check: its tree is elsewhere, so its call stays.
    assert (work / "pick.xml").read_text(encoding="utf-8") == OBJECTIVE.replace(
        '"Pick Object"', '"Pick_Object"'
    )
    assert "left 'Pick Object Helper' as it is" in capsys.readouterr().err


# -- the diagnostic says where the name must change first ----------------------------------


def _cpp_model(node_id: str, path: str, source: str = "cpp") -> dict[str, ModelDecl]:
    return {node_id: ModelDecl(node_id, "Action", (), path, 0, len(node_id), cast(Any, source))}


def test_a_node_type_registered_in_the_workspaces_cpp_is_renamed_there_first() -> None:
    # Declared in a <TreeNodesModel> of the workspace, but registered in the project's C++,
    # which bt-lsp reads and does not rewrite: renaming the XML alone breaks the node.
    doc = Document(
        '<root BTCPP_format="4"><BehaviorTree ID="T"><Say.Hi/></BehaviorTree>'
        '<TreeNodesModel><Action ID="Say.Hi"/></TreeNodesModel></root>',
        "/ws/pick.xml",
    )
    registered = _cpp_model("Say.Hi", "/ws/src/say_hi.cpp")
    found = fixes_for_name(doc, _diag(doc, "Say.Hi"), {}, registered)
    assert found and not any(f.preferred for f in found)
    assert found[0].title == (
        "Rename 'Say.Hi' to 'Say_Hi' (2 places); the node type 'Say.Hi' is registered in C++ "
        "in say_hi.cpp: rename it there too"
    )
    fixed = fix_all(doc, own_diagnostics(doc), {}, registered)
    assert fixed.edits == []
    assert fixed.notes == [
        "left 'Say.Hi' as it is: the node type 'Say.Hi' is registered in C++ in "
        "/ws/src/say_hi.cpp, which bt-lsp does not rename; its registration must be renamed too"
    ]
    (diag, *_) = with_targets(doc, own_diagnostics(doc), {}, registered)
    assert diag.message.endswith(
        "; the node type is registered in C++ in /ws/src/say_hi.cpp: rename it there first; "
        "fix-all leaves this name until then"
    )
    # Without the C++ model the workspace's declaration is the target: renamed with it.
    (fix, *_) = fixes_for_name(doc, _diag(doc, "Say.Hi"), {})
    assert fix.preferred and fix.title == "Rename 'Say.Hi' to 'Say_Hi' (2 places)"


def test_a_node_type_of_an_installed_catalog_is_renamed_there_first() -> None:
    doc = Document(
        '<root BTCPP_format="4"><BehaviorTree ID="T"><Say.Hi/></BehaviorTree></root>',
        "/ws/pick.xml",
    )
    registered = _cpp_model("Say.Hi", "/opt/ros/share/talk/nodes.xml", "ros")
    (fix, *_) = fixes_for_name(doc, _diag(doc, "Say.Hi"), {}, registered)
    assert not fix.preferred
    assert fix.title.endswith(
        "; the node type 'Say.Hi' is declared in nodes.xml, outside the workspace: "
        "rename it there too"
    )
    (diag, *_) = with_targets(doc, own_diagnostics(doc), {}, registered)
    assert diag.message.endswith(
        "; the node type is declared in the node catalog /opt/ros/share/talk/nodes.xml, "
        "outside the workspace: rename it there first; fix-all leaves this name until then"
    )


def test_check_reports_where_a_name_must_change_first(
    work: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    (work / "pick.xml").write_text(OBJECTIVE, encoding="utf-8")
    main(["check", "pick.xml"])
    out = capsys.readouterr().out
    assert (
        "error model-name-forbidden-char Model name 'Open Right Gripper' contains 2 "
        "forbidden characters: ' ' (space) at columns 5 and 11; whitespace breaks XML "
        "element/attribute names; the tree is not defined in this workspace: rename it "
        "where it is defined first; this call keeps its ID until then\n"
    ) in out
