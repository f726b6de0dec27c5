"""A tree file's lines and the running tree's nodes: which uids a breakpoint line stands for.

:func:`match_elements` decides which element of the text each running node came from,
with the live view's mapping (:mod:`bt_lsp.live.mapping`): each ``<BehaviorTree ID=X>``
of the file is matched with every instance of X in the running tree (the main tree, and
each SubTree node calling X), children aligned in order.  Where an element's type or
instance name differs from its running node's, it stands for no node: a breakpoint there
is reported unverified, never put on another node.

Pure: text in, offsets and lines out (lines 0-based, columns in UTF-16 code units, as the
Debug Adapter Protocol counts them).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Final

from bt_lsp.live.mapping import map_each_tree
from bt_lsp.live.tree import LiveTree
from bt_lsp.syntax.document import Document
from bt_lsp.syntax.elements import Zone
from bt_lsp.syntax.model import Model

MAX_LABEL: Final = 80


@dataclass(frozen=True, slots=True)
class NodeAt:
    """The element a line stands for: its index, where its start tag is, what it is."""

    element: int
    line: int
    column: int
    label: str


def match_elements(tree: LiveTree, model: Model) -> dict[int, list[int]]:
    """The running nodes each element of the text stands for: element index -> uids.

    An element of a tree called from several places stands for several nodes.  The text
    is aligned with the running tree as the live view does (:func:`map_each_tree`), so an
    element inserted or removed elsewhere leaves the others matched; an element whose
    type or instance name differs from its running node's stands for none."""
    tm = map_each_tree(tree, model)
    unsure = {m.uid for m in tm.mismatches if m.kind in ("renamed", "changed")}
    index = {el.name_start: i for i, el in enumerate(model.elements) if el.zone == Zone.NODE}
    out: dict[int, list[int]] = {}
    for uid, place in tm.places.items():
        i = index.get(place.start)
        if i is not None and uid not in unsure:
            out.setdefault(i, []).append(uid)
    return out


class SourceMap:
    """One file's text, and (once a running tree is known) its elements' uids."""

    def __init__(self, text: str) -> None:
        doc = Document(text)
        self._lines = doc.lines
        self._model = doc.model
        self._elements = doc.model.elements
        self._by_line: dict[int, list[int]] = {}
        self._spans: list[tuple[int, int, int]] = []  # (first line, last line, element)
        self.tree_ids: tuple[str, ...] = ()
        ids = []
        for i, el in enumerate(self._elements):
            if el.zone == Zone.TREE and el.name == "BehaviorTree":
                ids.append(el.value("ID") or "")
            elif el.zone != Zone.NODE:
                continue
            first = self._lines.line_of(el.token_start)
            last = self._lines.line_of(el.token_start + max(el.length - 1, 0))
            self._by_line.setdefault(first, []).append(i)
            if last > first:
                self._spans.append((first, last, i))
        self.tree_ids = tuple(ids)
        self._uids: dict[int, list[int]] = {}
        self._places: dict[int, int] = {}  # uid -> element

    def match(self, tree: LiveTree | None) -> None:
        """Match the elements with a running tree (None: forget the last one)."""
        self._uids = match_elements(tree, self._model) if tree is not None else {}
        self._places = {uid: i for i, uids in self._uids.items() for uid in uids}

    def node_at(self, line: int, column: int | None = None) -> NodeAt | None:
        """The node whose start tag is on ``line``: the one at ``column`` (UTF-16) when
        several start there, the first otherwise; a ``<BehaviorTree>`` line stands for
        its root node.  A line inside a start tag written over several lines counts."""
        found = self._by_line.get(line)
        if not found:
            found = [i for first, last, i in self._spans if first < line <= last]
        if not found:
            return None
        index = found[0]
        if column is not None and len(found) > 1:
            for i in found:
                if self._position(i)[1] <= column:
                    index = i
        el = self._elements[index]
        if el.zone == Zone.TREE:
            roots = [c for c in el.children if self._elements[c].zone == Zone.NODE]
            if not roots:
                return None
            index = roots[0]
        line, column = self._position(index)
        return NodeAt(index, line, column, self._label(index))

    def _position(self, index: int) -> tuple[int, int]:
        return self._lines.position(self._elements[index].token_start, "utf-16")

    def _label(self, index: int) -> str:
        el = self._elements[index]
        name = el.value("name")
        text = f"<{el.name}>" if name is None else f'<{el.name} name="{name}">'
        return text if len(text) <= MAX_LABEL else text[: MAX_LABEL - 4] + "...>"

    def uids(self, element: int) -> tuple[int, ...]:
        """The running nodes an element stands for (none when it did not match)."""
        return tuple(sorted(self._uids.get(element, ())))

    def place(self, uid: int) -> tuple[int, int] | None:
        """Where the element of a running node starts (line, UTF-16 column), if known."""
        index = self._places.get(uid)
        return None if index is None else self._position(index)

    def tree_of(self, element: int) -> str | None:
        """The ID of the ``<BehaviorTree>`` an element is in."""
        el = self._elements[element]
        while el.parent >= 0:
            parent = self._elements[el.parent]
            if parent.zone == Zone.TREE:
                return parent.value("ID")
            el = parent
        return None
