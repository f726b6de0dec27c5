"""Text edits over code-point offsets and applying them.

Core layers return edits; only front ends (server, CLI) decide to apply them.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass


@dataclass(frozen=True, slots=True, order=True)
class TextEdit:
    """Replace ``text[start:end]`` (code-point offsets) with ``new_text``."""

    start: int
    end: int
    new_text: str


def apply_edits(text: str, edits: Iterable[TextEdit]) -> str:
    """Apply non-overlapping edits (any order); identical duplicates are applied once."""
    ordered = sorted(set(edits))
    parts: list[str] = []
    pos = 0
    for edit in ordered:
        if edit.start < pos:
            raise ValueError(f"overlapping edits at offset {edit.start}")
        parts.append(text[pos : edit.start])
        parts.append(edit.new_text)
        pos = edit.end
    parts.append(text[pos:])
    return "".join(parts)


def escape_value(text: str, quote: str) -> str:
    """``text`` written inside an attribute value delimited by ``quote``."""
    text = text.replace("&", "&amp;").replace("<", "&lt;")
    if quote == '"':
        text = text.replace('"', "&quot;")
    elif quote == "'":
        text = text.replace("'", "&apos;")
    return text
