"""The ``bt-lsp`` command line: ``check`` output (text, json, sarif), exit codes, file
errors, ``--fix``, ``--severity``, the progress bar, ``serve`` and ``--version``."""

from __future__ import annotations

import codecs
import errno
import json
import os
import re
import shutil
import stat
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from lxml import etree

from bt_lsp import __version__
from bt_lsp.cli import fix_workspace
from bt_lsp.rules.registry import CODES
from bt_lsp.syntax.edits import TextEdit
from tests.pinned import later_off, main, pinned  # bt-lsp as the tests know it
from tests.test_fixes import AUTOREMAP, AUTOREMAP_WHY, PORTS, PORTS_FIXED

# The system's own words for a missing file (the message quotes the OS error).
NO_FILE = os.strerror(errno.ENOENT)

# 😋 (outside the BMP) sits before the bad port name on line 4: its column counts the emoji
# as one character (24); SARIF counts it as two UTF-16 code units (25).
EMOJI = (
    '<root BTCPP_format="4" main_tree_to_execute="Main">\n'
    '  <BehaviorTree ID="Main">\n'
    '    <Sequence name="😋">\n'
    '      <Say.Hi text="😋" 1port="2"/>\n'
    "    </Sequence>\n"
    "  </BehaviorTree>\n"
    "  <TreeNodesModel>\n"
    '    <Action ID="Say.Hi">\n'
    '      <input_port name="text"/>\n'
    '      <input_port name="1port" default="0"/>\n'
    "    </Action>\n"
    "  </TreeNodesModel>\n"
    "</root>\n"
)
EMOJI_LINES = [
    ("emoji.xml:4:8: error model-name-forbidden-char ", "'Say.Hi'"),
    ("emoji.xml:4:24: error port-name-leading-digit ", "'1port'"),
    ("emoji.xml:8:17: error model-name-forbidden-char ", "'Say.Hi'"),
    ("emoji.xml:10:25: error port-name-leading-digit ", "'1port'"),
]

CRLF = (
    '<root BTCPP_format="4" main_tree_to_execute="Main Tree">\r\n'
    '  <BehaviorTree ID="Main Tree">\r\n'
    '    <AlwaysSuccess name="ok"/>\r\n'
    "  </BehaviorTree>\r\n"
    "</root>\r\n"
)
CRLF_LINES = [("crlf.xml:2:21: error model-name-forbidden-char ", "'Main Tree'")]

CLEAN = (
    '<root BTCPP_format="4" main_tree_to_execute="Main">\n'
    '  <BehaviorTree ID="Main">\n'
    '    <AlwaysSuccess name="ok"/>\n'
    "  </BehaviorTree>\n"
    "</root>\n"
)

# Every kind of reference: a tree called by main_tree_to_execute and <SubTree>, a model used
# in a tree and declared in <TreeNodesModel>, a port declared and used.
FIXABLE = (
    '<root BTCPP_format="4" main_tree_to_execute="Main Tree">\n'
    '  <BehaviorTree ID="Main Tree">\n'
    "    <Sequence>\n"
    '      <Say.Hi text="😋" goal.x="2"/>\n'
    '      <SubTree ID="Sub Tree"/>\n'
    "    </Sequence>\n"
    "  </BehaviorTree>\n"
    '  <BehaviorTree ID="Sub Tree">\n'
    '    <Say.Hi text="b" goal.x="3"/>\n'
    "  </BehaviorTree>\n"
    "  <TreeNodesModel>\n"
    '    <Action ID="Say.Hi">\n'
    '      <input_port name="text"/>\n'
    '      <input_port name="goal.x" default="0"/>\n'
    "    </Action>\n"
    "  </TreeNodesModel>\n"
    "</root>\n"
)
RENAMES = {"Main Tree": "Main_Tree", "Sub Tree": "Sub_Tree", "Say.Hi": "Say_Hi", "goal.x": "goal_x"}


def _fixed(text: str) -> str:
    for old, new in RENAMES.items():
        text = text.replace(old, new)
    return text


def _put(path: Path, text: str, encoding: str = "utf-8", bom: bytes = b"") -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_bytes(bom + text.encode(encoding))
    return path


def _assert_lines(out: str, expected: list[tuple[str, str]]) -> None:
    lines = out.splitlines()
    assert len(lines) == len(expected), out
    for line, (prefix, name) in zip(lines, expected, strict=True):
        assert line.startswith(prefix), line
        assert name in line[len(prefix) :], line


@pytest.fixture
def work(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Iterator[Path]:
    monkeypatch.chdir(tmp_path)
    yield tmp_path


# -- commands and usage --------------------------------------------------------------------


def test_version(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["--version"]) == 0
    assert capsys.readouterr().out == f"bt-lsp {__version__}\n"


@pytest.mark.parametrize(
    "argv",
    [
        [],
        ["check"],
        ["check", "--format", "xml", "a.xml"],
        ["frobnicate"],
        ["check", "--bogus", "x"],
    ],
)
def test_usage_errors_exit_2(argv: list[str], capsys: pytest.CaptureFixture[str]) -> None:
    assert main(argv) == 2
    assert "usage:" in capsys.readouterr().err


def test_serve_calls_server_lazily(monkeypatch: pytest.MonkeyPatch) -> None:
    import bt_lsp.server

    calls: list[dict[str, Any]] = []
    monkeypatch.setattr(bt_lsp.server, "serve", lambda **kw: calls.append(kw))
    assert main(["serve"]) == 0
    assert main(["serve", "--stdio"]) == 0
    assert main(["serve", "--tcp", "--host", "0.0.0.0", "--port", "9999"]) == 0
    assert calls == [
        {"tcp": False, "host": "127.0.0.1", "port": 2087},
        {"tcp": False, "host": "127.0.0.1", "port": 2087},
        {"tcp": True, "host": "0.0.0.0", "port": 9999},
    ]
    assert main(["serve", "--port", "http"]) == 2


def test_check_does_not_import_the_server(work: Path) -> None:
    _put(work / "a.xml", CLEAN)
    code = (
        f"import sys; from bt_lsp.cli.main import main; rc = main(['check', 'a.xml', "
        f"*{later_off()!r}]); "
        "print(rc, sorted(m for m in sys.modules if m.split('.')[0] in "
        "('pygls', 'lsprotocol') or m.startswith('bt_lsp.server')))"
    )
    proc = subprocess.run(
        [sys.executable, "-c", code], cwd=work, capture_output=True, text=True, check=True
    )
    assert proc.stdout == "0 []\n"


def _entry_point() -> list[str]:
    exe = Path(sys.executable).with_name("bt-lsp")
    if exe.exists():
        return [str(exe)]
    found = shutil.which("bt-lsp")
    if found is None:
        pytest.skip("the bt-lsp entry point is not installed")
    return [found]


def test_installed_entry_point(work: Path) -> None:
    _put(work / "trees" / "emoji.xml", EMOJI)
    _put(work / "trees" / "crlf.xml", CRLF)
    proc = subprocess.run(
        [*_entry_point(), "check", "trees", *later_off()], cwd=work, capture_output=True, text=True
    )
    assert proc.returncode == 1, proc.stderr
    expected = [(f"trees/{p}", n) for p, n in CRLF_LINES + EMOJI_LINES]
    _assert_lines(proc.stdout, expected)
    assert proc.stderr == "5 errors, 0 warnings in 2 files\n"
    version = subprocess.run(
        [*_entry_point(), "--version"], capture_output=True, text=True, check=True
    )
    assert version.stdout == f"bt-lsp {__version__}\n"
    module = subprocess.run(
        [sys.executable, "-m", "bt_lsp", "--version"], capture_output=True, text=True, check=True
    )
    assert module.stdout == version.stdout


# -- text output and exit codes ------------------------------------------------------------


def test_text_output_exact_positions(work: Path, capsys: pytest.CaptureFixture[str]) -> None:
    _put(work / "emoji.xml", EMOJI)
    _put(work / "crlf.xml", CRLF)
    assert main(["check", "emoji.xml", "crlf.xml"]) == 1
    out, err = capsys.readouterr()
    _assert_lines(out, EMOJI_LINES + CRLF_LINES)
    assert err == "5 errors, 0 warnings in 2 files\n"


def test_full_line_format(work: Path, capsys: pytest.CaptureFixture[str]) -> None:
    _put(work / "crlf.xml", CRLF)
    assert main(["check", "crlf.xml"]) == 1
    from bt_lsp.rules.analysis import analyze
    from bt_lsp.syntax.document import Document

    (diag,) = pinned(analyze(Document(CRLF)))
    assert capsys.readouterr().out == (
        f"crlf.xml:2:21: error model-name-forbidden-char {diag.message}\n"
    )


def test_clean_file_exits_0(work: Path, capsys: pytest.CaptureFixture[str]) -> None:
    _put(work / "a.xml", CLEAN)
    assert main(["check", "a.xml"]) == 0
    assert capsys.readouterr() == ("", "0 errors, 0 warnings in 1 file\n")


def test_directory_search(work: Path, capsys: pytest.CaptureFixture[str]) -> None:
    _put(work / "d" / "z.xml", CRLF)
    _put(work / "d" / "a" / "b.xml", CRLF)
    _put(work / "d" / "a.xml", CRLF)
    _put(work / "d" / "notes.txt", CRLF)
    _put(work / "d" / ".hidden" / "h.xml", CRLF)
    _put(work / "d" / "node_modules" / "n.xml", CRLF)
    _put(work / "d" / ".#lock.xml", CRLF)
    assert main(["check", "d/", "d/z.xml"]) == 1  # z.xml only once
    out, err = capsys.readouterr()
    assert [line.split(":")[0] for line in out.splitlines()] == [
        "d/a/b.xml",
        "d/a.xml",
        "d/z.xml",
    ]
    assert err.endswith("in 3 files\n")


def test_current_directory_paths_are_relative(
    work: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    _put(work / "sub" / "crlf.xml", CRLF)
    assert main(["check", "."]) == 1
    assert capsys.readouterr().out.startswith("sub/crlf.xml:2:21: ")


def test_empty_directory(work: Path, capsys: pytest.CaptureFixture[str]) -> None:
    (work / "empty").mkdir()
    assert main(["check", "empty"]) == 0
    assert "no XML files" in capsys.readouterr().err


def test_missing_file_exits_2_and_others_are_checked(
    work: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    _put(work / "crlf.xml", CRLF)
    assert main(["check", "nope.xml", "crlf.xml"]) == 2
    out, err = capsys.readouterr()
    _assert_lines(out, CRLF_LINES)
    assert err.splitlines() == [
        f"bt-lsp: cannot read nope.xml: {NO_FILE}",
        "1 error, 0 warnings in 1 file; 1 file could not be checked",
    ]


def test_invalid_utf8_exits_2(work: Path, capsys: pytest.CaptureFixture[str]) -> None:
    (work / "bad.xml").write_bytes(b"<root>\n <a/>\xff</root>\n")
    _put(work / "clean.xml", CLEAN)
    assert main(["check", "bad.xml", "clean.xml"]) == 2
    out, err = capsys.readouterr()
    assert out == ""
    assert err.splitlines()[0] == "bt-lsp: bad.xml is not valid UTF-8 (byte 0xff at offset 12)"


def test_unreadable_file_in_a_directory(work: Path, capsys: pytest.CaptureFixture[str]) -> None:
    _put(work / "d" / "crlf.xml", CRLF)
    (work / "d" / "broken.xml").symlink_to(work / "missing-target.xml")
    assert main(["check", "d"]) == 2
    out, err = capsys.readouterr()
    _assert_lines(out, [("d/" + p, n) for p, n in CRLF_LINES])
    assert f"bt-lsp: cannot read d/broken.xml: {NO_FILE}\n" in err


def test_directory_named_like_a_file_is_searched(
    work: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    _put(work / "x.xml" / "crlf.xml", CRLF)
    assert main(["check", "x.xml"]) == 1
    assert capsys.readouterr().out.startswith("x.xml/crlf.xml:2:21: ")


def test_permission_denied_exits_2(
    work: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    from tests.test_fileio import deny_access

    path = _put(work / "locked.xml", CLEAN)
    path.chmod(0)
    deny_access(path.resolve(), monkeypatch)
    try:
        assert main(["check", "locked.xml"]) == 2
    finally:
        path.chmod(0o644)
    assert "bt-lsp: cannot read locked.xml: Permission denied" in capsys.readouterr().err


def test_too_large_file(work: Path, capsys: pytest.CaptureFixture[str]) -> None:
    _put(work / "a.xml", CLEAN)
    assert main(["check", "--max-file-size", "10", "a.xml"]) == 2
    assert "bt-lsp: a.xml is too large" in capsys.readouterr().err
    assert main(["check", "--max-file-size", "1K", "a.xml"]) == 0
    assert main(["check", "--max-file-size", "lots", "a.xml"]) == 2


def test_control_characters_are_shown_visibly(
    work: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    _put(
        work / "a.xml",
        '<root BTCPP_format="4"><BehaviorTree ID="Main">'
        '<AlwaysSuccess name="bell\x07\x1b[31m"/></BehaviorTree></root>',
    )
    assert main(["check", "a.xml"]) == 1
    out = capsys.readouterr().out
    assert "instance-name-control-char" in out
    assert "\x07" not in out and "\x1b" not in out


# -- --severity ----------------------------------------------------------------------------


def test_severity_downgrade_exits_0(work: Path, capsys: pytest.CaptureFixture[str]) -> None:
    _put(work / "emoji.xml", EMOJI)
    argv = [
        "check",
        "emoji.xml",
        "--severity",
        "model-name-forbidden-char=warning",
        "--severity=port-name-leading-digit=hint",
    ]
    assert main(argv) == 0
    out, err = capsys.readouterr()
    assert [line.split(" ")[1] for line in out.splitlines()] == ["warning", "hint"] * 2
    assert err == "0 errors, 2 warnings, 2 hints in 1 file\n"


def test_severity_off_and_commas(work: Path, capsys: pytest.CaptureFixture[str]) -> None:
    _put(work / "emoji.xml", EMOJI)
    argv = [
        "check",
        "emoji.xml",
        "--severity",
        "model-name-forbidden-char=off,port-name-leading-digit=info",
    ]
    assert main(argv) == 0
    out, err = capsys.readouterr()
    assert [line.split(" ")[1:3] for line in out.splitlines()] == [
        ["information", "port-name-leading-digit"]
    ] * 2
    assert err == "0 errors, 0 warnings, 2 information in 1 file\n"


@pytest.mark.parametrize(
    ("spec", "message"),
    [
        ("no-such-code=off", "unknown code 'no-such-code'"),
        ("model-name-empty=loud", "unknown severity 'loud'"),
        ("model-name-empty", "expected CODE=LEVEL"),
    ],
)
def test_severity_errors_exit_2(
    work: Path, capsys: pytest.CaptureFixture[str], spec: str, message: str
) -> None:
    _put(work / "a.xml", CLEAN)
    assert main(["check", "a.xml", "--severity", spec]) == 2
    err = capsys.readouterr().err
    assert "usage:" in err and message in err


# -- json ----------------------------------------------------------------------------------


def test_json_output(work: Path, capsys: pytest.CaptureFixture[str]) -> None:
    _put(work / "emoji.xml", EMOJI)
    assert main(["check", "--format", "json", "emoji.xml", "missing.xml"]) == 2
    out, err = capsys.readouterr()
    data = json.loads(out)
    keys = ["path", "line", "column", "endLine", "endColumn", "severity", "code", "message"]
    assert all(list(item) == keys for item in data)
    assert data[0] == {
        "path": "emoji.xml",
        "line": 4,
        "column": 8,
        "endLine": 4,
        "endColumn": 14,
        "severity": "error",
        "code": "model-name-forbidden-char",
        "message": data[0]["message"],
    }
    assert [(d["line"], d["column"], d["endColumn"]) for d in data[:4]] == [
        (4, 8, 14),
        (4, 24, 29),
        (8, 17, 23),
        (10, 25, 30),
    ]
    assert data[4] == {
        "path": "missing.xml",
        "line": None,
        "column": None,
        "endLine": None,
        "endColumn": None,
        "severity": "error",
        "code": "file-error",
        "message": f"cannot read missing.xml: {NO_FILE}",
    }
    assert err == f"bt-lsp: cannot read missing.xml: {NO_FILE}\n"


def test_json_empty(work: Path, capsys: pytest.CaptureFixture[str]) -> None:
    _put(work / "a.xml", CLEAN)
    assert main(["check", "--format=json", "a.xml"]) == 0
    assert capsys.readouterr() == ("[]\n", "")


# -- sarif ---------------------------------------------------------------------------------

_LEVELS = {"none", "note", "warning", "error"}


def _validate_sarif(log: dict[str, Any]) -> None:
    """The parts of the SARIF 2.1.0 schema and of GitHub code scanning's requirements that
    this output uses."""
    assert set(log) == {"$schema", "version", "runs"}
    assert log["$schema"].startswith("https://") and "sarif-2.1.0" in log["$schema"]
    assert log["version"] == "2.1.0"
    assert isinstance(log["runs"], list) and len(log["runs"]) == 1
    run = log["runs"][0]
    assert run["columnKind"] == "utf16CodeUnits"
    driver = run["tool"]["driver"]
    assert driver["name"] == "bt-lsp"
    assert driver["version"] == __version__
    assert driver["informationUri"].startswith("https://")
    rules = driver["rules"]
    ids = [r["id"] for r in rules]
    assert len(ids) == len(set(ids))
    for r in rules:
        assert set(r) >= {"id", "shortDescription", "helpUri", "defaultConfiguration"}
        assert r["id"] in CODES
        assert r["shortDescription"]["text"] == CODES[r["id"]].summary
        assert r["helpUri"] == CODES[r["id"]].url
        assert r["defaultConfiguration"]["level"] in _LEVELS
    assert isinstance(run["results"], list)
    for res in run["results"]:
        assert rules[res["ruleIndex"]]["id"] == res["ruleId"]
        assert res["level"] in _LEVELS
        assert isinstance(res["message"]["text"], str) and res["message"]["text"]
        (loc,) = res["locations"]
        phys = loc["physicalLocation"]
        art = phys["artifactLocation"]
        assert "\\" not in art["uri"] and " " not in art["uri"]
        if "uriBaseId" in art:
            assert art["uriBaseId"] == "%SRCROOT%"
            assert not art["uri"].startswith("/")
        else:
            assert art["uri"].startswith("file:///")
        region = phys["region"]
        for key in ("startLine", "startColumn", "endLine", "endColumn"):
            assert isinstance(region[key], int) and region[key] >= 1
        assert (region["endLine"], region["endColumn"]) >= (
            region["startLine"],
            region["startColumn"],
        )
        for value in res.get("partialFingerprints", {}).values():
            assert isinstance(value, str)
    for inv in run.get("invocations", []):
        assert isinstance(inv["executionSuccessful"], bool)
        for note in inv.get("toolExecutionNotifications", []):
            assert note["level"] in _LEVELS and note["message"]["text"]


def test_sarif_output(work: Path, capsys: pytest.CaptureFixture[str]) -> None:
    _put(work / "sub dir" / "emoji.xml", EMOJI)
    _put(work / "crlf.xml", CRLF)
    argv = [
        "check",
        "--format",
        "sarif",
        "crlf.xml",
        "sub dir",
        "--severity",
        "port-name-leading-digit=warning",
    ]
    assert main(argv) == 1
    log = json.loads(capsys.readouterr().out)
    _validate_sarif(log)
    run = log["runs"][0]
    assert [r["id"] for r in run["tool"]["driver"]["rules"]] == [
        "model-name-forbidden-char",
        "port-name-leading-digit",
    ]
    assert [r["defaultConfiguration"]["level"] for r in run["tool"]["driver"]["rules"]] == [
        "error",
        "error",
    ]
    got = [
        (
            r["ruleId"],
            r["level"],
            r["locations"][0]["physicalLocation"]["artifactLocation"]["uri"],
            tuple(r["locations"][0]["physicalLocation"]["region"].values()),
        )
        for r in run["results"]
    ]
    assert got == [
        ("model-name-forbidden-char", "error", "crlf.xml", (2, 21, 2, 30)),
        ("model-name-forbidden-char", "error", "sub%20dir/emoji.xml", (4, 8, 4, 14)),
        # 😋 before it: two UTF-16 code units, so one column more than the text output.
        ("port-name-leading-digit", "warning", "sub%20dir/emoji.xml", (4, 25, 4, 30)),
        ("model-name-forbidden-char", "error", "sub%20dir/emoji.xml", (8, 17, 8, 23)),
        ("port-name-leading-digit", "warning", "sub%20dir/emoji.xml", (10, 25, 10, 30)),
    ]
    prints = [r["partialFingerprints"]["btLspToken/v1"] for r in run["results"]]
    assert len(set(prints)) == len(prints)
    assert run["invocations"] == [{"executionSuccessful": True, "toolExecutionNotifications": []}]


def test_sarif_file_errors_and_outside_files(
    work: Path, tmp_path_factory: pytest.TempPathFactory, capsys: pytest.CaptureFixture[str]
) -> None:
    outside = _put(tmp_path_factory.mktemp("elsewhere") / "crlf.xml", CRLF)
    assert main(["check", "--format", "sarif", str(outside), "gone.xml"]) == 2
    log = json.loads(capsys.readouterr().out)
    _validate_sarif(log)
    run = log["runs"][0]
    (res,) = run["results"]
    assert res["locations"][0]["physicalLocation"]["artifactLocation"] == {"uri": outside.as_uri()}
    (inv,) = run["invocations"]
    assert inv["executionSuccessful"] is False
    (note,) = inv["toolExecutionNotifications"]
    assert note["descriptor"] == {"id": "file-error"}
    assert note["message"]["text"] == f"cannot read gone.xml: {NO_FILE}"


def test_sarif_clean(work: Path, capsys: pytest.CaptureFixture[str]) -> None:
    _put(work / "a.xml", CLEAN)
    assert main(["check", "--format", "sarif", "a.xml"]) == 0
    log = json.loads(capsys.readouterr().out)
    _validate_sarif(log)
    assert log["runs"][0]["results"] == []
    assert log["runs"][0]["tool"]["driver"]["rules"] == []


# -- progress ------------------------------------------------------------------------------


def _fake_tty(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(sys.stderr, "isatty", lambda: True)


def test_progress_on_a_tty(
    work: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    for i in range(4):
        _put(work / "d" / f"f{i}.xml", CLEAN)
    _fake_tty(monkeypatch)
    assert main(["check", "d"]) == 0
    err = capsys.readouterr().err
    assert "\r[##        ] 1/4 d/f0.xml" in err
    assert "\r[#####     ] 2/4 d/f1.xml" in err
    assert "\r[##########] 4/4 d/f3.xml" in err
    # Cleared before the summary, which is the only visible line left.
    head, _, tail = err.rpartition("\r")
    assert tail == "0 errors, 0 warnings in 4 files\n"
    assert head.endswith(" " * len("[##########] 4/4 d/f3.xml"))


def test_progress_is_cleared_before_output(
    work: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    _put(work / "a.xml", CRLF)
    _put(work / "b.xml", CRLF)
    _fake_tty(monkeypatch)
    assert main(["check", "a.xml", "b.xml", "--fix"]) == 0
    err = capsys.readouterr().err
    line = "[#####     ] 1/2 a.xml"
    assert f"\r{line}\r{' ' * len(line)}\rfixed 1 problem in a.xml\n" in err


@pytest.mark.parametrize("argv", [["d", "--no-progress"], ["d/f0.xml"]])
def test_no_progress(
    work: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
    argv: list[str],
) -> None:
    for i in range(2):
        _put(work / "d" / f"f{i}.xml", CLEAN)
    _fake_tty(monkeypatch)
    assert main(["check", *argv]) == 0
    err = capsys.readouterr().err
    assert "\r" not in err and "[" not in err


def test_no_progress_when_not_a_tty(work: Path, capsys: pytest.CaptureFixture[str]) -> None:
    for i in range(3):
        _put(work / "d" / f"f{i}.xml", CLEAN)
    assert main(["check", "d"]) == 0
    assert capsys.readouterr().err == "0 errors, 0 warnings in 3 files\n"


# -- --fix ---------------------------------------------------------------------------------


def _parses(data: bytes) -> bool:
    try:
        etree.fromstring(data, etree.XMLParser(resolve_entities=False, no_network=True))
    except etree.XMLSyntaxError:
        return False
    return True


def test_fix_renames_every_reference(work: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = _put(work / "a.xml", FIXABLE)
    assert _parses(path.read_bytes())
    assert main(["check", "--fix", "a.xml"]) == 0
    out, err = capsys.readouterr()
    assert path.read_text(encoding="utf-8") == _fixed(FIXABLE)
    assert _parses(path.read_bytes())
    assert out == ""
    assert err.splitlines() == ["fixed 9 problems in a.xml", "0 errors, 0 warnings in 1 file"]
    # Nothing left to fix: a second run changes nothing.
    assert main(["check", "--fix", "a.xml"]) == 0
    assert capsys.readouterr().err == "0 errors, 0 warnings in 1 file\n"


def test_fix_renames_tree_ports_with_their_keys(
    work: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = _put(work / "a.xml", PORTS)
    assert main(["check", "--fix", "a.xml"]) == 0
    assert path.read_text(encoding="utf-8") == PORTS_FIXED
    assert capsys.readouterr().err.splitlines() == [
        "fixed 5 problems in a.xml",
        "0 errors, 0 warnings in 1 file",
    ]


def test_fix_says_which_keys_it_left(work: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = _put(work / "a.xml", AUTOREMAP)
    assert main(["check", "--fix", "a.xml"]) == 0
    assert path.read_text(encoding="utf-8") == AUTOREMAP.replace(
        'name="bad.port"', 'name="bad_port"'
    )
    assert capsys.readouterr().err.splitlines() == [
        "fixed 1 problem in a.xml",
        "bt-lsp: a.xml: renamed 'bad.port' to 'bad_port' and left the key 'bad.port' in "
        f"tree 'Sub' as it is: {AUTOREMAP_WHY}",
        "0 errors, 0 warnings in 1 file",
    ]


def test_fix_gives_a_port_one_name_across_a_folder(
    work: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # The port is declared in one file; its tree and a call are in another.
    models = _put(
        work / "d" / "models.xml",
        '<root BTCPP_format="4">\n  <TreeNodesModel>\n    <SubTree ID="Sub">\n'
        '      <input_port name="bad.port"/>\n    </SubTree>\n  </TreeNodesModel>\n</root>\n',
    )
    trees = _put(
        work / "d" / "trees.xml",
        '<root BTCPP_format="4" main_tree_to_execute="Main">\n'
        '  <BehaviorTree ID="Main">\n    <SubTree ID="Sub" bad.port="1"/>\n  </BehaviorTree>\n'
        '  <BehaviorTree ID="Sub">\n'
        '    <SetBlackboard output_key="out" value="{bad.port}"/>\n'
        "  </BehaviorTree>\n</root>\n",
    )
    before = (models.read_text(encoding="utf-8"), trees.read_text(encoding="utf-8"))
    assert main(["check", "--fix", "d"]) == 0
    # One rename for the whole folder: the port gets the same name in both, its key
    # included, and each file counts its own problems that went away.
    assert models.read_text(encoding="utf-8") == before[0].replace("bad.port", "bad_port")
    assert trees.read_text(encoding="utf-8") == before[1].replace("bad.port", "bad_port")
    assert capsys.readouterr().err.splitlines() == [
        "fixed 1 problem in d/models.xml",
        "fixed 1 problem in d/trees.xml",
        "0 errors, 0 warnings in 2 files",
    ]


@pytest.mark.parametrize(
    ("encoding", "bom", "newline"),
    [
        ("utf-8", codecs.BOM_UTF8, "\r\n"),
        ("utf-8", b"", "\r"),
        ("utf-16-le", codecs.BOM_UTF16_LE, "\r\n"),
        ("utf-16-be", codecs.BOM_UTF16_BE, "\n"),
    ],
)
def test_fix_preserves_encoding_bom_line_ends_and_mode(
    work: Path, capsys: pytest.CaptureFixture[str], encoding: str, bom: bytes, newline: str
) -> None:
    text = FIXABLE.replace("\n", newline)
    path = _put(work / "a.xml", text, encoding, bom)
    path.chmod(0o640)
    assert main(["check", "--fix", "a.xml"]) == 0
    assert path.read_bytes() == bom + _fixed(text).encode(encoding)
    assert stat.S_IMODE(path.stat().st_mode) == 0o640
    assert sorted(os.listdir(work)) == ["a.xml"]
    assert "fixed 9 problems in a.xml" in capsys.readouterr().err


def test_fix_reports_what_is_left(work: Path, capsys: pytest.CaptureFixture[str]) -> None:
    # An XML error elsewhere stays (and is reported); the names are still fixed.
    text = FIXABLE.replace("<Sequence>", "<Sequence> 1 < 2 ")
    path = _put(work / "a.xml", text)
    assert not _parses(path.read_bytes())
    assert main(["check", "--fix", "--format", "json", "a.xml"]) == 1
    out, err = capsys.readouterr()
    assert path.read_text(encoding="utf-8") == _fixed(text)
    assert [(d["code"], d["line"], d["column"]) for d in json.loads(out)] == [("xml-syntax", 3, 18)]
    assert err == "fixed 9 problems in a.xml\n"


def test_fix_respects_severity_off(work: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = _put(work / "a.xml", FIXABLE)
    assert main(["check", "--fix", "a.xml", "--severity", "port-name-forbidden-char=off"]) == 0
    assert path.read_text(encoding="utf-8") == _fixed(FIXABLE).replace("goal_x", "goal.x")


def _patch_fix_all(monkeypatch: pytest.MonkeyPatch, bad: TextEdit) -> None:
    """The real fixes, with ``bad`` instead of any edit at the same place."""
    real = fix_workspace.edits_in

    def fake(renames: Any, path: str) -> list[TextEdit]:
        return [*(e for e in real(renames, path) if e.start != bad.start), bad]

    monkeypatch.setattr(fix_workspace, "edits_in", fake)


_SUBTREE_CALL = FIXABLE.index('<SubTree ID="Sub Tree"/>') + len('<SubTree ID="')


@pytest.mark.parametrize(
    ("bad", "reason"),
    [
        # Breaks the XML: a '<' in the middle of the root's attributes.
        (TextEdit(5, 5, "<"), "would add xml-syntax problems"),
        # A name error the edits target but do not remove.
        (
            TextEdit(_SUBTREE_CALL, _SUBTREE_CALL + len("Sub Tree"), "Sub Tree2"),
            "would leave model-name-forbidden-char at 5:20",
        ),
    ],
)
def test_unsafe_fix_leaves_the_file_alone(
    work: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
    bad: TextEdit,
    reason: str,
) -> None:
    path = _put(work / "a.xml", FIXABLE, "utf-8", codecs.BOM_UTF8)
    before = path.read_bytes()
    _patch_fix_all(monkeypatch, bad)
    assert main(["check", "--fix", "a.xml"]) == 1
    out, err = capsys.readouterr()
    assert path.read_bytes() == before
    assert f"bt-lsp: not fixing a.xml: the fixes {reason}" in err
    assert "fixed" not in err.replace("not fixing", "")
    assert len(out.splitlines()) == 9  # the original problems are reported


def test_fix_leaves_a_lossy_encoding_alone(work: Path, capsys: pytest.CaptureFixture[str]) -> None:
    data = (
        b'<?xml version="1.0" encoding="cp932"?>\n'
        b'<root BTCPP_format="4"><BehaviorTree ID="Main Tree">'
        b'<AlwaysSuccess name="\x87\x90"/></BehaviorTree></root>\n'
    )
    path = work / "a.xml"
    path.write_bytes(data)
    assert main(["check", "--fix", "a.xml"]) == 1
    assert path.read_bytes() == data
    assert "bt-lsp: not fixing a.xml: CP932 does not round-trip its bytes" in (
        capsys.readouterr().err
    )


def test_fix_keeps_a_symlink(work: Path, capsys: pytest.CaptureFixture[str]) -> None:
    real = _put(work / "real.xml", FIXABLE)
    (work / "link.xml").symlink_to(real)
    assert main(["check", "--fix", "link.xml"]) == 0
    assert (work / "link.xml").is_symlink()
    assert real.read_text(encoding="utf-8") == _fixed(FIXABLE)


def test_fix_does_not_rewrite_a_clean_file(work: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = _put(work / "a.xml", CLEAN)
    os.utime(path, ns=(1_000_000_000, 1_000_000_000))
    before = path.stat()
    assert main(["check", "--fix", "a.xml"]) == 0
    after = path.stat()
    assert (after.st_ino, after.st_mtime_ns) == (before.st_ino, before.st_mtime_ns)
    assert capsys.readouterr().err == "0 errors, 0 warnings in 1 file\n"


def test_internal_error_names_the_file_and_goes_on(
    work: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    from bt_lsp.rules import analysis

    real = analysis.analyze

    def flaky(doc: Any, *context: Any) -> Any:
        if doc.path == "boom.xml":
            raise RuntimeError("kaboom")
        return real(doc, *context)

    monkeypatch.setattr(analysis, "analyze", flaky)
    _put(work / "boom.xml", CLEAN)
    _put(work / "crlf.xml", CRLF)
    assert main(["check", "boom.xml", "crlf.xml"]) == 2
    out, err = capsys.readouterr()
    _assert_lines(out, CRLF_LINES)
    assert "bt-lsp: internal error while checking boom.xml: RuntimeError: kaboom\n" in err


# -- --fix corners: FIFOs, interrupted runs, failed writes, links out of the folder ----------


def test_a_fifo_named_explicitly_is_skipped(work: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A FIFO with no writer would block open() forever: it is refused at once."""
    os.mkfifo(work / "pipe.xml")
    _put(work / "a.xml", FIXABLE)
    assert main(["check", "--fix", "pipe.xml", "a.xml"]) == 2
    err = capsys.readouterr().err
    assert "bt-lsp: skipping pipe.xml: not a regular file (a FIFO)" in err
    assert (work / "a.xml").read_text(encoding="utf-8") == _fixed(FIXABLE)  # the rest goes on


def test_stale_temporaries_of_an_interrupted_fix_are_removed(
    work: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    _put(work / "d" / "a.xml", FIXABLE)
    ours = _put(work / "d" / ".a.xml.bt-lsp-k3j_9x0q.tmp", "<root")
    os.utime(ours, (1_000_000_000, 1_000_000_000))
    fresh = _put(work / "d" / ".a.xml.bt-lsp-zzzzzzzz.tmp", "<root")  # a run going on now
    os.utime(fresh, (time.time() + 60, time.time() + 60))
    others = [
        _put(work / "d" / ".a.xml.k3j_9x0q.tmp", "x"),  # not our name
        _put(work / "d" / ".a.xml.bt-lsp-k3j_9x0q.tmp~", "x"),
        _put(work / "d" / "notes.bt-lsp-k3j_9x0q.tmp", "x"),
    ]
    for p in others:
        os.utime(p, (1_000_000_000, 1_000_000_000))
    assert main(["check", "--fix", "d"]) == 0
    err = capsys.readouterr().err
    assert not ours.exists()
    assert "removed" in err and ".a.xml.bt-lsp-k3j_9x0q.tmp" in err
    assert fresh.exists() and all(p.exists() for p in others)
    # Without --fix nothing is touched.
    ours = _put(ours, "<root")
    os.utime(ours, (1_000_000_000, 1_000_000_000))
    main(["check", "d"])
    assert ours.exists()


def test_the_temporary_file_has_our_mark(work: Path, monkeypatch: pytest.MonkeyPatch) -> None:

    names: list[str] = []
    real = os.replace

    def spy(src: str, dst: str) -> None:
        names.append(os.path.basename(src))
        real(src, dst)

    _put(work / "a.xml", FIXABLE)
    monkeypatch.setattr(os, "replace", spy)
    assert main(["check", "--fix", "a.xml"]) == 0
    assert len(names) == 1 and re.fullmatch(r"\.a\.xml\.bt-lsp-[a-z0-9_]{8}\.tmp", names[0])


def test_a_failed_write_under_fix_exits_2(
    work: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:

    def full(src: str, dst: str) -> None:
        raise OSError(28, "No space left on device")

    path = _put(work / "a.xml", FIXABLE)
    monkeypatch.setattr(os, "replace", full)
    assert main(["check", "--fix", "a.xml"]) == 2
    err = capsys.readouterr().err
    assert "bt-lsp: not fixing a.xml: cannot write a.xml: No space left on device" in err
    assert path.read_text(encoding="utf-8") == FIXABLE
    assert [p.name for p in work.iterdir()] == ["a.xml"]  # no temporary file left


def test_a_link_out_of_the_folder_is_not_rewritten(
    work: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    outside = _put(work / "elsewhere" / "shared.xml", FIXABLE)
    inside = _put(work / "d" / "real.xml", FIXABLE)
    (work / "d" / "link.xml").symlink_to(outside)
    (work / "d" / "near.xml").symlink_to(inside)  # a link within the folder: fixed
    assert main(["check", "--fix", "d"]) == 1  # the link's problems remain
    err = capsys.readouterr().err
    assert "not fixing d/link.xml: it is a symbolic link to" in err
    assert "--follow-symlinks" in err
    assert outside.read_text(encoding="utf-8") == FIXABLE
    # Both files define the same trees: a rename of one of them renames it in both or in
    # neither, so the file inside (checked as d/near.xml, its link) keeps its names too,
    # with a note saying why.
    assert inside.read_text(encoding="utf-8") == FIXABLE
    assert (
        "bt-lsp: d/near.xml: left 'Main Tree' as it is (not renamed to 'Main_Tree' in any "
        "file): its rename changes d/link.xml too, which is not fixed: it is a symbolic link"
    ) in err
    assert main(["check", "--fix", "--follow-symlinks", "d"]) == 0
    assert inside.read_text(encoding="utf-8") != FIXABLE  # fixed
    assert outside.read_text(encoding="utf-8") != FIXABLE  # fixed through the link
    assert (work / "d" / "link.xml").is_symlink()
