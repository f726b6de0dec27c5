"""The ``bt-lsp check`` command: collect files, analyze them, fix them, report.

Output formats:

* ``text``: one line per diagnostic on stdout, ``path:line:col: severity code message``
  (1-based line and column; columns count characters, i.e. code points), and a summary
  line on stderr.
* ``json``: one array on stdout of ``{path, line, column, endLine, endColumn, severity,
  code, message}``; positions as in ``text``, ``endColumn`` is the column just after the
  last character. A file that cannot be read is an object with code ``file-error`` and
  ``null`` positions.
* ``sarif``: SARIF 2.1.0 for code scanning; columns count UTF-16 code units
  (``columnKind: utf16CodeUnits``), URIs are relative to the working directory
  (``%SRCROOT%``).

Exit status: 0 without errors, 1 with at least one error-severity diagnostic, 2 when a file
cannot be read or decoded (the others are still checked).
"""

from __future__ import annotations

import hashlib
import json
import os
import shutil
import stat
import sys
import traceback
import unicodedata
from bisect import bisect_right
from collections import Counter
from collections.abc import Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Final, Literal, TextIO
from urllib.parse import quote

from bt_lsp import __version__
from bt_lsp.ide import name_fixes as fixes
from bt_lsp.project.fileio import (
    DEFAULT_MAX_BYTES,
    Decoded,
    FileError,
    read_text,
    write_text_atomic,
)
from bt_lsp.project.settings import Settings
from bt_lsp.project.workspace import Workspace, normalize
from bt_lsp.rules import analysis
from bt_lsp.rules.codes import CODES, DOCS_URL, Severity
from bt_lsp.rules.diagnostics import Diagnostic, with_severities
from bt_lsp.syntax.document import Document
from bt_lsp.syntax.edits import TextEdit, apply_edits

__all__ = [
    "FORMATS",
    "FileResult",
    "Finding",
    "Options",
    "Progress",
    "check_file",
    "collect_files",
    "exit_code",
    "format_text",
    "parse_severities",
    "run",
    "summary",
    "to_json",
    "to_sarif",
]

Format = Literal["text", "json", "sarif"]
FORMATS: Final[tuple[Format, ...]] = ("text", "json", "sarif")

SKIP_DIRS: Final = frozenset({"node_modules"})
FILE_ERROR: Final = "file-error"
SARIF_SCHEMA: Final = "https://json.schemastore.org/sarif-2.1.0.json"
SRCROOT: Final = "%SRCROOT%"

_SARIF_LEVEL: Final[dict[Severity, str]] = {
    Severity.ERROR: "error",
    Severity.WARNING: "warning",
    Severity.INFORMATION: "note",
    Severity.HINT: "note",
}


@dataclass(frozen=True, slots=True)
class Options:
    format: Format = "text"
    fix: bool = False
    severities: Mapping[str, Severity | None] = field(default_factory=dict)
    progress: bool = True
    max_bytes: int = DEFAULT_MAX_BYTES


@dataclass(frozen=True, slots=True)
class Finding:
    """One diagnostic of one file, with its positions already converted.

    ``line``/``column`` are 1-based, columns in code points; ``end_column`` is the column
    after the last character. ``utf16_*`` are the same columns in UTF-16 code units.
    ``token`` is the text the diagnostic covers (for stable fingerprints).
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


@dataclass(slots=True)
class FileResult:
    path: str
    findings: list[Finding] = field(default_factory=list)
    error: FileError | None = None
    fixed: int = 0
    not_fixed: str | None = None  # why a file with fixes was left unchanged
    notes: list[str] = field(default_factory=list)  # what the applied fixes left as it was
    detail: str = ""  # the traceback of an internal error


# -- collecting files --------------------------------------------------------------------


def _part_key(path: str, root: str) -> list[str]:
    return os.path.relpath(path, root).split(os.sep)


def _search(root: str, errors: list[FileError]) -> list[str]:
    """Every ``*.xml`` file under ``root`` (regular files or links to them; hidden
    files and folders and ``node_modules`` skipped), sorted by path components."""

    def onerror(e: OSError) -> None:
        where = e.filename if isinstance(e.filename, str) else root
        errors.append(FileError(where, f"cannot read {where}: {e.strerror or e}"))

    found: list[str] = []
    for dirpath, dirnames, filenames in os.walk(root, onerror=onerror):
        dirnames[:] = sorted(d for d in dirnames if not d.startswith(".") and d not in SKIP_DIRS)
        for name in filenames:
            if name.startswith(".") or not name.endswith(".xml"):
                continue
            path = os.path.join(dirpath, name)
            if root == os.curdir:
                path = os.path.relpath(path)
            try:
                st = os.stat(path)
            except OSError:
                found.append(path)  # a broken link: reported when it is read
                continue
            if stat.S_ISREG(st.st_mode):
                found.append(path)
    found.sort(key=lambda p: _part_key(p, root))
    return found


def collect_files(paths: Iterable[str]) -> tuple[list[str], list[FileError]]:
    """The files to check, in order, each once: a directory gives its ``*.xml`` files
    (recursively), anything else is taken as a file (a missing one is reported when read).
    Also returns the folders that could not be searched."""
    files: list[str] = []
    errors: list[FileError] = []
    seen: set[str] = set()
    for given in paths:
        if os.path.isdir(given):
            root = given.rstrip("/" + os.sep) or given
            candidates = _search(root, errors)
        else:
            candidates = [given]
        for path in candidates:
            key = os.path.normcase(os.path.realpath(path))
            if key not in seen:
                seen.add(key)
                files.append(path)
    return files, errors


def parse_severities(specs: Iterable[str]) -> dict[str, Severity | None]:
    """``CODE=LEVEL`` settings (several may be joined with commas); ``ValueError`` on an
    unknown code or level."""
    out: dict[str, Severity | None] = {}
    for spec in specs:
        for item in spec.split(","):
            if not item.strip():
                continue
            code, sep, level = item.partition("=")
            code = code.strip()
            if not sep:
                raise ValueError(f"expected CODE=LEVEL, got {item.strip()!r}")
            if code not in CODES:
                raise ValueError(f"unknown code {code!r}")
            try:
                out[code] = Severity.parse(level)
            except ValueError:
                raise ValueError(
                    f"unknown severity {level.strip()!r} for {code} "
                    "(expected error, warning, information, hint or off)"
                ) from None
    return out


# -- checking and fixing -----------------------------------------------------------------


def _analyze(doc: Document, workspace: Workspace | None = None) -> list[Diagnostic]:
    """Every diagnostic of ``doc``, before severity settings; with a workspace, its
    includes, models and trees count too."""
    if workspace is None or doc.path is None:
        return analysis.analyze(doc)
    return workspace.diagnostics(normalize(doc.path), doc)


def _findings(path: str, doc: Document, diags: Iterable[Diagnostic]) -> list[Finding]:
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
            )
        )
    return out


def _new_spans(edits: Sequence[TextEdit]) -> list[tuple[int, int]]:
    """Where each edit's new text lies in the edited text."""
    spans: list[tuple[int, int]] = []
    shift = 0
    for e in sorted(edits):
        start = e.start + shift
        spans.append((start, start + len(e.new_text)))
        shift += len(e.new_text) - (e.end - e.start)
    return spans


def _touches(d: Diagnostic, spans: Sequence[tuple[int, int]], starts: Sequence[int]) -> bool:
    """Whether ``d`` overlaps or touches one of ``spans`` (sorted, disjoint; ``starts``
    are their starts)."""
    i = bisect_right(starts, d.end) - 1
    return i >= 0 and spans[i][1] >= d.start


def _xml_counts(diags: Iterable[Diagnostic]) -> Counter[str]:
    return Counter(d.code for d in diags if CODES[d.code].family == "xml")


def _well_formed(data: bytes) -> bool:
    from lxml import etree

    # Nothing is expanded, loaded or fetched; libxml2's default size limits stay on.
    parser = etree.XMLParser(
        resolve_entities=False,
        no_network=True,
        load_dtd=False,
        dtd_validation=False,
        huge_tree=False,
    )
    try:
        etree.fromstring(data, parser)
    except etree.LxmlError:
        return False
    return True


@dataclass(frozen=True, slots=True)
class _Fixed:
    doc: Document
    raw: list[Diagnostic]
    notes: list[str]


def _fix(
    decoded: Decoded,
    doc: Document,
    raw: list[Diagnostic],
    diags: list[Diagnostic],
    workspace: Workspace | None = None,
) -> _Fixed | str | None:
    """The fixed document, or why the file cannot be fixed safely (``None``: nothing to
    fix)."""
    fix_all = fixes.fix_all(doc, diags)
    edits = fix_all.edits
    if not edits:
        return None
    if not decoded.lossless:
        return f"{decoded.encoding.upper()} does not round-trip its bytes"
    try:
        new_text = apply_edits(doc.text, edits)
    except ValueError as e:
        return f"the fixes overlap ({e})"
    if new_text == doc.text:
        return None
    try:
        new_bytes = decoded.encode(new_text)
    except UnicodeEncodeError as e:
        char = e.object[e.start]
        return f"U+{ord(char):04X} cannot be written in {decoded.encoding.upper()}"
    new_doc = Document(new_text, doc.path)
    new_raw = _analyze(new_doc, workspace)
    before, after = _xml_counts(raw), _xml_counts(new_raw)
    worse = sorted(code for code in after if after[code] > before[code])
    if worse:
        return f"the fixes would add {', '.join(worse)} problems"
    old_spans = [(e.start, e.end) for e in sorted(edits)]
    old_starts = [start for start, _ in old_spans]
    new_spans = _new_spans(edits)
    new_starts = [start for start, _ in new_spans]
    left = [d for d in new_raw if d.is_name_rule and _touches(d, new_spans, new_starts)]
    if left:
        line, col = new_doc.lines.position(left[0].start, "utf-32")
        return f"the fixes would leave {left[0].code} at {line + 1}:{col + 1}"
    old_elsewhere = sum(1 for d in raw if d.is_name_rule and not _touches(d, old_spans, old_starts))
    new_elsewhere = sum(
        1 for d in new_raw if d.is_name_rule and not _touches(d, new_spans, new_starts)
    )
    if new_elsewhere > old_elsewhere:
        return "the fixes would add name problems elsewhere"
    if _well_formed(decoded.encode(doc.text)) and not _well_formed(new_bytes):
        return "the fixed file would not be well-formed XML"
    return _Fixed(new_doc, new_raw, fix_all.notes)


def check_file(path: str, options: Options, workspace: Workspace | None = None) -> FileResult:
    """Read, analyze and (with ``options.fix``) fix one file, in ``workspace`` if given."""
    result = FileResult(path)
    try:
        decoded = read_text(path, options.max_bytes)
    except FileError as e:
        result.error = e
        return result
    try:
        doc = Document(decoded.text, path)
        raw = _analyze(doc, workspace)
        diags = with_severities(raw, options.severities)
        if options.fix:
            outcome = _fix(decoded, doc, raw, diags, workspace)
            if isinstance(outcome, str):
                result.not_fixed = outcome
            elif outcome is not None:
                write_text_atomic(
                    path, outcome.doc.text, decoded.encoding, decoded.bom, expect=decoded.stamp
                )
                if workspace is not None:
                    workspace.file_changed(path)
                fixed_diags = with_severities(outcome.raw, options.severities)
                result.fixed = max(len(diags) - len(fixed_diags), 0)
                result.notes = outcome.notes
                doc, diags = outcome.doc, fixed_diags
        result.findings = _findings(path, doc, diags)
    except FileError as e:
        result.not_fixed = e.message
        result.findings = _findings(path, doc, diags)
    except Exception as e:
        result.detail = traceback.format_exc()
        result.error = FileError(
            path, f"internal error while checking {path}: {type(e).__name__}: {e}"
        )
    return result


# -- formatting --------------------------------------------------------------------------


def _visible(text: str) -> str:
    """``text`` on one line with control characters written as ``U+XXXX``, so that a
    message can never move the cursor or change the terminal."""
    if text.isprintable():
        return text
    return "".join(
        f"U+{ord(c):04X}" if unicodedata.category(c) in ("Cc", "Zl", "Zp") else c for c in text
    )


def format_text(findings: Iterable[Finding]) -> Iterator[str]:
    for f in findings:
        yield (
            f"{_visible(f.path)}:{f.line}:{f.column}: "
            f"{f.severity.label} {f.code} {_visible(f.message)}"
        )


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


def _plural(n: int, word: str, plural: str | None = None) -> str:
    return f"{n} {word if n == 1 else (plural or word + 's')}"


def summary(results: Sequence[FileResult]) -> str:
    """E.g. ``3 errors, 1 warning in 2 files``."""
    counts = Counter(f.severity for r in results for f in r.findings)
    parts = [
        _plural(counts[Severity.ERROR], "error"),
        _plural(counts[Severity.WARNING], "warning"),
    ]
    if counts[Severity.INFORMATION]:
        parts.append(_plural(counts[Severity.INFORMATION], "information", "information"))
    if counts[Severity.HINT]:
        parts.append(_plural(counts[Severity.HINT], "hint"))
    checked = sum(1 for r in results if r.error is None)
    text = f"{', '.join(parts)} in {_plural(checked, 'file')}"
    unreadable = len(results) - checked
    if unreadable:
        text += f"; {_plural(unreadable, 'file')} could not be checked"
    return text


def exit_code(results: Iterable[FileResult]) -> int:
    code = 0
    for r in results:
        if r.error is not None:
            return 2
        if any(f.severity == Severity.ERROR for f in r.findings):
            code = 1
    return code


# -- running -----------------------------------------------------------------------------


def _write(stream: TextIO, text: str) -> None:
    try:
        stream.write(text)
    except UnicodeEncodeError:
        enc = getattr(stream, "encoding", None) or "ascii"
        stream.write(text.encode(enc, "backslashreplace").decode(enc, "replace"))


def _isatty(stream: TextIO) -> bool:
    try:
        return stream.isatty()
    except (AttributeError, ValueError, OSError):
        return False


class Progress:
    """A one-line progress bar, ``[#####     ] 12/40 path``, redrawn with a carriage
    return. Disabled (no output at all) unless ``enabled``."""

    WIDTH: Final = 10

    def __init__(self, stream: TextIO, total: int, enabled: bool) -> None:
        self.stream = stream
        self.total = total
        self.enabled = enabled
        self._shown = 0  # length of the line on screen

    def show(self, done: int, path: str) -> None:
        if not self.enabled:
            return
        filled = self.WIDTH * done // self.total if self.total else self.WIDTH
        line = f"[{'#' * filled}{' ' * (self.WIDTH - filled)}] {done}/{self.total} "
        room = shutil.get_terminal_size((80, 24)).columns - 1 - len(line)
        shown_path = _visible(path)
        if len(shown_path) > room:
            shown_path = "..." + shown_path[-max(room - 3, 0) :] if room > 3 else ""
        line += shown_path
        pad = " " * max(self._shown - len(line), 0)
        _write(self.stream, f"\r{line}{pad}")
        self.stream.flush()
        self._shown = len(line) + len(pad)

    def clear(self) -> None:
        if self.enabled and self._shown:
            _write(self.stream, "\r" + " " * self._shown + "\r")
            self.stream.flush()
            self._shown = 0


def run(
    paths: Sequence[str],
    options: Options,
    out: TextIO | None = None,
    err: TextIO | None = None,
) -> int:
    """Check ``paths`` and print the report; returns the exit status."""
    out = out if out is not None else sys.stdout
    err = err if err is not None else sys.stderr
    files, walk_errors = collect_files(paths)
    progress = Progress(err, len(files), options.progress and len(files) > 1 and _isatty(err))

    def say(stream: TextIO, text: str) -> None:
        progress.clear()
        _write(stream, text)
        stream.flush()

    for e in walk_errors:
        say(err, f"bt-lsp: {e.message}\n")
    if not files:
        say(err, "bt-lsp: no XML files to check\n")
        return 2 if walk_errors else 0

    # The folders named on the command line are the workspace: includes resolve as
    # BehaviorTree.CPP resolves them, and every file's models and trees are known.
    workspace = Workspace(
        [p for p in paths if os.path.isdir(p)], Settings(max_document_bytes=options.max_bytes)
    )
    results: list[FileResult] = [FileResult(e.path, error=e) for e in walk_errors]
    for i, path in enumerate(files, 1):
        progress.show(i, path)
        r = check_file(path, options, workspace)
        results.append(r)
        if r.error is not None:
            say(err, f"{r.detail}bt-lsp: {r.error.message}\n")
        if r.not_fixed is not None:
            say(err, f"bt-lsp: not fixing {_visible(path)}: {r.not_fixed}\n")
        if r.fixed:
            say(err, f"fixed {_plural(r.fixed, 'problem')} in {_visible(path)}\n")
        for note in r.notes:
            say(err, f"bt-lsp: {_visible(path)}: {_visible(note)}\n")
        if options.format == "text" and r.findings:
            say(out, "".join(line + "\n" for line in format_text(r.findings)))
    progress.clear()

    if options.format == "json":
        say(out, json.dumps(to_json(results), indent=2) + "\n")
    elif options.format == "sarif":
        say(out, json.dumps(to_sarif(results), indent=2) + "\n")
    else:
        say(err, summary(results) + "\n")
    return exit_code(results)
