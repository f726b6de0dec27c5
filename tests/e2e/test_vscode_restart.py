"""A failed start and its recovery in a real VS Code (code-server driven by headless Chromium).

``btLsp.server.command`` names a program that is not installed: the notification says so in
one sentence, with no JavaScript stack trace and no "Sending notification
workspace/didChangeConfiguration failed", and offers "Restart server".  With the server
installed there and the button pressed, the server runs (the file's squiggle appears) and
no error notification of the failed start is left on screen or in the notification
center.
"""

from __future__ import annotations

import json
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from tests.e2e.test_vscode import (
    ARTIFACTS,
    DRIVER_TIMEOUT_S,
    EXT_DIR,
    SETUP,
    _code_server,
    _logs,
    _missing_setup,
)

pytestmark = pytest.mark.e2e

RESTART_DRIVER = EXT_DIR / "e2e" / "restart.js"
# What a JavaScript stack trace or the client's own failure text looks like.
STACK = re.compile(r"\n\s+at |\bat \S+ \(.*:\d+:\d+\)|Sending notification|Error: ")


def test_vscode_failed_start_then_restart(tmp_path: Path) -> None:
    missing = _missing_setup()
    if missing:
        pytest.fail(f"the VS Code e2e setup is missing: {', '.join(missing)}. Run `bash {SETUP}`.")
    server = str(tmp_path / "bin" / "bt-lsp")  # installed by the driver, after the failure
    settings = {"btLsp.server.command": [server, "serve"]}
    with _code_server(tmp_path, settings=settings) as cs:
        shots = tmp_path / "shots"
        shots.mkdir()
        config = {
            "url": cs.url,
            "file": "tree.xml",
            "installPath": server,
            "installScript": f'#!/bin/sh\nexec "{sys.executable}" -m bt_lsp "$@"\n',
            "shotDir": str(shots),
            "chromium": shutil.which("chromium"),
        }
        run = subprocess.run(
            ["node", str(RESTART_DRIVER), json.dumps(config)],
            env=cs.env,
            capture_output=True,
            text=True,
            timeout=DRIVER_TIMEOUT_S * 2,
        )
        ARTIFACTS.mkdir(parents=True, exist_ok=True)
        for shot in shots.glob("*.png"):
            shutil.copy(shot, ARTIFACTS / f"restart-{shot.name}")
        lines = run.stdout.strip().splitlines()
        assert lines, f"no driver output:\n{run.stderr}\n{_logs(cs.user_data, cs.log)}"
        result = json.loads(lines[-1])
        context = (
            f"\n{json.dumps(result, indent=1)}\n{run.stderr[-2000:]}\n{_logs(cs.user_data, cs.log)}"
        )
        assert run.returncode == 0 and "error" not in result, context

        # The failed start: one sentence that names the command, and the buttons.
        (failed,) = [n for n in result["failed"] if n["message"].startswith("bt-lsp:")]
        assert f"{server} does not exist" in failed["message"], context
        assert not STACK.search(failed["message"]), context
        assert "Restart server" in failed["buttons"], context
        assert "Open Settings" in failed["buttons"], context
        assert result["squiggleBeforeFix"] == 0, context

        # Installed and restarted: the server runs, and nothing of the failure is left.
        assert result["installed"], context
        assert result["pressedRestart"], context
        assert result["squiggle"], context
        shown = [n["message"] for n in result["toastsAfter"]] + result["centerAfter"]
        assert not [m for m in shown if STACK.search(m)], context
        assert not [m for m in shown if m.startswith("bt-lsp:")], context
