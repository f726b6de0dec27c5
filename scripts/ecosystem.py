#!/usr/bin/env python3
"""Ecosystem check: run ``bt-lsp check`` on whole real projects and hold it to a triage.

Each project folder of the projects directory (default ``../shared/projects`` beside the
repository) is checked as one workspace, the way a user opens it, with no configuration.
Every error and warning must match a line of ``tests/ecosystem/triage*.tsv`` (project,
path, line, code, verdict, reason); a ``true`` verdict is a real defect of the project, a
``false`` one a false alarm of bt-lsp. The run fails (exit 1) on an error or warning that
nobody triaged, on any ``false`` error, or when more than 5% of the warnings are ``false``.
Triage lines whose finding no longer appears are listed as stale (the code changed since
the file was written) but do not fail the run.

``--catalog`` compares ``bt-lsp models`` with the nodes written by hand from the projects'
C++ in ``tests/ecosystem/catalog_expected*.json`` and fails below 97% exact nodes.

Usage::

    python scripts/ecosystem.py [--projects DIR] [--only NAME ...] [--jobs 2]
        [--write-template FILE] [--json OUT] [--catalog]
"""

from __future__ import annotations

import argparse
import csv
import glob
import json
import os
import re
import subprocess
import sys
import time
from collections import Counter
from collections.abc import Iterable, Sequence
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parent.parent
DEFAULT_PROJECTS = ROOT.parent / "shared" / "projects"
TRIAGE_GLOB = "tests/ecosystem/triage*.tsv"
CATALOG_GLOB = "tests/ecosystem/catalog_expected*.json"
TRIAGE_HEADER = ("project", "path", "line", "code", "verdict", "reason")
MAX_FALSE_WARNING_PERCENT = 5.0
MIN_CATALOG_EXACT_PERCENT = 97.0
SEVERITIES = ("error", "warning", "hint")
CPP_SUFFIXES = {".cpp", ".cc", ".cxx", ".hpp", ".hh", ".h", ".ipp"}


@dataclass(frozen=True)
class Finding:
    """One diagnostic of ``bt-lsp check``, its path relative to the project root."""

    project: str
    path: str
    line: int
    code: str
    severity: str
    message: str

    @property
    def key(self) -> tuple[str, str, int, str]:
        return (self.project, self.path, self.line, self.code)


@dataclass(frozen=True)
class TriageLine:
    """One line of a triage file: every finding with the same key shares its verdict."""

    project: str
    path: str
    line: int
    code: str
    verdict: bool
    reason: str
    source: str = ""

    @property
    def key(self) -> tuple[str, str, int, str]:
        return (self.project, self.path, self.line, self.code)


@dataclass
class Report:
    """What the comparison found; ``failures`` says why the run fails (empty: it passes)."""

    counts_by_project: dict[str, Counter[str]] = field(default_factory=dict)
    counts_by_code: dict[str, Counter[str]] = field(default_factory=dict)
    untriaged: list[Finding] = field(default_factory=list)
    stale: list[TriageLine] = field(default_factory=list)
    true_errors: int = 0
    true_warnings: int = 0
    false_errors: list[Finding] = field(default_factory=list)
    false_warnings: list[Finding] = field(default_factory=list)
    warnings: int = 0
    own_unknown_nodes: Counter[str] = field(default_factory=Counter)
    own_unknown_examples: dict[str, list[str]] = field(default_factory=dict)

    @property
    def false_warning_percent(self) -> float:
        return 100.0 * len(self.false_warnings) / self.warnings if self.warnings else 0.0

    @property
    def failures(self) -> list[str]:
        out = []
        if self.untriaged:
            out.append(f"{len(self.untriaged)} error(s)/warning(s) not triaged")
        if self.false_errors:
            out.append(f"{len(self.false_errors)} false error(s)")
        if self.false_warning_percent > MAX_FALSE_WARNING_PERCENT:
            out.append(
                f"false warnings {self.false_warning_percent:.1f}% > "
                f"{MAX_FALSE_WARNING_PERCENT:.0f}%"
            )
        return out


# -- reading -------------------------------------------------------------------------------


def read_triage(paths: Iterable[Path]) -> list[TriageLine]:
    """The lines of every triage file; a malformed line is an error, not skipped."""
    lines: list[TriageLine] = []
    for path in paths:
        with path.open(encoding="utf-8", newline="") as f:
            rows = list(csv.reader(f, delimiter="\t", quoting=csv.QUOTE_NONE))
        if not rows or tuple(rows[0]) != TRIAGE_HEADER:
            raise ValueError(f"{path}: the first line must be {'<TAB>'.join(TRIAGE_HEADER)}")
        for n, row in enumerate(rows[1:], start=2):
            if not row or not "".join(row).strip():
                continue
            if len(row) != len(TRIAGE_HEADER) or row[4] not in ("true", "false"):
                raise ValueError(f"{path}:{n}: expected 6 columns and verdict true/false")
            lines.append(
                TriageLine(
                    project=row[0],
                    path=row[1],
                    line=int(row[2]),
                    code=row[3],
                    verdict=row[4] == "true",
                    reason=row[5],
                    source=f"{path.name}:{n}",
                )
            )
    return lines


def parse_check_output(project: str, root: Path, text: str) -> list[Finding]:
    """The findings of ``bt-lsp check --format json``, with paths relative to ``root``.

    ``check`` prints a path as given on its command line: relative to the working directory
    when ``root`` is relative (``--projects ../shared/projects``), so both are made absolute
    from there."""
    out = []
    base = os.path.abspath(root)
    for item in json.loads(text or "[]"):
        rel = os.path.relpath(os.path.abspath(item["path"]), base).replace(os.sep, "/")
        out.append(
            Finding(
                project=project,
                path=rel,
                line=int(item["line"]),
                code=str(item["code"]),
                severity=str(item["severity"]),
                message=str(item.get("message", "")),
            )
        )
    return out


# -- comparing -----------------------------------------------------------------------------

_QUOTED = re.compile(r"'([^']+)'")
_REGISTER = re.compile(
    r"\b(?:\w*[Rr]egister\w*|BT_REGISTER\w*|CreateRosNodePlugin|BT_RegisterRosNodeFromPlugin)\b"
)
_LITERAL = re.compile(r'"([A-Za-z_][\w.:/-]*)"')


# A C++ comment (a string holding // is rare in registration code; the count errs towards
# "registered" anyway).
_COMMENT = re.compile(r"//[^\n]*|/\*.*?\*/", re.DOTALL)


def registered_literals(root: Path) -> set[str]:
    """String literals that appear in a registration call of the project's C++.

    A grep, not a parse: after every ``register*`` / ``BT_REGISTER*`` /
    ``CreateRosNodePlugin`` token, the literals up to the next ``;`` (at most 400
    characters), comments left out. It errs towards "registered": it serves only to count
    the unknown-node hints whose node the project itself registers.
    """
    names: set[str] = set()
    for dirpath, _dirs, files in os.walk(root):
        for name in files:
            if Path(name).suffix not in CPP_SUFFIXES:
                continue
            try:
                text = (Path(dirpath) / name).read_text(encoding="utf-8", errors="replace")
            except OSError:
                continue
            text = _COMMENT.sub(" ", text)
            for m in _REGISTER.finditer(text):
                window = text[m.end() : m.end() + 400]
                window = window.split(";", 1)[0]
                names.update(_LITERAL.findall(window))
    return names


def unknown_node_id(message: str) -> str | None:
    m = _QUOTED.search(message)
    return m.group(1) if m else None


def compare(
    findings: Sequence[Finding],
    triage: Sequence[TriageLine],
    projects: Iterable[str],
    registered: dict[str, set[str]] | None = None,
) -> Report:
    """Hold the findings of ``projects`` to the triage lines of the same projects."""
    ran = set(projects)
    report = Report()
    by_key: dict[tuple[str, str, int, str], TriageLine] = {}
    for t in triage:
        if t.project in ran:
            by_key[t.key] = t
    seen: set[tuple[str, str, int, str]] = set()
    for project in sorted(ran):
        report.counts_by_project[project] = Counter()
    for f in findings:
        sev = f.severity if f.severity in SEVERITIES else "hint"
        if f.severity == "information":
            sev = "hint"
        report.counts_by_project.setdefault(f.project, Counter())[sev] += 1
        report.counts_by_code.setdefault(f.code, Counter())[sev] += 1
        if f.severity == "hint" and f.code == "unknown-node" and registered is not None:
            node = unknown_node_id(f.message)
            if node is not None and node in registered.get(f.project, set()):
                report.own_unknown_nodes[f.project] += 1
                report.own_unknown_examples.setdefault(f.project, []).append(node)
        if f.severity not in ("error", "warning"):
            continue
        if f.severity == "warning":
            report.warnings += 1
        line = by_key.get(f.key)
        if line is None:
            report.untriaged.append(f)
            continue
        seen.add(line.key)
        if line.verdict:
            if f.severity == "error":
                report.true_errors += 1
            else:
                report.true_warnings += 1
        elif f.severity == "error":
            report.false_errors.append(f)
        else:
            report.false_warnings.append(f)
    report.stale = [t for key, t in sorted(by_key.items()) if key not in seen]
    return report


# -- catalog -------------------------------------------------------------------------------


def _norm_type(t: str | None) -> str | None:
    """Spelling only: no whitespace, no leading ``::``; an untyped port is ``None``."""
    if t is None:
        return None
    t = re.sub(r"\s+", "", t)
    t = t[2:] if t.startswith("::") else t
    return None if t in ("AnyTypeAllowed", "BT::AnyTypeAllowed") else t


def _norm_default(value: str) -> str | float:
    v = value.strip()
    num = v[:-1] if v[-1:] in ("f", "F") and re.fullmatch(r"[-+]?[\d.]+[fF]", v) else v
    try:
        return float(num)
    except ValueError:
        return v


def compare_node(expected: dict[str, Any], actual: dict[str, Any] | None) -> list[str]:
    """How ``bt-lsp models``' node differs from the hand-written one (empty: exact)."""
    if actual is None:
        return ["not found"]
    problems = []
    if actual.get("kind") != expected["kind"]:
        problems.append(f"kind {actual.get('kind')} != {expected['kind']}")
    want = {p["name"]: p for p in expected["ports"]}
    got = {p["name"]: p for p in actual.get("ports", [])}
    for name in sorted(want.keys() - got.keys()):
        problems.append(f"port {name!r} missing")
    for name in sorted(got.keys() - want.keys()):
        problems.append(f"port {name!r} not expected")
    for name in sorted(want.keys() & got.keys()):
        w, g = want[name], got[name]
        if w["direction"] != g.get("direction"):
            problems.append(f"port {name!r} direction {g.get('direction')} != {w['direction']}")
        types = {_norm_type(w.get("type"))}
        if w.get("type_resolved"):
            types.add(_norm_type(w["type_resolved"]))
        if _norm_type(g.get("type")) not in types:
            problems.append(f"port {name!r} type {g.get('type')!r} != {w.get('type')!r}")
        wd, gd = w.get("default"), g.get("default")
        if (wd is None) != (gd is None) or (
            wd is not None
            and gd is not None
            and not w.get("default_expr")
            and _norm_default(str(wd)) != _norm_default(str(gd))
        ):
            problems.append(f"port {name!r} default {gd!r} != {wd!r}")
    return problems


def read_catalogs(paths: Iterable[Path]) -> list[dict[str, Any]]:
    nodes: list[dict[str, Any]] = []
    for path in paths:
        data = json.loads(path.read_text(encoding="utf-8"))
        for node in data["nodes"]:
            node = dict(node)
            node["_source"] = path.name
            nodes.append(node)
    return nodes


# -- running -------------------------------------------------------------------------------


def _env() -> dict[str, str]:
    env = dict(os.environ)
    src = str(ROOT / "src")
    env["PYTHONPATH"] = src + (os.pathsep + env["PYTHONPATH"] if env.get("PYTHONPATH") else "")
    return env


def run_bt_lsp(args: list[str]) -> tuple[int, str, str]:
    proc = subprocess.run(
        [sys.executable, "-m", "bt_lsp", *args],
        capture_output=True,
        text=True,
        env=_env(),
        check=False,
    )
    return proc.returncode, proc.stdout, proc.stderr


def check_project(root: Path) -> tuple[list[Finding], float, str, int | None]:
    """``bt-lsp check <root> --format json`` in a subprocess (its cache is the normal one),
    and how many BT files it checked (its summary on stderr says)."""
    start = time.monotonic()
    rc, out, err = run_bt_lsp(["check", str(root), "--format", "json", "--no-progress"])
    elapsed = time.monotonic() - start
    if rc not in (0, 1):
        return [], elapsed, f"exit {rc}: {err.strip()[-500:]}", None
    files = _FILES_CHECKED.search(err)
    count = int(files.group(1)) if files else None
    return parse_check_output(root.name, root, out), elapsed, "", count


_FILES_CHECKED = re.compile(r" in (\d+) files?\b")


def models_of(root: Path) -> dict[str, dict[str, Any]]:
    rc, out, err = run_bt_lsp(["models", str(root), "--format", "json"])
    if rc != 0:
        raise RuntimeError(f"bt-lsp models {root}: exit {rc}: {err.strip()[-500:]}")
    # The first node of an ID is the one ``check`` uses (the others are copies or
    # registrations in files that are not built, listed after it).
    nodes: dict[str, dict[str, Any]] = {}
    for n in json.loads(out)["nodes"]:
        nodes.setdefault(n["id"], n)
    return nodes


def project_dirs(projects: Path, only: Sequence[str]) -> list[Path]:
    dirs = sorted(p for p in projects.iterdir() if p.is_dir() and not p.name.startswith("."))
    if only:
        wanted = set(only)
        missing = wanted - {p.name for p in dirs}
        if missing:
            raise SystemExit(f"no such project: {', '.join(sorted(missing))}")
        dirs = [p for p in dirs if p.name in wanted]
    return dirs


# -- printing ------------------------------------------------------------------------------


def _fmt(f: Finding) -> str:
    return f"  {f.project}/{f.path}:{f.line}: {f.severity} {f.code}: {f.message[:160]}"


def print_report(report: Report, out: Any = sys.stdout) -> None:
    def p(text: str = "") -> None:
        print(text, file=out)

    p(f"{'project':<55} {'errors':>7} {'warnings':>8} {'hints':>6}")
    for project, c in sorted(report.counts_by_project.items()):
        p(f"{project:<55} {c['error']:>7} {c['warning']:>8} {c['hint']:>6}")
    p()
    p(f"{'code':<55} {'errors':>7} {'warnings':>8} {'hints':>6}")
    for code, c in sorted(report.counts_by_code.items()):
        p(f"{code:<55} {c['error']:>7} {c['warning']:>8} {c['hint']:>6}")
    p()
    p(f"not triaged ({len(report.untriaged)}):")
    for f in report.untriaged:
        p(_fmt(f))
    p(f"stale triage lines, changed since the file was written ({len(report.stale)}):")
    for t in report.stale:
        verdict = "true" if t.verdict else "false"
        p(f"  {t.project}/{t.path}:{t.line}: {t.code} ({verdict}; {t.source})")
    p(f"false errors ({len(report.false_errors)}):")
    for f in report.false_errors:
        p(_fmt(f))
    p(
        f"true errors {report.true_errors}, true warnings {report.true_warnings}, "
        f"false errors {len(report.false_errors)}, false warnings {len(report.false_warnings)} "
        f"of {report.warnings} warnings ({report.false_warning_percent:.1f}%)"
    )
    total = sum(report.own_unknown_nodes.values())
    p(f"unknown-node hints on nodes the project's own C++ registers: {total}")
    for project, n in sorted(report.own_unknown_nodes.items()):
        names = sorted(set(report.own_unknown_examples.get(project, [])))
        p(f"  {project}: {n} ({', '.join(names[:8])}{', ...' if len(names) > 8 else ''})")


def summary_json(report: Report, seconds: float, catalog: dict[str, Any] | None) -> dict[str, Any]:
    return {
        "seconds": round(seconds, 1),
        "counts_by_project": {k: dict(v) for k, v in sorted(report.counts_by_project.items())},
        "counts_by_code": {k: dict(v) for k, v in sorted(report.counts_by_code.items())},
        "untriaged": [f.__dict__ for f in report.untriaged],
        "stale": [
            {k: v for k, v in t.__dict__.items() if k != "source"} | {"source": t.source}
            for t in report.stale
        ],
        "true_errors": report.true_errors,
        "true_warnings": report.true_warnings,
        "false_errors": len(report.false_errors),
        "false_warnings": len(report.false_warnings),
        "warnings": report.warnings,
        "false_warning_percent": round(report.false_warning_percent, 2),
        "own_unknown_node_hints": dict(report.own_unknown_nodes),
        "catalog": catalog,
        "failures": report.failures,
    }


README = ROOT / "README.md"
README_BEGIN = "<!-- ecosystem:begin (generated by scripts/ecosystem.py --readme write) -->"
README_END = "<!-- ecosystem:end -->"


def readme_table(
    report: Report, bt_files: dict[str, int | None], findings: Sequence[Finding]
) -> str:
    """The README's table of the projects: the errors and warnings a check of each finds,
    and their triage.  Hints are left out: they are not triaged, and a new hint would make
    the table stale though nothing it holds to a triage changed."""
    by_project: dict[str, Counter[str]] = {}
    for f in findings:
        if f.severity in ("error", "warning"):
            by_project.setdefault(f.project, Counter())[f.code] += 1
    sources = _bt_files_of_sources()
    lines = [
        "| project | BT files | errors | warnings | errors and warnings by code |",
        "|---|---|---|---|---|",
    ]
    for project, c in sorted(report.counts_by_project.items()):
        counts = by_project.get(project, Counter())
        top = ", ".join(f"`{code}` {n}" for code, n in counts.most_common(4))
        files = bt_files.get(project) or sources.get(project)
        lines.append(
            f"| {project.replace('__', '/', 1)} | {files if files is not None else '?'} | "
            f"{c['error']} | {c['warning']} | {top} |"
        )
    errors = sum(c["error"] for c in report.counts_by_project.values())
    warnings = sum(c["warning"] for c in report.counts_by_project.values())
    lines += [
        "",
        f"Triage of these {errors} errors and {warnings} warnings: "
        f"{report.true_errors} errors and {report.true_warnings} warnings are real defects of "
        f"the projects, {len(report.false_errors)} errors and {len(report.false_warnings)} "
        "warnings are false alarms of bt-lsp.",
    ]
    return "\n".join(lines) + "\n"


def _bt_files_of_sources() -> dict[str, int]:
    """The ``bt_xml_files`` column of the projects' ``SOURCES.tsv`` (XML files holding a
    ``<BehaviorTree``), by project folder."""
    path = DEFAULT_PROJECTS / "SOURCES.tsv"
    out: dict[str, int] = {}
    try:
        with path.open(encoding="utf-8", newline="") as f:
            for row in csv.DictReader(f, delimiter="\t"):
                if row.get("bt_xml_files", "").isdigit():
                    out[row["folder"]] = int(row["bt_xml_files"])
    except OSError:
        pass
    return out


def readme_region() -> str | None:
    """The README's generated table as it stands (``None`` without the markers)."""
    text = README.read_text(encoding="utf-8")
    start, end = text.find(README_BEGIN), text.find(README_END)
    if start < 0 or end < start:
        return None
    return text[start + len(README_BEGIN) + 1 : end]


def write_readme(table: str) -> None:
    text = README.read_text(encoding="utf-8")
    start, end = text.find(README_BEGIN), text.find(README_END)
    if start < 0 or end < start:
        raise SystemExit(f"README.md has no {README_BEGIN!r} ... {README_END!r} region")
    README.write_text(
        text[: start + len(README_BEGIN)] + "\n" + table + text[end:], encoding="utf-8"
    )


def write_template(path: Path, findings: Sequence[Finding]) -> int:
    """Append one triage line per untriaged key (verdict and reason left to fill in)."""
    keys: dict[tuple[str, str, int, str], Finding] = {}
    for f in findings:
        keys.setdefault(f.key, f)
    new = not path.exists() or path.stat().st_size == 0
    with path.open("a", encoding="utf-8", newline="") as out:
        if new:
            out.write("\t".join(TRIAGE_HEADER) + "\n")
        for key in sorted(keys):
            f = keys[key]
            msg = f.message.replace("\t", " ").replace("\n", " ")
            out.write(f"{f.project}\t{f.path}\t{f.line}\t{f.code}\tTODO\t{f.severity}: {msg}\n")
    return len(keys)


def run_catalog(projects: Path) -> tuple[dict[str, Any], bool]:
    files = sorted(ROOT.glob(CATALOG_GLOB))
    nodes = read_catalogs(files)
    models: dict[str, dict[str, dict[str, Any]]] = {}
    exact = 0
    mismatches = []
    for node in nodes:
        project = node["project"]
        if project not in models:
            models[project] = models_of(projects / project)
        problems = compare_node(node, models[project].get(node["id"]))
        if problems:
            mismatches.append({"project": project, "id": node["id"], "problems": problems})
        else:
            exact += 1
    percent = 100.0 * exact / len(nodes) if nodes else 100.0
    print(f"\ncatalog: {exact}/{len(nodes)} nodes exact ({percent:.1f}%) from {len(files)} file(s)")
    for m in mismatches:
        print(f"  {m['project']} {m['id']}: {'; '.join(m['problems'])}")
    ok = percent >= MIN_CATALOG_EXACT_PERCENT
    summary = {"nodes": len(nodes), "exact": exact, "percent": round(percent, 2)}
    return summary | {"mismatches": mismatches}, ok


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0] if __doc__ else "")
    parser.add_argument("--projects", type=Path, default=DEFAULT_PROJECTS, metavar="DIR")
    parser.add_argument("--only", nargs="+", default=[], metavar="NAME", help="these projects")
    parser.add_argument("--jobs", type=int, default=2, choices=(1, 2), help="projects at once")
    parser.add_argument(
        "--triage", nargs="+", type=Path, default=None, help=f"default: {TRIAGE_GLOB}"
    )
    parser.add_argument("--write-template", type=Path, metavar="FILE")
    parser.add_argument("--json", type=Path, metavar="OUT", help="write the summary here")
    parser.add_argument("--catalog", action="store_true", help="also compare the catalogs")
    parser.add_argument(
        "--readme",
        choices=("check", "write"),
        default="check",
        help="check (default) or write the README's table of the projects",
    )
    args = parser.parse_args(argv)

    start = time.monotonic()
    dirs = project_dirs(args.projects, args.only)
    triage_files = args.triage or sorted(Path(p) for p in glob.glob(str(ROOT / TRIAGE_GLOB)))
    triage = read_triage(triage_files)

    findings: list[Finding] = []
    errors: list[str] = []
    bt_files: dict[str, int | None] = {}
    with ThreadPoolExecutor(max_workers=args.jobs) as pool:
        results = pool.map(check_project, dirs)
        for root, (found, _secs, err, count) in zip(dirs, results, strict=True):
            findings.extend(found)
            bt_files[root.name] = count
            if err:
                errors.append(f"{root.name}: {err}")
    registered = {
        root.name: registered_literals(root)
        for root in dirs
        if any(f.project == root.name and f.code == "unknown-node" for f in findings)
    }
    report = compare(findings, triage, [d.name for d in dirs], registered)
    print_report(report)
    failures = report.failures + [f"bt-lsp failed: {e}" for e in errors]

    # The README describes the shared projects, all of them: only such a run writes or
    # checks its table.
    if not args.only and args.projects.resolve() == DEFAULT_PROJECTS.resolve():
        table = readme_table(report, bt_files, findings)
        if args.readme == "write":
            write_readme(table)
        elif readme_region() not in (None, table):
            failures.append(
                "the README's real-project table is stale: python scripts/ecosystem.py "
                "--readme write"
            )

    catalog = None
    if args.catalog:
        catalog, ok = run_catalog(args.projects)
        if not ok:
            failures.append(f"catalog below {MIN_CATALOG_EXACT_PERCENT:.0f}% exact nodes")
    if args.write_template:
        n = write_template(args.write_template, report.untriaged)
        print(f"appended {n} line(s) to {args.write_template}")
    seconds = time.monotonic() - start
    if args.json:
        data = summary_json(report, seconds, catalog) | {"failures": failures}
        args.json.write_text(json.dumps(data, indent=2) + "\n", encoding="utf-8")
    print(f"\n{len(dirs)} projects in {seconds:.1f} s")
    for failure in failures:
        print(f"FAIL: {failure}")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
