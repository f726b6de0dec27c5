"""Document sync (open, incremental change, close) and pulled diagnostics."""

from __future__ import annotations

import json
from pathlib import Path
from typing import TYPE_CHECKING

from lsprotocol import types
from pygls.uris import to_fs_path

from bt_lsp.server.background import WORKER_CHARS
from bt_lsp.server.convert import RawJson, to_offsets
from bt_lsp.server.project import document_edited, is_project_file, sync_config_diagnostics
from bt_lsp.server.state import OpenDocument
from bt_lsp.syntax.document import Document

if TYPE_CHECKING:
    from bt_lsp.server.app import BtServer


def _opened(ls: BtServer, od: OpenDocument) -> None:
    ls.docs[od.uri] = od
    if od.path is not None:
        ls.project.open(od.path, od.doc)
    ls.cpp.document_changed(od)
    ls.edits += 1
    ls.publisher.schedule_all(od.uri)
    document_edited(ls, od, opened=True)


def _changed(ls: BtServer, od: OpenDocument, was_bt: bool) -> None:
    ls.cpp.document_changed(od)
    ls.edits += 1
    if was_bt and not od.is_bt:
        ls.publisher.clear(od.uri)
    ls.publisher.schedule_all(od.uri)
    document_edited(ls, od)


def register(server: BtServer) -> None:
    @server.feature(types.TEXT_DOCUMENT_DID_OPEN)
    def did_open(ls: BtServer, params: types.DidOpenTextDocumentParams) -> None:
        """A large document is prepared on the worker thread (its early name diagnostics
        pushed first): until it is ready the server knows it not, and holds the
        messages about it (see :mod:`bt_lsp.server.background`)."""
        item = params.text_document
        path = to_fs_path(item.uri) if item.uri.startswith("file:") else None
        od = OpenDocument(
            item.uri,
            Document(item.text, path or item.uri, scanned=False),
            item.version,
            item.language_id,
            Path(path) if path else None,
        )
        if not ls.background.prepare(od, lambda: _opened(ls, od)):  # which finds its kind
            od.refresh_kind()
            _opened(ls, od)

    @server.feature(types.TEXT_DOCUMENT_DID_CHANGE)
    def did_change(ls: BtServer, params: types.DidChangeTextDocumentParams) -> None:
        uri = params.text_document.uri
        od = ls.get(uri)
        if od is None:
            ls.log_message(f"bt-lsp: didChange for a document that is not open: {uri}")
            return
        enc = ls.encoding
        was_bt = od.is_bt
        for change in params.content_changes:
            if isinstance(change, types.TextDocumentContentChangePartial):
                start, end = to_offsets(od.doc.lines, change.range, enc)
                od.doc.edit(start, end, change.text)
            else:  # a large new text is scanned on the worker thread, not here
                od.doc.replace_all(change.text, scanned=len(change.text) < WORKER_CHARS)
        od.version = params.text_document.version
        if not od.doc.scanned and ls.background.prepare(od, lambda: _changed(ls, od, was_bt)):
            return  # (its kind found there too)
        od.refresh_kind()
        _changed(ls, od, was_bt)

    @server.feature(types.TEXT_DOCUMENT_DID_CLOSE)
    def did_close(ls: BtServer, params: types.DidCloseTextDocumentParams) -> None:
        uri = params.text_document.uri
        od = ls.docs.pop(uri, None)
        if od is not None:
            if od.path is not None:
                ls.project.close(od.path)  # from now on the file on disk counts
            ls.cpp.document_changed(od, closed=True)
            ls.publisher.clear(uri)
            document_edited(ls, od, closed=True)
            ls.publisher.schedule_all(uri)

    @server.feature(types.TEXT_DOCUMENT_DID_SAVE)
    def did_save(ls: BtServer, params: types.DidSaveTextDocumentParams) -> None:
        """A save writes the file the other documents may read from disk (a configuration
        file, a package.xml or a CMakeLists.txt among them)."""
        path = to_fs_path(params.text_document.uri)
        if path:
            ls.project.file_changed(path)
        ls.publisher.refresh_all()
        if path and is_project_file(Path(path)):
            sync_config_diagnostics(ls)

    @server.feature(
        types.TEXT_DOCUMENT_DIAGNOSTIC,
        types.DiagnosticOptions(
            identifier="bt-lsp", inter_file_dependencies=True, workspace_diagnostics=False
        ),
    )
    async def diagnostic(
        ls: BtServer, params: types.DocumentDiagnosticParams
    ) -> types.DocumentDiagnosticReport | RawJson:
        od = ls.get(params.text_document.uri)
        if od is not None:
            await ls.diagnostics.analysed(od)  # a large document on the worker thread
            od = ls.get(params.text_document.uri)
        if od is None:
            return types.RelatedFullDocumentDiagnosticReport(items=[], result_id=None)
        result_id = ls.diagnostics.result_id(od)
        if params.previous_result_id == result_id and od.cache_key is not None:
            return types.RelatedUnchangedDocumentDiagnosticReport(result_id=result_id)
        # A full report written as JSON, its items as a publication writes them.
        items = ls.diagnostics.as_json(od)
        return RawJson(f'{{"kind": "full", "resultId": {json.dumps(result_id)}, "items": {items}}}')
