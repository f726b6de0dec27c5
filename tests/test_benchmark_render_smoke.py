"""benchmarks/render.py works: its tree has the nodes asked for, and it writes its report.
Correctness only, never timings."""

from __future__ import annotations

import importlib.util
import json
import sys
from pathlib import Path

from lxml import etree

from bt_lsp.render import build_picture, main_tree
from bt_lsp.syntax.document import Document

_PATH = Path(__file__).resolve().parent.parent / "benchmarks" / "render.py"
_SPEC = importlib.util.spec_from_file_location("bench_render", _PATH)
assert _SPEC is not None and _SPEC.loader is not None
bench_render = importlib.util.module_from_spec(_SPEC)
sys.modules["bench_render"] = bench_render
_SPEC.loader.exec_module(bench_render)


def test_big_tree_has_the_nodes_asked_for() -> None:
    text = bench_render.big_tree(300)
    etree.fromstring(text.encode())
    doc = Document(text)
    tree = main_tree(doc.model)
    assert tree is not None
    pic = build_picture(doc.model, tree)
    assert len(pic.nodes) == 301  # and the tree's own node
    assert {n.kind for n in pic.nodes} >= {"control", "decorator", "action", "condition"}


def test_report(tmp_path: Path) -> None:
    out = tmp_path / "render.json"
    assert bench_render.main(["--nodes", "40", "--repeat", "2", "--json", str(out)]) == 0
    report = json.loads(out.read_text())
    assert report["nodes"] == 40
    assert set(report["phases"]) >= {"layout", "SVG text", "picture + layout + SVG"}
    assert all(p["cpu_median_ms"] >= 0 for p in report["phases"].values())
