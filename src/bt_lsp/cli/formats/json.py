"""The ``json`` format: one array of ``{path, line, column, endLine, endColumn, severity,
code, message}``; a configuration file that cannot be used is a ``config-error`` entry
at its position."""

from __future__ import annotations

from collections.abc import Iterable
from typing import Any

from bt_lsp.cli.results import FILE_ERROR, FileResult


def to_json(results: Iterable[FileResult]) -> list[dict[str, Any]]:
    out: list[dict[str, Any]] = []
    for r in results:
        if r.error is not None:
            out.append(
                {
                    "path": r.path,
                    "line": None,
                    "column": None,
                    "endLine": None,
                    "endColumn": None,
                    "severity": "error",
                    "code": FILE_ERROR,
                    "message": r.error.message,
                }
            )
        for f in r.findings:
            out.append(
                {
                    "path": f.path,
                    "line": f.line,
                    "column": f.column,
                    "endLine": f.end_line,
                    "endColumn": f.end_column,
                    "severity": f.severity.label,
                    "code": f.code,
                    "message": f.message,
                }
            )
    return out
