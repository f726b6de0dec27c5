"""textDocument/hover: why a name breaks a rule, or what a name is."""

from __future__ import annotations

from typing import TYPE_CHECKING

from lsprotocol import types

from bt_lsp.ide.hover import hover_at, root_hover
from bt_lsp.server.convert import to_range
from bt_lsp.server.lookup import context_of, offset_of

if TYPE_CHECKING:
    from bt_lsp.server.app import BtServer


def register(server: BtServer) -> None:
    @server.feature(types.TEXT_DOCUMENT_HOVER)
    def hover(ls: BtServer, params: types.HoverParams) -> types.Hover | None:
        od = ls.get(params.text_document.uri)
        if od is None or not od.is_bt:
            return None
        enc = ls.encoding
        lines = od.doc.lines
        offset = offset_of(ls, od, params.position)
        found = hover_at(od.doc, offset, context_of(ls, od))
        if found is None and od.path is not None:
            detected = ls.project.btcpp_for(od.path, od.doc)
            found = root_hover(od.doc, offset, detected.version, detected.source)
        if found is None:
            return None
        learned = ls.cpp.hover_markdown(od, offset)  # where the C++ declares it
        markdown = found.markdown if learned is None else f"{found.markdown}\n\n{learned}"
        return types.Hover(
            contents=types.MarkupContent(kind=types.MarkupKind.Markdown, value=markdown),
            range=to_range(lines, found.start, found.end, enc),
        )
