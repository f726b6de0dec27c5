"""Every request gets exactly one answer on trees nested up to and beyond the 256 levels
BehaviorTree.CPP allows; the outline keeps its nesting to ``MAX_SYMBOL_DEPTH`` levels and
lists deeper symbols after their ancestor at that depth, in document order."""

from __future__ import annotations

from typing import Any

import pytest
from lsprotocol import types

from bt_lsp.server.navigation import MAX_SYMBOL_DEPTH
from tests.server.conftest import BtClient, clients, raw_request

pytestmark = pytest.mark.asyncio(loop_scope="module")


def deep(depth: int) -> str:
    """A valid tree: ``depth`` nested Sequences (each named, so each is a symbol) around
    one action."""
    return (
        '<root BTCPP_format="4" main_tree_to_execute="Deep">\n'
        '<BehaviorTree ID="Deep">\n'
        + "".join(f'<Sequence name="s{i}">\n' for i in range(depth))
        + '<AlwaysSuccess name="leaf"/>\n'
        + "</Sequence>\n" * depth
        + "</BehaviorTree>\n</root>\n"
    )


def flatten(symbols: list[dict[str, Any]]) -> tuple[list[str], int]:
    """The symbols' names in document order and the deepest nesting, walked without
    recursion; checks that each child's range is inside its parent's."""
    names: list[str] = []
    deepest = 0
    stack = [(s, 1, None) for s in reversed(symbols)]
    while stack:
        s, depth, parent = stack.pop()
        names.append(s["name"])
        deepest = max(deepest, depth)
        if parent is not None:
            outer, inner = parent["range"], s["range"]
            key = lambda p: (p["line"], p["character"])  # noqa: E731
            assert key(outer["start"]) <= key(inner["start"])
            assert key(inner["end"]) <= key(outer["end"])
        stack.extend((c, depth + 1, s) for c in reversed(s.get("children") or []))
    return names, deepest


@clients("vscode", "nvim-0.11")
@pytest.mark.parametrize("depth", [195, 256, 257, 600])
async def test_every_request_answered_on_deep_trees(client: BtClient, depth: int) -> None:
    text = deep(depth)
    uri = client.open(text)
    await client.diags(uri, 1)
    symbols = await raw_request(
        client, types.TEXT_DOCUMENT_DOCUMENT_SYMBOL, {"textDocument": {"uri": uri}}
    )
    names, deepest = flatten(symbols)
    assert names == ["Deep", *(f"s{i}" for i in range(depth)), "leaf"]
    assert deepest == MAX_SYMBOL_DEPTH
    # The deepest node: every position request there is answered (a result, not an error).
    leaf = types.Position(depth + 2, 3)
    at = {
        "textDocument": {"uri": uri},
        "position": {"line": leaf.line, "character": leaf.character},
    }
    for method, extra in [
        (types.TEXT_DOCUMENT_HOVER, {}),
        (types.TEXT_DOCUMENT_DEFINITION, {}),
        (types.TEXT_DOCUMENT_REFERENCES, {"context": {"includeDeclaration": True}}),
        (types.TEXT_DOCUMENT_DOCUMENT_HIGHLIGHT, {}),
        (types.TEXT_DOCUMENT_COMPLETION, {}),
    ]:
        await raw_request(client, method, {**at, **extra})
    folds = await raw_request(
        client, types.TEXT_DOCUMENT_FOLDING_RANGE, {"textDocument": {"uri": uri}}
    )
    assert len(folds) >= depth
    whole = {"start": {"line": 0, "character": 0}, "end": {"line": 2 * depth + 5, "character": 0}}
    await raw_request(
        client,
        types.TEXT_DOCUMENT_CODE_ACTION,
        {"textDocument": {"uri": uri}, "range": whole, "context": {"diagnostics": []}},
    )
    client.close(uri)
