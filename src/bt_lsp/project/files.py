"""The files a check covers: the ``*.xml`` files under the folders it is given, each once,
in a stable order, and the folders that could not be searched."""

from __future__ import annotations

import os
import stat
from collections.abc import Iterable
from typing import Final

from bt_lsp.project.fileio import FileError

SKIP_DIRS: Final = frozenset({"node_modules"})


def _part_key(path: str, root: str) -> list[str]:
    return os.path.relpath(path, root).split(os.sep)


def _search(root: str, errors: list[FileError]) -> list[str]:
    """Every ``*.xml`` file under ``root`` (regular files or links to them; hidden
    files and folders and ``node_modules`` skipped), sorted by path components."""

    def onerror(e: OSError) -> None:
        where = e.filename if isinstance(e.filename, str) else root
        errors.append(FileError(where, f"cannot read {where}: {e.strerror or e}"))

    found: list[str] = []
    for dirpath, dirnames, filenames in os.walk(root, onerror=onerror):
        dirnames[:] = sorted(d for d in dirnames if not d.startswith(".") and d not in SKIP_DIRS)
        for name in filenames:
            if name.startswith(".") or not name.endswith(".xml"):
                continue
            path = os.path.join(dirpath, name)
            if root == os.curdir:
                path = os.path.relpath(path)
            try:
                st = os.stat(path)
            except OSError:
                found.append(path)  # a broken link: reported when it is read
                continue
            if stat.S_ISREG(st.st_mode):
                found.append(path)
    found.sort(key=lambda p: _part_key(p, root))
    return found


def collect_files(paths: Iterable[str]) -> tuple[list[str], list[FileError]]:
    """The files to check, in order, each once: a directory gives its ``*.xml`` files
    (recursively), anything else is taken as a file (a missing one is reported when read).
    Also returns the folders that could not be searched."""
    files: list[str] = []
    errors: list[FileError] = []
    seen: set[str] = set()
    for given in paths:
        if os.path.isdir(given):
            root = given.rstrip("/" + os.sep) or given
            candidates = _search(root, errors)
        else:
            candidates = [given]
        for path in candidates:
            key = os.path.normcase(os.path.realpath(path))
            if key not in seen:
                seen.add(key)
                files.append(path)
    return files, errors
