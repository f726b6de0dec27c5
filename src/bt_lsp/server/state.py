"""What the server knows about one open document."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from bt_lsp.rules.diagnostics import Diagnostic
from bt_lsp.server.convert import DiagnosticJson
from bt_lsp.syntax.document import Document


@dataclass(slots=True)
class OpenDocument:
    uri: str
    doc: Document
    version: int | None
    language_id: str
    path: Path | None = None  # None for documents that are not files (untitled)
    is_bt: bool = False
    # Diagnostics cached for (version, settings generation, workspace generation).
    cache_key: tuple[int | None, int, int] | None = None
    cached: list[Diagnostic] = field(default_factory=list)
    published: DiagnosticJson = field(default_factory=DiagnosticJson)  # reused JSON
    folding: tuple[int | None, str] | None = None  # the folding ranges' JSON, by version

    def refresh_kind(self) -> None:
        self.is_bt = self.doc.is_bt
