"""textDocument/completion: node types, ports, reserved attributes, tree IDs, blackboard
keys (see :mod:`bt_lsp.ide.completion`), as snippets when the client takes them."""

from __future__ import annotations

from typing import TYPE_CHECKING

from lsprotocol import types

from bt_lsp.ide.completion import ItemKind, complete
from bt_lsp.server.lookup import at_position

if TYPE_CHECKING:
    from bt_lsp.server.app import BtServer

TRIGGER_CHARACTERS = ["<", "/", "{", '"', "'"]

_KINDS = {
    ItemKind.ELEMENT: types.CompletionItemKind.Keyword,
    ItemKind.NODE: types.CompletionItemKind.Class,
    ItemKind.SUBTREE: types.CompletionItemKind.Module,
    ItemKind.ATTRIBUTE: types.CompletionItemKind.Property,
    ItemKind.PORT: types.CompletionItemKind.Field,
    ItemKind.TREE: types.CompletionItemKind.Module,
    ItemKind.MODEL: types.CompletionItemKind.Class,
    ItemKind.KEY: types.CompletionItemKind.Variable,
    ItemKind.VALUE: types.CompletionItemKind.Value,
}


def _item_caps(ls: BtServer) -> types.ClientCompletionItemOptions | None:
    try:
        caps = ls.client_capabilities
    except Exception:  # before initialize
        return None
    td = caps.text_document
    return td.completion.completion_item if td and td.completion else None


def register(server: BtServer) -> None:
    @server.feature(
        types.TEXT_DOCUMENT_COMPLETION,
        types.CompletionOptions(trigger_characters=TRIGGER_CHARACTERS),
    )
    def completion(ls: BtServer, params: types.CompletionParams) -> types.CompletionList | None:
        req = at_position(ls, params)
        if req is None:
            return None
        found = complete(req.doc, req.offset, req.context())
        if found is None:
            return types.CompletionList(is_incomplete=False, items=[])
        rng = req.range(found.start, found.end)
        item_caps = _item_caps(ls)
        snippets = bool(item_caps and item_caps.snippet_support)
        formats = (item_caps.documentation_format if item_caps else None) or []
        markdown = types.MarkupKind.Markdown in formats
        # The line break before an existing tag only where the client inserts it as it is
        # (else it would indent the tag's line twice); without it, on the tag's line.
        modes = item_caps.insert_text_mode_support if item_caps else None
        as_is = bool(found.trail) and bool(modes and types.InsertTextMode.AsIs in modes.value_set)
        items: list[types.CompletionItem] = []
        for it in found.items:
            use_snippet = snippets and it.snippet is not None
            new_text = it.snippet if use_snippet and it.snippet is not None else it.insert
            if as_is:
                new_text += ("$0" if use_snippet and "$0" not in new_text else "") + found.trail
            items.append(
                types.CompletionItem(
                    label=it.label,
                    kind=_KINDS[it.kind],
                    detail=it.detail or None,
                    documentation=(
                        types.MarkupContent(kind=types.MarkupKind.Markdown, value=it.documentation)
                        if markdown
                        else it.documentation
                    )
                    if it.documentation
                    else None,
                    sort_text=it.sort or None,
                    filter_text=it.filter,
                    insert_text_format=types.InsertTextFormat.Snippet
                    if use_snippet
                    else types.InsertTextFormat.PlainText,
                    text_edit=types.TextEdit(range=rng, new_text=new_text),
                    insert_text_mode=types.InsertTextMode.AsIs if as_is else None,
                )
            )
        return types.CompletionList(is_incomplete=found.incomplete, items=items)
