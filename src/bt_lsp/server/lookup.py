"""The workspace as the request handlers see it: the preamble of a position-based request
(:func:`at_position`), and for navigation the open documents first, files after.

Every other BT document is keyed by its path (its URI when it is not a file), with the URI,
text and version to answer with.  An open document's text wins over the file on disk, so
offsets computed on it are converted with its own line index.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Protocol

from lsprotocol import types
from pygls.uris import from_fs_path, to_fs_path

from bt_lsp.project.index import Include, normalize
from bt_lsp.rules.context import Context
from bt_lsp.server.convert import to_range
from bt_lsp.server.state import OpenDocument
from bt_lsp.syntax.document import Document
from bt_lsp.syntax.text import Encoding

if TYPE_CHECKING:
    from bt_lsp.server.app import BtServer


@dataclass(frozen=True, slots=True)
class Source:
    """A document to answer about: where it is, its text and (when open) its version."""

    uri: str
    doc: Document
    version: int | None


def offset_of(ls: BtServer, od: OpenDocument, pos: types.Position) -> int:
    """The code-point offset of a position in the client's encoding."""
    return od.doc.lines.offset(pos.line, pos.character, ls.encoding)


class AtPosition(Protocol):
    """The parameters of a request at a position (``textDocument/definition``, ``hover``,
    ``completion``, ...): lsprotocol gives them no common base."""

    @property
    def text_document(self) -> types.TextDocumentIdentifier: ...

    @property
    def position(self) -> types.Position: ...


class PositionRequest:
    """A request at a position of an open BT document, its shared look-up done once: the
    document, the cursor as a code-point offset (the position read with the document's
    line index in the negotiated encoding), the encoding to answer in, and the document's
    context, made on first use (some requests never need it)."""

    __slots__ = ("_ctx", "enc", "ls", "od", "offset")

    def __init__(self, ls: BtServer, od: OpenDocument, offset: int) -> None:
        self.ls = ls
        self.od = od
        self.offset = offset
        self.enc: Encoding = ls.encoding
        self._ctx: Context | None = None

    @property
    def doc(self) -> Document:
        return self.od.doc

    def context(self) -> Context:
        """The document's workspace context (see :func:`context_of`)."""
        if self._ctx is None:
            self._ctx = context_of(self.ls, self.od)
        return self._ctx

    def range(self, start: int, end: int) -> types.Range:
        """Offsets of the document as an LSP range in the negotiated encoding."""
        return to_range(self.od.doc.lines, start, end, self.enc)


def at_position(ls: BtServer, params: AtPosition) -> PositionRequest | None:
    """The request at ``params``'s position, or ``None`` when its document is not an open
    BT document (the handlers then answer with nothing)."""
    od = ls.get(params.text_document.uri)
    if od is None or not od.is_bt:
        return None
    return PositionRequest(ls, od, offset_of(ls, od, params.position))


def path_of(od: OpenDocument) -> Path | None:
    """The file behind an open document (``None`` for untitled and non-file documents)."""
    if od.path is not None:
        return od.path
    if not od.uri.startswith("file:"):
        return None
    fs = to_fs_path(od.uri)
    return normalize(fs) if fs else None


def key_of(od: OpenDocument) -> str:
    path = path_of(od)
    return str(path) if path is not None else od.uri


def context_of(ls: BtServer, od: OpenDocument) -> Context:
    """The document's workspace context (only itself when it is not a file)."""
    path = path_of(od)
    if path is None:
        return Context.from_document(od.doc)
    return ls.project.context_for(path, od.doc)


def includes_of(ls: BtServer, od: OpenDocument) -> list[Include]:
    path = path_of(od)
    return ls.project.includes.of(path, od.doc) if path is not None else []


def workspace_sources(ls: BtServer, skip: OpenDocument | None = None) -> dict[str, Source]:
    """Every BT document of the workspace by key, open ones with their editor text,
    ``skip`` left out."""
    out: dict[str, Source] = {}
    skipped = key_of(skip) if skip is not None else None
    for od in ls.docs.values():
        key = key_of(od)
        if od.is_bt and key != skipped:
            out[key] = Source(od.uri, od.doc, od.version)
    open_keys = {key_of(od) for od in ls.docs.values()}
    for path, doc in ls.project.bt_documents():
        key = str(path)
        if key == skipped or key in open_keys:
            continue
        out[key] = Source(from_fs_path(key) or key, doc, None)
    return out


def source_at(ls: BtServer, sources: dict[str, Source], key: str) -> Source | None:
    """The document behind a key: a workspace source, or any readable file by path."""
    found = sources.get(key)
    if found is not None:
        return found
    path = normalize(key)
    doc = ls.project.document(path)
    if doc is None:
        return None
    return Source(from_fs_path(str(path)) or str(path), doc, None)
