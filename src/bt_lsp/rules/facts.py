"""What one document declares (trees with their calls, node models), read from its model.

Extracted once per model and cached on the document; for a model made of sections, once
per section (kept on the section), so that an edit costs what its own sections declare.
"""

from __future__ import annotations

from array import array
from collections.abc import Callable, Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from functools import partial
from itertools import chain, compress, count, repeat
from operator import is_not, itemgetter, ne, or_
from types import MappingProxyType
from typing import TYPE_CHECKING, Any, Final, NamedTuple, TypeVar, cast

from bt_lsp.rules.builtins import Category, Direction, PortModel
from bt_lsp.rules.decls import DocumentFacts, FactsLayout, ModelDecl, TreeDecl
from bt_lsp.syntax.elements import Element, Zone
from bt_lsp.syntax.model import Model
from bt_lsp.syntax.sections import Section
from bt_lsp.syntax.table import ElementTable

if TYPE_CHECKING:
    from bt_lsp.syntax.document import Document

_ENTRY_CATEGORIES: Final[frozenset[str]] = frozenset(
    {"Action", "Condition", "Control", "Decorator", "SubTree"}
)
_DIRECTIONS: Final[Mapping[str, Direction]] = MappingProxyType(
    {"input_port": "input", "output_port": "output", "inout_port": "inout"}
)
# Attributes of a model entry that are not ports in the pre-3.x attribute form
# (``<Action ID="Say" message=""/>``).
# Groot2 writes `editable` on the entries whose ports its editor may change: not a port.
_ENTRY_NON_PORT_ATTRS: Final[frozenset[str]] = frozenset({"ID", "name", "description", "editable"})


def facts_of(doc: Document, path: str | None = None) -> DocumentFacts:
    """What ``doc`` declares (cached per model and path)."""
    model = doc.model
    if path is None:
        path = doc.path
    # Kept for the document (its history); valid while its model is the same object (a
    # document builds a new model after every edit).
    hit: tuple[Model, str | None, DocumentFacts] | None = doc.history.memo.get("facts")
    if hit is not None and hit[0] is model and hit[1] == path:
        return hit[2]
    if model.head is None:
        facts = extract_facts(model, path)
    else:
        facts = extract_sections(model, path, hit[2] if hit is not None else None)
    doc.history.memo["facts"] = (model, path, facts)
    return facts


def extract_sections(
    model: Model, path: str | None, before: DocumentFacts | None = None
) -> DocumentFacts:
    """:func:`extract_facts` for a model made of sections: each section's declarations are
    extracted once (they are kept on the section, in its coordinates) and placed here.

    With the facts ``before`` of an earlier version of the document, the sections both
    versions begin and end with keep their declarations: those before the edit as they
    are, those after it moved by the edit's length (in C: no Python code runs per tree),
    so that an edit costs what its own sections declare.
    """
    sections, origins = model.sections, model.origins
    if before is None or before.layout is None or before.path != path:
        return _extract_all(sections, origins, path)
    layout = before.layout
    old_sections, old_origins = layout.sections, layout.origins
    n_old, n_new = len(old_sections), len(sections)
    most = min(n_old, n_new)
    # The sections both begin with, where they were; then those both end with (moved).
    moved = map(or_, map(is_not, old_sections, sections), map(ne, old_origins, origins))
    p = next(compress(count(), moved), most)
    q = next(compress(count(), map(is_not, reversed(old_sections), reversed(sections))), most)
    q = min(q, most - p)
    if p == n_old == n_new:
        return before
    delta = origins[n_new - q] - old_origins[n_old - q] if q else 0
    mid = _extract_all(sections[p : n_new - q], origins[p : n_new - q], path)
    assert mid.layout is not None
    cut = _Cut(p, n_old - q, delta, path)
    trees, trees_at = cut.splice(
        before.trees, layout.trees_at, mid.trees, mid.layout.trees_at, _moved_trees
    )
    models, models_at = cut.splice(
        before.models, layout.models_at, mid.models, mid.layout.models_at, _moved_models
    )
    subs, subs_at = cut.splice(
        before.subtree_models,
        layout.subtree_models_at,
        mid.subtree_models,
        mid.layout.subtree_models_at,
        _moved_models,
    )
    return DocumentFacts(
        path, trees, models, subs, FactsLayout(sections, origins, trees_at, models_at, subs_at)
    )


D = TypeVar("D", bound="tuple[object, ...]")  # a TreeDecl or a ModelDecl


@dataclass(frozen=True, slots=True)
class _Cut:
    """An edit as the facts see it: old sections ``[first, stop)`` were replaced; those
    from ``stop`` on moved by ``delta`` characters."""

    first: int
    stop: int
    delta: int
    path: str | None

    def splice(
        self,
        old: tuple[D, ...],
        old_at: array[int],
        new: tuple[D, ...],
        new_at: array[int],
        move: _Mover,
    ) -> tuple[tuple[D, ...], array[int]]:
        """One kind of declaration: the old ones of the sections kept, the new ones of the
        sections in between, and where each section's begin."""
        first, stop = self.first, self.stop
        head_end: int = old_at[first]
        tail_start: int = old_at[stop]
        kept = old[tail_start:]
        tail: Iterable[D] = move(kept, self.delta, self.path) if self.delta else kept
        decls: tuple[D, ...] = tuple(chain(old[:head_end], new, tail))
        shift = head_end + len(new) - tail_start
        at = old_at[:first]
        at.extend(map(head_end.__add__, new_at))
        at.pop()  # the count of the new ones is where the tail begins
        at.extend(map(shift.__add__, old_at[stop:]) if shift else old_at[stop:])
        return decls, at


def local_facts(section: Section) -> DocumentFacts:
    """What ``section`` declares, in its coordinates (made again when asked: keeping it on
    each section would cost a declaration per tree twice)."""
    return _extract(section.elements, None)  # its root declares nothing


def _extract_all(
    sections: Sequence[Section], origins: Sequence[int], path: str | None
) -> DocumentFacts:
    """The declarations of ``sections`` (at ``origins``), with their layout."""
    trees: list[TreeDecl] = []
    models: list[ModelDecl] = []
    subtree_models: list[ModelDecl] = []
    trees_at, models_at, subs_at = array("q"), array("q"), array("q")
    spans: _Spans = {}  # for this pass (see _OpenTree.close)
    for section, o in zip(sections, origins, strict=True):
        trees_at.append(len(trees))
        models_at.append(len(models))
        subs_at.append(len(subtree_models))
        _extract_into(section.elements, path, o, trees, models, subtree_models, spans)
    trees_at.append(len(trees))
    models_at.append(len(models))
    subs_at.append(len(subtree_models))
    return DocumentFacts(
        path,
        tuple(trees),
        tuple(models),
        tuple(subtree_models),
        FactsLayout(sections, origins, trees_at, models_at, subs_at),
    )


_new = tuple.__new__
_FIELDS = tuple(itemgetter(i) for i in range(8))


class _Mover(NamedTuple):
    """Moves declarations of one kind: where their path and start are among their
    ``width`` fields (the end follows the start)."""

    make: Callable[[Iterable[object]], Any]
    width: int
    path_at: int
    start_at: int

    def __call__(self, decls: Sequence[D], by: int, path: str | None) -> Iterator[D]:
        """``decls`` moved by ``by`` characters, of ``path``, made by C code alone: a
        megabyte has thousands of trees."""
        columns: list[Iterator[Any]] = [map(f, decls) for f in _FIELDS[: self.width]]
        columns[self.path_at] = repeat(path)
        add = by.__add__
        s = self.start_at
        columns[s], columns[s + 1] = map(add, columns[s]), map(add, columns[s + 1])
        return map(self.make, zip(*columns, strict=False))


_moved_trees = _Mover(
    partial(_new, TreeDecl), len(TreeDecl._fields), *map(TreeDecl._fields.index, ("path", "start"))
)
_moved_models = _Mover(
    partial(_new, ModelDecl),
    len(ModelDecl._fields),
    *map(ModelDecl._fields.index, ("path", "start")),
)


def _id_span(el: Element) -> tuple[str | None, int, int]:
    a = el.attr("ID")
    if a is None or a.value is None:
        return None, el.name_start, el.name_end
    s, e = el.span_of_value(a)
    return a.value, s, e


def extract_facts(model: Model, path: str | None) -> DocumentFacts:
    """One pass over the elements: trees with their calls, and the model entries."""
    return _extract(model.elements, path)


def _extract(elements: Iterable[Element], path: str | None) -> DocumentFacts:
    """:func:`extract_facts` of ``elements``."""
    trees: list[TreeDecl] = []
    models: list[ModelDecl] = []
    subtree_models: list[ModelDecl] = []
    _extract_into(elements, path, 0, trees, models, subtree_models, {})
    return DocumentFacts(path, tuple(trees), tuple(models), tuple(subtree_models))


def _extract_into(
    elements: Iterable[Element],
    path: str | None,
    origin: int,
    trees: list[TreeDecl],
    models: list[ModelDecl],
    subtree_models: list[ModelDecl],
    spans: _Spans,
) -> None:
    """Add the declarations of ``elements``, placed ``origin`` code points further on
    (the calls' spans shared through ``spans``)."""
    tree: _OpenTree | None = None
    entry: _OpenEntry | None = None
    # Members bound once: reading one from its enum class is slow in Python 3.11.
    node, tree_zone, entry_zone, port_zone = Zone.NODE, Zone.TREE, Zone.MODEL_ENTRY, Zone.PORT_DECL
    for el in _declaring(elements):
        zone = el.zone
        if zone == node:
            if tree is not None and el.name == "SubTree":
                a = el.attr("ID")
                if a is not None and a.value:
                    tree.calls.append(a.value)
                    tree.spans.append(el.span_of_value(a))
            continue
        if el.depth <= 1 or zone == entry_zone:
            if tree is not None:
                trees.append(tree.close(path, origin, spans))
                tree = None
            if entry is not None:
                decl = entry.close(path, origin)
                (subtree_models if decl.category == "SubTree" else models).append(decl)
                entry = None
        if zone == tree_zone:
            tid, s, e = _id_span(el)
            if tid:
                tree = _OpenTree(tid, s, e)
        elif zone == entry_zone:
            if el.name in _ENTRY_CATEGORIES:
                mid, s, e = _id_span(el)
                if mid is not None:
                    entry = _OpenEntry(mid, cast("Category", el.name), s, e)
                    # The attribute form of very old models: every other attribute a port.
                    for a in el.attrs:
                        if a.name not in _ENTRY_NON_PORT_ATTRS and a.value is not None:
                            entry.ports.append(PortModel(a.name, "input", "", a.value, ""))
        elif zone == port_zone and entry is not None:
            pname = el.value("name")
            if pname is not None:
                entry.ports.append(
                    PortModel(
                        pname,
                        _DIRECTIONS[el.name],
                        el.value("type") or "",
                        el.value("default"),
                        el.value("description") or el.content or "",
                    )
                )
    if tree is not None:
        trees.append(tree.close(path, origin, spans))
    if entry is not None:
        decl = entry.close(path, origin)
        (subtree_models if decl.category == "SubTree" else models).append(decl)


def _declaring(elements: Iterable[Element]) -> Iterable[Element]:
    """``elements`` but the nodes other than ``<SubTree>`` (which declare nothing): of a
    section's columns, those rows are passed over in C without being made."""
    if not isinstance(elements, ElementTable) or elements.kept:  # made once: read as they are
        return elements
    rows = elements.rows
    cols = elements.columns
    lo, hi = rows.start, rows.stop
    tags = cols.tags[lo:hi]
    calls = {
        k for k, t in dict(zip(map(id, tags), tags, strict=True)).items() if t.name == "SubTree"
    }
    kept = map(or_, map(_NOT_NODE, cols.zones[lo:hi]), map(calls.__contains__, map(id, tags)))
    return map(elements.__getitem__, compress(range(hi - lo), kept))


_NOT_NODE: Final = int(Zone.NODE).__ne__


@dataclass(slots=True)
class _OpenTree:
    id: str
    start: int
    end: int
    calls: list[str] = field(default_factory=list)
    spans: list[tuple[int, int]] = field(default_factory=list)

    def close(self, path: str | None, origin: int, kept: _Spans) -> TreeDecl:
        s = self.start
        spans = tuple([(a - s, b - s) for a, b in self.spans])
        # Trees written alike call at the same offsets: one tuple for those of one pass.
        shared = kept.get(spans)
        if shared is None:
            shared = kept[spans] = spans
        calls = tuple(self.calls)
        return _new(TreeDecl, (self.id, path, s + origin, self.end + origin, calls, shared))


# The calls' spans of trees, each once (see _OpenTree.close).
_Spans = dict[tuple[tuple[int, int], ...], tuple[tuple[int, int], ...]]


@dataclass(slots=True)
class _OpenEntry:
    id: str
    category: Category
    start: int
    end: int
    ports: list[PortModel] = field(default_factory=list)

    def close(self, path: str | None, origin: int) -> ModelDecl:
        return ModelDecl(
            self.id, self.category, tuple(self.ports), path, self.start + origin, self.end + origin
        )
