"""Completion for BT XML, tolerant of half-typed text.

Pure: :func:`complete` reads the scanner's token under the cursor and the document model,
and returns plain items with the span they replace (code-point offsets).  Contexts:

* a start tag's name after ``<``: the elements allowed there (in a tree, the built-in and
  declared node types, with their required ports, and a ``<SubTree>`` call of each tree);
* an empty line, the space between tags or the indentation before a tag (Ctrl+Space with
  no ``<`` typed): the same elements, the ``<`` included, where one fits (not in a leaf, a
  full decorator or a tree that has its child); before a tag the new element goes in front
  of it, on a line of its own where the client inserts text as it is;
* an end tag's name after ``</``: the element it closes;
* an attribute name in a start tag: the ports of the node and the reserved attributes;
* an attribute value: tree IDs in ``<SubTree ID>`` and ``main_tree_to_execute``, node types
  in ``<Action|Condition|Control|Decorator ID>``, ``true``/``false`` and statuses for bool
  and ``NodeStatus`` ports, and after ``{`` the blackboard keys used in the tree (in port
  values and scripts).

This module finds the context; :mod:`~bt_lsp.ide.completion_tags` (element names) and
:mod:`~bt_lsp.ide.completion_attrs` (attribute names and values) make its items, with the
item types and text helpers of :mod:`~bt_lsp.ide.completion_items`.
"""

from __future__ import annotations

from bt_lsp.ide.completion_attrs import attribute_names, attribute_value
from bt_lsp.ide.completion_items import (
    Completions,
    Item,
    ItemKind,
    ports_markdown,
)
from bt_lsp.ide.completion_tags import between_tags, end_tag_name, innermost, tag_names
from bt_lsp.rules.context import Context
from bt_lsp.syntax.document import Document
from bt_lsp.syntax.elements import Element
from bt_lsp.syntax.model import Model
from bt_lsp.syntax.tokens import Kind

__all__ = ["Completions", "Item", "ItemKind", "complete", "ports_markdown"]


def _element_at(model: Model, token_start: int) -> tuple[int, Element] | None:
    for i, el in enumerate(model.elements):
        if el.token_start == token_start:
            return i, el
        if el.token_start > token_start:
            break
    return None


def complete(doc: Document, offset: int, ctx: Context | None = None) -> Completions | None:
    """Completions at ``offset``, or ``None`` where there is nothing to propose."""
    if ctx is None:
        ctx = Context.from_document(doc)
    offset = min(max(offset, 0), len(doc.text))
    if offset == 0:
        return None
    scan = doc.scan
    ti = scan.index_at(offset - 1)
    tstart, tok = scan.starts[ti], scan.tokens[ti]
    rel = offset - tstart
    model = doc.model
    if tok.kind == Kind.STRAY and tok.length == 1 and rel == 1:
        parent = innermost(model, offset)
        return tag_names(doc, ctx, offset, offset, parent, bare=True)
    if tok.kind == Kind.END and 2 <= rel <= tok.name_end:
        return end_tag_name(doc, tstart, tok, offset)
    if tok.kind == Kind.TEXT or (
        tok.kind in (Kind.START, Kind.END, Kind.COMMENT) and tok.closed and rel >= tok.length
    ):
        return between_tags(doc, ctx, offset, tstart if tok.kind == Kind.TEXT else offset)
    if tok.kind != Kind.START:
        return None
    hit = _element_at(model, tstart)
    if hit is None:
        return None
    idx, el = hit
    if rel <= tok.name_end:
        bare = not tok.attrs and not tok.closed
        return tag_names(doc, ctx, tstart + 1, tstart + tok.name_end, el.parent, bare=bare)
    if tok.closed and rel >= tok.length:
        return None
    text = doc.text
    for a in tok.attrs:
        if a.value is not None and a.value_start <= rel <= a.value_end:
            return attribute_value(doc, ctx, idx, el, a, offset)
        if a.name_start < rel <= a.name_end:
            return attribute_names(
                ctx, el, tstart + a.name_start, tstart + a.name_end, a.value is not None, a.name
            )
    if text[offset - 1] in " \t\r\n":
        return attribute_names(
            ctx, el, offset, offset, False, None, before_name=_name_follows(text, offset)
        )
    return None


def _name_follows(text: str, offset: int) -> bool:
    return offset < len(text) and text[offset] not in " \t\r\n/>"
