"""Which ROS packages a file's package reaches, and so which node catalogs apply to it.

A file's catalogs are the ``models`` of its settings, then those its ROS package ships and
those of the packages its ``package.xml`` depends on, transitively (in the workspace or
installed).  Another workspace package's catalogs are not the file's unless its package
depends on that one: their nodes are registered by another application.
"""

from __future__ import annotations

from collections.abc import Collection, Mapping
from pathlib import Path

from bt_lsp.project.documents import Documents
from bt_lsp.project.packages import Manifest, Packages
from bt_lsp.project.paths import normalize
from bt_lsp.project.ros import RosIndex
from bt_lsp.project.settings import Settings
from bt_lsp.project.settings_index import SettingsIndex
from bt_lsp.project.workspace_files import WorkspaceFiles

MAX_PACKAGES = 1000  # the dependency closure of one package


class PackageScope:
    """The ROS packages of the workspace and the installed ones (``ros``), and the
    packages and catalogs each file's package reaches."""

    def __init__(
        self,
        settings: SettingsIndex,
        packages: Packages,
        ros: RosIndex,
        files: WorkspaceFiles,
        documents: Documents,
    ) -> None:
        self._settings = settings
        self._packages = packages
        self._ros = ros
        self._files = files
        self._documents = documents  # its generation dates what is kept here
        self._ros_workspace: tuple[list[Path], dict[str, Path]] | None = None
        # Folder -> (generation, settings, its package's and its dependencies' folders).
        self._package_folders: dict[Path, tuple[int, Settings, list[Path]]] = {}

    # -- ROS packages --------------------------------------------------------------------------

    def workspace_packages(self) -> Mapping[str, Path]:
        """The ROS packages of the workspace folders: each ``package.xml`` among their
        files (a colcon workspace's ``src/``), by package name, the first found kept."""
        files = self._files.paths()
        if self._ros_workspace is None or self._ros_workspace[0] is not files:
            found: dict[str, Path] = {}
            for p in files:
                if p.name == "package.xml":
                    m = self._packages.manifest(p)
                    if m is not None:
                        found.setdefault(m.name, m.folder)
            self._ros_workspace = (files, found)
        return self._ros_workspace[1]

    def ros_package(self, name: str, settings: Settings | None = None) -> Path | None:
        """The folder of ROS package ``name``: the settings' ``ros-packages``, the
        workspace's packages, then the installed ones (``AMENT_PREFIX_PATH``)."""
        configured = (settings or self._settings.editor).ros_packages
        return self._ros.folder(name, configured, self.workspace_packages())

    def package_folders(self, path: Path) -> list[Path]:
        """The folder of the ROS package of the file at ``path`` and those of the packages
        it depends on, transitively (through each dependency's own ``package.xml``, in
        the workspace or installed; cycles cut), breadth first; empty outside a package."""
        settings = self._settings.for_path(path)
        generation = self._documents.generation
        hit = self._package_folders.get(path.parent)
        if hit is not None and hit[0] == generation and hit[1] is settings:
            return hit[2]
        folders = self._dependency_folders(path, settings)
        self._package_folders[path.parent] = (generation, settings, folders)
        return folders

    def _dependency_folders(self, path: Path, settings: Settings) -> list[Path]:
        own = self._packages.package_of(path.parent)
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
                found = self._packages.manifest(folder / "package.xml")
                if found is not None:
                    todo.append(found)
        return folders

    def dependency(self, name: str, settings: Settings) -> tuple[Manifest | None, list[Path]]:
        """A ROS package outside the workspace C++: its manifest and shipped catalogs."""
        folder = self.ros_package(name, settings)
        manifest = self._packages.manifest(folder / "package.xml") if folder else None
        if folder is None or manifest is None:
            return None, []
        return manifest, [normalize(p) for p in self._ros.catalogs(folder)]

    # -- the catalogs of a file ----------------------------------------------------------------

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
        for m in self._settings.for_path(path).models:
            p = self._settings.model_path(m)
            if p not in out:
                out.append(p)
        return out

    def ros_catalogs(self, path: Path) -> list[Path]:
        """The catalogs that the ROS package of the file at ``path`` ships and those of
        the packages its ``package.xml`` depends on (workspace or installed)."""
        out: list[Path] = []
        for folder in self.package_folders(path):
            for p in self._ros.catalogs(folder):
                p = normalize(p)
                if p not in out and p != path:
                    out.append(p)
        return out

    def unrelated_catalogs(self, path: Path) -> set[Path]:
        """The catalogs shipped by the workspace packages that the package of ``path``
        neither is nor depends on (none outside a package: a loose file sees them all)."""
        mine = self.package_folders(path)
        if not mine:
            return set()
        out: set[Path] = set()
        for folder in self.workspace_packages().values():
            if folder not in mine:
                out.update(normalize(p) for p in self._ros.catalogs(folder))
        return out

    def unrelated(self, p: Path, mine: Collection[Path]) -> bool:
        """Whether the BT file ``p`` (its ``<TreeNodesModel>``, a Groot2 palette) belongs
        to a package outside ``mine`` (a package and its dependencies): its models then
        describe another package's nodes.  A file outside any package sees every model
        (as it sees every catalog), and a file in a package also sees those of files
        outside any package (a repository's shared palette)."""
        pkg = self._packages.package_of(p.parent)
        return pkg is not None and pkg.folder not in mine
