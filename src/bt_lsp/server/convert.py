"""Conversions between the core's code-point offsets and LSP positions and types."""

from __future__ import annotations

from lsprotocol import types

from bt_lsp.rules.diagnostics import Diagnostic
from bt_lsp.rules.registry import CODES
from bt_lsp.syntax.edits import TextEdit
from bt_lsp.syntax.text import Encoding, LineIndex


def to_range(lines: LineIndex, start: int, end: int, enc: Encoding) -> types.Range:
    sl, sc = lines.position(start, enc)
    el, ec = lines.position(end, enc)
    return types.Range(types.Position(sl, sc), types.Position(el, ec))


def to_offsets(lines: LineIndex, rng: types.Range, enc: Encoding) -> tuple[int, int]:
    start = lines.offset(rng.start.line, rng.start.character, enc)
    end = lines.offset(rng.end.line, rng.end.character, enc)
    return (start, end) if start <= end else (end, start)


def to_diagnostic(
    lines: LineIndex, d: Diagnostic, enc: Encoding, described: bool = True
) -> types.Diagnostic:
    return diagnostic_at(to_range(lines, d.start, d.end, enc), d, described)


def diagnostic_at(rng: types.Range, d: Diagnostic, described: bool = True) -> types.Diagnostic:
    """``d`` as an LSP diagnostic over ``rng`` (its offsets converted by the caller), with
    a link to its code's documentation when ``described`` (the client declared
    ``codeDescriptionSupport``)."""
    info = CODES.get(d.code) if described else None
    return types.Diagnostic(
        range=rng,
        message=d.message,
        severity=types.DiagnosticSeverity(int(d.severity)),
        code=d.code,
        code_description=types.CodeDescription(href=info.url) if info else None,
        source="bt-lsp",
        data=d.data.as_json() if d.data is not None else None,
    )


def to_text_edit(lines: LineIndex, e: TextEdit, enc: Encoding) -> types.TextEdit:
    return types.TextEdit(range=to_range(lines, e.start, e.end, enc), new_text=e.new_text)


# The change annotation of the edits a fix or rename makes in files other than the one the
# user is in: clients that support annotations (VS Code) show those edits in a preview to be
# confirmed before they write the other files.
OTHER_FILES = "bt-lsp.other-files"


def workspace_edit(
    per_uri: list[tuple[str, int | None, list[types.TextEdit]]],
    versioned: bool,
    annotated: bool = False,
) -> types.WorkspaceEdit:
    """Edits to several documents as one WorkspaceEdit: versioned ``documentChanges`` when
    the client supports them (it then refuses edits to a document that has moved on),
    else plain ``changes``.  The first entry is the document the user is in; with
    ``annotated`` (the client supports change annotations) the edits of the other
    documents carry an annotation that needs confirmation."""
    if versioned:
        changes: list[types.TextDocumentEdit] = []
        others = False
        for i, (uri, version, lsp_edits) in enumerate(per_uri):
            edits: list[types.TextEdit | types.AnnotatedTextEdit | types.SnippetTextEdit]
            if annotated and i > 0 and lsp_edits:
                others = True
                edits = [
                    types.AnnotatedTextEdit(
                        range=e.range, new_text=e.new_text, annotation_id=OTHER_FILES
                    )
                    for e in lsp_edits
                ]
            else:
                edits = list(lsp_edits)
            changes.append(
                types.TextDocumentEdit(
                    text_document=types.OptionalVersionedTextDocumentIdentifier(
                        uri=uri, version=version
                    ),
                    edits=edits,
                )
            )
        return types.WorkspaceEdit(
            document_changes=list(changes),
            change_annotations={
                OTHER_FILES: types.ChangeAnnotation(
                    label="Other files",
                    needs_confirmation=True,
                    description="bt-lsp renames the same name in files other than this one",
                )
            }
            if others
            else None,
        )
    return types.WorkspaceEdit(changes={uri: list(e) for uri, _, e in per_uri})
