"""The C++ catalog benchmark's parts work (correctness only, never timings)."""

from __future__ import annotations

import sys
from pathlib import Path

BENCH = Path(__file__).resolve().parent.parent / "benchmarks"
sys.path.insert(0, str(BENCH))

import cpp_catalog  # noqa: E402
from bt_lsp.project.cpp_scan import Scanner, find_cpp_files, scan  # noqa: E402


def test_synthetic_workspace_registers_every_node_with_its_ports(tmp_path: Path) -> None:
    tree = cpp_catalog.make_tree(tmp_path / "ws", mb=0.3, nodes=8)
    assert tree.bytes >= 0.3 * 1024 * 1024 and tree.files > 16
    assert tree.changed.stat().st_size >= 50_000
    catalog = scan(find_cpp_files([tree.root]), Scanner(None))
    assert sorted(n.id for n in catalog.nodes) == [f"Node{i:03d}" for i in range(8)]
    assert all(n.authoritative and n.ports for n in catalog.nodes)
    action = catalog.by_id["Node000"]  # a BtActionNode: the base's basic ports come first
    assert [p.name for p in action.ports][:2] == ["server_name", "server_timeout"]
    assert catalog.by_id["Node002"].kind == "Condition"
    assert catalog.by_id["Node003"].kind == "Decorator"


def test_measure_runs_the_three_phases(tmp_path: Path) -> None:
    tree = cpp_catalog.make_tree(tmp_path / "ws", mb=0.2, nodes=4)
    figures = cpp_catalog.measure(tree, tmp_path / "cache")
    assert set(figures) == {"cold", "warm", "one changed, in a body", "one changed, a line added"}
    assert all(v > 0 for v in figures.values())
