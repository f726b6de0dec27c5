#!/usr/bin/env python3
"""Compare bt-lsp with BehaviorTree.CPP's own unit tests.

Usage: compare.py BT_LSP [--models] [--known FILE] [--verbose] [--dump FILE]

BT_LSP is the command that runs bt-lsp (split like a shell would: ``"python -m bt_lsp"``
works).

Each case folder next to this script holds tree.xml (the XML exactly as a BehaviorTree.CPP
gtest feeds it), the further files the test loads into the same factory, and models.xml
(a <TreeNodesModel> with the nodes the test registers in C++).  expected.json says what the
test expects.  Every folder is checked as one workspace with
``bt-lsp check FOLDER --format json``. With ``--models``, a case's models.xml is also given
as the authoritative node catalog (``--models FOLDER/models.xml``), as a catalog that
BehaviorTree.CPP itself would export for the nodes the test registers; a case without
models.xml registers no custom node, and gets an empty catalog (what BehaviorTree.CPP's
``writeTreeNodesModelXML`` writes for such a factory).

* expect "throw" at stage "load" or "instantiate": caught when bt-lsp reports at least one
  diagnostic of severity error whose code is one of the case's ``cause_codes`` (the codes
  that name the cause BehaviorTree.CPP throws for).  Anything else is a mismatch (MISS).
* expect "ok": any error or warning is a false alarm (a mismatch).  Hints and information
  are not counted.
* expect "throw" at stage "tick": a bonus only; counted as flagged when bt-lsp reports an
  error or warning with one of the cause codes; never a mismatch.

With ``--known FILE`` (a JSON object: case -> reason), the listed mismatches are known
limits or intended differences: printed as KNOWN, not counted.  A listed case that no
longer mismatches is printed as STALE and counted, so that the list stays true.

Prints one line per mismatch and a final summary line; exit status 1 if any mismatch.
Standard library only.
"""

from __future__ import annotations

import json
import os
import shlex
import subprocess
import sys
import tempfile
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from typing import Any

HERE = os.path.dirname(os.path.abspath(__file__))


EMPTY_CATALOG = '<root BTCPP_format="4">\n  <TreeNodesModel/>\n</root>\n'


# What runs bt-lsp on one case folder: (folder, catalog or None) -> its JSON diagnostics, or
# a string saying why there are none.
Runner = Callable[[str, "str | None"], "list[dict[str, Any]] | str"]


def run_case(exe: str, folder: str, models: str | None = None) -> list[dict[str, Any]] | str:
    """bt-lsp's diagnostics for one case folder, or a string saying why there are none.
    ``models`` is the catalog to give a case that has no models.xml."""
    return run_command(exe, folder, catalog_of(folder, models))


def case_files(folder: str) -> list[str]:
    """The XML files of a case that BehaviorTree.CPP is fed (all but its models.xml)."""
    return sorted(
        os.path.join(folder, f)
        for f in os.listdir(folder)
        if f.endswith(".xml") and f != "models.xml"
    )


def catalog_of(folder: str, models: str | None) -> str | None:
    """The catalog to give a case: its models.xml, else ``models`` (with ``--models``)."""
    catalog = os.path.join(folder, "models.xml")
    if models is None:
        return None
    return catalog if os.path.isfile(catalog) else models


def run_command(exe: str, folder: str, catalog: str | None) -> list[dict[str, Any]] | str:
    """``bt-lsp check folder --format json [--models catalog]`` in a process of its own."""
    # Each file is named too: the test feeds it to BehaviorTree.CPP, which loads it as BT
    # XML whatever it looks like (a walk of the folder would skip an empty file).
    argv = [*shlex.split(exe), "check", folder, *case_files(folder), "--format", "json"]
    argv.append("--no-progress")
    if catalog is not None:
        argv += ["--models", catalog]
    try:
        proc = subprocess.run(
            argv,
            capture_output=True,
            text=True,
            timeout=120,
        )
    except (OSError, subprocess.TimeoutExpired) as e:
        return f"could not run bt-lsp: {e}"
    try:
        diags = json.loads(proc.stdout)
    except json.JSONDecodeError:
        return f"no JSON from bt-lsp (exit {proc.returncode}): {proc.stderr.strip()[:200]}"
    if not isinstance(diags, list):
        return "unexpected JSON from bt-lsp"
    return diags


def describe(d: dict[str, Any], folder: str) -> str:
    rel = os.path.relpath(d.get("path", "?"), folder)
    msg = " ".join(str(d.get("message", "")).split())
    if len(msg) > 140:
        msg = msg[:137] + "..."
    return f"{d.get('severity')} {d.get('code')} {rel}:{d.get('line')}: {msg}"


def main(argv: list[str], runner: Runner | None = None) -> int:
    """``runner`` (for a caller that runs bt-lsp in its own process) replaces the
    command named by ``argv[1]``, which is then not run."""
    if len(argv) < 2 or argv[1] in ("-h", "--help"):
        print(__doc__.strip())
        return 2
    exe = argv[1]
    verbose = "--verbose" in argv[2:]
    models = "--models" in argv[2:]
    dump = None
    if "--dump" in argv[2:]:
        dump = argv[argv.index("--dump") + 1]
    known: dict[str, str] = {}
    if "--known" in argv[2:]:
        with open(argv[argv.index("--known") + 1], encoding="utf-8") as fh:
            known = json.load(fh)
    with open(os.path.join(HERE, "expected.json"), encoding="utf-8") as fh:
        cases = json.load(fh)

    folders = [os.path.join(HERE, c["case"]) for c in cases]
    with tempfile.TemporaryDirectory() as tmp:
        empty = None
        if models:
            empty = os.path.join(tmp, "empty_models.xml")
            with open(empty, "w", encoding="utf-8") as fh:
                fh.write(EMPTY_CATALOG)
        if runner is not None:
            results = [runner(f, catalog_of(f, empty)) for f in folders]
        else:
            with ThreadPoolExecutor(max_workers=max(1, min(4, os.cpu_count() or 1))) as pool:
                results = list(pool.map(lambda f: run_case(exe, f, empty), folders))

    mismatches = 0
    load_total = load_caught = 0
    ok_total = false_alarms = 0
    tick_total = tick_flagged = 0
    warn_only = known_hits = 0
    raw = {}
    missed: set[str] = set()

    def mismatch(name: str, line: str) -> int:
        """Report one mismatch; 1 when it counts (it is not a known one)."""
        nonlocal known_hits
        missed.add(name)
        if name in known:
            known_hits += 1
            if verbose:
                print(f"KNOWN {line} -- {known[name]}")
            return 0
        print(line)
        return 1

    for c, folder, diags in zip(cases, folders, results, strict=True):
        name, src = c["case"], c["source"]
        raw[name] = diags
        if isinstance(diags, str):
            mismatches += mismatch(name, f"ERROR {name} ({src}): {diags}")
            continue
        codes = set(c.get("cause_codes", []))
        errors = [d for d in diags if d.get("severity") == "error"]
        loud = [d for d in diags if d.get("severity") in ("error", "warning")]
        if c["expect"] == "throw" and c["stage"] in ("load", "instantiate"):
            load_total += 1
            if any(d.get("code") in codes for d in errors):
                load_caught += 1
                if verbose:
                    print(f"caught {name}")
                continue
            if any(d.get("code") in codes for d in loud):
                warn_only += 1
            said = "; ".join(describe(d, folder) for d in diags) or "nothing"
            mismatches += mismatch(
                name,
                f"MISS {name} ({src}): BT.CPP throws at {c['stage']} "
                f"[{', '.join(sorted(codes)) or 'no bt-lsp code'}]; bt-lsp: {said}",
            )
        elif c["expect"] == "throw":
            tick_total += 1
            flagged = any(d.get("code") in codes for d in loud)
            tick_flagged += flagged
            if verbose:
                said = "; ".join(describe(d, folder) for d in loud) or "nothing"
                print(f"tick {'flagged' if flagged else 'not flagged'} {name}: {said}")
        else:
            ok_total += 1
            if loud:
                false_alarms += 1
                said = "; ".join(describe(d, folder) for d in loud)
                mismatches += mismatch(name, f"FALSE-ALARM {name} ({src}): {said}")
            elif verbose:
                print(f"clean {name}")

    for name in sorted(set(known) - missed):
        mismatches += 1
        print(f"STALE {name}: listed as known, but bt-lsp now agrees with BehaviorTree.CPP")
    if dump:
        with open(dump, "w", encoding="utf-8") as fh:
            json.dump(raw, fh, indent=1)
    print(
        f"btcpp gtests: caught {load_caught}/{load_total} load-time throws, "
        f"{false_alarms} false alarms on {ok_total} ok cases "
        f"(misses flagged only as warning: {warn_only}; "
        f"tick-time throws flagged statically: {tick_flagged}/{tick_total}; "
        f"known: {known_hits})"
    )
    return 1 if mismatches else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
