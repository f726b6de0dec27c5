"""The include rules: what an ``<include>`` that BehaviorTree.CPP cannot follow gives.

The project layer resolves each ``<include path>`` as BehaviorTree.CPP does and reads the
files; these are the codes and messages it reports with (the rules read no files).
"""

from __future__ import annotations

from typing import Final

from bt_lsp.rules.codes import BT, Severity, define

# The codes of these rules (see bt_lsp.rules.registry).
INCLUDE_NOT_FOUND: Final = define(
    "include-not-found",
    Severity.ERROR,
    "an included file does not exist or cannot be read",
    BT,
    doc="""
        `<include path="…">` names a file BehaviorTree.CPP loads with the including one,
        `path` relative to the including file's folder (or under the share folder of
        `ros_pkg`). A file that does not exist or cannot be read makes loading fail: `Error
        parsing the XML: Error=XML_ERROR_FILE_NOT_FOUND …`. bt-lsp resolves the path the same
        way and says where it looked. No example: it depends on the files around the
        document.
        """,
    why="The file does not load, and the trees of the missing file are unknown.",
    since="Every version.",
)
INCLUDE_CYCLE: Final = define(
    "include-cycle",
    Severity.ERROR,
    "files include each other in a cycle",
    BT,
    doc="""
        Files that include each other in a cycle (`a.xml` → `b.xml` → `a.xml`).
        BehaviorTree.CPP has no check: a file that includes itself recurses until the process
        crashes, and a cycle through folders ends in a misleading `XML_ERROR_FILE_NOT_FOUND`
        whose path keeps growing. No example: it takes several files.
        """,
    why="The program crashes or fails with an error that names the wrong cause.",
    since="Every version.",
)


def includes_itself(written: str) -> str:
    return f"'{written}' includes this file itself; BehaviorTree.CPP recurses until it crashes"


def not_found(written: str, target: str, why: str) -> str:
    return f"Included file '{written}' not found ({target}: {why})"


def cycle(names: str) -> str:
    """``names``: the files of the cycle, joined with arrows."""
    return (
        f"Include cycle: {names}; BehaviorTree.CPP fails with a misleading 'file not found' "
        "or crashes"
    )
