"""Time the tree renderer: picture, layout and SVG of one large tree.

The tree is generated (deterministic for a seed): nested controls and decorators with
custom actions and conditions, ports with literals and ``{keys}``, and ``--nodes`` nodes
in all.  Each phase is timed ``--repeat`` times in this process (the document model is
built once, as the server has it); the median and the 95th percentile of the wall time are
printed, and the median CPU time of the process (``time.process_time``), which a busy
machine (the load average is printed too) inflates much less than the wall time.

    python benchmarks/render.py [--nodes 1000] [--repeat 30] [--json out.json]
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import random
import statistics
import sys
import time
from collections.abc import Callable
from typing import Any

from bt_lsp.render import build_picture, layout, main_tree, to_mermaid, to_svg
from bt_lsp.rules.analysis import analyze
from bt_lsp.rules.context import Context
from bt_lsp.syntax.document import Document

_CONTROLS = ("Sequence", "Fallback", "ReactiveSequence", "Parallel", "SequenceWithMemory")
_DECORATORS = ("Inverter", "ForceSuccess", "RetryUntilSuccessful", "Timeout")


def big_tree(nodes: int, seed: int = 1) -> str:
    """One ``<BehaviorTree>`` of exactly ``nodes`` nodes (the tree's own node excluded):
    decorators over one child, controls over 2–6, leaves of custom actions and conditions."""
    rng = random.Random(seed)
    out: list[str] = []
    left = nodes

    def leaf(i: int) -> str:
        if rng.random() < 0.3:
            return f'<Condition ID="IsReady{i % 17}" target="{{goal_{i % 9}}}"/>'
        return f'<Action ID="DoThing{i % 23}" name="step {i}" speed="{i % 5}.5" out="{{k{i}}}"/>'

    # Breadth-first plan of child counts, written out with an explicit stack.
    counts: list[int] = []
    queue = 1
    made = 1
    while made < nodes:
        k = min(rng.randint(1, 6), nodes - made)
        counts.append(k)
        made += k
        queue += k
    kids: list[list[int]] = [[]]
    nxt = 1
    for parent, k in enumerate(counts):
        for _ in range(k):
            kids[parent].append(nxt)
            kids.append([])
            nxt += 1
    stack: list[tuple[int, str | None]] = [(0, None)]
    while stack:
        i, closing = stack.pop()
        if closing is not None:
            out.append(closing)
            continue
        left -= 1
        if not kids[i]:
            out.append(leaf(i))
            continue
        if len(kids[i]) == 1:
            tag = _DECORATORS[i % len(_DECORATORS)]
            attrs = ' num_attempts="3"' if tag == "RetryUntilSuccessful" else ""
            attrs = ' msec="100"' if tag == "Timeout" else attrs
        else:
            tag = _CONTROLS[i % len(_CONTROLS)]
            attrs = ' success_count="1"' if tag == "Parallel" else ""
        out.append(f'<{tag} name="{tag.lower()} {i}"{attrs}>')
        stack.append((i, f"</{tag}>"))
        stack.extend((k, None) for k in reversed(kids[i]))
    body = "".join(out)
    return f'<root BTCPP_format="4"><BehaviorTree ID="Big">{body}</BehaviorTree></root>\n'


def timed(fn: Callable[[], object], repeat: int) -> tuple[list[float], list[float]]:
    """Wall and CPU seconds of ``repeat`` calls (after one to warm up)."""
    fn()
    wall: list[float] = []
    cpu: list[float] = []
    for _ in range(repeat):
        c0, t0 = time.process_time(), time.perf_counter()
        fn()
        wall.append(time.perf_counter() - t0)
        cpu.append(time.process_time() - c0)
    return wall, cpu


def _cpu() -> str:
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def p95(samples: list[float]) -> float:
    s = sorted(samples)
    return s[min(len(s) - 1, round(0.95 * (len(s) - 1)))]


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--nodes", type=int, default=1000)
    ap.add_argument("--repeat", type=int, default=30)
    ap.add_argument("--json", metavar="FILE")
    args = ap.parse_args(argv)

    doc = Document(big_tree(args.nodes))
    ctx = Context.from_document(doc)
    diags = analyze(doc, ctx)
    tree = main_tree(doc.model)
    assert tree is not None

    def picture() -> Any:
        return build_picture(doc.model, tree, ctx=ctx, diagnostics=diags)

    pic = picture()
    laid = layout(pic)
    phases: dict[str, Callable[[], object]] = {
        "picture (nodes, kinds, problems)": picture,
        "layout": lambda: layout(pic),
        "SVG text": lambda: to_svg(pic, laid),
        "picture + layout + SVG": lambda: to_svg(picture()),
        "picture + Mermaid": lambda: to_mermaid(picture()),
    }
    results: dict[str, dict[str, float]] = {}
    print(f"tree of {len(pic.nodes) - 1} nodes, {len(diags)} diagnostics; {args.repeat} runs")
    print(f"{'phase':36} {'median ms':>10} {'p95 ms':>8} {'CPU ms':>8}")
    for name, fn in phases.items():
        wall, cpu = timed(fn, args.repeat)
        r = results[name] = {
            "median_ms": statistics.median(wall) * 1000,
            "p95_ms": p95(wall) * 1000,
            "cpu_median_ms": statistics.median(cpu) * 1000,
        }
        print(f"{name:36} {r['median_ms']:10.1f} {r['p95_ms']:8.1f} {r['cpu_median_ms']:8.1f}")
    machine = f"{_cpu()}, {os.cpu_count()} cores, Python {platform.python_version()}"
    load = ", ".join(f"{x:.1f}" for x in os.getloadavg())
    print(f"machine: {machine}; load average {load}")
    if args.json:
        with open(args.json, "w") as f:
            json.dump(
                {"nodes": len(pic.nodes) - 1, "machine": machine, "load": load, "phases": results},
                f,
            )
    return 0


if __name__ == "__main__":
    sys.exit(main())
