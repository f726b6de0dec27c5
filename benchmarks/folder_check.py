"""How ``bt-lsp check`` grows with the number of files in one folder.

    python benchmarks/folder_check.py                       # 250, 1000, 5000, 10000 files
    python benchmarks/folder_check.py --counts 250,1000 --timeout 120 --json out.json

For each count a temporary folder gets that many small BehaviorTree.CPP files
(:func:`write_folder`): each defines a tree or two of a few controls, decorators and
custom nodes with ports and calls trees defined in other files by ``<SubTree>``, some
include another file, and one file holds the ``<TreeNodesModel>`` of the custom nodes.
Then ``bt-lsp check --no-cpp --format json FOLDER`` runs in a fresh process (``nice``) and
its wall time, CPU time (user + system), the findings and the exit status are printed.
With Nav2's sources at ``--nav2`` (default
``/work/shared/projects/ros-navigation__navigation2``), its whole tree is checked too
(with the C++ read).  Not part of the test suite
(``tests/test_benchmarks_smoke.py`` checks the generator only).
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import random
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

COUNTS = "250,1000,5000,10000"
NAV2 = "/work/shared/projects/ros-navigation__navigation2"
ROOT = Path(__file__).resolve().parent.parent

ACTIONS = (
    ("MoveTo", ("goal", "speed")),
    ("Grab", ("object",)),
    ("Say", ("text",)),
    ("Wait", ("msec",)),
    ("Scan", ("area", "result")),
)
CONDITIONS = (("IsReady", ()), ("BatteryOk", ("level",)), ("SeesObject", ("object",)))


def _node(rng: random.Random, indent: str) -> str:
    kind, ports = rng.choice(ACTIONS + CONDITIONS)
    attrs = "".join(
        f' {p}="{{{p}}}"' if rng.random() < 0.5 else f' {p}="{rng.randint(1, 9)}"' for p in ports
    )
    return f"{indent}<{kind}{attrs}/>\n"


def tree_id(n: int, k: int) -> str:
    return f"Task{n}_{k}"


def bt_file(n: int, count: int, rng: random.Random) -> str:
    """File ``n`` of ``count``: one or two trees calling trees of other files."""
    trees = rng.choice((1, 1, 2))
    main = f' main_tree_to_execute="{tree_id(n, 0)}"' if trees > 1 else ""
    out = [f'<root BTCPP_format="4"{main}>\n']
    if n > 0 and rng.random() < 0.2:
        out.append(f'  <include path="tree_{rng.randrange(n):05d}.xml"/>\n')
    for k in range(trees):
        out.append(f'  <BehaviorTree ID="{tree_id(n, k)}">\n')
        control = rng.choice(("Sequence", "Fallback", "ReactiveSequence"))
        out.append(f"    <{control}>\n")
        for _ in range(rng.randint(2, 5)):
            r = rng.random()
            if r < 0.25 and count > 1:
                other = rng.randrange(count)
                if other == n:
                    other = (n + 1) % count
                out.append(f'      <SubTree ID="{tree_id(other, 0)}" _autoremap="true"/>\n')
            elif r < 0.4:
                out.append('      <RetryUntilSuccessful num_attempts="3">\n')
                out.append(_node(rng, "        "))
                out.append("      </RetryUntilSuccessful>\n")
            else:
                out.append(_node(rng, "      "))
        out.append(f"    </{control}>\n")
        out.append("  </BehaviorTree>\n")
    out.append("</root>\n")
    return "".join(out)


def models_file() -> str:
    out = ['<root BTCPP_format="4">\n  <TreeNodesModel>\n']
    for kind, ports in ACTIONS:
        out.append(f'    <Action ID="{kind}">\n')
        out.extend(f'      <input_port name="{p}"/>\n' for p in ports)
        out.append("    </Action>\n")
    for kind, ports in CONDITIONS:
        out.append(f'    <Condition ID="{kind}">\n')
        out.extend(f'      <input_port name="{p}"/>\n' for p in ports)
        out.append("    </Condition>\n")
    out.append("  </TreeNodesModel>\n</root>\n")
    return "".join(out)


def write_folder(folder: Path, count: int, seed: int = 1) -> None:
    """``count`` BT files (and the models file) in ``folder``."""
    rng = random.Random(seed)
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "models.xml").write_text(models_file(), encoding="utf-8")
    for n in range(count):
        (folder / f"tree_{n:05d}.xml").write_text(bt_file(n, count, rng), encoding="utf-8")


def check(target: str, *, cpp: bool, timeout: float) -> dict[str, Any]:
    """Time one ``bt-lsp check`` of ``target`` in a fresh process."""
    cmd = ["nice", sys.executable, "-m", "bt_lsp", "check", "--no-progress", "--format", "json"]
    if not cpp:
        cmd.append("--no-cpp")
    env = dict(os.environ)
    env["PYTHONPATH"] = str(ROOT / "src") + os.pathsep + env.get("PYTHONPATH", "")
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    try:
        proc = subprocess.run(
            [*cmd, target], capture_output=True, text=True, timeout=timeout, env=env
        )
    except subprocess.TimeoutExpired:
        return {"seconds": None, "timeout": timeout}
    seconds = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = after.ru_utime - before.ru_utime + after.ru_stime - before.ru_stime
    findings = json.loads(proc.stdout) if proc.stdout.strip() else []
    return {
        "seconds": round(seconds, 2),
        "cpu_seconds": round(cpu, 2),  # the wall time's share of a loaded machine aside
        "exit": proc.returncode,
        "findings": len(findings),
    }


def machine() -> dict[str, Any]:
    model = platform.processor() or platform.machine()
    try:
        for line in subprocess.run(["lscpu"], capture_output=True, text=True).stdout.splitlines():
            if line.startswith("Model name:"):
                model = line.split(":", 1)[1].strip()
    except OSError:
        pass
    return {
        "cpu": model,
        "cpus": os.cpu_count(),
        "python": platform.python_version(),
        "load": [round(x, 2) for x in os.getloadavg()],
    }


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--counts", default=COUNTS, help="file counts (default: %(default)s)")
    ap.add_argument("--timeout", type=float, default=600.0, help="seconds per run")
    ap.add_argument("--nav2", default=NAV2, help="Nav2's sources ('' to skip)")
    ap.add_argument("--json", metavar="FILE", help="also write the figures here")
    args = ap.parse_args(argv)
    rows: list[dict[str, Any]] = []
    print(json.dumps(machine()))
    for count in (int(c) for c in args.counts.split(",") if c):
        with tempfile.TemporaryDirectory(prefix="bt-folder-") as tmp:
            write_folder(Path(tmp), count)
            row = {"files": count, **check(tmp, cpp=False, timeout=args.timeout)}
        rows.append(row)
        print(json.dumps(row), flush=True)
    if args.nav2 and os.path.isdir(args.nav2):
        row = {"files": "nav2", **check(args.nav2, cpp=True, timeout=args.timeout)}
        rows.append(row)
        print(json.dumps(row), flush=True)
    if args.json:
        Path(args.json).write_text(json.dumps({"machine": machine(), "rows": rows}, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
