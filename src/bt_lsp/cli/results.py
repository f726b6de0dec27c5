"""What checking a file gives: its diagnostics as findings with their positions
converted, the result of the file, the summary line and the exit status."""

from __future__ import annotations

from collections import Counter
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Final

from bt_lsp.ide.name_targets import with_targets
from bt_lsp.project.config import ConfigError
from bt_lsp.project.cpp_scan import CPP_SUFFIXES
from bt_lsp.project.fileio import FileError
from bt_lsp.project.index import ProjectIndex, normalize
from bt_lsp.rules import analysis
from bt_lsp.rules.codes import Severity
from bt_lsp.rules.configuration import CONFIG_ERROR
from bt_lsp.rules.diagnostics import Diagnostic
from bt_lsp.syntax.document import Document

FILE_ERROR: Final = "file-error"


@dataclass(frozen=True, slots=True)
class Finding:
    """One diagnostic of one file, with its positions already converted.

    ``line``/``column`` are 1-based, columns in code points; ``end_column`` is the column
    after the last character. ``utf16_*`` are the same columns in UTF-16 code units.
    ``token`` is the text the diagnostic covers (for stable fingerprints); ``fixable``:
    a fix the run may apply fixes it (known only for ``--statistics``).
    """

    path: str
    line: int
    column: int
    end_line: int
    end_column: int
    utf16_column: int
    utf16_end_column: int
    severity: Severity
    code: str
    message: str
    token: str = ""
    fixable: bool = False


@dataclass(slots=True)
class FileResult:
    path: str
    findings: list[Finding] = field(default_factory=list)
    error: FileError | None = None
    fixed: int = 0
    not_fixed: str | None = None  # why a file with fixes was left unchanged
    notes: list[str] = field(default_factory=list)  # what the applied fixes left as it was
    detail: str = ""  # the traceback of an internal error
    unwritten: bool = False  # --fix could not write the fixed file (exit status 2)
    config: bool = False  # a configuration file that cannot be used (exit status 2)
    text: str = ""  # the text the findings are positions of (for --output-format full)


def file_diagnostics(doc: Document, project: ProjectIndex | None = None) -> list[Diagnostic]:
    """Every diagnostic of ``doc``, before severity settings; with a project index, its
    includes, models and trees count too."""
    if project is None or doc.path is None:
        return with_targets(doc, analysis.analyze(doc))
    return project.diagnostics(normalize(doc.path), doc)


def findings_of(
    path: str,
    doc: Document,
    diags: Iterable[Diagnostic],
    fixable: Callable[[Diagnostic], bool] | None = None,
) -> list[Finding]:
    """The findings of ``diags`` in ``doc``; ``fixable`` says which a fix may fix."""
    lines = doc.lines
    out: list[Finding] = []
    for d in diags:
        sl, sc = lines.position(d.start, "utf-32")
        el, ec = lines.position(d.end, "utf-32")
        _, sc16 = lines.position(d.start, "utf-16")
        _, ec16 = lines.position(d.end, "utf-16")
        out.append(
            Finding(
                path,
                sl + 1,
                sc + 1,
                el + 1,
                ec + 1,
                sc16 + 1,
                ec16 + 1,
                d.severity,
                d.code,
                d.message,
                doc.text[d.start : min(d.end, d.start + 200)],
                fixable is not None and fixable(d),
            )
        )
    return out


def config_result(error: ConfigError, text: str | None) -> FileResult:
    """A configuration file that cannot be used, as a result with one ``config-error``
    finding at the error (``text``: the file's text, if it could be read, for the span
    and the UTF-16 columns)."""
    line, column, end_column = error.line, error.column, error.column
    utf16_column, utf16_end = column, end_column
    if text is not None:
        row, start, end = error.span(text)
        source = [part.removesuffix("\r") for part in text.split("\n")][row]
        line, column, end_column = row + 1, start + 1, end + 1
        utf16_column = len(source[:start].encode("utf-16-le")) // 2 + 1
        utf16_end = len(source[:end].encode("utf-16-le")) // 2 + 1
    path = str(error.path)
    finding = Finding(
        path,
        line,
        column,
        line,
        end_column,
        utf16_column,
        utf16_end,
        Severity.ERROR,
        CONFIG_ERROR.code,
        error.message,
    )
    return FileResult(path, findings=[finding], config=True)


def plural(n: int, word: str, plural: str | None = None) -> str:
    return f"{n} {word if n == 1 else (plural or word + 's')}"


def summary(results: Sequence[FileResult]) -> str:
    """E.g. ``3 errors, 1 warning in 2 files`` (the BehaviorTree.CPP files checked)."""
    counts = Counter(f.severity for r in results for f in r.findings)
    parts = [
        plural(counts[Severity.ERROR], "error"),
        plural(counts[Severity.WARNING], "warning"),
    ]
    if counts[Severity.INFORMATION]:
        parts.append(plural(counts[Severity.INFORMATION], "information", "information"))
    if counts[Severity.HINT]:
        parts.append(plural(counts[Severity.HINT], "hint"))
    # The BT files checked: the C++ files a folder run reads for the name rules are not.
    checked = sum(1 for r in results if r.error is None and Path(r.path).suffix not in CPP_SUFFIXES)
    text = f"{', '.join(parts)} in {plural(checked, 'file')}"
    unreadable = sum(1 for r in results if r.error is not None)
    if unreadable:
        text += f"; {plural(unreadable, 'file')} could not be checked"
    return text


def exit_code(results: Iterable[FileResult]) -> int:
    code = 0
    for r in results:
        if r.error is not None or r.unwritten or r.config:
            return 2
        if any(f.severity == Severity.ERROR for f in r.findings):
            code = 1
    return code
