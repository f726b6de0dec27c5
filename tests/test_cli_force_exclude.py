"""``bt-lsp check --force-exclude FILE...``: the files named on the command line are left
out as a walk over their workspace folder leaves them out (``exclude`` globs, build, VCS
and hidden folders, XML that is not BehaviorTree.CPP's), so a pre-commit hook can pass
the changed files: each is reported exactly as ``check FOLDER`` reports it, and a run
whose files are all left out is quiet and succeeds."""

from __future__ import annotations

import json
import os
import shutil
from collections.abc import Iterator
from pathlib import Path

import pytest

from bt_lsp.cli.main import main

PKG = Path(__file__).parent / "data" / "ros_pkg" / "my_robot_bt"

# What the package's walk leaves out, each for its own reason.
LEFT_OUT = (
    "package.xml",
    "plugins.xml",
    "launch/robot.launch.xml",
    "urdf/robot.urdf.xml",
    "generated/broken.xml",  # the exclude glob of bt-lsp.toml
    "build/tmp/copied.xml",  # broken BT XML in colcon's build folder
    "log/latest.xml",
)

MAIN = """\
<root BTCPP_format="4" main_tree_to_execute="Main Tree">
  <BehaviorTree ID="Main Tree">
    <Sequence>
      <SubTree ID="Dock"/>
      <Fallbak/>
    </Sequence>
  </BehaviorTree>
</root>
"""
DOCK = """\
<root BTCPP_format="4">
  <BehaviorTree ID="Dock">
    <SubTree ID="Missing"/>
  </BehaviorTree>
</root>
"""


@pytest.fixture
def pkg(tmp_path: Path) -> Path:
    dest = tmp_path / "my_robot_bt"
    shutil.copytree(PKG, dest)
    return dest


@pytest.fixture
def repo(tmp_path: Path) -> Iterator[Path]:
    """A repository (its root is the workspace of its files), as the working directory,
    as pre-commit runs a hook."""
    (tmp_path / ".git").mkdir()
    (tmp_path / "trees").mkdir()
    (tmp_path / "trees" / "main.xml").write_text(MAIN, encoding="utf-8")
    (tmp_path / "trees" / "dock.xml").write_text(DOCK, encoding="utf-8")
    (tmp_path / "package.xml").write_text("<package><name>p</name></package>\n")
    old = os.getcwd()
    os.chdir(tmp_path)
    try:
        yield tmp_path
    finally:
        os.chdir(old)


def run(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    code = main(["check", "--no-progress", "--no-cpp", *argv])
    out, err = capsys.readouterr()
    return code, out, err


def test_every_file_left_out_is_quiet_and_succeeds(
    pkg: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    files = [str(pkg / f) for f in LEFT_OUT]
    assert run(capsys, "--force-exclude", *files) == (0, "", "")
    # Without the flag the same files are checked as given, and fail.
    code, out, _ = run(capsys, *files)
    assert code == 1 and str(pkg / "package.xml") in out


def test_verbose_says_why_each_was_left_out(pkg: Path, capsys: pytest.CaptureFixture[str]) -> None:
    files = [str(pkg / f) for f in LEFT_OUT]
    code, out, err = run(capsys, "--force-exclude", "--verbose", *files)
    assert (code, out) == (0, "")
    assert err.splitlines() == [
        "bt-lsp: skipped 1 file: excluded",
        "bt-lsp: skipped 2 files: in build, install, log, VCS or hidden folders",
        "bt-lsp: skipped 4 files: not BehaviorTree.CPP XML",
    ]


def test_machine_formats_still_get_a_document(
    pkg: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    code, out, err = run(capsys, "--force-exclude", "--format", "json", str(pkg / "package.xml"))
    assert (code, json.loads(out), err) == (0, [], "")


def test_the_trees_among_them_are_checked(pkg: Path, capsys: pytest.CaptureFixture[str]) -> None:
    (pkg / "behavior_trees" / "sub.xml").write_text(
        '<root BTCPP_format="4"><BehaviorTree ID="Sub"><Fallbak/></BehaviorTree></root>'
    )
    files = [str(pkg / f) for f in (*LEFT_OUT, "behavior_trees/sub.xml")]
    code, out, err = run(capsys, "--force-exclude", *files)
    assert code == 0  # a warning
    assert {line.split(":")[0] for line in out.splitlines()} == {
        str(pkg / "behavior_trees" / "sub.xml")
    }
    assert " warning unknown-node " in out
    assert err.splitlines()[-1].endswith("in 1 file")


def _lines_of(out: str, path: str) -> list[str]:
    return [line for line in out.splitlines() if line.startswith(path + ":")]


def test_a_named_file_gets_what_its_folder_check_gives(
    repo: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Dock, defined in another file, resolves; the other file's problems are not
    reported; the findings of each file are those of the check of the whole repository."""
    _, whole, _ = run(capsys, ".")
    for name in ("trees/main.xml", "trees/dock.xml"):
        code, out, _ = run(capsys, "--force-exclude", name, "package.xml")
        assert code == 1
        assert out.splitlines() == _lines_of(whole, name), name
    _, out, _ = run(capsys, "--force-exclude", "trees/main.xml")
    assert "model-name-forbidden-char" in out
    assert "error unknown-subtree" not in out  # Dock is defined in dock.xml
    assert "Missing" not in out  # dock.xml's problem, and dock.xml did not change


def test_hidden_and_excluded_folders_leave_their_files_out(
    repo: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    for folder in (".ci", "node_modules/x", "install", "gen/deep"):
        (repo / folder).mkdir(parents=True)
        shutil.copy(repo / "trees" / "main.xml", repo / folder / "main.xml")
    shutil.copy(repo / "trees" / "main.xml", repo / "trees" / ".hidden.xml")
    (repo / "bt-lsp.toml").write_text('exclude = ["gen", "trees/skip.xml"]\n')
    shutil.copy(repo / "trees" / "main.xml", repo / "trees" / "skip.xml")
    named = [
        ".ci/main.xml",
        "node_modules/x/main.xml",
        "install/main.xml",
        "gen/deep/main.xml",
        "trees/.hidden.xml",
        "trees/skip.xml",
    ]
    assert run(capsys, "--force-exclude", *named) == (0, "", "")
    # A walk over the repository reports none of them either.
    _, whole, _ = run(capsys, ".")
    assert {line.split(":")[0] for line in whole.splitlines()} == {
        "trees/main.xml",
        "trees/dock.xml",
    }


def test_a_named_file_that_a_tree_includes_is_checked(
    repo: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A file that does not look like BT XML is loaded as such when a tree includes it,
    even when the including file is not among the named ones."""
    (repo / "trees" / "main.xml").write_text(
        '<root BTCPP_format="4" main_tree_to_execute="M"><include path="part.xml"/>'
        '<BehaviorTree ID="M"><AlwaysSuccess/></BehaviorTree></root>'
    )
    (repo / "trees" / "part.xml").write_text("<Root/>")
    (repo / "trees" / "lone.xml").write_text("<Root/>")
    code, out, _ = run(capsys, "--force-exclude", "trees/part.xml", "trees/lone.xml")
    assert code == 1
    assert {line.split(":")[0] for line in out.splitlines()} == {"trees/part.xml"}
    assert " error root-element " in out
    _, whole, _ = run(capsys, ".")
    assert out.splitlines() == _lines_of(whole, "trees/part.xml")


def test_folders_are_walked_as_before(pkg: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert run(capsys, "--force-exclude", str(pkg))[:2] == run(capsys, str(pkg))[:2]
