"""What kind of XML a file is, from its first bytes: enough to tell a BehaviorTree.CPP
document from the other XML of a source tree (``package.xml``, launch files, URDF and
xacro, pluginlib descriptions, other tools' files) without parsing it."""

from __future__ import annotations

import codecs
from pathlib import Path
from typing import Final

from bt_lsp.project.fileio import FileError, read_head
from bt_lsp.syntax.kind import HEAD_CHARS, looks_like_bt, not_xml, top_element

__all__ = ["SNIFF_BYTES", "head_of", "is_bt_file", "top_element"]

SNIFF_BYTES: Final = 64 * 1024

_BOMS: Final = (
    (codecs.BOM_UTF32_LE, "utf-32-le"),
    (codecs.BOM_UTF32_BE, "utf-32-be"),
    (codecs.BOM_UTF8, "utf-8"),
    (codecs.BOM_UTF16_LE, "utf-16-le"),
    (codecs.BOM_UTF16_BE, "utf-16-be"),
)


def head_of(path: Path | str, size: int = SNIFF_BYTES) -> str | None:
    """The first ``size`` bytes of a file as text (``None`` if it cannot be read, or is
    not a regular file: a FIFO or a device is never opened, and no read blocks)."""
    try:
        data = read_head(str(path), size)
    except FileError:
        return None
    for bom, enc in _BOMS:
        if data.startswith(bom):
            return data[len(bom) :].decode(enc, "replace")
    if data.startswith((b"<\x00?\x00", b"<\x00")):
        return data.decode("utf-16-le", "replace")
    if data.startswith((b"\x00<\x00?", b"\x00<")):
        return data.decode("utf-16-be", "replace")
    return data.decode("utf-8", "replace")


def is_bt_file(path: Path | str) -> bool:
    """Whether the file is to be checked as BehaviorTree.CPP XML when a folder is walked:
    what its content says (:func:`bt_lsp.syntax.kind.looks_like_bt`, the decision the
    workspace and the editor make too).  A file that cannot be read counts as one, so
    that reading it reports the error, and so does a file that is not XML at all
    (:func:`bt_lsp.syntax.kind.not_xml`: empty, or broken before its first tag closes)."""
    head = head_of(path, 4 * HEAD_CHARS)
    if head is None:
        return True
    return looks_like_bt(head) or not_xml(head)
