"""When diagnostics reach the client: pushed after the debounce delay to clients that do
not pull (a large document's early name diagnostics first), re-pulled through
workspace/diagnostic/refresh by those that do.

What the diagnostics are is :mod:`bt_lsp.server.diagnostics_cache`'s; this part only
decides when they are sent and writes the notification.
"""

from __future__ import annotations

import asyncio
import json
from typing import TYPE_CHECKING

from lsprotocol import types

from bt_lsp.project.config import CONFIG_NAMES
from bt_lsp.project.settings import shown
from bt_lsp.rules.diagnostics import Diagnostic, with_severities
from bt_lsp.server.convert import diagnostic_at
from bt_lsp.server.project import sync_config_diagnostics
from bt_lsp.server.state import OpenDocument

if TYPE_CHECKING:
    from bt_lsp.server.app import BtServer

# From this size (in characters) an opened document's name diagnostics are published
# first, found by lxml in a fraction of the full analysis; smaller documents are analysed
# in less time than an editor takes to notice.
EARLY_NAMES_CHARS = 256 * 1024


class Publisher:
    """The publications due, by URI (a debounce timer each), and sending them."""

    def __init__(self, ls: BtServer) -> None:
        self._ls = ls
        self._timers: dict[str, asyncio.TimerHandle] = {}

    def wants_early_names(self, od: OpenDocument) -> bool:
        """Whether the name diagnostics of ``od``, a large BT document being opened, are
        pushed first, found without its full analysis (:mod:`bt_lsp.rules.early_names`)."""
        return not self._ls.pull_diagnostics and len(od.doc.text) >= EARLY_NAMES_CHARS

    def early_names_json(
        self, od: OpenDocument, found: list[Diagnostic], at: dict[int, tuple[int, int]]
    ) -> str:
        """The params of the publication of ``found``, the early name diagnostics of
        ``od`` (with the positions ``at`` of their offsets), as JSON text: written on the
        worker thread while ``od`` is prepared, published by the loop ahead of the
        complete set."""
        ls = self._ls
        settings = ls.settings_state.of(od)
        found = shown(with_severities(found, settings.severity), settings.min_severity)
        params = types.PublishDiagnosticsParams(
            uri=od.uri,
            diagnostics=[
                diagnostic_at(
                    types.Range(types.Position(*at[d.start]), types.Position(*at[d.end])),
                    d,
                    ls.code_descriptions,
                )
                for d in found
            ],
            version=od.version,
        )
        return json.dumps(ls.protocol._converter.unstructure(params))

    def schedule(self, uri: str) -> None:
        """Diagnostics are due for ``uri``: push them after the debounce delay (clients
        that pull are told nothing; they ask after each change)."""
        if self._ls.pull_diagnostics:
            return
        timer = self._timers.pop(uri, None)
        if timer is not None:
            timer.cancel()
        delay = self._ls.settings_state.current.debounce_ms / 1000
        if delay <= 0:
            self.publish(uri)
            return
        loop = asyncio.get_running_loop()
        self._timers[uri] = loop.call_later(delay, self.publish, uri)

    def schedule_all(self, uri: str) -> None:
        """``uri`` changed: its diagnostics are due, and those of the other open BT
        documents too, whose includes, trees and models it may provide."""
        self.schedule(uri)
        for other, od in self._ls.docs.items():
            if other != uri and od.is_bt:
                self.schedule(other)

    def publish(self, uri: str) -> None:
        """Push ``uri``'s diagnostics now; a large document's once the worker thread has
        them (this is called again then)."""
        self._timers.pop(uri, None)
        ls = self._ls
        od = ls.docs.get(uri)
        if od is None:
            return
        if not od.is_bt and od.path is not None and od.path.name in CONFIG_NAMES:
            sync_config_diagnostics(ls)  # a configuration file's diagnostics are its error
            return
        diagnostics = ls.diagnostics
        if ls.background.wants(od):
            diagnostics.check_disk()
            if od.cache_key != diagnostics.key(od):
                if not ls.background.busy(od):  # else its end publishes
                    done = ls.background.analyse(od)
                    done.add_done_callback(lambda f: self._analysed(uri, f))
                return
        try:
            array = od.published.array(
                od.doc.lines, diagnostics.of(od), ls.encoding, ls.code_descriptions
            )
        except Exception:  # a bug must not stop the server; say so in its log
            ls.log_error(f"computing diagnostics for {uri}")
            return
        version = "" if od.version is None else f', "version": {int(od.version)}'
        ls.bt_protocol.notify_json(
            types.TEXT_DOCUMENT_PUBLISH_DIAGNOSTICS,
            f'{{"uri": {json.dumps(uri)}, "diagnostics": {array}{version}}}',
        )

    def _analysed(self, uri: str, done: asyncio.Future[list[Diagnostic] | None]) -> None:
        if done.result() is not None:  # else what changed the document publishes
            self.publish(uri)

    def clear(self, uri: str) -> None:
        """``uri`` was closed (or is no BT document any more): nothing is due for it, and
        its diagnostics are taken away."""
        ls = self._ls
        ls.background.forget(uri)
        timer = self._timers.pop(uri, None)
        if timer is not None:
            timer.cancel()
        if not ls.pull_diagnostics:
            ls.text_document_publish_diagnostics(
                types.PublishDiagnosticsParams(uri=uri, diagnostics=[])
            )

    def refresh_all(self) -> None:
        """The workspace changed: re-publish (or ask pull clients to re-pull) everything."""
        ls = self._ls
        ls.diagnostics.invalidate()
        if ls.pull_diagnostics:
            if ls.refresh_support:
                ls.workspace_diagnostic_refresh(None)
        else:
            for uri in list(ls.docs):
                self.schedule(uri)
