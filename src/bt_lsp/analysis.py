"""All diagnostics of a document: its own (cached on it) plus the BehaviorTree.CPP
semantic rules, which also see the rest of the workspace through a context."""

from __future__ import annotations

from bt_lsp import semantics
from bt_lsp.bulk import in_bulk
from bt_lsp.context import Context
from bt_lsp.diagnostics import Diagnostic, limited
from bt_lsp.document import Document


@in_bulk
def analyze(doc: Document, ctx: Context | None = None) -> list[Diagnostic]:
    """The document's own diagnostics and the semantic ones, sorted by (start, end, code).

    Without ``ctx`` the document is checked as if it were alone
    (:meth:`Context.from_document`).
    """
    out = list(doc.diagnostics)
    out.extend(semantics.check(doc, ctx if ctx is not None else Context.from_document(doc)))
    out.sort(key=lambda d: (d.start, d.end, d.code))
    return limited(out)
