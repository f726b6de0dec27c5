"""The README's promises that can drift: the code table and the first-screen commands."""

from __future__ import annotations

import importlib.util
from pathlib import Path

from bt_lsp.rules.registry import CODES

ROOT = Path(__file__).resolve().parent.parent
README = (ROOT / "README.md").read_text(encoding="utf-8")


def test_every_code_has_an_anchor_in_the_readme() -> None:
    for code in CODES:
        assert f'<a id="{code}"></a>`{code}`' in README, code


def test_readme_code_table_is_the_registry() -> None:
    """The README's code section is exactly what ``scripts/codes_doc.py`` makes of the
    registry: a code added, removed or changed there without ``--write`` fails here."""
    spec = importlib.util.spec_from_file_location("codes_doc", ROOT / "scripts" / "codes_doc.py")
    assert spec is not None and spec.loader is not None
    codes_doc = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(codes_doc)
    assert codes_doc.section() in README


def test_first_screen_commands_exist() -> None:
    first_screen = "\n".join(README.splitlines()[:20])
    assert "pip install . && bt-lsp check examples/" in first_screen
    assert "bash scripts/test.sh" in first_screen
    assert (ROOT / "scripts" / "test.sh").exists()
    assert "bash scripts/test.sh" in (ROOT / ".ci" / "run").read_text(encoding="utf-8")
