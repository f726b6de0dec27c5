"""Marked fixtures: ``⟦…⟧`` marks expected spans in an XML snippet and ``‸`` the cursor;
every test that marks a text reads its marks here."""

from __future__ import annotations

OPEN, CLOSE = "⟦", "⟧"
CURSOR = "‸"


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


def cursor(marked: str) -> tuple[str, int, list[tuple[int, int]]]:
    """The text without marks, the cursor's offset in it (``‸``; -1 without one) and the
    marked spans."""
    at = marked.find(CURSOR)
    offset = -1 if at == -1 else at - sum(marked[:at].count(c) for c in (OPEN, CLOSE))
    text, spans = unmark(marked.replace(CURSOR, ""))
    return text, offset, spans
