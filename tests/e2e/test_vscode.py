"""The bt-lsp extension in a real VS Code (code-server), driven by headless Chromium.

Needs `editors/vscode/e2e/setup.sh` to have run (Chromium, the packaged extension, code-server,
playwright-core); without it the test fails and says so. The server under test is this
checkout's `python -m bt_lsp serve` (src/ is put first on PYTHONPATH).

Screenshots go to `.e2e-artifacts/vscode/`; with BT_LSP_E2E_UPDATE_IMAGES=1 the hover and
quick-fix ones are also copied into `editors/vscode/images/` for the extension's README.
"""

from __future__ import annotations

import json
import os
import shutil
import signal
import socket
import subprocess
import sys
import time
import urllib.request
from collections.abc import Iterator, Mapping
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pytest

pytestmark = pytest.mark.e2e

REPO = Path(__file__).resolve().parents[2]
EXT_DIR = REPO / "editors" / "vscode"
SETUP = "editors/vscode/e2e/setup.sh"
CODE_SERVER = EXT_DIR / ".e2e" / "code-server" / "node_modules" / ".bin" / "code-server"
VSIX = EXT_DIR / "bt-lsp.vsix"
DRIVER = EXT_DIR / "e2e" / "drive.js"
PLAYWRIGHT = EXT_DIR / "e2e" / "node_modules" / "playwright-core"
ARTIFACTS = REPO / ".e2e-artifacts" / "vscode"
README_IMAGES = EXT_DIR / "images"

TREE = """\
<root BTCPP_format="4" main_tree_to_execute="Main Tree">
  <BehaviorTree ID="Main Tree">
    <AlwaysSuccess name="ok"/>
  </BehaviorTree>
</root>
"""
FIXED = TREE.replace("Main Tree", "Main_Tree")
CODE = "model-name-forbidden-char"
FIX_TITLE = "Rename 'Main Tree' to 'Main_Tree'"

DRIVER_TIMEOUT_S = 120


def _missing_setup() -> list[str]:
    missing = []
    if shutil.which("node") is None:
        missing.append("node")
    chromium = shutil.which("chromium")
    if chromium is None:
        missing.append("chromium (Debian package)")
    for path in (CODE_SERVER, VSIX, PLAYWRIGHT):
        if not path.exists():
            missing.append(str(path.relative_to(REPO)))
    if VSIX.exists():
        sources = [EXT_DIR / "package.json", *sorted((EXT_DIR / "src").rglob("*.ts"))]
        stale = [p for p in sources if p.stat().st_mtime > VSIX.stat().st_mtime]
        if stale:
            missing.append(
                f"an up-to-date {VSIX.relative_to(REPO)} "
                f"({stale[0].relative_to(REPO)} is newer; or run `npm run package` there)"
            )
    return missing


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def _wait_http(url: str, proc: subprocess.Popen[bytes], log: Path, timeout_s: float) -> None:
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        if proc.poll() is not None:
            pytest.fail(f"code-server exited with {proc.returncode}:\n{log.read_text()[-3000:]}")
        try:
            with urllib.request.urlopen(url, timeout=2) as response:
                if response.status == 200:
                    return
        except OSError:
            pass
        time.sleep(0.3)
    pytest.fail(f"code-server did not answer {url} within {timeout_s}s:\n{log.read_text()[-3000:]}")


def _kill_group(proc: subprocess.Popen[bytes]) -> None:
    """Ends code-server and every process it started (file watcher, extension host, bt-lsp)."""
    try:
        pgid = os.getpgid(proc.pid)
    except ProcessLookupError:
        return
    for sig, wait_s in ((signal.SIGTERM, 5.0), (signal.SIGKILL, 5.0)):
        try:
            os.killpg(pgid, sig)
        except ProcessLookupError:
            break
        deadline = time.monotonic() + wait_s
        while time.monotonic() < deadline:
            try:
                os.killpg(pgid, 0)
            except ProcessLookupError:
                proc.wait()
                return
            proc.poll()
            time.sleep(0.1)
    proc.wait()


def _logs(user_data: Path, log: Path) -> str:
    """The bt-lsp output channel and code-server's own log, for failure messages."""
    parts = []
    for channel in sorted(user_data.glob("logs/**/*bt-lsp*.log")):
        parts.append(f"--- {channel.name}\n{channel.read_text(errors='replace')[-4000:]}")
    parts.append(f"--- code-server\n{log.read_text(errors='replace')[-2000:]}")
    return "\n".join(parts)


@dataclass
class CodeServer:
    url: str
    workspace: Path
    user_data: Path
    log: Path
    env: dict[str, str]


def run_driver(
    code_server: CodeServer,
    driver: Path,
    config: Mapping[str, Any],
    name: str,
    timeout_s: float,
    keep: int = 6000,
) -> tuple[dict[str, Any], str]:
    """Run a playwright driver against ``code_server`` with ``config`` (its ``shotDir``'s
    screenshots copied to the artifacts): its last printed line as JSON, written to
    ``<name>-result.json``, and a failure context (the result's last ``keep`` characters,
    the driver's stderr, the logs).  The driver must end well and report no error."""
    shots = Path(config["shotDir"])
    try:
        run = subprocess.run(
            ["node", str(driver), json.dumps(config)],
            env=code_server.env,
            capture_output=True,
            text=True,
            timeout=timeout_s,
        )
    except subprocess.TimeoutExpired as e:
        logs = _logs(code_server.user_data, code_server.log)
        pytest.fail(f"the driver took more than {timeout_s}s\n{e.stderr!r}\n{logs}")
    finally:
        ARTIFACTS.mkdir(parents=True, exist_ok=True)
        for shot in shots.glob("*.png"):
            shutil.copy(shot, ARTIFACTS / shot.name)
    lines = run.stdout.strip().splitlines()
    logs = _logs(code_server.user_data, code_server.log)
    assert lines, f"no output from the driver (exit {run.returncode}):\n{run.stderr}\n{logs}"
    result: dict[str, Any] = json.loads(lines[-1])
    (ARTIFACTS / f"{name}-result.json").write_text(json.dumps(result, indent=1))
    context = (
        f"\ndriver result: {json.dumps(result, indent=1)[-keep:]}\n"
        f"driver stderr:\n{run.stderr[-2000:]}\n{logs}\nscreenshots: {ARTIFACTS}"
    )
    assert run.returncode == 0 and "error" not in result, context
    return result, context


@contextmanager
def _code_server(
    tmp_path: Path,
    files: dict[str, str] | None = None,
    settings: Mapping[str, object] = {},
    vsix: Path = VSIX,
    environ: Mapping[str, str] | None = None,
) -> Iterator[CodeServer]:
    """code-server on 127.0.0.1 with the extension, an isolated user-data dir and a workspace
    holding ``files`` (name -> text; by default tree.xml); ``settings`` override the user
    settings. ``environ`` replaces the process environment (then nothing is added to
    PYTHONPATH), ``vsix`` is the package installed."""
    workspace = tmp_path / "ws"
    workspace.mkdir()
    for name, text in (files or {"tree.xml": TREE}).items():
        (workspace / name).write_text(text, encoding="utf-8", newline="\n")
    user_data = tmp_path / "user-data"
    (user_data / "User").mkdir(parents=True)
    extensions = tmp_path / "extensions"
    xdg = tmp_path / "xdg"

    server_command = [sys.executable, "-m", "bt_lsp", "serve"]
    user_settings: dict[str, object] = {
        "btLsp.server.command": server_command,
        "btLsp.trace.server": "messages",
        "security.workspace.trust.enabled": False,
        "workbench.startupEditor": "none",
        "workbench.tips.enabled": False,
        "workbench.enableExperiments": False,
        "extensions.ignoreRecommendations": True,
        "extensions.autoCheckUpdates": False,
        "extensions.autoUpdate": False,
        "telemetry.telemetryLevel": "off",
        "update.mode": "none",
        "git.enabled": False,
        "chat.commandCenter.enabled": False,
        "files.autoSave": "off",
    }
    user_settings.update(settings)
    (user_data / "User" / "settings.json").write_text(json.dumps(user_settings, indent=2))
    # code-server's window is a remote one: VS Code ignores machine(-overridable) settings such
    # as btLsp.server.command in the user settings once it knows their scope, and reads them
    # from the machine's. Before, they may apply or not: with a .vscode folder (read after
    # the extension started) the server was restarted without its command.
    (user_data / "Machine").mkdir()
    (user_data / "Machine" / "settings.json").write_text(json.dumps(user_settings, indent=2))

    env = dict(os.environ if environ is None else environ)
    env.update(
        XDG_CONFIG_HOME=str(xdg / "config"),
        XDG_DATA_HOME=str(xdg / "data"),
        XDG_CACHE_HOME=str(xdg / "cache"),
    )
    if environ is None:
        paths = [str(REPO / "src"), env.get("PYTHONPATH")]
        env["PYTHONPATH"] = os.pathsep.join(filter(None, paths))
    env.pop("VSCODE_IPC_HOOK_CLI", None)
    base = [
        str(CODE_SERVER),
        "--user-data-dir",
        str(user_data),
        "--extensions-dir",
        str(extensions),
    ]
    install = subprocess.run(
        [*base, "--install-extension", str(vsix)],
        env=env,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert install.returncode == 0, install.stdout + install.stderr

    port = _free_port()
    config_file = tmp_path / "code-server.yaml"
    config_file.write_text("")
    log = tmp_path / "code-server.log"
    with log.open("wb") as log_file:
        proc = subprocess.Popen(
            [
                *base,
                "--config",
                str(config_file),
                "--bind-addr",
                f"127.0.0.1:{port}",
                "--auth",
                "none",
                "--disable-telemetry",
                "--disable-update-check",
                "--disable-workspace-trust",
                "--disable-getting-started-override",
                str(workspace),
            ],
            env=env,
            stdin=subprocess.DEVNULL,
            stdout=log_file,
            stderr=subprocess.STDOUT,
            start_new_session=True,
        )
    try:
        _wait_http(f"http://127.0.0.1:{port}/healthz", proc, log, timeout_s=60)
        yield CodeServer(
            url=f"http://127.0.0.1:{port}/?folder={workspace}",
            workspace=workspace,
            user_data=user_data,
            log=log,
            env=env,
        )
    finally:
        _kill_group(proc)


def test_vscode_squiggle_problems_quick_fix_hover(tmp_path: Path) -> None:
    missing = _missing_setup()
    if missing:
        pytest.fail(
            f"the VS Code e2e setup is missing: {', '.join(missing)}. Run `bash {SETUP}` first.",
            pytrace=False,
        )
    with _code_server(tmp_path) as code_server:
        _drive_and_check(code_server, tmp_path)


def _drive_and_check(code_server: CodeServer, tmp_path: Path, prefix: str = "") -> dict[str, Any]:
    """Squiggle, Problems entry, hover and quick fix; returns the driver's record. Screenshots
    and the record go to ARTIFACTS with ``prefix`` before their names."""

    def logs() -> str:
        return _logs(code_server.user_data, code_server.log)

    shots = tmp_path / "shots"
    shots.mkdir()
    # 1-based line and column of the name in <BehaviorTree ID="Main Tree">.
    line = 2
    column = TREE.splitlines()[line - 1].index('ID="Main Tree"') + len('ID="') + 1
    drive_config = {
        "url": code_server.url,
        "file": "tree.xml",
        "line": line,
        "column": column + 2,  # inside the name, where the hover and Ctrl+. happen
        "fixTitle": FIX_TITLE,
        "expectAfter": 'ID="Main_Tree"',
        "shotDir": str(shots),
        "chromium": shutil.which("chromium"),
    }
    try:
        run = subprocess.run(
            ["node", str(DRIVER), json.dumps(drive_config)],
            env=code_server.env,
            capture_output=True,
            text=True,
            timeout=DRIVER_TIMEOUT_S,
        )
    except subprocess.TimeoutExpired as e:
        pytest.fail(f"the driver took more than {DRIVER_TIMEOUT_S}s\n{e.stderr!r}\n{logs()}")
    finally:
        ARTIFACTS.mkdir(parents=True, exist_ok=True)
        for shot in shots.glob("*.png"):
            shutil.copy(shot, ARTIFACTS / f"{prefix}{shot.name}")

    lines = run.stdout.strip().splitlines()
    assert lines, f"no output from the driver (exit {run.returncode}):\n{run.stderr}\n{logs()}"
    result: dict[str, Any] = json.loads(lines[-1])
    (ARTIFACTS / f"{prefix}result.json").write_text(json.dumps(result, indent=1))
    context = (
        f"\ndriver result: {json.dumps(result, indent=1)}\ndriver stderr:\n{run.stderr[-2000:]}\n"
        f"{logs()}\nscreenshots: {ARTIFACTS}"
    )
    assert run.returncode == 0 and "error" not in result, context

    # The squiggle and the Problems entry with our source and code.
    assert result["squiggle"], context
    problems = [row for row in result["problemsBefore"] if CODE in row]
    assert len(problems) == 1, context
    assert "bt-lsp" in problems[0] and "Main Tree" in problems[0], context
    assert f"[Ln {line}, Col {column}]" in problems[0], context

    # The hover (our Markdown, not the problem's message above it) explains the character and
    # shows the replacement.
    explanation = "\n".join(part["text"] for part in result["hoverParts"] if not part["marker"])
    assert "' ' (space)" in explanation and "Main_Tree" in explanation, context

    # The preferred quick fix renames the tree and its reference; the problem is gone.
    assert any(a.startswith(FIX_TITLE) and "(2 places)" in a for a in result["actions"]), context
    assert result["textAfter"].strip() == FIXED.strip(), context
    assert result["problemsAfter"] == [] and result["squigglesAfter"] == 0, context
    assert result["saved"], context
    assert (code_server.workspace / "tree.xml").read_text(encoding="utf-8") == FIXED, context

    for name in ("hover.png", "quickfix.png", "fixed.png"):
        assert (ARTIFACTS / f"{prefix}{name}").stat().st_size > 10_000, name
    if os.environ.get("BT_LSP_E2E_UPDATE_IMAGES") == "1" and not prefix:
        for name in ("hover.png", "quickfix.png"):
            shutil.copy(ARTIFACTS / name, README_IMAGES / name)
    return result
