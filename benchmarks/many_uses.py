"""Requests about a name used 1,190,000 times on one 8 MB line, in the server.

A fresh ``bt-lsp serve`` opens a small document and ``tiny-8mib`` of
``benchmarks/hostile.py`` (``<Frob/>`` repeated to ``maxDocumentBytes``), waits for its
complete diagnostics, then sends each request on its first ``<Frob>`` with a hover on the
small document right after it. Printed per request: its round trip, the size of its
answer and the hover's round trip (what the request held the server for).

    python benchmarks/many_uses.py                          # every request
    python benchmarks/many_uses.py textDocument/references  # some of them
"""

from __future__ import annotations

import asyncio
import sys
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parent))

from hostile import INPUTS, SMALL
from lsp_client import LspClient
from run import SERVER


def _requests(uri: str, pos: dict[str, Any]) -> dict[str, Any]:
    at = {"textDocument": {"uri": uri}, "position": pos}
    return {
        "textDocument/documentHighlight": at,
        "textDocument/references": {**at, "context": {"includeDeclaration": True}},
        "textDocument/rename": {**at, "newName": "Knob"},
        "textDocument/definition": at,
        "textDocument/hover": at,
        "textDocument/codeAction": {
            "textDocument": {"uri": uri},
            "range": {"start": pos, "end": pos},
            "context": {"diagnostics": []},
        },
    }


def _size(result: Any) -> int:
    if isinstance(result, list):
        return len(result)
    if isinstance(result, dict) and "documentChanges" in result:
        return sum(len(c["edits"]) for c in result["documentChanges"])
    if isinstance(result, dict) and "changes" in result:
        return sum(map(len, result["changes"].values()))
    return int(result is not None)


async def measure(methods: list[str]) -> None:
    text = INPUTS["tiny-8mib"]()
    client = await LspClient.start(SERVER)
    try:
        await client.initialize(None, {"debounceMs": 0})
        small, uri = "untitled:small.xml", "untitled:many.xml"
        client.open(small, SMALL)
        client.open(uri, text)
        await client.complete(uri)
        at = text.index("<Frob") + 2
        pos = {"line": text.count("\n", 0, at), "character": at - (text.rfind("\n", 0, at) + 1)}
        requests = _requests(uri, pos)
        hover = {"textDocument": {"uri": small}, "position": {"line": 2, "character": 3}}
        print("| request | round trip | places | hover on another document meanwhile |")
        print("|---|---|---|---|")
        for method in methods or list(requests):
            sent = asyncio.ensure_future(client.request_timed(method, requests[method], 900))
            await asyncio.sleep(0.01)
            _, hover_seconds = await client.request_timed("textDocument/hover", hover, 900)
            result, seconds = await sent
            print(
                f"| {method} | {seconds:.1f} s | {_size(result):,} | {hover_seconds:.1f} s |",
                flush=True,
            )
    finally:
        await client.close()


if __name__ == "__main__":
    asyncio.run(measure(sys.argv[1:]))
