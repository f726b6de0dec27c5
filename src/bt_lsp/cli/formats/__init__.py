"""The output formats of ``bt-lsp check``, one module each."""

from __future__ import annotations

from typing import Final, Literal

Format = Literal["text", "json", "sarif"]
FORMATS: Final[tuple[Format, ...]] = ("text", "json", "sarif")
