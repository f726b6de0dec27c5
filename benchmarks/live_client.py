"""The Groot2 client alone (``bt_lsp.live.client``): the STATUS round trip to a real
BehaviorTree.CPP executor on loopback, and the CPU that polling a ``--nodes`` tree at 10 Hz
costs the client and the executor (Linux: /proc).

    python benchmarks/live_client.py             # 500 nodes
    python benchmarks/live_client.py --nodes 7
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(HERE.parent / "src"))

from bt_lsp.live.client import Groot2Client  # noqa: E402
from live_latency import _cpu_seconds, _free_port, _tree  # noqa: E402


def measure(nodes: int, polls: int = 500) -> dict[str, float]:
    with tempfile.TemporaryDirectory() as tmp:
        tree = Path(tmp) / "tree.xml"
        tree.write_text(_tree(nodes, 40), encoding="utf-8")
        port = _free_port()
        ex = subprocess.Popen(
            [sys.executable, str(HERE / "live_latency.py"), "--executor", str(port), str(tree),
             str(Path(tmp) / "run.btlog"), "60"],
            stdout=subprocess.PIPE,
            text=True,
        )  # fmt: skip
        try:
            assert ex.stdout is not None and ex.stdout.readline().strip() == "ready"
            with Groot2Client("127.0.0.1", port) as c:
                fulltree = time.perf_counter()
                assert len(c.read_tree().nodes) == nodes + 1
                fulltree = time.perf_counter() - fulltree
                times = []
                for _ in range(polls):
                    t0 = time.perf_counter()
                    c.status()
                    times.append(time.perf_counter() - t0)
                times.sort()
                ex0, wall0 = _cpu_seconds(ex.pid), time.monotonic()
                time.sleep(5)
                unpolled = (_cpu_seconds(ex.pid) - ex0) / (time.monotonic() - wall0)
                cpu0, ex0, wall0 = time.process_time(), _cpu_seconds(ex.pid), time.monotonic()
                for _ in range(50):
                    c.status()
                    time.sleep(0.1)
                wall = time.monotonic() - wall0
                client = (time.process_time() - cpu0) / wall
                polled = (_cpu_seconds(ex.pid) - ex0) / wall
        finally:
            ex.kill()
            ex.wait(10)
    return {
        "nodes": nodes,
        "fulltree_ms": round(1000 * fulltree, 2),
        "status_median_ms": round(1000 * times[len(times) // 2], 3),
        "status_p99_ms": round(1000 * times[int(0.99 * len(times))], 3),
        "client_cpu_percent_10hz": round(100 * client, 2),
        "executor_cpu_percent_polled": round(100 * polled, 2),
        "executor_cpu_percent_unpolled": round(100 * unpolled, 2),
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--nodes", type=int, default=500)
    print(json.dumps(measure(ap.parse_args().nodes), indent=1))


if __name__ == "__main__":
    main()
