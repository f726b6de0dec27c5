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
import weakref
from collections.abc import Callable, Iterator, Mapping, Sequence
from typing import TYPE_CHECKING, Final, TypeVar

from bt_lsp.rules.context import Context, DocumentFacts, ModelDecl, TreeDecl
from bt_lsp.rules.diagnostics import Diagnostic, capped
from bt_lsp.rules.semantics.base import State
from bt_lsp.syntax.elements import Element
from bt_lsp.syntax.model import Model
from bt_lsp.syntax.sections import Section

if TYPE_CHECKING:
    from bt_lsp.syntax.document import History
    from bt_lsp.syntax.text import LineIndex

__all__ = ["check_sections"]

V = TypeVar("V")
# A context lookup: (field, key); key None stands for the whole mapping (iterated).
Dep = tuple[str, str | None]

_FIELDS: Final = ("models", "subtree_models", "trees", "workspace_trees")
_KEY: Final = "semantics"


class _Recording(Mapping[str, V]):
    """A mapping of the context that notes which keys a rule looked up."""

    __slots__ = ("_deps", "_field", "_inner")

    def __init__(self, inner: Mapping[str, V], field: str, deps: set[Dep]) -> None:
        self._inner = inner
        self._field = field
        self._deps = deps

    def __getitem__(self, key: str) -> V:
        self._deps.add((self._field, key))
        return self._inner[key]

    def __contains__(self, key: object) -> bool:
        if isinstance(key, str):
            self._deps.add((self._field, key))
        return key in self._inner

    def __iter__(self) -> Iterator[str]:
        self._deps.add((self._field, None))
        return iter(self._inner)

    def __len__(self) -> int:
        self._deps.add((self._field, None))
        return len(self._inner)


def _content(value: ModelDecl | tuple[TreeDecl, ...]) -> object:
    """A context entry without positions."""
    if isinstance(value, ModelDecl):
        return (value.id, value.category, value.ports, value.path)
    return tuple((d.id, d.path, d.calls) for d in value)


def _signature(ctx: Context, dep: Dep) -> object:
    field, key = dep
    mapping: Mapping[str, ModelDecl | tuple[TreeDecl, ...]] = getattr(ctx, field)
    if key is None:
        return tuple((k, _content(v)) for k, v in mapping.items())
    value = mapping.get(key)
    return None if value is None else _content(value)


@dataclasses.dataclass(slots=True)
class _Entry:
    """The results of one section and what they depend on."""

    settings: tuple[object, ...]
    line: int | None  # the line the section starts on, when a message names a line
    deps: dict[Dep, object]  # the signature of each context entry looked up
    out: list[Diagnostic]  # the first MAX_DIAGNOSTICS by position
    more: int = 0  # how many more were found


@dataclasses.dataclass(slots=True)
class _History:
    """The last check of a document: the settings, the signature of every context entry
    looked up by its sections (so that the next check compares each entry once), what
    the context was combined from besides the document itself, and its sections (all of
    them valid then), with those that have diagnostics and those that name lines."""

    settings: tuple[object, ...] = ()
    sigs: dict[Dep, object] = dataclasses.field(default_factory=dict)
    sources: tuple[object, ...] = ()
    valid: set[Section] | None = None
    with_diagnostics: set[Section] = dataclasses.field(default_factory=set)
    lines: set[Section] = dataclasses.field(default_factory=set)


_HISTORY: weakref.WeakKeyDictionary[History, _History] = weakref.WeakKeyDictionary()


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
    memo: dict[Dep, object] = {}

    def current(dep: Dep) -> object:
        try:
            return memo[dep]
        except KeyError:
            sig = memo[dep] = _signature(ctx, dep)
            return sig

    hist = _HISTORY.get(st.doc.history)
    if hist is None:
        hist = _HISTORY[st.doc.history] = _History()
    sections, origins = model.sections, model.origins
    now = set(sections)
    same = hist.valid is not None and hist.settings == settings
    # The context entries that changed since the last check: a section that was valid
    # then is valid now unless it looked one of them up.
    touched = _touched(hist.valid, now, hist.sources, ctx) if same else None
    if touched is None:
        changed = {d for d, sig in hist.sigs.items() if current(d) != sig}
    else:
        changed = set()
        sigs = hist.sigs
        candidates: list[Dep] = [(f, key) for key in touched for f in _FIELDS]
        if touched:
            candidates.extend((f, None) for f in _FIELDS)
        for d in candidates:
            if d in sigs and current(d) != sigs[d]:
                changed.add(d)
    lines = st.doc.lines
    index: dict[Section, int] | None = None
    todo: list[Section] = []

    def keep(sec: Section, found: _Entry) -> None:
        """``sec``'s results are valid: file it under what the next check looks at."""
        valid.add(sec)
        if found.out:
            with_diagnostics.add(sec)
        if found.line is not None:
            line_dependent.add(sec)

    if same and not changed:
        assert hist.valid is not None
        valid = hist.valid & now
        todo.extend(now - valid)
        with_diagnostics = hist.with_diagnostics & valid
        line_dependent = hist.lines & valid
        if line_dependent:
            index = dict(zip(sections, range(len(sections)), strict=True))
            for sec in list(line_dependent):
                entry: _Entry = sec.cache[_KEY]
                if entry.line != lines.line_of(origins[index[sec]]):
                    valid.discard(sec)
                    with_diagnostics.discard(sec)
                    line_dependent.discard(sec)
                    todo.append(sec)
    else:
        trusted = hist.valid if same and hist.valid is not None else set()
        valid, with_diagnostics, line_dependent = set(), set(), set()
        for sec, origin in zip(sections, origins, strict=True):
            found: _Entry | None = sec.cache.get(_KEY)
            if found is not None and sec in trusted:
                ok = (
                    found.line is None or found.line == lines.line_of(origin)
                ) and changed.isdisjoint(found.deps)
            else:
                ok = _still_valid(found, settings, lines, origin, current)
            if ok:
                assert found is not None
                keep(sec, found)
            else:
                todo.append(sec)
    if todo:
        if index is None:
            index = dict(zip(sections, range(len(sections)), strict=True))
        recording = _RecordingContext(ctx)
        for sec in todo:
            origin = origins[index[sec]]
            found = sec.cache.get(_KEY)
            if not _still_valid(found, settings, lines, origin, current):
                found = _run(st, sec, origin, root, settings, check, current, lines, recording)
                sec.cache[_KEY] = found
            assert found is not None
            keep(sec, found)
    if with_diagnostics:
        if index is None:
            index = dict(zip(sections, range(len(sections)), strict=True))
        out = st.out
        for sec in with_diagnostics:
            origin = origins[index[sec]]
            entry = sec.cache[_KEY]
            st.more += entry.more
            out.extend(
                Diagnostic(d.start + origin, d.end + origin, d.code, d.message, d.severity, d.data)
                for d in entry.out
            )
    hist.settings = settings
    hist.sigs.update(memo)
    hist.sources = ctx.sources
    hist.valid, hist.with_diagnostics, hist.lines = valid, with_diagnostics, line_dependent


def _still_valid(
    entry: _Entry | None,
    settings: tuple[object, ...],
    lines: LineIndex,
    origin: int,
    current: Callable[[Dep], object],
) -> bool:
    """Whether remembered results hold, every context entry they read compared."""
    return (
        entry is not None
        and entry.settings == settings
        and (entry.line is None or entry.line == lines.line_of(origin))
        and all(current(d) == sig for d, sig in entry.deps.items())
    )


def _touched(
    before: set[Section] | None, now: set[Section], sources: tuple[object, ...], ctx: Context
) -> set[str] | None:
    """The names declared by the sections that came or went since the last check, when
    nothing else can have changed the context (``None`` when something else may have)."""
    if before is None or not ctx.sources or ctx.sources != sources:
        return None
    touched: set[str] = set()
    for sec in now.symmetric_difference(before):
        facts: DocumentFacts | None = sec.cache.get("facts")
        if facts is None:
            return None
        touched.update(t.id for t in facts.trees)
        touched.update(m.id for m in facts.models)
        touched.update(m.id for m in facts.subtree_models)
    return touched


class _RecordingContext:
    """The context as the runs over sections see it: the same, except that its mappings
    note in ``deps`` what a run looks up (cleared before each run)."""

    __slots__ = ("ctx", "deps")

    def __init__(self, ctx: Context) -> None:
        self.deps: set[Dep] = set()
        self.ctx = dataclasses.replace(
            ctx,
            models=_Recording(ctx.models, "models", self.deps),
            subtree_models=_Recording(ctx.subtree_models, "subtree_models", self.deps),
            trees=_Recording(ctx.trees, "trees", self.deps),
            workspace_trees=_Recording(ctx.workspace_trees, "workspace_trees", self.deps),
        )


def _run(
    st: State,
    sec: Section,
    origin: int,
    root: Element | None,
    settings: tuple[object, ...],
    check: Callable[[State, Sequence[Element]], None],
    current: Callable[[Dep], object],
    lines: LineIndex,
    recording: _RecordingContext,
) -> _Entry:
    deps = recording.deps
    deps.clear()
    local = Model.of_section(sec, root)
    run = State(
        st.doc,
        recording.ctx,
        local,
        st.text[origin : origin + sec.length],
        v4=st.v4,
        v3=st.v3,
        origin=origin,
        made=st.made,
    )
    elements = local.elements
    check(run, elements[1:])  # a view of the section's elements, not a copy
    line = lines.line_of(origin) if run.uses_lines else None
    out = capped(run.out, run.more)
    return _Entry(settings, line, {d: current(d) for d in deps}, out, out.more)
