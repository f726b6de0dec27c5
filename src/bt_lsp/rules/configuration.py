"""The code of a project configuration file that cannot be used (``bt-lsp.toml`` or the
``[tool.bt-lsp]`` table of a ``pyproject.toml``).

The project layer reads and checks the file (:mod:`bt_lsp.project.config`); the server
reports the problem on the file itself and the CLI prints it and exits with status 2.
"""

from __future__ import annotations

from typing import Final

from bt_lsp.rules.codes import PROJECT, Severity, define

CONFIG_ERROR: Final = define(
    "config-error",
    Severity.ERROR,
    "a `bt-lsp.toml` (or `[tool.bt-lsp]` table) that cannot be used; reported on that file, "
    "whose settings are then ignored",
    PROJECT,
    doc="""
        Not about BehaviorTree.CPP: a `bt-lsp.toml` (or the `[tool.bt-lsp]` table of a
        `pyproject.toml`) that cannot be used: not TOML, an unknown key (the message lists
        the keys), a value of the wrong type, an unknown
        code or severity in `severity`. The server reports it on the file, where it is, and
        ignores the file's settings; `bt-lsp check` prints it and exits with status 2. No
        example: it is about the configuration file, not a tree.
        """,
    why="""
        None of the file's settings apply (catalogs, severities, excluded files) until it is
        fixed, so the other results may be wrong.
        """,
    since="Every version of bt-lsp.",
)
