"""A C++-learned hover in a real VS Code (code-server driven by headless Chromium).

The workspace is the colcon workspace of ``tests/data/cpp_project`` plus a tree with one
bad name (the driver needs an error squiggle and a quick fix to apply); the hover is
taken on ``DriveTo``, a node registered in C++ only, and must say where.  Its screenshot
is the README's ``editors/vscode/images/cpp-hover.png``.
"""

from __future__ import annotations

import json
import shutil
import subprocess
from pathlib import Path

import pytest

from tests.e2e.test_vscode import (
    ARTIFACTS,
    DRIVER,
    DRIVER_TIMEOUT_S,
    SETUP,
    _code_server,
    _logs,
    _missing_setup,
)

pytestmark = pytest.mark.e2e

PROJECT = Path(__file__).resolve().parents[1] / "data" / "cpp_project"
TREE = """<root BTCPP_format="4" main_tree_to_execute="Main Tree">
  <BehaviorTree ID="Main Tree">
    <Sequence>
      <BatteryOk min_percent="20"/>
      <DriveTo target="dock"/>
    </Sequence>
  </BehaviorTree>
</root>
"""


def test_vscode_hover_of_a_node_learned_from_cpp(tmp_path: Path) -> None:
    missing = _missing_setup()
    if missing:
        pytest.fail(f"the VS Code e2e setup is missing: {', '.join(missing)}. Run `bash {SETUP}`.")
    with _code_server(tmp_path, {"mission.xml": TREE}) as cs:
        # The tree is at the top (the driver opens it from the Explorer), in no package:
        # it sees the C++ of the whole workspace.
        shutil.copytree(PROJECT / "src", cs.workspace / "src")
        shots = tmp_path / "shots"
        shots.mkdir()
        line = 5
        column = TREE.splitlines()[line - 1].index("DriveTo") + 3
        config = {
            "url": cs.url,
            "file": "mission.xml",
            "line": line,
            "column": column,
            "fixTitle": "Rename 'Main Tree'",
            "expectAfter": 'ID="Main_Tree"',
            "shotDir": str(shots),
            "chromium": shutil.which("chromium"),
        }
        run = subprocess.run(
            ["node", str(DRIVER), json.dumps(config)],
            env=cs.env,
            capture_output=True,
            text=True,
            timeout=DRIVER_TIMEOUT_S,
        )
        ARTIFACTS.mkdir(parents=True, exist_ok=True)
        shot = shots / "hover.png"
        if shot.exists():
            shutil.copy(shot, ARTIFACTS / "cpp-hover.png")
        lines = run.stdout.strip().splitlines()
        assert lines, f"no driver output:\n{run.stderr}\n{_logs(cs.user_data, cs.log)}"
        result = json.loads(lines[-1])
        context = f"\n{json.dumps(result, indent=1)}\n{run.stderr[-2000:]}"
        hover = result.get("hover") or ""
        assert "registered in src/robot_nodes/src/register.cpp:6" in hover, context
        assert "robot_nodes::DriveTo" in hover and "max_speed" in hover, context
