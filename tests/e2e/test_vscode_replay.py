""" "bt-lsp: Replay a .btlog" in a real VS Code (code-server driven by headless Chromium), on a
log BehaviorTree.CPP 4.8.2 itself wrote (behaviortreepy's FileLogger2): the timeline opens in
the panel area; at each position of its slider the Show Tree view's nodes and the editor's
after-texts show the statuses the log gives after that many transitions (read here with
`bt_lsp.live.btlog`, the extension's timeline counting them itself); play runs to the end; stop
hides the timeline and clears everything.

Needs what tests/e2e/test_vscode.py needs (`editors/vscode/e2e/setup.sh`). Its screenshot goes
to `.e2e-artifacts/vscode/replay.png`.
"""

from __future__ import annotations

import gc
import shutil
from collections import Counter
from pathlib import Path

import pytest

from bt_lsp.live.btlog import BtLog
from bt_lsp.live.protocol import NodeStatus
from tests.e2e.test_vscode import (
    EXT_DIR,
    SETUP,
    _code_server,
    _missing_setup,
    run_driver,
)
from tests.e2e.test_vscode_live import MISSION

pytestmark = pytest.mark.e2e

DRIVER = EXT_DIR / "e2e" / "replay.js"
DRIVER_TIMEOUT_S = 180


def _write_log(path: Path) -> None:
    """One run of MISSION to its end, logged by BehaviorTree.CPP's FileLogger2."""
    bt = pytest.importorskip("behaviortreepy")
    factory = bt.BehaviorTreeFactory()
    factory.register_behavior_tree_from_text(MISSION)
    tree = factory.create_tree("Mission")
    tree.root_blackboard().set_int("counter", 0)
    logger = bt.FileLogger(tree, str(path))
    status = tree.tick_while_running(5)
    assert str(status).endswith("SUCCESS")
    del logger  # the destructor joins the writer thread and closes the file
    gc.collect()


def _expected(path: Path, applied: int) -> tuple[list[str], list[str]]:
    """After ``applied`` transitions: the statuses of the Mission tree's own nodes in
    document order (the picture's, SubTree contents not expanded), and of every node."""
    with path.open("rb") as f:
        log = BtLog(f)
        state: dict[int, NodeStatus] = {}
        for i, t in enumerate(log.transitions()):
            if i >= applied:
                break
            state[t.uid] = t.status
        nodes = sorted(log.header.tree.nodes.values(), key=lambda n: n.uid)

    def name(uid: int) -> str:
        return state.get(uid, NodeStatus.IDLE).name.lower()

    own = [name(n.uid) for n in nodes if "/" not in n.path]
    return own, [name(n.uid) for n in nodes]


def _positions(path: Path) -> tuple[int, int, int]:
    """The number of transitions, the first after which AlwaysFailure is FAILURE, and the
    one after which the root Sequence is SUCCESS."""
    with path.open("rb") as f:
        steps = list(BtLog(f).steps())
    failing = next(
        i + 1
        for i, s in enumerate(steps)
        if s.node.tag == "AlwaysFailure" and s.after is NodeStatus.FAILURE
    )
    done = next(
        i + 1 for i, s in enumerate(steps) if s.node.uid == 1 and s.after is NodeStatus.SUCCESS
    )
    return len(steps), failing, done


def test_vscode_replay(tmp_path: Path) -> None:
    missing = _missing_setup()
    if missing:
        pytest.fail(
            f"the VS Code e2e setup is missing: {', '.join(missing)}. Run `bash {SETUP}` first.",
            pytrace=False,
        )
    assert DRIVER.exists(), DRIVER
    source = tmp_path / "run.btlog"
    _write_log(source)
    count, failing, done = _positions(source)
    seeks = [1, failing, done, count]
    assert len(set(seeks)) == 4, seeks
    with _code_server(tmp_path, {"mission.xml": MISSION}) as code_server:
        shutil.copy(source, code_server.workspace / "run.btlog")
        shots = tmp_path / "shots"
        shots.mkdir()
        config = {
            "url": code_server.url,
            "file": "mission.xml",
            "log": "run.btlog",
            "seeks": seeks,
            "shotDir": str(shots),
            "chromium": shutil.which("chromium"),
        }
        result, context = run_driver(code_server, DRIVER, config, "replay", DRIVER_TIMEOUT_S)

    # Opened at the start: every node idle, the timeline over every transition.
    opened = result["opened"]
    assert opened["timeline"]["max"] == count, context
    assert "BT live: replay" in opened["status"], context
    assert all(n["live"] == "live-idle" for n in opened["picture"]["nodes"][1:]), context

    # At each position, the picture and the editor show what the log says.
    for seek in result["seeks"]:
        own, every = _expected(source, seek["k"])
        shown = [n["live"].removeprefix("live-") for n in seek["picture"]["nodes"][1:]]
        assert seek["timeline"]["applied"] == seek["k"], context
        assert shown == own, (seek["k"], context)
        after = Counter(a.removeprefix("● ") for a in seek["after"])
        assert after == Counter(every), (seek["k"], context)
    assert "AlwaysFailure" in result["seeks"][1]["timeline"]["last"], context
    assert "FAILURE" in result["seeks"][1]["timeline"]["last"], context

    # Play from the start runs to the end, through positions in between, and stops there.
    assert result["played"]["applied"] == count and not result["played"]["playing"], context
    assert len([k for k in result["playedThrough"] if 0 < k < count]) >= 2, context

    # Stopped: no status anywhere, the status bar off.
    stopped = result["stopped"]
    assert not stopped["timelineShown"], context
    assert stopped["picture"]["live"] == 0 and stopped["after"] == [], context
    assert "BT live: off" in stopped["status"], context
