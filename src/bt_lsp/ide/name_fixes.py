"""Fixes for name diagnostics: sanitized, unique replacements, renamed as a rename would.

A fix renames a bad name exactly as :func:`bt_lsp.ide.rename.rename` renames it to the same
new name, through the same :class:`~bt_lsp.ide.rename.Renamer`: every reference in the
document and in the other workspace documents, a tree's port together with its uses as a
blackboard key inside the tree, and the ``{=}`` of a renamed port attribute written out.
Where the rename refuses:

* a refusal of the new name (it is taken, or would merge two keys): the next candidate
  name is tried, and numbered ones (``_2``, ``_3`` …) when no candidate will do;
* a refusal of the tree port's key itself (shared through ``_autoremap``, reached as
  ``@key``, written with references or after a script's syntax error): the fix renames the
  port's own names only, and its title says that the key is left as it is.

A fix never breaks a reference that works.  A name whose target is not in the workspace
(:func:`~bt_lsp.ide.name_edits.elsewhere`) is renamed only with its target: a call of a tree
defined elsewhere gets no fix at all (the rename refuses it), and a node type that no
``<TreeNodesModel>`` of the workspace declares (registered in C++ we cannot see) gets its
fixes, none preferred, each title saying that the registration must be renamed too; fix-all
leaves both as they are, with a note.

Pure: these functions return edits; the front ends decide whether to apply them.
"""

from __future__ import annotations

from collections.abc import Hashable, Iterable, Iterator, Mapping
from collections.abc import Set as AbstractSet
from dataclasses import dataclass, field

from bt_lsp.ide.fix import Fix
from bt_lsp.ide.name_edits import (
    namespace,
    occurrences,
    other_file_edits,
    rename_edits,
    shown,
    taken_names,
)
from bt_lsp.ide.rename import RenamePlan, Renamer, RenameRefused, combined
from bt_lsp.ide.sanitize import candidates, sanitize
from bt_lsp.rules.codes import Applicability
from bt_lsp.rules.context import ModelDecl
from bt_lsp.rules.diagnostics import Diagnostic
from bt_lsp.rules.names import NAME_FIX_TITLES
from bt_lsp.syntax.document import Document
from bt_lsp.syntax.edits import TextEdit, escape_value
from bt_lsp.syntax.elements import NameRef
from bt_lsp.syntax.model import Model

__all__ = [
    "Fix",
    "FixAll",
    "Renaming",
    "WorkspaceFix",
    "WorkspaceRename",
    "edits_in",
    "escape_value",
    "fix_all",
    "fix_workspace",
    "fixes_for_name",
    "occurrences",
    "other_file_edits",
    "preferred_renaming",
    "rename_edits",
    "renamings",
    "shown",
    "taken_names",
]

# Numbered names tried when the rename refuses every candidate name.
_MORE_NAMES = 20


@dataclass(frozen=True, slots=True)
class Renaming:
    """A new name for a bad name, and the edits of renaming it.  ``kept`` names what the
    rename leaves as it is (``"key 'x' in tree 'T'"``) because the full rename was refused,
    and ``why`` is that refusal."""

    old: str
    new: str
    plan: RenamePlan
    kept: str | None = None
    why: str | None = None
    caution: str | None = None  # what must be renamed too, outside the workspace

    @property
    def where(self) -> str:
        """How many places the renaming changes: ``"5 places, 4 other files"``."""
        places = self.plan.places
        where = "1 place" if places == 1 else f"{places} places"
        n = len(self.plan.other_edits)
        if n:
            where += f", {n} other file{'s' if n > 1 else ''}"
        return where

    @property
    def fix(self) -> str:
        """The key of the fix among the name codes' fixes (``NAME_FIX_TITLES``)."""
        if self.caution is not None:
            return "rename-elsewhere"
        return "rename" if self.new else "clear"

    @property
    def applicability(self) -> Applicability:
        return NAME_FIX_TITLES[self.fix].applicability

    @property
    def title(self) -> str:
        values = {"old": shown(self.old), "new": shown(self.new), "where": self.where}
        title = NAME_FIX_TITLES[self.fix].title.format(caution=self.caution, **values)
        if self.kept is not None:
            title += f"; {self.kept} left as it is"
        return title

    @property
    def note(self) -> str | None:
        """What the fix leaves as it is and why, for reports (``None``: nothing)."""
        if self.kept is None:
            return None
        return (
            f"renamed '{shown(self.old)}' to '{shown(self.new)}' and left the {self.kept} "
            f"as it is: {self.why}"
        )


class _Without(AbstractSet[str]):
    """A set minus one name, without copying the set."""

    def __init__(self, names: AbstractSet[str], left_out: str) -> None:
        self._names, self._left_out = names, left_out

    def __contains__(self, name: object) -> bool:
        return name != self._left_out and name in self._names

    def __iter__(self) -> Iterator[str]:
        return (n for n in self._names if n != self._left_out)

    def __len__(self) -> int:
        return len(self._names) - (self._left_out in self._names)


class _With(AbstractSet[str]):
    """The union of a set and a few more names, without copying the set."""

    def __init__(self, names: AbstractSet[str], more: AbstractSet[str]) -> None:
        self._names, self._more = names, more

    def __contains__(self, name: object) -> bool:
        return name in self._more or name in self._names

    def __iter__(self) -> Iterator[str]:
        yield from self._names
        yield from (n for n in self._more if n not in self._names)

    def __len__(self) -> int:
        return len(self._names) + sum(1 for n in self._more if n not in self._names)


def _renaming(renamer: Renamer, ref: NameRef, new: str, taken: AbstractSet[str]) -> Renaming | None:
    away = renamer.elsewhere(ref.symbol)
    caution = None if away is None else f"{away.what} is {away.where}: rename it there too"
    try:
        return Renaming(ref.text, new, renamer.plan(ref, new, taken=taken), caution=caution)
    except RenameRefused as e:
        sym = ref.symbol
        if e.new_name or sym is None or sym.kind != "port" or sym.owner_kind != "tree":
            return None
        why = e.message
    try:
        plan = renamer.plan(ref, new, keys=False, taken=taken)
    except RenameRefused:
        return None
    kept = f"key '{shown(sym.name)}' in tree '{shown(sym.owner)}'"
    return Renaming(ref.text, new, plan, kept, why, caution)


def renamings(renamer: Renamer, ref: NameRef, taken: AbstractSet[str]) -> Iterator[Renaming]:
    """The renamings of the bad name ``ref`` (of the renamer's document), best first: one
    for each candidate name (:func:`bt_lsp.ide.sanitize.candidates`) that the rename accepts,
    else for the first numbered name it accepts.  ``taken`` are the names of the symbol's
    namespace that the new name must avoid."""
    kind = ref.kind
    if kind is None:
        return
    away = renamer.elsewhere(ref.symbol)
    if away is not None and away.refuse:
        return
    tried: set[str] = set()
    found = False
    for new in candidates(ref.text, kind, taken):
        if new == ref.text or new in tried:
            continue
        tried.add(new)
        r = _renaming(renamer, ref, new, taken)
        if r is not None:
            found = True
            yield r
    if found:
        return
    for _ in range(_MORE_NAMES):
        new = sanitize(ref.text, kind, _With(taken, tried))
        if new == ref.text or new in tried:
            return
        tried.add(new)
        r = _renaming(renamer, ref, new, taken)
        if r is not None:
            yield r
            return


def _name_ref(doc: Document, diag: Diagnostic) -> NameRef | None:
    """The name token a name diagnostic is about."""
    if not diag.is_name_rule:
        return None
    ref = doc.model.ref_at(diag.start)
    if ref is None or ref.start != diag.start or ref.end != diag.end or ref.kind is None:
        return None
    return ref


def preferred_renaming(
    doc: Document,
    ref: NameRef,
    others: Mapping[str, Document] | None = None,
    registered: Mapping[str, ModelDecl] | None = None,
) -> Renaming | None:
    """The renaming of the preferred fix for the bad name ``ref``."""
    others = others or {}
    taken = taken_names(doc.model, ref.symbol, [d.model for d in others.values()])
    return next(renamings(Renamer(doc, others, registered), ref, taken), None)


def fixes_for_name(
    doc: Document,
    diag: Diagnostic,
    others: Mapping[str, Document] | None = None,
    registered: Mapping[str, ModelDecl] | None = None,
) -> list[Fix]:
    """Quick fixes for one name diagnostic: the preferred rename first, then alternatives.
    ``others`` are the other workspace documents, by path: references there are renamed
    too; ``registered`` (the context's models) says where node types are registered."""
    ref = _name_ref(doc, diag)
    if ref is None:
        return []
    others = others or {}
    taken = taken_names(doc.model, ref.symbol, [d.model for d in others.values()])
    return [
        Fix(
            r.title,
            r.plan.edits,
            i == 0 and r.applicability is Applicability.SAFE,
            diag,
            r.plan.other_edits,
            r.applicability,
        )
        for i, r in enumerate(renamings(Renamer(doc, others, registered), ref, taken))
    ]


@dataclass(frozen=True, slots=True)
class FixAll:
    """The edits of every preferred name fix of a document (``other_edits``: in the other
    workspace documents, by path), and a note for each fix that left something as it is
    (see :attr:`Renaming.note`) and for each name left alone because its target is outside
    the workspace."""

    edits: list[TextEdit]
    notes: list[str] = field(default_factory=list)
    other_edits: Mapping[str, tuple[TextEdit, ...]] = field(default_factory=dict)


def _taken_by_namespace(models: Iterable[Model]) -> dict[tuple[str, ...], set[str]]:
    taken: dict[tuple[str, ...], set[str]] = {}
    for m in models:
        for sym in m.by_symbol:
            taken.setdefault(namespace(sym), set()).add(sym.name)
    return taken


def _choose(
    doc: Document,
    renamer: Renamer,
    diags: Iterable[Diagnostic],
    done: set[Hashable],
    taken_by_ns: dict[tuple[str, ...], set[str]],
    notes: list[str],
) -> Iterator[Renaming]:
    """The preferred renaming of each bad name of ``doc`` not ``done`` yet (by symbol, or
    by ``(path, start, end)`` for a name without one), each new name added to the names
    taken in its namespace; a name whose target is outside the workspace is left, with a
    note."""
    for diag in diags:
        ref = _name_ref(doc, diag)
        if ref is None:
            continue
        key: Hashable = ref.symbol if ref.symbol is not None else (doc.path, ref.start, ref.end)
        if key in done:
            continue
        done.add(key)
        away = renamer.elsewhere(ref.symbol)
        if away is not None:
            notes.append(f"left '{shown(ref.text)}' as it is: {away.why}")
            continue
        names: set[str] | None = None
        taken: AbstractSet[str] = frozenset()
        if ref.symbol is not None:
            names = taken_by_ns.setdefault(namespace(ref.symbol), set())
            taken = _Without(names, ref.symbol.name)
        r = next(renamings(renamer, ref, taken), None)
        if r is None:
            continue
        if names is not None:
            names.add(r.new)
        if r.note is not None:
            notes.append(r.note)
        yield r


def fix_all(
    doc: Document,
    diags: Iterable[Diagnostic],
    others: Mapping[str, Document] | None = None,
    registered: Mapping[str, ModelDecl] | None = None,
) -> FixAll:
    """Every preferred name fix at once, consistently: one new name per symbol, all
    distinct from each other and from the names that stay in the workspace.  Each symbol
    is renamed as a rename renames it (its keys included), in the document and in the
    ``others`` (the other workspace documents, by path), which a tree defined here and
    called there needs, so that the call follows.  A name whose target is outside the
    workspace is left as it is, with a note: a call of a tree defined elsewhere, and a node
    type (or its port) that no ``<TreeNodesModel>`` of the workspace declares or that the
    project's C++ registers (``registered``: the context's models).

    ``bt-lsp check --fix`` plans a whole folder at once instead (:func:`fix_workspace`)."""
    others = others or {}
    renamer = Renamer(doc, others, registered)
    notes: list[str] = []
    taken_by_ns = _taken_by_namespace([doc.model, *(d.model for d in others.values())])
    chosen = list(_choose(doc, renamer, diags, set(), taken_by_ns, notes))
    plan = combined([r.plan for r in chosen])
    return FixAll(list(plan.edits), notes, plan.other_edits)


@dataclass(frozen=True, slots=True)
class WorkspaceRename:
    """One name's rename in a fix of a whole workspace: its edits in every file it
    touches, by path.  The files are written all together or not at all."""

    renaming: Renaming
    edits: Mapping[str, tuple[TextEdit, ...]]
    written_out: frozenset[tuple[str, int, int]]

    @property
    def paths(self) -> frozenset[str]:
        return frozenset(p for p, e in self.edits.items() if e)


@dataclass(frozen=True, slots=True)
class WorkspaceFix:
    """The renames of every preferred name fix of a workspace, and by path the notes of
    the names left as they are (see :class:`FixAll`)."""

    renames: list[WorkspaceRename]
    notes: Mapping[str, list[str]]


def fix_workspace(
    docs: Mapping[str, Document],
    diags: Mapping[str, Iterable[Diagnostic]],
    registered: Mapping[str, Mapping[str, ModelDecl]] | None = None,
) -> WorkspaceFix:
    """Every preferred name fix of the documents ``docs`` (by path) at once: one decision
    per symbol for the whole workspace, so that two bad names that sanitize to the same
    new name get the same new names in every file, and each rename carries its edits in
    all the files it touches (see :func:`edits_in`).  ``diags`` are each document's
    diagnostics, ``registered`` each document's context models, by path."""
    taken_by_ns = _taken_by_namespace(d.model for d in docs.values())
    done: set[Hashable] = set()
    renames: list[WorkspaceRename] = []
    notes: dict[str, list[str]] = {}
    for path, doc in docs.items():
        others = {p: d for p, d in docs.items() if p != path}
        renamer = Renamer(doc, others, (registered or {}).get(path))
        left = notes.setdefault(path, [])
        for r in _choose(doc, renamer, diags.get(path, ()), done, taken_by_ns, left):
            plan = r.plan
            edits = {path: plan.edits, **plan.other_edits}
            out = frozenset((p if p is not None else path, s, e) for p, s, e in plan.written_out)
            renames.append(WorkspaceRename(r, edits, out))
    return WorkspaceFix(renames, notes)


def edits_in(renames: Iterable[WorkspaceRename], path: str) -> list[TextEdit]:
    """The edits of ``renames`` in the file ``path``, combined as :func:`combined` combines
    renames (an edit that only writes out a key gives way to a rename of that key)."""
    return list(
        combined(
            RenamePlan(
                r.edits.get(path, ()),
                written_out=frozenset((None, s, e) for p, s, e in r.written_out if p == path),
            )
            for r in renames
        ).edits
    )
