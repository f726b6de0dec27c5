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
)
