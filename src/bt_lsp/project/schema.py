"""Every setting, as the documentation describes it: the editor's ``btLsp`` setting, the
configuration file's key and the ``check`` flag that set it, its type, default and
meaning.

:mod:`bt_lsp.project.config` takes its key list from here, and ``tests/test_docs.py``
holds :meth:`bt_lsp.project.settings.Settings.parse` to the setting names, so the
configuration reference (``docs/configuration.md``, written by ``scripts/docs_gen.py``)
cannot name a key the code does not read, or miss one it does.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Final

from bt_lsp.project.settings import DEFAULT_MAX_DOCUMENT_BYTES, MAX_DEBOUNCE_MS

__all__ = ["FILE_KEYS", "KEYS", "Key"]


@dataclass(frozen=True, slots=True)
class Key:
    """One setting.  ``setting`` is its name in the editor's ``btLsp`` section (``None``:
    the editor cannot set it), ``file`` its key in ``bt-lsp.toml`` / ``[tool.bt-lsp]``
    (``None``: not in the file), ``flag`` the ``bt-lsp check`` option.  ``type``,
    ``default`` and ``doc`` are Markdown."""

    setting: str | None
    file: str | None
    flag: str | None
    type: str
    default: str
    doc: str


_LEVELS = '`"error"`, `"warning"`, `"information"`, `"hint"` or `"off"`'

KEYS: Final[tuple[Key, ...]] = (
    Key(
        "modelFiles",
        "models",
        "--models FILE (repeatable)",
        "list of paths",
        "`[]`",
        "Node catalogs: a `TreeNodesModel` XML file that BehaviorTree.CPP exported "
        "(`writeTreeNodesModelXML`, authoritative: a node it lacks is not registered) or a "
        "Groot2 `.btproj` palette (advisory). A relative path is relative to the "
        "configuration file's folder (for the editor setting, to the first workspace folder).",
    ),
    Key(
        "btcpp",
        "btcpp",
        "--btcpp auto|3|4",
        '`"auto"`, `"3"` or `"4"`',
        '`"auto"`',
        "The BehaviorTree.CPP major version the files are checked against. `auto` decides "
        "per file: the `package.xml` or `CMakeLists.txt` of the file's package, then the "
        "document's `BTCPP_format`; with no version found, 4.",
    ),
    Key(
        "severity",
        "severity",
        "--severity CODE=LEVEL (repeatable)",
        "table of code = level",
        "`{}`",
        f"Per-code severity: {_LEVELS}. Merged code by code over the layer below (a code "
        "the file does not name keeps the editor's level). The codes are listed under "
        "[Diagnostics](rules/index.md).",
    ),
    Key(
        "minSeverity",
        "min-severity",
        "--min-severity error|warning|information|hint",
        '`"error"`, `"warning"`, `"information"` or `"hint"`',
        '`"hint"`',
        "The least severe diagnostics shown: `check` prints and the editor publishes only "
        "those at least this severe (`--fix` still applies every fix).",
    ),
    Key(
        None,
        "exclude",
        None,
        "list of globs",
        "`[]`",
        "Files and folders left out of the workspace: not checked when a folder is walked "
        "(nor when named with `check --force-exclude`), and their trees and models count "
        "for no other file. A glob without `/` matches a "
        "name at any depth, one with `/` a path from the configuration file's folder (`**` "
        "spans folders). A file opened in the editor is still checked.",
    ),
    Key(
        "rosPackages",
        "ros-packages",
        None,
        "table of name = folder",
        "`{}`",
        'ROS package name → its share folder, for `<include ros_pkg="…">` and the '
        "package's node catalogs. Merged entry by entry.",
    ),
    Key(
        None,
        "sources",
        None,
        "list of globs",
        "`[]`",
        "The project's C++ sources, read for the node catalog from C++ (instead of every "
        "folder of each package but build output, tests and nested packages).",
    ),
    Key(
        "debounceMs",
        None,
        None,
        f"number, 0 to {MAX_DEBOUNCE_MS}",
        "`200`",
        "Milliseconds before diagnostics are recomputed after an edit; `0` is right away.",
    ),
    Key(
        "maxDocumentBytes",
        None,
        None,
        "positive integer",
        f"`{DEFAULT_MAX_DOCUMENT_BYTES}`",
        "Above this size (UTF-8 bytes) only the XML and name checks run; an information "
        "diagnostic (`document-too-large`) says so.",
    ),
)

#: The keys of the configuration file, in the order error messages list them.
FILE_KEYS: Final[tuple[str, ...]] = tuple(k.file for k in KEYS if k.file is not None)
