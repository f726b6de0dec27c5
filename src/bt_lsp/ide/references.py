"""Find references and document highlights: every occurrence of a name, or of a
blackboard key (its uses in its tree and, when it is a port of the tree, that port)."""

from __future__ import annotations

from bisect import bisect_right
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from operator import attrgetter
from typing import Final, TypeVar

from bt_lsp.ide.blackboard import key_at
from bt_lsp.ide.keygraph import KeyGraph, Tree, is_tree_port, key_targets, port_targets
from bt_lsp.ide.places import Place, element_at_tag
from bt_lsp.syntax.document import Document
from bt_lsp.syntax.elements import NameRef, Role


def references(
    doc: Document,
    offset: int,
    others: Mapping[str, Document] | None = None,
    *,
    include_declaration: bool = True,
) -> list[Place]:
    """Every occurrence of the name under ``offset`` in this document and the others (end
    tags left out: they repeat their start tag).

    A blackboard key's references are its uses in its tree (port values and script
    identifiers) and, when the key is a port of its tree, that port's declarations and the
    ``<SubTree>`` attributes that remap it: the places a rename of the key changes.  A
    tree's port likewise includes its uses as a key inside the tree."""
    graph = KeyGraph(doc, others or {})
    ref = doc.model.ref_at(offset)
    if ref is None:
        key = key_at(doc, offset)
        if key is None or key.tree < 0:
            return []
        targets = key_targets(graph, Tree(None, doc, key.tree), key.key)
        return [
            Place(path, s, e)
            for path, s, e, decl in targets.places()
            if include_declaration or not decl
        ]
    if ref.symbol is None:
        return [Place(None, ref.start, ref.end)]

    def keep(r: NameRef) -> bool:
        return r.role != Role.NODE_TYPE_END and (include_declaration or not r.declaration)

    out = [Place(path, r.start, r.end) for path, _, r in graph.refs(ref.symbol) if keep(r)]
    if is_tree_port(ref.symbol):
        out.extend(Place(t.path, u.start, u.end) for t, u in port_targets(graph, ref.symbol).uses)
    return out


# Editors ask for the highlights at every move of the cursor, and show those on screen: a
# name used a million times gave a million highlights, seconds of work at each move.
MAX_HIGHLIGHTS: Final = 1_000

_T = TypeVar("_T")
_START = attrgetter("start")


def _around(items: Sequence[_T], offset: int) -> Sequence[_T]:
    """At most :data:`MAX_HIGHLIGHTS` of ``items`` (in document order): those nearest
    ``offset``, in order."""
    n = len(items)
    if n <= MAX_HIGHLIGHTS:
        return items
    i = bisect_right(items, offset, key=_START) - 1  # the last to start at or before it
    lo = max(0, min(i - MAX_HIGHLIGHTS // 2, n - MAX_HIGHLIGHTS))
    return items[lo : lo + MAX_HIGHLIGHTS]


@dataclass(frozen=True, slots=True, order=True)
class Highlight:
    """An occurrence in the document: ``write`` for a declaration, else a read (or plain
    text, ``text``, for tag names that are not names of the BT model)."""

    start: int
    end: int
    write: bool = False
    text: bool = False


# Highlight's own order (its fields in turn), read in C rather than by its __lt__.
_ORDER = attrgetter("start", "end", "write", "text")


def highlights(doc: Document, offset: int) -> list[Highlight]:
    """The occurrences, in this document, of the name under ``offset``: a tree, node type,
    port or instance name, a blackboard key (as :func:`references` finds it), or an
    element's start and end tag names; at most :data:`MAX_HIGHLIGHTS`, those nearest it."""
    model = doc.model
    graph = KeyGraph(doc, {})
    ref = model.ref_at(offset)
    if ref is not None:
        if ref.symbol is None:
            return [Highlight(ref.start, ref.end)]
        refs = _around(model.refs_to(ref.symbol), offset)
        found = {Highlight(r.start, r.end, r.declaration) for r in refs}
        if is_tree_port(ref.symbol):
            found.update(Highlight(u.start, u.end) for _, u in port_targets(graph, ref.symbol).uses)
        return list(_around(sorted(found, key=_ORDER), offset))
    key = key_at(doc, offset)
    if key is not None:
        if key.tree < 0:
            return [Highlight(key.start, key.end)]
        targets = key_targets(graph, Tree(None, doc, key.tree), key.key)
        places = {Highlight(s, e, decl) for _, s, e, decl in targets.places()}
        return list(_around(sorted(places, key=_ORDER), offset))
    hit = element_at_tag(model, offset)
    if hit is None:
        return []
    el = model.elements[hit[0]]
    out = [Highlight(el.name_start, el.name_end, text=True)]
    if el.end_name_start >= 0:
        out.append(Highlight(el.end_name_start, el.end_name_end, text=True))
    return out
