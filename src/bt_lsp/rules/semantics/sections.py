"""The section pass of the semantic checks, remembered on each section of the model.

:func:`bt_lsp.rules.semantics.check` runs the document-wide rules (the root and its sections,
tree IDs across the document, the main tree, recursion) over the whole model, and the
rules that look at one element and at what the context says about the names it uses over
each section of the model (:class:`bt_lsp.syntax.sections.Section`: one child of ``<root>``), in
the section's coordinates.  A section's results are kept on it with everything they read
besides the section: the context entries looked up (through mappings that record every
lookup, compared by their position-free content), the context's settings, the root's
``BTCPP_format`` and whether the root has more than one child, and, when a message names
a line, the line the section starts on.  They are used again while all of that is the same,
so that an edit re-checks its own section, and the sections that use a declaration it
changed.

A rule of the section pass must therefore read nothing else outside its section: not the
positions of this document's declarations in the context (every edit before them moves
them; such rules belong to the document-wide pass), nor the root's other children.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Iterator, Mapping, Sequence
from itertools import compress, count
from typing import TYPE_CHECKING, Final, TypeVar, cast

from bt_lsp.rules.context import Context, ModelDecl, TreeDecl
from bt_lsp.rules.diagnostics import Diagnostic, capped
from bt_lsp.rules.facts import facts_of, local_facts
from bt_lsp.rules.section_diff import common_ends
from bt_lsp.rules.semantics.base import State, TagFindings
from bt_lsp.syntax.elements import Element
from bt_lsp.syntax.model import Model
from bt_lsp.syntax.sections import Section

if TYPE_CHECKING:
    from bt_lsp.syntax.text import LineIndex

__all__ = ["check_sections"]

V = TypeVar("V")

# The mappings of the context a run records its lookups in, by index.  A lookup is a
# field's index and a key (``None`` stands for the whole mapping, iterated).
_FIELDS: Final = ("models", "subtree_models", "trees", "workspace_trees")
_KEY: Final = "semantics"
_UNKNOWN: Final = object()  # a signature not yet computed
# Per field, what was looked up (or what changed): keys.
Keys = tuple[set[str | None], ...]
# The signature of a lookup now: (field index, key) -> signature.
Current = Callable[[int, "str | None"], object]


class _Recording(Mapping[str, V]):
    """A mapping of the context that notes which keys a rule looked up."""

    __slots__ = ("_count", "_inner", "_keys")

    def __init__(self, inner: Mapping[str, V], keys: set[str | None], count: list[int]) -> None:
        self._inner = inner
        self._keys = keys
        self._count = count  # of every lookup (see State.lookups)

    def __getitem__(self, key: str) -> V:
        self._keys.add(key)
        self._count[0] += 1
        return self._inner[key]

    def get(self, key: str, default: V | None = None) -> V | None:  # type: ignore[override]
        self._keys.add(key)  # (Mapping.get would raise and catch a KeyError on a miss)
        self._count[0] += 1
        return self._inner.get(key, default)

    def __contains__(self, key: object) -> bool:
        if isinstance(key, str):
            self._keys.add(key)
        self._count[0] += 1
        return key in self._inner

    def __iter__(self) -> Iterator[str]:
        self._keys.add(None)
        self._count[0] += 1
        return iter(self._inner)

    def __len__(self) -> int:
        self._keys.add(None)
        self._count[0] += 1
        return len(self._inner)


def _content(value: ModelDecl | tuple[TreeDecl, ...], own: str | None) -> object:
    """A context entry without positions (a tree's ID is its key).  Made for every tree a
    section calls, so the usual one, a single definition in the document ``own`` itself,
    is its calls alone (a tuple of strings, never equal to the other forms, whose second
    item is a tuple or whose first is)."""
    if isinstance(value, ModelDecl):
        return (value.id, value.category, value.ports, value.path)
    if len(value) == 1:
        d = value[0]
        return d.calls if d.path == own else (d.path, d.calls)
    return tuple([(d.path, d.calls) for d in value])


def _signature(
    mapping: Mapping[str, ModelDecl | tuple[TreeDecl, ...]], key: str | None, own: str | None
) -> object:
    if key is None:
        return tuple([(k, _content(v, own)) for k, v in mapping.items()])
    value = mapping.get(key)
    return None if value is None else _content(value, own)


class _Entry:
    """The results of one section and what they depend on: ``deps`` holds a flat
    ``(field, key, signature)`` triple for each context entry looked up (one tuple: a
    document may have twenty thousand sections)."""

    __slots__ = ("deps", "line", "more", "out", "settings")

    def __init__(
        self,
        settings: tuple[object, ...],
        line: int | None,  # the line the section starts on, when a message names a line
        deps: tuple[object, ...],
        out: list[Diagnostic],  # the first MAX_DIAGNOSTICS by position
        more: int = 0,  # how many more were found
    ) -> None:
        self.settings = settings
        self.line = line
        self.deps = deps
        self.out = out
        self.more = more


@dataclasses.dataclass(slots=True)
class _History:
    """The last check of a document: the settings, the signature of every context entry
    looked up by its sections and found (so that the next check compares each entry once;
    most lookups find nothing, and a key absent from these counts as absent then), what
    the context was combined from besides the document itself, and its sections (all of
    them valid then), with those that have diagnostics and those that name lines.

    Besides the entries looked up, ``sigs`` holds those of every ID the document declared
    when every section was last looked at: the first edit of a section compares the
    entries of what it declares with what they were, where an entry nobody had looked up
    (the ID of a tree no other tree calls) counted as absent then, hence changed, and
    made the check look at every section."""

    settings: tuple[object, ...] = ()
    sigs: tuple[dict[str | None, object], ...] = dataclasses.field(
        default_factory=lambda: tuple({} for _ in _FIELDS)
    )
    sources: tuple[object, ...] = ()
    sections: list[Section] | None = None
    with_diagnostics: set[Section] = dataclasses.field(default_factory=set)
    lines: set[Section] = dataclasses.field(default_factory=set)


def check_sections(st: State, check: Callable[[State, Sequence[Element]], None]) -> None:
    """Add the section pass's diagnostics of every section of ``st.model`` to ``st.out``:
    ``check`` runs over the elements of the sections whose remembered results are out of
    date.  When the context's entries did not change, only the sections that are new
    since the last check of the document are looked at (and those whose messages name a
    line), so that an edit costs what it changes."""
    model, ctx = st.model, st.ctx
    root = model.root
    settings = (
        ctx.path,
        ctx.workspace_has_custom_models,
        ctx.registered,
        ctx.incomplete,
        tuple(sorted(ctx.ros_pkg_paths.items())),
        ctx.included_by,
        ctx.included,
        ctx.workspace_files,
        st.v4,
        st.v3,
        root is not None and len(root.children) > 1,
    )
    mappings: list[Mapping[str, ModelDecl | tuple[TreeDecl, ...]]] = [
        getattr(ctx, f) for f in _FIELDS
    ]
    memo: tuple[dict[str | None, object], ...] = tuple({} for _ in _FIELDS)

    def current(field: int, key: str | None) -> object:
        found = memo[field]
        sig = found.get(key, _UNKNOWN)
        if sig is _UNKNOWN:
            sig = found[key] = _signature(mappings[field], key, ctx.path)
        return sig

    # Kept for the document (its history), updated by one analysis at a time (its lock).
    hist: _History | None = st.doc.history.memo.get("section-checks")
    if hist is None:
        hist = _History()
        st.doc.history.memo["section-checks"] = hist
    sections, origins = model.sections, model.origins
    n = len(sections)
    old = hist.sections
    same = old is not None and hist.settings == settings
    # The sections both checks begin and end with; those between are new (``came``).
    p, q = common_ends(old, sections) if old is not None else (0, 0)
    went = old[p : len(old) - q] if old is not None else []
    changed: Keys = tuple(set() for _ in _FIELDS)
    if same:
        # The context entries that changed since the last check: a section that was valid
        # then is valid now unless it looked one of them up.
        touched = _touched(went, sections[p : n - q], hist.sources, ctx)
        if touched is None:
            _all_changed(hist.sigs, mappings, current, changed)
        elif touched:
            for f, sigs in enumerate(hist.sigs):
                for key in touched:
                    if sigs.get(key) != current(f, key):
                        changed[f].add(key)
                if None in sigs and sigs[None] != current(f, None):
                    changed[f].add(None)
    lines = st.doc.lines
    todo: list[tuple[Section, int]] = []

    def keep(sec: Section, found: _Entry) -> None:
        """``sec``'s results are valid: file it under what the next check looks at."""
        if found.out:
            with_diagnostics.add(sec)
        if found.line is not None:
            line_dependent.add(sec)

    if same and not any(changed):
        todo.extend(zip(sections[p : n - q], origins[p : n - q], strict=True))
        with_diagnostics = hist.with_diagnostics.difference(went)
        line_dependent = hist.lines.difference(went)
        if line_dependent:
            index = dict(zip(sections, range(n), strict=True))
            for sec in list(line_dependent):
                origin = origins[index[sec]]
                entry: _Entry = sec.cache[_KEY]
                if entry.line != lines.line_of(origin):
                    with_diagnostics.discard(sec)
                    line_dependent.discard(sec)
                    todo.append((sec, origin))
    else:
        with_diagnostics, line_dependent = set(), set()
        for k, (sec, origin) in enumerate(zip(sections, origins, strict=True)):
            found: _Entry | None = sec.cache.get(_KEY)
            if found is not None and same and (k < p or k >= n - q):  # valid last time
                ok = (found.line is None or found.line == lines.line_of(origin)) and _unaffected(
                    found.deps, changed
                )
            else:
                ok = _still_valid(found, settings, lines, origin, current)
            if ok:
                assert found is not None
                keep(sec, found)
            else:
                todo.append((sec, origin))
    if todo:
        recording = _RecordingContext(ctx)
        for sec, origin in todo:
            found = sec.cache.get(_KEY)
            if not _still_valid(found, settings, lines, origin, current):
                found = _run(st, sec, origin, root, settings, check, current, lines, recording)
                sec.cache[_KEY] = found
            assert found is not None
            keep(sec, found)
    if with_diagnostics:
        out = st.out
        for k in compress(count(), map(with_diagnostics.__contains__, sections)):
            origin = origins[k]
            entry = sections[k].cache[_KEY]
            st.more += entry.more
            out.extend(
                Diagnostic(d.start + origin, d.end + origin, d.code, d.message, d.severity, d.data)
                for d in entry.out
            )
    hist.settings = settings
    if not same:  # the entries of what the document declares (see _History)
        own = facts_of(st.doc, ctx.path)
        ids = {t.id for t in own.trees}
        ids.update(m.id for m in (*own.models, *own.subtree_models))
        for key in ids:
            for f in range(len(_FIELDS)):
                current(f, key)
    for sigs, now in zip(hist.sigs, memo, strict=True):
        for looked, sig in now.items():
            if sig is None:
                sigs.pop(looked, None)
            else:
                sigs[looked] = sig
    hist.sources = ctx.sources
    hist.sections, hist.with_diagnostics, hist.lines = sections, with_diagnostics, line_dependent


def _all_changed(
    sigs: tuple[dict[str | None, object], ...],
    mappings: Sequence[Mapping[str, object]],
    current: Current,
    changed: Keys,
) -> None:
    """Add to ``changed`` every context entry that may differ from the last check: those
    found then whose signature changed, and every key present now that was not then (it
    may have been looked up and missed)."""
    for f, (was, mapping) in enumerate(zip(sigs, mappings, strict=True)):
        changed[f].update(key for key, sig in was.items() if current(f, key) != sig)
        changed[f].update(key for key in mapping if key not in was)


def _unaffected(deps: tuple[object, ...], changed: Keys) -> bool:
    """Whether none of the lookups ``deps`` (flat triples) is among ``changed``."""
    if not any(changed):
        return True
    return all(key not in changed[f] for f, key, _ in _triples(deps))


def _still_valid(
    entry: _Entry | None,
    settings: tuple[object, ...],
    lines: LineIndex,
    origin: int,
    current: Current,
) -> bool:
    """Whether remembered results hold, every context entry they read compared."""
    if (
        entry is None
        or entry.settings != settings
        or (entry.line is not None and entry.line != lines.line_of(origin))
    ):
        return False
    return all(current(f, key) == sig for f, key, sig in _triples(entry.deps))


def _triples(deps: tuple[object, ...]) -> Iterator[tuple[int, str | None, object]]:
    """The ``(field, key, signature)`` triples of a flat ``deps``."""
    return cast(
        "Iterator[tuple[int, str | None, object]]",
        zip(deps[::3], deps[1::3], deps[2::3], strict=True),
    )


def _touched(
    went: Sequence[Section], came: Sequence[Section], sources: tuple[object, ...], ctx: Context
) -> set[str] | None:
    """The names declared by the sections that came or went since the last check, when
    nothing else can have changed the context (``None`` when something else may have)."""
    if not ctx.sources or ctx.sources != sources:
        return None
    touched: set[str] = set()
    for sec in (*went, *came):
        facts = local_facts(sec)
        if facts is None:
            return None
        touched.update(t.id for t in facts.trees)
        touched.update(m.id for m in facts.models)
        touched.update(m.id for m in facts.subtree_models)
    return touched


class _RecordingContext:
    """The context as the runs over sections see it: the same, except that its mappings
    note in ``keys`` what a run looks up (cleared before each run)."""

    __slots__ = ("count", "ctx", "keys", "tags")

    def __init__(self, ctx: Context) -> None:
        self.keys: Keys = tuple(set() for _ in _FIELDS)
        self.count = [0]  # lookups, for State.lookups
        self.tags: dict[int, TagFindings] = {}  # for State.shared_tags
        models, subtree_models, trees, workspace_trees = self.keys
        c = self.count
        self.ctx = dataclasses.replace(
            ctx,
            models=_Recording(ctx.models, models, c),
            subtree_models=_Recording(ctx.subtree_models, subtree_models, c),
            trees=_Recording(ctx.trees, trees, c),
            workspace_trees=_Recording(ctx.workspace_trees, workspace_trees, c),
        )


def _run(
    st: State,
    sec: Section,
    origin: int,
    root: Element | None,
    settings: tuple[object, ...],
    check: Callable[[State, Sequence[Element]], None],
    current: Current,
    lines: LineIndex,
    recording: _RecordingContext,
) -> _Entry:
    for keys in recording.keys:
        keys.clear()
    run = State(
        st.doc,
        recording.ctx,
        Model.of_section(sec, root),
        st.text[origin : origin + sec.length],
        v4=st.v4,
        v3=st.v3,
        origin=origin,
        made=st.made,
        shared_tags=recording.tags,
        lookups=recording.count,
    )
    check(run, sec.elements)  # the section's model's elements but its root
    line = lines.line_of(origin) if run.uses_lines else None
    out = capped(run.out, run.more)
    deps: list[object] = []
    for f, keys in enumerate(recording.keys):
        for key in keys:
            deps += (f, key, current(f, key))
    return _Entry(settings, line, tuple(deps), out, out.more)
