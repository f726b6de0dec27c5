"""The Neovim plugin (editors/neovim) in a real headless Neovim, loaded as a user loads it.

Neovim starts with tests/e2e/nvim/minimal_init.lua (the plugin folder on the runtimepath,
`filetype plugin on`, `require("bt_lsp").setup{...}`) on a copy of a fixture, and
tests/e2e/nvim/driver.lua does what a user does (hover, code action with the preferred fix
picked from the list) and prints each result as a `BTLSP-E2E {json}` line.

Needs `nvim` on PATH (Debian: `apt-get install neovim`, which is 0.7.2); BT_LSP_E2E_NVIM
picks another Neovim binary. The server is this checkout's `python -m bt_lsp serve`.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pytest

pytestmark = pytest.mark.e2e

REPO = Path(__file__).resolve().parents[2]
NVIM_DIR = Path(__file__).resolve().parent / "nvim"
INIT = NVIM_DIR / "minimal_init.lua"
DRIVER = NVIM_DIR / "driver.lua"
RUN_TIMEOUT_S = 60
MARK = "BTLSP-E2E "

TREE = """\
<root BTCPP_format="4" main_tree_to_execute="Main Tree">
  <BehaviorTree ID="Main Tree">
    <Sequence>
      <Open.Door door.id="{d}"/>
    </Sequence>
  </BehaviorTree>
  <TreeNodesModel><Action ID="Open.Door"><input_port name="door.id"/></Action></TreeNodesModel>
</root>
"""

# The same tree with text before the names whose UTF-8, UTF-16 and code point lengths all
# differ, so that byte columns (what Neovim shows) and LSP characters do not agree.
TREE_UNICODE = TREE.replace(
    '  <BehaviorTree ID="Main Tree">', '  <!--Tür--><BehaviorTree ID="Main Tree">'
).replace('      <Open.Door door.id="{d}"/>', '      <!--😋 ü--><Open.Door door.id="{d}"/>')

PLAIN = '<launch><node name="a.b"/></launch>\n'

FIX_TITLE = "Rename 'Main Tree' to 'Main_Tree' (2 places)"
MODEL = "model-name-forbidden-char"
PORT = "port-name-forbidden-char"


@dataclass(frozen=True)
class Expected:
    code: str
    lnum: int
    col: int
    end_lnum: int
    end_col: int


def _expected(text: str) -> list[Expected]:
    """Where the name diagnostics must be: 0-based line and *byte* column, which is what
    vim.diagnostic holds whatever the position encoding."""
    lines = text.splitlines()

    def at(context: str, name: str, code: str) -> Expected:
        row = next(i for i, line in enumerate(lines) if context in line)
        line = lines[row]
        start = line.index(name, line.index(context))
        col = len(line[:start].encode("utf-8"))
        return Expected(code, row, col, row, col + len(name.encode("utf-8")))

    return sorted(
        [
            at('<BehaviorTree ID="Main Tree"', "Main Tree", MODEL),
            at("<Open.Door door.id=", "Open.Door", MODEL),
            at("<Open.Door door.id=", "door.id", PORT),
            at('<Action ID="Open.Door"', "Open.Door", MODEL),
            at('<input_port name="door.id"', "door.id", PORT),
        ],
        key=lambda e: (e.lnum, e.col),
    )


def _nvim() -> str:
    nvim = os.environ.get("BT_LSP_E2E_NVIM") or shutil.which("nvim")
    if nvim is None:
        pytest.fail(
            "Neovim (`nvim`) is not on PATH, so the Neovim plugin cannot be tested: "
            "install it (Debian/Ubuntu: `apt-get install neovim`; scripts/setup.sh does this) "
            "or point BT_LSP_E2E_NVIM at an nvim binary.",
            pytrace=False,
        )
    return nvim


def _env(tmp_path: Path) -> dict[str, str]:
    """The environment for nvim: its own config/data/state/cache folders (no user config,
    plugins or shada), and this checkout's server on PYTHONPATH."""
    env = dict(os.environ)
    for var in ("XDG_CONFIG_HOME", "XDG_DATA_HOME", "XDG_STATE_HOME", "XDG_CACHE_HOME"):
        path = tmp_path / "home" / var.lower()
        path.mkdir(parents=True, exist_ok=True)
        env[var] = str(path)
    for var in ("NVIM", "NVIM_LISTEN_ADDRESS", "VIMINIT", "MYVIMRC"):
        env.pop(var, None)
    env["PYTHONPATH"] = os.pathsep.join(
        p for p in (str(REPO / "src"), env.get("PYTHONPATH", "")) if p
    )
    env["BT_LSP_E2E_PYTHON"] = sys.executable
    return env


@dataclass
class Run:
    events: dict[str, dict[str, Any]]
    stdout: str
    stderr: str
    lsp_log: str
    returncode: int

    def explain(self) -> str:
        return (
            f"nvim exit code {self.returncode}\n--- stdout\n{self.stdout}\n--- stderr\n"
            f"{self.stderr}\n--- lsp.log (tail)\n{self.lsp_log[-4000:]}"
        )


def _run_nvim(tmp_path: Path, file: Path, scenario: str, env_extra: dict[str, str]) -> Run:
    nvim = _nvim()
    env = _env(tmp_path)
    env["BT_LSP_E2E_SCENARIO"] = scenario
    env.update(env_extra)
    argv = [
        nvim,
        "--headless",
        "-u",
        str(INIT),
        "-i",
        "NONE",
        "-n",
        str(file),
        "-c",
        f"lua dofile({json.dumps(str(DRIVER))})",
    ]
    if shutil.which("timeout"):
        argv = ["timeout", "-k", "5", str(RUN_TIMEOUT_S), *argv]
    try:
        proc = subprocess.run(
            argv,
            cwd=file.parent,
            env=env,
            stdin=subprocess.DEVNULL,
            capture_output=True,
            text=True,
            timeout=RUN_TIMEOUT_S + 15,
        )
        stdout, stderr, rc = proc.stdout, proc.stderr, proc.returncode
    except subprocess.TimeoutExpired as exc:
        out, err = exc.stdout or "", exc.stderr or ""
        stdout = out.decode() if isinstance(out, bytes) else out
        stderr = err.decode() if isinstance(err, bytes) else err
        rc = -1
    # Neovim 0.7 writes lsp.log to the cache folder, 0.8+ to the state folder.
    logs = [Path(env[var]) / "nvim" / "lsp.log" for var in ("XDG_CACHE_HOME", "XDG_STATE_HOME")]
    lsp_log = "".join(p.read_text(errors="replace") for p in logs if p.exists())
    events: dict[str, dict[str, Any]] = {}
    for line in stdout.splitlines():
        if line.startswith(MARK):
            event = json.loads(line[len(MARK) :])
            events[event["event"]] = event
    run = Run(events, stdout, stderr, lsp_log, rc)
    if rc != 0 or "error" in events or "done" not in events:
        message = events.get("error", {}).get("message", "the driver did not finish")
        pytest.fail(f"headless Neovim run failed: {message}\n{run.explain()}", pytrace=False)
    return run


def _workspace(tmp_path: Path) -> Path:
    """A project folder marked by a Groot project file (one of the default root markers)."""
    ws = tmp_path / "ws"
    (ws / "trees").mkdir(parents=True)
    (ws / "project.btproj").write_text('<root BTCPP_format="4"/>\n', encoding="utf-8")
    return ws


def _name_diags(items: list[dict[str, Any]]) -> list[Expected]:
    """The name-rule diagnostics. Others (e.g. about ports) may come and go as the checker
    grows and are not what this test is about."""
    return sorted(
        (
            Expected(d["code"], d["lnum"], d["col"], d["end_lnum"], d["end_col"])
            for d in items
            if d["code"] in (MODEL, PORT)
        ),
        key=lambda e: (e.lnum, e.col),
    )


def _warnings(run: Run) -> list[str]:
    """Deprecation warnings and errors Neovim showed while the plugin ran."""
    text = run.events["done"]["messages"] + "\n" + run.stderr
    return [line for line in text.splitlines() if "deprecat" in line.lower() or "E5108" in line]


def _server_complaints(lsp_log: str) -> list[str]:
    """Warnings and errors the server sent with window/logMessage (they all start with
    "bt-lsp"), e.g. settings it could not read or an internal error."""
    return [
        line
        for line in lsp_log.splitlines()
        if ("[WARN]" in line or "[ERROR]" in line) and '"bt-lsp' in line
    ]


@pytest.mark.parametrize("text", [TREE, TREE_UNICODE], ids=["ascii", "unicode"])
def test_diagnostics_hover_and_quick_fix(tmp_path: Path, text: str) -> None:
    ws = _workspace(tmp_path)
    tree = ws / "trees" / "tree.xml"
    tree.write_text(text, encoding="utf-8")

    run = _run_nvim(tmp_path, tree, "quickfix", {})
    ev = run.events
    why = run.explain()

    assert ev["start"]["filetype"] == "xml", why
    client = ev["attached"]["client"]
    assert client["name"] == "bt_lsp", why
    assert Path(client["root_dir"]) == ws, why

    expected = _expected(text)
    diags = ev["diagnostics"]["items"]
    assert _name_diags(diags) == expected, why
    assert all(d["source"] == "bt-lsp" for d in diags), why
    main = next(d for d in diags if d["code"] == MODEL and d["lnum"] == expected[0].lnum)
    assert "Main Tree" in main["message"], why
    assert "' ' (space)" in main["message"], why

    markdown = ev["hover"]["markdown"]
    assert isinstance(markdown, str), why
    assert "Main Tree" in markdown, why
    assert "' ' (space)" in markdown, why
    assert "Main_Tree" in markdown, why
    assert "Main_Tree" in "\n".join(ev["hover"]["window"]), why

    actions = ev["actions"]["items"]
    assert actions[0]["title"] == FIX_TITLE, why
    assert actions[0]["isPreferred"] is True, why
    assert actions[0]["kind"] == "quickfix", why
    assert [a["isPreferred"] for a in actions].count(True) == 1, why
    assert ev["actions"]["picked"] == 1, why

    assert ev["buffer"]["lines"] == text.replace("Main Tree", "Main_Tree").splitlines(), why
    assert ev["buffer"]["modified"] is True, why

    after = ev["diagnostics_after"]["items"]
    assert _name_diags(after) == expected[1:], why
    assert not any("Main Tree" in d["message"] for d in after), why

    assert _server_complaints(run.lsp_log) == [], why
    assert _warnings(run) == [], why


def test_plain_xml_gets_no_client(tmp_path: Path) -> None:
    ws = _workspace(tmp_path)
    launch = ws / "launch.xml"
    launch.write_text(PLAIN, encoding="utf-8")
    tree = ws / "trees" / "tree.xml"
    tree.write_text(TREE, encoding="utf-8")

    run = _run_nvim(tmp_path, launch, "no-client", {"BT_LSP_E2E_OTHER": str(tree)})
    ev = run.events
    why = run.explain()

    assert ev["start"]["filetype"] == "xml", why
    assert ev["plain"]["buffer_clients"] == 0, why
    assert ev["plain"]["clients"] == [], why

    # The plugin was working all along: the BehaviorTree file next to it gets a client...
    other = ev["other"]
    assert other["client"]["name"] == "bt_lsp", why
    assert Path(other["client"]["root_dir"]) == ws, why
    assert other["plain_buffer_clients"] == 0, why

    # ... and :BtLspRestart replaces it with exactly one new client.
    restarted = ev["restarted"]
    assert restarted["client"]["id"] != other["client"]["id"], why
    assert [c["id"] for c in restarted["clients"]] == [restarted["client"]["id"]], why

    assert _server_complaints(run.lsp_log) == [], why
    assert _warnings(run) == [], why


def test_checkhealth_runs_the_server(tmp_path: Path) -> None:
    nvim = _nvim()
    env = _env(tmp_path)
    report = tmp_path / "health.txt"
    argv = [
        nvim,
        "--headless",
        "-u",
        str(INIT),
        "-i",
        "NONE",
        "-n",
        "-c",
        "checkhealth bt_lsp",
        "-c",
        f"lua vim.fn.writefile(vim.api.nvim_buf_get_lines(0, 0, -1, false), "
        f"{json.dumps(str(report))})",
        "-c",
        "qa!",
    ]
    if shutil.which("timeout"):
        argv = ["timeout", "-k", "5", str(RUN_TIMEOUT_S), *argv]
    proc = subprocess.run(
        argv,
        cwd=tmp_path,
        env=env,
        stdin=subprocess.DEVNULL,
        capture_output=True,
        text=True,
        timeout=RUN_TIMEOUT_S + 15,
    )
    text = report.read_text(encoding="utf-8") if report.exists() else ""
    why = f"exit {proc.returncode}\n--- report\n{text}\n--- stderr\n{proc.stderr}"
    assert proc.returncode == 0, why
    assert "bt-lsp" in text, why
    assert "setup() called" in text, why
    assert f"`{sys.executable} -m bt_lsp serve` runs: bt-lsp" in text, why
    assert "ERROR" not in text, why
