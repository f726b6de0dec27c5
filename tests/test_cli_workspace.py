"""A file named alone on the command line is checked in its project: the same diagnostics
as a run over the project's folder gives it, so that a pre-commit hook (which passes file
names) and CI (which passes the folder) agree.  The workspace is found upward: the folder
of a bt-lsp.toml, the repository root, the ROS workspace's src folder or the package."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

from bt_lsp.cli.project import workspace_of
from tests.pinned import main  # bt-lsp as the tests know it (tests/pinned.py)

CPP_PROJECT = Path(__file__).parent / "data" / "cpp_project"

MAIN = """<root BTCPP_format="4" main_tree_to_execute="Main">
  <include path="sub.xml"/>
  <BehaviorTree ID="Main">
    <Sequence>
      <Say/>
      <SubTree ID="Sub"/>
      <SubTree ID="Announce"/>
      <SubTree ID="Elsewhere"/>
    </Sequence>
  </BehaviorTree>
</root>
"""
SUB = '<root BTCPP_format="4"><BehaviorTree ID="Sub"><Say message="x"/></BehaviorTree></root>\n'
OTHER = (
    '<root BTCPP_format="4"><BehaviorTree ID="Elsewhere"><AlwaysSuccess/></BehaviorTree></root>\n'
)
# A catalog in another file: Say has a port without a default; Announce is a node, not a
# tree, so <SubTree ID="Announce"> names no tree.
MODELS = (
    '<root BTCPP_format="4"><TreeNodesModel><Action ID="Say"><input_port name="message"/>'
    '</Action><Action ID="Announce"/></TreeNodesModel></root>\n'
)


def findings(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, list[dict[str, object]]]:
    code = main(["check", "--no-progress", "--format", "json", *argv])
    out, _ = capsys.readouterr()
    return code, json.loads(out or "[]")


def same_as_the_folder_run(
    capsys: pytest.CaptureFixture[str], folder: Path, file: Path, *flags: str
) -> list[dict[str, object]]:
    """The file's findings, asserted to be those the folder run reports for it."""
    _, whole = findings(capsys, *flags, str(folder))
    code, alone = findings(capsys, *flags, str(file))
    mine = [d for d in whole if d["path"] == str(file)]
    assert alone == mine
    assert code == (1 if any(d["severity"] == "error" for d in alone) else 0)
    return alone


def codes(found: list[dict[str, object]]) -> list[str]:
    return sorted(str(d["code"]) for d in found)


def write_project(top: Path) -> Path:
    (top / "trees").mkdir(parents=True)
    (top / "models").mkdir()
    (top / "trees" / "main.xml").write_text(MAIN)
    (top / "trees" / "sub.xml").write_text(SUB)
    (top / "trees" / "other.xml").write_text(OTHER)
    (top / "models" / "nodes.xml").write_text(MODELS)
    return top / "trees" / "main.xml"


def test_a_configuration_in_a_parent_makes_the_workspace(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Included trees, a catalog in another folder, a tree another file defines."""
    (tmp_path / "bt-lsp.toml").write_text("")
    main_xml = write_project(tmp_path)
    assert workspace_of(main_xml) == (tmp_path, "the folder of bt-lsp.toml")
    found = same_as_the_folder_run(capsys, tmp_path, main_xml)
    # Say's port is known from the catalog, Elsewhere is another file's tree (a hint),
    # Announce a node of the catalog but no tree: the error BehaviorTree.CPP's VerifyXML
    # gives at load (a registered name), in both runs.
    assert codes(found) == [
        "missing-port-without-default",
        "registered-name-as-tree-id",
        "unknown-subtree",
    ]
    assert [d["severity"] for d in found if d["code"] != "missing-port-without-default"] == [
        "error",
        "hint",
    ]


def test_the_repository_root_makes_the_workspace(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    (tmp_path / ".git").mkdir()
    main_xml = write_project(tmp_path / "robot")
    assert workspace_of(main_xml) == (tmp_path, "the repository root")
    assert len(same_as_the_folder_run(capsys, tmp_path, main_xml)) == 3


def test_models_from_the_configuration(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A catalog the configuration names (its models are authoritative)."""
    main_xml = write_project(tmp_path)
    (tmp_path / "bt-lsp.toml").write_text('models = ["models/nodes.xml"]\n')
    found = same_as_the_folder_run(capsys, tmp_path, main_xml)
    assert "unknown-subtree" in codes(found)


def test_cpp_registrations_of_a_ros_workspace(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Nodes registered in the packages' C++: the file alone sees them too."""
    ws = tmp_path / "ws"
    shutil.copytree(CPP_PROJECT, ws)
    tree = ws / "src" / "robot_nodes" / "trees" / "main.xml"
    assert workspace_of(tree) == (ws / "src", "the ROS workspace's src folder")
    same_as_the_folder_run(capsys, ws / "src", tree)
    same_as_the_folder_run(capsys, ws / "src", tree, "--no-cpp")
    # Without the C++, the run differs: the registrations were seen.
    _, with_cpp = findings(capsys, str(tree))
    _, without = findings(capsys, "--no-cpp", str(tree))
    assert with_cpp != without


def test_a_lone_file_is_its_own_folder(tmp_path: Path) -> None:
    (tmp_path / "t.xml").write_text(SUB)
    assert workspace_of(tmp_path / "t.xml") == (tmp_path, "the file's folder")
    pkg = tmp_path / "pkg"
    (pkg / "trees").mkdir(parents=True)
    (pkg / "package.xml").write_text("<package><name>pkg</name></package>")
    assert workspace_of(pkg / "trees" / "t.xml") == (pkg, "the ROS package")


def test_a_file_under_a_named_folder_keeps_that_folder(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    (tmp_path / ".git").mkdir()
    main_xml = write_project(tmp_path / "robot")
    (tmp_path / "robot" / "models" / "nodes.xml").unlink()
    (tmp_path / "catalog.xml").write_text(MODELS)  # outside the named folder
    _, found = findings(capsys, str(tmp_path / "robot"), str(main_xml))
    assert "unknown-node" in codes(found)  # Say: the catalog is not in the workspace
    _, alone = findings(capsys, str(main_xml))
    assert "unknown-node" not in codes(alone)


def test_verbose_says_the_workspace(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    (tmp_path / ".git").mkdir()
    main_xml = write_project(tmp_path / "robot")
    main(["check", "--no-progress", "--verbose", str(main_xml)])
    _, err = capsys.readouterr()
    assert f"bt-lsp: workspace {tmp_path} (the repository root) for 1 named file" in err
