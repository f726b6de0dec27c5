"""The workspace: open documents, the BT XML files around them, and their includes.

This is the only layer that reads files.  It resolves ``<include path>`` the way
BehaviorTree.CPP does (relative to the including file; ``ros_pkg`` through the
``rosPackages`` setting), finds include cycles, collects the other BT files of the
workspace folders, and gives each document the :class:`~bt_lsp.rules.context.Context` that the
semantic rules read.  Files are read lazily and cached by modification time and size.
Nothing here ever fetches a URL or follows a DOCTYPE.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Collection, Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass, replace
from pathlib import Path

from bt_lsp.ide.name_targets import with_targets
from bt_lsp.ide.places import IncludeLink
from bt_lsp.project.config import CONFIG_FILE, ConfigError, Configs, Layer, excluded
from bt_lsp.project.cpp_models import CppModels, cpp_diagnostics
from bt_lsp.project.cpp_scan import CPP_SUFFIXES
from bt_lsp.project.fileio import FileError, read_text
from bt_lsp.project.packages import Detected, Manifest, Packages
from bt_lsp.project.ros import RosIndex
from bt_lsp.project.settings import Settings
from bt_lsp.rules import analysis
from bt_lsp.rules.context import Context
from bt_lsp.rules.diagnostics import Diagnostic, limited, make
from bt_lsp.rules.includes import (
    INCLUDE_CYCLE,
    INCLUDE_NOT_FOUND,
    cycle,
    includes_itself,
    not_found,
)
from bt_lsp.rules.shared_context import SharedDecls
from bt_lsp.syntax.document import Document
from bt_lsp.syntax.model import Model

# Folders that never hold a project's own trees (build outputs, VCS, dependencies).
SKIP_DIRS = frozenset(
    {
        ".git",
        ".hg",
        ".svn",
        "node_modules",
        "build",
        "install",
        "log",
        "__pycache__",
        ".venv",
        "venv",
        ".tox",
        ".mypy_cache",
        ".ruff_cache",
        ".pytest_cache",
    }
)
MAX_WORKSPACE_FILES = 5000
MAX_INCLUDE_FILES = 1000
MAX_PACKAGES = 1000  # the dependency closure of one package


def normalize(path: str | os.PathLike[str]) -> Path:
    """An absolute, normalized path (``..`` folded lexically, symlinks kept)."""
    return Path(os.path.normpath(os.path.abspath(os.fspath(path))))


@dataclass(frozen=True, slots=True)
class Include:
    """One ``<include>`` of a document: the span of its ``path`` value and where it leads."""

    start: int
    end: int
    written: str
    target: Path | None  # None when it cannot be resolved (no path, unknown ros_pkg)
    ros_pkg: str | None


def links(includes: Iterable[Include]) -> list[IncludeLink]:
    """The resolved includes as the editing layer takes them (spans and target paths)."""
    return [IncludeLink(i.start, i.end, str(i.target)) for i in includes if i.target is not None]


def includes_of(
    path: Path,
    doc: Document,
    settings: Settings,
    package: Callable[[str], Path | None] | None = None,
) -> list[Include]:
    """The includes of ``doc``; ``ros_pkg`` resolves through the settings, else through
    ``package`` (the workspace's and the installed ROS packages)."""
    out: list[Include] = []
    for el in doc.model.root_children_named(("include",)):  # the INCLUDE zone
        a = el.attr("path")
        if a is None or a.value is None or not a.value.strip():
            continue  # include-missing-path is a semantic rule of the document itself
        start, end = el.span_of_value(a)
        written = a.value.strip()
        pkg = el.value("ros_pkg")
        target: Path | None
        if os.path.isabs(written):
            target = normalize(written)
        elif pkg:
            base: str | Path | None = settings.ros_packages.get(pkg)
            if base is None and package is not None:
                base = package(pkg)
            target = normalize(Path(base) / written) if base else None
        else:
            target = normalize(path.parent / written)
        out.append(Include(start, end, written, target, pkg or None))
    return out


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
        # Every file of the folders, not the first MAX_WORKSPACE_FILES: the command line
        # reads every file it checks anyway, and a tree in a file left out is unknown.
        self.all_files = all_files
        self.settings = settings or Settings()
        self.configs = configs if configs is not None else Configs()
        self.overrides = overrides
        self.packages = Packages()
        # Installed ROS packages (AMENT_PREFIX_PATH unless given) and their catalogs.
        self.ros = RosIndex(self.packages, ament_prefix_path)
        self._ros_workspace: tuple[list[Path], dict[str, Path]] | None = None
        # Folder -> (generation, settings, its package's and its dependencies' folders).
        self._package_folders: dict[Path, tuple[int, Settings, list[Path]]] = {}
        # Folder -> (the editor settings they were made from, the folder's settings).
        self._scoped: dict[Path, tuple[Settings, Settings]] = {}
        self._open: dict[Path, Document] = {}
        self._disk: dict[Path, tuple[tuple[int, int], Document | None, str | None]] = {}
        self._files: list[Path] | None = None
        # The folders walked for _files, with their modification times: a file created,
        # deleted or renamed in one changes its folder's (see revalidate).
        self._folders: dict[str, int] = {}
        self._includes: dict[Path, tuple[Model, Settings, list[Include]]] = {}
        self._paths: tuple[tuple[int, tuple[Path, ...]], list[Path]] | None = None
        self.generation = 0  # bumps whenever a file other than an edited open one changes
        # The other documents combined once per set of catalogs left out (see _shared).
        self._shared_stamp: tuple[object, ...] | None = None
        self._shared_by_skip: dict[
            frozenset[Path], tuple[SharedDecls, Mapping[Path, list[Path]]]
        ] = {}
        self._documents_by_name: dict[str, Document] | None = None
        self._foreign_by_packages: dict[frozenset[Path], frozenset[str]] = {}
        # The C++ node catalogs (bt_lsp.project.cpp_models), when the caller reads C++.
        self.cpp: CppModels | None = None

    # -- documents --------------------------------------------------------------------------

    def open(self, path: str | os.PathLike[str], doc: Document) -> None:
        self._open[normalize(path)] = doc

    def close(self, path: str | os.PathLike[str]) -> None:
        p = normalize(path)
        self._open.pop(p, None)
        self._disk.pop(p, None)  # read again: the file may have been saved while open
        self.generation += 1

    def is_open(self, path: Path) -> bool:
        return path in self._open

    def document(self, path: Path) -> Document | None:
        """The open document at ``path``, else the file on disk (cached), else ``None``."""
        doc = self._open.get(path)
        if doc is not None:
            return doc
        return self._read(path)[0]

    def read_document(self, path: Path, text: str) -> Document | None:
        """The document already read from disk at ``path`` if its text is ``text`` (never
        reads): a caller that read the file itself parses it once."""
        hit = self._disk.get(path)
        doc = hit[1] if hit is not None else None
        return doc if doc is not None and doc.text == text else None

    def read_error(self, path: Path) -> str | None:
        if path in self._open:
            return None
        return self._read(path)[1]

    def _read(self, path: Path) -> tuple[Document | None, str | None]:
        """Read a file once; it is read again only after :meth:`file_changed` (the server
        hears of changes through watched-file notifications) or :meth:`refresh`."""
        cached = self._disk.get(path)
        if cached is not None:
            return cached[1], cached[2]
        try:
            st = path.stat()
        except OSError as e:
            self._disk[path] = ((0, 0), None, e.strerror or str(e))
            return None, e.strerror or str(e)
        except ValueError as e:  # a path the OS cannot look up ("embedded null byte")
            self._disk[path] = ((0, 0), None, str(e))
            return None, str(e)
        if not path.is_file():
            self._disk[path] = ((st.st_mtime_ns, st.st_size), None, "not a file")
            return None, "not a file"
        stamp = (st.st_mtime_ns, st.st_size)
        try:
            decoded = read_text(str(path), max_bytes=self.settings.max_document_bytes)
            doc: Document | None = Document(decoded.text, str(path))
            err = None
        except FileError as e:
            doc, err = None, e.message
        self._disk[path] = (stamp, doc, err)
        return doc, err

    def file_changed(self, path: str | os.PathLike[str]) -> None:
        """A file was created, changed or deleted on disk (workspace/didChangeWatchedFiles)."""
        p = normalize(path)
        self._disk.pop(p, None)
        self._files = None
        if self.configs.changed(p) | self.packages.changed(p):
            self._scoped.clear()
            self.ros.changed()
        elif p.suffix == ".xml":
            self.ros.file_changed(p)  # it may be a catalog
        if self.cpp is not None:
            self.cpp.file_changed(p)
        self.generation += 1

    def revalidate(self) -> bool:
        """Forget the files whose modification time or size changed since they were read,
        and find the workspace's files again when a file was created or deleted in one of
        its folders (for clients that do not report file changes); ``True`` if any was."""
        changed = [p for p, (stamp, _, _) in self._disk.items() if _stamp(p) != stamp]
        changed += self.configs.revalidate()  # bt-lsp.toml created, edited or deleted
        for p in changed:
            self.file_changed(p)
        # The C++ files read and the folders searched for them, by the same stamps.
        cpp = self.cpp is not None and self.cpp.revalidate()
        if cpp:
            self.generation += 1
        if self._files is not None and any(_folder_stamp(d) != t for d, t in self._folders.items()):
            before = self._files
            self._files = None
            now = self.files()
            if now != before:
                for p in set(before).symmetric_difference(now):
                    self.file_changed(p)  # a catalog, a package.xml: forgotten
                self._files = now
                return True
        return bool(changed) or cpp

    def refresh(self) -> None:
        """Forget everything read from disk (for clients that do not report file changes)."""
        self._disk.clear()
        self._files = None
        self._scoped.clear()
        self.configs.changed(Path(CONFIG_FILE))
        self.packages.changed(Path("package.xml"))
        self.ros.changed()
        self.generation += 1

    # -- each file's settings -------------------------------------------------------------------

    def settings_for(self, path: Path) -> Settings:
        """The settings of the file at ``path``: command-line flags over its configuration
        file over the editor settings (the same object while none of them changes)."""
        folder = path.parent
        hit = self._scoped.get(folder)
        if hit is not None and hit[0] is self.settings:
            return hit[1]
        scoped = self._editor_settings()
        config = self.configs.for_path(path)
        if config is not None and not isinstance(config, ConfigError):
            scoped = config.over(scoped)
        if self.overrides is not None:
            scoped = self.overrides.over(scoped)
        if scoped == self.settings:
            scoped = self.settings
        self._scoped[folder] = (self.settings, scoped)
        return scoped

    def _editor_settings(self) -> Settings:
        """The editor settings with their relative model files resolved against the first
        workspace folder, as they always were."""
        models = tuple(self.model_files())
        if models == self.settings.models:
            return self.settings
        return replace(self.settings, models=models)

    def config_edited(self, path: Path, text: str | None) -> bool:
        """A configuration file open in an editor changed (``None``: closed); true if
        ``path`` may be one, and then every file's settings are made again."""
        if not self.configs.set_text(normalize(path), text):
            return False
        self._scoped.clear()
        self._files = None  # its exclude globs may have changed
        self.generation += 1
        return True

    def config_errors(self) -> list[ConfigError]:
        """The configuration files read so far that cannot be used."""
        return self.configs.errors()

    def btcpp_for(self, path: Path, doc: Document | None = None) -> Detected:
        """The BehaviorTree.CPP major version the file at ``path`` is built for: the
        ``btcpp`` setting if not ``auto``, else what its package's build uses
        (``CMakeLists.txt`` and C++ includes, then ``package.xml``: see
        :meth:`Packages.package_btcpp`; unclear when they name both versions), else its
        dependencies' ``package.xml``, else the document's ``BTCPP_format``."""
        chosen = self.settings_for(path).btcpp
        if chosen in ("3", "4"):
            return Detected(chosen, "the btcpp setting")
        found = self.packages.btcpp_of(path.parent)
        if found.version is not None or found.conflict:
            return found
        # A package that does not name BehaviorTree.CPP builds against the version of the
        # packages it depends on (a tutorial package over its library package).
        for folder in self.package_folders(path)[1:]:
            m = self.packages.manifest(folder / "package.xml")
            if m is not None and m.btcpp is not None:
                return Detected(
                    m.btcpp,
                    f"{m.folder / 'package.xml'} (of the dependency {m.name}) names "
                    f"BehaviorTree.CPP {m.btcpp}",
                )
        doc = doc if doc is not None else self.document(path)
        root = doc.model.root if doc is not None else None
        if root is not None and root.name == "root":
            written = (root.value("BTCPP_format") or "").strip()
            if written in ("3", "4"):
                return Detected(written, "the document's BTCPP_format=\"" + written + '"')
        return found

    def set_settings(self, settings: Settings) -> None:
        self.settings = settings
        self._scoped.clear()
        self._disk.clear()
        self.generation += 1

    # -- the workspace's BT files -------------------------------------------------------------

    def files(self) -> list[Path]:
        """Every BT XML file under the workspace folders and the model files from the
        settings (sorted; skipping build and VCS folders; at most MAX_WORKSPACE_FILES
        unless ``all_files``)."""
        if self._files is None:
            found: set[Path] = set()
            self._folders = {}
            for root in self.roots:
                for p in _walk_xml(root, self.is_excluded, self._folders):
                    found.add(p)
                    if len(found) >= MAX_WORKSPACE_FILES and not self.all_files:
                        break
            found.update(self.model_files())
            self._files = sorted(found)
        return self._files

    def is_excluded(self, path: Path, is_dir: bool = False) -> bool:
        """Whether the configuration's ``exclude`` globs leave ``path`` out of the
        workspace (a folder's globs are those of a file inside it)."""
        return excluded(path, self.settings_for(path / "-" if is_dir else path).exclude)

    def model_files(self) -> list[Path]:
        """The model files named in the settings (relative to the first workspace folder)."""
        out = []
        for mp in self.settings.models:
            out.append(normalize(mp if mp.is_absolute() or not self.roots else self.roots[0] / mp))
        return out

    def bt_documents(self) -> Iterator[tuple[Path, Document]]:
        key = (self.generation, tuple(self._open))
        if self._paths is None or self._paths[0] != key:
            # An open excluded file is diagnosed (it was opened) but is no more part of
            # the workspace for the other files than when it is closed.
            shown = {p for p in self._open if not self.is_excluded(p)}
            self._paths = (key, sorted(set(self.files()) | shown))
        for p in self._paths[1]:
            doc = self.document(p)
            if doc is not None and (doc.is_bt or p.suffix == ".btproj"):
                yield p, doc

    # -- includes -----------------------------------------------------------------------------

    def includes(self, path: Path, doc: Document | None = None) -> list[Include]:
        doc = doc if doc is not None else self.document(path)
        if doc is None:
            return []
        # Kept per path while the document's model and the settings are the same (every
        # document's includes are looked at for every other one).
        model = doc.model
        settings = self.settings_for(path)
        hit = self._includes.get(path)
        if hit is not None and hit[0] is model and hit[1] is settings:
            return hit[2]
        found = includes_of(path, doc, settings, lambda name: self.ros_package(name, settings))
        self._includes[path] = (model, settings, found)
        return found

    def include_closure(self, path: Path, doc: Document | None = None) -> list[Path]:
        """Files reachable through includes from ``path`` (not ``path`` itself), in
        depth-first order; iterative and bounded, cycles are cut."""
        seen = {path}
        order: list[Path] = []
        stack: list[Path] = [
            inc.target for inc in reversed(self.includes(path, doc)) if inc.target is not None
        ]
        while stack and len(order) < MAX_INCLUDE_FILES:
            p = stack.pop()
            if p in seen:
                continue
            seen.add(p)
            order.append(p)
            for inc in reversed(self.includes(p)):
                if inc.target is not None and inc.target not in seen:
                    stack.append(inc.target)
        return order

    def _reaches(self, start: Path, goal: Path) -> list[Path] | None:
        """A chain of includes from ``start`` to ``goal`` (both included), or None."""
        parent: dict[Path, Path | None] = {start: None}
        stack = [start]
        while stack and len(parent) < MAX_INCLUDE_FILES:
            p = stack.pop()
            if p == goal:
                chain = [p]
                while parent[chain[-1]] is not None:
                    prev = parent[chain[-1]]
                    assert prev is not None
                    chain.append(prev)
                return chain[::-1]
            for inc in self.includes(p):
                t = inc.target
                if t is not None and t not in parent:
                    parent[t] = p
                    stack.append(t)
        return None

    def include_diagnostics(self, path: Path, doc: Document) -> list[Diagnostic]:
        """``include-not-found`` and ``include-cycle`` for the includes of one document."""
        out: list[Diagnostic] = []
        for inc in self.includes(path, doc):
            if inc.target is None:
                continue  # no path / unmapped ros_pkg: the document's own rules say so
            if inc.target == path:
                out.append(
                    make(inc.start, inc.end, INCLUDE_CYCLE.code, includes_itself(inc.written))
                )
                continue
            if self.document(inc.target) is None:
                why = self.read_error(inc.target) or "cannot be read"
                out.append(
                    make(
                        inc.start,
                        inc.end,
                        INCLUDE_NOT_FOUND.code,
                        not_found(inc.written, str(inc.target), why),
                    )
                )
                continue
            chain = self._reaches(inc.target, path)
            if chain is not None:
                names = " → ".join(_short(p, path) for p in [path, *chain])
                out.append(make(inc.start, inc.end, INCLUDE_CYCLE.code, cycle(names)))
        return out

    # -- what one document sees ----------------------------------------------------------------

    def context_for(self, path: Path, doc: Document) -> Context:
        """The rest of the workspace as ``doc`` (at ``path``) sees it: its include closure
        (trees join its namespace) and every other BT file (models count).  The other
        files are combined once for all the files that leave out the same catalogs
        (:meth:`_shared`), so that a folder's check grows with its number of files."""
        closure = self.include_closure(path, doc)
        in_closure = set(closure)
        # BehaviorTree.CPP loads included documents depth-first before the includer.
        included: list[tuple[str, Document]] = []
        for p in reversed(closure):
            d = self.document(p)
            if d is not None:
                included.append((str(p), d))
        settings = self.settings_for(path)
        model_paths = self.model_catalogs(path)
        model_files: list[tuple[str, Document]] = []
        for p in model_paths:
            d = self.document(p)
            if d is not None and p != path:
                model_files.append((str(p), d))
        skip = set(model_paths)
        # The catalogs of the document's ROS package and its dependencies: authoritative
        # for their nodes (what the package registers), but not complete (one package's
        # catalog does not list every node the application registers).
        ros_models: list[tuple[str, Document]] = []
        for p in self.ros_catalogs(path):
            d = self.document(p)
            if d is not None and p != path and p not in skip and p not in in_closure:
                skip.add(p)
                ros_models.append((str(p), d))
        # Another workspace package's catalogs are not this document's unless it depends
        # on that package.
        skip.update(self.unrelated_catalogs(path))
        shared, includers = self._shared(frozenset(skip), (path, doc))
        included_by = [str(p) for p in includers.get(path, ()) if p not in in_closure]
        detected = self.btcpp_for(path, doc)
        ctx = shared.context(
            doc,
            included,
            path=str(path),
            ros_pkg_paths=self._ros_paths(path, doc, settings),
            model_files=model_files,
            ros_models=ros_models,
            included_by=included_by,
            btcpp_version=detected.version,
            foreign=self._foreign(path, doc),
            btcpp_unclear=detected.conflict,
        )
        if self.cpp is not None:
            ctx = self.cpp.context_with_models(
                ctx, path, settings, lambda name: self._dependency(name, settings)
            )
        return ctx

    def _check_shared(self, own: Path | None = None, doc: Document | None = None) -> None:
        """Forget what :meth:`_shared`, :meth:`_foreign` and :meth:`other_documents` made
        once a file changed or an open document was edited.

        ``own`` is the document they are asked for (``doc``: its text being analysed, a
        snapshot of the open one).  What they made leaves its own declarations out of
        what they give for it, so an edit of ``own`` alone keeps them for it, and its open
        document's model is not made here: the analysis of a snapshot on the worker
        thread made the open document's model as well (a second one, which the open
        document then kept instead of the snapshot's, so that the next edit's model
        shared no section with the last one analysed), and every edit combined the
        workspace again for the one document in it."""
        models = tuple(
            (None if doc is None else doc.model) if p == own else d.model
            for p, d in self._open.items()
        )
        stamp = (self.generation, tuple(self._open), models)
        old = self._shared_stamp
        if old is None or not _same(old, stamp, own):
            self._shared_by_skip.clear()
            self._foreign_by_packages.clear()
            self._documents_by_name = None
            # Its slot holds the model its caches were made from, or None: unknown (a
            # check for another document then finds it changed).
            self._shared_stamp = stamp

    def _shared(
        self, skip: frozenset[Path], own: tuple[Path, Document] | None = None
    ) -> tuple[SharedDecls, Mapping[Path, list[Path]]]:
        """The workspace's BT documents but ``skip``, combined once while none of them
        changes, and who includes whom among them (the includers of each path, in order).
        ``own``: the document asked for and its text being analysed (see
        :meth:`_check_shared`), which stands for the open document at its path."""
        self._check_shared(*(own or (None, None)))
        hit = self._shared_by_skip.get(skip)
        if hit is not None:
            return hit
        docs = [(p, d) for p, d in self.bt_documents() if p not in skip]
        if own is not None and own[0] in self._open:
            docs = [(p, own[1] if p == own[0] else d) for p, d in docs]
        includers: dict[Path, list[Path]] = {}
        for p, d in docs:
            for target in dict.fromkeys(i.target for i in self.includes(p, d)):
                if target is not None and target != p:
                    includers.setdefault(target, []).append(p)
        made = (SharedDecls([(str(p), d) for p, d in docs]), includers)
        self._shared_by_skip[skip] = made
        return made

    def _dependency(self, name: str, settings: Settings) -> tuple[Manifest | None, list[Path]]:
        """A ROS package outside the workspace C++: its manifest and shipped catalogs."""
        folder = self.ros_package(name, settings)
        manifest = self.packages.manifest(folder / "package.xml") if folder else None
        if folder is None or manifest is None:
            return None, []
        return manifest, [normalize(p) for p in self.ros.catalogs(folder)]

    def catalog_files(self, path: Path) -> list[Path]:
        """The node catalog files in scope for the document at ``path``: the ``models``
        of its settings (configuration file, flags, editor), then those its ROS package
        ships and those of the packages its ``package.xml`` depends on."""
        out = self.model_catalogs(path)
        out.extend(p for p in self.ros_catalogs(path) if p not in out)
        return out

    def model_catalogs(self, path: Path) -> list[Path]:
        """The ``models`` of the settings of the file at ``path``, as absolute paths."""
        out: list[Path] = []
        for m in self.settings_for(path).models:
            p = normalize(m if m.is_absolute() or not self.roots else self.roots[0] / m)
            if p not in out:
                out.append(p)
        return out

    def ros_catalogs(self, path: Path) -> list[Path]:
        """The catalogs that the ROS package of the file at ``path`` ships and those of
        the packages its ``package.xml`` depends on (workspace or installed)."""
        out: list[Path] = []
        for folder in self.package_folders(path):
            for p in self.ros.catalogs(folder):
                p = normalize(p)
                if p not in out and p != path:
                    out.append(p)
        return out

    def package_folders(self, path: Path) -> list[Path]:
        """The folder of the ROS package of the file at ``path`` and those of the packages
        it depends on, transitively (through each dependency's own ``package.xml``, in
        the workspace or installed; cycles cut), breadth first; empty outside a package."""
        settings = self.settings_for(path)
        hit = self._package_folders.get(path.parent)
        if hit is not None and hit[0] == self.generation and hit[1] is settings:
            return hit[2]
        folders = self._dependency_folders(path, settings)
        self._package_folders[path.parent] = (self.generation, settings, folders)
        return folders

    def _dependency_folders(self, path: Path, settings: Settings) -> list[Path]:
        own = self.packages.package_of(path.parent)
        if own is None:
            return []
        folders = [own.folder]
        seen = {own.name}
        todo = [own]
        while todo and len(folders) < MAX_PACKAGES:
            m = todo.pop(0)
            for dep in sorted(m.depends - seen):
                seen.add(dep)
                folder = self.ros_package(dep, settings)
                if folder is None or folder in folders:
                    continue
                folders.append(folder)
                found = self.packages.manifest(folder / "package.xml")
                if found is not None:
                    todo.append(found)
        return folders

    def unrelated_catalogs(self, path: Path) -> set[Path]:
        """The catalogs shipped by the workspace packages that the package of ``path``
        neither is nor depends on (none outside a package: a loose file sees them all)."""
        mine = self.package_folders(path)
        if not mine:
            return set()
        out: set[Path] = set()
        for folder in self.workspace_packages().values():
            if folder not in mine:
                out.update(normalize(p) for p in self.ros.catalogs(folder))
        return out

    def _foreign(self, path: Path, doc: Document | None = None) -> frozenset[str]:
        """The workspace's BT files whose models do not count for the file at ``path``:
        those of packages its package neither is nor depends on (see :meth:`_unrelated`);
        made once per package while no file changes, so that a folder's check stays
        linear."""
        mine = frozenset(self.package_folders(path))
        if not mine:
            return frozenset()
        self._check_shared(path, doc)  # (``path`` itself is never foreign to itself)
        hit = self._foreign_by_packages.get(mine)
        if hit is None:
            hit = frozenset(str(p) for p, _ in self.bt_documents() if self._unrelated(p, mine))
            self._foreign_by_packages[mine] = hit
        return hit

    def _unrelated(self, p: Path, mine: Collection[Path]) -> bool:
        """Whether the BT file ``p`` (its ``<TreeNodesModel>``, a Groot2 palette) belongs
        to a package outside ``mine`` (a package and its dependencies): its models then
        describe another package's nodes.  A file outside any package sees every model
        (as it sees every catalog), and a file in a package also sees those of files
        outside any package (a repository's shared palette)."""
        pkg = self.packages.package_of(p.parent)
        return pkg is not None and pkg.folder not in mine

    # -- ROS packages --------------------------------------------------------------------------

    def workspace_packages(self) -> Mapping[str, Path]:
        """The ROS packages of the workspace folders: each ``package.xml`` among their
        files (a colcon workspace's ``src/``), by package name, the first found kept."""
        files = self.files()
        if self._ros_workspace is None or self._ros_workspace[0] is not files:
            found: dict[str, Path] = {}
            for p in files:
                if p.name == "package.xml":
                    m = self.packages.manifest(p)
                    if m is not None:
                        found.setdefault(m.name, m.folder)
            self._ros_workspace = (files, found)
        return self._ros_workspace[1]

    def ros_package(self, name: str, settings: Settings | None = None) -> Path | None:
        """The folder of ROS package ``name``: the settings' ``ros-packages``, the
        workspace's packages, then the installed ones (``AMENT_PREFIX_PATH``)."""
        configured = (settings or self.settings).ros_packages
        return self.ros.folder(name, configured, self.workspace_packages())

    def _ros_paths(self, path: Path, doc: Document, settings: Settings) -> Mapping[str, str]:
        """The packages the rules may take as known: the configured ones and those the
        document's includes name that resolve."""
        named = {i.ros_pkg for i in self.includes(path, doc) if i.ros_pkg and i.target}
        if not named - settings.ros_packages.keys():
            return settings.ros_packages
        out = dict(settings.ros_packages)
        for name in sorted(named):
            folder = self.ros_package(name, settings)
            if folder is not None and name not in out:
                out[name] = str(folder)
        return out

    def diagnostics(self, path: Path, doc: Document) -> list[Diagnostic]:
        """Every diagnostic of ``doc`` in this workspace."""
        if path.suffix in CPP_SUFFIXES:  # a C++ source: the name rules at its literals
            return limited(cpp_diagnostics(doc.text, self.cpp.scanner if self.cpp else None))
        ctx = self.context_for(path, doc)
        out = analysis.analyze(doc, ctx)
        out.extend(self.include_diagnostics(path, doc))
        out.sort(key=lambda d: (d.start, d.end, d.code))
        out = limited(out)
        if any(d.is_name_rule for d in out):  # where a name must change first, if not here
            out = with_targets(doc, out, self.other_documents(path, doc), ctx.models)
        return out

    def other_documents(self, path: Path, doc: Document | None = None) -> dict[str, Document]:
        """The other BT documents of the workspace (open ones as edited), by path: what a
        rename or a name fix of the document at ``path`` (``doc``: its text in use, see
        :meth:`_check_shared`) reaches and checks."""
        self._check_shared(path, doc)  # (the document itself is left out)
        if self._documents_by_name is None:
            self._documents_by_name = {str(p): d for p, d in self.bt_documents()}
        out = dict(self._documents_by_name)  # copied whole (in C), then less one
        out.pop(str(path), None)
        return out

    def dependents(self, path: Path) -> list[Path]:
        """Open documents whose include closure contains ``path``."""
        return [p for p in self._open if p != path and path in self.include_closure(p)]


def _stamp(path: Path) -> tuple[int, int]:
    """What :meth:`Workspace._read` records of a file: (mtime_ns, size), (0, 0) if none."""
    try:
        st = path.stat()
    except (OSError, ValueError):
        return (0, 0)
    return (st.st_mtime_ns, st.st_size)


def _same(a: tuple[object, ...], b: tuple[object, ...], own: Path | None) -> bool:
    """Whether two stamps of :meth:`ProjectIndex._check_shared` are the same: equal
    generations and open paths, and the same model objects (compared by identity) but
    that of the open document at ``own``."""
    if a[0] != b[0] or a[1] != b[1]:
        return False
    paths = b[1]
    assert isinstance(paths, tuple)
    skip = paths.index(own) if own in paths else -1
    return all(
        x is y or k == skip
        for k, (x, y) in enumerate(zip(a[2], b[2], strict=True))  # type: ignore[call-overload]
    )


def _short(p: Path, base: Path) -> str:
    try:
        return os.path.relpath(p, base.parent)
    except ValueError:
        return str(p)


def _folder_stamp(folder: str) -> int:
    """A folder's modification time (-1 if it is gone)."""
    try:
        return os.stat(folder).st_mtime_ns
    except (OSError, ValueError):
        return -1


def _walk_xml(
    root: Path, skip: Callable[[Path, bool], bool], folders: dict[str, int] | None = None
) -> Iterable[Path]:
    """The XML and ``.btproj`` files under ``root``, but what ``skip(path, is_dir)``
    leaves out (the configuration's ``exclude``); each folder walked is recorded in
    ``folders`` with its modification time, taken before it is listed (a file created
    meanwhile shows)."""
    if root.is_file():
        if root.suffix in (".xml", ".btproj") and not skip(root, False):
            yield root
        return
    if folders is not None:
        folders[str(root)] = _folder_stamp(str(root))
    for dirpath, dirnames, filenames in os.walk(root):
        here = Path(dirpath)
        dirnames[:] = sorted(
            d
            for d in dirnames
            if d not in SKIP_DIRS and not d.startswith(".") and not skip(here / d, True)
        )
        if folders is not None:
            for d in dirnames:
                path = os.path.join(dirpath, d)
                folders[path] = _folder_stamp(path)
        for f in sorted(filenames):
            if f.endswith((".xml", ".btproj")):
                p = normalize(here / f)
                if not skip(p, False):
                    yield p
