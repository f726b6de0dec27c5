"""The files a check covers: the ``*.xml`` files under the folders it is given, each once,
in a stable order, and the folders that could not be searched."""

from __future__ import annotations

import os
from collections.abc import Callable, Iterable
from typing import Final

from bt_lsp.project.fileio import FileError

SKIP_DIRS: Final = frozenset({"node_modules"})


def _part_key(path: str, root: str) -> list[str]:
    return os.path.relpath(path, root).split(os.sep)


# Whether a walk leaves out a path (the path, whether it is a folder).
Skip = Callable[[str, bool], bool]


def _search(root: str, errors: list[FileError], skip: Skip | None = None) -> list[str]:
    """Every ``*.xml`` file under ``root`` (hidden files and folders and ``node_modules``
    skipped, and the regular files ``skip`` leaves out), sorted by path components.  A
    FIFO, socket or device named ``*.xml`` is kept, never opened: reading it reports it."""

    def onerror(e: OSError) -> None:
        where = e.filename if isinstance(e.filename, str) else root
        errors.append(FileError(where, f"cannot read {where}: {e.strerror or e}"))

    found: list[str] = []
    for dirpath, dirnames, filenames in os.walk(root, onerror=onerror):
        dirnames[:] = sorted(
            d
            for d in dirnames
            if not d.startswith(".")
            and d not in SKIP_DIRS
            and (skip is None or not skip(os.path.join(dirpath, d), True))
        )
        for name in filenames:
            if name.startswith(".") or not name.endswith(".xml"):
                continue
            path = os.path.join(dirpath, name)
            if root == os.curdir:
                path = os.path.relpath(path)
            # ``skip`` may sniff the file's first bytes: it never opens anything but a
            # regular file (a FIFO would block the walk).  A FIFO, a socket, a device or a
            # broken link is kept: reading it reports it.
            if skip is not None and skip(path, False):
                continue
            found.append(path)
    found.sort(key=lambda p: _part_key(p, root))
    return found


def collect_files(
    paths: Iterable[str], skip: Skip | None = None
) -> tuple[list[str], list[FileError]]:
    """The files to check, in order, each once: a directory gives its ``*.xml`` files
    (recursively, but what ``skip`` leaves out), anything else is taken as a file (a
    missing one is reported when read). Also returns the folders that could not be
    searched."""
    files: list[str] = []
    errors: list[FileError] = []
    seen: set[str] = set()
    for given in paths:
        if os.path.isdir(given):
            root = given.rstrip("/" + os.sep) or given
            candidates = _search(root, errors, skip)
        else:
            candidates = [given]
        for path in candidates:
            key = os.path.normcase(os.path.realpath(path))
            if key not in seen:
                seen.add(key)
                files.append(path)
    return files, errors
