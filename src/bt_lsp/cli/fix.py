"""``bt-lsp check --fix``: the fixed text of a file, or why it is left as it was.

A file is written only when every fix applies, its encoding round-trips, the fixes add
no XML problem, leave no name problem where they edited, add none elsewhere, and keep a
well-formed file well-formed."""

from __future__ import annotations

from bisect import bisect_right
from collections import Counter
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass

from bt_lsp.cli.results import file_diagnostics
from bt_lsp.ide.fix_all import applies, has_bulk_fix
from bt_lsp.ide.fix_all import fix_document as plan_fixes
from bt_lsp.ide.name_fixes import fixes_for_name
from bt_lsp.ide.semantic_fixes import fixes_for_rule
from bt_lsp.project.fileio import Decoded
from bt_lsp.project.index import ProjectIndex, normalize
from bt_lsp.rules.codes import XML, defined
from bt_lsp.rules.context import Context
from bt_lsp.rules.diagnostics import Diagnostic
from bt_lsp.syntax.document import Document
from bt_lsp.syntax.edits import TextEdit, apply_edits


def _new_spans(edits: Sequence[TextEdit]) -> list[tuple[int, int]]:
    """Where each edit's new text lies in the edited text."""
    spans: list[tuple[int, int]] = []
    shift = 0
    for e in sorted(edits):
        start = e.start + shift
        spans.append((start, start + len(e.new_text)))
        shift += len(e.new_text) - (e.end - e.start)
    return spans


def _touches(d: Diagnostic, spans: Sequence[tuple[int, int]], starts: Sequence[int]) -> bool:
    """Whether ``d`` overlaps or touches one of ``spans`` (sorted, disjoint; ``starts``
    are their starts)."""
    i = bisect_right(starts, d.end) - 1
    return i >= 0 and spans[i][1] >= d.start


def _xml_counts(diags: Iterable[Diagnostic]) -> Counter[str]:
    return Counter(d.code for d in diags if defined(d.code).family == XML)


def _well_formed(data: bytes) -> bool:
    from lxml import etree

    # Nothing is expanded, loaded or fetched; libxml2's default size limits stay on.
    parser = etree.XMLParser(
        resolve_entities=False,
        no_network=True,
        load_dtd=False,
        dtd_validation=False,
        huge_tree=False,
    )
    try:
        etree.fromstring(data, parser)
    except etree.LxmlError:
        return False
    return True


@dataclass(frozen=True, slots=True)
class Fixed:
    doc: Document
    raw: list[Diagnostic]
    notes: list[str]


def fix_document(
    decoded: Decoded,
    doc: Document,
    raw: list[Diagnostic],
    diags: list[Diagnostic],
    project: ProjectIndex | None = None,
    others: Mapping[str, Document] | None = None,
    unsafe: bool = False,
) -> Fixed | str | None:
    """The fixed document, or why the file cannot be fixed safely (``None``: nothing to
    fix): every safe fix (with ``unsafe``, the unsafe ones too).  ``others`` are the other
    files of the workspace as they were before any was fixed: a name is renamed only with
    its target."""
    ctx = context_of(doc, project)
    planned = plan_fixes(doc, ctx, diags, others, unsafe=unsafe)
    return apply_fixes(decoded, doc, raw, planned.edits, planned.notes, project)


def fixability(
    doc: Document, project: ProjectIndex | None, unsafe: bool = False
) -> Callable[[Diagnostic], bool]:
    """Whether a fix that ``--fix`` (with ``unsafe``, ``--fix --unsafe-fixes``) applies
    fixes a diagnostic of ``doc``: the ``[*]`` of ``--statistics``."""
    ctx = context_of(doc, project)
    others = (
        project.other_documents(normalize(doc.path))
        if project is not None and doc.path is not None
        else {}
    )

    def fixable(d: Diagnostic) -> bool:
        if not has_bulk_fix(d, unsafe):
            return False
        found = (
            fixes_for_name(doc, d, others, ctx.models)
            if d.is_name_rule
            else fixes_for_rule(doc, ctx, d)
        )
        return any(applies(f, unsafe) for f in found)

    return fixable


def context_of(doc: Document, project: ProjectIndex | None) -> Context:
    """What the rules knew of ``doc``'s surroundings when they checked it."""
    if project is not None and doc.path is not None:
        return project.context_for(normalize(doc.path), doc)
    return Context.from_document(doc)


def apply_fixes(
    decoded: Decoded,
    doc: Document,
    raw: list[Diagnostic],
    edits: list[TextEdit],
    notes: list[str],
    project: ProjectIndex | None = None,
) -> Fixed | str | None:
    """``doc`` with ``edits`` applied, or why they cannot be applied safely (``None``:
    nothing to change); ``raw`` are its diagnostics before, ``notes`` what the fixes left."""
    if not edits:
        return None
    if not decoded.lossless:
        return f"{decoded.encoding.upper()} does not round-trip its bytes"
    try:
        new_text = apply_edits(doc.text, edits)
    except ValueError as e:
        return f"the fixes overlap ({e})"
    if new_text == doc.text:
        return None
    try:
        new_bytes = decoded.encode(new_text)
    except UnicodeEncodeError as e:
        char = e.object[e.start]
        return f"U+{ord(char):04X} cannot be written in {decoded.encoding.upper()}"
    new_doc = Document(new_text, doc.path)
    new_raw = file_diagnostics(new_doc, project)
    before, after = _xml_counts(raw), _xml_counts(new_raw)
    worse = sorted(code for code in after if after[code] > before[code])
    if worse:
        return f"the fixes would add {', '.join(worse)} problems"
    old_spans = [(e.start, e.end) for e in sorted(edits)]
    old_starts = [start for start, _ in old_spans]
    new_spans = _new_spans(edits)
    new_starts = [start for start, _ in new_spans]
    left = [d for d in new_raw if d.is_name_rule and _touches(d, new_spans, new_starts)]
    if left:
        line, col = new_doc.lines.position(left[0].start, "utf-32")
        return f"the fixes would leave {left[0].code} at {line + 1}:{col + 1}"
    old_elsewhere = sum(1 for d in raw if d.is_name_rule and not _touches(d, old_spans, old_starts))
    new_elsewhere = sum(
        1 for d in new_raw if d.is_name_rule and not _touches(d, new_spans, new_starts)
    )
    if new_elsewhere > old_elsewhere:
        return "the fixes would add name problems elsewhere"
    if _well_formed(decoded.encode(doc.text)) and not _well_formed(new_bytes):
        return "the fixed file would not be well-formed XML"
    return Fixed(new_doc, new_raw, notes)
