"""Drive the real bt-lsp server over stdio like an editor and time it against lxml.

For each document size: start the server (time to the ``initialize`` result, beside a bare
pygls server started the same way), open a generated document (time to its first
diagnostics, which for a large document are its name diagnostics, and to its complete
diagnostics, the publication after those, or the first when the document is small or the
early pass gives up), type (a letter inserted at the end of a node's ``name`` or a port value and
deleted again, at places spread over the trees; time from each ``didChange`` to the
diagnostics of that version), ask for a quick fix (``codeAction`` + ``codeAction/resolve``
of its preferred action), a fix-all (the same for ``source.fixAll.bt-lsp``) and a hover.
Memory is the server's VmRSS from /proc: idle (after a tiny document was opened and
closed, so that everything imported on first use is in the baseline), after the open, and
at the end (and VmHWM, its peak).  Then ``bt-lsp check`` over a corpus.

Every figure is the median and the 95th percentile of its samples; lxml's time to parse
the same bytes once (``lxml.etree.fromstring``) is measured in the same run.

    python benchmarks/run.py [--sizes 60K,1M,4M] [--repeat 5] [--edits 20] [--json out.json]
"""

from __future__ import annotations

import argparse
import asyncio
import contextlib
import gc
import json
import math
import os
import platform
import re
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parent))

from generate import generate, parse_size
from lsp_client import LspClient, path_uri, rss_kib

HERE = Path(__file__).resolve().parent
SERVER = [sys.executable, "-m", "bt_lsp", "serve"]
BARE = [sys.executable, str(HERE / "bare_server.py")]
DEFAULT_CORPUS = HERE.parent / "tests" / "data" / "corpus_real"
# The warm-up document: one bad name, to ask for each kind of request once.
TINY = '<root BTCPP_format="4"><BehaviorTree ID="T 1"><AlwaysSuccess/></BehaviorTree></root>\n'


# -- statistics ---------------------------------------------------------------------------


def percentile(samples: Sequence[float], q: float) -> float:
    """The ``q`` quantile (0-1) with linear interpolation between closest ranks."""
    s = sorted(samples)
    if not s:
        return math.nan
    k = (len(s) - 1) * q
    lo, hi = math.floor(k), math.ceil(k)
    return s[lo] + (s[hi] - s[lo]) * (k - lo)


def summary(samples: Sequence[float]) -> dict[str, float]:
    return {
        "median": statistics.median(samples) if samples else math.nan,
        "p95": percentile(samples, 0.95),
        "n": len(samples),
    }


def ms(seconds: float) -> str:
    v = seconds * 1000
    return f"{v:.0f}" if v >= 100 else f"{v:.1f}" if v >= 10 else f"{v:.2f}"


# -- the document ---------------------------------------------------------------------------


@dataclass
class Doc:
    text: str
    size: int
    path: Path
    uri: str
    typing_offsets: list[int]  # where a letter is typed
    hover_offset: int
    bad_name: tuple[int, int] | None  # span of a planted bad name near the middle


def _position(text: str, offset: int) -> dict[str, int]:
    """LSP position of an offset (the generated text is ASCII: UTF-16 = code points)."""
    line = text.count("\n", 0, offset)
    col = offset - (text.rfind("\n", 0, offset) + 1)
    return {"line": line, "character": col}


def _spread(items: Sequence[int], k: int) -> list[int]:
    if not items:
        return []
    if len(items) <= k:
        return list(items)
    return (
        [items[round(i * (len(items) - 1) / (k - 1))] for i in range(k)]
        if k > 1
        else [items[len(items) // 2]]
    )


def make_doc(size: int, folder: Path, edits: int, seed: int) -> Doc:
    g = generate(size, seed)
    text = g.text
    path = folder / f"bench_{size}.xml"
    path.write_text(text, encoding="utf-8", newline="\n")
    trees_end = text.find("<TreeNodesModel>")
    # The end of instance names and port values inside the trees (no IDs: renaming a
    # tree or a node type is not typing inside a tree).
    values = [
        m.end(2)
        for m in re.finditer(r'\s([A-Za-z_][\w.]*)="([^"]*)"', text, 0)
        if m.start() < trees_end and m.group(1) != "ID"
    ]
    start_of_trees = text.find("<BehaviorTree", text.find("</BehaviorTree>"))
    values = [v for v in values if v > start_of_trees]
    nodes = [
        m.start(1)
        for m in re.finditer(r"<([A-Z][A-Za-z0-9]*) name=", text)
        if m.start() < trees_end
    ]
    hover = nodes[len(nodes) // 2] + 2 if nodes else 0
    bad: tuple[int, int] | None = None
    mid = len(text) // 2
    for p in sorted(g.planted, key=lambda p: p.name):
        for m in re.finditer(re.escape(f'"{p.name}"'), text):
            span = (m.start() + 1, m.end() - 1)
            if bad is None or abs(span[0] - mid) < abs(bad[0] - mid):
                bad = span
    return Doc(text, len(text.encode()), path, path_uri(path), _spread(values, edits), hover, bad)


# -- one server session -----------------------------------------------------------------------


@dataclass
class Session:
    startup: float = math.nan
    open: float = math.nan  # to the first diagnostics published for the open
    open_complete: float = math.nan  # to the last, the complete set
    edits: list[float] = field(default_factory=list)
    edit_cpu: float = math.nan  # server CPU seconds per edit (utime + stime)
    quick_fix: list[float] = field(default_factory=list)
    fix_all: list[float] = field(default_factory=list)
    hover: list[float] = field(default_factory=list)
    rss_idle: int = 0
    rss_open: int = 0
    rss_end: int = 0
    hwm: int = 0
    diagnostics: int = 0


def cpu_seconds(pid: int) -> float:
    try:
        with open(f"/proc/{pid}/stat", encoding="ascii") as f:
            fields = f.read().rsplit(")", 1)[1].split()
        return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")
    except OSError:
        return math.nan


async def start_timed(command: Sequence[str], root: str) -> tuple[LspClient, float]:
    t0 = time.perf_counter()
    client = await LspClient.start(command)
    await client.initialize(root, {"debounceMs": 0})
    # The answer's arrival time, not the time this coroutine resumed.
    return client, client.last_answer_at - t0


async def startup_only(command: Sequence[str], root: str) -> float:
    client, seconds = await start_timed(command, root)
    await client.close()
    return seconds


async def session(doc: Doc, root: str, edits_per_place: int = 2, requests: int = 5) -> Session:
    s = Session()
    client, s.startup = await start_timed(SERVER, root)
    try:
        # Warm up with a tiny document (opened, each request asked once, closed) so that
        # the idle baseline holds what is imported or compiled on first use.
        tiny = doc.path.parent / "tiny.xml"
        tiny_uri = path_uri(tiny)
        fut = client.expect_diagnostics(tiny_uri, 1)
        client.notify(
            "textDocument/didOpen",
            {"textDocument": {"uri": tiny_uri, "languageId": "xml", "version": 1, "text": TINY}},
        )
        warm = await asyncio.wait_for(fut, 60)
        await _warm_up(client, tiny_uri, warm.diagnostics)
        client.notify("textDocument/didClose", {"textDocument": {"uri": tiny_uri}})
        await asyncio.sleep(0.2)
        s.rss_idle = rss_kib(client.pid)

        version = 1
        fut = client.expect_diagnostics(doc.uri, version)
        t0 = client.notify(
            "textDocument/didOpen",
            {
                "textDocument": {
                    "uri": doc.uri,
                    "languageId": "xml",
                    "version": version,
                    "text": doc.text,
                }
            },
        )
        await client.drain()
        pub = await asyncio.wait_for(fut, 600)
        s.open = pub.at - t0
        # The complete set comes from the worker thread, after the name diagnostics.
        last = await client.published_count(doc.uri, open_publications(doc.text))
        assert last.version == version
        s.open_complete = last.at - t0
        s.diagnostics = len(last.diagnostics)
        s.rss_open = rss_kib(client.pid)

        cpu0 = cpu_seconds(client.pid)
        for offset in doc.typing_offsets:
            pos = _position(doc.text, offset)
            after = {"line": pos["line"], "character": pos["character"] + 1}
            for i in range(edits_per_place):
                version += 1
                insert = i % 2 == 0
                change = {
                    "range": {"start": pos, "end": pos if insert else after},
                    "text": "x" if insert else "",
                }
                fut = client.expect_diagnostics(doc.uri, version)
                t0 = client.notify(
                    "textDocument/didChange",
                    {
                        "textDocument": {"uri": doc.uri, "version": version},
                        "contentChanges": [change],
                    },
                )
                pub = await asyncio.wait_for(fut, 600)
                s.edits.append(pub.at - t0)
        if s.edits:
            s.edit_cpu = (cpu_seconds(client.pid) - cpu0) / len(s.edits)

        latest = client.latest(doc.uri)
        diags = latest.diagnostics if latest else []
        whole = {"start": {"line": 0, "character": 0}, "end": _position(doc.text, len(doc.text))}
        target = None
        if doc.bad_name is not None:
            start = _position(doc.text, doc.bad_name[0])
            target = next((d for d in diags if d["range"]["start"] == start), None)
        for _ in range(requests):
            if target is not None:
                s.quick_fix.append(
                    await _action(client, doc.uri, target["range"], [target], ["quickfix"])
                )
            s.fix_all.append(await _action(client, doc.uri, whole, [], ["source.fixAll.bt-lsp"]))
            _, seconds = await client.request_timed(
                "textDocument/hover",
                {
                    "textDocument": {"uri": doc.uri},
                    "position": _position(doc.text, doc.hover_offset),
                },
            )
            s.hover.append(seconds)
        s.rss_end = rss_kib(client.pid)
        s.hwm = rss_kib(client.pid, "VmHWM")
    finally:
        await client.close()
    return s


async def _warm_up(client: LspClient, uri: str, diags: list[dict[str, Any]]) -> None:
    at = TINY.index('"T 1"') + 1
    rng = {"start": _position(TINY, at), "end": _position(TINY, at + 3)}
    await client.request(
        "textDocument/hover", {"textDocument": {"uri": uri}, "position": rng["start"]}
    )
    named = [d for d in diags if d["range"] == rng]
    await _action(client, uri, rng, named, ["quickfix"])
    whole = {"start": _position(TINY, 0), "end": _position(TINY, len(TINY))}
    await _action(client, uri, whole, [], ["source.fixAll.bt-lsp"])


async def _action(
    client: LspClient, uri: str, rng: dict[str, Any], diags: list[Any], only: list[str]
) -> float:
    """``codeAction`` then ``codeAction/resolve`` of its preferred (or first) action."""
    actions, t1 = await client.request_timed(
        "textDocument/codeAction",
        {
            "textDocument": {"uri": uri},
            "range": rng,
            "context": {"diagnostics": diags, "only": only},
        },
    )
    if not actions:
        raise RuntimeError(f"no code action for {only} at {rng}")
    action = next((a for a in actions if a.get("isPreferred")), actions[0])
    if "edit" in action:
        return t1
    resolved, t2 = await client.request_timed("codeAction/resolve", action)
    if not resolved.get("edit"):
        raise RuntimeError(f"codeAction/resolve gave no edit for {action.get('title')}")
    return t1 + t2


# -- lxml and the check command -------------------------------------------------------------


def lxml_parse_seconds(data: bytes) -> float:
    from lxml import etree

    gc.collect()
    t0 = time.perf_counter()
    tree = etree.fromstring(data)
    t1 = time.perf_counter()
    del tree
    return t1 - t0


# The least any Python analysis must do: visit every tag and read every attribute's name,
# value and offset once (C regular expressions, one tuple per attribute, an element stack),
# with no name rule, model or semantic check.  It bounds what a pure-Python first analysis
# can reach against lxml's C parser.
_FLOOR_TOKEN = re.compile(
    r"<([^ \t\r\n/>=<\"']+)((?:[ \t\r\n]+[^ \t\r\n/>=<\"']+[ \t\r\n]*=[ \t\r\n]*"
    r"(?:\"[^\"<]*\"|'[^'<]*'))*)[ \t\r\n]*(/?)>|</([^ \t\r\n/>=<\"']+)[ \t\r\n]*>|[^<]+"
    r"|<!--.*?-->|<[?!][^>]*>",
    re.S,
)
_FLOOR_ATTR = re.compile(
    r"[ \t\r\n]+([^ \t\r\n/>=<\"']+)[ \t\r\n]*=[ \t\r\n]*(?:\"([^\"<]*)\"|'([^'<]*)')"
)


def floor_pass(text: str) -> tuple[int, int]:
    """The minimal pass over ``text`` (see above); returns the elements and attributes
    it read."""
    stack: list[tuple[str, int, list[tuple[str, str, int]]]] = []
    elements = attributes = 0
    for m in _FLOOR_TOKEN.finditer(text):
        name, attrs, empty, end = m.group(1, 2, 3, 4)
        if name:
            found = [
                (a.group(1), a.group(2) or a.group(3) or "", a.start(1))
                for a in _FLOOR_ATTR.finditer(attrs)
            ]
            elements += 1
            attributes += len(found)
            if not empty:
                stack.append((name, m.start(), found))
        elif end and stack:
            stack.pop()
    return elements, attributes


def python_floor_seconds(text: str) -> float:
    """The time of :func:`floor_pass` over ``text``."""
    gc.collect()
    gc.disable()
    t0 = time.perf_counter()
    floor_pass(text)
    t1 = time.perf_counter()
    gc.enable()
    return t1 - t0


# The phases of a first analysis, as the server runs them on open (each one's result is
# kept on the document and used by the next).
PHASES = (
    "early names",
    "scan",
    "model",
    "own diagnostics",
    "workspace context",
    "semantic rules",
)


def open_publications(text: str) -> int:
    """How many publications the open of ``text`` makes: from ``EARLY_NAMES_CHARS`` on,
    the name diagnostics first (unless that pass gives up on the text), then the complete
    set."""
    from bt_lsp.rules.early_names import early_name_diagnostics
    from bt_lsp.server.publishing import EARLY_NAMES_CHARS

    early = len(text) >= EARLY_NAMES_CHARS and early_name_diagnostics(text) is not None
    return 2 if early else 1


def phase_seconds(text: str, path: Path) -> dict[str, float]:
    """One first analysis of ``text`` (as if opened at ``path``, in its folder), in the
    benchmark process, timed by phase: where the time of an open goes, without the
    protocol (reading the JSON, converting positions, writing the diagnostics).  The
    first phase is the pass whose name diagnostics a large document's open publishes
    first (:mod:`bt_lsp.rules.early_names`); the others make the complete set."""
    from bt_lsp.project.index import ProjectIndex
    from bt_lsp.rules import semantics
    from bt_lsp.rules.diagnostics import own_diagnostics
    from bt_lsp.rules.early_names import early_name_diagnostics
    from bt_lsp.server import GC_THRESHOLD
    from bt_lsp.syntax.document import Document

    ws = ProjectIndex([str(path.parent)])
    gc.collect()
    threshold = gc.get_threshold()
    gc.set_threshold(GC_THRESHOLD, 10, 10)  # as the server does (bt_lsp.server.serve)
    try:
        t_early = time.perf_counter()
        early_name_diagnostics(text)
        t0 = time.perf_counter()
        doc = Document(text, str(path))
        t1 = time.perf_counter()
        doc.model  # noqa: B018 (built when first asked for)
        t2 = time.perf_counter()
        own_diagnostics(doc)
        t3 = time.perf_counter()
        ws.open(path, doc)
        ctx = ws.context_for(path, doc)
        t4 = time.perf_counter()
        semantics.check(doc, ctx)
        t5 = time.perf_counter()
    finally:
        gc.set_threshold(*threshold)
    times = (t0 - t_early, t1 - t0, t2 - t1, t3 - t2, t4 - t3, t5 - t4)
    return dict(zip(PHASES, times, strict=True))


def corpus_files(corpus: Path) -> list[Path]:
    return sorted(p for p in corpus.rglob("*.xml") if p.is_file())


def lxml_corpus_seconds(files: list[Path]) -> float:
    from lxml import etree

    datas = [p.read_bytes() for p in files]
    parser = etree.XMLParser(recover=True)
    gc.collect()
    t0 = time.perf_counter()
    for d in datas:
        etree.fromstring(d, parser)
    return time.perf_counter() - t0


def check_seconds(corpus: Path) -> float:
    t0 = time.perf_counter()
    subprocess.run(
        [sys.executable, "-m", "bt_lsp", "check", str(corpus), "--no-progress"],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        check=False,
    )
    return time.perf_counter() - t0


# -- the run --------------------------------------------------------------------------------


def machine() -> dict[str, str]:
    cpu = platform.processor() or ""
    try:
        with open("/proc/cpuinfo", encoding="utf-8") as f:
            for line in f:
                if line.startswith("model name"):
                    cpu = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    load = ""
    with contextlib.suppress(OSError):
        load = " ".join(f"{x:.1f}" for x in os.getloadavg())
    return {
        "cpus": str(os.cpu_count()),
        "cpu": cpu,
        "python": platform.python_version(),
        "platform": platform.platform(),
        "load": load,
    }


async def run(args: argparse.Namespace) -> dict[str, Any]:
    results: dict[str, Any] = {"machine": machine(), "sizes": {}}
    with tempfile.TemporaryDirectory(prefix="bt-lsp-bench-") as tmp:
        folder = Path(tmp)
        root = path_uri(folder)
        startups: list[float] = []
        bare: list[float] = []
        for size in args.sizes:
            doc = make_doc(size, folder, args.edits, args.seed)
            lx: list[float] = []
            floor: list[float] = []
            phases: list[dict[str, float]] = []
            sessions: list[Session] = []
            for r in range(args.repeat):
                # Interleave everything, so that a busy moment of the machine hits all.
                lx.extend(lxml_parse_seconds(doc.text.encode()) for _ in range(3))
                bare.append(await startup_only(BARE, root))
                s = await session(doc, root, requests=args.requests)
                sessions.append(s)
                startups.append(s.startup)
                lx.append(lxml_parse_seconds(doc.text.encode()))
                floor.append(python_floor_seconds(doc.text))
                phases.append(phase_seconds(doc.text, doc.path))
                print(
                    f"  {doc.size} bytes, run {r + 1}/{args.repeat}: open {ms(s.open)} ms, "
                    f"edit {ms(statistics.median(s.edits))} ms, lxml "
                    f"{ms(statistics.median(lx))} ms",
                    file=sys.stderr,
                )
            results["sizes"][str(size)] = _size_result(doc, lx, floor, phases, sessions)
        results["startup"] = {"bt-lsp": summary(startups), "bare pygls": summary(bare)}
        results["startup"]["samples"] = {"bt-lsp": startups, "bare pygls": bare}
        if args.corpus and not args.no_check:
            files = corpus_files(args.corpus)
            lxc: list[float] = []
            chk: list[float] = []
            for _ in range(args.repeat):
                lxc.append(lxml_corpus_seconds(files))
                chk.append(check_seconds(args.corpus))
            results["check"] = {
                "corpus": str(args.corpus),
                "files": len(files),
                "bytes": sum(p.stat().st_size for p in files),
                "check": summary(chk),
                "lxml": summary(lxc),
                "samples": {"check": chk, "lxml": lxc},
            }
    return results


def _size_result(
    doc: Doc,
    lx: list[float],
    floor: list[float],
    phases: list[dict[str, float]],
    sessions: list[Session],
) -> dict[str, Any]:
    def cat(get: Callable[[Session], list[float]]) -> list[float]:
        return [x for s in sessions for x in get(s)]

    samples = {
        "lxml": lx,
        "python floor": floor,
        "open": [s.open for s in sessions],
        "open complete": [s.open_complete for s in sessions],
        "edit": cat(lambda s: s.edits),
        "quick fix": cat(lambda s: s.quick_fix),
        "fix-all": cat(lambda s: s.fix_all),
        "hover": cat(lambda s: s.hover),
        **{f"phase: {k}": [p[k] for p in phases] for k in PHASES},
    }
    kib = 1024
    return {
        "bytes": doc.size,
        "diagnostics": sessions[-1].diagnostics,
        **{k: summary(v) for k, v in samples.items()},
        "edit cpu": summary([s.edit_cpu for s in sessions]),
        "memory": {
            "idle": statistics.median(s.rss_idle * kib for s in sessions),
            "after open": statistics.median((s.rss_open - s.rss_idle) * kib for s in sessions),
            "at end": statistics.median((s.rss_end - s.rss_idle) * kib for s in sessions),
            "peak": statistics.median((s.hwm - s.rss_idle) * kib for s in sessions),
        },
        "samples": samples,
    }


# -- the table --------------------------------------------------------------------------------


def _size_label(n: int) -> str:
    if n >= 1024**2 * 0.9:
        return f"{n / 1024**2:.1f} MB".replace(".0 MB", " MB")
    return f"{n / 1024:.0f} KB"


def table(results: dict[str, Any]) -> str:
    sizes = list(results["sizes"].values())
    head = "| | " + " | ".join(_size_label(s["bytes"]) for s in sizes) + " |"
    rows = [head, "|---|" + "---|" * len(sizes)]

    def cell(s: dict[str, Any], key: str, ratio: bool) -> str:
        v = s[key]
        text = f"{ms(v['median'])} / {ms(v['p95'])}"
        if ratio:
            text += f" ({v['median'] / s['lxml']['median']:.2f}×)"
        return text

    rows.append(
        "| lxml parses the document once (ms) | "
        + " | ".join(cell(s, "lxml", False) for s in sizes)
        + " |"
    )
    for key, label, ratio in (
        ("python floor", "Python reads every tag and attribute once, no rules (ms, × lxml)", True),
        ("open", "open → first diagnostics (ms, × lxml)", True),
        ("open complete", "open → complete diagnostics (ms, × lxml)", True),
        ("edit", "1-character edit → its diagnostics (ms, × lxml)", True),
        ("quick fix", "quick fix: codeAction + resolve (ms)", False),
        ("fix-all", "fix-all: codeAction + resolve (ms)", False),
        ("hover", "hover (ms)", False),
    ):
        rows.append(f"| {label} | " + " | ".join(cell(s, key, ratio) for s in sizes) + " |")
    # Where the time of an open goes (in the benchmark process, without the protocol).
    for key in PHASES:
        rows.append(
            f"| open, phase: {key} (ms, × lxml) | "
            + " | ".join(cell(s, f"phase: {key}", True) for s in sizes)
            + " |"
        )
    rows.append(
        "| server CPU per edit (ms) | "
        + " | ".join(f"{ms(s['edit cpu']['median'])}" for s in sizes)
        + " |"
    )
    rows.append(
        "| memory above idle after open / at end / peak (× document) | "
        + " | ".join(
            " / ".join(
                f"{s['memory'][k] / s['bytes']:.1f}" for k in ("after open", "at end", "peak")
            )
            for s in sizes
        )
        + " |"
    )
    out = ["\n".join(rows), ""]
    st = results["startup"]
    extra = st["bt-lsp"]["median"] - st["bare pygls"]["median"]
    out.append(
        f"Start to `initialize` result: bt-lsp {ms(st['bt-lsp']['median'])} / "
        f"{ms(st['bt-lsp']['p95'])} ms, a bare pygls server {ms(st['bare pygls']['median'])} / "
        f"{ms(st['bare pygls']['p95'])} ms ({extra * 1000:+.0f} ms)."
    )
    if "check" in results:
        c = results["check"]
        out.append(
            f"`bt-lsp check` over {c['files']} files ({c['bytes'] / 1024:.0f} KB): "
            f"{ms(c['check']['median'])} / {ms(c['check']['p95'])} ms; lxml parses them in "
            f"{ms(c['lxml']['median'])} / {ms(c['lxml']['p95'])} ms "
            f"({c['check']['median'] / c['lxml']['median']:.0f}×, the check includes "
            "starting Python)."
        )
    m = results["machine"]
    out.append(
        f"Machine: {m['cpus']} CPUs, {m['cpu']}, Python {m['python']}; load average at the "
        f"end {m['load']}. Figures are median / p95."
    )
    return "\n".join(out)


def targets(results: dict[str, Any]) -> list[tuple[str, bool, str]]:
    """The issue's targets: (what, met, numbers)."""
    out: list[tuple[str, bool, str]] = []
    by = {int(k): v for k, v in results["sizes"].items()}

    def near(mib: int) -> dict[str, Any] | None:
        return next((v for k, v in by.items() if 0.9 <= k / (mib * 1024**2) <= 1.1), None)

    one, four = near(1), near(4)
    if one is not None:
        e, lx, o = one["edit"]["median"], one["lxml"]["median"], one["open"]["median"]
        out.append(("1 MB edit < lxml parse", e < lx, f"{ms(e)} vs {ms(lx)} ms"))
        out.append(("1 MB open → first diagnostics ≤ 5× lxml", o <= 5 * lx, f"{o / lx:.1f}×"))
        for v, name in ((one, "1 MB"), (four, "4 MB")):
            if v is not None:
                used = v["memory"]["at end"] / v["bytes"]
                out.append((f"{name} memory ≤ 20× document", used <= 20, f"{used:.1f}×"))
        if four is not None:
            for key in ("open", "open complete", "edit"):
                r = four[key]["median"] / one[key]["median"]
                out.append((f"4 MB {key} ≤ 4.5× 1 MB", r <= 4.5, f"{r:.2f}×"))
    st = results["startup"]
    extra = st["bt-lsp"]["median"] - st["bare pygls"]["median"]
    out.append(("start ≤ bare pygls + 150 ms", extra <= 0.150, f"{extra * 1000:+.0f} ms"))
    return out


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument(
        "--sizes",
        default="60K,1M,4M",
        type=lambda s: [parse_size(x) for x in s.split(",") if x.strip()],
        help="document sizes (default: %(default)s)",
    )
    parser.add_argument("--repeat", type=int, default=5, help="server sessions per size")
    parser.add_argument("--edits", type=int, default=20, help="places typed at per session")
    parser.add_argument("--requests", type=int, default=5, help="of each request per session")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument(
        "--corpus", type=Path, default=DEFAULT_CORPUS if DEFAULT_CORPUS.is_dir() else None
    )
    parser.add_argument("--no-check", action="store_true", help="skip `bt-lsp check`")
    parser.add_argument("--json", type=Path, help="write every sample here")
    args = parser.parse_args(argv)
    results = asyncio.run(run(args))
    print(table(results))
    print()
    for what, met, numbers in targets(results):
        print(f"- {'met' if met else 'NOT met'}: {what} ({numbers})")
    if args.json:
        args.json.write_text(json.dumps(results, indent=1), encoding="utf-8")
    return 0


if __name__ == "__main__":
    sys.exit(main())
