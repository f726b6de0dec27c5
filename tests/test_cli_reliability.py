"""``bt-lsp check`` where files are not what they seem: FIFOs and pseudo files that would
block a read, a broken configuration, read-only files and hard links under ``--fix``."""

from __future__ import annotations

import errno
import fcntl
import json
import os
import signal
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from bt_lsp.cli.main import build_parser, main
from bt_lsp.project.fileio import DEFAULT_MAX_BYTES, FileError, read_bytes, write_text_atomic
from bt_lsp.project.index import ProjectIndex, normalize
from bt_lsp.project.settings import Settings
from bt_lsp.project.sniff import head_of
from bt_lsp.syntax.document import Document
from tests.test_cli import FIXABLE, _fixed, _put

pytestmark = pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="needs FIFOs")


@pytest.fixture
def work(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Iterator[Path]:
    """The test's folder as the working directory, and an alarm that interrupts a test
    blocked on a FIFO (a blocked open() or read() would otherwise hang the suite)."""
    monkeypatch.chdir(tmp_path)

    def interrupt(signum: int, frame: Any) -> None:
        raise TimeoutError("blocked on a file")

    old = signal.signal(signal.SIGALRM, interrupt)
    signal.alarm(60)
    try:
        yield tmp_path
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, old)


# -- 2. FIFOs and reads that would block -----------------------------------------------------


@pytest.mark.parametrize("fix", [False, True])
def test_a_fifo_in_a_folder_is_reported_not_read(
    work: Path, capsys: pytest.CaptureFixture[str], fix: bool
) -> None:
    """The walk sniffs each ``*.xml`` file's top element: a FIFO is never opened."""
    _put(work / "d" / "a.xml", FIXABLE)
    os.mkfifo(work / "d" / "pipe.xml")
    assert main(["check", *(["--fix"] if fix else []), "d"]) == 2
    err = capsys.readouterr().err
    assert "bt-lsp: skipping d/pipe.xml: not a regular file (a FIFO)" in err
    if fix:
        assert (work / "d" / "a.xml").read_text(encoding="utf-8") == _fixed(FIXABLE)


def test_fifos_among_configuration_and_manifests_are_not_opened(
    work: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    _put(work / "d" / "a.xml", FIXABLE)
    for name in ("bt-lsp.toml", "CMakeLists.txt", "package.xml", "pyproject.toml"):
        os.mkfifo(work / "d" / name)
    assert main(["check", "--format", "json", "d"]) == 2
    assert main(["check", "--config", "d/bt-lsp.toml", "d/a.xml"]) == 2
    err = capsys.readouterr().err
    assert "config-error cannot read the file: not a regular file (a FIFO)" in err
    assert head_of(work / "d" / "package.xml") is None


def test_a_fifo_among_the_cpp_sources_is_not_read(
    work: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The C++ catalog of a folder reads its ``*.cpp`` files: a FIFO is left out."""
    _put(work / "d" / "a.xml", FIXABLE)
    _put(work / "d" / "nodes.cpp", '#include "x.h"\n')
    os.mkfifo(work / "d" / "pipe.cpp")
    assert main(["check", "--format", "json", "d"]) == 1
    assert "pipe.cpp" not in capsys.readouterr().out


def _blocking_read(target: Path, seen: list[bool]) -> Any:
    """``os.read`` as a pseudo file with no data answers (``/proc/kmsg``): a blocking read
    of ``target`` would wait forever, a non-blocking one fails with EAGAIN."""
    real = os.read
    inode = target.stat().st_ino

    def read(fd: int, n: int) -> bytes:
        if os.fstat(fd).st_ino != inode:
            return real(fd, n)
        nonblocking = bool(fcntl.fcntl(fd, fcntl.F_GETFL) & os.O_NONBLOCK)
        seen.append(nonblocking)
        if not nonblocking:
            raise TimeoutError("a blocking read of a file that never has data")
        raise BlockingIOError(errno.EAGAIN, os.strerror(errno.EAGAIN))

    return read


def test_a_regular_file_whose_read_blocks_is_skipped(
    work: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    kmsg = _put(work / "d" / "kmsg.xml", "")
    _put(work / "d" / "a.xml", FIXABLE)
    seen: list[bool] = []
    monkeypatch.setattr(os, "read", _blocking_read(kmsg, seen))
    with pytest.raises(FileError, match="reading it would block"):
        read_bytes(str(kmsg))
    assert head_of(kmsg) is None
    assert main(["check", "d"]) == 2
    err = capsys.readouterr().err
    assert "bt-lsp: skipping d/kmsg.xml: reading it would block" in err
    assert seen and all(seen)


# -- 8. one size limit for the server and the command line ------------------------------------

BIG_INCLUDER = (
    '<root BTCPP_format="4" main_tree_to_execute="Main">\n'
    '  <include path="big.xml"/>\n'
    '  <BehaviorTree ID="Main"><SubTree ID="Big"/></BehaviorTree>\n'
    "</root>\n"
)


def _big_include(folder: Path) -> Path:
    """``main.xml`` including ``big.xml``, one byte above the default limit."""
    head = '<root BTCPP_format="4"><BehaviorTree ID="Big"><AlwaysSuccess/></BehaviorTree>'
    tail = "</root>\n"
    pad = DEFAULT_MAX_BYTES + 1 - len(head) - len(tail) - len("<!---->")
    (folder / "big.xml").write_text(head + "<!--" + " " * pad + "-->" + tail)
    assert (folder / "big.xml").stat().st_size == DEFAULT_MAX_BYTES + 1
    return _put(folder / "main.xml", BIG_INCLUDER)


def test_the_server_and_the_command_line_share_one_size_limit() -> None:
    parser = build_parser()
    args = parser.parse_args(["check", "x.xml"])
    assert Settings().max_document_bytes == DEFAULT_MAX_BYTES == args.max_file_size


def test_an_included_file_above_the_limit_reads_the_same_in_both(
    work: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    main_xml = _big_include(work)
    # The command line.
    assert main(["check", "--format", "json", "main.xml"]) == 1
    cli = [(d["code"], d["message"]) for d in json.loads(capsys.readouterr().out)]
    # The server reads the includes of an open document through its ProjectIndex.
    index = ProjectIndex([work], Settings())
    path = normalize(main_xml)
    doc = Document(main_xml.read_text(), str(path))
    index.open(path, doc)
    server = [(d.code, d.message) for d in index.diagnostics(path, doc)]
    assert [c for c, _ in cli] == ["include-not-found", "unknown-subtree"]
    assert cli == server
    assert "too large" in cli[0][1] and "the limit is 8 MB" in cli[0][1]


# -- 9. a broken configuration: reported in every format, the files still checked -------------

BROKEN = 'btcpp = "4"\nexclude = "gen"\n[severity]\nmodel-name-forbidden-char = "off"\n'


def _broken_config(folder: Path) -> Path:
    _put(folder / "t.xml", FIXABLE)
    return _put(folder / "bt-lsp.toml", BROKEN)


def test_a_broken_configuration_is_a_json_entry(
    work: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    cfg = _broken_config(work)
    assert main(["check", "--format", "json", "."]) == 2
    entries = json.loads(capsys.readouterr().out)
    assert entries[0] == {
        "path": str(cfg),
        "line": 2,
        "column": 1,
        "endLine": 2,
        "endColumn": 16,
        "severity": "error",
        "code": "config-error",
        "message": "'exclude' must be a list of strings",
    }
    # The file is checked with the defaults: the broken file's severity is not applied.
    checked = {e["code"] for e in entries if e["path"] == "t.xml"}
    assert "model-name-forbidden-char" in checked


def test_a_broken_configuration_is_a_sarif_result_and_notification(
    work: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    _broken_config(work)
    assert main(["check", "--format", "sarif", "."]) == 2
    (run,) = json.loads(capsys.readouterr().out)["runs"]
    first = run["results"][0]
    assert first["ruleId"] == "config-error"
    where = first["locations"][0]["physicalLocation"]
    assert where["artifactLocation"]["uri"] == "bt-lsp.toml"
    assert where["region"]["startLine"] == 2
    assert any(
        r["locations"][0]["physicalLocation"]["artifactLocation"]["uri"] == "t.xml"
        for r in run["results"][1:]
    )
    (note,) = run["invocations"][0]["toolExecutionNotifications"]
    assert note["descriptor"]["id"] == "config-error"
    assert run["invocations"][0]["executionSuccessful"] is False


def test_a_broken_configuration_in_text_and_under_fix(
    work: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    cfg = _broken_config(work)
    assert main(["check", "--fix", "."]) == 2
    out, err = capsys.readouterr()
    assert f"{cfg}:2:1: error config-error 'exclude' must be a list of strings\n" in err
    assert "t.xml:" in out  # checked
    assert "not fixing any file: a configuration file cannot be used" in err
    assert (work / "t.xml").read_text(encoding="utf-8") == FIXABLE  # its excludes unknown


# -- 10. --fix keeps a file's identity: read-only files and hard links are not rewritten -----

DOCK = (
    '<root BTCPP_format="4">\n'
    '  <BehaviorTree ID="Dock Robot">\n'
    "    <AlwaysSuccess/>\n"
    "  </BehaviorTree>\n"
    "</root>\n"
)
CALLS = (
    '<root BTCPP_format="4" main_tree_to_execute="Main">\n'
    '  <BehaviorTree ID="Main"><SubTree ID="Dock Robot"/></BehaviorTree>\n'
    "</root>\n"
)


def test_fix_does_not_rewrite_a_read_only_file(
    work: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = _put(work / "d" / "a.xml", FIXABLE)
    path.chmod(0o444)
    try:
        assert main(["check", "--fix", "d"]) == 1
        assert path.read_text(encoding="utf-8") == FIXABLE
        assert oct(path.stat().st_mode & 0o777) == "0o444"
        err = capsys.readouterr().err
        assert "bt-lsp: not fixing d/a.xml: it is read-only (mode 0444)" in err
        path.chmod(0o644)  # made writable, it is fixed
        assert main(["check", "--fix", "d"]) == 0
        assert path.read_text(encoding="utf-8") == _fixed(FIXABLE)
    finally:
        path.chmod(0o644)


def test_a_rename_needing_a_read_only_file_is_made_in_none(
    work: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    dock = _put(work / "d" / "dock.xml", DOCK)
    calls = _put(work / "d" / "main.xml", CALLS)
    calls.chmod(0o444)
    try:
        assert main(["check", "--fix", "d"]) == 1
    finally:
        calls.chmod(0o644)
    assert dock.read_text(encoding="utf-8") == DOCK
    assert calls.read_text(encoding="utf-8") == CALLS
    err = capsys.readouterr().err
    assert (
        "bt-lsp: d/dock.xml: left 'Dock Robot' as it is (not renamed to 'Dock_Robot' in any "
        "file): its rename changes d/main.xml too, which is not fixed: it is read-only"
    ) in err


def test_fix_keeps_hard_links_whole(work: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = _put(work / "d" / "a.xml", FIXABLE)
    os.link(path, work / "elsewhere.xml")
    assert main(["check", "--fix", "d"]) == 1
    err = capsys.readouterr().err
    assert "bt-lsp: not fixing d/a.xml: it has 2 hard links" in err
    assert path.read_text(encoding="utf-8") == FIXABLE
    assert path.stat().st_ino == (work / "elsewhere.xml").stat().st_ino  # still one file


def test_the_write_itself_refuses_a_split(tmp_path: Path) -> None:
    """The check before the write is repeated by the write (the file may have been
    linked meanwhile)."""
    path = _put(tmp_path / "a.xml", "<a/>")
    os.link(path, tmp_path / "b.xml")
    with pytest.raises(FileError, match="2 hard links"):
        write_text_atomic(str(path), "<b/>", "utf-8", False)
    assert (tmp_path / "b.xml").read_text() == "<a/>" == path.read_text()
