"""All diagnostics of a document: its own (cached on it) plus the BehaviorTree.CPP
semantic rules, which also see the rest of the workspace through a context."""

from __future__ import annotations

from bt_lsp.rules import semantics
from bt_lsp.rules.context import Context
from bt_lsp.rules.diagnostics import Diagnostic, limited, more_of, own_diagnostics
from bt_lsp.syntax.document import Document


def analyze(doc: Document, ctx: Context | None = None) -> list[Diagnostic]:
    """The document's own diagnostics and the semantic ones, sorted by (start, end, code).

    Without ``ctx`` the document is checked as if it were alone
    (:meth:`Context.from_document`).
    """
    own = own_diagnostics(doc)
    found = semantics.check(doc, ctx if ctx is not None else Context.from_document(doc))
    out = [*own, *found]
    out.sort(key=lambda d: (d.start, d.end, d.code))
    return limited(out, more=more_of(own) + more_of(found))
