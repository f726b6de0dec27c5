"""``bt-lsp.mapRunningTree`` end to end: a running tree's FULLTREE (recorded from
BehaviorTree.CPP 4.8.2) mapped by the real server onto an open document and the document
it includes, with ranges in the negotiated encoding (UTF-16, UTF-8, UTF-32 clients)."""

from __future__ import annotations

import asyncio
from typing import Any

import pytest
from lsprotocol import types
from pygls.exceptions import JsonRpcException

from tests.server.conftest import TIMEOUT, BtClient, clients
from tests.test_live_mapping import EXPECTED, FULLTREE, INC, MAIN, at

pytestmark = [
    pytest.mark.asyncio(loop_scope="module"),
    clients("vscode", "nvim-0.11", "emacs"),  # utf-16, utf-8 and utf-32
]

COMMAND = "bt-lsp.mapRunningTree"
# Comments change no node: characters of every width before the elements, on their line.
INC_TEXT = INC.replace("<Sleep", "<!-- 😋 ü --><Sleep")


async def _map(client: BtClient, args: Any) -> Any:
    return await asyncio.wait_for(
        client.workspace_execute_command_async(
            types.ExecuteCommandParams(command=COMMAND, arguments=[args])
        ),
        TIMEOUT,
    )


def _range(r: dict[str, Any]) -> types.Range:
    return types.Range(
        types.Position(r["start"]["line"], r["start"]["character"]),
        types.Position(r["end"]["line"], r["end"]["character"]),
    )


def _open_pair(client: BtClient, main: str = MAIN) -> tuple[str, str, dict[str, str]]:
    """inc.xml and main.xml (including it) open; their URIs and texts by file name."""
    inc_uri = client.open(INC_TEXT, name="inc")
    inc_name = inc_uri.rsplit("/", 1)[1]
    main_text = main.replace('path="inc.xml"', f'path="{inc_name}"')
    main_text = main_text.replace("<Script", "<!-- 🚀 --><Script")
    main_uri = client.open(main_text, name="main")
    return main_uri, inc_uri, {"main.xml": main_text, "inc.xml": INC_TEXT}


def _name_range(client: BtClient, text: str, start: int) -> types.Range:
    end = start
    while text[end].isalnum():
        end += 1
    return client.range(text, start, end)


async def test_command_is_declared(client: BtClient) -> None:
    provider = client.init_result.capabilities.execute_command_provider
    assert provider is not None and COMMAND in provider.commands


async def test_every_uid_maps_to_its_element_in_the_document_or_its_include(
    client: BtClient,
) -> None:
    main_uri, inc_uri, texts = _open_pair(client)
    await client.diags(main_uri, 1)
    result = await _map(client, {"uri": main_uri, "tree": FULLTREE})
    assert result["tree"] == "Main" and result["mismatches"] == []
    uris = {"main.xml": main_uri, "inc.xml": inc_uri}
    got = {n["uid"]: (n["uri"], _range(n["range"])) for n in result["nodes"]}
    want = {
        uid: (uris[file], _name_range(client, texts[file], at(texts[file], snippet)))
        for uid, (file, snippet) in EXPECTED.items()
    }
    assert got == want
    tree = result["treeLocation"]
    start = at(texts["main.xml"], '<|BehaviorTree ID="Main"')
    assert tree["uri"] == main_uri
    assert _range(tree["range"]) == _name_range(client, texts["main.xml"], start)


async def test_an_edit_is_reported_where_it_is(client: BtClient) -> None:
    main_uri, _, texts = _open_pair(client)
    await client.diags(main_uri, 1)
    edited = texts["main.xml"].replace('name="ok"', 'name="fine"')
    edited = edited.replace('      <Action ID="AlwaysSuccess" name="act"/>\n', "")
    client.replace(main_uri, 2, edited)
    result = await _map(client, {"uri": main_uri, "tree": FULLTREE})
    by_uid = {m["uid"]: m for m in result["mismatches"]}
    assert set(by_uid) == {19, 22}
    assert by_uid[19]["kind"] == "missing" and "range" not in by_uid[19]
    assert by_uid[19]["path"] == "act" and by_uid[19]["tag"] == "AlwaysSuccess"
    renamed = by_uid[22]
    assert renamed["kind"] == "renamed" and renamed["uri"] == main_uri
    fine = at(edited, '<|AlwaysSuccess name="fine"')
    assert _range(renamed["range"]) == _name_range(client, edited, fine)
    assert 19 not in {n["uid"] for n in result["nodes"]}


async def test_malformed_trees_and_bad_arguments_are_clear_errors(client: BtClient) -> None:
    main_uri, _, _ = _open_pair(client)
    await client.diags(main_uri, 1)
    for tree, why in (
        ("<root><BehaviorTree", "not XML"),
        ('<root><BehaviorTree ID="M"><A/></BehaviorTree></root>', "no valid _uid"),
        ("", "not XML"),
    ):
        with pytest.raises(JsonRpcException, match=why):
            await _map(client, {"uri": main_uri, "tree": tree})
    for bad in ({"uri": main_uri}, {"uri": main_uri, "tree": 3}, {"tree": FULLTREE}):
        with pytest.raises(JsonRpcException):
            await _map(client, bad)
    with pytest.raises(JsonRpcException, match="not an open document"):
        await _map(client, {"uri": "file:///nowhere/x.xml", "tree": FULLTREE})
    # The server keeps serving.
    result = await _map(client, {"uri": main_uri, "tree": FULLTREE})
    assert len(result["nodes"]) == 22
