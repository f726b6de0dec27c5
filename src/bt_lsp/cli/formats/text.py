"""The ``text`` format: ``path:line:col: severity code message``, one line per
diagnostic."""

from __future__ import annotations

import unicodedata
from collections.abc import Iterable, Iterator

from bt_lsp.cli.results import Finding


def visible(text: str) -> str:
    """``text`` on one line with control characters written as ``U+XXXX``, so that a
    message can never move the cursor or change the terminal."""
    if text.isprintable():
        return text
    return "".join(
        f"U+{ord(c):04X}" if unicodedata.category(c) in ("Cc", "Zl", "Zp") else c for c in text
    )


def format_text(findings: Iterable[Finding]) -> Iterator[str]:
    for f in findings:
        yield (
            f"{visible(f.path)}:{f.line}:{f.column}: "
            f"{f.severity.label} {f.code} {visible(f.message)}"
        )
