"""The name rules at their C++ string literals, and what BehaviorTree.CPP 4.10 does."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from bt_lsp.cpp.extract import extract
from bt_lsp.rules.codes import Severity
from bt_lsp.rules.cpp_names import cpp_name_diagnostics
from bt_lsp.rules.registry import CODES
from tests.pinned import main  # bt-lsp as the tests know it (tests/pinned.py)

SRC = """// ünïcödé 𝄞 before the literals
class Pick : public BT::SyncActionNode {
public:
  static BT::PortsList providedPorts() {
    return { BT::InputPort<Pose>("goal.pose"), BT::InputPort<int>("_hidden"),
             BT::InputPort<int>("name"), BT::OutputPort<int>("fine"), BT::InputPort<int>("2nd") };
  }
};
void reg(BT::BehaviorTreeFactory& factory) {
  /* 𝄞 */ factory.registerNodeType<Pick>("Dock Robot");
  factory.registerNodeType<Pick>("Root");
  factory.registerNodeType<Pick>("Fine");
  factory.registerSimpleAction("Say", fn, { BT::InputPort<std::string>("a b") });
}
"""


def _diags(text: str = SRC) -> list[tuple[str, str]]:
    return [
        (d.code, text[d.start : d.end]) for d in cpp_name_diagnostics(extract(text.encode()), text)
    ]


def test_each_bad_name_at_its_literal() -> None:
    assert _diags() == [
        ("cpp-port-name", '"goal.pose"'),
        ("cpp-port-name", '"_hidden"'),
        ("cpp-port-name", '"name"'),
        ("cpp-port-name", '"2nd"'),
        ("cpp-model-name", '"Dock Robot"'),
        ("cpp-model-name", '"Root"'),
        ("cpp-port-name", '"a b"'),
    ]


def test_messages_say_what_btcpp_does() -> None:
    by_text = {SRC[d.start : d.end]: d for d in cpp_name_diagnostics(extract(SRC.encode()), SRC)}
    port = by_text['"goal.pose"']
    assert "'.' (period)" in port.message and "throws when the node is registered" in port.message
    assert port.severity is Severity.ERROR
    model = by_text['"Dock Robot"']
    assert model.severity is Severity.WARNING  # BehaviorTree.CPP registers it without a check
    assert '<Action ID="Dock Robot"/>' in model.message
    assert "reserved" in by_text['"Root"'].message
    assert "ASCII letter" in by_text['"_hidden"'].message
    assert CODES["cpp-port-name"].severity is Severity.ERROR


def test_names_from_constants_and_valid_names_are_quiet() -> None:
    text = (
        'static constexpr const char* P = "bad.name";\n'
        "struct A : BT::SyncActionNode { static BT::PortsList providedPorts() "
        '{ return { BT::InputPort<int>(P), BT::InputPort<int>("ok_Name-2") }; } };\n'
        'void f(F& f) { f.registerNodeType<A>("检查门状态"); }\n'
    )
    assert _diags(text) == []


def test_check_reports_them_with_columns_in_characters(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    pkg = tmp_path / "pkg" / "src"
    pkg.mkdir(parents=True)
    (pkg / "nodes.cpp").write_text(SRC, encoding="utf-8")
    assert main(["check", "--format", "json", str(tmp_path / "pkg")]) == 1
    found = json.loads(capsys.readouterr().out)
    dock = next(f for f in found if f["message"].startswith("Model name 'Dock Robot'"))
    line = SRC.splitlines()[9]
    assert (dock["line"], dock["column"]) == (10, line.index('"Dock Robot"') + 1)
    assert dock["severity"] == "warning"
    # A C++ file named on the command line is checked the same way.
    assert main(["check", str(pkg / "nodes.cpp")]) == 1
    assert "cpp-port-name" in capsys.readouterr().out
    # --no-cpp: directories give their XML only.
    assert main(["check", "--no-cpp", str(tmp_path / "pkg")]) == 0
