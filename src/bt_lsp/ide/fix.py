"""A fix: titled edits that resolve a diagnostic, in its document and in other files."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

from bt_lsp.rules.codes import Applicability
from bt_lsp.rules.diagnostics import Diagnostic
from bt_lsp.syntax.edits import TextEdit


@dataclass(frozen=True, slots=True)
class Fix:
    """A fix: edits to the document, and to other workspace files by path.

    ``applicability`` is the fix's class as its code defines it (see
    :class:`~bt_lsp.rules.codes.Applicability`); ``preferred`` marks the one fix of a
    diagnostic that the editor applies by default, always a safe one, so that it is the fix
    that fix-all and ``check --fix`` make too."""

    title: str
    edits: tuple[TextEdit, ...]
    preferred: bool
    diagnostic: Diagnostic
    other_edits: Mapping[str, tuple[TextEdit, ...]] = field(default_factory=dict)
    applicability: Applicability = Applicability.SAFE

    def __post_init__(self) -> None:
        if self.preferred and self.applicability is not Applicability.SAFE:
            raise ValueError(f"a preferred fix must be safe: {self.title!r}")

    @property
    def places(self) -> int:
        return len(self.edits) + sum(len(e) for e in self.other_edits.values())

    @property
    def safe(self) -> bool:
        return self.applicability is Applicability.SAFE
