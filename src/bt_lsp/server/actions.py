"""textDocument/codeAction and codeAction/resolve: quick fixes and fix-all.

Fix-all (``source.fixAll.bt-lsp``) applies the safe fixes, as ``bt-lsp check --fix`` does
(:func:`bt_lsp.ide.fix_all.fix_document`); a quick fix that is not safe says so in its
title, ``(unsafe)``, as ruff's do.

Fixes come from the server's own diagnostics in the requested range, never from the
client's copies (Neovim 0.7 sends byte columns there).  When the client can resolve
edits lazily, actions carry only a reference to their fix and the edit is built on
``codeAction/resolve``.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any

from lsprotocol import types
from pygls.uris import from_fs_path

from bt_lsp.ide import semantic_fixes
from bt_lsp.ide.fix_all import fix_document, has_bulk_fix
from bt_lsp.ide.name_fixes import Fix, fixes_for_name
from bt_lsp.project.index import normalize
from bt_lsp.rules.context import Context
from bt_lsp.rules.diagnostics import Diagnostic
from bt_lsp.server.convert import to_diagnostic, to_offsets, to_text_edits, workspace_edit
from bt_lsp.server.state import OpenDocument
from bt_lsp.syntax.document import Document
from bt_lsp.syntax.edits import TextEdit

if TYPE_CHECKING:
    from bt_lsp.server.app import BtServer

FIX_ALL_KIND = "source.fixAll.bt-lsp"
FIX_ALL_TITLE = "Apply all safe bt-lsp fixes"


def action_title(fix: Fix) -> str:
    """A quick fix's title as the editor shows it: ``(unsafe)`` after one that fix-all and
    ``check --fix`` do not apply."""
    return fix.title if fix.safe else f"{fix.title} (unsafe)"


def _wants(only: Sequence[str] | None, kind: str) -> bool:
    """Whether a requested ``only`` list admits ``kind`` (kinds are dot-separated
    hierarchies: ``source.fixAll`` admits ``source.fixAll.bt-lsp``)."""
    if not only:
        return True
    return any(kind == k or kind.startswith(k + ".") for k in only)


def _workspace_edit(
    ls: BtServer,
    od: OpenDocument,
    edits: Sequence[TextEdit],
    other_edits: Mapping[str, Sequence[TextEdit]] | None = None,
    what: str = "the fix",
) -> types.WorkspaceEdit:
    """One edit for the document and, by path, for other workspace files (converted with
    their own line index; versioned when they are open in the editor)."""
    enc = ls.encoding
    per_uri: list[tuple[str, int | None, list[types.TextEdit]]] = [
        (od.uri, od.version, to_text_edits(od.doc.lines, edits, enc))
    ]
    for path, file_edits in (other_edits or {}).items():
        doc = ls.project.document(normalize(path))
        if doc is None:
            continue
        uri = from_fs_path(path) or path
        open_doc = ls.get(uri)
        version = open_doc.version if open_doc is not None else None
        per_uri.append((uri, version, to_text_edits(doc.lines, file_edits, enc)))
    return workspace_edit(per_uri, ls.versioned_edits, ls.annotated_edits, what)


def _others(ls: BtServer, od: OpenDocument) -> dict[str, Document]:
    return ls.project.other_documents(normalize(od.path)) if od.path is not None else {}


def _context(ls: BtServer, od: OpenDocument) -> Context:
    if od.path is not None:
        return ls.project.context_for(od.path, od.doc)
    return Context.from_document(od.doc)


def _all_fixes(ls: BtServer, od: OpenDocument, diag: Diagnostic) -> list[Fix]:
    ctx = _context(ls, od)
    fixes = fixes_for_name(od.doc, diag, _others(ls, od), ctx.models)
    if not diag.is_name_rule:
        fixes += semantic_fixes.fixes_for_rule(od.doc, ctx, diag)
    return fixes


def _fix_all_edit(ls: BtServer, od: OpenDocument) -> types.WorkspaceEdit:
    """Every safe fix of the document, as ``check --fix`` makes them; a tree defined here
    is renamed in the other files that call it too (those edits need confirmation where
    the client can)."""
    fixed = fix_document(od.doc, _context(ls, od), ls.diagnostics.of(od), _others(ls, od))
    return _workspace_edit(ls, od, fixed.edits, fixed.other_edits, FIX_ALL_TITLE)


def register(server: BtServer) -> None:
    @server.feature(
        types.TEXT_DOCUMENT_CODE_ACTION,
        types.CodeActionOptions(
            code_action_kinds=[types.CodeActionKind.QuickFix, FIX_ALL_KIND],
            resolve_provider=True,
        ),
    )
    async def code_action(
        ls: BtServer, params: types.CodeActionParams
    ) -> list[types.CodeAction | types.Command] | None:
        od = ls.get(params.text_document.uri)
        if od is not None:
            await ls.diagnostics.analysed(od)  # a large document on the worker thread
            od = ls.get(params.text_document.uri)
        if od is None or not od.is_bt:
            return []
        enc = ls.encoding
        lines = od.doc.lines
        start, end = to_offsets(lines, params.range, enc)
        only = params.context.only
        diags = ls.diagnostics.of(od)
        actions: list[types.CodeAction | types.Command] = []
        # A name that breaks several rules has one diagnostic per rule, all with the same
        # fixes: offer each fix once, listing every diagnostic it fixes.
        same_fix: dict[tuple[int, int, str], list[types.Diagnostic]] = {}
        if _wants(only, types.CodeActionKind.QuickFix):
            for d in diags:
                if d.start > end or d.end < start:
                    continue
                for i, fix in enumerate(_all_fixes(ls, od, d)):
                    fixed = same_fix.get((d.start, d.end, fix.title))
                    if fixed is not None:
                        fixed.append(to_diagnostic(lines, d, enc, ls.code_descriptions))
                        continue
                    fixed = same_fix[(d.start, d.end, fix.title)] = [
                        to_diagnostic(lines, d, enc, ls.code_descriptions)
                    ]
                    action = types.CodeAction(
                        title=action_title(fix),
                        kind=types.CodeActionKind.QuickFix,
                        diagnostics=fixed,
                        is_preferred=fix.preferred,
                    )
                    if ls.resolve_edits:
                        action.data = {
                            "uri": od.uri,
                            "version": od.version,
                            "start": d.start,
                            "end": d.end,
                            "code": d.code,
                            "index": i,
                        }
                    else:
                        action.edit = _workspace_edit(
                            ls, od, fix.edits, fix.other_edits, action_title(fix)
                        )
                    actions.append(action)
        if _wants(only, FIX_ALL_KIND) and any(has_bulk_fix(d) for d in diags):
            action = types.CodeAction(title=FIX_ALL_TITLE, kind=FIX_ALL_KIND)
            if ls.resolve_edits:
                action.data = {"uri": od.uri, "version": od.version, "fixAll": True}
            else:
                action.edit = _fix_all_edit(ls, od)
            actions.append(action)
        return actions

    @server.feature(types.CODE_ACTION_RESOLVE)
    async def resolve(ls: BtServer, action: types.CodeAction) -> types.CodeAction:
        data: Any = action.data
        if not isinstance(data, dict):
            return action
        od = ls.get(str(data.get("uri")))
        if od is not None:
            await ls.diagnostics.analysed(od)  # a large document on the worker thread
            od = ls.get(str(data.get("uri")))
        if od is None or od.version != data.get("version"):
            return action  # the document changed; the client asks again
        if data.get("fixAll"):
            action.edit = _fix_all_edit(ls, od)
            return action
        for d in ls.diagnostics.of(od):
            if (d.start, d.end, d.code) == (data.get("start"), data.get("end"), data.get("code")):
                fixes = _all_fixes(ls, od, d)
                index = data.get("index")
                if isinstance(index, int) and 0 <= index < len(fixes):
                    fix = fixes[index]
                    action.edit = _workspace_edit(
                        ls, od, fix.edits, fix.other_edits, action_title(fix)
                    )
                break
        return action
