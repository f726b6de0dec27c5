"""What one document sees of the rest of the project: the trees of its include closure
(they join its namespace), the models of its catalogs and of the workspace's other BT
files, and its BehaviorTree.CPP version, as the :class:`~bt_lsp.rules.context.Context`
that the semantic rules read.

The other files are combined once for all the files that leave out the same catalogs,
while none of them changes, so that a folder's check grows with its number of files,
not its square.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

from bt_lsp.project.documents import Documents
from bt_lsp.project.include_graph import IncludeGraph
from bt_lsp.project.package_scope import PackageScope
from bt_lsp.project.settings import Settings
from bt_lsp.project.settings_index import SettingsIndex
from bt_lsp.project.versions import BtcppVersions
from bt_lsp.project.workspace_files import WorkspaceFiles
from bt_lsp.rules.context import Context
from bt_lsp.rules.shared_context import SharedDecls
from bt_lsp.syntax.document import Document


class FileContexts:
    """Each document's context in the project, and the other documents it reaches."""

    def __init__(
        self,
        documents: Documents,
        files: WorkspaceFiles,
        settings: SettingsIndex,
        includes: IncludeGraph,
        scope: PackageScope,
        versions: BtcppVersions,
    ) -> None:
        self._documents = documents
        self._files = files
        self._settings = settings
        self._includes = includes
        self._scope = scope
        self._versions = versions
        # The other documents combined once per set of catalogs left out (see _shared),
        # while the documents are in the state _stamp records.
        self._stamp: tuple[object, ...] | None = None
        self._shared_by_skip: dict[
            frozenset[Path], tuple[SharedDecls, Mapping[Path, list[Path]]]
        ] = {}
        self._documents_by_name: dict[str, Document] | None = None
        self._foreign_by_packages: dict[frozenset[Path], frozenset[str]] = {}

    def context_for(self, path: Path, doc: Document) -> Context:
        """The rest of the workspace as ``doc`` (at ``path``) sees it: its include closure
        (trees join its namespace) and every other BT file (models count).  The other
        files are combined once for all the files that leave out the same catalogs
        (:meth:`_shared`), so that a folder's check grows with its number of files."""
        docs = self._documents
        closure = self._includes.closure(path, doc)
        in_closure = set(closure)
        # BehaviorTree.CPP loads included documents depth-first before the includer.
        included: list[tuple[str, Document]] = []
        for p in reversed(closure):
            d = docs.document(p)
            if d is not None:
                included.append((str(p), d))
        settings = self._settings.for_path(path)
        model_paths = self._scope.model_catalogs(path)
        model_files: list[tuple[str, Document]] = []
        for p in model_paths:
            d = docs.document(p)
            if d is not None and p != path:
                model_files.append((str(p), d))
        skip = set(model_paths)
        # The catalogs of the document's ROS package and its dependencies: authoritative
        # for their nodes (what the package registers), but not complete (one package's
        # catalog does not list every node the application registers).
        ros_models: list[tuple[str, Document]] = []
        for p in self._scope.ros_catalogs(path):
            d = docs.document(p)
            if d is not None and p != path and p not in skip and p not in in_closure:
                skip.add(p)
                ros_models.append((str(p), d))
        # Another workspace package's catalogs are not this document's unless it depends
        # on that package.
        skip.update(self._scope.unrelated_catalogs(path))
        shared, includers = self._shared(frozenset(skip), (path, doc))
        included_by = [str(p) for p in includers.get(path, ()) if p not in in_closure]
        detected = self._versions.of(path, doc)
        return shared.context(
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

    def other_documents(self, path: Path, doc: Document | None = None) -> dict[str, Document]:
        """The other BT documents of the workspace (open ones as edited), by path: what a
        rename or a name fix of the document at ``path`` (``doc``: its text in use, see
        :meth:`_check_stamp`) reaches and checks."""
        self._check_stamp(path, doc)  # (the document itself is left out)
        if self._documents_by_name is None:
            self._documents_by_name = {str(p): d for p, d in self._files.bt_documents()}
        out = dict(self._documents_by_name)  # copied whole (in C), then less one
        out.pop(str(path), None)
        return out

    def _check_stamp(self, own: Path | None = None, doc: Document | None = None) -> None:
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
        stamp = self._documents.state(own, doc)
        old = self._stamp
        if old is None or not _same(old, stamp, own):
            self._shared_by_skip.clear()
            self._foreign_by_packages.clear()
            self._documents_by_name = None
            # Its slot holds the model its caches were made from, or None: unknown (a
            # check for another document then finds it changed).
            self._stamp = stamp

    def _shared(
        self, skip: frozenset[Path], own: tuple[Path, Document] | None = None
    ) -> tuple[SharedDecls, Mapping[Path, list[Path]]]:
        """The workspace's BT documents but ``skip``, combined once while none of them
        changes, and who includes whom among them (the includers of each path, in order).
        ``own``: the document asked for and its text being analysed (see
        :meth:`_check_stamp`), which stands for the open document at its path."""
        self._check_stamp(*(own or (None, None)))
        hit = self._shared_by_skip.get(skip)
        if hit is not None:
            return hit
        docs = [(p, d) for p, d in self._files.bt_documents() if p not in skip]
        if own is not None and self._documents.is_open(own[0]):
            docs = [(p, own[1] if p == own[0] else d) for p, d in docs]
        includers: dict[Path, list[Path]] = {}
        for p, d in docs:
            for target in dict.fromkeys(i.target for i in self._includes.of(p, d)):
                if target is not None and target != p:
                    includers.setdefault(target, []).append(p)
        made = (SharedDecls([(str(p), d) for p, d in docs]), includers)
        self._shared_by_skip[skip] = made
        return made

    def _foreign(self, path: Path, doc: Document | None = None) -> frozenset[str]:
        """The workspace's BT files whose models do not count for the file at ``path``:
        those of packages its package neither is nor depends on (see
        :meth:`PackageScope.unrelated`); made once per package while no file changes, so
        that a folder's check stays linear."""
        mine = frozenset(self._scope.package_folders(path))
        if not mine:
            return frozenset()
        self._check_stamp(path, doc)  # (``path`` itself is never foreign to itself)
        hit = self._foreign_by_packages.get(mine)
        if hit is None:
            hit = frozenset(
                str(p) for p, _ in self._files.bt_documents() if self._scope.unrelated(p, mine)
            )
            self._foreign_by_packages[mine] = hit
        return hit

    def _ros_paths(self, path: Path, doc: Document, settings: Settings) -> Mapping[str, str]:
        """The packages the rules may take as known: the configured ones and those the
        document's includes name that resolve."""
        named = {i.ros_pkg for i in self._includes.of(path, doc) if i.ros_pkg and i.target}
        if not named - settings.ros_packages.keys():
            return settings.ros_packages
        out = dict(settings.ros_packages)
        for name in sorted(named):
            folder = self._scope.ros_package(name, settings)
            if folder is not None and name not in out:
                out[name] = str(folder)
        return out


def _same(a: tuple[object, ...], b: tuple[object, ...], own: Path | None) -> bool:
    """Whether two stamps of :meth:`FileContexts._check_stamp` are the same: equal
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
