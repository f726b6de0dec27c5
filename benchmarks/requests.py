"""Requests on a large document while the server is busy with it, and what they keep.

Three measurements, each in a fresh ``bt-lsp serve``:

- ``outline``: the generated 8 MiB document (``hostile.py``'s ``realistic``) is opened and
  ``documentSymbol`` asked right after the ``didOpen``, while the worker thread prepares
  and analyses it: the time to the answer, its size, and the server's RSS (above its RSS
  before the open, as a multiple of the document) once the complete diagnostics are in
  and after a second outline;
- ``hover-key``: a hover, a definition and the references on a blackboard key of the
  script of 200,000 statements (``hostile.py``'s ``script``), each the first on its
  version (after an edit) and again;
- ``first-open``: the outline, folding ranges and a hover asked with the open of the same
  8 MiB document, each timed from the open.

    python benchmarks/requests.py                 # all three
    python benchmarks/requests.py outline
"""

from __future__ import annotations

import argparse
import asyncio
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from hostile import INPUTS
from lsp_client import LspClient, rss_kib
from run import SERVER

MIB = 1024 * 1024


async def outline() -> None:
    text = INPUTS["realistic"]()
    size = len(text.encode("utf-8"))
    client = await LspClient.start(SERVER)
    try:
        await client.initialize(None, {"debounceMs": 0})
        before = rss_kib(client.pid)
        uri = "untitled:big.xml"
        item = {"uri": uri, "languageId": "xml", "version": 1, "text": text}
        opened = time.perf_counter()
        client.notify("textDocument/didOpen", {"textDocument": item})
        params = {"textDocument": {"uri": uri}}
        symbols, _ = await client.request_timed("textDocument/documentSymbol", params, 600)
        first = time.perf_counter() - opened
        await client.complete(uri)
        done = time.perf_counter() - opened
        after_diags = rss_kib(client.pid)
        _, again = await client.request_timed("textDocument/documentSymbol", params, 600)
        after = rss_kib(client.pid)
        peak = rss_kib(client.pid, "VmHWM")
        print(f"document {size / MIB:.1f} MiB, {len(symbols)} top-level symbols")
        print(f"open → outline answered: {first:.2f} s; → complete diagnostics {done:.2f} s")
        print(f"second outline: {again * 1000:.0f} ms")
        for label, kib in (
            ("after the diagnostics", after_diags),
            ("after the second outline", after),
            ("peak", peak),
        ):
            print(
                f"RSS {label}: {kib / 1024:.0f} MiB, "
                f"{(kib - before) * 1024 / size:.1f}× the document above the idle server"
            )
    finally:
        await client.close()


async def hover_key() -> None:
    text = INPUTS["script"]()
    client = await LspClient.start(SERVER)
    try:
        await client.initialize(None, {"debounceMs": 0})
        uri = "untitled:script.xml"
        client.open(uri, text)
        await client.complete(uri)
        line = text.split("\n")[2]
        col = line.index("a1000:=")
        at = {"textDocument": {"uri": uri}, "position": {"line": 2, "character": col + 1}}
        refs = dict(at, context={"includeDeclaration": True})
        for version in (2, 3):
            # An edit in the same script (a statement appended at its end) first.
            end = line.index('"/>')
            change = {
                "range": {
                    "start": {"line": 2, "character": end},
                    "end": {"line": 2, "character": end},
                },
                "text": f"b{version}:=1; ",
            }
            client.notify(
                "textDocument/didChange",
                {"textDocument": {"uri": uri, "version": version}, "contentChanges": [change]},
            )
            line = line[:end] + change["text"] + line[end:]
            for method, params in (
                ("textDocument/hover", at),
                ("textDocument/hover", at),
                ("textDocument/definition", at),
                ("textDocument/references", refs),
            ):
                result, seconds = await client.request_timed(method, params, 600)
                n = len(result) if isinstance(result, list) else int(result is not None)
                print(f"v{version} {method}: {seconds * 1000:.0f} ms ({n} results)")
    finally:
        await client.close()


async def first_open() -> None:
    text = INPUTS["realistic"]()
    client = await LspClient.start(SERVER)
    try:
        await client.initialize(None, {"debounceMs": 0})
        uri = "untitled:big.xml"
        item = {"uri": uri, "languageId": "xml", "version": 1, "text": text}
        opened = time.perf_counter()
        client.notify("textDocument/didOpen", {"textDocument": item})
        doc = {"textDocument": {"uri": uri}}
        hover = dict(doc, position={"line": 3, "character": 5})
        asks = {
            "outline": ("textDocument/documentSymbol", doc),
            "folding": ("textDocument/foldingRange", doc),
            "hover": ("textDocument/hover", hover),
        }
        tasks = {
            name: asyncio.ensure_future(client.request_timed(method, params, 600))
            for name, (method, params) in asks.items()
        }
        for name, task in tasks.items():
            await task
            print(f"open → {name}: {client.last_answer_at - opened:.2f} s")
    finally:
        await client.close()


RUNS = {"outline": outline, "hover-key": hover_key, "first-open": first_open}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("runs", nargs="*", help=f"some of: {', '.join(RUNS)}")
    args = parser.parse_args(argv)
    for name in args.runs or list(RUNS):
        print(f"## {name}", flush=True)
        asyncio.run(RUNS[name]())
    return 0


if __name__ == "__main__":
    sys.exit(main())
