"""A document: its text, line index, tokens and model, kept current by edits.

An edit re-scans only the tokens around it (:func:`bt_lsp.syntax.scanner.rescan`) and updates the
line index in place of rebuilding it; the model is derived lazily from
the tokens when first asked for, the model from the previous one (only the sections around
the tokens replaced since are built again, see :mod:`bt_lsp.syntax.builder`).  A document
made with ``scanned=False`` makes its line index and tokens on first use, or when
:meth:`Document.prepare` is called: the server prepares a large document on a worker
thread, so that the event loop never scans megabytes.

An edit replaces the text, line index and tokens with new objects and never changes the
old ones, so :meth:`Document.snapshot` is a cheap copy that another thread can analyse
while the editor keeps editing; the model is built from one consistent state under a
short lock, and kept only if no edit came in meanwhile.
"""

from __future__ import annotations

import threading
from types import MappingProxyType
from typing import Any, Final

from bt_lsp.syntax.builder import build
from bt_lsp.syntax.kind import HEAD_CHARS, bt_evidence_end, looks_like_bt
from bt_lsp.syntax.model import Model
from bt_lsp.syntax.scanner import Rescan, Scan, rescan, scan
from bt_lsp.syntax.text import LineIndex

__all__ = ["Document", "History", "looks_like_bt"]

# The keys of what the layers above keep for a document from one version to the next
# (see History), and the slots that hold them.
_HISTORY_SLOTS: Final = MappingProxyType(
    {
        key: "_memo_" + key.replace("-", "_")
        for key in (
            "amended",
            "facts",
            "generated",
            "names",
            "own-sections",
            "section-checks",
            "tagged",
            "walks",
        )
    }
)


class History:
    """What a document and its snapshots have in common: the caches the rules keep from
    one version to the next (a snapshot analysed on a worker thread finds what the
    versions before it left, instead of starting again in proportion to the whole
    document), read and written like a dict by fixed keys (``history.memo``), and the
    lock held while one of them is analysed, so that two threads never update those
    caches at once.  A value is replaced whole, never changed in place, except by an
    analysis holding the lock."""

    __slots__ = ("__weakref__", "lock", *_HISTORY_SLOTS.values())

    def __init__(self) -> None:
        self.lock = threading.RLock()

    @property
    def memo(self) -> History:
        """The caches, by key (a history is its own memo, as a section is)."""
        return self

    def get(self, key: str, default: Any = None) -> Any:
        return getattr(self, _HISTORY_SLOTS[key], default)

    def __setitem__(self, key: str, value: Any) -> None:
        setattr(self, _HISTORY_SLOTS[key], value)


class Document:
    def __init__(self, text: str, path: str | None = None, *, scanned: bool = True) -> None:
        self.path = path
        self.text = text
        self._lines: LineIndex | None = LineIndex(text) if scanned else None
        self._scan: Scan | None = scan(text) if scanned else None
        self._model: Model | None = None
        # The document's own diagnostics, kept here by bt_lsp.rules.diagnostics.own_diagnostics
        # (this layer knows no rules); an edit clears them.
        self.own_diagnostics: list[Any] | None = None
        # The last model built and the tokens replaced since, for the next model.
        self._base: Model | None = None
        self._change: Rescan | None = None
        self._is_bt: bool | None = None
        self._bt_end = -1  # where the first BT marker ends (with _is_bt True)
        self._utf8_size: int | None = None
        # Guards the state read to build a model against an edit on another thread (held
        # only to read or write attributes, never while building).
        self._lock = threading.Lock()
        self._edits = 0  # bumped by every edit: a model built before it is not kept
        self.history = History()  # shared with the snapshots (see snapshot)

    @property
    def lines(self) -> LineIndex:
        lines = self._lines
        if lines is None:
            text = self.text
            lines = LineIndex(text)
            if self.text is text:
                self._lines = lines
        return lines

    @property
    def scan(self) -> Scan:
        """The tokens of the text (scanned on first use when made with ``scanned=False``)."""
        tokens = self._scan
        if tokens is None:
            text = self.text
            tokens = scan(text)
            if self.text is text:
                self._scan = tokens
        return tokens

    @property
    def scanned(self) -> bool:
        """Whether the tokens are made (see ``scanned=False``)."""
        return self._scan is not None

    def prepare(self, model: bool = True) -> None:
        """Make the line index and tokens now, and the model with ``model`` (a worker
        thread does it for a large document, before the event loop uses it)."""
        _ = self.lines, (self.model if model else None)

    def snapshot(self) -> Document:
        """A copy that later edits of this document leave alone, for analysing it on
        another thread (the text, line index, tokens and model are shared, not copied)."""
        snap = Document.__new__(Document)
        with self._lock:
            snap.__dict__.update(self.__dict__)
        snap._lock = threading.Lock()
        return snap

    def adopt(self, snap: Document) -> None:
        """Keep what the analysis of ``snap`` (a :meth:`snapshot` of this document) built,
        the model and own diagnostics, if this document was not edited since."""
        with self._lock:
            if snap.scan is not self.scan or snap.text is not self.text:
                return
            if self._model is None and snap._model is not None:
                self._model = snap._model
                self._base = self._change = None
            if self.own_diagnostics is None:
                self.own_diagnostics = snap.own_diagnostics

    def edit(self, start: int, end: int, new_text: str) -> None:
        """Replace ``text[start:end]`` (code-point offsets, clamped) with ``new_text``."""
        with self._lock:
            self._edit(start, end, new_text)

    def _edit(self, start: int, end: int, new_text: str) -> None:
        self._edits += 1
        n = len(self.text)
        start = min(max(start, 0), n)
        end = min(max(end, start), n)
        new_full = self.text[:start] + new_text + self.text[end:]
        self._lines = self.lines.edited(start, end, new_text, new_full)
        if self._scan is None:  # never scanned (a text that is not BT): scanned when used
            self.text = new_full
            self._model = self._base = self._change = self.own_diagnostics = None
            self._utf8_size = None
            self._kind_after(start, len(new_text))
            return
        self._scan, change = rescan(self._scan, new_full, start, end, len(new_text))
        self.text = new_full
        if self._model is not None:
            self._base, self._change = self._model, change
        elif self._change is not None:
            self._change = self._change.then(change)
        self._model = None
        self.own_diagnostics = None
        self._kind_after(start, len(new_text))
        self._utf8_size = None

    def _kind_after(self, start: int, inserted: int) -> None:
        """:attr:`is_bt` after an edit at ``start`` that wrote ``inserted`` characters,
        without looking at the text again when it cannot have changed: the decision reads
        the head of the text only (an edit past it changes nothing), and evidence that
        ends before the edit stays."""
        if start >= HEAD_CHARS or (self._is_bt and self._bt_end <= start):
            return
        self._is_bt = None

    def replace_all(self, text: str, *, scanned: bool = True) -> None:
        fresh = Document(text, self.path, scanned=scanned)
        with self._lock:
            edits = self._edits + 1
            lock, history = self._lock, self.history
            self.__dict__.update(fresh.__dict__)
            # The same document: its caches continue (a client that sends the whole
            # text at every change still gets edits that cost what they changed).
            self._lock, self._edits, self.history = lock, edits, history

    @property
    def model(self) -> Model:
        model = self._model
        if model is not None:
            return model
        tokens = self.scan  # made outside the lock, on first use
        with self._lock:
            if self._model is not None:
                return self._model
            if self._scan is not tokens:
                tokens = self.scan
            state = tokens, self.text, self._base, self._change
            edits = self._edits
        model = build(*state)
        with self._lock:
            if self._edits == edits and self._model is None:
                self._model = model
                self._base = self._change = None
        return model

    @property
    def is_bt(self) -> bool:
        """Whether the text :func:`~bt_lsp.syntax.kind.looks_like_bt` (remembered until
        an edit that may change it)."""
        if self._is_bt is None:
            end = bt_evidence_end(self.text)
            self._is_bt, self._bt_end = end >= 0, end
        return self._is_bt

    @property
    def utf8_size(self) -> int:
        """The size of the text in UTF-8 bytes (remembered until the next edit)."""
        if self._utf8_size is None:
            text = self.text
            self._utf8_size = (
                len(text) if text.isascii() else len(text.encode("utf-8", "surrogatepass"))
            )
        return self._utf8_size
