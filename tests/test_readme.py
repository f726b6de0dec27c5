"""The README's promises that can drift: the code table and the first-screen commands."""

from __future__ import annotations

from pathlib import Path

from bt_lsp.rules.codes import CODES

ROOT = Path(__file__).resolve().parent.parent
README = (ROOT / "README.md").read_text(encoding="utf-8")


def test_every_code_has_an_anchor_in_the_readme() -> None:
    for code in CODES:
        assert f'<a id="{code}"></a>`{code}`' in README, code


def test_first_screen_commands_exist() -> None:
    first_screen = "\n".join(README.splitlines()[:20])
    assert "pip install . && bt-lsp check examples/" in first_screen
    assert "bash scripts/test.sh" in first_screen
    assert (ROOT / "scripts" / "test.sh").exists()
    assert "bash scripts/test.sh" in (ROOT / ".ci" / "run").read_text(encoding="utf-8")
