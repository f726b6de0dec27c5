"""Reading users' XML files and writing them back safely.

Reading opens the file in binary and decodes it here, so line ends (``\\r\\n``, lone
``\\r``) reach the core exactly as written. The encoding is, in this order:

1. a byte-order mark: UTF-8, UTF-16 LE/BE or UTF-32 LE/BE (the mark is not part of the text);
2. the first characters of a UTF-16 document without a mark (``<?`` as two-byte units);
3. ``encoding="..."`` of an XML declaration at the very start, if it names a text codec
   Python knows that writes ASCII as ASCII (a declaration that can be read as ASCII
   cannot truthfully name UTF-16 or UTF-32);
4. UTF-8.

Writing goes to a temporary file in the same directory, which is flushed to disk, given the
original file's mode (and owner, where allowed) and then renamed over the original, so a
reader sees either the old or the new file, never a half-written one.  A new file is not
the same file: one that is read-only or has hard links is not written at all
(:func:`not_replaceable`). A write encodes
with the same codec and byte-order mark, so every byte outside the changed text stays as
it was.
"""

from __future__ import annotations

import codecs
import contextlib
import os
import re
import stat
import tempfile
from dataclasses import dataclass
from typing import Final

__all__ = [
    "DEFAULT_MAX_BYTES",
    "Decoded",
    "FileError",
    "Stamp",
    "decode_bytes",
    "encode_text",
    "not_replaceable",
    "read_bytes",
    "read_head",
    "read_text",
    "write_text_atomic",
]

# The one size limit of a document, for the server (``maxDocumentBytes``: an open document
# above it gets the XML and name checks only, a file above it is not read) and for
# ``bt-lsp check`` (``--max-file-size``): an include above it is not found in either.
DEFAULT_MAX_BYTES: Final = 8 * 1024 * 1024
# In the name of write_text_atomic's temporary files, so that the ones a killed run left
# can be told from anyone else's (see stale_temporaries).
TEMP_MARK: Final = ".bt-lsp-"

# Longest first: the UTF-32 LE mark starts with the UTF-16 LE one.
_BOMS: Final[tuple[tuple[bytes, str], ...]] = (
    (codecs.BOM_UTF32_LE, "utf-32-le"),
    (codecs.BOM_UTF32_BE, "utf-32-be"),
    (codecs.BOM_UTF8, "utf-8"),
    (codecs.BOM_UTF16_LE, "utf-16-le"),
    (codecs.BOM_UTF16_BE, "utf-16-be"),
)
_BOM_OF: Final[dict[str, bytes]] = {name: bom for bom, name in _BOMS}

# "<?" as UTF-16 without a byte-order mark (XML 1.0, appendix F).
_UNMARKED: Final[tuple[tuple[bytes, str], ...]] = (
    (b"<\x00?\x00", "utf-16-le"),
    (b"\x00<\x00?", "utf-16-be"),
)

_DECLARATION: Final = re.compile(
    rb"<\?xml[ \t\r\n][^>]*?\bencoding[ \t\r\n]*=[ \t\r\n]*([\"'])([A-Za-z][A-Za-z0-9._-]*)\1"
)


class FileError(Exception):
    """A file that cannot be read, decoded or written; the message names the file."""

    def __init__(self, path: str, message: str, reason: str | None = None) -> None:
        super().__init__(message)
        self.path = path
        self.message = message
        self.reason = reason if reason is not None else message  # without the file's name

    def __str__(self) -> str:
        return self.message


@dataclass(frozen=True, slots=True)
class Stamp:
    """What identifies one version of a file on disk: a write checks it is unchanged."""

    size: int
    mtime_ns: int
    inode: int

    @classmethod
    def of(cls, st: os.stat_result) -> Stamp:
        return cls(st.st_size, st.st_mtime_ns, st.st_ino)


@dataclass(frozen=True, slots=True)
class Decoded:
    """A file's text and how to write it back byte for byte.

    ``encoding`` is a Python codec name without a byte-order mark (``"utf-8"``,
    ``"utf-16-le"``, ...); ``bom`` says whether the file starts with one. ``lossless`` is
    true when encoding ``text`` again gives exactly the bytes that were read, which is what
    a safe rewrite needs (some legacy codecs have more than one spelling of a character).
    """

    text: str
    encoding: str
    bom: bool
    lossless: bool = True
    stamp: Stamp | None = None

    def encode(self, text: str) -> bytes:
        """``text`` as this file's bytes; raises ``UnicodeEncodeError``."""
        return encode_text(text, self.encoding, self.bom)


def _label(encoding: str) -> str:
    return encoding.upper()


def _declared(data: bytes) -> str | None:
    """The codec named by the XML declaration at the start of ``data``, if usable."""
    if not data.startswith(b"<?xml"):
        return None
    end = data.find(b"?>", 0, 1024)
    head = data[: end if end >= 0 else 1024]
    m = _DECLARATION.match(head)
    if m is None:
        return None
    try:
        info = codecs.lookup(m.group(2).decode("ascii"))
        # Only a text codec that writes ASCII as ASCII can have a declaration we just read.
        if "<?xml version='\"=".encode(info.name) != b"<?xml version='\"=":
            return None
    except (LookupError, UnicodeError, TypeError):
        return None
    return info.name


def sniff(data: bytes) -> tuple[str, bool]:
    """``(codec, has_bom)`` for the bytes of an XML file."""
    for bom, name in _BOMS:
        if data.startswith(bom):
            return name, True
    for head, name in _UNMARKED:
        if data.startswith(head):
            return name, False
    declared = _declared(data)
    if declared is not None and declared not in ("utf-8", "utf-8-sig"):
        return declared, False
    return "utf-8", False


def decode_bytes(data: bytes, path: str) -> Decoded:
    """Decode the bytes of ``path``; raises :class:`FileError` naming the bad byte."""
    encoding, bom = sniff(data)
    skip = len(_BOM_OF[encoding]) if bom else 0
    try:
        text = data[skip:].decode(encoding)
    except UnicodeDecodeError as e:
        offset = skip + e.start
        if e.start < len(e.object):
            where = f"byte 0x{e.object[e.start]:02x} at offset {offset}"
        else:  # pragma: no cover - decoders report the first byte of the bad sequence
            where = f"offset {offset}"
        if e.reason == "truncated data":
            where = f"truncated data at offset {offset}"
        raise FileError(path, f"{path} is not valid {_label(encoding)} ({where})") from None
    try:
        lossless = data[skip:] == text.encode(encoding)
    except UnicodeEncodeError:
        lossless = False
    return Decoded(text, encoding, bom, lossless)


def encode_text(text: str, encoding: str, bom: bool) -> bytes:
    """``text`` in ``encoding``, after the byte-order mark if ``bom``; strict."""
    data = text.encode(encoding)
    return _BOM_OF[encoding] + data if bom else data


def _reason(e: OSError) -> str:
    return e.strerror or e.__class__.__name__


def _size(n: int) -> str:
    if n >= 1024 * 1024 and n % (1024 * 1024) == 0:
        return f"{n // (1024 * 1024)} MB"
    if n >= 1024 * 1024:
        return f"{n / (1024 * 1024):.1f} MB"
    return f"{n} bytes"


def _too_large(path: str, size: int | None, max_bytes: int) -> FileError:
    what = f"{_size(size)}; " if size is not None else ""
    return FileError(path, f"{path} is too large ({what}the limit is {_size(max_bytes)})")


def _kind(st: os.stat_result) -> str:
    mode = st.st_mode
    if stat.S_ISFIFO(mode):
        return "a FIFO"
    if stat.S_ISSOCK(mode):
        return "a socket"
    if stat.S_ISCHR(mode) or stat.S_ISBLK(mode):
        return "a device"
    return "not a file"


def _cannot(path: str, why: str) -> FileError:
    return FileError(path, f"cannot read {path}: {why}", why)


def _not_regular(path: str, st: os.stat_result) -> FileError:
    why = f"not a regular file ({_kind(st)})"
    return FileError(path, f"skipping {path}: {why}", why)


def _open_regular(path: str) -> tuple[int, os.stat_result]:
    """A descriptor of ``path`` opened for reading, and its status: only a regular file is
    opened (a FIFO would block the open, a device may act on it), and without blocking (a
    regular file of a pseudo file system such as ``/proc/kmsg`` may block a read)."""
    try:
        st = os.stat(path)
    except OSError as e:
        raise _cannot(path, _reason(e)) from None
    except ValueError as e:  # a path the OS cannot look up ("embedded null byte")
        raise _cannot(path, str(e)) from None
    if stat.S_ISDIR(st.st_mode):
        raise _cannot(path, "Is a directory")
    if not stat.S_ISREG(st.st_mode):
        raise _not_regular(path, st)
    flags = os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_NOCTTY", 0)
    try:
        fd = os.open(path, flags | getattr(os, "O_BINARY", 0))
    except OSError as e:
        raise _cannot(path, _reason(e)) from None
    try:
        st = os.fstat(fd)  # the name may lead elsewhere by now
    except OSError as e:
        os.close(fd)
        raise _cannot(path, _reason(e)) from None
    if not stat.S_ISREG(st.st_mode):
        os.close(fd)
        raise _not_regular(path, st)
    return fd, st


def _read_fd(fd: int, path: str, limit: int, hint: int) -> bytes:
    """Up to ``limit`` bytes of the open file ``fd``; ``hint`` is its reported size.  A
    read that would block (a pseudo file that waits for data) is an error."""
    chunks: list[bytes] = []
    total = 0
    while total < limit:
        want = min(limit - total, max(hint + 1 - total, 64 * 1024))
        try:
            chunk = os.read(fd, want)
        except BlockingIOError:
            why = "reading it would block (not an ordinary file)"
            raise FileError(path, f"skipping {path}: {why}", why) from None
        if not chunk:
            break
        chunks.append(chunk)
        total += len(chunk)
    return b"".join(chunks)


def read_head(path: str, size: int) -> bytes:
    """The first ``size`` bytes of ``path`` (fewer if it is shorter), read as
    :func:`read_bytes` reads: never from anything but a regular file, never blocking."""
    fd, st = _open_regular(path)
    try:
        return _read_fd(fd, path, size, min(st.st_size, size))
    except OSError as e:
        raise _cannot(path, _reason(e)) from None
    finally:
        os.close(fd)


def read_bytes(path: str, max_bytes: int = DEFAULT_MAX_BYTES) -> tuple[bytes, Stamp]:
    """The bytes of ``path``, refusing anything larger than ``max_bytes``, anything but a
    regular file, and a file whose read would block."""
    fd, st = _open_regular(path)
    try:
        if st.st_size > max_bytes:
            raise _too_large(path, st.st_size, max_bytes)
        # A pseudo file reports no size: read one byte past the limit to notice.
        data = _read_fd(fd, path, max_bytes + 1, st.st_size)
    except OSError as e:
        raise _cannot(path, _reason(e)) from None
    finally:
        os.close(fd)
    if len(data) > max_bytes:
        raise _too_large(path, None, max_bytes)
    return data, Stamp.of(st)


def read_text(path: str, max_bytes: int = DEFAULT_MAX_BYTES) -> Decoded:
    """Read and decode ``path`` (see the module docstring for how the encoding is found).

    Raises :class:`FileError` with a message naming the file when it cannot be read, is
    larger than ``max_bytes``, or is not valid in its encoding.
    """
    data, st = read_bytes(path, max_bytes)
    decoded = decode_bytes(data, path)
    return Decoded(decoded.text, decoded.encoding, decoded.bom, decoded.lossless, st)


def not_replaceable(path: str) -> str | None:
    """Why :func:`write_text_atomic` must not put a new file in place of ``path``
    (``None``: it may): a read-only file would be rewritten all the same (the folder is
    what a rename needs), and a file with hard links would be split (its other names
    keep the old text).  Said in words for a note; a missing file is the write's to
    report."""
    try:
        st = os.stat(path)
    except (OSError, ValueError):
        return None
    mode = stat.S_IMODE(st.st_mode)
    if not mode & 0o222:
        return f"it is read-only (mode {mode:04o}); make it writable to have it fixed"
    if not os.access(path, os.W_OK):
        return f"this user may not write it (mode {mode:04o})"
    if st.st_nlink > 1:
        return (
            f"it has {st.st_nlink} hard links; a fixed copy would leave the other "
            "names with the old text"
        )
    return None


def write_text_atomic(
    path: str, text: str, encoding: str, bom: bool, *, expect: Stamp | None = None
) -> None:
    """Replace the contents of ``path`` with ``text`` atomically.

    The text is encoded strictly (a character the encoding cannot hold raises
    :class:`FileError` before anything is written). A symbolic link is followed, so the link
    stays a link. With ``expect``, the file must still be the version that was read, else
    :class:`FileError` and nothing is written. On any error the original file is untouched
    and the temporary file is removed.
    """
    try:
        data = encode_text(text, encoding, bom)
    except UnicodeEncodeError as e:
        char = e.object[e.start]
        raise FileError(
            path,
            f"cannot write {path}: U+{ord(char):04X} cannot be written in {_label(encoding)}",
        ) from None
    target = os.path.realpath(path)
    directory = os.path.dirname(target) or "."
    try:
        st = os.stat(target)
    except OSError as e:
        raise FileError(path, f"cannot write {path}: {_reason(e)}") from None
    if expect is not None and Stamp.of(st) != expect:
        raise FileError(path, f"cannot write {path}: it changed on disk while being checked")
    why = not_replaceable(target)
    if why is not None:
        raise FileError(path, f"cannot write {path}: {why}")
    try:
        fd, tmp = tempfile.mkstemp(
            prefix=f".{os.path.basename(target)}{TEMP_MARK}", suffix=".tmp", dir=directory
        )
    except OSError as e:
        raise FileError(path, f"cannot write {path}: {_reason(e)}") from None
    try:
        with os.fdopen(fd, "wb") as f:
            f.write(data)
            f.flush()
            os.fsync(f.fileno())
        if hasattr(os, "chown"):
            with contextlib.suppress(OSError):
                os.chown(tmp, st.st_uid, st.st_gid)
        os.chmod(tmp, stat.S_IMODE(st.st_mode))
        os.replace(tmp, target)
    except OSError as e:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise FileError(path, f"cannot write {path}: {_reason(e)}") from None
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise
    _sync_directory(directory)


def stale_temporaries(directory: str, before: float) -> list[str]:
    """The temporary files :func:`write_text_atomic` left in ``directory`` when it was
    killed, older than ``before`` (a time stamp): ``.NAME.bt-lsp-XXXXXXXX.tmp`` regular
    files of the current user.  Nothing else matches: another program's temporary file
    is never taken for ours."""
    pattern = re.compile(r"\..+" + re.escape(TEMP_MARK) + r"[a-z0-9_]{8}\.tmp")
    found: list[str] = []
    try:
        names = os.listdir(directory)
    except OSError:
        return found
    uid = os.getuid() if hasattr(os, "getuid") else None
    for name in names:
        if not pattern.fullmatch(name):
            continue
        full = os.path.join(directory, name)
        try:
            st = os.lstat(full)
        except OSError:
            continue
        if stat.S_ISREG(st.st_mode) and st.st_mtime < before and uid in (None, st.st_uid):
            found.append(full)
    return sorted(found)


def _sync_directory(directory: str) -> None:
    """Make the rename durable (best effort; not every system can open a directory)."""
    try:
        fd = os.open(directory, os.O_RDONLY)
    except OSError:
        return
    try:
        with contextlib.suppress(OSError):
            os.fsync(fd)
    finally:
        os.close(fd)
