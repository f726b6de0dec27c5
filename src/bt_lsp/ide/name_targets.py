"""Name diagnostics that say where a name must change first.

A bad name whose target is not in the workspace (a ``<SubTree ID>`` of a tree that no
workspace file defines, a node type registered in C++ or declared in an installed
catalog) cannot be fixed where it is: renamed alone, the reference would break (see
:func:`~bt_lsp.ide.name_edits.elsewhere`).  Its diagnostic says so in its own message, so
that a user who reads only the Problems list knows why no fix is applied and what to
rename first.

The name rules run per section, blind to the workspace; this adds the clause afterwards,
from the same test the fixes use, so that the message and the fixes always agree.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import replace
from typing import Final

from bt_lsp.ide.name_edits import Elsewhere, elsewhere
from bt_lsp.rules.context import ModelDecl, facts_of
from bt_lsp.rules.diagnostics import Diagnostic
from bt_lsp.syntax.document import Document
from bt_lsp.syntax.elements import NameSymbol, Symbol

__all__ = ["with_targets"]

_MAX_AMENDED: Final = 4096


def _amended(
    d: Diagnostic, clause: str, kept: dict[int, tuple[Diagnostic, str, Diagnostic]]
) -> Diagnostic:
    """``d`` with ``clause`` added, the same object as last time: amended diagnostics are
    ``kept`` by the identity of the original (with it, so that the identity stays
    valid), for the document: an unchanged section keeps its diagnostic objects, and the
    server writes a diagnostic's JSON once per object.  Bounded."""
    hit = kept.get(id(d))
    if hit is not None and hit[0] is d and hit[1] == clause:
        return hit[2]
    new = replace(d, message=f"{d.message}; {clause}")
    if len(kept) >= _MAX_AMENDED:
        kept.clear()
    kept[id(d)] = (d, clause, new)
    return new


def with_targets(
    doc: Document,
    diags: Sequence[Diagnostic],
    others: Mapping[str, Document] | None = None,
    registered: Mapping[str, ModelDecl] | None = None,
) -> list[Diagnostic]:
    """``diags`` of ``doc``, each name diagnostic on a reference whose target is outside the
    workspace (``doc`` and ``others``; ``registered``: the context's models) ending with
    where the name must change first.  The other diagnostics are the same objects."""
    out = list(diags)
    model = doc.model
    # What the workspace defines, from the declarations the context is made of (kept per
    # section), not from every name token of every document.
    ids: tuple[set[str], set[str]] | None = None

    def defined(owner: NameSymbol) -> bool:
        nonlocal ids
        if ids is None:
            facts = [facts_of(doc), *(facts_of(o) for o in (others or {}).values())]
            ids = ({t.id for f in facts for t in f.trees}, {m.id for f in facts for m in f.models})
        return owner.name in ids[0 if owner.kind == "tree" else 1]

    found: dict[Symbol, Elsewhere | None] = {}
    for i, d in enumerate(out):
        if not d.is_name_rule:
            continue
        ref = model.ref_at(d.start)
        if ref is None or ref.start != d.start or ref.end != d.end or ref.symbol is None:
            continue
        sym = ref.symbol
        if sym not in found:
            found[sym] = elsewhere(sym, (), registered, defined)
        away = found[sym]
        if away is not None and away.first:
            out[i] = _amended(d, away.first, _kept_amended(doc))
    return out


def _kept_amended(doc: Document) -> dict[int, tuple[Diagnostic, str, Diagnostic]]:
    """The amended diagnostics kept for ``doc`` (its history; written by the analysis
    that holds its lock)."""
    kept: dict[int, tuple[Diagnostic, str, Diagnostic]] | None = doc.history.memo.get("amended")
    if kept is None:
        kept = {}
        doc.history.memo["amended"] = kept
    return kept
