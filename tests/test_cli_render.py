"""``bt-lsp render``: end to end through the command line, with the file's folder as the
workspace (models and trees of the other files, includes)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest
from lxml import etree

from bt_lsp.cli.main import main

SVG = "{http://www.w3.org/2000/svg}"

MAIN = """<root BTCPP_format="4" main_tree_to_execute="Main">
  <include path="nav.xml"/>
  <BehaviorTree ID="Main">
    <Sequence name="mission">
      <Charge level="{battery}"/>
      <SubTree ID="Navigate"/>
      <SubTree ID="Dock"/>
      <Inverter><AlwaysSuccess/><AlwaysFailure/></Inverter>
    </Sequence>
  </BehaviorTree>
  <BehaviorTree ID="Other">
    <AlwaysSuccess name="only"/>
  </BehaviorTree>
</root>
"""
NAV = """<root BTCPP_format="4">
  <BehaviorTree ID="Navigate">
    <Fallback><IsArrived/><MoveBase goal="{goal}"/></Fallback>
  </BehaviorTree>
</root>
"""
DOCK = """<root BTCPP_format="4">
  <BehaviorTree ID="Dock"><Align/></BehaviorTree>
</root>
"""
MODELS = """<root BTCPP_format="4">
  <TreeNodesModel>
    <Action ID="Charge"><input_port name="level"/></Action>
    <Condition ID="IsArrived"/>
    <Action ID="MoveBase"><input_port name="goal"/></Action>
    <Action ID="Align"/>
  </TreeNodesModel>
</root>
"""


@pytest.fixture
def ws(tmp_path: Path) -> Path:
    (tmp_path / "main.xml").write_text(MAIN)
    (tmp_path / "nav.xml").write_text(NAV)
    (tmp_path / "dock.xml").write_text(DOCK)
    (tmp_path / "models.xml").write_text(MODELS)
    return tmp_path


def _svg(text: str) -> etree._Element:
    return etree.fromstring(text.encode())


def _attr(el: etree._Element, name: str) -> str:
    value = el.get(name)
    assert value is not None, name
    return value


def _nodes(svg: etree._Element) -> list[tuple[str | None, str | None]]:
    return [
        (g.get("data-kind"), g.get("data-type"))
        for g in svg.iter(f"{SVG}g")
        if "node" in (g.get("class") or "").split()
    ]


def test_svg_of_the_main_tree(ws: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["render", str(ws / "main.xml")]) == 0
    svg = _svg(capsys.readouterr().out)
    assert svg.get("data-tree") == "Main"
    assert _nodes(svg) == [
        ("tree", "Main"),
        ("control", "Sequence"),
        ("action", "Charge"),  # declared in models.xml, another file of the folder
        ("subtree", "Navigate"),
        ("subtree", "Dock"),
        ("decorator", "Inverter"),
        ("action", "AlwaysSuccess"),
        ("action", "AlwaysFailure"),
    ]
    # The Inverter has two children: BehaviorTree.CPP refuses it, and check says so.
    inverter = next(g for g in svg.iter(f"{SVG}g") if g.get("data-type") == "Inverter")
    assert "sev-error" in _attr(inverter, "class")
    sequence = next(g for g in svg.iter(f"{SVG}g") if g.get("data-type") == "Sequence")
    assert "sev-" not in _attr(sequence, "class")
    start, end = int(_attr(inverter, "data-start")), int(_attr(inverter, "data-end"))
    assert MAIN[start:end].startswith("<Inverter>") and MAIN[start:end].endswith("</Inverter>")


def test_expanded_subtrees_come_from_other_files(
    ws: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["render", str(ws / "main.xml"), "--expand-subtrees", "--ports"]) == 0
    svg = _svg(capsys.readouterr().out)
    nodes = _nodes(svg)
    assert ("condition", "IsArrived") in nodes and ("action", "MoveBase") in nodes  # included
    assert ("action", "Align") in nodes  # dock.xml: a workspace file, not included
    move = next(g for g in svg.iter(f"{SVG}g") if g.get("data-type") == "MoveBase")
    assert move.get("data-source") == str(ws / "nav.xml")
    keys = [t.text for t in svg.iter(f"{SVG}tspan") if t.get("class") == "key"]
    assert keys == ["{battery}", "{goal}"]


def test_tree_option_mermaid_and_dot(ws: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["render", str(ws / "main.xml"), "--tree", "Other", "--format", "mermaid"]) == 0
    out = capsys.readouterr().out
    assert out.splitlines() == [
        "flowchart TD",
        '  n0>"Other"]',
        '  n1("AlwaysSuccess<br>#quot;only#quot;")',
        "  n0 --> n1",
        *[ln for ln in out.splitlines() if ln.startswith("  class")],
    ]
    assert main(["render", str(ws / "main.xml"), "--format", "dot"]) == 0
    dot = capsys.readouterr().out
    assert dot.startswith('digraph "Main" {') and 'n2 [label="Charge' in dot
    assert dot.count(" -> ") == 7


def test_output_file(ws: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = ws / "out" / "tree.svg"
    out.parent.mkdir()
    assert main(["render", str(ws / "main.xml"), "-o", str(out)]) == 0
    assert capsys.readouterr().out == ""
    assert _svg(out.read_text()).get("data-tree") == "Main"


def test_unknown_tree_exits_2(ws: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["render", str(ws / "main.xml"), "--tree", "Nope"]) == 2
    err = capsys.readouterr().err
    assert "no tree 'Nope'" in err and "'Main', 'Other'" in err


def test_unreadable_file_exits_2(ws: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["render", str(ws / "missing.xml")]) == 2
    assert "missing.xml" in capsys.readouterr().err
    (ws / "bad.xml").write_bytes(b"<root>\xff\xfe\xfa</root>")
    assert main(["render", str(ws / "bad.xml")]) == 2
    assert "bad.xml" in capsys.readouterr().err


def test_file_without_trees_exits_2(ws: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["render", str(ws / "models.xml")]) == 2
    assert "no <BehaviorTree>" in capsys.readouterr().err


def test_output_that_cannot_be_written(ws: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["render", str(ws / "main.xml"), "-o", str(ws / "no" / "such" / "x.svg")]) == 2
    assert "cannot write" in capsys.readouterr().err


def test_installed_command(ws: Path) -> None:
    r = subprocess.run(
        [sys.executable, "-m", "bt_lsp", "render", "main.xml", "--format", "mermaid"],
        cwd=ws,
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert r.returncode == 0, r.stderr
    assert r.stdout.startswith("flowchart TD\n")


ROOT = Path(__file__).resolve().parent.parent
EXAMPLE = ROOT / "docs" / "tree" / "mission.xml"


def test_documented_pictures_are_current(capsys: pytest.CaptureFixture[str]) -> None:
    """The pictures page's Mermaid block is what `render --format mermaid` prints for it, and
    the SVG it shows has the nodes `render` draws now."""
    readme = (ROOT / "docs" / "pictures.md").read_text(encoding="utf-8")
    assert main(["render", str(EXAMPLE), "--tree", "Dock", "--format", "mermaid"]) == 0
    mermaid = capsys.readouterr().out
    assert f"```mermaid\n{mermaid}```\n" in readme
    assert main(["render", str(EXAMPLE), "--ports", "--expand-subtrees"]) == 0
    now = _nodes(_svg(capsys.readouterr().out))
    shown = _nodes(etree.parse(str(EXAMPLE.with_suffix(".svg"))).getroot())
    assert shown == now and ("subtree", "Dock") in now and ("action", "Align") in now
    assert "](tree/mission.svg)" in readme and "/editors/vscode/images/tree.png)" in readme
    assert (ROOT / "editors" / "vscode" / "images" / "tree.png").is_file()


def test_configured_severities_colour_the_nodes(
    ws: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The badges are what `check` reports with the project's configuration: a code made a
    warning draws a warning, a code turned off draws none."""

    def inverter_class() -> str:
        assert main(["render", str(ws / "main.xml")]) == 0
        svg = _svg(capsys.readouterr().out)
        return _attr(
            next(g for g in svg.iter(f"{SVG}g") if g.get("data-type") == "Inverter"), "class"
        )

    (ws / "bt-lsp.toml").write_text('[severity]\nchild-count = "warning"\n')
    assert "sev-warning" in inverter_class()
    (ws / "bt-lsp.toml").write_text('[severity]\nchild-count = "off"\n')
    assert "sev-" not in inverter_class()
