"""The benchmark's parts work: the generator writes the intended XML, the client drives the
real server, and the runner produces its table.  Correctness only, never timings."""

from __future__ import annotations

import asyncio
import importlib.util
import json
import re
import sys
from collections import Counter
from pathlib import Path
from typing import Any

import pytest
from lxml import etree

from bt_lsp.rules.analysis import analyze
from bt_lsp.rules.names import PROJECT_NAME_CODES
from bt_lsp.syntax.document import Document

BENCH = Path(__file__).resolve().parent.parent / "benchmarks"
sys.path.insert(0, str(BENCH))

import generate as bench_generate  # noqa: E402
import lsp_client as bench_client  # noqa: E402
import run as bench_run  # noqa: E402


@pytest.mark.parametrize("size", [3_000, 40_000, 300_000])
def test_generated_xml_parses_and_has_exactly_the_planted_bad_names(size: int) -> None:
    g = bench_generate.generate(size, seed=7)
    assert g.text == bench_generate.generate(size, seed=7).text  # deterministic
    root = etree.fromstring(g.text.encode())
    assert root.tag == "root"
    assert len(root.findall("BehaviorTree")) == g.trees
    if size >= 40_000:
        assert abs(len(g.text) - size) < size * 0.05

    diags = analyze(Document(g.text))
    named = Counter((d.code, g.text[d.start : d.end]) for d in diags if d.is_name_rule)
    assert named == Counter({(p.code, p.name): p.count for p in g.planted})
    assert {p.code for p in g.planted} >= {
        "model-name-forbidden-char",
        "port-name-forbidden-char",
        "port-name-reserved-groot2",
    }
    # Apart from the planted names the document is clean.
    assert [d for d in diags if not d.is_name_rule] == []


def test_python_floor_reads_every_element_and_attribute() -> None:
    g = bench_generate.generate(40_000, seed=3)
    root = etree.fromstring(g.text.encode())
    elements = [e for e in root.iter() if isinstance(e.tag, str)]
    assert bench_run.floor_pass(g.text) == (len(elements), sum(len(e.attrib) for e in elements))
    assert bench_run.python_floor_seconds(g.text) > 0


def test_phases_time_a_whole_first_analysis(tmp_path: Path) -> None:
    g = bench_generate.generate(20_000, seed=3)
    path = tmp_path / "doc.xml"
    path.write_text(g.text, encoding="utf-8")
    phases = bench_run.phase_seconds(g.text, path)
    assert list(phases) == list(bench_run.PHASES)
    assert all(t > 0 for t in phases.values())


def test_generator_command_line(tmp_path: Path) -> None:
    out = tmp_path / "g.xml"
    assert bench_generate.main(["12K", str(out), "--seed", "2"]) == 0
    assert out.read_text(encoding="utf-8") == bench_generate.generate(12 * 1024, 2).text


def _document(tmp_path: Path, text: str) -> str:
    """The URI of ``text`` written to a file in ``tmp_path``."""
    path = tmp_path / "doc.xml"
    path.write_text(text, encoding="utf-8")
    return bench_client.path_uri(path)


def _open(client: bench_client.LspClient, uri: str, text: str) -> None:
    client.notify(
        "textDocument/didOpen",
        {"textDocument": {"uri": uri, "languageId": "xml", "version": 1, "text": text}},
    )


async def test_client_drives_the_server(tmp_path: Path) -> None:
    g = bench_generate.generate(3_000, seed=5)
    uri = _document(tmp_path, g.text)
    client = await bench_client.LspClient.start(bench_run.SERVER)
    try:
        result, seconds = await client.initialize(
            bench_client.path_uri(tmp_path), {"debounceMs": 0}
        )
        assert "capabilities" in result and seconds > 0
        assert bench_client.rss_kib(client.pid) > 0

        fut = client.expect_diagnostics(uri, 1)
        _open(client, uri, g.text)
        first = await fut
        expected: Counter[str] = Counter()
        for p in g.planted:
            expected[p.code] += p.count
        assert Counter(d["code"] for d in first.diagnostics) == expected

        # An edit that breaks the main tree's name: the diagnostics of version 2 say so.
        at = g.text.index('main_tree_to_execute="') + len('main_tree_to_execute="')
        pos = bench_run._position(g.text, at)
        fut = client.expect_diagnostics(uri, 2)
        client.notify(
            "textDocument/didChange",
            {
                "textDocument": {"uri": uri, "version": 2},
                "contentChanges": [{"range": {"start": pos, "end": pos}, "text": "x"}],
            },
        )
        second = await fut
        assert second.version == 2
        assert "unknown-main-tree" in {d["code"] for d in second.diagnostics}
    finally:
        await client.close()
    assert client.proc.returncode is not None


async def test_a_large_open_publishes_names_first_then_the_complete_set(tmp_path: Path) -> None:
    g = bench_generate.generate(300_000, seed=5)
    uri = _document(tmp_path, g.text)
    client = await bench_client.LspClient.start(bench_run.SERVER)
    try:
        await client.initialize(bench_client.path_uri(tmp_path), {"debounceMs": 0})
        first = client.expect_diagnostics(uri, 1)
        _open(client, uri, g.text)
        names = await first
        assert bench_run.open_publications(g.text) == 2  # what the runner waits for
        complete = await client.published_count(uri, 2)
        assert client.counts[uri] == 2 and complete.at >= names.at
        # Only names are planted; the early pass leaves those that depend on the project
        # (a declared port's reserved name) to the complete set.
        assert [
            d for d in complete.diagnostics if d["code"] not in PROJECT_NAME_CODES
        ] == names.diagnostics
        expected: Counter[str] = Counter()
        for p in g.planted:
            expected[p.code] += p.count
        assert Counter(d["code"] for d in complete.diagnostics) == expected
        assert any(d["code"] in PROJECT_NAME_CODES for d in complete.diagnostics)
        never = client.expect_diagnostics("untitled:never-opened.xml", 1)
    finally:
        await client.close()
    # Closing gives up on what nobody will see, without a failed future to be logged.
    assert never.cancelled()
    assert bench_run.open_publications(bench_generate.generate(4_000, seed=5).text) == 1


def test_runner_table_and_json(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "r.json"
    args = ["--sizes", "4K", "--repeat", "1", "--edits", "2", "--requests", "1"]
    assert bench_run.main([*args, "--no-check", "--json", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "| open → first diagnostics" in printed and "Start to `initialize`" in printed
    assert "| open → complete diagnostics" in printed
    assert "| Python reads every tag" in printed
    for phase in bench_run.PHASES:
        assert f"| open, phase: {phase} (ms, × lxml) |" in printed
    results = json.loads(out.read_text(encoding="utf-8"))
    (size,) = results["sizes"].values()
    samples = size["samples"]
    assert len(samples["open"]) == 1 and len(samples["edit"]) == 4
    assert samples["open complete"][0] >= samples["open"][0]
    assert len(samples["quick fix"]) == len(samples["fix-all"]) == len(samples["hover"]) == 1
    assert all(x > 0 for v in samples.values() for x in v)
    assert size["diagnostics"] > 0 and size["memory"]["idle"] > 0
    assert results["startup"]["samples"]["bare pygls"]


def test_runner_checks_a_corpus(tmp_path: Path) -> None:
    (tmp_path / "a.xml").write_text(bench_generate.generate(2_000, 1).text, encoding="utf-8")
    files = bench_run.corpus_files(tmp_path)
    assert len(files) == 1
    assert bench_run.lxml_corpus_seconds(files) > 0
    assert bench_run.check_seconds(tmp_path) > 0


def test_soak_runs_a_short_session(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    import soak as bench_soak  # type: ignore[import-not-found]

    out = tmp_path / "soak.json"
    assert bench_soak.main(["--size", "4K", "--edits", "10", "--json", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "10 edits and 12 requests" in printed and "server RSS:" in printed
    result = json.loads(out.read_text(encoding="utf-8"))
    assert result["edits"] == 10 and result["rss_start_kib"] > 0 and result["rss_end_kib"] > 0
    assert set(result["request_ms"]) == set(bench_soak.REQUESTS)
    assert all(s["p50"] > 0 for s in result["request_ms"].values())


def test_scale_times_the_outline_and_a_publication(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    import scale as bench_scale  # type: ignore[import-not-found]

    out = tmp_path / "scale.json"
    argv = ["--sizes", "6K", "--repeat", "2", "--edits", "4", "--publication-size", "30K"]
    assert bench_scale.main([*argv, "--json", str(out)]) == 0
    assert "documentSymbol (ms):" in capsys.readouterr().out
    result = json.loads(out.read_text(encoding="utf-8"))
    (outline,) = result["outline"]
    assert outline["symbols"] > 10 and outline["after_edit_ms"]["p50"] > 0
    # The document of the publication is full of port problems, as intended.
    publication = result["publication"]
    assert publication["edits"] == 4 and publication["diagnostics"] > 50
    assert publication["edit_ms"]["p50"] > 0


def _bench_module(name: str) -> Any:
    """A benchmark script as a module of its own name (``requests.py`` would otherwise be
    shadowed by, or shadow, the HTTP library of that name)."""
    spec = importlib.util.spec_from_file_location(f"bench_{name}", BENCH / f"{name}.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_requests_benchmark_runs_each_measurement(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    bench_requests = _bench_module("requests")
    # The same shapes as the benchmark's, small: a document past the size that is prepared
    # on the worker thread, with one unknown node, and a script of 2,000 statements.
    realistic = bench_generate.generate(300_000, seed=1).text.replace(
        "</BehaviorTree>", "<Frob/></BehaviorTree>", 1
    )
    script = (
        '<root BTCPP_format="4">\n<BehaviorTree ID="T">\n<Script code="'
        + "".join(f"a{i}:=1; " for i in range(2_000))
        + '"/><Frob/></BehaviorTree>\n</root>\n'
    )
    monkeypatch.setattr(
        bench_requests, "INPUTS", {"realistic": lambda: realistic, "script": lambda: script}
    )
    assert bench_requests.main([]) == 0
    printed = capsys.readouterr().out
    assert "open → outline answered:" in printed and "RSS peak:" in printed
    # The key a1000 is written once: its references are that one use.
    assert re.search(r"v3 textDocument/references: \d+ ms \(1 results\)", printed), printed
    assert re.search(r"v3 textDocument/hover: \d+ ms \(1 results\)", printed), printed
    for name in ("outline", "folding", "hover"):
        assert f"open → {name}:" in printed


def test_hostile_measures_an_input() -> None:
    bench_hostile = _bench_module("hostile")
    text = bench_hostile._sequence("<Frob/>" * 2_000)
    result = asyncio.run(bench_hostile.measure("small", text))
    assert result["size"] == len(text)
    assert result["diagnostics_s"] > 0 and result["hover_s"] > 0 and result["rss_peak_mib"] > 0


def test_folder_check_writes_small_trees_that_call_each_other(tmp_path: Path) -> None:
    folder_check = _bench_module("folder_check")
    folder_check.write_folder(tmp_path, 20)
    files = sorted(tmp_path.glob("tree_*.xml"))
    assert len(files) == 20
    called = set()
    for f in files:
        root = etree.fromstring(f.read_bytes())
        assert root.tag == "root" and root.findall("BehaviorTree")
        called |= {s.get("ID", "") for s in root.iter("SubTree")}
    assert called and all(re.fullmatch(r"Task\d+_0", c) for c in called)
    assert (
        etree.fromstring((tmp_path / "models.xml").read_bytes()).find("TreeNodesModel") is not None
    )


def test_live_latency_matches_each_change_with_its_logged_transition(tmp_path: Path) -> None:
    """The live benchmark's arithmetic: a status a notification reports changed is timed
    from the executor's transition of that node to it; the first notification is the
    baseline, an IDLE is not timed, a status the log never had is counted unmatched."""
    import struct

    import live_latency

    start = 1_700_000_000_000_000
    xml = (
        b'<root BTCPP_format="4"><BehaviorTree ID="Main" _fullpath="">'
        b'<Sequence name="all" _uid="1"><Sleep name="a" _uid="2"/><Sleep name="b" _uid="3"/>'
        b"</Sequence></BehaviorTree></root>"
    )

    def rec(us: int, uid: int, status: int) -> bytes:
        return us.to_bytes(6, "little") + uid.to_bytes(2, "little") + bytes([status])

    log = tmp_path / "run.btlog"
    head = b"BTCPP4-FileLogger2\x01" + struct.pack("<i", len(xml)) + xml
    log.write_bytes(
        head + struct.pack("<q", start) + rec(0, 1, 1) + rec(0, 2, 1) + rec(40_000, 2, 2)
        + rec(40_000, 3, 1)
    )  # fmt: skip
    t0 = start / 1e6

    def note(at: float, a: str, b: str) -> tuple[float, dict[str, Any]]:
        statuses = {1: "running", 2: a, 3: b}
        return t0 + at, {"nodes": [{"uid": u, "status": s} for u, s in statuses.items()]}

    notes = [note(0.01, "running", "idle"), note(0.1, "success", "running"),
             note(0.2, "success", "failure")]  # fmt: skip
    lat, matched, unmatched = live_latency._latencies(notes, log)
    assert matched == 2 and unmatched == 1  # b never failed in the log
    assert [round(x, 3) for x in lat] == [0.06, 0.06]
