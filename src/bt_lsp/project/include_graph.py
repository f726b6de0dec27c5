"""Who includes whom: each document's ``<include path>`` resolved the way
BehaviorTree.CPP does (relative to the including file; ``ros_pkg`` through the
``rosPackages`` setting, then the workspace's and the installed ROS packages), the files
each one reaches, and the include rules that need the other files (not found, cycles)."""

from __future__ import annotations

import os
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from pathlib import Path

from bt_lsp.ide.places import IncludeLink
from bt_lsp.project.documents import Documents
from bt_lsp.project.package_scope import PackageScope
from bt_lsp.project.paths import normalize
from bt_lsp.project.settings import Settings
from bt_lsp.project.settings_index import SettingsIndex
from bt_lsp.rules.diagnostics import Diagnostic, make
from bt_lsp.rules.includes import (
    INCLUDE_CYCLE,
    INCLUDE_NOT_FOUND,
    cycle,
    includes_itself,
    not_found,
)
from bt_lsp.syntax.document import Document
from bt_lsp.syntax.model import Model

MAX_INCLUDE_FILES = 1000


@dataclass(frozen=True, slots=True)
class Include:
    """One ``<include>`` of a document: the span of its ``path`` value and where it leads."""

    start: int
    end: int
    written: str
    target: Path | None  # None when it cannot be resolved (no path, unknown ros_pkg)
    ros_pkg: str | None


def links(includes: Iterable[Include]) -> list[IncludeLink]:
    """The resolved includes as the editing layer takes them (spans and target paths)."""
    return [IncludeLink(i.start, i.end, str(i.target)) for i in includes if i.target is not None]


def includes_of(
    path: Path,
    doc: Document,
    settings: Settings,
    package: Callable[[str], Path | None] | None = None,
) -> list[Include]:
    """The includes of ``doc``; ``ros_pkg`` resolves through the settings, else through
    ``package`` (the workspace's and the installed ROS packages)."""
    out: list[Include] = []
    for el in doc.model.root_children_named(("include",)):  # the INCLUDE zone
        a = el.attr("path")
        if a is None or a.value is None or not a.value.strip():
            continue  # include-missing-path is a semantic rule of the document itself
        start, end = el.span_of_value(a)
        written = a.value.strip()
        pkg = el.value("ros_pkg")
        target: Path | None
        if os.path.isabs(written):
            target = normalize(written)
        elif pkg:
            base: str | Path | None = settings.ros_packages.get(pkg)
            if base is None and package is not None:
                base = package(pkg)
            target = normalize(Path(base) / written) if base else None
        else:
            target = normalize(path.parent / written)
        out.append(Include(start, end, written, target, pkg or None))
    return out


class IncludeGraph:
    """The includes of the project's documents, resolved, and the paths through them."""

    def __init__(self, documents: Documents, settings: SettingsIndex, scope: PackageScope) -> None:
        self._documents = documents
        self._settings = settings
        self._scope = scope
        # Path -> (the model and settings they were read with, the includes).
        self._includes: dict[Path, tuple[Model, Settings, list[Include]]] = {}

    def of(self, path: Path, doc: Document | None = None) -> list[Include]:
        """The includes of the document at ``path`` (``doc``, else the one open or on disk)."""
        doc = doc if doc is not None else self._documents.document(path)
        if doc is None:
            return []
        # Kept per path while the document's model and the settings are the same (every
        # document's includes are looked at for every other one).
        model = doc.model
        settings = self._settings.for_path(path)
        hit = self._includes.get(path)
        if hit is not None and hit[0] is model and hit[1] is settings:
            return hit[2]
        found = includes_of(
            path, doc, settings, lambda name: self._scope.ros_package(name, settings)
        )
        self._includes[path] = (model, settings, found)
        return found

    def closure(self, path: Path, doc: Document | None = None) -> list[Path]:
        """Files reachable through includes from ``path`` (not ``path`` itself), in
        depth-first order; iterative and bounded, cycles are cut."""
        seen = {path}
        order: list[Path] = []
        stack: list[Path] = [
            inc.target for inc in reversed(self.of(path, doc)) if inc.target is not None
        ]
        while stack and len(order) < MAX_INCLUDE_FILES:
            p = stack.pop()
            if p in seen:
                continue
            seen.add(p)
            order.append(p)
            for inc in reversed(self.of(p)):
                if inc.target is not None and inc.target not in seen:
                    stack.append(inc.target)
        return order

    def _reaches(self, start: Path, goal: Path) -> list[Path] | None:
        """A chain of includes from ``start`` to ``goal`` (both included), or None."""
        parent: dict[Path, Path | None] = {start: None}
        stack = [start]
        while stack and len(parent) < MAX_INCLUDE_FILES:
            p = stack.pop()
            if p == goal:
                chain = [p]
                while parent[chain[-1]] is not None:
                    prev = parent[chain[-1]]
                    assert prev is not None
                    chain.append(prev)
                return chain[::-1]
            for inc in self.of(p):
                t = inc.target
                if t is not None and t not in parent:
                    parent[t] = p
                    stack.append(t)
        return None

    def diagnostics(self, path: Path, doc: Document) -> list[Diagnostic]:
        """``include-not-found`` and ``include-cycle`` for the includes of one document."""
        out: list[Diagnostic] = []
        for inc in self.of(path, doc):
            if inc.target is None:
                continue  # no path / unmapped ros_pkg: the document's own rules say so
            if inc.target == path:
                out.append(
                    make(inc.start, inc.end, INCLUDE_CYCLE.code, includes_itself(inc.written))
                )
                continue
            if self._documents.document(inc.target) is None:
                why = self._documents.read_error(inc.target) or "cannot be read"
                out.append(
                    make(
                        inc.start,
                        inc.end,
                        INCLUDE_NOT_FOUND.code,
                        not_found(inc.written, str(inc.target), why),
                    )
                )
                continue
            chain = self._reaches(inc.target, path)
            if chain is not None:
                names = " → ".join(_short(p, path) for p in [path, *chain])
                out.append(make(inc.start, inc.end, INCLUDE_CYCLE.code, cycle(names)))
        return out

    def dependents(self, path: Path) -> list[Path]:
        """Open documents whose include closure contains ``path``."""
        return [p for p in self._documents.open_paths() if p != path and path in self.closure(p)]


def _short(p: Path, base: Path) -> str:
    try:
        return os.path.relpath(p, base.parent)
    except ValueError:
        return str(p)
