"""The ecosystem check's comparison: triage matching, stale lines, the gates, the catalog."""

from __future__ import annotations

import importlib.util
import json
import sys
from pathlib import Path
from types import ModuleType

import pytest

ROOT = Path(__file__).resolve().parent.parent


def _load() -> ModuleType:
    spec = importlib.util.spec_from_file_location("ecosystem", ROOT / "scripts" / "ecosystem.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules["ecosystem"] = module
    spec.loader.exec_module(module)
    return module


eco = _load()
HEADER = "project\tpath\tline\tcode\tverdict\treason\n"


def _finding(path: str, line: int, code: str, severity: str, message: str = "m") -> object:
    return eco.Finding("p", path, line, code, severity, message)


def _triage(tmp_path: Path, *rows: str) -> list[object]:
    f = tmp_path / "triage.tsv"
    f.write_text(HEADER + "".join(r + "\n" for r in rows), encoding="utf-8")
    return list(eco.read_triage([f]))


def test_a_triage_line_matches_every_finding_with_its_key(tmp_path: Path) -> None:
    triage = _triage(tmp_path, "p\ta.xml\t3\tundeclared-port\tfalse\tclass: x")
    findings = [
        _finding("a.xml", 3, "undeclared-port", "warning", "port a"),
        _finding("a.xml", 3, "undeclared-port", "warning", "port b"),
        _finding("a.xml", 4, "undeclared-port", "warning"),
    ]
    report = eco.compare(findings, triage, ["p"])
    assert [(f.line, f.code) for f in report.untriaged] == [(4, "undeclared-port")]
    assert len(report.false_warnings) == 2
    assert report.stale == []
    assert report.failures  # untriaged, and 2 of 3 warnings are false


def test_stale_lines_are_listed_and_do_not_fail(tmp_path: Path) -> None:
    triage = _triage(
        tmp_path,
        "p\ta.xml\t1\troot-element\tfalse\tclass: non-BT XML",
        "p\tb.xml\t2\tunknown-node\ttrue\treal",
        "other\tc.xml\t1\tx\ttrue\tnot run, not stale",
    )
    findings = [_finding("b.xml", 2, "unknown-node", "error")]
    report = eco.compare(findings, triage, ["p"])
    assert [(t.path, t.line) for t in report.stale] == [("a.xml", 1)]
    assert report.true_errors == 1
    assert report.failures == []


def test_a_finding_that_became_a_hint_leaves_its_line_stale(tmp_path: Path) -> None:
    triage = _triage(tmp_path, "p\ta.xml\t1\tunknown-node\tfalse\tclass: y")
    report = eco.compare([_finding("a.xml", 1, "unknown-node", "hint")], triage, ["p"])
    assert len(report.stale) == 1
    assert report.counts_by_code["unknown-node"]["hint"] == 1
    assert report.failures == []


def test_gates_false_error_and_false_warning_percentage(tmp_path: Path) -> None:
    rows = [f"p\tw.xml\t{n}\tw\ttrue\tok" for n in range(1, 20)]
    rows.append("p\tw.xml\t20\tw\tfalse\tclass: z")
    triage = _triage(tmp_path, *rows)
    warnings = [_finding("w.xml", n, "w", "warning") for n in range(1, 21)]
    report = eco.compare(warnings, triage, ["p"])
    assert report.false_warning_percent == pytest.approx(5.0)
    assert report.failures == []  # 5% is allowed, more is not
    report = eco.compare(warnings[1:], triage, ["p"])
    assert report.false_warning_percent > 5.0
    assert any("false warnings" in f for f in report.failures)
    triage = _triage(tmp_path, "p\te.xml\t1\te\tfalse\tclass: z")
    report = eco.compare([_finding("e.xml", 1, "e", "error")], triage, ["p"])
    assert report.failures == ["1 false error(s)"]


def test_malformed_triage_is_refused(tmp_path: Path) -> None:
    f = tmp_path / "t.tsv"
    f.write_text(HEADER + "p\ta.xml\t1\tcode\tmaybe\treason\n", encoding="utf-8")
    with pytest.raises(ValueError, match="verdict"):
        eco.read_triage([f])
    f.write_text("path\tline\n", encoding="utf-8")
    with pytest.raises(ValueError, match="first line"):
        eco.read_triage([f])


def test_own_unknown_node_hints_come_from_registration_literals(tmp_path: Path) -> None:
    (tmp_path / "src").mkdir()
    (tmp_path / "src" / "nodes.cpp").write_text(
        'BT_REGISTER_NODES(factory)\n{\n  factory.registerNodeType<Mine>("MyNode");\n}\n'
        'const char* other = "NotANode";\n'
        'REGISTER_BUILDER(Builder)\nfactory.registerBuilder<X>(\n    "Built", builder);\n',
        encoding="utf-8",
    )
    names = eco.registered_literals(tmp_path)
    assert {"MyNode", "Built"} <= names
    assert "NotANode" not in names
    hints = [
        _finding("a.xml", 1, "unknown-node", "hint", "Node type 'MyNode' is not a built-in"),
        _finding("a.xml", 2, "unknown-node", "hint", "Node type 'Elsewhere' is not a built-in"),
    ]
    report = eco.compare(hints, [], ["p"], {"p": names})
    assert report.own_unknown_nodes["p"] == 1


def test_write_template_appends_one_line_per_key(tmp_path: Path) -> None:
    out = tmp_path / "new.tsv"
    findings = [
        _finding("a.xml", 3, "c", "error", "one\ttab"),
        _finding("a.xml", 3, "c", "error", "same key"),
    ]
    assert eco.write_template(out, findings) == 1
    lines = out.read_text(encoding="utf-8").splitlines()
    assert lines[0] == HEADER.strip()
    assert lines[1].split("\t")[:5] == ["p", "a.xml", "3", "c", "TODO"]


def test_catalog_node_comparison() -> None:
    expected = {
        "id": "N",
        "kind": "Action",
        "ports": [
            {"name": "x", "direction": "input", "type": "double", "default": "1.0"},
            {"name": "g", "direction": "output", "type": "Goal", "type_resolved": "ns::Goal"},
            {"name": "e", "direction": "input", "type": "int", "default": "K", "default_expr": 1},
            {"name": "u", "direction": "input", "type": None},
        ],
    }
    ports: list[dict[str, object]] = [
        {"name": "x", "direction": "input", "type": " double", "default": "1"},
        {"name": "g", "direction": "output", "type": "::ns::Goal", "default": None},
        {"name": "e", "direction": "input", "type": "int", "default": "5"},
        {"name": "u", "direction": "input", "type": "AnyTypeAllowed", "default": None},
    ]
    actual = {"kind": "Action", "ports": ports}
    assert eco.compare_node(expected, actual) == []
    ports[0]["default"] = "2.0"
    ports.append({"name": "y", "direction": "input", "type": None, "default": None})
    problems = eco.compare_node(expected, actual)
    assert any("default" in p for p in problems)
    assert "port 'y' not expected" in problems
    assert eco.compare_node(expected, None) == ["not found"]


def test_whole_run_on_a_fake_projects_dir(tmp_path: Path) -> None:
    """A project whose only finding is triaged passes; the JSON summary says so."""
    project = tmp_path / "projects" / "demo"
    project.mkdir(parents=True)
    (project / "config.xml").write_text(
        '<root BTCPP_format="4"><BehaviorTree ID="Sleepy"><Sleep/></BehaviorTree></root>\n',
        encoding="utf-8",
    )
    (project / "tree.xml").write_text(
        '<root BTCPP_format="4"><BehaviorTree ID="Main"><AlwaysSuccess/></BehaviorTree></root>\n',
        encoding="utf-8",
    )
    triage = tmp_path / "triage.tsv"
    triage.write_text(
        HEADER
        + "demo\tconfig.xml\t1\tmissing-required-port\tfalse\tclass: a test of the script\n"
        + "demo\tgone.xml\t1\tunknown-node\ttrue\tstale\n",
        encoding="utf-8",
    )
    summary = tmp_path / "summary.json"
    args = ["--projects", str(tmp_path / "projects"), "--triage", str(triage)]
    assert eco.main([*args, "--json", str(summary)]) == 1  # a false error fails
    data = json.loads(summary.read_text(encoding="utf-8"))
    assert data["false_errors"] == 1
    assert data["untriaged"] == []
    assert [s["path"] for s in data["stale"]] == ["gone.xml"]
    triage.write_text(HEADER, encoding="utf-8")
    template = tmp_path / "todo.tsv"
    assert eco.main([*args, "--write-template", str(template)]) == 1
    assert "demo\tconfig.xml\t1\tmissing-required-port\tTODO" in template.read_text(
        encoding="utf-8"
    )


def test_a_relative_projects_dir_keys_findings_by_their_path_in_the_project(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """``--projects ../shared/projects`` (as CI passes it): ``check`` prints paths relative
    to the working directory, and the triage key is still the path inside the project."""
    project = tmp_path / "projects" / "demo"
    (project / "trees").mkdir(parents=True)
    (project / "trees" / "config.xml").write_text(
        '<root BTCPP_format="4"><BehaviorTree ID="Sleepy"><Sleep/></BehaviorTree></root>\n',
        encoding="utf-8",
    )
    work = tmp_path / "work"
    work.mkdir()
    monkeypatch.chdir(work)
    triage = tmp_path / "triage.tsv"
    triage.write_text(
        HEADER + "demo\ttrees/config.xml\t1\tmissing-required-port\ttrue\ta test\n",
        encoding="utf-8",
    )
    summary = tmp_path / "summary.json"
    args = ["--projects", "../projects", "--triage", str(triage), "--json", str(summary)]
    assert eco.main(args) == 0
    data = json.loads(summary.read_text(encoding="utf-8"))
    assert data["untriaged"] == []
    assert data["true_errors"] == 1


def test_the_readme_table_does_not_change_with_a_new_hint(tmp_path: Path) -> None:
    triage = _triage(tmp_path, "p\ta.xml\t3\tundeclared-port\ttrue\tclass: x")
    loud = [_finding("a.xml", 3, "undeclared-port", "error")]
    hint = _finding("a.xml", 4, "some-new-code", "hint")

    def table(findings: list[object]) -> str:
        text: str = eco.readme_table(eco.compare(findings, triage, ["p"]), {"p": 1}, findings)
        return text

    assert table(loud) == table([*loud, hint])
    assert "| p | 1 | 1 | 0 | `undeclared-port` 1 |" in table(loud)
