"""All diagnostics of a document: its own (cached on it) plus the BehaviorTree.CPP
semantic rules, which also see the rest of the workspace through a context."""

from __future__ import annotations

from bt_lsp.diagnostics import Diagnostic
from bt_lsp.document import Document


def analyze(doc: Document) -> list[Diagnostic]:
    return list(doc.diagnostics)
