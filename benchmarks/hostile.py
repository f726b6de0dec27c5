"""Hostile sizes in the server: memory and waiting per input, up to ``maxDocumentBytes``.

For each input a fresh ``bt-lsp serve`` opens a small document, then the input; right
after the input's ``didOpen`` it asks for a hover on the small document. Printed per
input: its size; the time from the open to its first diagnostics (from 256 KiB on, the
name diagnostics published first) and to its complete diagnostics (those holding
``unknown-node``, which only the complete analysis reports; above ``maxDocumentBytes``,
those holding ``document-too-large``, as only the XML and name checks run); the hover's
round trip while the input is analysed; a hover on the input's first ``<Frob>`` once it
is; and the server's peak RSS (VmHWM) above its RSS before the open, as a multiple of the
input's size.

    python benchmarks/hostile.py                 # every input
    python benchmarks/hostile.py duplicates      # some of them
"""

from __future__ import annotations

import argparse
import asyncio
import sys
import time
from collections.abc import Callable
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from generate import generate
from lsp_client import LspClient, rss_kib
from run import SERVER

MIB = 1024 * 1024
TREE = '<root BTCPP_format="4">\n<BehaviorTree ID="T">\n'
END = "</BehaviorTree>\n</root>\n"
SMALL = TREE + "<AlwaysSuccess/>\n" + END


def _realistic(size: int = 8 * MIB - 4096) -> str:
    text = generate(size, seed=1).text
    return text.replace("</BehaviorTree>", "<Frob/></BehaviorTree>", 1)


def _sequence(body: str) -> str:
    return TREE + "<Sequence>" + body + "</Sequence>" + END


INPUTS: dict[str, Callable[[], str]] = {
    "duplicates": lambda: TREE + "<Frob" + ' a="1"' * 1_000_000 + "/>" + END,
    "attributes": lambda: (
        TREE + "<Frob" + "".join(f' a{i}="1"' for i in range(700_000)) + "/>" + END
    ),
    "realistic": _realistic,
    "elements": lambda: _sequence("<Frob/>" * 100_000),
    "attributed": lambda: _sequence(
        "".join(f'<Frob a="1" b="x" c="{k}"/>' for k in range(100_000))
    ),
    "attributed-8mib": lambda: _sequence(
        "".join(f'<Frob a="1" b="x" c="{k}"/>' for k in range(280_000))
    ),
    "pairs": lambda: _sequence("<Sequence><Frob/></Sequence>" * 50_000),
    "texts": lambda: _sequence("<Frob/>text<!-- note -->" * 100_000),
    "lines": lambda: _sequence("\n" + "  <Frob/>\n" * 100_000),
    "tiny-2mib": lambda: _sequence("<Frob/>" * 300_000),
    "tiny-8mib": lambda: _sequence("<Frob/>" * 1_190_000),
    # Shapes a per-statement, per-tree or recursive walk would make slow or break.
    "script": lambda: (
        TREE + '<Script code="' + "".join(f"a{i}:=1; " for i in range(200_000)) + '"/><Frob/>' + END
    ),
    "skip_if": lambda: (
        TREE
        + "<Sequence><Frob/>"
        + "".join(f'<AlwaysSuccess _skipIf="k{i}==1"/>' for i in range(100_000))
        + "</Sequence>"
        + END
    ),
    "keys": lambda: (
        TREE
        + "<Sequence><Frob/>"
        + "".join(f'<SetBlackboard value="1" output_key="{{k{i}}}"/>' for i in range(100_000))
        + "</Sequence>"
        + END
    ),
    "subtree_chain": lambda: (
        '<root BTCPP_format="4" main_tree_to_execute="T0">'
        + "".join(
            f'<BehaviorTree ID="T{i}"><Sequence><SubTree ID="T{i + 1}"/><AlwaysSuccess/>'
            "</Sequence></BehaviorTree>\n"
            for i in range(20_000)
        )
        + '<BehaviorTree ID="T20000"><Frob/><SubTree ID="T0"/></BehaviorTree></root>\n'
    ),
    "deep": lambda: TREE + "<Sequence>" * 10_000 + "<Frob/>" + "</Sequence>" * 10_000 + END,
    "single_line": lambda: _realistic().replace("\n", " "),
    # Above the default maxDocumentBytes (8 MiB): the too-large path, capped like the others.
    "over_limit": lambda: _realistic(10 * MIB).replace("\n", " "),
}

#: The code that marks a complete publication: only the full analysis reports
#: ``unknown-node``; above ``maxDocumentBytes`` the publication says the document is too large.
LIMIT = 8 * MIB


async def measure(name: str, text: str) -> dict[str, float]:
    client = await LspClient.start(SERVER)
    try:
        await client.initialize(None, {"debounceMs": 0})
        small = "untitled:small.xml"
        item = {"uri": small, "languageId": "xml", "version": 1, "text": SMALL}
        fut = client.expect_diagnostics(small, 1)
        client.notify("textDocument/didOpen", {"textDocument": item})
        await asyncio.wait_for(fut, 60)
        hover = {"textDocument": {"uri": small}, "position": {"line": 2, "character": 3}}
        await client.request("textDocument/hover", hover)
        before = rss_kib(client.pid)
        uri = f"untitled:{name}.xml"
        item = {"uri": uri, "languageId": "xml", "version": 1, "text": text}
        done = "document-too-large" if len(text.encode("utf-8")) > LIMIT else "unknown-node"
        first = client.expect_diagnostics(uri, 1)
        opened = time.perf_counter()
        client.notify("textDocument/didOpen", {"textDocument": item})
        _, hover_seconds = await client.request_timed("textDocument/hover", hover, 600)
        while True:  # the complete set, not the early names published first
            fut = client.expect_diagnostics(uri, 1)
            latest = client.latest(uri)
            if latest is not None and any(d.get("code") == done for d in latest.diagnostics):
                published = latest
                break
            await asyncio.wait_for(fut, 600)
        size = len(text.encode("utf-8"))
        first_at = (await asyncio.wait_for(first, 1)).at
        peak = rss_kib(client.pid, "VmHWM")
        # Then a hover on the input itself, on its first <Frob> (the first after the
        # analysis: what it gathers is made once per version).
        at = text.index("<Frob") + 2
        line = text.count("\n", 0, at)
        here = {
            "textDocument": {"uri": uri},
            "position": {"line": line, "character": at - (text.rfind("\n", 0, at) + 1)},
        }
        _, own_hover_seconds = await client.request_timed("textDocument/hover", here, 600)
        return {
            "size": size,
            "first_s": first_at - opened,
            "diagnostics_s": published.at - opened,
            "hover_s": hover_seconds,
            "own_hover_s": own_hover_seconds,
            "rss_peak_mib": peak / 1024,
            "ratio": (peak - before) * 1024 / size,
        }
    finally:
        await client.close()


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("inputs", nargs="*", help=f"some of: {', '.join(INPUTS)}")
    args = parser.parse_args(argv)
    unknown = set(args.inputs) - set(INPUTS)
    if unknown:
        parser.error(f"unknown inputs: {', '.join(sorted(unknown))}")
    print(
        "| input | size | open → first diagnostics | open → complete diagnostics "
        "| hover meanwhile | hover on it then | peak RSS | peak / size |"
    )
    print("|---|---|---|---|---|---|---|---|")
    for name in args.inputs or list(INPUTS):
        r = asyncio.run(measure(name, INPUTS[name]()))
        print(
            f"| {name} | {r['size'] / MIB:.1f} MiB | {r['first_s']:.1f} s "
            f"| {r['diagnostics_s']:.1f} s "
            f"| {r['hover_s']:.2f} s | {r['own_hover_s']:.2f} s "
            f"| {r['rss_peak_mib']:.0f} MiB | {r['ratio']:.1f}× |",
            flush=True,
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
