"""The project's documents: those open in an editor, as edited, over the files on disk.

A file is read once and kept until it is said to have changed (a watched-file
notification, :meth:`Documents.stale` for clients that report none): every other file's
check looks at it again.  ``generation`` counts what may have changed on disk, and the
other objects of the project index key their caches by it.
"""

from __future__ import annotations

import os
from pathlib import Path

from bt_lsp.project.fileio import FileError, read_text
from bt_lsp.project.paths import normalize
from bt_lsp.syntax.document import Document
from bt_lsp.syntax.model import Model

# What a file read records: its (mtime_ns, size), the document, why it cannot be read.
_Read = tuple[tuple[int, int], Document | None, str | None]


class Documents:
    """Open documents and the files read from disk, at most ``max_bytes`` each (the
    editor's ``max_document_bytes``)."""

    def __init__(self, max_bytes: int) -> None:
        self.max_bytes = max_bytes
        # Bumps whenever a file other than an edited open one changes.
        self.generation = 0
        self._open: dict[Path, Document] = {}
        self._disk: dict[Path, _Read] = {}

    def open(self, path: str | os.PathLike[str], doc: Document) -> None:
        self._open[normalize(path)] = doc

    def close(self, path: str | os.PathLike[str]) -> None:
        p = normalize(path)
        self._open.pop(p, None)
        self._disk.pop(p, None)  # read again: the file may have been saved while open
        self.generation += 1

    def is_open(self, path: Path) -> bool:
        return path in self._open

    def open_paths(self) -> tuple[Path, ...]:
        """The open documents' paths, in the order they were opened."""
        return tuple(self._open)

    def state(
        self, own: Path | None = None, doc: Document | None = None
    ) -> tuple[int, tuple[Path, ...], tuple[Model | None, ...]]:
        """What the documents are now: the generation, the open paths and the models of
        the open documents (new objects after an edit).  The slot of the open document
        at ``own`` holds ``doc``'s model instead (``None`` without ``doc``): its text
        being analysed, whose open document's model is not made here (see
        ``FileContexts._check_stamp``)."""
        models = tuple(
            (None if doc is None else doc.model) if p == own else d.model
            for p, d in self._open.items()
        )
        return (self.generation, tuple(self._open), models)

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
        """Read a file once; it is read again only after :meth:`forget` (the server hears
        of changes through watched-file notifications) or :meth:`forget_all`."""
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
            decoded = read_text(str(path), max_bytes=self.max_bytes)
            doc: Document | None = Document(decoded.text, str(path))
            err = None
        except FileError as e:
            doc, err = None, e.message
        self._disk[path] = (stamp, doc, err)
        return doc, err

    def forget(self, path: Path) -> None:
        """Read the file at ``path`` again when it is next asked for."""
        self._disk.pop(path, None)

    def forget_all(self) -> None:
        self._disk.clear()

    def stale(self) -> list[Path]:
        """The files read whose modification time or size changed since."""
        return [p for p, (stamp, _, _) in self._disk.items() if _stamp(p) != stamp]


def _stamp(path: Path) -> tuple[int, int]:
    """What :meth:`Documents._read` records of a file: (mtime_ns, size), (0, 0) if none."""
    try:
        st = path.stat()
    except (OSError, ValueError):
        return (0, 0)
    return (st.st_mtime_ns, st.st_size)
