"""Conversions between the core's code-point offsets and LSP positions and types."""

from __future__ import annotations

import json
from collections.abc import Iterable, Sequence
from itertools import chain
from urllib.parse import unquote

from lsprotocol import types
from pygls.uris import to_fs_path

from bt_lsp.rules.codes import FixData, Severity
from bt_lsp.rules.diagnostics import Diagnostic
from bt_lsp.rules.registry import CODES
from bt_lsp.syntax.edits import TextEdit
from bt_lsp.syntax.text import Encoding, LineIndex

# What a diagnostic's JSON says apart from its range.
_TailKey = tuple[str, str, Severity, FixData | None]


def to_range(lines: LineIndex, start: int, end: int, enc: Encoding) -> types.Range:
    sl, sc = lines.position(start, enc)
    el, ec = lines.position(end, enc)
    return types.Range(types.Position(sl, sc), types.Position(el, ec))


def to_ranges(
    lines: LineIndex, spans: Iterable[tuple[int, int]], enc: Encoding
) -> list[types.Range]:
    """:func:`to_range` of each of ``spans``, their positions found in one pass
    (:meth:`LineIndex.positions`): one at a time, each position counts its line from its
    start, and a name used a million times on one 8 MB line took minutes to convert."""
    spans = list(spans)
    at = lines.positions(chain.from_iterable(spans), enc)
    P, R = types.Position, types.Range
    return [R(P(*at[s]), P(*at[e])) for s, e in spans]


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


def to_text_edits(
    lines: LineIndex, edits: Sequence[TextEdit], enc: Encoding
) -> list[types.TextEdit]:
    """Each of ``edits`` as an LSP text edit (positions as :func:`to_ranges` finds them)."""
    ranges = to_ranges(lines, ((e.start, e.end) for e in edits), enc)
    return [
        types.TextEdit(range=r, new_text=e.new_text) for r, e in zip(ranges, edits, strict=True)
    ]


# The change annotations of the edits a fix or rename makes in files other than the one the
# user is in, one per file: clients that support annotations (VS Code) show those edits in
# a preview, grouped under the file's annotation, to be confirmed before they are written.
OTHER_FILES = "bt-lsp.other-files"


def _file_name(uri: str) -> str:
    return unquote(uri.rstrip("/").rsplit("/", 1)[-1]) or uri


def workspace_edit(
    per_uri: list[tuple[str, int | None, list[types.TextEdit]]],
    versioned: bool,
    annotated: bool = False,
    what: str = "the rename",
) -> types.WorkspaceEdit:
    """Edits to several documents as one WorkspaceEdit: versioned ``documentChanges`` when
    the client supports them (it then refuses edits to a document that has moved on),
    else plain ``changes``.  The first entry is the document the user is in; with
    ``annotated`` (the client supports change annotations) the edits of each other
    document carry an annotation of their own that needs confirmation, saying which file
    it is and why it changes: ``what`` (``"Rename 'a b' to 'a_b' (3 places, 1 other
    file)"``) renames the same name there."""
    if versioned:
        changes: list[types.TextDocumentEdit] = []
        annotations: dict[str, types.ChangeAnnotation] = {}
        for i, (uri, version, lsp_edits) in enumerate(per_uri):
            edits: list[types.TextEdit | types.AnnotatedTextEdit | types.SnippetTextEdit]
            if annotated and i > 0 and lsp_edits:
                key = f"{OTHER_FILES}.{i}"
                name = _file_name(uri)
                annotations[key] = types.ChangeAnnotation(
                    label=f"Other file: {name}",
                    needs_confirmation=True,
                    description=(
                        f"{what}: {name} uses the same name, so its references there are "
                        f"renamed too ({len(lsp_edits)} edit{'s' if len(lsp_edits) != 1 else ''}"
                        f" in {to_fs_path(uri) or unquote(uri)}, not the file you are in)"
                    ),
                )
                edits = [
                    types.AnnotatedTextEdit(range=e.range, new_text=e.new_text, annotation_id=key)
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
            document_changes=list(changes), change_annotations=annotations or None
        )
    return types.WorkspaceEdit(changes={uri: list(e) for uri, _, e in per_uri})


class RawJson(str):
    """A result that is already JSON text: written into the response as it is (see
    :meth:`bt_lsp.server.protocol.BtProtocol._send_data`)."""


class DiagnosticJson:
    """LSP diagnostics written as JSON text directly, for publication.

    Converting every diagnostic to lsprotocol objects and unstructuring them again on each
    edit cost most of a publication (2,000 diagnostics of a 200 KB document: 157 ms).
    The part of a diagnostic that does not move with edits (message, code, severity,
    data) is written once and reused for as long as a diagnostic with the same content
    is published: the core makes its diagnostics anew in document coordinates on every
    version, but those of an unchanged section keep their content, so an edit writes only
    the parts of the diagnostics it changed.  The range is written each time, its
    positions found in one pass (:meth:`LineIndex.positions`).  ``converted`` counts the
    parts written (what reuse saves)."""

    def __init__(self) -> None:
        self._tails: dict[_TailKey, str] = {}
        self.described = True  # with codeDescription links (the client shows them)
        self.converted = 0

    def tail(self, d: Diagnostic) -> str:
        key = (d.code, d.message, d.severity, d.data)
        kept = self._tails.get(key)
        if kept is not None:
            return kept
        info = CODES.get(d.code) if self.described else None
        fields: dict[str, object] = {
            "message": d.message,
            "severity": int(d.severity),
            "code": d.code,
            "source": "bt-lsp",
        }
        if info:
            fields["codeDescription"] = {"href": info.url}
        if d.data is not None:
            fields["data"] = d.data.as_json()
        text = json.dumps(fields)[1:]  # without its "{": it follows the range
        self._tails[key] = text
        self.converted += 1
        return text

    def array(
        self, lines: LineIndex, diags: list[Diagnostic], enc: Encoding, described: bool = True
    ) -> str:
        """The JSON array of ``diags``; forgets the parts of diagnostics not among them."""
        if described != self.described:
            self._tails.clear()
            self.described = described
        at = lines.positions([o for d in diags for o in (d.start, d.end)], enc)
        tail = self.tail
        parts = []
        for d in diags:
            (sl, sc), (el, ec) = at[d.start], at[d.end]
            parts.append(
                f'{{"range": {{"start": {{"line": {sl}, "character": {sc}}}, '
                f'"end": {{"line": {el}, "character": {ec}}}}}, {tail(d)}'
            )
        if len(self._tails) > len(diags):
            keep = {(d.code, d.message, d.severity, d.data) for d in diags}
            self._tails = {k: v for k, v in self._tails.items() if k in keep}
        return "[" + ", ".join(parts) + "]"
