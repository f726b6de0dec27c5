"""The project around the documents: configuration-file errors as diagnostics on the
configuration file, re-reading it when it changes, and the BehaviorTree.CPP version of
each package in the server's log."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Final

from lsprotocol import types
from pygls.uris import from_fs_path, to_fs_path

from bt_lsp.project.config import CONFIG_NAMES, ConfigError
from bt_lsp.project.index import normalize
from bt_lsp.rules.configuration import CONFIG_ERROR
from bt_lsp.syntax.text import LineIndex

if TYPE_CHECKING:
    from bt_lsp.server.app import BtServer
    from bt_lsp.server.state import OpenDocument

# Files whose change may change every file's settings or BehaviorTree.CPP version.
PROJECT_FILES: Final = (*CONFIG_NAMES, "package.xml", "CMakeLists.txt")
WATCHED: Final = ("**/bt-lsp.toml", "**/pyproject.toml", "**/CMakeLists.txt")


def is_project_file(path: Path) -> bool:
    return path.name in PROJECT_FILES


def sync_config_diagnostics(ls: BtServer) -> None:
    """Publish each configuration file's error (one diagnostic) and clear those fixed."""
    for uri in ls.config_published:  # read again what changed since it was published
        fs = to_fs_path(uri)
        if fs and Path(fs).is_file():
            ls.project.configs.load(normalize(fs))
    errors: dict[str, ConfigError] = {}
    for e in ls.project.config_errors():
        uri = from_fs_path(str(e.path))
        if uri:
            errors[uri] = e
    for uri in set(errors) | set(ls.config_published):
        error = errors.get(uri)
        key = None if error is None else (error.line, error.column, error.message)
        if ls.config_published.get(uri) == key:
            continue
        if key is None:
            ls.config_published.pop(uri, None)
        else:
            ls.config_published[uri] = key
        diags = [] if error is None else [_diagnostic(ls, uri, error)]
        ls.text_document_publish_diagnostics(
            types.PublishDiagnosticsParams(uri=uri, diagnostics=diags)
        )


def config_diagnostics(ls: BtServer, uri: str) -> list[types.Diagnostic]:
    """The configuration error of the file at ``uri`` (for a client that shows or pulls
    the diagnostics of an open configuration file)."""
    if uri not in ls.config_published:
        return []
    for e in ls.project.config_errors():
        if from_fs_path(str(e.path)) == uri:
            return [_diagnostic(ls, uri, e)]
    return []


def _diagnostic(ls: BtServer, uri: str, e: ConfigError) -> types.Diagnostic:
    """The error's position in the client's encoding: from the column to the end of its
    line (the text as the editor has it, else as on disk)."""
    text = ""
    od = ls.get(uri)
    if od is not None:
        text = od.doc.text
    else:
        try:
            text = e.path.read_bytes().decode("utf-8", "replace")
        except OSError:
            text = ""
    lines = LineIndex(text)
    row, start_col, end_col = e.span(text)
    line_start = lines.line_start(row) if row < lines.line_count else len(text)
    enc = ls.encoding
    a = lines.position(min(line_start + start_col, len(text)), enc)
    b = lines.position(min(line_start + end_col, len(text)), enc)
    return types.Diagnostic(
        range=types.Range(types.Position(*a), types.Position(*b)),
        message=f"bt-lsp configuration: {e.message}",
        severity=types.DiagnosticSeverity.Error,
        code=CONFIG_ERROR.code,
        source="bt-lsp",
    )


def log_version(ls: BtServer, path: Path) -> None:
    """Say which BehaviorTree.CPP the files of a package (or folder) are checked as: once,
    and again only when it changes.  A version read from a document's own
    ``BTCPP_format`` is that document's, so it is logged per document."""
    project = ls.project
    found = project.btcpp_for(path)
    where = project.packages.package_of(path.parent)
    folder = where.folder if where is not None else path.parent
    of_project = (
        project.settings_for(path).btcpp in ("3", "4")
        or project.packages.btcpp_of(path.parent).version is not None
        or found.conflict
    )
    key = folder if of_project or found.version is None else path
    value = (found.version, found.source)
    if ls.versions_logged.get(key) == value:
        return
    ls.versions_logged[key] = value
    version = f"BehaviorTree.CPP {found.version}" if found.version else "BehaviorTree.CPP 4"
    why = found.source if found.version else "not detected; checked as version 4"
    if found.conflict:
        version, why = "BehaviorTree.CPP version unclear", f"{found.source}; checked as 4"
    ls.log_message(f"bt-lsp: {key}: {version} ({why})", types.MessageType.Info)


def document_edited(
    ls: BtServer, od: OpenDocument, *, opened: bool = False, closed: bool = False
) -> None:
    """A document was opened, edited or closed: if it is a configuration file, the files'
    settings are made again from its text; else its configuration file is read."""
    if od.path is None:
        return
    if ls.project.config_edited(od.path, None if closed else od.doc.text):
        if closed:  # its diagnostics were cleared with the document's
            ls.config_published.pop(od.uri, None)
        ls.publisher.refresh_all()
    elif opened:  # its configuration, read now: a pull client may not ask for a while
        ls.project.configs.for_path(od.path)
    else:
        return
    sync_config_diagnostics(ls)
