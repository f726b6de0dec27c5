"""The project's configuration file, read by both ``bt-lsp check`` and the server.

It is ``bt-lsp.toml``, or the ``[tool.bt-lsp]`` table of a ``pyproject.toml``, found by
looking upward from the checked file (or the workspace folder): the nearest folder that
holds either wins, ``bt-lsp.toml`` first.  Paths in it are relative to its folder.

A file that cannot be used (a TOML syntax error, an unknown key, a value of the wrong
type) raises :class:`ConfigError` with the line and column of the first problem: one clear
error, never a half-applied configuration.
"""

from __future__ import annotations

import os
import re
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any, Final

from bt_lsp.project.fileio import FileError, read_head
from bt_lsp.project.schema import FILE_KEYS
from bt_lsp.project.settings import BTCPP_CHOICES, Settings
from bt_lsp.rules.codes import Severity
from bt_lsp.rules.registry import CODES

__all__ = [
    "CONFIG_FILE",
    "CONFIG_NAMES",
    "Config",
    "ConfigError",
    "Configs",
    "Layer",
    "find_config",
    "load_config",
]

CONFIG_FILE: Final = "bt-lsp.toml"
PYPROJECT: Final = "pyproject.toml"
CONFIG_NAMES: Final = (CONFIG_FILE, PYPROJECT)
MAX_CONFIG_BYTES: Final = 1024 * 1024
# How far upward a configuration is looked for (folders).
MAX_DEPTH: Final = 64

# What ``min-severity`` may be.
MIN_SEVERITIES: Final = ("error", "warning", "information", "hint")
# The keys, as the configuration reference documents them (bt_lsp.project.schema).
KEYS: Final = FILE_KEYS


class ConfigError(Exception):
    """A configuration file that cannot be used: where (1-based line and column) and why."""

    def __init__(self, path: Path, line: int, column: int, message: str) -> None:
        super().__init__(f"{path}:{line}:{column}: {message}")
        self.path = path
        self.line = line
        self.column = column
        self.message = message

    def span(self, text: str) -> tuple[int, int, int]:
        """Where the error shows in the file's ``text``: its 0-based line and the columns
        (code points) from the error to the end of that line, at least one character when
        the line has one."""
        lines = [line.removesuffix("\r") for line in text.split("\n")]  # as TOML counts
        row = min(max(self.line - 1, 0), len(lines) - 1)
        length = len(lines[row])
        start = min(max(self.column - 1, 0), length)
        if start == length and start > 0:
            start -= 1
        return row, start, length


@dataclass(frozen=True, slots=True)
class Layer:
    """Settings given by one source (a configuration file, command-line flags); ``None``
    is "not given here", so the layer below decides."""

    models: tuple[Path, ...] | None = None
    btcpp: str | None = None
    severity: Mapping[str, Severity | None] | None = None
    exclude: tuple[str, ...] | None = None
    ros_packages: Mapping[str, str] | None = None
    sources: tuple[str, ...] | None = None
    min_severity: Severity | None = None

    def over(self, base: Settings) -> Settings:
        """``base`` with what this layer gives; severities are merged code by code."""
        kw: dict[str, Any] = {}
        if self.models is not None:
            kw["models"] = self.models
        if self.btcpp is not None:
            kw["btcpp"] = self.btcpp
        if self.severity is not None:
            kw["severity"] = {**base.severity, **self.severity}
        if self.exclude is not None:
            kw["exclude"] = self.exclude
        if self.ros_packages is not None:
            kw["ros_packages"] = {**base.ros_packages, **self.ros_packages}
        if self.sources is not None:
            kw["sources"] = self.sources
        if self.min_severity is not None:
            kw["min_severity"] = self.min_severity
        return replace(base, **kw) if kw else base


@dataclass(frozen=True, slots=True)
class Config(Layer):
    """A configuration file's settings, paths made absolute (exclude and source globs are
    anchored at the file's folder)."""

    path: Path = field(default=Path())


Stamp = tuple[int, int]


def _stamp(path: Path) -> Stamp:
    """A file's or folder's (mtime_ns, size); (0, 0) when it is not there."""
    try:
        st = path.stat()
    except (OSError, ValueError):
        return (0, 0)
    return (st.st_mtime_ns, st.st_size)


def find_config(start: Path, searched: dict[Path, Stamp] | None = None) -> Path | None:
    """The nearest configuration file at or above ``start`` (a file or a folder).  Each
    folder looked in, and each ``pyproject.toml`` read, is recorded in ``searched`` with
    its stamp, taken before (a file created or deleted in a folder changes the folder's
    modification time)."""
    folder = start if os.path.isdir(start) else start.parent
    for _ in range(MAX_DEPTH):
        if searched is not None:
            searched[folder] = _stamp(folder)
        for name in CONFIG_NAMES:
            if searched is not None and name == PYPROJECT:
                searched[folder / name] = _stamp(folder / name)
            candidate = folder / name
            try:
                if not candidate.is_file():
                    continue
            except (OSError, ValueError):
                continue
            if name == PYPROJECT:
                try:
                    head = read_head(str(candidate), MAX_CONFIG_BYTES)
                except FileError:
                    continue
                text = head.decode("utf-8", "replace")
                if not _mentions_table(text):
                    continue
            return candidate
        if folder.parent == folder:
            break
        folder = folder.parent
    return None


_TOOL_TABLE: Final = re.compile(r'^\s*\[\s*tool\s*\.\s*(?:bt-lsp|"bt-lsp")\s*[\].]', re.MULTILINE)
_TOOL_INLINE: Final = re.compile(r"^\s*(?:bt-lsp|\"bt-lsp\")\s*=", re.MULTILINE)


def _mentions_table(text: str) -> bool:
    return _TOOL_TABLE.search(text) is not None or (
        "[tool]" in text and _TOOL_INLINE.search(text) is not None
    )


_AT: Final = re.compile(r"\(at line (\d+), column (\d+)\)")


def load_config(path: Path, data: bytes | None = None) -> Config | None:
    """The configuration in ``path`` (or ``data``, its text as an editor has it);
    ``None`` for a ``pyproject.toml`` without a ``[tool.bt-lsp]`` table.
    :class:`ConfigError` when it cannot be used."""
    if data is None:
        try:
            # Never from a FIFO or a device, and without blocking (see read_head).
            data = read_head(str(path), MAX_CONFIG_BYTES + 1)
        except FileError as e:
            raise ConfigError(path, 1, 1, f"cannot read the file: {e.reason}") from None
    if len(data) > MAX_CONFIG_BYTES:
        raise ConfigError(path, 1, 1, f"larger than {MAX_CONFIG_BYTES} bytes")
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as e:
        line, col = _position(data[: e.start].decode("utf-8", "replace"))
        raise ConfigError(path, line, col, "not UTF-8 text") from None
    try:
        doc = tomllib.loads(text)
    except tomllib.TOMLDecodeError as e:
        msg = str(e)
        m = _AT.search(msg)
        if m is not None:
            line, col = int(m.group(1)), int(m.group(2))
            msg = msg[: m.start()].rstrip()
        else:  # "at end of document"
            line, col = _position(text)
            msg = re.sub(r"\s*\(at end of document\)", "", msg) + " at the end of the file"
        raise ConfigError(path, line, col, f"TOML syntax error: {msg}") from None
    table: Any = doc
    prefix: tuple[str, ...] = ()
    if path.name == PYPROJECT:
        tool = doc.get("tool")
        table = tool.get("bt-lsp") if isinstance(tool, dict) else None
        if table is None:
            return None
        prefix = ("tool", "bt-lsp")
        if not isinstance(table, dict):
            raise _error(path, text, prefix, "[tool.bt-lsp] must be a table")
    return _parse(path, text, table, prefix)


def _position(text: str) -> tuple[int, int]:
    """The 1-based line and column just after ``text``."""
    line = text.count("\n") + 1
    return line, len(text) - (text.rfind("\n") + 1) + 1


def _parse(path: Path, text: str, table: dict[str, Any], prefix: tuple[str, ...]) -> Config:
    folder = path.parent
    for key in table:
        if key not in KEYS:
            hint = ""
            if key.replace("_", "-") in KEYS:
                hint = f" (did you mean '{key.replace('_', '-')}'?)"
            raise _error(
                path,
                text,
                (*prefix, key),
                f"unknown key '{key}'{hint}; the keys are: {', '.join(KEYS)}",
            )
    kw: dict[str, Any] = {}

    def strings(key: str) -> tuple[str, ...] | None:
        value = table.get(key)
        if value is None:
            return None
        if not isinstance(value, list) or not all(isinstance(v, str) for v in value):
            raise _error(path, text, (*prefix, key), f"'{key}' must be a list of strings")
        return tuple(value)

    models = strings("models")
    if models is not None:
        kw["models"] = tuple(_absolute(folder, m) for m in models)
    if "btcpp" in table:
        raw = table["btcpp"]
        word = str(raw) if isinstance(raw, str | int) and not isinstance(raw, bool) else None
        if word not in BTCPP_CHOICES:
            raise _error(
                path,
                text,
                (*prefix, "btcpp"),
                f'\'btcpp\' must be "auto", "3" or "4", not {_toml(raw)}',
            )
        kw["btcpp"] = word
    if "severity" in table:
        kw["severity"] = _severities(path, text, prefix, table["severity"])
    if "min-severity" in table:
        raw = table["min-severity"]
        minimum = Severity.parse(raw) if raw in MIN_SEVERITIES else None
        if minimum is None:
            raise _error(
                path,
                text,
                (*prefix, "min-severity"),
                f'\'min-severity\' must be "error", "warning", "information" or '
                f'"hint", not {_toml(raw)}',
            )
        kw["min_severity"] = minimum
    exclude = strings("exclude")
    if exclude is not None:
        kw["exclude"] = tuple(anchor(folder, g) for g in exclude)
    sources = strings("sources")
    if sources is not None:
        kw["sources"] = tuple(anchor(folder, g) for g in sources)
    if "ros-packages" in table:
        ros = table["ros-packages"]
        if not isinstance(ros, dict):
            raise _error(path, text, (*prefix, "ros-packages"), "'ros-packages' must be a table")
        out: dict[str, str] = {}
        for name, folder_name in ros.items():
            if not isinstance(folder_name, str):
                raise _error(
                    path,
                    text,
                    (*prefix, "ros-packages", name),
                    f"ros-packages: the folder of '{name}' must be a string",
                )
            out[name] = str(_absolute(folder, folder_name))
        kw["ros_packages"] = out
    return Config(path=path, **kw)


def _severities(
    path: Path, text: str, prefix: tuple[str, ...], raw: object
) -> dict[str, Severity | None]:
    if not isinstance(raw, dict):
        raise _error(
            path, text, (*prefix, "severity"), "'severity' must be a table of code = \"level\""
        )
    out: dict[str, Severity | None] = {}
    for code, word in raw.items():
        where = (*prefix, "severity", code)
        if code not in CODES:
            raise _error(path, text, where, f"severity: unknown code '{code}'")
        try:
            if not isinstance(word, str):
                raise ValueError
            out[code] = Severity.parse(word)
        except ValueError:
            raise _error(
                path,
                text,
                where,
                f"severity: {_toml(word)} for {code} is not one of "
                '"error", "warning", "information", "hint", "off"',
            ) from None
    return out


def _toml(value: object) -> str:
    if isinstance(value, str):
        return '"' + value.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, dict):
        return "a table"
    if isinstance(value, list):
        return "a list"
    return str(value)


def _absolute(folder: Path, written: str) -> Path:
    p = Path(os.path.expanduser(written))
    return Path(os.path.normpath(p if p.is_absolute() else folder / p))


def anchor(folder: Path, glob: str) -> str:
    """A glob of a configuration file made absolute: one with a ``/`` is relative to the
    file's folder; one without matches a file or folder name anywhere below it."""
    g = glob.replace("\\", "/").rstrip("/")
    if g.startswith("/"):
        return g
    base = folder.as_posix().rstrip("/")
    if "/" not in g:
        return f"{base}/**/{g}"
    return f"{base}/{g.removeprefix('./')}"


# -- where a key is ----------------------------------------------------------------------


def _error(path: Path, text: str, keys: tuple[str, ...], message: str) -> ConfigError:
    line, col = locate(text, keys)
    return ConfigError(path, line, col, message)


def locate(text: str, keys: tuple[str, ...]) -> tuple[int, int]:
    """The 1-based line and column where the key ``keys`` is written: as ``key =`` (also
    dotted and quoted) or as a table header.  tomllib does not keep positions, so this
    looks for the key's last name after the header of the table above it; the start of
    the file if it cannot be found."""
    lines = text.splitlines()
    if not keys:
        return 1, 1
    header_line = 0
    # The table that holds the key: the longest prefix that is written as a header.
    for n in range(len(keys) - 1, 0, -1):
        found = _header(lines, keys[:n])
        if found is not None:
            header_line = found
            break
    own = _header(lines, keys)  # the key may itself be a table: [tool.bt-lsp.severity]
    if own is not None:
        return own + 1, _indent(lines[own]) + 1
    name = keys[-1]
    pattern = re.compile(
        r"^(\s*)(?:[\w.\"'-]+\.)?(?:" + re.escape(name) + r'|"' + re.escape(name) + r'"'
        r"|'" + re.escape(name) + r"')\s*="
    )
    inline = re.compile(r"(?:^|[{,\s])(" + re.escape(name) + r'|"' + re.escape(name) + r'")\s*=')
    for i in range(header_line, len(lines)):
        m = pattern.match(lines[i])
        if m is not None:
            return i + 1, len(m.group(1)) + 1
    for i in range(header_line, len(lines)):
        m = inline.search(lines[i])
        if m is not None:
            return i + 1, m.start(1) + 1
    return header_line + 1, 1


def _indent(line: str) -> int:
    return len(line) - len(line.lstrip())


def _header(lines: list[str], keys: tuple[str, ...]) -> int | None:
    parts = [r"\s*(?:" + re.escape(k) + r'|"' + re.escape(k) + r'")\s*' for k in keys]
    pattern = re.compile(r"^\s*\[" + r"\.".join(parts) + r"\]")
    for i, line in enumerate(lines):
        if pattern.match(line):
            return i
    return None


# -- found and cached ----------------------------------------------------------------------


class Configs:
    """The configuration files of a workspace: found upward from each file, read once and
    read again after they change.  With ``explicit`` (``check --config FILE``) that file
    is every file's configuration."""

    def __init__(self, explicit: Path | None = None) -> None:
        self.explicit = explicit
        self._found: dict[Path, Path | None] = {}
        self._loaded: dict[Path, Config | ConfigError | None] = {}
        self._texts: dict[Path, str] = {}  # configuration files open in an editor
        # What the files found and read depend on, on disk (see revalidate).
        self._searched: dict[Path, Stamp] = {}
        self._read: dict[Path, Stamp] = {}

    def path_for(self, path: Path) -> Path | None:
        """The configuration file that applies to ``path`` (a file or folder)."""
        if self.explicit is not None:
            return self.explicit
        folder = path if os.path.isdir(path) else path.parent
        if folder not in self._found:
            self._found[folder] = find_config(folder, self._searched)
        return self._found[folder]

    def load(self, config_path: Path) -> Config | ConfigError | None:
        if config_path not in self._loaded:
            text = self._texts.get(config_path)
            if text is None:
                self._read[config_path] = _stamp(config_path)
            try:
                self._loaded[config_path] = load_config(
                    config_path, None if text is None else text.encode("utf-8")
                )
            except ConfigError as e:
                self._loaded[config_path] = e
        return self._loaded[config_path]

    def for_path(self, path: Path) -> Config | ConfigError | None:
        found = self.path_for(path)
        return None if found is None else self.load(found)

    def errors(self) -> list[ConfigError]:
        """The errors of the configuration files read so far."""
        return [e for e in self._loaded.values() if isinstance(e, ConfigError)]

    def loaded(self) -> list[Path]:
        return list(self._loaded)

    def set_text(self, path: Path, text: str | None) -> bool:
        """An editor opened, changed (``text``) or closed (``None``) the file at ``path``;
        true if it may be a configuration file (then it is read again)."""
        if path.name not in CONFIG_NAMES and path != self.explicit:
            return False
        if text is None:
            self._texts.pop(path, None)
        else:
            self._texts[path] = text
        return self.changed(path)

    def changed(self, path: Path) -> bool:
        """``path`` changed on disk; true (and everything forgotten) if it may be a
        configuration file."""
        if path.name not in CONFIG_NAMES and path != self.explicit:
            return False
        self._forget()
        return True

    def _forget(self) -> None:
        self._found.clear()
        self._loaded.clear()
        self._searched.clear()
        self._read.clear()

    def revalidate(self) -> list[Path]:
        """For clients that do not report file changes: the configuration files created,
        changed or deleted on disk since they were looked for or read (then everything is
        forgotten).  A folder on the way that changed for another reason (a file of
        another kind made in it) only costs looking again."""
        changed = [p for p, st in self._read.items() if _stamp(p) != st]
        if not changed and not any(_stamp(p) != st for p, st in self._searched.items()):
            return []
        before = dict(self._found)
        self._found.clear()
        self._searched.clear()
        for folder, found in before.items():
            now = self.path_for(folder)
            if now != found:
                changed.extend(p for p in (found, now) if p is not None)
        if changed:
            self._forget()
        return changed


# -- exclude globs -------------------------------------------------------------------------


def _glob_regex(glob: str) -> re.Pattern[str]:
    """A glob over ``/``-separated paths: ``**`` spans folders, ``*`` and ``?`` stay in one."""
    out: list[str] = []
    i = 0
    while i < len(glob):
        c = glob[i]
        if glob.startswith("**/", i):
            out.append("(?:.*/)?")
            i += 3
        elif glob.startswith("**", i):
            out.append(".*")
            i += 2
        elif c == "*":
            out.append("[^/]*")
            i += 1
        elif c == "?":
            out.append("[^/]")
            i += 1
        else:
            out.append(re.escape(c))
            i += 1
    return re.compile("".join(out) + r"\Z")


_GLOBS: dict[str, re.Pattern[str]] = {}


def excluded(path: Path, globs: tuple[str, ...]) -> bool:
    """Whether ``path`` (absolute) matches one of the anchored ``exclude`` globs."""
    if not globs:
        return False
    text = path.as_posix()
    for g in globs:
        pattern = _GLOBS.get(g)
        if pattern is None:
            pattern = _GLOBS[g] = _glob_regex(g)
        if pattern.match(text):
            return True
    return False
