"""A name used thousands of times in one tree: a hover or a definition there reads the tag
under the cursor and the declarations only, and the document highlights (asked at every
move of the cursor) are the ``MAX_HIGHLIGHTS`` uses nearest it, not all of them."""

from __future__ import annotations

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
