"""Typing recovery end to end: a ``<BehaviorTree`` typed below a tree that is not closed
yet is a tree, its ID checked as a tree ID, as the user types it; a NUL reference in a name
gets the name's own diagnostic."""

from __future__ import annotations

import pytest
from lsprotocol import types

from tests.server.conftest import BtClient, clients
from tests.test_typing_recovery import OPEN_TREE

pytestmark = [pytest.mark.asyncio(loop_scope="module"), clients("vscode", "nvim-0.11")]


async def test_a_tree_typed_below_an_open_one_is_checked_as_a_tree(client: BtClient) -> None:
    typed = '  <BehaviorTree ID="Bad Tree">\n'
    at = OPEN_TREE.index(typed)
    before = OPEN_TREE[:at]
    uri = client.open(before + "</root>\n")
    await client.diags(uri, 1)
    # Typed at the end of the open tree, as one change.
    where = client.pos(before, at)
    client.change(
        uri,
        2,
        types.TextDocumentContentChangePartial(range=types.Range(where, where), text=typed),
    )
    diags = await client.diags(uri, 2)
    text = before + typed + "</root>\n"
    found = [(d.code, d.range) for d in diags]
    s = text.index("Bad Tree")
    assert ("model-name-forbidden-char", client.range(text, s, s + len("Bad Tree"))) in found
    assert not any(d.code in ("unknown-node", "id-on-compact-node") for d in diags)


async def test_a_nul_reference_in_a_name(client: BtClient) -> None:
    text = '<root BTCPP_format="4"><BehaviorTree ID="A&#0;B"><AlwaysSuccess/></BehaviorTree></root>'
    uri = client.open(text)
    diags = await client.diags(uri, 1)
    s = text.index("A&#0;B")
    name = [d for d in diags if d.code == "model-name-forbidden-char"]
    assert [d.range for d in name] == [client.range(text, s, s + len("A&#0;B"))]
    assert "U+0000" in name[0].message
    assert any(d.code == "xml-syntax" for d in diags)
