"""The workspace's documents combined once, shared by the contexts of all of them.

:meth:`Context.combine <bt_lsp.rules.context.Context.combine>` looks at every other
document for each document it makes a context for: a folder of N files costs N² there.
:class:`SharedDecls` reads the workspace's documents once (their declarations by ID, each
ID's declarations in order) and :meth:`SharedDecls.context` then makes the context of one
of them, its include closure taken out of the shared part, in time that depends on that
document, its closure and the number of distinct model IDs, not on the number of
documents.  The context is the one ``combine`` makes from the same inputs (same entries,
same order, same first-wins choices); ``workspace_trees`` is a view of the shared trees
without the excluded documents, made whole only if it is iterated.
"""

from __future__ import annotations

from collections.abc import Collection, Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass
from types import MappingProxyType
from typing import TYPE_CHECKING, Generic, TypeVar

from bt_lsp.rules.builtins_v3 import builtins_for
from bt_lsp.rules.context import Context, _all_by_id, _tagged, is_generated_catalog
from bt_lsp.rules.decls import DocumentFacts, ModelDecl, TreeDecl
from bt_lsp.rules.facts import facts_of

if TYPE_CHECKING:
    from bt_lsp.syntax.document import Document

__all__ = ["SharedDecls"]

D = TypeVar("D", ModelDecl, TreeDecl)


class _Candidates(Generic[D]):
    """Every declaration of each ID among the shared documents, in order: ``(document
    position, place in the document's declarations, declaration)``, IDs in the order of
    their first declarations."""

    __slots__ = ("by_id", "firsts", "firsts_at")

    def __init__(self, groups: Iterable[tuple[int, Sequence[D]]]) -> None:
        self.by_id: dict[str, list[tuple[int, int, D]]] = {}
        for i, decls in groups:
            for j, d in enumerate(decls):
                self.by_id.setdefault(d.id, []).append((i, j, d))
        # The first declaration of each ID, in order, and the documents that hold one.
        self.firsts: list[D] = [c[0][2] for c in self.by_id.values()]
        self.firsts_at: set[int] = {c[0][0] for c in self.by_id.values()}

    def first_without(self, hit: Collection[int]) -> list[D]:
        """The first declaration of each ID that no document at a position in ``hit``
        makes, in the order of those declarations: what the other documents declare,
        first wins, as if the documents at ``hit`` were not there."""
        if not hit or self.firsts_at.isdisjoint(hit):
            return self.firsts
        kept: list[tuple[int, int, D]] = []
        for cands in self.by_id.values():
            for cand in cands:
                if cand[0] not in hit:
                    kept.append(cand)
                    break
        kept.sort(key=lambda c: (c[0], c[1]))
        return [d for _, _, d in kept]


class _WorkspaceTrees(Mapping[str, tuple[TreeDecl, ...]]):
    """The shared documents' trees by ID, without those of the documents at ``hit``.  An
    entry is made when first looked up: the document being checked is one of ``hit``, and
    patching every tree ID it declares (thousands) at every edit cost more than the
    lookups of the sections an edit checks again."""

    __slots__ = ("_groups", "_hit", "_patch", "_positions", "_shared", "_whole")

    def __init__(
        self,
        shared: dict[str, tuple[TreeDecl, ...]],
        positions: Mapping[str, tuple[int, ...]],
        groups: Sequence[tuple[TreeDecl, ...]],
        hit: frozenset[int],
    ) -> None:
        self._shared = shared
        self._positions = positions
        self._groups = groups
        self._hit = hit
        self._whole: dict[str, tuple[TreeDecl, ...]] | None = None
        # The entries looked up so far whose declarations the documents at ``hit`` share
        # (None: they made them all).
        self._patch: dict[str, tuple[TreeDecl, ...] | None] = {}
        if not hit:
            self._whole = shared

    def _entry(self, key: str) -> tuple[TreeDecl, ...] | None:
        """The entry of ``key``, ``None`` if there is none."""
        found = self._shared.get(key)
        if found is None or self._whole is self._shared:
            return found
        patch = self._patch
        if key in patch:
            return patch[key]
        hit = self._hit
        at = self._positions[key]
        if not hit.isdisjoint(at):
            found = tuple(d for d, i in zip(found, at, strict=True) if i not in hit) or None
        patch[key] = found
        return found

    def __getitem__(self, key: str) -> tuple[TreeDecl, ...]:
        found = self._entry(key)
        if found is None:
            raise KeyError(key)
        return found

    def get(  # type: ignore[override]
        self, key: str, default: tuple[TreeDecl, ...] | None = None
    ) -> tuple[TreeDecl, ...] | None:
        found = self._entry(key) if isinstance(key, str) else None
        return default if found is None else found

    def __contains__(self, key: object) -> bool:
        return isinstance(key, str) and self._entry(key) is not None

    def _all(self) -> dict[str, tuple[TreeDecl, ...]]:
        """The whole mapping, in the order ``combine`` makes it (made when iterated)."""
        if self._whole is None:
            hit = self._hit
            self._whole = _all_by_id(g for i, g in enumerate(self._groups) if i not in hit)
        return self._whole

    def __iter__(self) -> Iterator[str]:
        return iter(self._all())

    def __len__(self) -> int:
        return len(self._all())


class _RestKey:
    """What a context was combined from among the shared documents: the facts of those
    not excluded.  Equal keys mean equal declarations (see ``Context.sources``)."""

    __slots__ = ("hit", "shared")

    def __init__(self, shared: SharedDecls, hit: frozenset[int]) -> None:
        self.shared = shared
        self.hit = hit

    def facts(self) -> list[DocumentFacts]:
        return [f for i, f in enumerate(self.shared.facts) if i not in self.hit]

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, _RestKey):
            return NotImplemented
        if other.shared is self.shared and other.hit == self.hit:
            return True
        return self.facts() == other.facts()

    def __hash__(self) -> int:
        return len(self.shared.facts) - len(self.hit)


@dataclass(frozen=True, slots=True, eq=False)
class _Entry:
    path: str
    facts: DocumentFacts
    models: tuple[ModelDecl, ...]  # tagged with their source
    generated: bool


class SharedDecls:
    """The declarations of the workspace's documents ``docs`` (``(path, document)`` in
    the workspace's order), read once."""

    def __init__(self, docs: Sequence[tuple[str, Document]]) -> None:
        self.paths = [p for p, _ in docs]
        self.position = {p: i for i, p in enumerate(self.paths)}
        entries = [_entry(p, d) for p, d in docs]
        self.facts = [e.facts for e in entries]
        self._authoritative = _Candidates(
            (i, e.models) for i, e in enumerate(entries) if e.generated
        )
        self._advisory = _Candidates(
            (i, e.models) for i, e in enumerate(entries) if not e.generated
        )
        self._subtree_models = _Candidates(
            (i, e.facts.subtree_models) for i, e in enumerate(entries)
        )
        self._tree_groups = [e.facts.trees for e in entries]
        positions: dict[str, list[int]] = {}
        for i, trees in enumerate(self._tree_groups):
            for t in trees:
                positions.setdefault(t.id, []).append(i)
        self._tree_positions = {k: tuple(v) for k, v in positions.items()}
        self._trees = _all_by_id(self._tree_groups)

    def context(
        self,
        own: Document,
        closure: Sequence[tuple[str, Document]],
        *,
        path: str,
        ros_pkg_paths: Mapping[str, str] | None = None,
        model_files: Iterable[tuple[str, Document]] = (),
        ros_models: Iterable[tuple[str, Document]] = (),
        included_by: Iterable[str] = (),
        btcpp_version: str | None = None,
        foreign: Collection[str] = (),
        btcpp_unclear: bool = False,
    ) -> Context:
        """What ``Context.combine(own, others, ...)`` gives when ``others`` are
        ``closure`` (included, in load order) then the shared documents but ``own`` and
        those of the closure (not included); the models of the shared documents in
        ``foreign`` do not count, their trees do."""
        own_facts = facts_of(own, path)
        hit = frozenset(
            i
            for i in (self.position.get(p) for p in (path, *(p for p, _ in closure)))
            if i is not None
        )
        foreign_hit = frozenset(i for i in (self.position.get(p) for p in foreign) if i is not None)
        no_models = hit | foreign_hit
        closure_entries = [_entry(p, d) for p, d in closure if p != path]
        authoritative: list[Iterable[ModelDecl]] = [
            e.models for e in closure_entries if e.generated
        ]
        authoritative.append(self._authoritative.first_without(no_models))
        advisory: list[Iterable[ModelDecl]] = [own_facts.models]
        advisory.extend(e.models for e in closure_entries if not e.generated)
        advisory.append(self._advisory.first_without(no_models))
        subtree_models: list[Iterable[ModelDecl]] = [own_facts.subtree_models]
        subtree_models.extend(e.facts.subtree_models for e in closure_entries)
        subtree_models.append(self._subtree_models.first_without(no_models))
        sources: list[object] = [path]
        sources.extend((e.facts, True) for e in closure_entries)
        sources.append(_RestKey(self, hit))
        sources.append(("foreign", _RestKey(self, no_models)))
        catalog = False
        for model_path, model_doc in model_files:
            f = facts_of(model_doc, model_path)
            sources.append(f)
            if model_path.endswith(".btproj"):
                advisory.append(_tagged(f, "palette", model_doc))
            else:
                authoritative.append(_tagged(f, "catalog", model_doc))
                catalog = True
            subtree_models.append(f.subtree_models)
        for model_path, model_doc in ros_models:
            f = facts_of(model_doc, model_path)
            sources.append(("ros", f))
            authoritative.append(_tagged(f, "ros", model_doc))
        trees = [e.facts.trees for e in closure_entries]
        trees.append(own_facts.trees)
        return Context(
            path=path,
            models=MappingProxyType(
                _first([*authoritative, *advisory], builtins_for(btcpp_version))
            ),
            subtree_models=MappingProxyType(_first(subtree_models)),
            trees=MappingProxyType(_all_by_id(trees)),
            workspace_trees=_WorkspaceTrees(
                self._trees, self._tree_positions, self._tree_groups, hit
            ),
            workspace_has_custom_models=catalog,
            ros_pkg_paths=MappingProxyType(dict(ros_pkg_paths or {})),
            included_by=tuple(included_by),
            btcpp_version=btcpp_version,
            btcpp_unclear=btcpp_unclear,
            included=tuple(e.path for e in closure_entries),
            workspace_files=len(self.paths) - len(hit),
            sources=(*sources, None, btcpp_version, btcpp_unclear),
        )


def _entry(path: str, doc: Document) -> _Entry:
    """How ``combine`` takes one other document's models."""
    f = facts_of(doc, path)
    if path.endswith(".btproj"):
        return _Entry(path, f, _tagged(f, "palette", doc), False)
    if f.models and is_generated_catalog(doc):
        return _Entry(path, f, _tagged(f, "generated", doc), True)
    return _Entry(path, f, f.models, False)


def _first(
    groups: Iterable[Iterable[ModelDecl]], left_out: Collection[str] = ()
) -> dict[str, ModelDecl]:
    """The first declaration of each ID but those in ``left_out``, in order."""
    out: dict[str, ModelDecl] = {}
    for group in groups:
        for d in group:
            if d.id not in out:
                out[d.id] = d
    for key in out.keys() & left_out:
        del out[key]
    return out
