"""The workspace: open documents, the BT XML files around them, and their includes.

This is the only layer that reads files.  :class:`ProjectIndex` owns one object per
concern and keeps them consistent when a file changes:

- :class:`~bt_lsp.project.documents.Documents`: the open documents and the files read
  from disk (cached by modification time and size), and the ``generation`` that dates
  every other cache;
- :class:`~bt_lsp.project.settings_index.SettingsIndex`: each file's settings (flags over
  its configuration file over the editor's);
- :class:`~bt_lsp.project.workspace_files.WorkspaceFiles`: the BT files of the folders;
- :class:`~bt_lsp.project.package_scope.PackageScope`: the ROS packages, and which
  catalogs apply to each file;
- :class:`~bt_lsp.project.versions.BtcppVersions`: each file's BehaviorTree.CPP version;
- :class:`~bt_lsp.project.include_graph.IncludeGraph`: includes resolved the way
  BehaviorTree.CPP does, include closures and cycles;
- :class:`~bt_lsp.project.file_context.FileContexts`: the
  :class:`~bt_lsp.rules.context.Context` each document's semantic rules read.

Nothing here ever fetches a URL or follows a DOCTYPE.
"""

from __future__ import annotations

import os
from collections.abc import Iterator, Sequence
from pathlib import Path

from bt_lsp.ide.name_targets import with_targets
from bt_lsp.project.config import CONFIG_FILE, ConfigError, Configs, Layer
from bt_lsp.project.cpp_models import CppModels, cpp_diagnostics
from bt_lsp.project.cpp_scan import CPP_SUFFIXES
from bt_lsp.project.documents import Documents
from bt_lsp.project.file_context import FileContexts
from bt_lsp.project.include_graph import Include as Include
from bt_lsp.project.include_graph import IncludeGraph
from bt_lsp.project.include_graph import links as links
from bt_lsp.project.package_scope import PackageScope
from bt_lsp.project.packages import Detected, Packages
from bt_lsp.project.paths import normalize as normalize
from bt_lsp.project.ros import RosIndex
from bt_lsp.project.settings import Settings
from bt_lsp.project.settings_index import SettingsIndex
from bt_lsp.project.versions import BtcppVersions
from bt_lsp.project.workspace_files import WorkspaceFiles
from bt_lsp.rules import analysis
from bt_lsp.rules.context import Context
from bt_lsp.rules.diagnostics import Diagnostic, limited
from bt_lsp.syntax.document import Document


class ProjectIndex:
    """The files of one or more folders.  ``settings`` are the editor's (or the defaults);
    each file's settings are those with its configuration file (:mod:`bt_lsp.project.config`)
    over them, and ``overrides`` (command-line flags) over both."""

    def __init__(
        self,
        roots: Sequence[str | os.PathLike[str]] = (),
        settings: Settings | None = None,
        *,
        configs: Configs | None = None,
        overrides: Layer | None = None,
        ament_prefix_path: Sequence[str] | None = None,
        all_files: bool = False,
    ) -> None:
        self.roots = [normalize(r) for r in roots]
        settings = settings or Settings()
        self.configs = configs if configs is not None else Configs()
        self.settings_index = SettingsIndex(self.roots, settings, self.configs, overrides)
        self.documents = Documents(settings.max_document_bytes)
        # Every file of the folders with ``all_files``, not the first MAX_WORKSPACE_FILES.
        self.files = WorkspaceFiles(
            self.roots, self.settings_index, self.documents, all_files=all_files
        )
        self.packages = Packages()
        # Installed ROS packages (AMENT_PREFIX_PATH unless given) and their catalogs.
        self.ros = RosIndex(self.packages, ament_prefix_path)
        self.scope = PackageScope(
            self.settings_index, self.packages, self.ros, self.files, self.documents
        )
        self.versions = BtcppVersions(
            self.settings_index, self.packages, self.scope, self.documents
        )
        self.includes = IncludeGraph(self.documents, self.settings_index, self.scope)
        self.contexts = FileContexts(
            self.documents,
            self.files,
            self.settings_index,
            self.includes,
            self.scope,
            self.versions,
        )
        # The C++ node catalogs (bt_lsp.project.cpp_models), when the caller reads C++.
        self.cpp: CppModels | None = None

    @property
    def generation(self) -> int:
        """Bumps whenever a file other than an edited open one changes."""
        return self.documents.generation

    # -- documents --------------------------------------------------------------------------

    def open(self, path: str | os.PathLike[str], doc: Document) -> None:
        self.documents.open(path, doc)

    def close(self, path: str | os.PathLike[str]) -> None:
        self.documents.close(path)

    def document(self, path: Path) -> Document | None:
        """The open document at ``path``, else the file on disk (cached), else ``None``."""
        return self.documents.document(path)

    # -- changes --------------------------------------------------------------------------------

    def file_changed(self, path: str | os.PathLike[str]) -> None:
        """A file was created, changed or deleted on disk (workspace/didChangeWatchedFiles)."""
        p = normalize(path)
        self.documents.forget(p)
        self.files.forget()
        if self.configs.changed(p) | self.packages.changed(p):
            self.settings_index.forget()
            self.ros.changed()
        elif p.suffix == ".xml":
            self.ros.file_changed(p)  # it may be a catalog
        if self.cpp is not None:
            self.cpp.file_changed(p)
        self.documents.generation += 1

    def revalidate(self) -> bool:
        """Forget the files whose modification time or size changed since they were read,
        and find the workspace's files again when a file was created or deleted in one of
        its folders (for clients that do not report file changes); ``True`` if any was."""
        changed = self.documents.stale()
        changed += self.configs.revalidate()  # bt-lsp.toml created, edited or deleted
        for p in changed:
            self.file_changed(p)
        # The C++ files read and the folders searched for them, by the same stamps.
        cpp = self.cpp is not None and self.cpp.revalidate()
        if cpp:
            self.documents.generation += 1
        if self.files.revalidate(self.file_changed):
            return True
        return bool(changed) or cpp

    def refresh(self) -> None:
        """Forget everything read from disk (for clients that do not report file changes)."""
        self.documents.forget_all()
        self.files.forget()
        self.settings_index.forget()
        self.configs.changed(Path(CONFIG_FILE))
        self.packages.changed(Path("package.xml"))
        self.ros.changed()
        self.documents.generation += 1

    def set_settings(self, settings: Settings) -> None:
        self.settings_index.set_editor(settings)
        self.documents.max_bytes = settings.max_document_bytes
        self.documents.forget_all()
        self.documents.generation += 1

    def config_edited(self, path: Path, text: str | None) -> bool:
        """A configuration file open in an editor changed (``None``: closed); true if
        ``path`` may be one, and then every file's settings are made again."""
        if not self.settings_index.config_edited(path, text):
            return False
        self.files.forget()  # its exclude globs may have changed
        self.documents.generation += 1
        return True

    # -- what the front ends ask ----------------------------------------------------------------

    def settings_for(self, path: Path) -> Settings:
        """The settings of the file at ``path`` (see :meth:`SettingsIndex.for_path`)."""
        return self.settings_index.for_path(path)

    def config_errors(self) -> list[ConfigError]:
        """The configuration files read so far that cannot be used."""
        return self.settings_index.errors()

    def btcpp_for(self, path: Path, doc: Document | None = None) -> Detected:
        """The BehaviorTree.CPP major version of the file at ``path`` (see
        :meth:`BtcppVersions.of`)."""
        return self.versions.of(path, doc)

    def bt_documents(self) -> Iterator[tuple[Path, Document]]:
        """The workspace's BT documents, open ones as edited (see
        :meth:`WorkspaceFiles.bt_documents`)."""
        return self.files.bt_documents()

    def other_documents(self, path: Path, doc: Document | None = None) -> dict[str, Document]:
        """The other BT documents of the workspace, by path (see
        :meth:`FileContexts.other_documents`)."""
        return self.contexts.other_documents(path, doc)

    def context_for(self, path: Path, doc: Document) -> Context:
        """The rest of the workspace as ``doc`` (at ``path``) sees it (see
        :meth:`FileContexts.context_for`), with the nodes the C++ registers when it is
        read."""
        ctx = self.contexts.context_for(path, doc)
        if self.cpp is not None:
            settings = self.settings_for(path)
            scope = self.scope
            ctx = self.cpp.context_with_models(
                ctx, path, settings, lambda name: scope.dependency(name, settings)
            )
        return ctx

    def diagnostics(self, path: Path, doc: Document) -> list[Diagnostic]:
        """Every diagnostic of ``doc`` in this workspace."""
        if path.suffix in CPP_SUFFIXES:  # a C++ source: the name rules at its literals
            return limited(cpp_diagnostics(doc.text, self.cpp.scanner if self.cpp else None))
        ctx = self.context_for(path, doc)
        out = analysis.analyze(doc, ctx)
        out.extend(self.includes.diagnostics(path, doc))
        out.sort(key=lambda d: (d.start, d.end, d.code))
        out = limited(out)
        if any(d.is_name_rule for d in out):  # where a name must change first, if not here
            out = with_targets(doc, out, self.other_documents(path, doc), ctx.models)
        return out
