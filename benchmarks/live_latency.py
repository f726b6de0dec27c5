"""The editor's live view: how long a node's status takes from the executor to the editor,
and what watching costs.

A real BehaviorTree.CPP executor (behaviortreepy, with a Groot2Publisher and a FileLogger2
writing each transition with its time) ticks a Sequence of ``--nodes`` Sleep nodes, so
that a node changes status about every ``--sleep-ms``.  ``bt-lsp serve`` is started as an
editor starts it, the tree's file opened, and ``bt-lsp.liveConnect`` asked at ``--rate``
Hz.  For ``--seconds``, each ``bt-lsp/liveStatus`` notification is kept with the time it
was read; afterwards, each status it reports that the previous one did not is matched with
the executor's transition of that node to that status (from the log), and the latency is
the difference (the same machine's clock).  The editor's own drawing (a decoration, a class
on an SVG node) comes on top.  The CPU time the server and the executor used meanwhile is
read from /proc (Linux).

    python benchmarks/live_latency.py                      # 500 nodes, 10 Hz, 20 s
    python benchmarks/live_latency.py --nodes 7 --rate 30 --json out.json
"""

from __future__ import annotations

import argparse
import asyncio
import json
import os
import socket
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(HERE.parent / "src"))

from bt_lsp.live.btlog import BtLog  # noqa: E402
from lsp_client import LspClient, path_uri  # noqa: E402


def _tree(nodes: int, sleep_ms: int) -> str:
    leaves = "\n".join(f'      <Sleep name="s{i}" msec="{sleep_ms}"/>' for i in range(nodes))
    return (
        '<root BTCPP_format="4" main_tree_to_execute="Main">\n'
        '  <BehaviorTree ID="Main">\n    <Sequence name="all">\n'
        f"{leaves}\n    </Sequence>\n  </BehaviorTree>\n</root>\n"
    )


def _executor(port: int, tree: str, log: str, seconds: float) -> None:
    """Runs in the child process: tick the tree every 2 ms with a publisher and a logger."""
    import behaviortreepy as bt

    with open(tree, encoding="utf-8") as f:
        text = f.read()
    factory = bt.BehaviorTreeFactory()
    factory.register_behavior_tree_from_text(text)
    tree_ = factory.create_tree("Main")
    publisher = bt.Groot2Publisher(tree_, port)
    logger = bt.FileLogger(tree_, log)
    print("ready", flush=True)
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        if tree_.tick_once() != bt.NodeStatus.RUNNING:
            tree_.halt_tree()
        time.sleep(0.002)
    del logger, publisher


def _free_port() -> int:
    for _ in range(50):
        with socket.socket() as a:
            a.bind(("127.0.0.1", 0))
            port = int(a.getsockname()[1])
            with socket.socket() as b:
                try:
                    b.bind(("127.0.0.1", port + 1))
                except OSError:
                    continue
            return port
    raise RuntimeError("no two free ports in a row")


def _cpu_seconds(pid: int) -> float:
    """User and system CPU time of a process so far (its threads included)."""
    with open(f"/proc/{pid}/stat", encoding="ascii") as f:
        fields = f.read().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def _latencies(notes: list[tuple[float, Any]], log: Path) -> tuple[list[float], int, int]:
    """Per status seen changed in a notification: its delay after the logged transition
    (seconds); with how many changes were matched and how many were not."""
    with log.open("rb") as f:
        btlog = BtLog(f)
        start = btlog.header.start_us
        by_uid: dict[int, list[tuple[float, str]]] = {}
        for t in btlog.transitions():
            by_uid.setdefault(t.uid, []).append(((start + t.offset_us) / 1e6, t.status.name))
    out: list[float] = []
    unmatched = 0
    # The first notification is the baseline: what changed is measured from the second on.
    previous: dict[int, str] = {
        n["uid"]: n["status"].upper() for n in (notes[0][1].get("nodes", []) if notes else [])
    }
    for at, params in notes[1:]:
        for node in params.get("nodes", []):
            uid, status = node["uid"], node["status"].upper()
            if previous.get(uid) == status:
                continue
            previous[uid] = status
            if status == "IDLE":
                continue  # also every node before it first ran: not a transition
            times = [t for t, s in by_uid.get(uid, []) if s == status and t <= at]
            if times:
                out.append(at - times[-1])
            else:
                unmatched += 1
    return out, len(out), unmatched


async def _measure(args: argparse.Namespace, work: Path) -> dict[str, Any]:
    tree = work / "tree.xml"
    tree.write_text(_tree(args.nodes, args.sleep_ms), encoding="utf-8")
    log = work / "run.btlog"
    port = _free_port()
    executor = subprocess.Popen(
        [sys.executable, __file__, "--executor", str(port), str(tree), str(log),
         str(args.seconds + 15)],
        stdout=subprocess.PIPE,
        text=True,
    )  # fmt: skip
    assert executor.stdout is not None and executor.stdout.readline().strip() == "ready"
    env = dict(os.environ, PYTHONPATH=str(HERE.parent / "src"))
    client = await LspClient.start([sys.executable, "-m", "bt_lsp", "serve"], env=env)
    try:
        await client.initialize(path_uri(work), {"debounceMs": 0})
        uri = path_uri(tree)
        client.open(uri, tree.read_text(encoding="utf-8"))
        notes = client.watch("bt-lsp/liveStatus")
        arg = {"uri": uri, "host": "127.0.0.1", "port": port, "rateHz": args.rate}
        connected = await client.request(
            "workspace/executeCommand", {"command": "bt-lsp.liveConnect", "arguments": [arg]}
        )
        await asyncio.sleep(1.0)  # settle: the first status and the first transitions
        cpu_server, cpu_executor = _cpu_seconds(client.pid), _cpu_seconds(executor.pid)
        begin, first = time.monotonic(), len(notes)
        await asyncio.sleep(args.seconds)
        elapsed = time.monotonic() - begin
        cpu_server = _cpu_seconds(client.pid) - cpu_server
        cpu_executor = _cpu_seconds(executor.pid) - cpu_executor
        window = notes[max(first - 1, 0) :]
        await client.request(
            "workspace/executeCommand", {"command": "bt-lsp.liveDisconnect", "arguments": []}
        )
    finally:
        await client.close()
        executor.kill()
        executor.wait(10)
    lat, matched, unmatched = _latencies(window, log)
    lat.sort()

    def pct(p: float) -> float:
        return round(1000 * lat[min(len(lat) - 1, int(p * len(lat)))], 1) if lat else 0.0

    return {
        "nodes": args.nodes,
        "mapped": connected.get("nodes"),
        "rate_hz": args.rate,
        "seconds": round(elapsed, 1),
        "notifications": max(len(window) - 1, 0),
        "changes_matched": matched,
        "changes_unmatched": unmatched,
        "latency_ms": {
            "median": round(1000 * statistics.median(lat), 1) if lat else 0.0,
            "p90": pct(0.9),
            "p99": pct(0.99),
            "max": round(1000 * lat[-1], 1) if lat else 0.0,
        },
        "server_cpu_percent": round(100 * cpu_server / elapsed, 1),
        "executor_cpu_percent": round(100 * cpu_executor / elapsed, 1),
    }


def main() -> None:
    if len(sys.argv) > 1 and sys.argv[1] == "--executor":
        port, tree, log, seconds = sys.argv[2:6]
        _executor(int(port), tree, log, float(seconds))
        return
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--nodes", type=int, default=500)
    ap.add_argument("--rate", type=float, default=10.0, help="the status polls per second")
    ap.add_argument("--seconds", type=float, default=20.0)
    ap.add_argument("--sleep-ms", type=int, default=40, help="how long each Sleep node runs")
    ap.add_argument("--json", type=Path)
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        result = asyncio.run(_measure(args, Path(tmp)))
    print(json.dumps(result, indent=1))
    if args.json:
        args.json.write_text(json.dumps(result, indent=1), encoding="utf-8")


if __name__ == "__main__":
    main()
