"""What kind of XML a file is, from its first bytes: enough to tell a BehaviorTree.CPP
document (top element ``<root>``) from the other XML of a source tree (``package.xml``,
launch files, URDF and xacro, pluginlib descriptions) without parsing it."""

from __future__ import annotations

import codecs
import re
from pathlib import Path
from typing import Final

from bt_lsp.project.fileio import FileError, read_head

__all__ = ["SNIFF_BYTES", "head_of", "is_bt_file", "top_element"]

SNIFF_BYTES: Final = 64 * 1024

# Before the top element: an XML declaration, processing instructions, comments, a
# DOCTYPE without an internal subset, white space.
_TOP: Final = re.compile(
    r"(?:\s+|<\?.*?\?>|<!--.*?-->|<!DOCTYPE[^>\[]*(?:\[.*?\])?\s*>)*<([^\s/>!?]+)",
    re.DOTALL,
)
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


def top_element(text: str) -> str | None:
    """The name of the first element of an XML text (``None`` if there is none in it)."""
    m = _TOP.match(text.removeprefix("\ufeff"))
    return m.group(1) if m is not None else None


# The top elements of the other XML a ROS source tree holds: package manifests, launch
# files, URDF and xacro, pluginlib descriptions, Gazebo SDF, ament/catkin metadata.
OTHER_XML: Final = frozenset(
    {"package", "launch", "robot", "library", "class_libraries", "sdf", "model", "world"}
)


def is_bt_file(path: Path | str) -> bool:
    """Whether the file is to be checked as BehaviorTree.CPP XML: anything but the known
    other XML of a source tree (its top element one of :data:`OTHER_XML`), so that a
    broken BT file (no element, a misspelt ``<root>``) is still reported. A file that
    cannot be read counts as one, so that reading it reports the error."""
    head = head_of(path)
    if head is None:
        return True
    top = top_element(head)
    return top is None or top.rpartition(":")[2] not in OTHER_XML
