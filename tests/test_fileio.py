"""Reading users' files (encodings, byte-order marks, line ends, errors) and writing them
back atomically and byte for byte."""

from __future__ import annotations

import codecs
import os
import stat
import tempfile
from pathlib import Path
from typing import Any

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from bt_lsp.project import fileio
from bt_lsp.project.fileio import (
    DEFAULT_MAX_BYTES,
    Decoded,
    FileError,
    decode_bytes,
    read_text,
    write_text_atomic,
)

TEXT = '<root BTCPP_format="4">\r\n  <BehaviorTree ID="Grüße 😋"/>\r\n</root>\r\n'


def _write(path: Path, data: bytes) -> str:
    path.write_bytes(data)
    return str(path)


# -- reading -------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("data", "encoding", "bom"),
    [
        (TEXT.encode("utf-8"), "utf-8", False),
        (codecs.BOM_UTF8 + TEXT.encode("utf-8"), "utf-8", True),
        (codecs.BOM_UTF16_LE + TEXT.encode("utf-16-le"), "utf-16-le", True),
        (codecs.BOM_UTF16_BE + TEXT.encode("utf-16-be"), "utf-16-be", True),
        (codecs.BOM_UTF32_LE + TEXT.encode("utf-32-le"), "utf-32-le", True),
        (codecs.BOM_UTF32_BE + TEXT.encode("utf-32-be"), "utf-32-be", True),
    ],
)
def test_read_detects_bom(tmp_path: Path, data: bytes, encoding: str, bom: bool) -> None:
    d = read_text(_write(tmp_path / "a.xml", data))
    assert (d.text, d.encoding, d.bom, d.lossless) == (TEXT, encoding, bom, True)
    assert d.stamp is not None and d.stamp.size == len(data)


def test_read_keeps_line_ends(tmp_path: Path) -> None:
    text = "<root>\r\n<a/>\r<b/>\n</root>"
    assert read_text(_write(tmp_path / "a.xml", text.encode())).text == text


def test_read_utf16_without_bom(tmp_path: Path) -> None:
    text = '<?xml version="1.0" encoding="UTF-16"?>\n<root/>'
    for codec in ("utf-16-le", "utf-16-be"):
        d = read_text(_write(tmp_path / "a.xml", text.encode(codec)))
        assert (d.text, d.encoding, d.bom) == (text, codec, False)


def test_read_honors_declared_encoding(tmp_path: Path) -> None:
    text = "<?xml version='1.0' encoding='ISO-8859-1'?>\n<root name=\"Grüße\"/>"
    d = read_text(_write(tmp_path / "a.xml", text.encode("latin-1")))
    assert d.text == text
    assert codecs.lookup(d.encoding).name == "iso8859-1"
    assert not d.bom


@pytest.mark.parametrize("declared", ["no-such-codec", "UTF-16", "utf-32", "rot13", "hex"])
def test_read_ignores_unusable_declaration(tmp_path: Path, declared: str) -> None:
    text = f'<?xml version="1.0" encoding="{declared}"?>\n<root name="Grüße"/>'
    d = read_text(_write(tmp_path / "a.xml", text.encode("utf-8")))
    assert (d.text, d.encoding) == (text, "utf-8")


def test_bom_wins_over_declaration(tmp_path: Path) -> None:
    text = '<?xml version="1.0" encoding="ISO-8859-1"?>\n<root name="Grüße"/>'
    d = read_text(_write(tmp_path / "a.xml", codecs.BOM_UTF8 + text.encode("utf-8")))
    assert (d.text, d.encoding, d.bom) == (text, "utf-8", True)


def test_invalid_utf8_names_byte_and_offset(tmp_path: Path) -> None:
    path = _write(tmp_path / "bad.xml", b"<root>\n  <a/>\xff</root>")
    with pytest.raises(FileError) as e:
        read_text(path)
    assert str(e.value) == f"{path} is not valid UTF-8 (byte 0xff at offset 13)"
    assert e.value.path == path


def test_invalid_utf8_offset_counts_the_bom(tmp_path: Path) -> None:
    path = _write(tmp_path / "bad.xml", codecs.BOM_UTF8 + b"<r>\xc3</r>")
    with pytest.raises(FileError, match=r"not valid UTF-8 \(byte 0xc3 at offset 6\)"):
        read_text(path)


def test_truncated_utf16(tmp_path: Path) -> None:
    path = _write(tmp_path / "bad.xml", codecs.BOM_UTF16_LE + "<r/>".encode("utf-16-le") + b"<")
    with pytest.raises(FileError, match=r"not valid UTF-16-LE \(truncated data at offset 10\)"):
        read_text(path)


def test_missing_file(tmp_path: Path) -> None:
    path = str(tmp_path / "nope.xml")
    with pytest.raises(FileError) as e:
        read_text(path)
    assert str(e.value) == f"cannot read {path}: No such file or directory"


def test_directory(tmp_path: Path) -> None:
    path = tmp_path / "dir.xml"
    path.mkdir()
    with pytest.raises(FileError, match=r"cannot read .*dir\.xml: Is a directory"):
        read_text(str(path))


def deny_access(path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Make ``path`` (a file, or a folder's entries) refuse access.  File modes do that for
    ordinary users; root ignores them, so there the operating system's refusal is raised at
    fileio's own calls instead, the same ``PermissionError`` a denied ``open`` gives."""
    if os.name == "posix" and not os.access(path, os.R_OK | os.W_OK):
        return
    real_open = open
    real_mkstemp: Any = tempfile.mkstemp
    denied = os.path.abspath(path)

    def refuse(target: Any) -> None:
        where = os.path.abspath(os.fspath(target))
        if where == denied or where.startswith(denied + os.sep):
            raise PermissionError(13, "Permission denied", os.fspath(target))

    def guarded_open(file: Any, *args: Any, **kwargs: Any) -> Any:
        if not isinstance(file, int):  # a descriptor was checked when it was opened
            refuse(file)
        return real_open(file, *args, **kwargs)

    real_os_open = os.open

    def guarded_os_open(file: Any, *args: Any, **kwargs: Any) -> int:
        refuse(file)
        return real_os_open(file, *args, **kwargs)

    def guarded_mkstemp(*args: Any, dir: Any = None, **kwargs: Any) -> Any:
        refuse(os.path.join(dir or os.getcwd(), "x"))
        return real_mkstemp(*args, dir=dir, **kwargs)

    monkeypatch.setattr(fileio, "open", guarded_open, raising=False)
    monkeypatch.setattr(os, "open", guarded_os_open)
    monkeypatch.setattr(tempfile, "mkstemp", guarded_mkstemp)


def test_permission_denied(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    path = tmp_path / "locked.xml"
    path.write_text("<root/>")
    path.chmod(0)
    deny_access(path, monkeypatch)
    try:
        with pytest.raises(FileError, match=r"cannot read .*locked\.xml: Permission denied"):
            read_text(str(path))
    finally:
        path.chmod(0o644)


def test_size_limit(tmp_path: Path) -> None:
    path = _write(tmp_path / "big.xml", b"<r>" + b" " * 2000 + b"</r>")
    assert DEFAULT_MAX_BYTES == 8 * 1024 * 1024
    with pytest.raises(FileError) as e:
        read_text(path, max_bytes=1000)
    assert str(e.value) == f"{path} is too large (2007 bytes; the limit is 1000 bytes)"
    assert read_text(path, max_bytes=2007).text.startswith("<r>")


def test_lossy_codec_is_flagged(tmp_path: Path) -> None:
    # In cp932 the bytes 87 90 decode to U+2252, which encodes back as 81 E0.
    data = b'<?xml version="1.0" encoding="cp932"?><r n="\x87\x90"/>'
    d = read_text(_write(tmp_path / "a.xml", data))
    assert d.text.endswith('<r n="\u2252"/>')
    assert not d.lossless


def test_decode_bytes_without_a_file() -> None:
    assert decode_bytes(b"<r/>", "x.xml") == Decoded("<r/>", "utf-8", False, True)


# -- writing -------------------------------------------------------------------------------


def test_write_keeps_encoding_bom_and_mode(tmp_path: Path) -> None:
    path = tmp_path / "a.xml"
    path.write_bytes(codecs.BOM_UTF16_BE + TEXT.encode("utf-16-be"))
    path.chmod(0o640)
    d = read_text(str(path))
    new = d.text.replace("Grüße 😋", "Grüße_😋")
    write_text_atomic(str(path), new, d.encoding, d.bom, expect=d.stamp)
    assert path.read_bytes() == codecs.BOM_UTF16_BE + new.encode("utf-16-be")
    assert stat.S_IMODE(path.stat().st_mode) == 0o640
    assert os.listdir(tmp_path) == ["a.xml"]  # no temporary file left behind


def test_write_follows_symlink(tmp_path: Path) -> None:
    target = tmp_path / "real.xml"
    target.write_text("<a/>")
    link = tmp_path / "link.xml"
    link.symlink_to(target)
    write_text_atomic(str(link), "<b/>", "utf-8", False)
    assert link.is_symlink()
    assert target.read_text() == "<b/>"


def test_write_refuses_unencodable_text(tmp_path: Path) -> None:
    path = tmp_path / "a.xml"
    path.write_bytes(b"<a/>")
    with pytest.raises(FileError, match=r"U\+20AC cannot be written in LATIN-1"):
        write_text_atomic(str(path), "<€/>", "latin-1", False)
    assert path.read_bytes() == b"<a/>"
    assert os.listdir(tmp_path) == ["a.xml"]


def test_write_refuses_a_file_changed_since_read(tmp_path: Path) -> None:
    path = tmp_path / "a.xml"
    path.write_bytes(b"<a/>")
    d = read_text(str(path))
    path.write_bytes(b"<changed/>")
    with pytest.raises(FileError, match="changed on disk"):
        write_text_atomic(str(path), "<b/>", d.encoding, d.bom, expect=d.stamp)
    assert path.read_bytes() == b"<changed/>"


def test_write_to_missing_file(tmp_path: Path) -> None:
    with pytest.raises(FileError, match="cannot write"):
        write_text_atomic(str(tmp_path / "gone.xml"), "<a/>", "utf-8", False)


def test_write_in_read_only_directory(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    path = tmp_path / "a.xml"
    path.write_bytes(b"<a/>")
    tmp_path.chmod(0o555)
    deny_access(tmp_path, monkeypatch)
    try:
        with pytest.raises(FileError, match=r"cannot write .*Permission denied"):
            write_text_atomic(str(path), "<b/>", "utf-8", False)
    finally:
        tmp_path.chmod(0o755)
    assert path.read_bytes() == b"<a/>"


_ENCODED = st.sampled_from(
    [
        ("utf-8", b""),
        ("utf-8", codecs.BOM_UTF8),
        ("utf-16-le", codecs.BOM_UTF16_LE),
        ("utf-16-be", codecs.BOM_UTF16_BE),
    ]
)


@settings(
    max_examples=150, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(text=st.text(st.characters(exclude_categories=["Cs"])), enc=_ENCODED)
def test_read_then_write_is_byte_identical(
    tmp_path: Path, text: str, enc: tuple[str, bytes]
) -> None:
    codec, bom = enc
    data = bom + text.encode(codec)
    path = tmp_path / "p.xml"
    path.write_bytes(data)
    try:
        d = read_text(str(path))
    except FileError:
        return  # e.g. bytes that look like another byte-order mark
    assert d.lossless
    write_text_atomic(str(path), d.text, d.encoding, d.bom)
    assert path.read_bytes() == data
