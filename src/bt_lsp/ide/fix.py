"""A fix: titled edits that resolve a diagnostic, in its document and in other files."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

from bt_lsp.rules.diagnostics import Diagnostic
from bt_lsp.syntax.edits import TextEdit


@dataclass(frozen=True, slots=True)
class Fix:
    """A fix: edits to the document, and to other workspace files by path."""

    title: str
    edits: tuple[TextEdit, ...]
    preferred: bool
    diagnostic: Diagnostic
    other_edits: Mapping[str, tuple[TextEdit, ...]] = field(default_factory=dict)

    @property
    def places(self) -> int:
        return len(self.edits) + sum(len(e) for e in self.other_edits.values())
