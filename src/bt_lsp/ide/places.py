"""What the navigation features answer with: a :class:`Place` in some document, an
``<include>`` resolved by the project layer, and where an element's tags are."""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

from bt_lsp.syntax.document import Document
from bt_lsp.syntax.elements import Element
from bt_lsp.syntax.model import Model


class IncludeLink(NamedTuple):
    """An ``<include path>`` value's span and the file it resolves to (the project layer
    resolves it; this layer reads no files)."""

    start: int
    end: int
    target: str


@dataclass(frozen=True, slots=True, order=True)
class Place:
    """A span in a document: ``None`` for the document asked about, else a path (or
    :data:`BUILTIN_CATALOG`)."""

    path: str | None
    start: int
    end: int


def element_end(doc: Document, el: Element) -> int:
    """Offset after an element: after its end tag, or after its start tag when it was
    never closed."""
    if el.end >= 0:
        return el.end
    return el.token_start + doc.scan.tokens[el.token_index].length


def element_at_tag(model: Model, offset: int) -> tuple[int, bool] | None:
    """The element whose start-tag name (``False``) or end-tag name (``True``) holds
    ``offset`` (its end counts)."""
    for i, el in enumerate(model.elements):
        if el.name_start <= offset <= el.name_end:
            return i, False
        if el.end_name_start >= 0 and el.end_name_start <= offset <= el.end_name_end:
            return i, True
    return None
