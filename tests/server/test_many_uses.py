"""A name used thousands of times in one tree: a hover or a definition there reads the tag
under the cursor and the declarations only, and the document highlights (asked at every
move of the cursor) are the ``MAX_HIGHLIGHTS`` uses nearest it, not all of them."""

from __future__ import annotations

from typing import Any

import pytest
from lsprotocol import types

from bt_lsp.ide.references import MAX_HIGHLIGHTS
from tests.server.conftest import BtClient, clients, raw_request

pytestmark = pytest.mark.asyncio(loop_scope="module")

USES = 3 * MAX_HIGHLIGHTS
TEXT = (
    '<root BTCPP_format="4" main_tree_to_execute="T">\n'
    '<BehaviorTree ID="T">\n<Sequence>\n'
    + '  <Frob goal="{g}"/>\n'
    * USES
    + "</Sequence>\n</BehaviorTree>\n"
    '<TreeNodesModel>\n<Action ID="Frob">\n<input_port name="goal"/>\n</Action>\n'
    "</TreeNodesModel>\n</root>\n"
)
MIDDLE = 3 + USES // 2  # the line of a use in the middle of the tree
DECLARED = 3 + USES + 3  # the line of <Action ID="Frob">


@clients("vscode", "nvim-0.11")
async def test_requests_on_a_name_used_thousands_of_times(client: BtClient) -> None:
    uri = client.open(TEXT)
    await client.diags(uri, 1)
    at = {"textDocument": {"uri": uri}, "position": {"line": MIDDLE, "character": 4}}

    hover = await client.hover(uri, types.Position(MIDDLE, 4))
    assert hover is not None
    assert isinstance(hover.contents, types.MarkupContent)
    assert f"line {DECLARED + 1}" in hover.contents.value  # where its model declares it

    places = await raw_request(client, types.TEXT_DOCUMENT_DEFINITION, at)
    assert [p["range"]["start"]["line"] for p in places] == [DECLARED]

    found = await raw_request(client, types.TEXT_DOCUMENT_DOCUMENT_HIGHLIGHT, at)
    lines = [h["range"]["start"]["line"] for h in found]
    assert len(lines) == MAX_HIGHLIGHTS
    assert lines == list(range(MIDDLE - MAX_HIGHLIGHTS // 2, MIDDLE + MAX_HIGHLIGHTS // 2))

    refs = await raw_request(
        client, types.TEXT_DOCUMENT_REFERENCES, {**at, "context": {"includeDeclaration": True}}
    )
    assert len(refs) == USES + 1  # references stay complete: every use and the declaration
    client.close(uri)


# The same uses on one line after characters of every width: each request converts all its
# positions in one pass over the line (one at a time, each counted the line from its start).
LINE_USES = 2_000
ONE_LINE = (
    '<root BTCPP_format="4" main_tree_to_execute="T">\n'
    '<BehaviorTree ID="T"><Sequence>'
    + '<Frob goal="😋é\t{g}"/>'
    * LINE_USES
    + "</Sequence></BehaviorTree>\n"
    '<TreeNodesModel>\n<Action ID="Frob">\n<input_port name="goal"/>\n</Action>\n'
    "</TreeNodesModel>\n</root>\n"
)


@clients("vscode-utf8", "nvim-0.11-utf16", "vscode-utf32")
async def test_many_positions_on_one_line_are_exact(client: BtClient) -> None:
    uri = client.open(ONE_LINE)
    await client.diags(uri, 1)
    uses = [i + 1 for i in range(len(ONE_LINE)) if ONE_LINE.startswith("<Frob ", i)]
    assert len(uses) == LINE_USES
    middle = uses[LINE_USES // 2]
    pos = client.pos(ONE_LINE, middle + 1)
    at = {
        "textDocument": {"uri": uri},
        "position": {"line": pos.line, "character": pos.character},
    }
    declared = ONE_LINE.index('"Frob"') + 1

    def ranges(found: list[dict[str, object]]) -> list[types.Range]:
        return [
            types.Range(
                types.Position(**r["range"]["start"]),  # type: ignore[index]
                types.Position(**r["range"]["end"]),  # type: ignore[index]
            )
            for r in found
        ]

    expected = [client.range(ONE_LINE, u, u + 4) for u in [*uses, declared]]
    refs = await raw_request(
        client, types.TEXT_DOCUMENT_REFERENCES, {**at, "context": {"includeDeclaration": True}}
    )
    assert sorted(ranges(refs), key=_key) == sorted(expected, key=_key)

    found = await raw_request(client, types.TEXT_DOCUMENT_DOCUMENT_HIGHLIGHT, at)
    near = uses[LINE_USES // 2 - MAX_HIGHLIGHTS // 2 : LINE_USES // 2 + MAX_HIGHLIGHTS // 2]
    assert ranges(found) == [client.range(ONE_LINE, u, u + 4) for u in near]

    edit = await client.text_document_rename_async(
        types.RenameParams(types.TextDocumentIdentifier(uri), pos, "Knob")
    )
    assert edit is not None
    edits: list[Any]
    if edit.document_changes:
        edits = [e for c in edit.document_changes for e in c.edits]  # type: ignore[union-attr]
    else:
        assert edit.changes is not None
        edits = list(edit.changes[uri])
    assert {e.new_text for e in edits} == {"Knob"}
    assert sorted((e.range for e in edits), key=_key) == sorted(expected, key=_key)
    client.close(uri)


def _key(r: types.Range) -> tuple[int, int, int, int]:
    return r.start.line, r.start.character, r.end.line, r.end.character
