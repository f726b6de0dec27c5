"""Every fix of a document at once, as fix-all and ``bt-lsp check --fix`` apply them.

The name fixes are planned together (one new name per symbol, see
:func:`bt_lsp.ide.name_fixes.fix_all`); every other diagnostic gets its first fix that
the run may apply: a safe one, or with ``unsafe`` an unsafe one too (never a fix that is
offered in the editor only).  A fix whose edits meet an edit already chosen is left for
the next run, so that no two fixes fight over one place.

Pure: these functions return edits; the front ends decide whether to apply them.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field

from bt_lsp.ide import name_fixes
from bt_lsp.ide.fix import Fix
from bt_lsp.ide.semantic_fixes import fixes_for_rule
from bt_lsp.rules.codes import Applicability, defined
from bt_lsp.rules.context import Context
from bt_lsp.rules.diagnostics import Diagnostic
from bt_lsp.syntax.document import Document
from bt_lsp.syntax.edits import TextEdit

__all__ = ["DocumentFixes", "applies", "fix_document", "has_bulk_fix", "rule_fixes"]


def applies(fix: Fix, unsafe: bool) -> bool:
    """Whether a run applies ``fix``: a safe one always, an unsafe one with ``unsafe``."""
    kind = fix.applicability
    return kind is Applicability.SAFE or (unsafe and kind is Applicability.UNSAFE)


def has_bulk_fix(diag: Diagnostic, unsafe: bool = False) -> bool:
    """Whether the code of ``diag`` has a fix that a run may apply (cheap: no fix is
    made)."""
    kinds = {f.applicability for f in defined(diag.code).fixes.values()}
    return Applicability.SAFE in kinds or (unsafe and Applicability.UNSAFE in kinds)


def _meets(a: TextEdit, b: TextEdit) -> bool:
    """Whether two edits overlap, or insert at one place (their order would be a guess)."""
    return a.start == b.start or (a.start < b.end and b.start < a.end)


def rule_fixes(
    doc: Document,
    ctx: Context,
    diags: Iterable[Diagnostic],
    *,
    unsafe: bool = False,
    taken: Sequence[TextEdit] = (),
) -> list[Fix]:
    """The first fix a run applies of each diagnostic that is not a name rule's, in the
    document alone, none meeting another or an edit of ``taken``."""
    chosen: list[TextEdit] = list(taken)
    out: list[Fix] = []
    for d in diags:
        if d.is_name_rule or not has_bulk_fix(d, unsafe):
            continue
        fix = next((f for f in fixes_for_rule(doc, ctx, d) if applies(f, unsafe)), None)
        if fix is None or fix.other_edits or not fix.edits:
            continue
        if any(_meets(e, c) for e in fix.edits for c in chosen):
            continue
        chosen.extend(fix.edits)
        out.append(fix)
    return out


@dataclass(frozen=True, slots=True)
class DocumentFixes:
    """The edits of every fix a run applies to a document (``other_edits``: the name
    fixes' edits in other workspace files, by path), the fixes of the other rules among
    them, and the notes of what the name fixes left (see :class:`name_fixes.FixAll`)."""

    edits: list[TextEdit]
    rules: list[Fix] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    other_edits: Mapping[str, tuple[TextEdit, ...]] = field(default_factory=dict)


def fix_document(
    doc: Document,
    ctx: Context,
    diags: Sequence[Diagnostic],
    others: Mapping[str, Document] | None = None,
    *,
    unsafe: bool = False,
) -> DocumentFixes:
    """Every fix a run applies to ``doc``: the name fixes (renamed in the ``others`` too,
    see :func:`bt_lsp.ide.name_fixes.fix_all`), then the first applicable fix of each
    other diagnostic."""
    names = name_fixes.fix_all(doc, diags, others, ctx.models)
    rules = rule_fixes(doc, ctx, diags, unsafe=unsafe, taken=names.edits)
    edits = [*names.edits, *(e for f in rules for e in f.edits)]
    return DocumentFixes(edits, rules, names.notes, names.other_edits)
