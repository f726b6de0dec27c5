"""`:BtLspMonitor` in a real headless Neovim (0.7 and 0.11, as tests/e2e/test_neovim.py finds
them) against a real BehaviorTree.CPP 4.8.2 executor (tests/live/executor.py) running the
file Neovim edits: each node's start tag name gets an extmark in the namespace
"bt_lsp_live" with its status's highlight group and " ● <status>" after the line, the
running Sleep node among them; the executor killed, the marks go and the loss is said;
`:BtLspMonitorStop` ends the session."""

from __future__ import annotations

import json
import shutil
import subprocess
from pathlib import Path

import pytest

pytest.importorskip("behaviortreepy")
pytest.importorskip("zmq")

from tests.e2e.test_neovim import (
    INIT,
    MARK,
    NVIM_DIR,
    RUN_TIMEOUT_S,
    Target,
    _env,
    _find_nvim,
    _workspace,
    target,
)
from tests.live.harness import Executor, free_port

pytestmark = pytest.mark.e2e

__all__ = ["target"]  # the fixture, parametrized over the Neovim versions

DRIVER = NVIM_DIR / "live_driver.lua"

# A Sleep keeps its node (and those above it) RUNNING most of the time; the comment before
# it makes byte columns differ from UTF-16 ones.
TREE = """\
<root BTCPP_format="4" main_tree_to_execute="Main">
  <BehaviorTree ID="Main">
    <Sequence name="seq">
      <Script code="counter := counter + 1"/>
      <!-- ü 😋 --><Sleep msec="300"/>
      <AlwaysSuccess name="ok"/>
    </Sequence>
  </BehaviorTree>
</root>
"""
GROUPS = {
    "BtLspLiveRunning": "running",
    "BtLspLiveSuccess": "success",
    "BtLspLiveFailure": "failure",
    "BtLspLiveIdle": "idle",
    "BtLspLiveSkipped": "skipped",
}


def _name_at(line: str, tag: str) -> tuple[int, int]:
    """The byte columns of the tag's name on its line."""
    start = line.index(tag) + 1
    name = tag[1:].split()[0]
    col = len(line[:start].encode("utf-8"))
    return col, col + len(name.encode("utf-8"))


def test_bt_lsp_monitor(tmp_path: Path, target: Target) -> None:
    nvim = _find_nvim(target)
    ws = _workspace(tmp_path)
    tree = ws / "trees" / "live.xml"
    tree.write_text(TREE, encoding="utf-8")
    port = free_port()
    executor = Executor(port, lifetime=RUN_TIMEOUT_S, tree=tree)
    try:
        env = _env(tmp_path)
        env.setdefault("BT_LSP_E2E_WAIT_MS", "30000")  # a busy machine starts slowly
        env["BT_LSP_E2E_ADDRESS"] = f"127.0.0.1:{port}"
        env["BT_LSP_E2E_EXECUTOR_PID"] = str(executor.proc.pid)
        lines = TREE.splitlines()
        sleep_row = next(i for i, ln in enumerate(lines) if "<Sleep" in ln)
        env["BT_LSP_E2E_LINE"] = str(sleep_row + 1)
        argv = [nvim.path, "--headless", "-u", str(INIT), "-i", "NONE", "-n", str(tree)]
        argv += ["-c", f"lua dofile({json.dumps(str(DRIVER))})"]
        if shutil.which("timeout"):
            argv = ["timeout", "-k", "5", str(RUN_TIMEOUT_S), *argv]
        proc = subprocess.run(
            argv,
            cwd=tree.parent,
            env=env,
            stdin=subprocess.DEVNULL,
            capture_output=True,
            text=True,
            timeout=RUN_TIMEOUT_S + 15,
        )
    finally:
        executor.kill()
    events = {
        e["event"]: e
        for e in (
            json.loads(ln[len(MARK) :]) for ln in proc.stdout.splitlines() if ln.startswith(MARK)
        )
    }
    why = f"exit {proc.returncode}\n--- stdout\n{proc.stdout}\n--- stderr\n{proc.stderr}"
    assert proc.returncode == 0 and "done" in events and "error" not in events, why
    assert events["start"]["mode"] == target.mode, why

    # Every node's tag name is marked, on its line, with its status's group and text.
    marks = events["marks"]["marks"]
    want = {}
    for tag in ('<Sequence name="seq"', "<Script", "<Sleep", "<AlwaysSuccess"):
        row = next(i for i, ln in enumerate(lines) if tag in ln)
        want[row] = _name_at(lines[row], tag)
    got = {m["row"]: (m["col"], m["end_col"]) for m in marks}
    assert got == want, why
    for m in marks:
        assert m["end_row"] == m["row"], why
        assert m["hl_group"] in GROUPS and m["virt_group"] == m["hl_group"], why
        assert m["virt_text"] == f" ● {GROUPS[m['hl_group']]}", why
    by_row = {m["row"]: m["hl_group"] for m in marks}
    assert by_row[sleep_row] == "BtLspLiveRunning", why
    seq_row = next(i for i, ln in enumerate(lines) if "<Sequence" in ln)
    assert by_row[seq_row] == "BtLspLiveRunning", why  # a Sleep's parent runs with it
    links = events["marks"]["links"]
    success = "DiagnosticOk" if target.version >= (0, 9) else "String"
    assert links == {
        "running": "DiagnosticWarn",
        "success": success,
        "failure": "DiagnosticError",
        "idle": "Comment",
        "skipped": "Comment",
    }, why
    messages = events["marks"]["messages"]
    assert "bt-lsp: watching tree Main at 127.0.0.1" in messages, why
    assert "deprecated" not in messages.lower(), why

    # The executor killed: every mark removed, the loss said.
    lost = events["lost"]["last"]
    assert lost["connected"] is False and lost["nodes"] == [], why
    assert "connection lost" in lost["message"], why
    assert "bt-lsp live: connection lost" in events["lost"]["messages"], why

    # :BtLspMonitorStop: no mark left, the last notification says disconnected.
    stopped = events["stopped"]
    assert stopped["marks"] == [], why
    assert stopped["last"]["connected"] is False and stopped["last"]["nodes"] == [], why
    assert stopped["last"]["message"] == "disconnected", why
