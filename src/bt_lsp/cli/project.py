"""What ``bt-lsp check`` knows of the project: its configuration files and command-line
flags layered into one workspace, their errors, and the version each file is checked as."""

from __future__ import annotations

import os
from collections import Counter
from collections.abc import Mapping, Sequence, Set
from pathlib import Path
from typing import Final, Protocol

from bt_lsp.project.config import MAX_DEPTH, ConfigError, Configs, Layer, excluded, find_config
from bt_lsp.project.cpp_scan import CPP_SUFFIXES
from bt_lsp.project.index import ProjectIndex, normalize
from bt_lsp.project.settings import Settings
from bt_lsp.project.sniff import is_bt_file
from bt_lsp.rules.codes import Severity

__all__ = [
    "NOT_BT",
    "WALK_SKIP_DIRS",
    "config_errors",
    "forced_skip_reason",
    "included_back",
    "project_index",
    "skip_reason",
    "version_lines",
    "workspace_lines",
    "workspace_of",
    "workspaces",
]

# Folders a walk never enters: colcon's build, install and log folders, version control,
# JavaScript dependencies.
WALK_SKIP_DIRS: Final = frozenset({"build", "install", "log", ".git", "node_modules"})
NOT_BT: Final = "not BehaviorTree.CPP XML"
EXCLUDED: Final = "excluded"
BUILD_FOLDER: Final = "build, install, log and VCS folders"
IN_SKIPPED_FOLDER: Final = "in build, install, log, VCS or hidden folders"
HIDDEN: Final = "hidden"


class ProjectOptions(Protocol):
    @property
    def config(self) -> str | None: ...
    @property
    def models(self) -> tuple[str, ...]: ...
    @property
    def btcpp(self) -> str | None: ...
    @property
    def severities(self) -> Mapping[str, Severity | None]: ...
    @property
    def max_bytes(self) -> int: ...
    @property
    def min_severity(self) -> Severity | None: ...


def workspace_of(path: str | os.PathLike[str]) -> tuple[Path, str]:
    """The workspace of a file named on the command line, and why: the nearest folder
    above it with a configuration file (``bt-lsp.toml``, or ``pyproject.toml`` with
    ``[tool.bt-lsp]``), else its repository's root (the nearest folder with ``.git``),
    else its ROS package's colcon ``src`` folder (the package folder's parent or
    grandparent named ``src``) or the package folder, else the file's folder.  The file is
    then checked among that folder's trees, catalogs and C++, as a run over the folder
    checks it."""
    folder = normalize(path).parent
    config = find_config(folder)
    if config is not None:
        return config.parent, f"the folder of {config.name}"
    package: Path | None = None
    f = folder
    for _ in range(MAX_DEPTH):
        if _exists(f / ".git"):
            return f, "the repository root"
        if package is None and _is_file(f / "package.xml"):
            package = f
        if f.parent == f:
            break
        f = f.parent
    if package is not None:
        for above in (package.parent, package.parent.parent):
            if above.name == "src":
                return above, "the ROS workspace's src folder"
        return package, "the ROS package"
    return folder, "the file's folder"


def _exists(path: Path) -> bool:
    try:
        return path.exists()
    except (OSError, ValueError):
        return False


def _is_file(path: Path) -> bool:
    try:
        return path.is_file()
    except (OSError, ValueError):
        return False


def _under(path: Path, folder: Path) -> bool:
    return path == folder or folder in path.parents


def workspaces(paths: Sequence[str]) -> dict[Path, tuple[str, list[str]]]:
    """The workspace folders of a run, each with why and the files named alone that it is
    the workspace of: every folder named on the command line (its own workspace, with the
    files named inside it), then the workspace of each other named file
    (:func:`workspace_of`)."""
    out: dict[Path, tuple[str, list[str]]] = {}
    for p in paths:
        if os.path.isdir(p):
            out.setdefault(normalize(p), ("named on the command line", []))
    named = list(out)
    for p in paths:
        if os.path.isdir(p):
            continue
        where = normalize(p)
        inside = next((d for d in named if _under(where, d)), None)
        if inside is not None:
            out[inside][1].append(p)
            continue
        folder, why = workspace_of(p)
        out.setdefault(folder, (why, []))[1].append(p)
    return out


def workspace_lines(paths: Sequence[str]) -> list[str]:
    """For ``--verbose``: the workspace each file named alone is checked in, and why."""
    return [
        f"bt-lsp: workspace {folder} ({why}) for {len(files)} named "
        f"file{'s' if len(files) != 1 else ''}"
        for folder, (why, files) in workspaces(paths).items()
        if files
    ]


def project_index(paths: Sequence[str], options: ProjectOptions) -> ProjectIndex:
    """The workspace of a run (:func:`workspaces`: the folders named on the command line,
    and those found for the files named alone), each file with its configuration file's
    settings and the flags over them."""
    overrides = Layer(
        models=tuple(normalize(m) for m in options.models) or None,
        btcpp=options.btcpp,
        severity=dict(options.severities) or None,
        min_severity=options.min_severity,
    )
    found = list(workspaces(paths))
    roots = [r for r in found if not any(o != r and _under(r, o) for o in found)]
    return ProjectIndex(
        roots,
        Settings(max_document_bytes=options.max_bytes),
        configs=Configs(normalize(options.config) if options.config else None),
        overrides=overrides,
        all_files=True,  # every file checked is read: its trees are known to the others
    )


def config_errors(workspace: ProjectIndex, files: Sequence[str]) -> list[ConfigError]:
    """The errors of the configuration files that the checked files use (and of the one
    given with ``--config``, which must hold settings)."""
    explicit = workspace.configs.explicit
    if explicit is not None and workspace.configs.load(explicit) is None:
        return [ConfigError(explicit, 1, 1, "has no [tool.bt-lsp] table")]
    for f in files:
        workspace.configs.for_path(normalize(f))
    return sorted(workspace.config_errors(), key=lambda e: str(e.path))


def version_lines(workspace: ProjectIndex, files: Sequence[str]) -> list[str]:
    """For ``--verbose``: which BehaviorTree.CPP version how many files are checked as,
    and why."""
    counts: Counter[tuple[str, str]] = Counter()
    for f in files:
        found = workspace.btcpp_for(normalize(f))
        if found.conflict:
            counts["version unclear", f"{found.source}; checked as version 4"] += 1
        elif found.version is None:
            counts["4", "not detected; checked as version 4"] += 1
        else:
            counts[found.version, found.source] += 1
    return [
        f"bt-lsp: BehaviorTree.CPP {version}: {n} file{'s' if n != 1 else ''} ({why})"
        for (version, why), n in sorted(counts.items())
    ]


def skip_reason(workspace: ProjectIndex, path: str, is_dir: bool) -> str | None:
    """Why a walk over a folder leaves ``path`` out (``None``: it is checked): a build or
    VCS folder, an ``exclude`` glob of its configuration, or a file whose content is not
    BehaviorTree.CPP XML (``package.xml``, launch files, URDF, other tools' XML; see
    :func:`bt_lsp.syntax.kind.looks_like_bt`)."""
    p = normalize(path)
    if is_dir:
        if p.name in WALK_SKIP_DIRS:
            return BUILD_FOLDER
        return EXCLUDED if excluded(p, workspace.settings_for(p / "-").exclude) else None
    if excluded(p, workspace.settings_for(p).exclude):
        return EXCLUDED
    return None if is_bt_file(p) else NOT_BT


def forced_skip_reason(workspace: ProjectIndex, path: str, root: Path) -> str | None:
    """``--force-exclude``: why a walk over ``root``, the workspace folder of ``path`` (a
    file named on the command line), would leave the file out (``None``: it would check
    it).  A folder on the way down from ``root`` that is hidden, a build or VCS folder or
    an ``exclude`` glob leaves it out, and so do a hidden name, the file's own ``exclude``
    glob and content that is not BehaviorTree.CPP XML (:func:`skip_reason`), so that
    ``check --force-exclude FILE...`` (what a pre-commit hook runs with the changed files)
    reports what ``check ROOT`` reports for them.  A C++ file is never sniffed."""
    p = normalize(path)
    parts = p.relative_to(root).parts if _under(p, root) else (p.name,)
    folder = root
    for name in parts[:-1]:
        folder = folder / name
        if name.startswith(".") or name in WALK_SKIP_DIRS:
            return IN_SKIPPED_FOLDER
        if skip_reason(workspace, str(folder), True) is not None:
            return EXCLUDED
    if p.name.startswith("."):
        return HIDDEN
    if p.suffix in CPP_SUFFIXES:
        return EXCLUDED if excluded(p, workspace.settings_for(p).exclude) else None
    return skip_reason(workspace, str(p), False)


def included_back(workspace: ProjectIndex, files: Sequence[str], not_bt: Set[str]) -> set[str]:
    """The files of ``not_bt`` (skipped for their content) that one of the other
    ``files`` includes, directly or through others: BehaviorTree.CPP loads them as BT
    XML, so they are checked as such."""
    if not not_bt:
        return set()
    by_path = {normalize(f): f for f in not_bt}
    out: set[str] = set()
    for f in files:
        if not f.endswith(".xml") or normalize(f) in by_path:
            continue
        for p in workspace.includes.closure(normalize(f)):
            hit = by_path.get(p)
            if hit is not None:
                out.add(hit)
    return out
