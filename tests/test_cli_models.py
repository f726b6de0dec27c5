"""``bt-lsp models``: the learned catalog as a TreeNodesModel document or JSON."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest
from lxml import etree

from bt_lsp.cli.main import main
from bt_lsp.syntax.document import Document

DATA = Path(__file__).parent / "data" / "cpp"


@pytest.fixture(autouse=True)
def _cache(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))


def test_xml_has_writeTreeNodesModelXML_shape(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["models", str(DATA / "register_node_type"), str(DATA / "ros2")]) == 0
    out = capsys.readouterr().out
    root = etree.fromstring(out.encode())
    assert root.tag == "root" and root.get("BTCPP_format") == "4"
    (model,) = root
    assert model.tag == "TreeNodesModel"
    ids = [(el.tag, el.get("ID")) for el in model if isinstance(el.tag, str)]
    assert ids == [
        ("Action", "Fibonacci"),
        ("Decorator", "Gate"),
        ("Condition", "IsReady"),
        ("Control", "Pick"),
        ("Condition", "ReceiveString"),
        ("Action", "SaySomething"),
    ]
    say = model.find("Action[@ID='SaySomething']")
    assert say is not None
    pause = say.find("input_port[@name='pause']")
    assert pause is not None
    assert (pause.get("type"), pause.get("default"), pause.text) == (
        "double",
        "0.500000",  # BT::toStr of the double 0.5, as writeTreeNodesModelXML writes it
        "seconds between two",
    )
    anything = say.find("input_port[@name='anything']")
    assert anything is not None and anything.get("type") is None  # untyped: no type attribute
    assert say.find("inout_port[@name='queue']") is not None
    last = say.find("output_port[@name='last']")
    assert last is not None and last.get("default") == "{last_count}"


def test_xml_output_is_a_clean_bt_lsp_document(capsys: pytest.CaptureFixture[str]) -> None:
    """What `models` prints is a model file bt-lsp itself reads without a diagnostic."""
    from bt_lsp.rules.analysis import analyze

    main(["models", str(DATA / "register_node_type"), str(DATA / "inheritance")])
    out = capsys.readouterr().out
    assert analyze(Document(out)) == []


def test_xml_says_what_it_cannot_know_in_comments(capsys: pytest.CaptureFixture[str]) -> None:
    main(["models", str(DATA / "limits")])
    out = capsys.readouterr().out
    assert "<!-- Vendored: kind unknown (base class vendor::FancyAction" in out
    root = etree.fromstring(out.encode())
    timeout = root.find(".//Action[@ID='Wait']/input_port[@name='timeout']")
    assert timeout is not None and timeout.get("default") is None
    assert "std::numeric_limits<double>::infinity()" in "".join(
        c.text or "" for c in timeout.iter(etree.Comment)
    )


def test_json_gives_positions_and_flags(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["models", "--format", "json", str(DATA / "limits")]) == 0
    doc = json.loads(capsys.readouterr().out)
    nodes = {n["id"]: n for n in doc["nodes"]}
    spin = nodes["Spin"]
    assert spin["kind"] == "Action" and spin["authoritative"] is False
    assert spin["flags"] == ["ports-incomplete"]
    assert spin["registered"]["path"].endswith("limits/nodes.cpp")
    assert spin["registered"]["line"] == 62 and spin["registered"]["column"] == 34
    assert spin["classDeclared"]["line"] == 29
    wait = nodes["Wait"]["ports"][0]
    assert wait["defaultIsExpression"] is True
    assert wait["declared"]["line"] == 10
    assert doc["unresolved"] == [
        {
            "form": "registerLater",
            "name": "computed_name",
            "path": doc["unresolved"][0]["path"],
            "line": 66,
            "column": 32,
            "endLine": 66,
            "endColumn": 45,
        }
    ]


def test_missing_path_is_exit_2(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    assert main(["models", str(tmp_path / "nope")]) == 2
    assert "no such file" in capsys.readouterr().err


def test_console_script_with_progress(tmp_path: Path) -> None:
    env = {"XDG_CACHE_HOME": str(tmp_path), "PYTHONPATH": str(Path(__file__).parents[1] / "src")}
    r = subprocess.run(
        [sys.executable, "-m", "bt_lsp", "models", "--verbose", str(DATA / "macro")],
        capture_output=True,
        text=True,
        env=env,
        check=True,
    )
    assert '<Action ID="Dock">' in r.stdout
    assert "reading C++: 2/2 files" in r.stderr
    assert list(tmp_path.rglob("*.json"))  # the cache was written
