"""The bt-lsp language server: state, lifecycle and settings.

Each LSP feature lives in its own module and only translates between LSP types and the
core; this module owns the open documents and when diagnostics are published.
"""

from __future__ import annotations

import asyncio
import json
import logging
import time
import traceback
from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any, BinaryIO

from lsprotocol import types
from pygls.exceptions import JsonRpcException, JsonRpcInternalError, JsonRpcMethodNotFound
from pygls.lsp.server import LanguageServer
from pygls.uris import to_fs_path

from bt_lsp import __version__
from bt_lsp.ide.name_targets import with_targets
from bt_lsp.project.config import CONFIG_NAMES
from bt_lsp.project.index import ProjectIndex
from bt_lsp.project.settings import Settings, shown
from bt_lsp.rules.analysis import analyze
from bt_lsp.rules.diagnostics import Diagnostic, size_limited, with_severities
from bt_lsp.rules.registry import CODES
from bt_lsp.server import transport
from bt_lsp.server.background import Background
from bt_lsp.server.convert import diagnostic_at
from bt_lsp.server.cpp import WATCH_GLOBS as CPP_WATCH_GLOBS
from bt_lsp.server.cpp import CppService
from bt_lsp.server.project import (
    WATCHED,
    config_diagnostics,
    is_project_file,
    log_version,
    sync_config_diagnostics,
)
from bt_lsp.server.protocol import BtProtocol
from bt_lsp.server.state import OpenDocument
from bt_lsp.syntax.document import Document
from bt_lsp.syntax.text import Encoding, normalize_encoding

if TYPE_CHECKING:
    from bt_lsp.server.live_session import LiveMonitor

log = logging.getLogger(__name__)

SECTION = "btLsp"

# From this size (in characters) an opened document's name diagnostics are published
# first, found by lxml in a fraction of the full analysis; smaller documents are analysed
# in less time than an editor takes to notice.
EARLY_NAMES_CHARS = 256 * 1024

# How often, at most, files read from disk are compared with the disk again, for clients
# that do not send workspace/didChangeWatchedFiles.
DISK_CHECK_SECONDS = 1.0


class BtServer(LanguageServer):
    def __init__(self) -> None:
        super().__init__(
            "bt-lsp",
            __version__,
            protocol_cls=BtProtocol,
            text_document_sync_kind=types.TextDocumentSyncKind.Incremental,
        )
        self.docs: dict[str, OpenDocument] = {}
        self.settings = Settings()
        self.settings_in_use = self.settings  # what diagnostics were last computed with
        self.init_options: object = None  # the client's initializationOptions
        self._settings_stamps = 0  # counts settings sources, in the order they arrive
        self._settings_in_force = 0  # the stamp of the settings in force
        self.pull_diagnostics = False
        self.configuration_support = False
        self.refresh_support = False
        self.resolve_edits = False
        self.versioned_edits = False
        self.annotated_edits = False  # change annotations (confirm edits of other files)
        self.code_descriptions = False  # the client shows a diagnostic's codeDescription
        self._fetching: asyncio.Future[None] | None = None  # a workspace/configuration
        self.watch_files = False
        self.generation = 0  # bumped when settings change; part of every resultId
        self.project = ProjectIndex()
        self.edits = 0  # bumped by every change of an open document
        self._timers: dict[str, asyncio.TimerHandle] = {}
        self.cpp = CppService(self)
        # Configuration files' errors as published, by URI (see server/project.py).
        self.config_published: dict[str, tuple[int, int, str]] = {}
        # Package folder (or document) -> the BehaviorTree.CPP version logged for it.
        self.versions_logged: dict[Path, tuple[str | None, str]] = {}
        self._disk_checked = -DISK_CHECK_SECONDS  # when check_disk last looked
        self.background = Background(self)  # large documents are analysed off the loop
        self.live: LiveMonitor | None = None  # a running tree watched (server/live_session.py)

    @property
    def bt_protocol(self) -> BtProtocol:
        assert isinstance(self.protocol, BtProtocol)
        return self.protocol

    def start_io(self, stdin: BinaryIO | None = None, stdout: BinaryIO | None = None) -> None:
        transport.start_io(self, stdin, stdout)

    def start_tcp(self, host: str, port: int) -> None:
        transport.start_tcp(self, host, port)

    def shutdown(self) -> None:
        """The connection ends: no thread watching an executor is left behind."""
        if self.live is not None:
            self.live.stop()
        super().shutdown()  # type: ignore[no-untyped-call]

    # -- state ----------------------------------------------------------------------------

    @property
    def encoding(self) -> Encoding:
        try:
            return normalize_encoding(self.workspace.position_encoding)
        except RuntimeError:  # before initialize
            return "utf-16"

    def get(self, uri: str) -> OpenDocument | None:
        return self.docs.get(uri)

    def check_disk(self) -> None:
        """Without watched-file notifications, notice files changed on disk by their
        modification time and size (at most once a second): they are read again, and
        every document's diagnostics are due."""
        if self.watch_files:
            return
        now = time.monotonic()
        if now - self._disk_checked < DISK_CHECK_SECONDS:
            return
        self._disk_checked = now
        if self.project.revalidate():
            self.refresh_all()

    def diagnostics_key(self, od: OpenDocument) -> tuple[int | None, int, int]:
        """What ``od``'s diagnostics depend on: its version, the settings and the rest of
        the workspace (every open document's edits included)."""
        return (od.version, self.generation, self.project.generation + self.edits)

    def diagnostics_of(self, od: OpenDocument) -> list[Diagnostic]:
        """The document's diagnostics after severity settings, cached per version."""
        self.check_disk()
        key = self.diagnostics_key(od)
        if od.cache_key == key:
            return od.cached
        self.diagnostics_computed(od, key, self.compute_diagnostics(od, od.doc))
        return od.cached

    def compute_diagnostics(self, od: OpenDocument, doc: Document) -> list[Diagnostic]:
        """The diagnostics of ``doc`` (``od``'s document or a snapshot of it) after
        severity settings.  Sends nothing, so the worker thread may call it."""
        if not od.is_bt:
            found = self.cpp.diagnostics(od, doc)
            return shown(found, self._settings_of(od).min_severity) if found else found
        with doc.history.lock:  # the caches it shares with the open document's snapshots
            if doc.utf8_size > self.settings.max_document_bytes:
                result = size_limited(doc, self.settings.max_document_bytes)
            elif od.path is not None:
                result = self.project.diagnostics(od.path, doc)
            else:
                result = with_targets(doc, analyze(doc))
        settings = self._settings_of(od)
        return shown(with_severities(result, settings.severity), settings.min_severity)

    def _settings_of(self, od: OpenDocument) -> Settings:
        """The settings of an open document: its file's, or the editor's if it is none."""
        return self.settings if od.path is None else self.project.settings_for(od.path)

    def diagnostics_computed(
        self, od: OpenDocument, key: tuple[int | None, int, int], result: list[Diagnostic]
    ) -> None:
        """Keep ``od``'s diagnostics for ``key``, and say what computing them found."""
        od.cache_key, od.cached = key, result
        if od.is_bt and od.path is not None:
            log_version(self, od.path)
        sync_config_diagnostics(self)  # the files' settings were made: their errors known

    async def analysed(self, od: OpenDocument) -> None:
        """Wait, without holding the loop, until ``od``'s diagnostics are current: a
        large document is analysed on the worker thread (:mod:`bt_lsp.server.background`),
        others when :meth:`diagnostics_of` is called."""
        while self.get(od.uri) is od and self.background.wants(od):
            self.check_disk()
            key = self.diagnostics_key(od)
            if od.cache_key == key:
                return
            found = await asyncio.shield(self.background.analyse(od))
            if found is None and self.diagnostics_key(od) == key:
                return  # it failed (and was logged): the caller finds out for itself

    def diagnostics_json(self, od: OpenDocument) -> str:
        """The JSON array of ``od``'s diagnostics, for a pull client: written as a
        publication is, reusing what its unchanged diagnostics wrote before
        (:class:`~bt_lsp.server.convert.DiagnosticJson`)."""
        array = od.published.array(
            od.doc.lines, self.diagnostics_of(od), self.encoding, self.code_descriptions
        )
        config = config_diagnostics(self, od.uri) if not od.is_bt else []
        if not config:
            return array
        extra = json.dumps(self.protocol._converter.unstructure(config))
        return array[:-1] + (", " if array != "[]" else "") + extra[1:]

    # -- publishing -------------------------------------------------------------------------

    def wants_early_names(self, od: OpenDocument) -> bool:
        """Whether the name diagnostics of ``od``, a large BT document being opened, are
        pushed first, found without its full analysis (:mod:`bt_lsp.rules.early_names`)."""
        return not self.pull_diagnostics and len(od.doc.text) >= EARLY_NAMES_CHARS

    def early_names_json(
        self, od: OpenDocument, found: list[Diagnostic], at: dict[int, tuple[int, int]]
    ) -> str:
        """The params of the publication of ``found``, the early name diagnostics of
        ``od`` (with the positions ``at`` of their offsets), as JSON text: written on the
        worker thread while ``od`` is prepared, published by the loop ahead of the
        complete set."""
        settings = self.settings if od.path is None else self.project.settings_for(od.path)
        found = shown(with_severities(found, settings.severity), settings.min_severity)
        params = types.PublishDiagnosticsParams(
            uri=od.uri,
            diagnostics=[
                diagnostic_at(
                    types.Range(types.Position(*at[d.start]), types.Position(*at[d.end])),
                    d,
                    self.code_descriptions,
                )
                for d in found
            ],
            version=od.version,
        )
        return json.dumps(self.protocol._converter.unstructure(params))

    def schedule(self, uri: str) -> None:
        """Diagnostics are due for ``uri``: push them after the debounce delay (clients
        that pull are told nothing; they ask after each change)."""
        if self.pull_diagnostics:
            return
        timer = self._timers.pop(uri, None)
        if timer is not None:
            timer.cancel()
        delay = self.settings.debounce_ms / 1000
        if delay <= 0:
            self.publish(uri)
            return
        loop = asyncio.get_running_loop()
        self._timers[uri] = loop.call_later(delay, self.publish, uri)

    def schedule_all(self, uri: str) -> None:
        """``uri`` changed: its diagnostics are due, and those of the other open BT
        documents too, whose includes, trees and models it may provide."""
        self.schedule(uri)
        for other, od in self.docs.items():
            if other != uri and od.is_bt:
                self.schedule(other)

    def publish(self, uri: str) -> None:
        self._timers.pop(uri, None)
        od = self.docs.get(uri)
        if od is None:
            return
        if not od.is_bt and od.path is not None and od.path.name in CONFIG_NAMES:
            sync_config_diagnostics(self)  # a configuration file's diagnostics are its error
            return
        if self.background.wants(od):
            self.check_disk()
            if od.cache_key != self.diagnostics_key(od):
                if not self.background.busy(od):  # else its end publishes
                    done = self.background.analyse(od)
                    done.add_done_callback(lambda f: self._analysed(uri, f))
                return
        try:
            array = od.published.array(
                od.doc.lines, self.diagnostics_of(od), self.encoding, self.code_descriptions
            )
        except Exception:  # a bug must not stop the server; say so in its log
            self.log_error(f"computing diagnostics for {uri}")
            return
        version = "" if od.version is None else f', "version": {int(od.version)}'
        self.bt_protocol.notify_json(
            types.TEXT_DOCUMENT_PUBLISH_DIAGNOSTICS,
            f'{{"uri": {json.dumps(uri)}, "diagnostics": {array}{version}}}',
        )

    def _analysed(self, uri: str, done: asyncio.Future[list[Diagnostic] | None]) -> None:
        if done.result() is not None:  # else what changed the document publishes
            self.publish(uri)

    def clear(self, uri: str) -> None:
        self.background.forget(uri)
        timer = self._timers.pop(uri, None)
        if timer is not None:
            timer.cancel()
        if not self.pull_diagnostics:
            self.text_document_publish_diagnostics(
                types.PublishDiagnosticsParams(uri=uri, diagnostics=[])
            )

    def refresh_all(self) -> None:
        """The workspace changed: re-publish (or ask pull clients to re-pull) everything."""
        self.generation += 1
        if self.pull_diagnostics:
            if self.refresh_support:
                self.workspace_diagnostic_refresh(None)
        else:
            for uri in list(self.docs):
                self.schedule(uri)

    def settings_changed(self) -> None:
        if self.settings == self.settings_in_use:
            return  # e.g. a didChangeConfiguration about other extensions' settings
        self.settings_in_use = self.settings
        self.project.set_settings(self.settings)
        self.refresh_all()

    # -- logging ----------------------------------------------------------------------------

    def log_message(self, message: str, kind: types.MessageType = types.MessageType.Log) -> None:
        try:
            self.window_log_message(types.LogMessageParams(type=kind, message=message))
        except Exception:  # no client connected yet
            log.warning("%s", message)

    def log_error(self, what: str) -> None:
        self.log_message(
            f"bt-lsp: error {what}:\n{traceback.format_exc()}", types.MessageType.Error
        )

    def report_server_error(self, error: Exception, source: Any) -> None:
        """Log internal errors to the client's log instead of popping up messages; requests
        are answered with a JSON-RPC error by pygls itself.  Deliberate error answers (a
        refused rename, an unknown method, malformed params) are not internal errors."""
        if isinstance(error, JsonRpcException) and not isinstance(error, JsonRpcInternalError):
            refusal = (
                isinstance(error, JsonRpcMethodNotFound)
                or error.code == types.LSPErrorCodes.RequestFailed
            )
            self.log_message(
                f"bt-lsp: {type(error).__name__}: {error}",
                types.MessageType.Log if refusal else types.MessageType.Warning,
            )
            return
        self.log_message(
            f"bt-lsp: internal error ({getattr(source, '__name__', source)}): {error!r}",
            types.MessageType.Error,
        )

    # -- settings ---------------------------------------------------------------------------

    def apply_settings(self, raw: object, issued: int | None = None) -> None:
        """Settings from the client's ``btLsp`` section over its initializationOptions: a
        key the section leaves out keeps its initializationOptions value, and a missing
        section (``null``) means the initializationOptions alone.

        ``issued`` orders the sources: the answer to a workspace/configuration request is
        dropped if settings that arrived after the request was sent are already in force."""
        issued = self._next_settings_stamp() if issued is None else issued
        if issued < self._settings_in_force:
            return
        self._settings_in_force = issued
        problems: list[str] = []
        if raw is not None and not isinstance(raw, Mapping):
            problems.append("btLsp settings must be an object")
        merged = {**_section(self.init_options), **_section(raw)}
        self.settings = Settings.parse(merged, problems)
        for p in problems:
            self.log_message(f"bt-lsp settings: {p}", types.MessageType.Warning)

    def _next_settings_stamp(self) -> int:
        self._settings_stamps += 1
        return self._settings_stamps

    async def fetch_settings(self) -> None:
        """Ask for the ``btLsp`` section.  While a request is on its way, a second one is
        not sent (VS Code sends a didChangeConfiguration right after ``initialized``): the
        answer to the first one is as new as the change, since the client sent the change
        before answering it."""
        if not self.configuration_support:
            return
        pending = self._fetching
        if pending is not None and not pending.done():
            await asyncio.shield(pending)
            return
        self._fetching = asyncio.get_running_loop().create_future()
        try:
            await self._fetch_settings()
        finally:
            self._fetching.set_result(None)

    async def _fetch_settings(self) -> None:
        issued = self._next_settings_stamp()
        try:
            result = await self.workspace_configuration_async(
                types.ConfigurationParams(items=[types.ConfigurationItem(section=SECTION)])
            )
        except Exception:
            self.log_error("reading workspace/configuration")
            return
        self.apply_settings(result[0] if result else None, issued)


def _section(raw: object) -> Mapping[str, Any]:
    """The ``btLsp`` settings in ``raw`` (the section itself, or an object holding it)."""
    if not isinstance(raw, Mapping):
        return {}
    inner = raw.get(SECTION)
    return inner if isinstance(inner, Mapping) else raw


def create_server() -> BtServer:
    from bt_lsp.server import actions, completion, documents, hover, live_session, navigation
    from bt_lsp.server import replay as replay_command
    from bt_lsp.server import live as live_command
    from bt_lsp.server import render as render_command

    server = BtServer()

    @server.feature(types.INITIALIZE)
    def initialize(ls: BtServer, params: types.InitializeParams) -> None:
        caps = params.capabilities
        td = caps.text_document
        ls.pull_diagnostics = td is not None and td.diagnostic is not None
        ws = caps.workspace
        ls.configuration_support = bool(ws and ws.configuration)
        ls.refresh_support = bool(ws and ws.diagnostics and ws.diagnostics.refresh_support)
        ls.versioned_edits = bool(ws and ws.workspace_edit and ws.workspace_edit.document_changes)
        ls.annotated_edits = ls.versioned_edits and bool(
            ws and ws.workspace_edit and ws.workspace_edit.change_annotation_support
        )
        ls.code_descriptions = bool(
            td
            and (
                (td.publish_diagnostics and td.publish_diagnostics.code_description_support)
                or (td.diagnostic and td.diagnostic.code_description_support)
            )
        )
        ca = td.code_action if td else None
        ls.resolve_edits = bool(
            ca and ca.resolve_support and "edit" in ca.resolve_support.properties
        )
        if params.initialization_options is not None:
            ls.apply_settings(params.initialization_options)
            ls.init_options = params.initialization_options
        ls.settings_in_use = ls.settings
        roots = [f.uri for f in params.workspace_folders or []]
        if not roots and params.root_uri:
            roots = [params.root_uri]
        paths = [p for p in (to_fs_path(r) for r in roots) if p]
        ls.project = ProjectIndex(paths, ls.settings)
        ls.cpp.attach(params)
        ls.watch_files = bool(
            ws and ws.did_change_watched_files and ws.did_change_watched_files.dynamic_registration
        )

    @server.feature(types.INITIALIZED)
    async def initialized(ls: BtServer, params: types.InitializedParams) -> None:
        if ls.watch_files:
            try:
                await ls.client_register_capability_async(
                    types.RegistrationParams(
                        registrations=[
                            types.Registration(
                                id="bt-lsp-watched-files",
                                method=types.WORKSPACE_DID_CHANGE_WATCHED_FILES,
                                register_options=types.DidChangeWatchedFilesRegistrationOptions(
                                    watchers=[
                                        types.FileSystemWatcher(glob_pattern="**/*.xml"),
                                        types.FileSystemWatcher(glob_pattern="**/*.btproj"),
                                        *(
                                            types.FileSystemWatcher(glob_pattern=g)
                                            for g in CPP_WATCH_GLOBS
                                        ),
                                        *(types.FileSystemWatcher(glob_pattern=g) for g in WATCHED),
                                    ]
                                ),
                            )
                        ]
                    )
                )
            except Exception:
                ls.log_error("registering for watched-file changes")
                if ls.project.cpp is not None:
                    ls.project.cpp.watched = False  # changes on disk are not reported
        if ls.configuration_support:
            await ls.fetch_settings()
            ls.settings_changed()
        for root in ls.project.roots:  # a broken configuration is shown before any file
            ls.project.configs.for_path(root)
        sync_config_diagnostics(ls)

    @server.feature(types.WORKSPACE_DID_CHANGE_WATCHED_FILES)
    def did_change_watched_files(ls: BtServer, params: types.DidChangeWatchedFilesParams) -> None:
        project_files = False
        for change in params.changes:  # each alone: one that fails leaves the others
            try:
                path = to_fs_path(change.uri)
                if path:
                    ls.project.file_changed(path)
                    project_files = project_files or is_project_file(Path(path))
            except Exception:
                ls.log_error(f"reading the change of {change.uri}")
        ls.refresh_all()
        if project_files:
            sync_config_diagnostics(ls)

    @server.feature(types.WORKSPACE_DID_CHANGE_CONFIGURATION)
    async def did_change_configuration(
        ls: BtServer, params: types.DidChangeConfigurationParams
    ) -> None:
        raw = params.settings
        if isinstance(raw, dict) and isinstance(raw.get(SECTION), dict):
            ls.apply_settings(raw[SECTION])
        elif ls.configuration_support:
            await ls.fetch_settings()
        ls.settings_changed()

    documents.register(server)
    actions.register(server)
    hover.register(server)
    navigation.register(server)
    completion.register(server)
    render_command.register(server)
    live_command.register(server)
    live_session.register(server)
    replay_command.register(server)
    return server


__all__ = ["CODES", "BtServer", "OpenDocument", "create_server"]
