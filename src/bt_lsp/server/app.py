"""The bt-lsp language server: its lifecycle (transport, initialize), the open documents,
and the parts it owns, one concern each: the editor's settings (server/settings_state.py),
the documents' diagnostics (server/diagnostics_cache.py) and their publication
(server/publishing.py).

Each LSP feature lives in its own module and only translates between LSP types and the
core.
"""

from __future__ import annotations

import logging
import traceback
from pathlib import Path
from typing import TYPE_CHECKING, Any, BinaryIO

from lsprotocol import types
from pygls.exceptions import JsonRpcException, JsonRpcInternalError, JsonRpcMethodNotFound
from pygls.lsp.server import LanguageServer
from pygls.uris import to_fs_path

from bt_lsp import __version__
from bt_lsp.project.index import ProjectIndex
from bt_lsp.rules.registry import CODES
from bt_lsp.server import transport
from bt_lsp.server.background import Background
from bt_lsp.server.cpp import WATCH_GLOBS as CPP_WATCH_GLOBS
from bt_lsp.server.cpp import CppService
from bt_lsp.server.diagnostics_cache import DiagnosticsCache
from bt_lsp.server.project import WATCHED, is_project_file, sync_config_diagnostics
from bt_lsp.server.protocol import BtProtocol
from bt_lsp.server.publishing import Publisher
from bt_lsp.server.settings_state import SECTION, SettingsState
from bt_lsp.server.state import OpenDocument
from bt_lsp.syntax.text import Encoding, normalize_encoding

if TYPE_CHECKING:
    from bt_lsp.server.live_session import LiveMonitor

log = logging.getLogger(__name__)


class BtServer(LanguageServer):
    """The server as pygls runs it and handlers receive it: the connection, what the client
    said in ``initialize``, the open documents, and one part per concern, each owning its
    state (see docs/architecture.md)."""

    def __init__(self) -> None:
        super().__init__(
            "bt-lsp",
            __version__,
            protocol_cls=BtProtocol,
            text_document_sync_kind=types.TextDocumentSyncKind.Incremental,
        )
        self.docs: dict[str, OpenDocument] = {}
        self.edits = 0  # bumped by every change of an open document
        # What the client supports, from its initialize request.
        self.pull_diagnostics = False
        self.configuration_support = False
        self.refresh_support = False
        self.resolve_edits = False
        self.versioned_edits = False
        self.annotated_edits = False  # change annotations (confirm edits of other files)
        self.code_descriptions = False  # the client shows a diagnostic's codeDescription
        self.watch_files = False
        self.project = ProjectIndex()
        self.settings_state = SettingsState(self)  # the editor's btLsp settings
        self.diagnostics = DiagnosticsCache(self)  # each document's, computed and kept
        self.publisher = Publisher(self)  # when they are pushed (or re-pulled)
        self.cpp = CppService(self)
        # Configuration files' errors as published, by URI (see server/project.py).
        self.config_published: dict[str, tuple[int, int, str]] = {}
        # Package folder (or document) -> the BehaviorTree.CPP version logged for it.
        self.versions_logged: dict[Path, tuple[str | None, str]] = {}
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

    @property
    def encoding(self) -> Encoding:
        try:
            return normalize_encoding(self.workspace.position_encoding)
        except RuntimeError:  # before initialize
            return "utf-16"

    def get(self, uri: str) -> OpenDocument | None:
        return self.docs.get(uri)

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


def create_server() -> BtServer:
    from bt_lsp.server import actions, completion, documents, hover, live_session, navigation
    from bt_lsp.server import live as live_command
    from bt_lsp.server import render as render_command
    from bt_lsp.server import replay as replay_command

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
            ls.settings_state.apply(params.initialization_options)
            ls.settings_state.init_options = params.initialization_options
        ls.settings_state.in_use = ls.settings_state.current
        roots = [f.uri for f in params.workspace_folders or []]
        if not roots and params.root_uri:
            roots = [params.root_uri]
        paths = [p for p in (to_fs_path(r) for r in roots) if p]
        ls.project = ProjectIndex(paths, ls.settings_state.current)
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
            await ls.settings_state.fetch()
            ls.settings_state.changed()
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
        ls.publisher.refresh_all()
        if project_files:
            sync_config_diagnostics(ls)

    @server.feature(types.WORKSPACE_DID_CHANGE_CONFIGURATION)
    async def did_change_configuration(
        ls: BtServer, params: types.DidChangeConfigurationParams
    ) -> None:
        raw = params.settings
        if isinstance(raw, dict) and isinstance(raw.get(SECTION), dict):
            ls.settings_state.apply(raw[SECTION])
        elif ls.configuration_support:
            await ls.settings_state.fetch()
        ls.settings_state.changed()

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
