"""``bt-lsp.renderTree`` end to end: the tree at a position, drawn by the real server,
with every node's range in the negotiated encoding (UTF-16, UTF-8, UTF-32 clients)."""

from __future__ import annotations

import asyncio
from typing import Any

import pytest
from lsprotocol import types
from lxml import etree
from pygls.exceptions import JsonRpcException

from tests.server.conftest import TIMEOUT, BtClient, clients

pytestmark = [
    pytest.mark.asyncio(loop_scope="module"),
    clients("vscode", "nvim-0.11", "emacs"),  # utf-16, utf-8 and utf-32
]

SVG = "{http://www.w3.org/2000/svg}"

DOC = (
    '<root BTCPP_format="4" main_tree_to_execute="Main">\r\n'
    '  <BehaviorTree ID="Main">\r\n'
    '    <Sequence name="😋 first">\r\n'
    '      <Say msg="{greeting}"/>\r\n'
    '      <SubTree ID="Helper"/>\r\n'
    "    </Sequence>\r\n"
    "  </BehaviorTree>\r\n"
    '  <BehaviorTree ID="Helper">\r\n'
    "    <Inverter><AlwaysSuccess/><AlwaysFailure/></Inverter>\r\n"
    "  </BehaviorTree>\r\n"
    "  <TreeNodesModel>\r\n"
    '    <Action ID="Say"><input_port name="msg"/></Action>\r\n'
    "  </TreeNodesModel>\r\n"
    "</root>\r\n"
)


async def _render(client: BtClient, args: Any) -> Any:
    return await asyncio.wait_for(
        client.workspace_execute_command_async(
            types.ExecuteCommandParams(command="bt-lsp.renderTree", arguments=[args])
        ),
        TIMEOUT,
    )


def _span(text: str, needle: str, end_needle: str | None = None) -> tuple[int, int]:
    start = text.index(needle)
    if end_needle is None:
        return start, text.index("/>", start) + 2
    return start, text.index(end_needle, start) + len(end_needle)


def _as_range(r: dict[str, Any]) -> types.Range:
    return types.Range(
        types.Position(r["start"]["line"], r["start"]["character"]),
        types.Position(r["end"]["line"], r["end"]["character"]),
    )


async def test_command_is_declared(client: BtClient) -> None:
    provider = client.init_result.capabilities.execute_command_provider
    assert provider is not None and "bt-lsp.renderTree" in provider.commands


async def test_tree_at_position_with_exact_ranges(client: BtClient) -> None:
    uri = client.open(DOC)
    await client.diags(uri, 1)
    at = DOC.index("<Say")
    result = await _render(client, {"uri": uri, "position": _pos(client, at)})
    assert result["tree"] == "Main" and result["format"] == "svg"
    assert result["trees"] == ["Main", "Helper"]
    nodes = result["nodes"]
    assert [(n["kind"], n["type"], n["name"]) for n in nodes] == [
        ("tree", "Main", None),
        ("control", "Sequence", "😋 first"),
        ("action", "Say", None),
        ("subtree", "Helper", None),
    ]
    expected = {
        "Sequence": _span(DOC, "<Sequence", "</Sequence>"),
        "Say": _span(DOC, "<Say"),
        "Helper": _span(DOC, '<SubTree ID="Helper"'),
        "Main": _span(DOC, '<BehaviorTree ID="Main"', "</BehaviorTree>"),
    }
    for n in nodes:
        assert _as_range(n["range"]) == client.range(DOC, *expected[n["type"]]), n
    # The SubTree node says where its tree is, for the client to open it.
    helper_id = DOC.index('"Helper">') + 1
    target = nodes[3]["target"]
    assert target["uri"] == uri
    assert _as_range(target["range"]).start == client.pos(DOC, DOC.index('BehaviorTree ID="Helper'))
    assert helper_id > 0
    svg = etree.fromstring(result["svg"].encode())
    ids = [g.get("id") for g in svg.iter(f"{SVG}g") if "node" in (g.get("class") or "").split()]
    assert ids == [n["id"] for n in nodes]


async def test_other_tree_with_problems_expanded_and_text_formats(client: BtClient) -> None:
    uri = client.open(DOC)
    await client.diags(uri, 1)
    at = DOC.index("<AlwaysFailure")
    result = await _render(client, {"uri": uri, "position": _pos(client, at), "format": "mermaid"})
    assert result["tree"] == "Helper" and "svg" not in result
    assert result["text"].startswith("flowchart TD\n")
    inverter = next(n for n in result["nodes"] if n["type"] == "Inverter")
    assert inverter["severity"] == 1  # a decorator with two children: an error
    result = await _render(
        client, {"uri": uri, "tree": "Main", "format": "dot", "expandSubtrees": True, "ports": True}
    )
    assert result["text"].startswith('digraph "Main" {')
    types_ = [n["type"] for n in result["nodes"]]
    assert types_ == [
        "Main",
        "Sequence",
        "Say",
        "Helper",
        "Inverter",
        "AlwaysSuccess",
        "AlwaysFailure",
    ]
    assert "msg: {greeting}" in result["text"]


async def test_follows_an_edit(client: BtClient) -> None:
    uri = client.open(DOC)
    await client.diags(uri, 1)
    new = DOC.replace('<Say msg="{greeting}"/>', '<Say msg="{greeting}"/><AlwaysSuccess/>')
    client.replace(uri, 2, new)
    result = await _render(client, {"uri": uri, "position": _pos(client, 0, new)})
    assert [n["type"] for n in result["nodes"]] == [
        "Main",
        "Sequence",
        "Say",
        "AlwaysSuccess",
        "Helper",
    ]


def _lsp_range(client: BtClient, text: str, start: int, end: int) -> dict[str, Any]:
    r = client.range(text, start, end)
    return {
        "start": {"line": r.start.line, "character": r.start.character},
        "end": {"line": r.end.line, "character": r.end.character},
    }


async def test_names_the_node_an_edit_changed(client: BtClient) -> None:
    """``edited`` (what the client's edits replaced) gives ``changed``, the node to keep in
    view: a node typed in, a character of a line with a non-ASCII one before it."""
    uri = client.open(DOC)
    await client.diags(uri, 1)
    added = "<AlwaysSuccess/>"
    new = DOC.replace('<Say msg="{greeting}"/>', '<Say msg="{greeting}"/>' + added)
    client.replace(uri, 2, new)
    at = new.index(added)
    plain = await _render(client, {"uri": uri, "position": _pos(client, 0, new)})
    assert plain["changed"] is None
    result = await _render(
        client,
        {
            "uri": uri,
            "position": _pos(client, 0, new),
            "edited": _lsp_range(client, new, at, at + len(added)),
        },
    )
    by_id = {n["id"]: n["type"] for n in result["nodes"]}
    assert by_id[result["changed"]] == "AlwaysSuccess"
    # The last character of a node after an emoji (2 UTF-16 units, 4 bytes) of its line:
    # read one code point too far, the edit would be the next node's.
    emoji = new.replace('msg="{greeting}"', 'msg="😋"')
    client.replace(uri, 3, emoji)
    gt = emoji.index("<AlwaysSuccess/>") - 1
    edited = _lsp_range(client, emoji, gt, gt + 1)
    result = await _render(client, {"uri": uri, "tree": "Main", "edited": edited})
    assert by_id[result["changed"]] == "Say"
    edited = _lsp_range(client, emoji, gt + 1, gt + 2)
    result = await _render(client, {"uri": uri, "tree": "Main", "edited": edited})
    assert by_id[result["changed"]] == "AlwaysSuccess"
    outside = emoji.index("<TreeNodesModel>")
    edited = _lsp_range(client, emoji, outside, outside)
    result = await _render(client, {"uri": uri, "tree": "Main", "edited": edited})
    assert result["changed"] is None


async def test_no_tree_and_bad_arguments(client: BtClient) -> None:
    uri = client.open('<root BTCPP_format="4"><TreeNodesModel/></root>')
    assert await _render(client, {"uri": uri, "position": {"line": 0, "character": 0}}) is None
    for bad in (
        {"position": {"line": 0, "character": 0}},
        {"uri": uri, "format": "png"},
        {"uri": uri, "edited": {"start": {"line": 0, "character": 0}}},
        {"uri": uri, "edited": [0, 1]},
    ):
        with pytest.raises(JsonRpcException):
            await _render(client, bad)
    with pytest.raises(JsonRpcException, match="not an open document"):
        await _render(client, {"uri": "file:///nowhere/x.xml"})
    with pytest.raises(JsonRpcException, match="no tree 'Nope'"):
        await _render(client, {"uri": uri, "tree": "Nope"})
    # The server keeps serving.
    assert await _render(client, {"uri": uri}) is None


def _pos(client: BtClient, offset: int, text: str = DOC) -> dict[str, int]:
    p = client.pos(text, offset)
    return {"line": p.line, "character": p.character}
