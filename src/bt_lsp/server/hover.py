"""textDocument/hover: why a name breaks a rule, what a name is, or where a blackboard key
is written and read; in the markup the client asks for first."""

from __future__ import annotations

import re
from typing import TYPE_CHECKING

from lsprotocol import types

from bt_lsp.ide.hover import hover_at, root_hover
from bt_lsp.project.index import normalize
from bt_lsp.server.lookup import at_position

# Inline code in the C++ catalog's Markdown, written as quotes for plain-text clients.
_INLINE_CODE_RE = re.compile(r"`([^`]*)`")

if TYPE_CHECKING:
    from bt_lsp.server.app import BtServer


def wants_markdown(caps: types.ClientCapabilities | None) -> bool:
    """Whether the client's ``textDocument.hover.contentFormat`` puts Markdown first
    (a client that declares no format gets Markdown, as the protocol's default)."""
    td = caps.text_document if caps is not None else None
    formats = td.hover.content_format if td is not None and td.hover is not None else None
    if not formats:
        return True
    return formats[0] == types.MarkupKind.Markdown


def register(server: BtServer) -> None:
    @server.feature(types.TEXT_DOCUMENT_HOVER)
    def hover(ls: BtServer, params: types.HoverParams) -> types.Hover | None:
        req = at_position(ls, params)
        if req is None:
            return None
        od, offset = req.od, req.offset
        others = ls.project.other_documents(normalize(od.path)) if od.path is not None else {}
        try:
            caps: types.ClientCapabilities | None = ls.client_capabilities
        except Exception:  # before initialize
            caps = None
        markdown = wants_markdown(caps)
        found = hover_at(od.doc, offset, req.context(), others, markdown=markdown)
        if found is None and od.path is not None:
            detected = ls.project.btcpp_for(od.path, od.doc)
            found = root_hover(
                od.doc, offset, detected.version, detected.source, markdown, detected.conflict
            )
        live = ls.live.hover(od, offset, markdown) if ls.live is not None else None
        if found is None:
            if live is None:
                return None
            text, start, end = live
            kind = types.MarkupKind.Markdown if markdown else types.MarkupKind.PlainText
            return types.Hover(
                contents=types.MarkupContent(kind=kind, value=text), range=req.range(start, end)
            )
        learned = ls.cpp.hover_markdown(od, offset, found.markdown)  # where the C++ declares it
        text = found.text
        if learned is not None:
            if not found.markdown:
                learned = _INLINE_CODE_RE.sub(r"'\1'", learned)
            text = f"{text}\n\n{learned}"
        if live is not None:  # (written in the markup the client asked for, as found is)
            text = f"{text}\n\n{live[0]}"
        kind = types.MarkupKind.Markdown if found.markdown else types.MarkupKind.PlainText
        return types.Hover(
            contents=types.MarkupContent(kind=kind, value=text),
            range=req.range(found.start, found.end),
        )
