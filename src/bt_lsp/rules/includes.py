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
)
INCLUDE_CYCLE: Final = define(
    "include-cycle", Severity.ERROR, "files include each other in a cycle", BT
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
