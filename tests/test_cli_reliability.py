"""``bt-lsp check`` where files are not what they seem: FIFOs and pseudo files that would
block a read, a broken configuration, read-only files and hard links under ``--fix``."""

from __future__ import annotations

import errno
import fcntl
import os
import signal
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from bt_lsp.cli.main import main
from bt_lsp.project.fileio import FileError, read_bytes
from bt_lsp.project.sniff import head_of
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
