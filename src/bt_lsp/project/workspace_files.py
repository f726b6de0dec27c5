"""The workspace's BT files: the XML and ``.btproj`` files under its folders (but build
and VCS folders and what the configuration's ``exclude`` leaves out) and the model files
of the settings.  Every document's check sees them (their trees and models count), so
the walk is made once and again only when one of the folders walked changes."""

from __future__ import annotations

import os
from collections.abc import Callable, Iterable, Iterator, Sequence
from pathlib import Path

from bt_lsp.project.config import excluded
from bt_lsp.project.documents import Documents
from bt_lsp.project.paths import normalize
from bt_lsp.project.settings_index import SettingsIndex
from bt_lsp.syntax.document import Document

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


class WorkspaceFiles:
    """The BT files of ``roots``: every one when ``all_files`` (the command line reads
    every file it checks anyway, and a tree in a file left out is unknown), else the
    first MAX_WORKSPACE_FILES."""

    def __init__(
        self,
        roots: Sequence[Path],
        settings: SettingsIndex,
        documents: Documents,
        *,
        all_files: bool = False,
    ) -> None:
        self.roots = roots
        self.all_files = all_files
        self._settings = settings
        self._documents = documents
        self._files: list[Path] | None = None
        # The folders walked for _files, with their modification times: a file created,
        # deleted or renamed in one changes its folder's (see revalidate).
        self._folders: dict[str, int] = {}
        self._paths: tuple[tuple[int, tuple[Path, ...]], list[Path]] | None = None

    def paths(self) -> list[Path]:
        """Every BT XML file under the workspace folders and the model files from the
        settings (sorted; skipping build and VCS folders; at most MAX_WORKSPACE_FILES
        unless ``all_files``).  The same list object until :meth:`forget`."""
        if self._files is None:
            found: set[Path] = set()
            self._folders = {}
            for root in self.roots:
                for p in _walk_xml(root, self.is_excluded, self._folders):
                    found.add(p)
                    if len(found) >= MAX_WORKSPACE_FILES and not self.all_files:
                        break
            found.update(self._settings.model_files())
            self._files = sorted(found)
        return self._files

    def is_excluded(self, path: Path, is_dir: bool = False) -> bool:
        """Whether the configuration's ``exclude`` globs leave ``path`` out of the
        workspace (a folder's globs are those of a file inside it)."""
        return excluded(path, self._settings.for_path(path / "-" if is_dir else path).exclude)

    def bt_documents(self) -> Iterator[tuple[Path, Document]]:
        """The BT documents of the workspace and the open ones (as edited), by path."""
        docs = self._documents
        key = (docs.generation, docs.open_paths())
        if self._paths is None or self._paths[0] != key:
            # An open excluded file is diagnosed (it was opened) but is no more part of
            # the workspace for the other files than when it is closed.
            shown = {p for p in key[1] if not self.is_excluded(p)}
            self._paths = (key, sorted(set(self.paths()) | shown))
        for p in self._paths[1]:
            doc = docs.document(p)
            if doc is not None and (doc.is_bt or p.suffix == ".btproj"):
                yield p, doc

    def forget(self) -> None:
        """Walk the folders again when the files are next asked for."""
        self._files = None

    def revalidate(self, changed: Callable[[Path], None]) -> bool:
        """Walk again if a file was created or deleted in a folder walked (for clients
        that do not report file changes), telling ``changed`` of each file that came or
        went; ``True`` if one did."""
        if self._files is None or all(_folder_stamp(d) == t for d, t in self._folders.items()):
            return False
        before = self._files
        self._files = None
        now = self.paths()
        if now == before:
            return False
        for p in set(before).symmetric_difference(now):
            changed(p)  # a catalog, a package.xml: forgotten
        self._files = now
        return True


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
