"""bt-lsp in a real headless Emacs 28 with eglot 1.9 (Debian 12's ``emacs-nox`` and
``elpa-eglot``, which scripts/setup.sh installs), as a user without markdown-mode has it.

tests/e2e/emacs/driver.el opens a copy of a fixture in nxml-mode, connects eglot to this
checkout's ``python -m bt_lsp serve``, and does what a user does: reads the Flymake
diagnostics, asks for the hover on the first bad name and applies the preferred quick fix
through ``eglot-code-actions`` (accepting its prompt's default, the preferred action). It
prints each result as a ``BTLSP-E2E {json}`` line.

eglot 1.9 offers no position encodings, so positions are UTF-16, which eglot converts with
``eglot-current-column-function``; the fixture puts non-ASCII characters and an emoji (two
UTF-16 units, one Emacs character) before bad names, so that a wrong conversion moves the
diagnostic. Without markdown-mode eglot asks for plain-text hovers only. A missing Emacs or
eglot fails the test (never skips it): run scripts/setup.sh.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest

pytestmark = pytest.mark.e2e

DRIVER = Path(__file__).resolve().parent / "emacs" / "driver.el"
REPO = Path(__file__).resolve().parents[2]
EGLOT = Path("/usr/share/emacs/site-lisp/elpa/eglot-1.9")
MARK = "BTLSP-E2E "
RUN_TIMEOUT_S = 120

TREE = """\
<root BTCPP_format="4" main_tree_to_execute="Main Tree">
  <!--Tür 😋--><BehaviorTree ID="Main Tree">
    <Sequence>
      <!--😋 ü--><Open.Door door.id="{d}"/>
    </Sequence>
  </BehaviorTree>
  <TreeNodesModel><Action ID="Open.Door"><input_port name="door.id"/></Action></TreeNodesModel>
</root>
"""

FIX_TITLE = "Rename 'Main Tree' to 'Main_Tree' (2 places)"


def _expected(text: str) -> list[tuple[str, int, int, int, str]]:
    """(code, line, start, end, name) of the name diagnostics: 0-based line, columns in
    characters, as Emacs counts them (an emoji is one)."""
    lines = text.splitlines()

    def at(context: str, name: str, code: str) -> tuple[str, int, int, int, str]:
        row = next(i for i, line in enumerate(lines) if context in line)
        start = lines[row].index(name, lines[row].index(context))
        return (code, row, start, start + len(name), name)

    model, port = "model-name-forbidden-char", "port-name-forbidden-char"
    return [
        at('<BehaviorTree ID="Main Tree"', "Main Tree", model),
        at("<Open.Door door.id=", "Open.Door", model),
        at("<Open.Door door.id=", "door.id", port),
        at('<Action ID="Open.Door"', "Open.Door", model),
        at('<input_port name="door.id"', "door.id", port),
    ]


def _run(tmp_path: Path, text: str) -> dict[str, Any]:
    emacs = shutil.which("emacs")
    assert emacs is not None, "Emacs is not installed: run scripts/setup.sh"
    assert EGLOT.is_dir(), "eglot 1.9 (elpa-eglot) is not installed: run scripts/setup.sh"
    ws = tmp_path / "ws"
    ws.mkdir()
    tree = ws / "tree.xml"
    tree.write_text(text, encoding="utf-8")
    home = tmp_path / "home"
    home.mkdir()
    env = {
        **os.environ,
        "HOME": str(home),
        "PYTHONPATH": str(REPO / "src"),
        "XDG_CACHE_HOME": str(tmp_path / "cache"),
        "BT_LSP_SERVER": "\t".join([sys.executable, "-m", "bt_lsp", "serve"]),
    }
    proc = subprocess.run(
        [emacs, "--batch", "-Q", "-l", str(DRIVER), str(tree)],
        cwd=ws,
        env=env,
        capture_output=True,
        text=True,
        timeout=RUN_TIMEOUT_S,
        check=False,
    )
    events = {}
    for line in proc.stdout.splitlines():
        if line.startswith(MARK):
            ev = json.loads(line[len(MARK) :])
            events[ev["event"]] = ev["data"]
    why = f"rc={proc.returncode}\nstdout:\n{proc.stdout}\nstderr:\n{proc.stderr}"
    assert proc.returncode == 0 and "error" not in events, why
    events["why"] = why
    return events


def test_eglot_diagnostics_hover_and_quick_fix(tmp_path: Path) -> None:
    ev = _run(tmp_path, TREE)
    why = ev["why"]

    # Diagnostics at the exact characters, after non-ASCII text and emoji on their lines.
    got = sorted(
        (d["code"], d["line"], d["col"], d["end_col"], d["text"])
        for d in ev["diagnostics"]
        if d["code"] in ("model-name-forbidden-char", "port-name-forbidden-char")
    )
    assert got == sorted(_expected(TREE)), why
    assert all(d["line"] == d["end_line"] for d in ev["diagnostics"]), why

    # eglot without markdown-mode asks for plain text, and gets it: no Markdown markup.
    assert ev["capabilities"]["hover_formats"] == ["plaintext"], why
    hover = ev["hover"]
    assert hover["kind"] == "plaintext", why
    assert hover["value"].startswith(
        "Model name 'Main Tree' breaks the BehaviorTree.CPP naming rules\n"
    ), why
    assert "' ' (space), whitespace" in hover["value"], why
    assert (
        "Suggested replacement: 'Main_Tree' (the quick fix renames 2 places)" in (hover["value"])
    ), why
    for markup in ("**", "`", "\n|"):
        assert markup not in hover["shown"], why

    # The quick fix through eglot-code-actions: the preferred action is the prompt's
    # default, and it renames the tree and its reference.
    assert ev["fix"]["offered"][0] == FIX_TITLE, why
    assert ev["fix"]["text"] == TREE.replace("Main Tree", "Main_Tree"), why
