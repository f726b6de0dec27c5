"""The workspace as the navigation features see it: open documents first, files after.

Every other BT document is keyed by its path (its URI when it is not a file), with the URI,
text and version to answer with.  An open document's text wins over the file on disk, so
offsets computed on it are converted with its own line index.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from lsprotocol import types
from pygls.uris import from_fs_path, to_fs_path

from bt_lsp.project.index import Include, normalize
from bt_lsp.rules.context import Context
from bt_lsp.server.state import OpenDocument
from bt_lsp.syntax.document import Document

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
    return ls.project.includes(path, od.doc) if path is not None else []


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
