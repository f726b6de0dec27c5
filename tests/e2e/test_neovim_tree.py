"""`:BtLspTree` in a real headless Neovim (0.7 and 0.11, as tests/e2e/test_neovim.py finds
them): it writes the tree under the cursor as SVG through the server's bt-lsp.renderTree,
opens it with the viewer (a fake xdg-open on PATH records the call) and prints its path;
with `!` it only prints the path."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
from pathlib import Path

import pytest
from lxml import etree

from tests.e2e.test_neovim import (
    INIT,
    MARK,
    NVIM_DIR,
    RUN_TIMEOUT_S,
    Target,
    _env,
    _find_nvim,
    _workspace,
    target,
)

pytestmark = pytest.mark.e2e

__all__ = ["target"]  # the fixture, parametrized over the Neovim versions

DRIVER = NVIM_DIR / "tree_driver.lua"
SVG = "{http://www.w3.org/2000/svg}"

TREES = """\
<root BTCPP_format="4" main_tree_to_execute="Main">
  <BehaviorTree ID="Main">
    <Sequence>
      <SubTree ID="Dock"/>
    </Sequence>
  </BehaviorTree>
  <BehaviorTree ID="Dock">
    <Fallback name="dock">
      <IsDocked/>
      <Align speed="{v}"/>
    </Fallback>
  </BehaviorTree>
</root>
"""


def test_bt_lsp_tree(tmp_path: Path, target: Target) -> None:
    nvim = _find_nvim(target)
    ws = _workspace(tmp_path)
    tree = ws / "trees" / "mission.xml"
    tree.write_text(TREES, encoding="utf-8")
    bin_dir = tmp_path / "bin"
    bin_dir.mkdir()
    record = tmp_path / "opened.txt"
    viewer = bin_dir / "xdg-open"
    viewer.write_text(f'#!/bin/sh\nprintf "%s\\n" "$1" >> "{record}"\n')
    viewer.chmod(0o755)
    env = _env(tmp_path)
    env["PATH"] = f"{bin_dir}{os.pathsep}{env['PATH']}"
    env.setdefault("BT_LSP_E2E_WAIT_MS", "30000")  # the server may start slowly on a busy machine
    env["BT_LSP_E2E_LINE"] = str(TREES.splitlines().index("      <IsDocked/>") + 1)
    argv = [nvim.path, "--headless", "-u", str(INIT), "-i", "NONE", "-n", str(tree)]
    argv += ["-c", f"lua dofile({json.dumps(str(DRIVER))})"]
    if shutil.which("timeout"):
        argv = ["timeout", "-k", "5", str(RUN_TIMEOUT_S), *argv]
    proc = subprocess.run(
        argv,
        cwd=tree.parent,
        env=env,
        stdin=subprocess.DEVNULL,
        capture_output=True,
        text=True,
        timeout=RUN_TIMEOUT_S + 15,
    )
    events = {
        e["event"]: e
        for e in (
            json.loads(ln[len(MARK) :]) for ln in proc.stdout.splitlines() if ln.startswith(MARK)
        )
    }
    why = f"exit {proc.returncode}\n--- stdout\n{proc.stdout}\n--- stderr\n{proc.stderr}"
    assert proc.returncode == 0 and "done" in events and "error" not in events, why
    assert events["start"]["mode"] == target.mode, why

    # With the cursor in the Dock tree: its SVG, with ports, opened with the viewer.
    opened = Path(events["opened"]["path"])
    svg = etree.parse(str(opened)).getroot()
    assert svg.tag == f"{SVG}svg" and svg.get("data-tree") == "Dock", why
    nodes = [
        g.get("data-type") for g in svg.iter(f"{SVG}g") if "node" in g.get("class", "").split()
    ]
    assert nodes == ["Dock", "Fallback", "IsDocked", "Align"], why
    keys = [t.text for t in svg.iter(f"{SVG}tspan") if t.get("class") == "key"]
    assert keys == ["{v}"], why
    assert record.read_text().splitlines() == [str(opened)], why
    assert f"tree 'Dock' written to {opened}" in events["opened"]["messages"], why

    # With `!` on line 1 (outside every tree): the main tree, only printed.
    printed = Path(events["printed"]["path"])
    svg = etree.parse(str(printed)).getroot()
    assert svg.get("data-tree") == "Main", why
    assert f"tree 'Main' written to {printed}" in events["printed"]["messages"], why
    assert record.read_text().splitlines() == [str(opened)], why  # not opened again
