"""Marked fixtures: ``⟦…⟧`` marks expected spans in an XML snippet."""

from __future__ import annotations

OPEN, CLOSE = "⟦", "⟧"


def unmark(marked: str) -> tuple[str, list[tuple[int, int]]]:
    """The text without marks, and the code-point spans the marks enclosed (in order)."""
    out: list[str] = []
    spans: list[tuple[int, int]] = []
    stack: list[int] = []
    pos = 0
    for ch in marked:
        if ch == OPEN:
            stack.append(pos)
        elif ch == CLOSE:
            spans.append((stack.pop(), pos))
        else:
            out.append(ch)
            pos += 1
    assert not stack, "unbalanced marks"
    return "".join(out), sorted(spans)
