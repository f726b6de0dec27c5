"""User settings (the ``btLsp`` section), parsed leniently: a bad value is ignored and
reported, never fatal."""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Final, Protocol, TypeVar

from bt_lsp.project.fileio import DEFAULT_MAX_BYTES
from bt_lsp.rules.codes import Severity
from bt_lsp.rules.registry import CODES

# The same limit as the command line's (see fileio.DEFAULT_MAX_BYTES).
DEFAULT_MAX_DOCUMENT_BYTES: Final = DEFAULT_MAX_BYTES
MAX_DEBOUNCE_MS = 60_000
# What ``btcpp`` may be: detect the version, or BehaviorTree.CPP 3.x / 4.x.
BTCPP_CHOICES: Final = ("auto", "3", "4")


@dataclass(frozen=True)
class Settings:
    debounce_ms: int = 200
    severity: Mapping[str, Severity | None] = field(default_factory=dict)
    # Above this size (UTF-8 bytes) only the lexical and name checks run.
    max_document_bytes: int = DEFAULT_MAX_DOCUMENT_BYTES
    # ROS package name -> folder, for <include ros_pkg="...">.
    ros_packages: Mapping[str, str] = field(default_factory=dict)
    # Node catalogs: generated TreeNodesModel XML files, Groot2 .btproj files (the
    # ``modelFiles`` setting, the ``models`` key of bt-lsp.toml, ``check --models``). A
    # relative path is relative to the first workspace folder.
    models: tuple[Path, ...] = ()
    # The project's BehaviorTree.CPP major version: "auto" (detected per file), "3" or "4".
    btcpp: str = "auto"
    # Globs (relative to the configuration file's folder) of files and folders to skip.
    exclude: tuple[str, ...] = ()
    # Globs of the project's C++ sources (read by the C++ catalog reader).
    sources: tuple[str, ...] = ()
    # The least severe diagnostics shown (published, printed): less severe ones are not.
    min_severity: Severity = Severity.HINT

    @classmethod
    def parse(cls, raw: Any, problems: list[str] | None = None) -> Settings:
        """Settings from the client's JSON (``btLsp`` section or initializationOptions)."""
        problems = problems if problems is not None else []
        if not isinstance(raw, Mapping):
            if raw is not None:
                problems.append("btLsp settings must be an object")
            return cls()
        section: Mapping[str, Any] = raw
        if isinstance(section.get("btLsp"), Mapping):
            section = section["btLsp"]
        raw = section
        kw: dict[str, Any] = {}
        debounce = raw.get("debounceMs")
        if debounce is not None:
            if (
                isinstance(debounce, int | float)
                and not isinstance(debounce, bool)
                and 0 <= debounce <= MAX_DEBOUNCE_MS  # also rejects NaN and infinity
            ):
                kw["debounce_ms"] = int(debounce)
            else:
                problems.append(
                    f"debounceMs must be a number from 0 to {MAX_DEBOUNCE_MS}, not {debounce!r}"
                )
        sev = raw.get("severity")
        if isinstance(sev, Mapping):
            parsed: dict[str, Severity | None] = {}
            for code, word in sev.items():
                if code not in CODES:
                    problems.append(f"severity: unknown code {code!r}")
                    continue
                try:
                    parsed[code] = Severity.parse(str(word))
                except ValueError:
                    problems.append(f"severity: {word!r} for {code} is not a severity")
            kw["severity"] = parsed
        elif sev is not None:
            problems.append("severity must be an object of code -> level")
        size = raw.get("maxDocumentBytes")
        if isinstance(size, int) and not isinstance(size, bool) and size > 0:
            kw["max_document_bytes"] = size
        ros = raw.get("rosPackages")
        if isinstance(ros, Mapping):
            kw["ros_packages"] = {str(k): str(v) for k, v in ros.items()}
        models = raw.get("modelFiles")
        if isinstance(models, list):
            kw["models"] = tuple(Path(str(m)) for m in models)
        btcpp = raw.get("btcpp")
        if btcpp is not None:
            if str(btcpp) in BTCPP_CHOICES:
                kw["btcpp"] = str(btcpp)
            else:
                problems.append(f"btcpp must be one of {', '.join(BTCPP_CHOICES)}, not {btcpp!r}")
        minimum = raw.get("minSeverity")
        if minimum is not None:
            found = _min_severity(minimum)
            if found is None:
                problems.append(
                    f"minSeverity must be one of error, warning, information, hint, not {minimum!r}"
                )
            else:
                kw["min_severity"] = found
        return cls(**kw)


def _min_severity(word: object) -> Severity | None:
    """A ``minSeverity`` value: a severity word (``None`` if it is not one; ``off`` is
    not one here)."""
    if not isinstance(word, str):
        return None
    try:
        return Severity.parse(word)
    except ValueError:
        return None


def shown(diags: Iterable[D], minimum: Severity) -> list[D]:
    """The diagnostics at least as severe as ``minimum`` (the ``min-severity`` setting)."""
    if minimum == Severity.HINT:
        return list(diags)
    return [d for d in diags if d.severity <= minimum]


class _HasSeverity(Protocol):
    @property
    def severity(self) -> Severity: ...


D = TypeVar("D", bound=_HasSeverity)
