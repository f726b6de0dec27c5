"""Noise control of ``bt-lsp check``: ``--min-severity`` (and ``min-severity`` in
bt-lsp.toml, ``minSeverity`` in the editor) leaves out the less severe diagnostics,
``--quiet`` prints the diagnostics only, and the summary counts the BT files checked."""

from __future__ import annotations

from pathlib import Path

import pytest

from bt_lsp.project.settings import Settings
from bt_lsp.rules.codes import Severity
from tests.pinned import main  # bt-lsp as the tests know it (tests/pinned.py)

# An error (a built-in's missing port), a warning (an unknown underscore attribute close to
# a reserved one) and a hint (a custom node's port without a default).
TREE = """<root BTCPP_format="4" main_tree_to_execute="Main">
  <BehaviorTree ID="Main">
    <Sequence>
      <Sleep/>
      <AlwaysSuccess _skipIff="x"/>
      <Say/>
    </Sequence>
  </BehaviorTree>
  <TreeNodesModel>
    <Action ID="Say"><input_port name="message"/></Action>
  </TreeNodesModel>
</root>
"""


def run(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    code = main(["check", "--no-progress", "--no-cpp", *argv])
    out, err = capsys.readouterr()
    return code, out, err


def levels(out: str) -> list[str]:
    return [line.split(": ", 1)[1].split()[0] for line in out.splitlines()]


@pytest.fixture
def tree(tmp_path: Path) -> Path:
    (tmp_path / "t.xml").write_text(TREE)
    return tmp_path / "t.xml"


def test_all_levels_by_default(tree: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code, out, err = run(capsys, str(tree))
    assert code == 1
    assert sorted(levels(out)) == ["error", "hint", "warning"]
    assert err == "1 error, 1 warning, 1 hint in 1 file\n"


def test_min_severity_flag(tree: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code, out, err = run(capsys, "--min-severity", "error", str(tree))
    assert code == 1
    assert levels(out) == ["error"]
    assert err == "1 error, 0 warnings in 1 file\n"
    _, out, _ = run(capsys, "--min-severity", "warning", str(tree))
    assert sorted(levels(out)) == ["error", "warning"]


def test_min_severity_in_the_configuration(tree: Path, capsys: pytest.CaptureFixture[str]) -> None:
    (tree.parent / "bt-lsp.toml").write_text('min-severity = "warning"\n')
    _, out, _ = run(capsys, str(tree))
    assert sorted(levels(out)) == ["error", "warning"]
    _, out, _ = run(capsys, "--min-severity", "hint", str(tree))  # the flag wins
    assert sorted(levels(out)) == ["error", "hint", "warning"]
    (tree.parent / "bt-lsp.toml").write_text('min-severity = "off"\n')
    code, _, err = run(capsys, str(tree))
    assert code == 2
    assert "config-error 'min-severity' must be" in err


def test_quiet_prints_the_diagnostics_only(tree: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code, out, err = run(capsys, "--quiet", "--min-severity", "error", str(tree))
    assert code == 1
    assert levels(out) == ["error"]
    assert err == ""
    (tree.parent / "package.xml").write_text("<package/>")
    tree.unlink()
    code, out, err = run(capsys, "-q", str(tree.parent))
    assert (code, out, err) == (0, "", "")


def test_no_files_in_json_is_still_json(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    (tmp_path / "package.xml").write_text("<package/>")
    code, out, _ = run(capsys, "--format", "json", str(tmp_path))
    assert (code, out) == (0, "[]\n")


def test_the_summary_counts_the_bt_files(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Not the C++ files a folder run reads for the name rules, nor the skipped XML."""
    (tmp_path / "t.xml").write_text(TREE.replace("<Sleep/>", '<Sleep msec="1"/>'))
    (tmp_path / "nodes.cpp").write_text('void f(F& f) { f.registerNodeType<Say>("Say"); }\n')
    (tmp_path / "package.xml").write_text("<package/>")
    code = main(["check", "--no-progress", str(tmp_path)])
    _, err = capsys.readouterr()
    assert code == 0
    assert err.endswith(" in 1 file\n")


def test_the_editor_setting() -> None:
    problems: list[str] = []
    assert Settings.parse({"minSeverity": "warning"}).min_severity == Severity.WARNING
    assert Settings.parse({"minSeverity": "off"}, problems) == Settings()
    assert Settings.parse({"minSeverity": 2}, problems) == Settings()
    assert len(problems) == 2 and "minSeverity must be one of" in problems[0]
