"""ROS workspaces: where each package is, and the node catalogs packages ship.

A package is found, in this order, in the ``ros-packages`` / ``rosPackages`` setting (name
-> folder), among the packages of the workspace folders (each ``package.xml``, as in a
colcon workspace's ``src/``), and among the installed ones: ``share/<name>/package.xml``
under each prefix of ``AMENT_PREFIX_PATH``.  That is where ``<include ros_pkg="name">``
leads (ROS resolves it to the package's share folder, which installs what the source
folder holds).

A package's catalogs are the XML files of its folder (up to three folders down) whose
``<root>`` holds a ``<TreeNodesModel>`` and no ``<BehaviorTree>``: what
BehaviorTree.CPP's ``writeTreeNodesModelXML`` writes, e.g. Nav2's
``share/nav2_behavior_tree/nav2_tree_nodes.xml``.  A document's catalogs in scope are its
own package's and those of the packages its ``package.xml`` depends on.
"""

from __future__ import annotations

import os
import re
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Final

from bt_lsp.project.packages import Packages, is_file
from bt_lsp.project.sniff import head_of, top_element

__all__ = ["RosIndex", "is_catalog"]

MAX_CATALOG_FILES: Final = 64  # per package
CATALOG_DEPTH: Final = 3  # folders below a package's folder searched for catalogs
MAX_EXAMINED: Final = 2000  # XML files looked at per package
# Folders of a source package that hold no catalog it ships.
_NOT_SHIPPED: Final = frozenset({"build", "install", "log", "node_modules", "__pycache__"})
MAX_INSTALLED: Final = 10_000
# Enough of a file to see whether it declares trees.
CATALOG_SNIFF_BYTES: Final = 256 * 1024


def is_catalog(path: Path) -> bool:
    """Whether ``path`` is a node catalog: a ``<root>`` with a ``<TreeNodesModel>`` and no
    ``<BehaviorTree>`` (read from its first bytes, never parsed as a whole)."""
    head = head_of(path, CATALOG_SNIFF_BYTES)
    if head is None or top_element(head) != "root":
        return False
    return "<TreeNodesModel" in head and re.search(r"<BehaviorTree[\s/>]", head) is None


class RosIndex:
    """Package name -> folder, and each folder's catalogs, cached until a manifest
    changes.  ``prefixes`` default to ``AMENT_PREFIX_PATH``."""

    def __init__(self, packages: Packages, prefixes: Iterable[str] | None = None) -> None:
        self.packages = packages
        if prefixes is None:
            prefixes = [p for p in os.environ.get("AMENT_PREFIX_PATH", "").split(os.pathsep)]
        self.prefixes = [Path(p) for p in prefixes if p]
        self._installed: dict[str, Path] | None = None
        self._catalogs: dict[Path, tuple[Path, ...]] = {}

    def installed(self) -> Mapping[str, Path]:
        """The installed packages: ``share/<name>/package.xml`` of each prefix, the first
        prefix first (as ament's index finds them)."""
        if self._installed is None:
            found: dict[str, Path] = {}
            for prefix in self.prefixes:
                share = prefix / "share"
                try:
                    names = sorted(os.listdir(share))
                except (OSError, ValueError):
                    continue
                for name in names[:MAX_INSTALLED]:
                    if name not in found and is_file(share / name / "package.xml"):
                        found[name] = share / name
            self._installed = found
        return self._installed

    def folder(
        self, name: str, configured: Mapping[str, str], workspace: Mapping[str, Path]
    ) -> Path | None:
        """Where package ``name`` is: configured, in the workspace, or installed."""
        if name in configured:
            return Path(configured[name])
        if name in workspace:
            return workspace[name]
        return self.installed().get(name)

    def catalogs(self, folder: Path) -> tuple[Path, ...]:
        """The catalog files a package folder ships (up to three folders down)."""
        hit = self._catalogs.get(folder)
        if hit is not None:
            return hit
        found: list[Path] = []
        for candidate in _xml_near(folder):
            if len(found) >= MAX_CATALOG_FILES:
                break
            if candidate.name != "package.xml" and is_catalog(candidate):
                found.append(candidate)
        result = tuple(found)
        self._catalogs[folder] = result
        return result

    def file_changed(self, path: Path) -> None:
        """An XML file changed: forget the catalogs of the package folders it may be in
        (up to three folders above it)."""
        folder = path.parent
        for _ in range(CATALOG_DEPTH + 1):
            self._catalogs.pop(folder, None)
            folder = folder.parent

    def changed(self) -> None:
        self._installed = None
        self._catalogs.clear()


def _xml_near(folder: Path) -> list[Path]:
    """The ``*.xml`` files under ``folder``, at most :data:`CATALOG_DEPTH` folders down
    (hidden and build folders skipped, at most :data:`MAX_EXAMINED` files), sorted by
    depth, then by path."""
    out: list[Path] = []
    level = [folder]
    for _ in range(CATALOG_DEPTH + 1):
        below: list[Path] = []
        for here in level:
            try:
                entries = sorted(os.scandir(here), key=lambda e: e.name)
            except (OSError, ValueError):
                continue
            for e in entries:
                if e.name.startswith("."):
                    continue
                try:
                    if e.is_file() and e.name.endswith(".xml"):
                        out.append(Path(e.path))
                        if len(out) >= MAX_EXAMINED:
                            return out
                    elif e.is_dir() and e.name not in _NOT_SHIPPED:
                        below.append(Path(e.path))
                except OSError:
                    continue
        level = below
    return out
