"""How two costs grow with the document: the outline and the publication of many
diagnostics, through the real server.

    python benchmarks/scale.py                           # outline at 125K..7M, publication
    python benchmarks/scale.py --sizes 125K,1M --repeat 5 --json scale.json

- ``documentSymbol``: for each size a generated document is opened; then, ``--repeat``
  times, one letter is typed in a node's ``name`` (the diagnostics of that version waited
  for) and the outline is asked for: the time of that request (a new version each time,
  so no answer can be reused whole), and the outline of the same version asked again.
- publication: a 200 KB (``--publication-size``) generated document whose trees use
  port names no model declares (``goal`` typed ``goalx``), which the server reports up
  to its cap of 2,000 diagnostics per document; one letter is typed and deleted again
  at places spread over the trees, and each ``didChange`` is timed to the diagnostics
  of its version.

Every figure is the median and the 95th percentile of its samples.  Not part of the test
suite (``tests/test_benchmarks_smoke.py`` runs a tiny one to check the pieces work).
"""

from __future__ import annotations

import argparse
import asyncio
import json
import re
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parent))

from generate import _PORT_WORDS, generate, parse_size
from lsp_client import LspClient, path_uri
from run import SERVER, _position, _spread, percentile

SIZES = "125K,250K,500K,1M,7M"


def bad_ports(text: str) -> str:
    """``text`` with every port of the common names, in the trees, renamed so that no
    model declares it (and the declared one goes missing where it is required)."""
    models = text.index("<TreeNodesModel>")
    words = "|".join(_PORT_WORDS)
    body = re.sub(f' ({words})="', lambda m: f' {m.group(1)}x="', text[:models])
    return body + text[models:]


def typing_places(text: str, k: int) -> list[int]:
    """The ends of ``k`` node names spread over the trees."""
    models = text.find("<TreeNodesModel>")
    ends = [m.end(1) for m in re.finditer(r' name="([^"]*)', text) if m.start() < models]
    return _spread(ends, k)


async def _open(client: LspClient, folder: Path, name: str, text: str) -> str:
    path = folder / name
    path.write_text(text, encoding="utf-8", newline="\n")
    uri = path_uri(path)
    fut = client.expect_diagnostics(uri, 1)
    client.notify(
        "textDocument/didOpen",
        {"textDocument": {"uri": uri, "languageId": "xml", "version": 1, "text": text}},
    )
    await asyncio.wait_for(fut, 600)
    return uri


def _change(uri: str, version: int, text: str, offset: int, typed: bool) -> dict[str, Any]:
    at = _position(text, offset)
    if typed:
        change = {"range": {"start": at, "end": at}, "text": "x"}
    else:
        after = {"line": at["line"], "character": at["character"] + 1}
        change = {"range": {"start": at, "end": after}, "text": ""}
    return {"textDocument": {"uri": uri, "version": version}, "contentChanges": [change]}


async def outline(size: int, repeat: int, seed: int) -> dict[str, Any]:
    text = generate(size, seed).text
    with tempfile.TemporaryDirectory(prefix="bt-lsp-scale-") as tmp:
        client = await LspClient.start(SERVER, cwd=tmp)
        try:
            await client.initialize(path_uri(tmp), {"debounceMs": 0})
            uri = await _open(client, Path(tmp), "outline.xml", text)
            ident = {"textDocument": {"uri": uri}}
            symbols, first = await client.request_timed("textDocument/documentSymbol", ident, 600)
            after_edit: list[float] = []
            again: list[float] = []
            version = 1
            places = typing_places(text, repeat)
            for n in range(2 * repeat):
                version += 1
                fut = client.expect_diagnostics(uri, version)
                client.notify(
                    "textDocument/didChange",
                    _change(uri, version, text, places[(n // 2) % len(places)], n % 2 == 0),
                )
                await asyncio.wait_for(fut, 600)
                _, seconds = await client.request_timed("textDocument/documentSymbol", ident, 600)
                after_edit.append(seconds)
                _, seconds = await client.request_timed("textDocument/documentSymbol", ident, 600)
                again.append(seconds)
        finally:
            await client.close()
    return {
        "size": len(text.encode()),
        "symbols": _count(symbols),
        "first_ms": first * 1000,
        "after_edit_ms": _stats(after_edit),
        "same_version_ms": _stats(again),
    }


def _count(symbols: list[dict[str, Any]]) -> int:
    n, stack = 0, list(symbols)
    while stack:
        s = stack.pop()
        n += 1
        stack.extend(s.get("children") or ())
    return n


async def publication(size: int, edits: int, seed: int) -> dict[str, Any]:
    text = bad_ports(generate(size, seed).text)
    with tempfile.TemporaryDirectory(prefix="bt-lsp-scale-") as tmp:
        client = await LspClient.start(SERVER, cwd=tmp)
        try:
            await client.initialize(path_uri(tmp), {"debounceMs": 0})
            uri = await _open(client, Path(tmp), "publication.xml", text)
            published = client.latest(uri)
            count = len(published.diagnostics) if published is not None else 0
            places = typing_places(text, max(edits // 2, 1))
            times: list[float] = []
            started = time.perf_counter()
            for n in range(edits):
                fut = client.expect_diagnostics(uri, n + 2)
                t0 = client.notify(
                    "textDocument/didChange",
                    _change(uri, n + 2, text, places[(n // 2) % len(places)], n % 2 == 0),
                )
                got = await asyncio.wait_for(fut, 600)
                times.append(got.at - t0)
            wall = time.perf_counter() - started
        finally:
            await client.close()
    return {
        "size": len(text.encode()),
        "diagnostics": count,
        "edits": edits,
        "seconds": wall,
        "edit_ms": _stats(times),
    }


def _stats(samples: list[float]) -> dict[str, float]:
    return {"p50": percentile(samples, 0.5) * 1000, "p95": percentile(samples, 0.95) * 1000}


def report(r: dict[str, Any]) -> str:
    lines = [
        "documentSymbol (ms):",
        "| size | symbols | first | after an edit p50 / p95 | same version p50 |",
        "|---|---|---|---|---|",
    ]
    for o in r["outline"]:
        a, s = o["after_edit_ms"], o["same_version_ms"]
        lines.append(
            f"| {o['size'] / 1e6:.3f} MB | {o['symbols']} | {o['first_ms']:.0f} | "
            f"{a['p50']:.1f} / {a['p95']:.1f} | {s['p50']:.1f} |"
        )
    p = r["publication"]
    if p is not None:
        e = p["edit_ms"]
        lines.append(
            f"publication: {p['diagnostics']} diagnostics on {p['size'] / 1000:.0f} KB, "
            f"{p['edits']} edits: edit → diagnostics p50 {e['p50']:.1f} ms, "
            f"p95 {e['p95']:.1f} ms"
        )
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--sizes", default=SIZES, help=f"outline sizes (default {SIZES})")
    ap.add_argument("--repeat", type=int, default=10, help="edits per outline size")
    ap.add_argument("--edits", type=int, default=200, help="edits of the publication")
    ap.add_argument(
        "--publication-size", type=parse_size, default=parse_size("200K"), metavar="SIZE"
    )
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--json", metavar="FILE", help="also write the figures as JSON")
    args = ap.parse_args(argv)

    async def both() -> dict[str, Any]:
        sizes = [parse_size(s) for s in args.sizes.split(",") if s]
        found = [await outline(s, args.repeat, args.seed) for s in sizes]
        published = None
        if args.edits:
            published = await publication(args.publication_size, args.edits, args.seed)
        return {"outline": found, "publication": published}

    result = asyncio.run(both())
    print(report(result))
    if args.json:
        Path(args.json).write_text(json.dumps(result, indent=2) + "\n", encoding="utf-8")
    return 0


if __name__ == "__main__":
    sys.exit(main())
