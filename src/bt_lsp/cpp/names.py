"""Small helpers on C++ source text: names as written, template arguments, escapes."""

from __future__ import annotations

import re
from typing import Final


def split_top(s: str) -> list[str]:
    """``s`` split at its top-level commas (not those inside ``<>``, ``()``, ``[]``, ``{}``)."""
    out: list[str] = []
    depth = 0
    cur: list[str] = []
    for ch in s:
        if ch in "<([{":
            depth += 1
        elif ch in ">)]}":
            depth -= 1
        if ch == "," and depth == 0:
            out.append("".join(cur))
            cur = []
        else:
            cur.append(ch)
    if "".join(cur).strip():
        out.append("".join(cur))
    return out


def squash(s: str) -> str:
    """Source text with its runs of whitespace made one space (none next to ``<>:,``)."""
    s = " ".join(s.split())
    return re.sub(r"\s*(::|<|>|,)\s*", lambda m: m.group(1) + (" " if m.group(1) == "," else ""), s)


def strip_args(name: str) -> str:
    """``ns::Foo<int>`` -> ``ns::Foo``; ``A<B>::C`` -> ``A::C``."""
    if "<" not in name:
        return name.strip()
    out: list[str] = []
    depth = 0
    for ch in name:
        if ch == "<":
            depth += 1
        elif ch == ">":
            depth -= 1
        elif depth == 0:
            out.append(ch)
    return "".join(out).strip()


def last_name(name: str) -> str:
    return name.rsplit("::", 1)[-1].strip()


_ESCAPES: Final = {"n": "\n", "t": "\t", "r": "\r", "\\": "\\", '"': '"', "'": "'", "0": "\0"}


def unescape(s: str) -> str:
    return re.sub(r"\\(.)", lambda m: _ESCAPES.get(m.group(1), m.group(0)), s)
