"""The outline's JSON, written directly, is what lsprotocol's DocumentSymbols give once
unstructured, in every encoding; deeper than ``MAX_SYMBOL_DEPTH`` the symbols follow
their ancestor at that depth."""

from __future__ import annotations

import json
from typing import Any

import pytest
from lsprotocol import types
from pygls.protocol import default_converter

from bt_lsp.ide.symbols import DocSymbol, document_symbols
from bt_lsp.server.convert import to_range
from bt_lsp.server.navigation import _SYMBOL_KINDS, MAX_SYMBOL_DEPTH, document_symbols_json
from bt_lsp.syntax.document import Document
from bt_lsp.syntax.text import Encoding, LineIndex
from tests.server.test_deep_nesting import deep

DOCS = [
    '<root BTCPP_format="4">\r\n<BehaviorTree ID="😋 a">\r<Sequence name="é"/>'
    '</BehaviorTree>\n<TreeNodesModel><Action ID="X"><input_port name="p"/></Action>'
    '</TreeNodesModel><include path="b.xml"/></root>',
    deep(3),
    deep(MAX_SYMBOL_DEPTH + 5),
]


def reference(lines: LineIndex, s: DocSymbol, enc: Encoding, depth: int) -> list[Any]:
    """The expected symbols through lsprotocol (recursive; fine at these depths):
    ``s`` with its children nested, or at the depth limit followed by its descendants."""

    def made(children: list[Any]) -> types.DocumentSymbol:
        return types.DocumentSymbol(
            name=s.name,
            detail=s.detail or None,
            kind=_SYMBOL_KINDS[s.kind],
            range=to_range(lines, s.start, s.end, enc),
            selection_range=to_range(lines, s.sel_start, s.sel_end, enc),
            children=children,
        )

    if depth < MAX_SYMBOL_DEPTH:
        return [made([x for c in s.children for x in reference(lines, c, enc, depth + 1)])]
    return [made([]), *(x for c in s.children for x in reference(lines, c, enc, depth))]


@pytest.mark.parametrize("text", DOCS)
@pytest.mark.parametrize("enc", ["utf-8", "utf-16", "utf-32"])
def test_outline_json_is_lsprotocol_s(text: str, enc: Encoding) -> None:
    doc = Document(text, "x.xml")
    symbols = document_symbols(doc)
    expected: list[Any] = []
    for s in symbols:
        expected.extend(reference(doc.lines, s, enc, 1))
    got = json.loads(document_symbols_json(doc.lines, symbols, enc))
    assert got == default_converter().unstructure(expected)
    assert got  # the documents do have an outline
