"""``bt-lsp monitor --map PATH``: where each running node comes from, as ``file:line``.

PATH is the tree file the executor loaded (its folder is the workspace, as for ``bt-lsp
render``: includes resolve, SubTree calls reach the other files), or a folder, where the
file that declares the running main tree is found.  The files are read again when they
change on disk (checked at most once a second), so what the text changed since the
executor started is reported as the user edits.
"""

from __future__ import annotations

import os
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Final

from bt_lsp.ide.places import Place
from bt_lsp.live.mapping import TreeMap, map_tree
from bt_lsp.live.tree import LiveTree
from bt_lsp.project.fileio import DEFAULT_MAX_BYTES
from bt_lsp.project.index import ProjectIndex, normalize
from bt_lsp.project.pictures import tree_resolver
from bt_lsp.project.settings import Settings
from bt_lsp.render import find_tree
from bt_lsp.syntax.document import Document

NOT_IN_TEXT: Final = "(not in the text)"
RECHECK_SECONDS: Final = 1.0


@dataclass(frozen=True, slots=True)
class Located:
    """A map with its places written ``file:line``: by uid, and for each difference."""

    tree_map: TreeMap | None
    where: dict[int, str]
    differences: list[str]
    note: str | None = None  # why nothing was mapped


def shown(path: Path) -> str:
    """``path`` relative to the working directory when it is below it."""
    try:
        rel = os.path.relpath(path)
    except ValueError:  # another drive
        return str(path)
    return str(path) if rel.startswith("..") else rel


class SourceMap:
    """The files a running tree is mapped onto (``--map``), read through a project index
    so that includes, other files and changes on disk are handled as ``check`` does."""

    def __init__(self, target: str, max_bytes: int = DEFAULT_MAX_BYTES) -> None:
        self.target = target
        self.is_dir = os.path.isdir(target)
        root = target if self.is_dir else os.path.dirname(os.path.abspath(target))
        self.workspace = ProjectIndex([root], Settings(max_document_bytes=max_bytes))
        self.file = None if self.is_dir else normalize(target)
        self._checked = time.monotonic()
        self._last: tuple[LiveTree, Located] | None = None

    def _document(self, tree_id: str) -> tuple[Path, Document] | str:
        """The document to map onto, or why there is none."""
        if self.file is not None:
            doc = self.workspace.document(self.file)
            if doc is None:
                error = self.workspace.documents.read_error(self.file) or "cannot be read"
                return f"{self.target}: {error}"
            return self.file, doc
        found = [(p, d) for p, d in self.workspace.bt_documents() if find_tree(d.model, tree_id)]
        for p, d in found:  # the file that runs it as its main tree, if one does
            root = d.model.root
            if root is not None and root.value("main_tree_to_execute") == tree_id:
                return p, d
        if found:
            return found[0]
        return f"no file in {self.target} declares tree {tree_id!r}"

    def locate(self, tree: LiveTree) -> Located:
        """The map of ``tree``, made again when the tree or a file read for it changed."""
        now = time.monotonic()
        if now - self._checked >= RECHECK_SECONDS:
            self._checked = now
            if self.workspace.revalidate():
                self._last = None
        if self._last is not None and self._last[0] is tree:
            return self._last[1]
        located = self._locate(tree)
        self._last = (tree, located)
        return located

    def _locate(self, tree: LiveTree) -> Located:
        found = self._document(tree.tree_id)
        if isinstance(found, str):
            return Located(None, {}, [], found)
        path, doc = found
        tm = map_tree(tree, doc.model, tree_resolver(self.workspace, path, doc))

        def at(place: Place) -> str:
            file = path if place.path is None else Path(place.path)
            d = doc if place.path is None else self.workspace.document(file)
            line = d.lines.line_of(min(place.start, len(d.text))) + 1 if d is not None else 0
            return f"{shown(file)}:{line}"

        where = {uid: at(p) for uid, p in tm.places.items()}
        where.update({uid: NOT_IN_TEXT for uid in tm.missing})
        differences = [
            f"{at(m.place)}: {m.message}" if m.place is not None else m.message
            for m in tm.mismatches
        ]
        return Located(tm, where, differences)

    def lines(self, located: Located) -> list[str]:
        """What the snapshot says under the tree: the differences, or why none is known."""
        if located.note is not None:
            return [f"not mapped: {located.note}"]
        if not located.differences:
            return []
        head = f"the text differs from the running tree ({len(located.differences)}):"
        return [head, *(f"  {d}" for d in located.differences)]
