"""The editor's ``btLsp`` settings: where they come from, in what order, and what a change
of them makes due.

The client gives them in its initializationOptions, in a didChangeConfiguration and in
the answers to workspace/configuration requests; each source is stamped when it arrives
(or, for an answer, when its request was sent), so that an answer older than the settings
in force is dropped.
"""

from __future__ import annotations

import asyncio
from collections.abc import Mapping
from typing import TYPE_CHECKING, Any

from lsprotocol import types

from bt_lsp.project.settings import Settings
from bt_lsp.server.state import OpenDocument

if TYPE_CHECKING:
    from bt_lsp.server.app import BtServer

SECTION = "btLsp"


class SettingsState:
    """The editor's settings in force, and those the diagnostics were last computed with."""

    def __init__(self, ls: BtServer) -> None:
        self._ls = ls
        self.current = Settings()
        self.in_use = self.current  # what diagnostics were last computed with
        self.init_options: object = None  # the client's initializationOptions
        self._stamps = 0  # counts settings sources, in the order they arrive
        self._in_force = 0  # the stamp of the settings in force
        self._fetching: asyncio.Future[None] | None = None  # a workspace/configuration

    def of(self, od: OpenDocument) -> Settings:
        """The settings of an open document: its file's, or the editor's if it is none.
        Sends nothing, so the worker thread may call it."""
        return self.current if od.path is None else self._ls.project.settings_for(od.path)

    def apply(self, raw: object, issued: int | None = None) -> None:
        """Settings from the client's ``btLsp`` section over its initializationOptions: a
        key the section leaves out keeps its initializationOptions value, and a missing
        section (``null``) means the initializationOptions alone.

        ``issued`` orders the sources: the answer to a workspace/configuration request is
        dropped if settings that arrived after the request was sent are already in force."""
        issued = self._next_stamp() if issued is None else issued
        if issued < self._in_force:
            return
        self._in_force = issued
        problems: list[str] = []
        if raw is not None and not isinstance(raw, Mapping):
            problems.append("btLsp settings must be an object")
        merged = {**_section(self.init_options), **_section(raw)}
        self.current = Settings.parse(merged, problems)
        for p in problems:
            self._ls.log_message(f"bt-lsp settings: {p}", types.MessageType.Warning)

    def changed(self) -> None:
        """The settings may have changed: if they did, the project reads them and every
        document's diagnostics are due."""
        if self.current == self.in_use:
            return  # e.g. a didChangeConfiguration about other extensions' settings
        self.in_use = self.current
        self._ls.project.set_settings(self.current)
        self._ls.publisher.refresh_all()

    def _next_stamp(self) -> int:
        self._stamps += 1
        return self._stamps

    async def fetch(self) -> None:
        """Ask for the ``btLsp`` section.  While a request is on its way, a second one is
        not sent (VS Code sends a didChangeConfiguration right after ``initialized``): the
        answer to the first one is as new as the change, since the client sent the change
        before answering it."""
        if not self._ls.configuration_support:
            return
        pending = self._fetching
        if pending is not None and not pending.done():
            await asyncio.shield(pending)
            return
        self._fetching = asyncio.get_running_loop().create_future()
        try:
            await self._fetch()
        finally:
            self._fetching.set_result(None)

    async def _fetch(self) -> None:
        issued = self._next_stamp()
        try:
            result = await self._ls.workspace_configuration_async(
                types.ConfigurationParams(items=[types.ConfigurationItem(section=SECTION)])
            )
        except Exception:
            self._ls.log_error("reading workspace/configuration")
            return
        self.apply(result[0] if result else None, issued)


def _section(raw: object) -> Mapping[str, Any]:
    """The ``btLsp`` settings in ``raw`` (the section itself, or an object holding it)."""
    if not isinstance(raw, Mapping):
        return {}
    inner = raw.get(SECTION)
    return inner if isinstance(inner, Mapping) else raw
