""" "bt-lsp: Connect to a Running Tree" in a real VS Code (code-server driven by headless
Chromium) against a real BehaviorTree.CPP 4.8.2 executor (behaviortreepy) with a Groot2
publisher: the address is validated; the Show Tree view colours its nodes with their running
statuses (also when it draws the tree again, after an edit or after another file); the editor
writes each status after its node's tag name (also in a new editor of the file); the status
bar says connected; with the executor killed it says lost and the statuses go; with the
executor started again on the same port it reconnects; disconnecting turns everything off.

Needs what tests/e2e/test_vscode.py needs (`editors/vscode/e2e/setup.sh`). Its screenshot goes
to `.e2e-artifacts/vscode/live.png`; with BT_LSP_E2E_UPDATE_IMAGES=1 also into
`docs/images/live-tree.png` for the README.
"""

from __future__ import annotations

import os
import shutil
import sys
from pathlib import Path

import pytest

from tests.e2e.test_vscode import (
    ARTIFACTS,
    EXT_DIR,
    REPO,
    SETUP,
    CodeServer,
    _code_server,
    _missing_setup,
    run_driver,
)

pytest.importorskip("behaviortreepy")
pytest.importorskip("zmq")

from tests.live.harness import EXECUTOR, Executor, free_port

pytestmark = pytest.mark.e2e

DRIVER = EXT_DIR / "e2e" / "live.js"
DRIVER_TIMEOUT_S = 240
EXECUTOR_LIFETIME_S = 300.0  # the driver ends it before; a bound if the test is killed
DOC_IMAGE = REPO / "docs" / "images" / "live-tree.png"

# What the executor runs is this file: the text and the running tree are the same. The sleeps
# keep nodes RUNNING long enough to be seen at 10 polls a second; AlwaysFailure fails each time.
MISSION = """\
<root BTCPP_format="4" main_tree_to_execute="Mission">
  <BehaviorTree ID="Mission">
    <Sequence name="mission">
      <Script code="counter := counter + 1"/>
      <Fallback name="dock if needed">
        <AlwaysFailure name="is_docked"/>
        <SubTree ID="Dock" name="dock"/>
      </Fallback>
      <Sleep msec="400" name="work"/>
      <AlwaysSuccess name="report"/>
    </Sequence>
  </BehaviorTree>
  <BehaviorTree ID="Dock">
    <Sequence name="docking">
      <Sleep msec="300" name="align"/>
      <AlwaysSuccess name="stop"/>
    </Sequence>
  </BehaviorTree>
</root>
"""
# Another tree file: the Show Tree view follows it, and comes back.
OTHER = """\
<root BTCPP_format="4">
  <BehaviorTree ID="Other">
    <Sequence><AlwaysSuccess/><AlwaysSuccess/></Sequence>
  </BehaviorTree>
</root>
"""
STATUSES = {"idle", "running", "success", "failure", "skipped"}


def test_vscode_live_tree(tmp_path: Path) -> None:
    missing = _missing_setup()
    if missing:
        pytest.fail(
            f"the VS Code e2e setup is missing: {', '.join(missing)}. Run `bash {SETUP}` first.",
            pytrace=False,
        )
    assert DRIVER.exists(), DRIVER
    port = free_port()
    with _code_server(tmp_path, {"mission.xml": MISSION, "other.xml": OTHER}) as code_server:
        tree = code_server.workspace / "mission.xml"
        executor = Executor(port, lifetime=EXECUTOR_LIFETIME_S, tree=tree)
        try:
            result, context = _drive(code_server, tmp_path, port, executor, tree)
        finally:
            executor.kill()
    _check(result, context, port)


def _drive(
    code_server: CodeServer, tmp_path: Path, port: int, executor: Executor, tree: Path
) -> tuple[dict[str, object], str]:
    shots = tmp_path / "shots"
    shots.mkdir()
    config = {
        "url": code_server.url,
        "file": "mission.xml",
        "otherFile": "other.xml",
        "address": f"127.0.0.1:{port}",
        "badAddress": "127.0.0.1:99999",
        "badAddressMessage": "between 1 and 65534",
        "executorPid": executor.proc.pid,
        # The same executor, on the same port, after the first one is killed.
        "restart": [sys.executable, str(EXECUTOR), str(port), str(EXECUTOR_LIFETIME_S), str(tree)],
        "shotDir": str(shots),
        "chromium": shutil.which("chromium"),
    }
    return run_driver(code_server, DRIVER, config, "live", DRIVER_TIMEOUT_S)


def _classes(snapshot: object) -> dict[str, str]:
    """The live class of each node drawn, by its type and SVG id."""
    assert isinstance(snapshot, dict)
    out = {}
    for node in snapshot["nodes"]:
        live = node["live"]
        assert len(live) <= 1, node  # one status a node
        if live:
            out[f"{node['type']}#{node['id']}"] = live[0]
    return out


def _check(result: dict[str, object], context: str, port: int) -> None:
    # The address: 127.0.0.1:1667 offered, a port out of range refused with the reason.
    assert result["defaultAddress"] == "127.0.0.1:1667", context
    assert "the port must be between 1 and 65534" in str(result["validation"]), context
    assert result["stillAsking"], context

    # Before connecting nothing is coloured.
    before = result["before"]
    assert isinstance(before, dict)
    assert before["live"] == 0 and before["after"] == [], context

    # Connected: the status bar says so; every node of the picture but the <BehaviorTree>
    # itself has a status, and the editor writes statuses after the tag names.
    connected = result["connected"]
    assert isinstance(connected, dict)
    assert "BT live: connected" in connected["status"], context
    classes = _classes(connected)
    assert connected["live"] == len(classes) == len(connected["nodes"]) - 1, context
    assert {c.removeprefix("live-") for c in classes.values()} <= STATUSES, context
    after = connected["after"]
    assert after and all(a.startswith("● ") and a[2:] in STATUSES for a in after), context

    # A moment later, a mix: AlwaysFailure under the Fallback fails each time it ticks; the
    # root Sequence is running whenever a Sleep is.
    mix = result["mix"]
    assert isinstance(mix, dict)
    mixed = _classes(mix)
    assert "live-running" in mixed.values(), context
    assert len(set(mixed.values())) >= 3, context
    failing = [v for k, v in mixed.items() if k.startswith("AlwaysFailure#")]
    assert failing and failing[0] in ("live-failure", "live-idle"), context
    # The CSS applied: a running node's fill is not the picture's own box colour.
    fills = {n["id"]: n["fill"] for n in mix["nodes"]}
    running = [i for i, c in mix["classes"].items() if c == "live-running"]
    idle_fill = result["before"]["nodes"][1]["fill"]  # type: ignore[index]
    assert running and all(fills[i] != idle_fill for i in running), context

    # An edit draws the picture again: its nodes keep their statuses.
    redrawn = result["redrawn"]
    assert isinstance(redrawn, dict)
    assert redrawn["renders"] > mix["renders"] and redrawn["live"] == connected["live"], context

    # Another file in front: its picture has no statuses (not part of the running tree);
    # back to the tree's file, its new editor and its picture have them again.
    other = result["other"]
    assert isinstance(other, dict)
    assert len(other["nodes"]) == 4 and other["live"] == 0, context
    back = result["back"]
    assert isinstance(back, dict)
    assert back["live"] == connected["live"] and back["after"], context

    # The executor killed: lost, and no stale status left in the picture or the editor.
    lost = result["lost"]
    assert isinstance(lost, dict)
    assert "BT live: lost" in lost["status"], context
    assert lost["live"] == 0 and lost["after"] == [], context

    # Started again on the same port: connected again, with statuses.
    again = result["reconnected"]
    assert isinstance(again, dict)
    assert "BT live: connected" in again["status"], context
    assert again["live"] > 0 and again["after"], context

    # Disconnected: off, nothing coloured.
    off = result["off"]
    assert isinstance(off, dict)
    assert "BT live: off" in off["status"], context
    assert off["live"] == 0 and off["after"] == [], context

    shot = ARTIFACTS / "live.png"
    assert shot.stat().st_size > 10_000, context
    if os.environ.get("BT_LSP_E2E_UPDATE_IMAGES") == "1":
        DOC_IMAGE.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy(shot, DOC_IMAGE)
