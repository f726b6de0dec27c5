"""The `bt` debugger in a real VS Code (code-server driven by headless Chromium) against a
real BehaviorTree.CPP 4.8.2 executor (behaviortreepy) with a Groot2 publisher: a gutter
breakpoint (F9) on a node of a SubTree, F5 with the workspace's launch.json; VS Code stops
there (debug toolbar, the line highlighted, the Call Stack from the node up through the
SubTree call to the root, the stop's reason); the Variables view shows the blackboards and
the main tree's ``counter``; selecting the main tree's frame shows its blackboard; "bt-lsp:
Fail node" makes the tree fail once, Continue lets it succeed; stopping the debugger leaves
no hook (the tree runs on). Then a breakpoint set before the executor starts: pending while
there is none, verified and stopping once it runs.

Needs what tests/e2e/test_vscode.py needs (`editors/vscode/e2e/setup.sh`). The driver
(editors/vscode/e2e/debug.js) starts the executors itself (tests/live/executor.py) to read
their result lines as they come. Screenshots go to `.e2e-artifacts/vscode/debug*.png`.
"""

from __future__ import annotations

import json
import shutil
import sys
from pathlib import Path
from typing import Any

import pytest

from tests.e2e.test_vscode import (
    ARTIFACTS,
    EXT_DIR,
    SETUP,
    CodeServer,
    _code_server,
    _missing_setup,
    run_driver,
)

pytest.importorskip("behaviortreepy")
pytest.importorskip("zmq")

from tests.live.harness import EXECUTOR, free_port

pytestmark = pytest.mark.e2e

DRIVER = EXT_DIR / "e2e" / "debug.js"
DRIVER_TIMEOUT_S = 420
EXECUTOR_LIFETIME_S = 400.0  # the driver ends them before; a bound if the test is killed

# What the executor runs is this file. Failing "stop" fails the Dock Sequence, the SubTree and
# so the whole tree; its Sleep gives the publisher's subscriber time to see each stop.
MISSION = """\
<root BTCPP_format="4" main_tree_to_execute="Mission">
  <BehaviorTree ID="Mission">
    <Sequence name="mission">
      <Script code="counter := counter + 1"/>
      <SubTree ID="Dock" name="dock"/>
      <AlwaysSuccess name="report"/>
    </Sequence>
  </BehaviorTree>
  <BehaviorTree ID="Dock">
    <Sequence name="docking">
      <Script code="aligned := true"/>
      <Sleep msec="50" name="align"/>
      <AlwaysSuccess name="stop"/>
    </Sequence>
  </BehaviorTree>
</root>
"""
LINES = MISSION.splitlines()
LINE = 1 + next(i for i, t in enumerate(LINES) if 'name="stop"' in t)
# The Call Stack: the node, then each node above it through the SubTree call (file and line).
FRAMES = [
    ('AlwaysSuccess "stop"', LINE),
    ('Sequence "docking"', 1 + next(i for i, t in enumerate(LINES) if 'name="docking"' in t)),
    ('SubTree "dock" -> Dock', 1 + next(i for i, t in enumerate(LINES) if 'name="dock"' in t)),
    ('Sequence "mission"', 1 + next(i for i, t in enumerate(LINES) if 'name="mission"' in t)),
]


def test_vscode_debugger_breakpoints(tmp_path: Path) -> None:
    missing = _missing_setup()
    if missing:
        pytest.fail(
            f"the VS Code e2e setup is missing: {', '.join(missing)}. Run `bash {SETUP}` first.",
            pytrace=False,
        )
    assert DRIVER.exists(), DRIVER
    port = free_port()
    with _code_server(tmp_path, {"mission.xml": MISSION}) as code_server:
        launch = {
            "version": "0.2.0",
            "configurations": [
                {
                    "type": "bt",
                    "request": "attach",
                    "name": "Attach to the mission",
                    "host": "127.0.0.1",
                    "port": port,
                }
            ],
        }
        (code_server.workspace / ".vscode").mkdir()
        (code_server.workspace / ".vscode" / "launch.json").write_text(json.dumps(launch))
        result, context = _drive(code_server, tmp_path, port)
    _check(result, context, port)


def _drive(code_server: CodeServer, tmp_path: Path, port: int) -> tuple[dict[str, Any], str]:
    shots = tmp_path / "shots"
    shots.mkdir()
    tree = code_server.workspace / "mission.xml"
    config = {
        "url": code_server.url,
        "file": "mission.xml",
        "line": LINE,
        "mainTree": "Mission",
        "mainFrame": FRAMES[-1][0],
        "executor": [sys.executable, str(EXECUTOR), str(port), str(EXECUTOR_LIFETIME_S), str(tree)],
        "shotDir": str(shots),
        "chromium": shutil.which("chromium"),
        "stepTimeoutMs": 60000,
        "serverTimeoutMs": 120000,
    }
    return run_driver(code_server, DRIVER, config, "debug", DRIVER_TIMEOUT_S, keep=8000)


def _check_stop(stop: dict[str, Any], context: str) -> int:
    """A stop at LINE as VS Code shows it; returns the counter it showed."""
    assert stop["toolbar"] == {"continue": True, "pause": False}, context
    glyphs = {g["line"]: g["icons"] for g in stop["glyphs"]}
    assert set(glyphs) == {LINE}, context
    assert "codicon-debug-breakpoint" in glyphs[LINE], context  # verified
    assert "codicon-debug-stackframe" in glyphs[LINE], context
    assert stop["topFrame"] == [LINE], context
    assert any("before AlwaysSuccess" in t for t in stop["callStackTitle"]), context
    frames = stop["callStack"]
    assert len(frames) == len(FRAMES), context
    for frame, (name, line) in zip(frames, FRAMES, strict=True):
        assert frame.startswith(f"Stack Frame {name} #"), context
        assert frame.endswith(f", line {line}, mission.xml"), context
    # The node's own tree's blackboard first (Dock's, with its entry), then all of them.
    variables = stop["variables"]
    assert variables[:2] == ["Scope Blackboard dock", "aligned, value 1"], context
    assert "Scope All blackboards" in variables, context
    assert f"counter, value {stop['counter']}" in variables, context
    counter: int = stop["counter"]
    return counter


def _results(lines: list[dict[str, Any]]) -> list[str]:
    return [x["line"] for x in lines if x["line"].startswith("result ")]


def _check(result: dict[str, Any], context: str, port: int) -> None:
    # F9 put a breakpoint on the line (before any session: a plain breakpoint).
    assert {g["line"] for g in result["breakpointSet"]["glyphs"]} == {LINE}, context

    # F5 attached with launch.json and stopped at the node, before it ticked.
    first = _check_stop(result["stopped"], context)
    assert first > 0, context
    assert (
        f"bt-lsp: attached to the executor at 127.0.0.1:{port}: tree Mission, 8 nodes"
        in (result["console"])
    ), context
    # The tree waited there: no result while stopped.
    assert result["whileStopped"] == [], context

    # The main tree's frame selected: its line highlighted, its blackboard first.
    main = result["mainFrame"]
    assert main["focusedFrame"] == [FRAMES[-1][1]], context
    assert main["variables"][:2] == ["Scope Blackboard Mission", f"counter, value {first}"], context

    # "bt-lsp: Fail node": "stop" fails, so does the tree; it runs again and stops again.
    assert result["afterFail"]["line"] == "result FAILURE", context
    again = _check_stop(result["stoppedAfterFail"], context)
    assert again == first + 1, context

    # Continue: "stop" ticks and succeeds, so does the tree; then the next stop.
    assert result["afterContinue"]["line"] == "result SUCCESS", context
    assert _check_stop(result["stoppedAfterContinue"], context) == again + 1, context

    # Shift+F5: no session, no stop; every hook removed, so the tree runs on and succeeds.
    gone = result["stoppedDebugging"]
    assert gone["toolbar"] is None and gone["topFrame"] == [] and gone["callStack"] == [], context
    assert [g["icons"] for g in gone["glyphs"]] == [["codicon-debug-breakpoint"]], context
    assert set(_results(result["afterStop"])) == {"result SUCCESS"}, context
    assert "bt-lsp: removed every hook; the tree runs on" in result["consoleAfterStop"], context
    # The one failure was the forced one.
    assert result["executors"][0]["printed"].get("result FAILURE") == 1, context

    # F5 with no executor: attached, the breakpoint pending (unverified, with the reason).
    pending = result["pending"]
    assert pending["toolbar"] == {"continue": False, "pause": True}, context
    assert [g["icons"] for g in pending["glyphs"]] == [["codicon-debug-breakpoint-unverified"]], (
        context
    )
    reason = f"pending: waiting for the executor at 127.0.0.1:{port}"
    assert pending["breakpoints"] == [f"mission.xml {LINE}, {reason}"], context
    assert any("waiting for the executor" in x for x in result["pendingConsole"]), context

    # The executor started: the breakpoint verified, and the tree stops there.
    later = result["stoppedLater"]
    _check_stop(later, context)
    assert all("pending" not in b for b in later["breakpoints"]), context

    # Stopped debugging again: the new run goes on.
    assert result["stoppedDebuggingAgain"]["toolbar"] is None, context
    assert set(_results(result["afterStopAgain"])) == {"result SUCCESS"}, context

    assert (ARTIFACTS / "debug.png").stat().st_size > 10_000, context
