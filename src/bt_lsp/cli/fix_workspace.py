"""``bt-lsp check --fix`` over a workspace: every rename applied in all its files or none.

A rename of a tree defined in one file and called in others changes several files.  Fixed
one file at a time, a file whose fixes are refused (an XML error the fixer will not touch,
a lossy encoding, a symbolic link to outside the folder, a failed write) would keep the
old name while the others take the new one, and the reference would break.  So the fixes
of the whole workspace are planned at once (:func:`bt_lsp.ide.name_fixes.fix_workspace`:
one new name per symbol, the same in every file), each rename carries its edits in all the
files it touches, and a rename is applied only if every one of those files can be fixed
and written; otherwise it is left out everywhere, with a note saying why.  The files that
a set of renames links are written together: when one write fails, the others are put
back as they were.

The fixes of the other rules change one file each (:func:`bt_lsp.ide.fix_all.rule_fixes`:
the safe ones, with ``--unsafe-fixes`` the unsafe ones too); they give way to the renames:
when a file cannot be fixed with them, it is fixed without them, with a note.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

from bt_lsp.cli.fix import Fixed, apply_fixes, context_of
from bt_lsp.cli.results import file_diagnostics
from bt_lsp.ide.fix_all import rule_fixes
from bt_lsp.ide.name_edits import shown
from bt_lsp.ide.name_fixes import WorkspaceRename, edits_in, fix_workspace
from bt_lsp.project.cpp_scan import CPP_SUFFIXES
from bt_lsp.project.fileio import Decoded, FileError, read_text, write_text_atomic
from bt_lsp.project.index import ProjectIndex, normalize
from bt_lsp.rules.codes import Severity
from bt_lsp.rules.diagnostics import Diagnostic, with_severities
from bt_lsp.syntax.document import Document
from bt_lsp.syntax.edits import TextEdit

__all__ = ["Planned", "edits_in", "fix_files"]


@dataclass(slots=True)
class Planned:
    """What ``--fix`` did to one checked file: ``outcome`` is the fixed document (written),
    why it was left as it was, or ``None`` (nothing to fix); ``unwritten``: the write
    failed.  ``notes`` say what the fixes left as it is."""

    decoded: Decoded
    doc: Document
    raw: list[Diagnostic]
    diags: list[Diagnostic]
    severities: Mapping[str, Severity | None]
    outcome: Fixed | str | None = None
    unwritten: bool = False
    notes: list[str] = field(default_factory=list)


def _severities(project: ProjectIndex, path: str) -> Mapping[str, Severity | None]:
    return project.settings_for(normalize(path)).severity


def _read(
    paths: Sequence[str], project: ProjectIndex, max_bytes: int
) -> dict[str, tuple[str, Planned]]:
    """The checked XML files that can be read, by normalized path: (path as given, plan)."""
    out: dict[str, tuple[str, Planned]] = {}
    for path in paths:
        if Path(path).suffix in CPP_SUFFIXES:
            continue
        try:
            decoded = read_text(path, max_bytes)
        except FileError:
            continue  # reported when the file is checked
        doc = Document(decoded.text, path)
        raw = file_diagnostics(doc, project)
        severities = _severities(project, path)
        diags = with_severities(raw, severities)
        planned = Planned(decoded, doc, raw, diags, severities)
        out.setdefault(str(normalize(path)), (path, planned))
    return out


def _components(renames: Sequence[WorkspaceRename]) -> list[list[str]]:
    """The groups of files that the renames link (each group written together)."""
    parent: dict[str, str] = {}

    def find(p: str) -> str:
        while parent.setdefault(p, p) != p:
            parent[p] = parent[parent[p]]
            p = parent[p]
        return p

    for r in renames:
        first, *rest = sorted(r.paths)
        find(first)
        for p in rest:
            parent[find(p)] = find(first)
    groups: dict[str, list[str]] = {}
    for p in sorted(parent):
        groups.setdefault(find(p), []).append(p)
    return list(groups.values())


def _name(checked: Mapping[str, tuple[str, Planned]], path: str) -> str:
    """A file as the command line names it."""
    return checked[path][0] if path in checked else path


def _left_out(r: WorkspaceRename, why: str) -> str:
    old, new = shown(r.renaming.old), shown(r.renaming.new)
    return f"left '{old}' as it is (not renamed to '{new}' in any file): {why}"


def fix_files(
    paths: Sequence[str],
    project: ProjectIndex,
    max_bytes: int,
    keep: Callable[[str], str | None],
    unsafe: bool = False,
) -> dict[str, Planned]:
    """Fix the checked files ``paths`` of ``project``'s workspace (see the module), by
    normalized path.  ``keep`` says why a file must not be rewritten (``None``: it may);
    ``unsafe``: apply the unsafe fixes too."""
    checked = _read(paths, project, max_bytes)
    docs: dict[str, Document] = {k: p.doc for k, (_, p) in checked.items()}
    # A workspace file that a checked one reaches through a symbolic link is that file.
    real = {os.path.realpath(given) for given, _ in checked.values()}
    for at, d in project.bt_documents():
        if os.path.realpath(at) not in real:
            docs.setdefault(str(at), d)
    registered = {k: project.context_for(Path(k), d).models for k, d in docs.items()}
    plan = fix_workspace(docs, {k: p.diags for k, (_, p) in checked.items()}, registered)
    for k, (_, item) in checked.items():
        item.notes.extend(plan.notes.get(k, ()))
    alive = list(plan.renames)
    refused: dict[str, str] = {}
    fixed: dict[str, Fixed] = {}
    # The files whose other fixes were given up, so that their renames could be made.
    without_local: set[str] = set()
    may_fix_locally = {
        k for k, (given, p) in checked.items() if any(not d.is_name_rule for d in p.diags)
    }
    while True:
        fixed.clear()
        touched = sorted({p for r in alive for p in r.paths} | (may_fix_locally - without_local))
        newly: dict[str, str] = {}
        for path in touched:
            if path in refused:
                continue
            if path not in checked:
                newly[path] = "it is not among the checked files"
                continue
            given, planned = checked[path]
            mine = [r for r in alive if path in r.paths]
            renames = edits_in(mine, path)
            local: list[TextEdit] = []
            if path not in without_local:
                ctx = context_of(planned.doc, project)
                fixes = rule_fixes(planned.doc, ctx, planned.diags, unsafe=unsafe, taken=renames)
                local = [e for f in fixes for e in f.edits]
            if not renames and not local:
                continue
            why = keep(given)
            if why is not None:
                newly[path] = why
                continue
            outcome = apply_fixes(
                planned.decoded, planned.doc, planned.raw, [*renames, *local], [], project
            )
            if isinstance(outcome, str) and local and renames:
                # The renames first: they change other files too.
                planned.notes.append(f"left the fixes of other problems as they are: {outcome}")
                without_local.add(path)
                outcome = apply_fixes(
                    planned.decoded, planned.doc, planned.raw, renames, [], project
                )
            if isinstance(outcome, str):
                newly[path] = outcome
            elif outcome is not None:
                fixed[path] = outcome
        if not newly:
            break
        refused.update(newly)
        kept: list[WorkspaceRename] = []
        for r in alive:
            bad = sorted(p for p in r.paths if p in refused)
            if not bad:
                kept.append(r)
                continue
            why = f"its rename changes {_name(checked, bad[0])} too, which is not fixed: "
            why += refused[bad[0]]
            for p in sorted(r.paths):
                if p in checked and p not in bad:
                    checked[p][1].notes.append(_left_out(r, why))
        alive = kept
    for path, why in refused.items():
        if path in checked:
            checked[path][1].outcome = why
    groups = _components(alive)
    linked = {p for g in groups for p in g}
    groups += [[p] for p in sorted(fixed) if p not in linked]  # other fixes only
    _write(checked, fixed, groups, project)
    return {k: p for k, (_, p) in checked.items()}


def _write(
    checked: Mapping[str, tuple[str, Planned]],
    fixed: Mapping[str, Fixed],
    groups: Sequence[Sequence[str]],
    project: ProjectIndex,
) -> None:
    """Write each group of linked files together: when a write fails, the files of its
    group already written are put back as they were, and none of the group is fixed."""
    for group in groups:
        written: list[str] = []
        failed: tuple[str, str] | None = None
        for path in group:
            if path not in fixed:
                continue
            given, planned = checked[path]
            d = planned.decoded
            try:
                write_text_atomic(given, fixed[path].doc.text, d.encoding, d.bom, expect=d.stamp)
            except FileError as e:
                failed = (path, e.message)
                break
            written.append(path)
        if failed is not None:
            for path in written:
                given, planned = checked[path]
                d = planned.decoded
                try:
                    write_text_atomic(given, d.text, d.encoding, d.bom)
                except FileError as e:  # pragma: no cover - the file was just written
                    checked[path][1].notes.append(f"could not be put back: {e.message}")
            bad, message = failed
            checked[bad][1].outcome = message
            checked[bad][1].unwritten = True
            for path in group:
                if path != bad and path in fixed:
                    checked[path][1].outcome = (
                        f"its renames change {checked[bad][0]} too, which could not be "
                        f"written: {message}"
                    )
            continue
        for path in written:
            checked[path][1].outcome = fixed[path]
            project.file_changed(checked[path][0])
    # What the written files report now, with every file of their renames updated.
    for path in fixed:
        given, planned = checked[path]
        outcome = planned.outcome
        if isinstance(outcome, Fixed):
            raw = file_diagnostics(outcome.doc, project)
            planned.outcome = Fixed(outcome.doc, raw, [])
