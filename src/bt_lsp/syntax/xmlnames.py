"""XML 1.0 names: the check the parser makes of every element and attribute name, minus
what the name rules already report (so that one bad character is reported once)."""

from __future__ import annotations

import re
from typing import Any

from bt_lsp.syntax.lazyre import LazyPattern
from bt_lsp.syntax.vocabulary import CONTROL_CHARS, FORBIDDEN

# An XML 1.0 (5th edition) Name.
_NAME_START = (
    ":A-Z_a-z\u00c0-\u00d6\u00d8-\u00f6\u00f8-\u02ff\u0370-\u037d\u037f-\u1fff\u200c-\u200d"
    "\u2070-\u218f\u2c00-\u2fef\u3001-\ud7ff\uf900-\ufdcf\ufdf0-\ufffd\U00010000-\U000effff"
)
_NAME_CHAR = _NAME_START + r"\-.0-9\u00b7\u0300-\u036f\u203f-\u2040"


# Compiled on first use: these character classes take tens of milliseconds to compile.
XML_NAME_RE = LazyPattern(f"[{_NAME_START}][{_NAME_CHAR}]*")
_NOT_NAME_CHAR = LazyPattern(f"[^{_NAME_CHAR}]")
# The same for ASCII names (the common case), cheap to compile.
_ASCII_NAME_RE = re.compile(r"[:A-Z_a-z][-.0-9:A-Z_a-z]*")
_ASCII_NOT_NAME_CHAR = re.compile(r"[^-.0-9:A-Z_a-z]")
# Characters the name rules already report (so an XML-name error would only repeat it).
_RULE_FORBIDDEN = FORBIDDEN | CONTROL_CHARS


def xml_name_problem(name: str, checked: bool, port: bool = False) -> tuple[int, str] | None:
    """First character that makes ``name`` an invalid XML name, unless the name rules
    already report it (``checked``; for a ``port``, a leading digit too): (index, message)."""
    if name.isascii():
        if _ASCII_NAME_RE.fullmatch(name):
            return None
        name_re: Any = _ASCII_NAME_RE
        not_name: Any = _ASCII_NOT_NAME_CHAR
    else:
        name_re, not_name = XML_NAME_RE, _NOT_NAME_CHAR
        if name_re.fullmatch(name):
            return None
    if name and not name_re.match(name[0]) and not_name.match(name[0]) is None:
        if port and checked and name[0] in "0123456789":
            return None
        if not checked or name[0] not in _RULE_FORBIDDEN:
            return 0, f"An XML name cannot start with {name[0]!r}"
        return None
    for m in not_name.finditer(name):
        ch = m.group(0)
        if checked and ch in _RULE_FORBIDDEN:
            continue
        shown = repr(ch) if ch.isprintable() else f"U+{ord(ch):04X}"
        return m.start(), f"{shown} is not allowed in an XML name ('{name}')"
    return None


# What names were found to break, by (name, checked, port): for one pass (names repeat).
XmlNameMemo = dict[tuple[str, bool, bool], tuple[int, str] | None]


def cached_xml_name_problem(
    name: str, checked: bool, port: bool, memo: XmlNameMemo
) -> tuple[int, str] | None:
    """:func:`xml_name_problem`, remembered in ``memo`` (the caller's, bounded)."""
    key = (name, checked, port)
    try:
        return memo[key]
    except KeyError:
        pass
    if len(memo) >= 65536:
        memo.clear()
    found = memo[key] = xml_name_problem(name, checked, port)
    return found
