"""What ``bt-lsp check`` knows of the project: its configuration files and command-line
flags layered into one workspace, their errors, and the version each file is checked as."""

from __future__ import annotations

import os
from collections import Counter
from collections.abc import Mapping, Sequence
from typing import Final, Protocol

from bt_lsp.project.config import ConfigError, Configs, Layer, excluded
from bt_lsp.project.index import ProjectIndex, normalize
from bt_lsp.project.settings import Settings
from bt_lsp.project.sniff import is_bt_file
from bt_lsp.rules.codes import Severity

__all__ = [
    "NOT_BT",
    "WALK_SKIP_DIRS",
    "config_errors",
    "project_index",
    "skip_reason",
    "version_lines",
]

# Folders a walk never enters: colcon's build, install and log folders, version control,
# JavaScript dependencies.
WALK_SKIP_DIRS: Final = frozenset({"build", "install", "log", ".git", "node_modules"})
NOT_BT: Final = "not BehaviorTree.CPP XML"
EXCLUDED: Final = "excluded"
BUILD_FOLDER: Final = "build, install, log and VCS folders"


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


def project_index(paths: Sequence[str], options: ProjectOptions) -> ProjectIndex:
    """The folders named on the command line as one workspace, each file with its
    configuration file's settings and the flags over them."""
    overrides = Layer(
        models=tuple(normalize(m) for m in options.models) or None,
        btcpp=options.btcpp,
        severity=dict(options.severities) or None,
    )
    return ProjectIndex(
        [p for p in paths if os.path.isdir(p)],
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
        if found.version is None:
            counts["4", "not detected; checked as version 4"] += 1
        else:
            counts[found.version, found.source] += 1
    return [
        f"bt-lsp: BehaviorTree.CPP {version}: {n} file{'s' if n != 1 else ''} ({why})"
        for (version, why), n in sorted(counts.items())
    ]


def skip_reason(workspace: ProjectIndex, path: str, is_dir: bool) -> str | None:
    """Why a walk over a folder leaves ``path`` out (``None``: it is checked): a build or
    VCS folder, an ``exclude`` glob of its configuration, or a file whose top element is
    not ``<root>`` (``package.xml``, launch files, URDF, pluginlib descriptions)."""
    p = normalize(path)
    if is_dir:
        if p.name in WALK_SKIP_DIRS:
            return BUILD_FOLDER
        return EXCLUDED if excluded(p, workspace.settings_for(p / "-").exclude) else None
    if excluded(p, workspace.settings_for(p).exclude):
        return EXCLUDED
    return None if is_bt_file(p) else NOT_BT
