"""The ``bt-lsp check`` command: collect files, analyze them, fix them, report.

Output formats:

* ``text``: one line per diagnostic on stdout, ``path:line:col: severity code message``
  (1-based line and column; columns count characters, i.e. code points), and a summary
  line on stderr.  ``--output-format full`` adds the source line and a caret under the
  range; ``--statistics`` prints a count per code instead of the diagnostics; on a
  terminal (``--color``) the path, severity and code are coloured.
* ``json``: one array on stdout of ``{path, line, column, endLine, endColumn, severity,
  code, message}``; positions as in ``text``, ``endColumn`` is the column just after the
  last character. A file that cannot be read is an object with code ``file-error`` and
  ``null`` positions.
* ``sarif``: SARIF 2.1.0 for code scanning; columns count UTF-16 code units
  (``columnKind: utf16CodeUnits``), URIs are relative to the working directory
  (``%SRCROOT%``).

Exit status: 0 without errors, 1 with at least one error-severity diagnostic, 2 when a file
cannot be read or decoded, is not a regular file (a FIFO would block), or its fix cannot be
written (the others are still checked), or a configuration file cannot be used (it is
reported as a ``config-error`` at its position, in every format, and the files are
checked without it; ``--fix`` then fixes nothing).

``--fix`` removes the temporary files an interrupted ``--fix`` left
(``.NAME.bt-lsp-XXXXXXXX.tmp``, older than the run), and does not rewrite a file that a
checked folder reaches through a symbolic link to outside it unless ``--follow-symlinks``,
nor a read-only file or one with hard links (a fixed file is a new file: it would ignore
the mode, and split the links); a rename that needs such a file is made in none.
"""

from __future__ import annotations

import json
import os
import re
import shutil
import sys
import time
import traceback
from collections import Counter
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Final, TextIO

from bt_lsp.cli.fix import fix_document, fixability
from bt_lsp.cli.fix_workspace import Planned, fix_files
from bt_lsp.cli.formats import Format
from bt_lsp.cli.formats.json import to_json
from bt_lsp.cli.formats.sarif import to_sarif
from bt_lsp.cli.formats.text import OutputFormat, Style, format_text, statistics, visible
from bt_lsp.cli.project import (
    BUILD_FOLDER,
    NOT_BT,
    config_errors,
    forced_skip_reason,
    included_back,
    project_index,
    skip_reason,
    version_lines,
    workspace_lines,
    workspaces,
)
from bt_lsp.cli.results import (
    FileResult,
    config_result,
    exit_code,
    file_diagnostics,
    findings_of,
    plural,
    summary,
)
from bt_lsp.project.config import MAX_CONFIG_BYTES
from bt_lsp.project.cpp_models import CppModels
from bt_lsp.project.cpp_scan import CPP_SUFFIXES, Scanner, find_cpp_files
from bt_lsp.project.fileio import (
    DEFAULT_MAX_BYTES,
    FileError,
    not_replaceable,
    read_head,
    read_text,
    stale_temporaries,
    write_text_atomic,
)
from bt_lsp.project.files import collect_files
from bt_lsp.project.index import ProjectIndex, normalize
from bt_lsp.project.settings import shown
from bt_lsp.rules.codes import Severity
from bt_lsp.rules.cpp_names import cpp_name_diagnostics
from bt_lsp.rules.diagnostics import Diagnostic, with_severities
from bt_lsp.rules.registry import CODES
from bt_lsp.syntax.document import Document

__all__ = ["Options", "Progress", "check_file", "parse_severities", "run"]

# The line ends of Document.lines: the source lines of --output-format full.
_LINE_BREAK: Final = re.compile(r"\r\n|\r|\n")


@dataclass(frozen=True, slots=True)
class Options:
    format: Format = "text"
    fix: bool = False
    unsafe_fixes: bool = False  # --unsafe-fixes: --fix applies the unsafe fixes too
    severities: Mapping[str, Severity | None] = field(default_factory=dict)
    progress: bool = True
    max_bytes: int = DEFAULT_MAX_BYTES
    cpp: bool = True  # learn the node catalog from the C++ of the files' packages
    config: str | None = None  # --config: one configuration file for every file
    models: tuple[str, ...] = ()  # authoritative node catalogs (--models)
    btcpp: str | None = None  # --btcpp
    verbose: bool = False
    follow_symlinks: bool = False  # --fix rewrites files linked from outside the folder
    min_severity: Severity | None = None  # --min-severity (None: the configuration's)
    quiet: bool = False  # --quiet: the diagnostics and errors only
    output_format: OutputFormat = "concise"  # --output-format (text only)
    color: bool = False  # colour the text output (--color, NO_COLOR, FORCE_COLOR)
    statistics: bool = False  # --statistics: a count per code instead of the diagnostics
    force_exclude: bool = False  # --force-exclude: a walk's exclusions for named files too
    started: float = field(default_factory=time.time)  # older temporaries are stale


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


def check_file(
    path: str,
    options: Options,
    project: ProjectIndex | None = None,
    before: Mapping[Path, Document] | None = None,
    keep: str | None = None,
    planned: Planned | None = None,
) -> FileResult:
    """Read, analyze and (with ``options.fix``) fix one file, in ``project`` if given;
    ``before`` are the workspace's documents before any file was fixed; ``keep`` says why
    the file must not be rewritten, if it must not.  ``planned``: what the fix of the whole
    workspace did to the file (:func:`bt_lsp.cli.fix_workspace.fix_files`), reported as
    it is."""
    result = FileResult(path)
    if planned is not None:
        return _planned_result(result, planned, options, project)
    try:
        decoded = read_text(path, options.max_bytes)
    except FileError as e:
        result.error = e
        return result
    try:
        # The workspace has usually read the file already (for the other files' sake).
        shared = project.documents.read_document(normalize(path), decoded.text) if project else None
        doc = shared if shared is not None else Document(decoded.text, path)
        if Path(path).suffix in CPP_SUFFIXES:  # the name rules where names are born
            facts = Scanner().facts(path, decoded.text.encode("utf-8", "surrogatepass"))
            diags = with_severities(cpp_name_diagnostics(facts, decoded.text), options.severities)
            result.findings = findings_of(path, doc, diags)
            result.text = doc.text
            return result
        raw = file_diagnostics(doc, project)
        # The workspace's settings for the file hold the flags' severities over its
        # configuration file's.
        severities = (
            options.severities
            if project is None
            else project.settings_for(normalize(path)).severity
        )
        diags = with_severities(raw, severities)
        if options.fix:
            me = normalize(path)
            others = {str(p): d for p, d in (before or {}).items() if p != me}
            outcome = fix_document(
                decoded, doc, raw, diags, project, others, unsafe=options.unsafe_fixes
            )
            if isinstance(outcome, str):
                result.not_fixed = outcome
            elif outcome is not None and keep is not None:
                result.not_fixed = keep
            elif outcome is not None:
                write_text_atomic(
                    path, outcome.doc.text, decoded.encoding, decoded.bom, expect=decoded.stamp
                )
                if project is not None:
                    project.file_changed(path)
                fixed_diags = with_severities(outcome.raw, severities)
                result.fixed = max(len(diags) - len(fixed_diags), 0)
                result.notes = outcome.notes
                doc, diags = outcome.doc, fixed_diags
        result.findings = findings_of(path, doc, diags, _fixable(doc, options, project))
        result.text = doc.text
    except FileError as e:
        result.not_fixed = e.message
        result.unwritten = True
        result.findings = findings_of(path, doc, diags)
        result.text = doc.text
    except Exception as e:
        result.detail = traceback.format_exc()
        result.error = FileError(
            path, f"internal error while checking {path}: {type(e).__name__}: {e}"
        )
    return result


def _fixable(
    doc: Document, options: Options, project: ProjectIndex | None
) -> Callable[[Diagnostic], bool] | None:
    """Which diagnostics a fix fixes, for ``--statistics`` (not worked out otherwise)."""
    return fixability(doc, project, options.unsafe_fixes) if options.statistics else None


def _planned_result(
    result: FileResult, planned: Planned, options: Options, project: ProjectIndex | None
) -> FileResult:
    """The result of a file that the fix of the whole workspace handled."""
    doc, diags = planned.doc, planned.diags
    outcome = planned.outcome
    result.notes = list(planned.notes)
    if isinstance(outcome, str):
        result.not_fixed = outcome
        result.unwritten = planned.unwritten
    elif outcome is not None:
        fixed_diags = with_severities(outcome.raw, planned.severities)
        result.fixed = max(len(diags) - len(fixed_diags), 0)
        doc, diags = outcome.doc, fixed_diags
    result.findings = findings_of(result.path, doc, diags, _fixable(doc, options, project))
    result.text = doc.text
    return result


# -- running -----------------------------------------------------------------------------


def _remove_stale_temporaries(files: Sequence[str], before: float) -> list[str]:
    """Remove the temporary files an interrupted ``--fix`` left beside ``files`` (those
    older than this run); returns them."""
    removed: list[str] = []
    for directory in sorted({os.path.dirname(os.path.realpath(f)) for f in files}):
        for tmp in stale_temporaries(directory, before):
            try:
                os.unlink(tmp)
            except OSError:
                continue
            removed.append(tmp)
    return removed


def _linked_from_outside(path: str, roots: Sequence[str]) -> str | None:
    """Why ``path``, found in one of the folders ``roots``, is not rewritten: it leads
    through a symbolic link to a file outside that folder (``None`` if it does not)."""
    here = os.path.abspath(path)
    real = os.path.realpath(path)
    for root in roots:
        top = os.path.abspath(root)
        if os.path.commonpath([here, top]) != top:
            continue
        real_top = os.path.realpath(root)
        if os.path.commonpath([real, real_top]) != real_top:
            return (
                f"it is a symbolic link to {real}, outside {root} "
                "(--follow-symlinks rewrites such files)"
            )
    return None


def write(stream: TextIO, text: str) -> None:
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
        shown_path = visible(path)
        if len(shown_path) > room:
            shown_path = "..." + shown_path[-max(room - 3, 0) :] if room > 3 else ""
        self.line(line + shown_path)

    def line(self, line: str) -> None:
        """Draw ``line`` in place of the last one (the C++ scan's ``reading C++: 3/40``)."""
        if not self.enabled:
            return
        pad = " " * max(self._shown - len(line), 0)
        write(self.stream, f"\r{line}{pad}")
        self.stream.flush()
        self._shown = len(line) + len(pad)

    def clear(self) -> None:
        if self.enabled and self._shown:
            write(self.stream, "\r" + " " * self._shown + "\r")
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
    # The folders named on the command line are the workspace: includes resolve as
    # BehaviorTree.CPP resolves them, and every file's models and trees are known.
    project = project_index(paths, options)
    if options.cpp:
        project.cpp = CppModels(project.roots, project.packages)
    skipped: Counter[str] = Counter()
    not_bt: set[str] = set()  # kept by the walk until the includes are known

    def skip(path: str, is_dir: bool) -> bool:
        why = skip_reason(project, path, is_dir)
        if why == NOT_BT:
            not_bt.add(path)
            return False
        if why is not None:
            skipped[why] += 1
        return why is not None

    given = paths
    forced: set[str] = set()  # the named files that content alone may leave out
    if options.force_exclude:
        paths, forced = _force_exclude(paths, project, skipped)
    files, walk_errors = collect_files(paths, skip)
    named = {os.path.realpath(p) for p in paths if not os.path.isdir(p)}  # checked as given
    not_bt = {p for p in not_bt if os.path.realpath(p) not in named} | forced
    # A named file is checked if a file of its workspace includes it, as in a walk over
    # the workspace; a walk's own files are the others it knows.
    includers = [*files, *(str(p) for p, _ in project.bt_documents())] if forced else files
    not_bt -= included_back(project, includers, not_bt)
    if not_bt:
        skipped[NOT_BT] += len(not_bt)
        files = [f for f in files if f not in not_bt]
    if options.cpp:
        files += [str(f) for p in paths if os.path.isdir(p) for f in find_cpp_files([p])]
    progress = Progress(
        err,
        len(files),
        options.progress and not options.quiet and len(files) > 1 and _isatty(err),
    )
    if project.cpp is not None and progress.enabled:
        # The C++ is read when the first file of a package needs it: say so meanwhile.
        project.cpp.progress = lambda done, total: progress.line(
            f"reading C++: {done}/{total} files"
        )

    def say(stream: TextIO, text: str) -> None:
        progress.clear()
        write(stream, text)
        stream.flush()

    # A configuration file that cannot be used is reported (exit status 2) and the files
    # are checked without it; none is fixed, as its excludes and settings are not known.
    configs = [config_result(ce, _config_text(ce.path)) for ce in config_errors(project, files)]
    for ce in configs:
        f = ce.findings[0]
        say(err, f"{visible(f.path)}:{f.line}:{f.column}: error config-error {f.message}\n")
    if configs and options.fix:
        say(err, "bt-lsp: not fixing any file: a configuration file cannot be used\n")
        options = replace(options, fix=False)
    for e in walk_errors:
        say(err, f"bt-lsp: {e.message}\n")
    if not files and not configs:
        # --force-exclude leaving out every file it was given (a pre-commit hook run on
        # package.xml) is no mistake: nothing is said.
        all_left_out = options.force_exclude and not any(os.path.isdir(p) for p in given)
        none = "no BehaviorTree.CPP XML files" if skipped else "no XML files"
        if options.verbose:
            _skipped_lines(skipped, say, err)
        if not options.quiet and not all_left_out:
            say(err, f"bt-lsp: {none} to check\n")
        if options.format != "text":  # still a document a reader can parse
            _report(out, options.format, [FileResult(e.path, error=e) for e in walk_errors])
        return 2 if walk_errors else 0

    if options.verbose:
        _skipped_lines(skipped, say, err)
        for line in workspace_lines(paths):
            say(err, line + "\n")
        for line in version_lines(project, [f for f in files if f.endswith(".xml")]):
            say(err, line + "\n")
    results: list[FileResult] = [*configs, *(FileResult(e.path, error=e) for e in walk_errors)]
    style = Style(color=options.color)
    # What fixes see of the other files: the workspace before any file is fixed.
    before = dict(project.bt_documents()) if options.fix else None
    roots = [p for p in paths if os.path.isdir(p)]
    if options.fix:
        for tmp in _remove_stale_temporaries(files, options.started):
            if not options.quiet:
                say(err, f"bt-lsp: removed {visible(tmp)}, left by an interrupted --fix\n")

    def keep_of(path: str) -> str | None:
        linked = None if options.follow_symlinks else _linked_from_outside(path, roots)
        return linked or not_replaceable(path)  # read-only, hard links

    # Every rename of --fix in all the files it touches, or in none (see fix_workspace).
    planned = (
        fix_files(files, project, options.max_bytes, keep_of, options.unsafe_fixes)
        if options.fix
        else {}
    )
    for i, path in enumerate(files, 1):
        progress.show(i, path)
        keep = keep_of(path)
        r = check_file(path, options, project, before, keep, planned.get(str(normalize(path))))
        r.findings = shown(r.findings, project.settings_for(normalize(path)).min_severity)
        results.append(r)
        if r.error is not None:
            say(err, f"{r.detail}bt-lsp: {r.error.message}\n")
        if r.not_fixed is not None:
            say(err, f"bt-lsp: not fixing {visible(path)}: {r.not_fixed}\n")
        if r.fixed and not options.quiet:
            say(err, f"fixed {plural(r.fixed, 'problem')} in {visible(path)}\n")
        for note in r.notes if not options.quiet else ():
            say(err, f"bt-lsp: {visible(path)}: {visible(note)}\n")
        if options.format == "text" and r.findings and not options.statistics:
            source = _LINE_BREAK.split(r.text) if options.output_format == "full" else None
            lines = format_text(r.findings, style, source)
            say(out, "".join(line + "\n" for line in lines))
    progress.clear()

    if options.format != "text":
        _report(out, options.format, results)
    elif options.statistics:
        summaries = {code: c.summary.replace("`", "") for code, c in CODES.items()}
        table = statistics((f for r in results for f in r.findings), summaries, style)
        if table:
            say(out, "".join(line + "\n" for line in table))
        if not options.quiet:
            say(err, summary(results) + "\n")
    elif not options.quiet:
        text = summary([r for r in results if not r.config])
        if configs:
            text += f"; {plural(len(configs), 'configuration file')} could not be used"
        say(err, text + "\n")
    return exit_code(results)


def _force_exclude(
    paths: Sequence[str], project: ProjectIndex, skipped: Counter[str]
) -> tuple[list[str], set[str]]:
    """``--force-exclude``: the paths less the named files that a walk over their
    workspace folder would leave out (counted in ``skipped``), and the named files kept
    that are not BehaviorTree.CPP XML by their content (left out unless a file of the
    workspace includes them)."""
    root_of = {f: folder for folder, (_, named) in workspaces(paths).items() for f in named}
    kept: list[str] = []
    not_bt: set[str] = set()
    for p in paths:
        why = None if os.path.isdir(p) else forced_skip_reason(project, p, root_of[p])
        if why is None or why == NOT_BT:
            kept.append(p)
            if why == NOT_BT:
                not_bt.add(p)
        else:
            skipped[why] += 1
    return kept, not_bt


def _skipped_lines(skipped: Counter[str], say: Callable[[TextIO, str], None], err: TextIO) -> None:
    """For ``--verbose``: how many folders and files were left out, and why."""
    for why, n in sorted(skipped.items()):
        what = "folder" if why == BUILD_FOLDER else "file"
        say(err, f"bt-lsp: skipped {n} {what}{'s' if n != 1 else ''}: {why}\n")


def _report(out: TextIO, format: Format, results: Sequence[FileResult]) -> None:
    """The JSON or SARIF document of ``results`` on ``out``."""
    document = to_json(results) if format == "json" else to_sarif(results)
    write(out, json.dumps(document, indent=2) + "\n")
    out.flush()


def _config_text(path: Path) -> str | None:
    """A configuration file's text, to place its error (``None`` if it cannot be read)."""
    try:
        return read_head(str(path), MAX_CONFIG_BYTES).decode("utf-8", "replace")
    except FileError:
        return None
