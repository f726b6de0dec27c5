"""The linux-x64 package, which brings its own server, in a real VS Code (code-server driven by
headless Chromium), on a machine where nothing of bt-lsp is installed for the user.

The environment has no virtual environment, no PYTHONPATH, no ``bt-lsp`` on PATH, and a
``python3`` on PATH that cannot import bt_lsp (this machine's base interpreter). Only
``bt-lsp-linux-x64.vsix`` is installed, into a fresh profile, with no server setting. The
extension must unpack its wheels for that Python into its storage and run the server from
there: squiggle, Problems entry, hover and quick fix as in test_vscode.py. When no Python can
run it, the status bar says so in red and the Problems view shows one warning on the file.

Needs `editors/vscode/e2e/setup.sh` (which builds the package with scripts/vscode_bundle.py).
"""

from __future__ import annotations

import json
import os
import platform
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
    REPO,
    SETUP,
    _code_server,
    _drive_and_check,
    _logs,
    _missing_setup,
)

pytestmark = pytest.mark.e2e

# The package setup.sh builds for this machine (linux-x64 on CI).
TARGET = {"aarch64": "linux-arm64"}.get(platform.machine(), "linux-x64")
BUNDLED_VSIX = EXT_DIR / f"bt-lsp-{TARGET}.vsix"
NOT_RUNNING_DRIVER = EXT_DIR / "e2e" / "notrunning.js"
BUILD = f"python scripts/vscode_bundle.py --target {TARGET}"


def _check_setup() -> None:
    missing = _missing_setup()
    if not BUNDLED_VSIX.exists():
        missing.append(f"{BUNDLED_VSIX.relative_to(REPO)} (`{BUILD}`)")
    else:
        sources = [
            EXT_DIR / "package.json",
            *(EXT_DIR / "src").rglob("*.ts"),
            *(EXT_DIR / "python").iterdir(),
            *(REPO / "src" / "bt_lsp").rglob("*.py"),
        ]
        newest = max(sources, key=lambda p: p.stat().st_mtime)
        if newest.stat().st_mtime > BUNDLED_VSIX.stat().st_mtime:
            missing.append(
                f"an up-to-date {BUNDLED_VSIX.relative_to(REPO)} "
                f"({newest.relative_to(REPO)} is newer; run `{BUILD}`)"
            )
    if missing:
        pytest.fail(
            f"the VS Code e2e setup is missing: {', '.join(missing)}. Run `bash {SETUP}` first.",
            pytrace=False,
        )


def _bare_environment(tmp_path: Path) -> dict[str, str]:
    """This process's environment without anything that reaches bt-lsp: PATH holds a
    ``python3`` (the base interpreter, not the virtual environment), node and the system
    folders; no PYTHONPATH, no VIRTUAL_ENV."""
    bin_dir = tmp_path / "bin"
    bin_dir.mkdir()
    base = Path(getattr(sys, "_base_executable", sys.executable)).resolve()
    (bin_dir / "python3").symlink_to(base)
    node = shutil.which("node")
    assert node is not None
    dirs = [str(bin_dir), str(Path(node).parent), "/usr/local/bin", "/usr/bin", "/bin"]
    drop = ("PYTHONPATH", "PYTHONHOME", "VIRTUAL_ENV", "CONDA_PREFIX", "PYTHONSTARTUP")
    env = {k: v for k, v in os.environ.items() if k not in drop}
    env["PATH"] = os.pathsep.join(dict.fromkeys(dirs))
    assert shutil.which("bt-lsp", path=env["PATH"]) is None, env["PATH"]
    probe = subprocess.run(
        ["python3", "-c", "import bt_lsp"], env=env, capture_output=True, text=True, check=False
    )
    assert probe.returncode != 0, f"{base} can import bt_lsp: the test would prove nothing"
    return env


def _channel_log(user_data: Path) -> str:
    return "\n".join(
        p.read_text(errors="replace") for p in sorted(user_data.glob("logs/**/*bt-lsp*.log"))
    )


def test_bundled_server_squiggle_problems_hover_fix(tmp_path: Path) -> None:
    _check_setup()
    env = _bare_environment(tmp_path)
    settings: dict[str, object] = {"btLsp.server.command": []}  # none: the default strategy
    with _code_server(tmp_path, settings=settings, vsix=BUNDLED_VSIX, environ=env) as cs:
        result = _drive_and_check(cs, tmp_path, prefix="bundled-")
        log = _channel_log(cs.user_data)
        context = f"\n{_logs(cs.user_data, cs.log)}"
        # The server came from the wheels unpacked into the extension's storage.
        storage = cs.user_data / "User" / "globalStorage" / "bt-lsp.bt-lsp" / "server"
        unpacked = sorted(storage.glob(f"{TARGET}-cp{sys.version_info[0]}{sys.version_info[1]}-*"))
        assert len(unpacked) == 1, f"{sorted(storage.glob('*'))}{context}"
        assert (unpacked[0] / "lxml").is_dir() and (unpacked[0] / "bt_lsp").is_dir()
        assert "Starting the server (bundled bt-lsp" in log, context
        assert f"(bundled, {unpacked[0] / 'bt_lsp'})" in log, context
        assert "python3 on PATH" in log, context
        assert result["statusBar"] == ["bt-lsp"], result["statusBar"]


def test_bundled_server_without_python_says_so(tmp_path: Path) -> None:
    _check_setup()
    env = _bare_environment(tmp_path)
    missing_python = str(tmp_path / "no-such-python")
    settings = {"btLsp.server.command": [], "btLsp.interpreter": [missing_python]}
    with _code_server(tmp_path, settings=settings, vsix=BUNDLED_VSIX, environ=env) as cs:
        shots = tmp_path / "shots"
        shots.mkdir()
        config = {
            "url": cs.url,
            "file": "tree.xml",
            "shotDir": str(shots),
            "chromium": shutil.which("chromium"),
        }
        run = subprocess.run(
            ["node", str(NOT_RUNNING_DRIVER), json.dumps(config)],
            env=cs.env,
            capture_output=True,
            text=True,
            timeout=DRIVER_TIMEOUT_S,
        )
        ARTIFACTS.mkdir(parents=True, exist_ok=True)
        for shot in shots.glob("*.png"):
            shutil.copy(shot, ARTIFACTS / f"bundled-{shot.name}")
        lines = run.stdout.strip().splitlines()
        assert lines, f"no driver output:\n{run.stderr}\n{_logs(cs.user_data, cs.log)}"
        result = json.loads(lines[-1])
        logs = _logs(cs.user_data, cs.log)
        context = f"\n{json.dumps(result, indent=1)}\n{run.stderr[-2000:]}\n{logs}"
        assert run.returncode == 0 and "error" not in result, context

        # The status bar: red, and it says the server is not running.
        (item,) = [i for i in result["statusBar"] if "not running" in i["text"]]
        red, green, blue = (int(c) for c in re.findall(r"\d+", item["background"])[:3])
        assert red > 150 and green < 100 and blue < 100, context

        # The Problems view is not silent: one warning on the file, that says why and the fix.
        (problem,) = [row for row in result["problems"] if "did not check this file" in row]
        assert "server-not-running" in problem, context
        assert missing_python in problem and "btLsp.interpreter" in problem, context
        assert any(n.startswith("bt-lsp:") for n in result["notifications"]), context
