"""``bt-lsp check``: safe and unsafe fixes (``--fix``, ``--unsafe-fixes``), and the text
output's ``--output-format full``, ``--statistics`` and colours."""

from __future__ import annotations

import sys
from collections.abc import Iterator
from pathlib import Path

import pytest

from tests.pinned import main  # bt-lsp as the tests know it (tests/pinned.py)

TYPO = (
    '<root BTCPP_format="4">\n'
    '  <BehaviorTree ID="Main">\n'
    '    <Fallbak name="a&b">\n'
    "      <AlwaysSuccess/>\n"
    "    </Fallbak>\n"
    "  </BehaviorTree>\n"
    "</root>\n"
)
CATALOG = (
    '<root BTCPP_format="4">\n'
    '  <TreeNodesModel>\n    <Action ID="Dock"/>\n  </TreeNodesModel>\n'
    "</root>\n"
)


@pytest.fixture
def work(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Iterator[Path]:
    monkeypatch.chdir(tmp_path)
    for name in ("NO_COLOR", "FORCE_COLOR"):
        monkeypatch.delenv(name, raising=False)
    yield tmp_path


def _put(path: Path, text: str) -> Path:
    path.write_text(text, encoding="utf-8")
    return path


def test_fix_applies_the_safe_fixes_and_unsafe_ones_when_asked(
    work: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = _put(work / "t.xml", TYPO)
    assert main(["check", "--fix", "--no-cpp", "t.xml"]) == 0
    # The escape is safe; the typo guess is not: C++ bt-lsp did not see may register it.
    assert path.read_text(encoding="utf-8") == TYPO.replace("a&b", "a&amp;b")
    assert capsys.readouterr().err.startswith("fixed 1 problem in t.xml\n")
    assert main(["check", "--fix", "--unsafe-fixes", "--no-cpp", "t.xml"]) == 0
    assert path.read_text(encoding="utf-8") == TYPO.replace("a&b", "a&amp;b").replace(
        "Fallbak", "Fallback"
    )


def test_a_typo_is_fixed_safely_when_every_registration_is_known(
    work: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # With a node catalog BehaviorTree.CPP surely fails on 'Fallbak' and 'Fallback' is
    # the one nearest name: the editor's preferred fix, and --fix makes it.
    path = _put(work / "t.xml", TYPO)
    _put(work / "catalog.xml", CATALOG)
    assert main(["check", "--no-cpp", "--models", "catalog.xml", "t.xml"]) == 1
    assert "error unknown-node" in capsys.readouterr().out
    assert main(["check", "--fix", "--no-cpp", "--models", "catalog.xml", "t.xml"]) == 0
    assert path.read_text(encoding="utf-8") == TYPO.replace("a&b", "a&amp;b").replace(
        "Fallbak", "Fallback"
    )


def test_statistics(work: Path, capsys: pytest.CaptureFixture[str]) -> None:
    _put(
        work / "t.xml", TYPO.replace("<AlwaysSuccess/>", '<Repeat a="&"><AlwaysSuccess/></Repeat>')
    )
    assert main(["check", "--no-cpp", "--statistics", "t.xml"]) == 1
    out, err = capsys.readouterr()
    assert out.splitlines() == [
        "2\txml-unescaped-char   \t[*] a raw & or < in an attribute value (tinyxml2 accepts "
        "it, XML does not)",
        "1\tmissing-required-port\ta built-in's or a <SubTree> model's port without a default "
        "that is not given (BehaviorTree.CPP fails)",
        "1\tundeclared-port      \tan attribute the node's model does not declare",
        "1\tunknown-node         \ta node type that is neither built in nor registered (an "
        "error with a node catalog; else a warning one typo away from a known node, a hint "
        "otherwise)",
    ]
    assert err == "2 errors, 3 warnings in 1 file\n"
    # With --unsafe-fixes the typo and the missing port count as fixable too.
    assert main(["check", "--no-cpp", "--statistics", "--unsafe-fixes", "t.xml"]) == 1
    marks = [line.split("\t")[2][:4] for line in capsys.readouterr().out.splitlines()]
    assert marks == ["[*] ", "[*] ", "an a", "[*] "]
    # Only the diagnostics shown count.
    assert (
        main(["check", "--no-cpp", "--statistics", "--min-severity", "error", "-q", "t.xml"]) == 1
    )
    out, err = capsys.readouterr()
    assert [line.split("\t")[1].strip() for line in out.splitlines()] == [
        "missing-required-port",
        "undeclared-port",
    ]
    assert err == ""


def test_full_output_format_shows_the_line_and_a_caret(
    work: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # A tab and a wide character before the range: the caret is under it on screen.
    _put(
        work / "t.xml", TYPO.replace("    <Fallbak name", "\t漢<Fallbak name").replace("a&b", "ab")
    )
    assert main(["check", "--no-cpp", "--output-format", "full", "t.xml"]) == 0
    out = capsys.readouterr().out.splitlines()
    assert out[0].startswith("t.xml:3:4: warning unknown-node Node type 'Fallbak'")
    assert out[1:] == [
        "  |",
        '3 |     漢<Fallbak name="ab">',
        "  |        ^^^^^^^",
        "  |",
    ]


def test_concise_is_the_default_and_unchanged(
    work: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    _put(work / "t.xml", TYPO)
    assert main(["check", "--no-cpp", "t.xml"]) == 0
    concise = capsys.readouterr().out
    assert main(["check", "--no-cpp", "--output-format", "concise", "t.xml"]) == 0
    assert capsys.readouterr().out == concise
    assert [line.split(" ")[0] for line in concise.splitlines()] == ["t.xml:3:6:", "t.xml:3:21:"]
    assert "\x1b" not in concise


@pytest.mark.parametrize(
    ("argv", "env", "tty", "colored"),
    [
        ([], {}, True, True),
        ([], {"NO_COLOR": "1"}, True, False),
        ([], {"NO_COLOR": ""}, True, True),  # an empty value does not count
        ([], {"FORCE_COLOR": "1"}, False, True),
        ([], {}, False, False),
        (["--color", "never"], {"FORCE_COLOR": "1"}, True, False),
        (["--color", "always"], {"NO_COLOR": "1"}, False, True),
    ],
)
def test_color(
    work: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
    argv: list[str],
    env: dict[str, str],
    tty: bool,
    colored: bool,
) -> None:
    _put(work / "t.xml", TYPO)
    for name, value in env.items():
        monkeypatch.setenv(name, value)
    monkeypatch.setattr(sys.stdout, "isatty", lambda: tty)
    assert main(["check", "--no-cpp", *argv, "t.xml"]) == 0
    out = capsys.readouterr().out
    assert ("\x1b[1;33mwarning\x1b[0m" in out) is colored, out
    if colored:
        assert out.startswith("\x1b[1mt.xml:3:6:\x1b[0m \x1b[1;33mwarning\x1b[0m ")


def test_json_is_never_colored_and_text_flags_are_refused(
    work: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    _put(work / "t.xml", TYPO)
    assert main(["check", "--no-cpp", "--format", "json", "--color", "always", "t.xml"]) == 0
    assert "\x1b" not in capsys.readouterr().out
    assert main(["check", "--format", "json", "--statistics", "t.xml"]) == 2
    assert "--statistics is for --format text" in capsys.readouterr().err
    assert main(["check", "--format", "sarif", "--output-format", "full", "t.xml"]) == 2
