"""The open documents' diagnostics: what they depend on, computing them, and keeping them
per document until that changes.

A document's diagnostics depend on its version, the settings (:attr:`generation`) and the
rest of the workspace (the project's generation and every open document's edits); they
are cached on the :class:`~bt_lsp.server.state.OpenDocument` under that key.  A large
document's are computed on the worker thread (:mod:`bt_lsp.server.background`), which
calls :meth:`DiagnosticsCache.compute` only.
"""

from __future__ import annotations

import asyncio
import json
import time
from typing import TYPE_CHECKING

from bt_lsp.ide.name_targets import with_targets
from bt_lsp.project.settings import shown
from bt_lsp.rules.analysis import analyze
from bt_lsp.rules.diagnostics import Diagnostic, size_limited, with_severities
from bt_lsp.server.project import config_diagnostics, log_version, sync_config_diagnostics
from bt_lsp.server.state import OpenDocument
from bt_lsp.syntax.document import Document

if TYPE_CHECKING:
    from bt_lsp.server.app import BtServer

Key = tuple[int | None, int, int]

# How often, at most, files read from disk are compared with the disk again, for clients
# that do not send workspace/didChangeWatchedFiles.
DISK_CHECK_SECONDS = 1.0


class DiagnosticsCache:
    """Each open document's diagnostics after severity settings, computed when asked for
    and kept until what they depend on changes."""

    def __init__(self, ls: BtServer) -> None:
        self._ls = ls
        self.generation = 0  # bumped when settings change; part of every resultId
        self._disk_checked = -DISK_CHECK_SECONDS  # when check_disk last looked

    def invalidate(self) -> None:
        """The settings or the workspace changed: every document's diagnostics are stale."""
        self.generation += 1

    def check_disk(self) -> None:
        """Without watched-file notifications, notice files changed on disk by their
        modification time and size (at most once a second): they are read again, and
        every document's diagnostics are due."""
        ls = self._ls
        if ls.watch_files:
            return
        now = time.monotonic()
        if now - self._disk_checked < DISK_CHECK_SECONDS:
            return
        self._disk_checked = now
        if ls.project.revalidate():
            ls.publisher.refresh_all()

    def key(self, od: OpenDocument) -> Key:
        """What ``od``'s diagnostics depend on: its version, the settings and the rest of
        the workspace (every open document's edits included)."""
        return (od.version, self.generation, self._ls.project.generation + self._ls.edits)

    def result_id(self, od: OpenDocument) -> str:
        """The resultId of ``od``'s pulled diagnostics: its :meth:`key`, other documents
        included, since those can change this one's diagnostics."""
        version, generation, workspace = self.key(od)
        return f"{version}:{generation}:{workspace}"

    def of(self, od: OpenDocument) -> list[Diagnostic]:
        """The document's diagnostics after severity settings, cached per version."""
        self.check_disk()
        key = self.key(od)
        if od.cache_key == key:
            return od.cached
        self.computed(od, key, self.compute(od, od.doc))
        return od.cached

    def compute(self, od: OpenDocument, doc: Document) -> list[Diagnostic]:
        """The diagnostics of ``doc`` (``od``'s document or a snapshot of it) after
        severity settings.  Sends nothing, so the worker thread may call it."""
        ls = self._ls
        if not od.is_bt:
            found = ls.cpp.diagnostics(od, doc)
            return shown(found, ls.settings_state.of(od).min_severity) if found else found
        limit = ls.settings_state.current.max_document_bytes
        with doc.history.lock:  # the caches it shares with the open document's snapshots
            if doc.utf8_size > limit:
                result = size_limited(doc, limit)
            elif od.path is not None:
                result = ls.project.diagnostics(od.path, doc)
            else:
                result = with_targets(doc, analyze(doc))
        settings = ls.settings_state.of(od)
        return shown(with_severities(result, settings.severity), settings.min_severity)

    def computed(self, od: OpenDocument, key: Key, result: list[Diagnostic]) -> None:
        """Keep ``od``'s diagnostics for ``key``, and say what computing them found."""
        od.cache_key, od.cached = key, result
        if od.is_bt and od.path is not None:
            log_version(self._ls, od.path)
        sync_config_diagnostics(self._ls)  # the files' settings were made: their errors known

    async def analysed(self, od: OpenDocument) -> None:
        """Wait, without holding the loop, until ``od``'s diagnostics are current: a
        large document is analysed on the worker thread (:mod:`bt_lsp.server.background`),
        others when :meth:`of` is called."""
        ls = self._ls
        while ls.get(od.uri) is od and ls.background.wants(od):
            self.check_disk()
            key = self.key(od)
            if od.cache_key == key:
                return
            found = await asyncio.shield(ls.background.analyse(od))
            if found is None and self.key(od) == key:
                return  # it failed (and was logged): the caller finds out for itself

    def as_json(self, od: OpenDocument) -> str:
        """The JSON array of ``od``'s diagnostics, for a pull client: written as a
        publication is, reusing what its unchanged diagnostics wrote before
        (:class:`~bt_lsp.server.convert.DiagnosticJson`)."""
        ls = self._ls
        array = od.published.array(od.doc.lines, self.of(od), ls.encoding, ls.code_descriptions)
        config = config_diagnostics(ls, od.uri) if not od.is_bt else []
        if not config:
            return array
        extra = json.dumps(ls.protocol._converter.unstructure(config))
        return array[:-1] + (", " if array != "[]" else "") + extra[1:]
