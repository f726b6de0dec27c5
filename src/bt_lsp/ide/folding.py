"""Folding ranges and linked editing of an element's start- and end-tag names."""

from __future__ import annotations

from dataclasses import dataclass

from bt_lsp.ide.places import element_at_tag, element_end
from bt_lsp.syntax.document import Document
from bt_lsp.syntax.tokens import Kind


@dataclass(frozen=True, slots=True, order=True)
class Fold:
    """Lines to fold (0-based, both included); ``comment`` for comments."""

    start_line: int
    end_line: int
    comment: bool = False


def folding_ranges(doc: Document) -> list[Fold]:
    """Elements that span several lines (the line of their end tag stays visible when the
    end tag starts its line), and comments that span several lines."""
    lines = doc.lines
    text = doc.text
    out: set[Fold] = set()
    for el in doc.model.elements:
        first = lines.line_of(el.token_start)
        end = element_end(doc, el)
        last = lines.line_of(max(end - 1, el.token_start))
        if el.end_name_start >= 0:
            tag = el.end_name_start - 2  # '</'
            line_start = lines.line_start(last)
            if text[line_start:tag].strip() == "" and last > first:
                last -= 1
        if last > first:
            out.add(Fold(first, last))
    for start, tok in zip(doc.scan.starts, doc.scan.tokens, strict=True):
        if tok.kind == Kind.COMMENT:
            first = lines.line_of(start)
            last = lines.line_of(start + tok.length - 1)
            if last > first:
                out.add(Fold(first, last, comment=True))
    return sorted(out)


def linked_editing_ranges(doc: Document, offset: int) -> list[tuple[int, int]] | None:
    """The start-tag and end-tag names of the element whose tag name holds ``offset``, so
    that editing one edits the other; ``None`` outside a tag name or without an end tag."""
    model = doc.model
    hit = element_at_tag(model, offset)
    if hit is None:
        return None
    el = model.elements[hit[0]]
    if el.end_name_start < 0:
        return None
    return [(el.name_start, el.name_end), (el.end_name_start, el.end_name_end)]
