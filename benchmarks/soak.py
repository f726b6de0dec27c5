"""A working day in one session: many edits on one document, with the requests an editor
sends between them, and the server's memory at the start and at the end.

    python benchmarks/soak.py                    # 20,000 edits on a 200 KB document
    python benchmarks/soak.py --quick            # 400 edits on 60 KB: a smoke test
    python benchmarks/soak.py --edits 5000 --size 1M --json soak.json

Each edit types one letter at the end of a node's name or a port value and the next edit
deletes it again, so the text returns to the original every second edit, at places
spread over the trees; after every edit the client waits for the diagnostics of that
version (``debounceMs: 0``).  Every 5th edit it also asks for a hover, the code actions
of a line, a completion, the document symbols, a definition and the references of a node
type.  Printed: the edits, the wall time, the server's RSS after the open and at the end,
its peak (VmHWM), and the median and 95th percentile of the edit → diagnostics time and
of each request.  Not part of the test suite (``tests/test_benchmarks_smoke.py`` runs a
10-edit session to check that the pieces work, never how fast).
"""

from __future__ import annotations

import argparse
import asyncio
import json
import sys
import tempfile
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parent))

from generate import parse_size
from lsp_client import LspClient, path_uri, rss_kib
from run import SERVER, Doc, _position, make_doc, percentile

REQUESTS = ("hover", "codeAction", "completion", "documentSymbol", "definition", "references")


def _params(doc: Doc, kind: str, at: dict[str, int]) -> tuple[str, dict[str, Any]]:
    ident = {"uri": doc.uri}
    if kind == "codeAction":
        line = {"start": {"line": at["line"], "character": 0}, "end": at}
        return "textDocument/codeAction", {
            "textDocument": ident,
            "range": line,
            "context": {"diagnostics": []},
        }
    if kind == "documentSymbol":
        return "textDocument/documentSymbol", {"textDocument": ident}
    if kind == "references":
        return "textDocument/references", {
            "textDocument": ident,
            "position": at,
            "context": {"includeDeclaration": True},
        }
    return f"textDocument/{kind}", {"textDocument": ident, "position": at}


async def soak(size: int, edits: int, seed: int, every: int = 5) -> dict[str, Any]:
    with tempfile.TemporaryDirectory(prefix="bt-lsp-soak-") as tmp:
        folder = Path(tmp)
        doc = make_doc(size, folder, max(edits // 2, 1), seed)
        client = await LspClient.start(SERVER, cwd=tmp)
        try:
            await client.initialize(path_uri(folder), {"debounceMs": 0})
            fut = client.expect_diagnostics(doc.uri, 1)
            client.notify(
                "textDocument/didOpen",
                {
                    "textDocument": {
                        "uri": doc.uri,
                        "languageId": "xml",
                        "version": 1,
                        "text": doc.text,
                    }
                },
            )
            await asyncio.wait_for(fut, 300)
            hover_at = _position(doc.text, doc.hover_offset)
            # Warm up every request once, so that what is imported or compiled on first
            # use counts in the starting figure.
            for kind in REQUESTS:
                await client.request(*_params(doc, kind, hover_at))
            rss_start = rss_kib(client.pid)
            started = time.perf_counter()
            edit_times: list[float] = []
            request_times: dict[str, list[float]] = {k: [] for k in REQUESTS}
            places = doc.typing_offsets
            version = 1
            for n in range(edits):
                offset = places[(n // 2) % len(places)]
                at = _position(doc.text, offset)
                if n % 2 == 0:
                    change = {"range": {"start": at, "end": at}, "text": "x"}
                else:
                    after = {"line": at["line"], "character": at["character"] + 1}
                    change = {"range": {"start": at, "end": after}, "text": ""}
                version += 1
                fut = client.expect_diagnostics(doc.uri, version)
                t0 = client.notify(
                    "textDocument/didChange",
                    {
                        "textDocument": {"uri": doc.uri, "version": version},
                        "contentChanges": [change],
                    },
                )
                published = await asyncio.wait_for(fut, 120)
                edit_times.append(published.at - t0)
                if n % every == every - 1:
                    for kind in REQUESTS:
                        _, seconds = await client.request_timed(*_params(doc, kind, hover_at))
                        request_times[kind].append(seconds)
            wall = time.perf_counter() - started
            rss_end = rss_kib(client.pid)
            peak = rss_kib(client.pid, "VmHWM")
        finally:
            await client.close()
    return {
        "size": doc.size,
        "edits": edits,
        "requests": sum(len(v) for v in request_times.values()),
        "seconds": wall,
        "rss_start_kib": rss_start,
        "rss_end_kib": rss_end,
        "rss_peak_kib": peak,
        "edit_ms": _stats(edit_times),
        "request_ms": {k: _stats(v) for k, v in request_times.items()},
    }


def _stats(samples: Sequence[float]) -> dict[str, float]:
    return {
        "p50": percentile(samples, 0.5) * 1000,
        "p95": percentile(samples, 0.95) * 1000,
        "max": max(samples, default=float("nan")) * 1000,
    }


def report(r: dict[str, Any]) -> str:
    mib = 1024
    lines = [
        f"{r['edits']} edits and {r['requests']} requests on a {r['size'] / 1000:.0f} KB "
        f"document in {r['seconds']:.0f} s",
        f"server RSS: {r['rss_start_kib'] / mib:.1f} MiB after the open, "
        f"{r['rss_end_kib'] / mib:.1f} MiB at the end "
        f"({(r['rss_end_kib'] - r['rss_start_kib']) / mib:+.1f} MiB), "
        f"peak {r['rss_peak_kib'] / mib:.1f} MiB",
        "edit → diagnostics: p50 {p50:.1f} ms, p95 {p95:.1f} ms, max {max:.0f} ms".format(
            **r["edit_ms"]
        ),
    ]
    for kind, s in r["request_ms"].items():
        lines.append(f"{kind}: p50 {s['p50']:.1f} ms, p95 {s['p95']:.1f} ms")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--size", type=parse_size, default=parse_size("200K"))
    ap.add_argument("--edits", type=int, default=20_000)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--quick", action="store_true", help="400 edits on 60 KB")
    ap.add_argument("--json", metavar="FILE", help="also write the figures as JSON")
    args = ap.parse_args(argv)
    if args.quick:
        args.size, args.edits = parse_size("60K"), 400
    result = asyncio.run(soak(args.size, args.edits, args.seed))
    print(report(result))
    if args.json:
        Path(args.json).write_text(json.dumps(result, indent=2) + "\n", encoding="utf-8")
    return 0


if __name__ == "__main__":
    sys.exit(main())
