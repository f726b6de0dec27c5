"""The ``sarif`` format: SARIF 2.1.0 for code scanning, with UTF-16 columns and stable
fingerprints."""

from __future__ import annotations

import hashlib
import os
from collections import Counter
from collections.abc import Sequence
from pathlib import Path
from typing import Any, Final
from urllib.parse import quote

from bt_lsp import __version__
from bt_lsp.cli.results import FILE_ERROR, FileResult
from bt_lsp.rules.codes import DOCS_URL, Severity
from bt_lsp.rules.registry import CODES

SARIF_SCHEMA: Final = "https://json.schemastore.org/sarif-2.1.0.json"
SRCROOT: Final = "%SRCROOT%"

_SARIF_LEVEL: Final[dict[Severity, str]] = {
    Severity.ERROR: "error",
    Severity.WARNING: "warning",
    Severity.INFORMATION: "note",
    Severity.HINT: "note",
}


def artifact_location(path: str, root: str) -> dict[str, str]:
    """A SARIF ``artifactLocation``: relative to ``root`` (``%SRCROOT%``) with forward
    slashes when the file is under it, else an absolute ``file:`` URI."""
    absolute = os.path.abspath(path)
    try:
        rel = os.path.relpath(absolute, root)
    except ValueError:  # another drive
        rel = ""
    if not rel or rel == os.pardir or rel.startswith(os.pardir + os.sep) or os.path.isabs(rel):
        return {"uri": Path(absolute).as_uri()}
    return {"uri": quote(Path(rel).as_posix(), safe="/"), "uriBaseId": SRCROOT}


def _fingerprint(code: str, uri: str, token: str, nth: int) -> str:
    data = "\0".join((code, uri, token, str(nth))).encode("utf-8", "surrogatepass")
    return hashlib.sha256(data).hexdigest()[:32]


def to_sarif(results: Sequence[FileResult], root: str | None = None) -> dict[str, Any]:
    """A SARIF 2.1.0 log of ``results``; ``root`` is ``%SRCROOT%`` (default: the working
    directory)."""
    root = os.path.abspath(root if root is not None else os.getcwd())
    used = sorted({f.code for r in results for f in r.findings})
    index = {code: i for i, code in enumerate(used)}
    rules = [
        {
            "id": code,
            "name": code,
            "shortDescription": {"text": CODES[code].summary},
            "helpUri": CODES[code].url,
            "defaultConfiguration": {"level": _SARIF_LEVEL[CODES[code].severity]},
        }
        for code in used
    ]
    sarif_results: list[dict[str, Any]] = []
    notifications: list[dict[str, Any]] = []
    for r in results:
        location = artifact_location(r.path, root)
        if r.error is not None:
            notifications.append(
                {
                    "level": "error",
                    "message": {"text": r.error.message},
                    "descriptor": {"id": FILE_ERROR},
                    "locations": [{"physicalLocation": {"artifactLocation": location}}],
                }
            )
        if r.config:  # the run went on without that configuration: say so
            notifications.extend(
                {
                    "level": "error",
                    "message": {"text": f"{f.message} (the file's settings were not used)"},
                    "descriptor": {"id": f.code},
                    "locations": [{"physicalLocation": {"artifactLocation": location}}],
                }
                for f in r.findings
            )
        seen: Counter[tuple[str, str]] = Counter()
        for f in r.findings:
            nth = seen[(f.code, f.token)]
            seen[(f.code, f.token)] += 1
            sarif_results.append(
                {
                    "ruleId": f.code,
                    "ruleIndex": index[f.code],
                    "level": _SARIF_LEVEL[f.severity],
                    "message": {"text": f.message},
                    "locations": [
                        {
                            "physicalLocation": {
                                "artifactLocation": dict(location),
                                "region": {
                                    "startLine": f.line,
                                    "startColumn": f.utf16_column,
                                    "endLine": f.end_line,
                                    "endColumn": f.utf16_end_column,
                                },
                            }
                        }
                    ],
                    "partialFingerprints": {
                        "btLspToken/v1": _fingerprint(f.code, location["uri"], f.token, nth)
                    },
                }
            )
    run: dict[str, Any] = {
        "tool": {
            "driver": {
                "name": "bt-lsp",
                "informationUri": DOCS_URL,
                "version": __version__,
                "semanticVersion": __version__,
                "rules": rules,
            }
        },
        "invocations": [
            {
                "executionSuccessful": not notifications,
                "toolExecutionNotifications": notifications,
            }
        ],
        "columnKind": "utf16CodeUnits",
        "results": sarif_results,
    }
    return {"$schema": SARIF_SCHEMA, "version": "2.1.0", "runs": [run]}
