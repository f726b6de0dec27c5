"""A document while a declaration before ``<root>`` is being typed (``<!``, ``<!-``,
``<!DOCTYPE``, ``<?``): the scanner reads the rest as one stray token, and the document
has no element at all.  Its element table had a length of -1 there, and the outline
failed (``__len__() should return >= 0``)."""

from __future__ import annotations

import contextlib

import pytest

from bt_lsp.ide.folding import folding_ranges, linked_editing_ranges
from bt_lsp.ide.references import highlights
from bt_lsp.ide.rename import RenameRefused, prepare_rename
from bt_lsp.ide.symbols import document_symbols
from bt_lsp.rules.analysis import analyze
from bt_lsp.rules.context import Context
from bt_lsp.server.navigation import outline_json
from bt_lsp.syntax.document import Document

BODY = '<root BTCPP_format="4"><BehaviorTree ID="Main"><AlwaysSuccess/></BehaviorTree></root>'

# The states of typing each declaration in front of the document, one character at a time.
DECLARATIONS = ["<!-- note -->", "<!DOCTYPE root>", '<?xml version="1.0"?>', "<![CDATA[x]]>"]
PREFIXES = sorted({d[:k] for d in DECLARATIONS for k in range(1, len(d) + 1)})
REPORTED = ["<!<root>", "<!-<root>", "<!DOCTYPE<root>", "<?<BehaviorTree "]


def _texts() -> list[str]:
    return REPORTED + [p + BODY for p in PREFIXES] + [p + " " + BODY for p in PREFIXES]


@pytest.mark.parametrize("text", _texts())
def test_every_feature_on_a_half_typed_declaration(text: str) -> None:
    doc = Document(text)
    head = doc.model.head
    assert head is not None and len(head.elements) >= 0
    outline_json(doc, Context(), "utf-16")
    document_symbols(doc)
    folding_ranges(doc)
    analyze(doc)
    for offset in range(len(text) + 1):
        highlights(doc, offset)
        linked_editing_ranges(doc, offset)
        with contextlib.suppress(RenameRefused):
            prepare_rename(doc, offset)


def test_an_empty_element_table_has_no_rows() -> None:
    for text in ["", "text", "<!", "<!<root>"]:
        head = Document(text).model.head
        assert head is not None
        elements = head.elements
        assert len(elements) == 0
        assert list(elements) == []
        assert list(elements[0:5]) == []
