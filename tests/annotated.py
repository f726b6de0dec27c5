"""Annotated fixtures: the expected diagnostics written under the text they cover.

An annotation is a line of its own, an XML comment right under the line it speaks of::

    <BehaviorTree ID="Main Tree">
    <!--              ^^^^^^^^^ error model-name-forbidden-char: ... -->

The carets stand under the characters of the range (columns count code points); a ``|``
marks an empty range at its column.  A range that starts left of the comment's own
``<!--``, or spans lines, is written ``@C-E`` (columns of the line above, end exclusive)
or ``@L:C-L:C`` (0-based lines and columns of the text without its annotations).  Then
the severity, the code, and after ``:`` the message exactly (without one, the message is
not checked); ``{root}`` in a message
stands for the folder the files of a fixture are written to (the path after it written
with ``/`` on every system), ``{not-found}`` for the operating system's words for a
missing file, ``{size}`` for the size of the text in bytes (which its line ends change).

Annotation lines are removed (with their line ends) before the text is analysed, so they
never shift what they annotate.  :func:`check` compares every diagnostic of the text,
none left out, with LF and again with CRLF line ends: every diagnostic of the codes the
whole-output tests know (:mod:`tests.pinned`), of the codes the fixture annotates and of
the code it is named after, so that a rule added later does not change a fixture written
for another.  A fixture of several files
separates them with ``<!-- file: trees/dock.xml -->`` lines; each is written to a fresh
folder, analysed in a workspace of all of them, and checked against its own annotations.

Directives (lines of their own): ``<!-- check: max-diagnostics=N -->`` limits the report
as the server and the check command do at their maximum; ``<!-- check:
max-document-bytes=N -->`` analyses the text as the server does a document above its
size limit.

A ``bt-lsp.toml`` (or ``pyproject.toml``) among the files is the configuration of the
others; its annotations are its ``config-error``, if it has one.

A one-file fixture may end with the result of a quick fix: a ``<!-- fixed: TITLE -->``
line, then the whole document once the first fix called ``TITLE`` is applied
(:func:`split_fixed`; several such sections, one per fix).
"""

from __future__ import annotations

import errno
import os
import re
import tempfile
from collections.abc import Collection
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Final

from bt_lsp.ide.fix import Fix
from bt_lsp.ide.name_fixes import fixes_for_name
from bt_lsp.ide.name_targets import with_targets
from bt_lsp.ide.semantic_fixes import fixes_for_rule
from bt_lsp.project.config import CONFIG_NAMES, ConfigError
from bt_lsp.project.index import ProjectIndex, normalize
from bt_lsp.project.settings import Settings
from bt_lsp.rules.analysis import analyze
from bt_lsp.rules.context import Context
from bt_lsp.rules.diagnostics import Diagnostic, limited, size_limited
from bt_lsp.syntax.document import Document
from bt_lsp.syntax.edits import apply_edits
from tests.pinned import pinned

_LINE_END = re.compile(r"\r\n|\r|\n")
_ANNOTATION = re.compile(
    r"<!--(?P<marks> *(?:\^+|\||@\d+-\d+|@\d+:\d+-\d+:\d+)) "
    r"(?P<severity>error|warning|information|hint) (?P<code>[a-z0-9-]+)"
    r"(?:: (?P<message>.*?))? *-->"
)
# What operating systems say of a missing file: C's strerror(ENOENT), and Windows's own
# words where Python reports a Windows error.
_NOT_FOUND_REASONS = (
    os.strerror(errno.ENOENT),
    "The system cannot find the file specified",
    "The system cannot find the path specified",
)
_UNDER_ROOT = re.compile(r"\{root\}[^\s:'\")]*")
_FILE = re.compile(r"<!-- file: (?P<path>\S+) -->")
_DIRECTIVE = re.compile(r"<!-- check: (?P<name>[a-z-]+)=(?P<value>\d+) -->")


@dataclass(frozen=True, slots=True, order=True)
class Expected:
    """A diagnostic by 0-based line and column (code points) of its start and end."""

    start: tuple[int, int]
    end: tuple[int, int]
    severity: str
    code: str
    message: str


@dataclass(frozen=True, slots=True)
class Fixture:
    """One file of a fixture: its text (LF line ends) and what it must report."""

    path: str
    text: str
    expected: list[Expected]
    directives: dict[str, int]


def _lines(text: str) -> list[str]:
    """The lines of ``text`` without their ends (XML's three line ends)."""
    return _LINE_END.split(text)


def parse(fixture: str, path: str = "fixture.xml") -> Fixture:
    """The text of a one-file fixture without its annotations, and its expectations."""
    kept: list[str] = []
    expected: list[Expected] = []
    directives: dict[str, int] = {}
    for line in _lines(fixture):
        d = _DIRECTIVE.fullmatch(line.strip())
        if d is not None:
            directives[d["name"]] = int(d["value"])
            continue
        m = _ANNOTATION.fullmatch(line)
        if m is None:
            kept.append(line)
            continue
        assert kept, f"an annotation with no line above it: {line!r}"
        row = len(kept) - 1
        marks = m["marks"]
        first = line.index(marks.strip()[0], 4)
        body = marks.strip()
        if body.startswith("@") and ":" in body:
            a, b = body[1:].split("-")
            sl, sc = map(int, a.split(":"))
            el, ec = map(int, b.split(":"))
            start, end = (sl, sc), (el, ec)
        elif body.startswith("@"):
            sc, ec = map(int, body[1:].split("-"))
            start, end = (row, sc), (row, ec)
        elif body == "|":
            start = end = (row, first)
        else:
            start, end = (row, first), (row, first + len(body))
        expected.append(Expected(start, end, m["severity"], m["code"], m["message"] or ""))
    return Fixture(path, "\n".join(kept), sorted(expected), directives)


_FIXED: Final = re.compile(r"<!-- fixed: (?P<title>.+) -->")


def split_fixed(fixture: str) -> tuple[str, list[tuple[str, str]]]:
    """The fixture before its first ``<!-- fixed: TITLE -->`` line, and each such section
    as (``TITLE``, the document it holds), each text ending with one line end."""
    head: list[str] = []
    sections: list[tuple[str, list[str]]] = []
    for line in _lines(fixture):
        m = _FIXED.fullmatch(line.strip())
        if m is not None:
            sections.append((m["title"], []))
        else:
            (sections[-1][1] if sections else head).append(line)

    def text(lines: list[str]) -> str:
        return "\n".join(lines).rstrip("\n") + "\n"

    return text(head) if sections else fixture, [(t, text(ls)) for t, ls in sections]


def split_files(fixture: str) -> list[Fixture]:
    """The files of a fixture (one, ``fixture.xml``, when it has no ``file:`` lines)."""
    parts: list[tuple[str, list[str]]] = []
    for line in _lines(fixture):
        m = _FILE.fullmatch(line.strip())
        if m is not None:
            parts.append((m["path"], []))
        elif parts:
            parts[-1][1].append(line)
        elif line.strip():
            parts.append(("fixture.xml", [line]))
    return [parse("\n".join(lines), path) for path, lines in parts]


def _position(doc: Document, offset: int) -> tuple[int, int]:
    return doc.lines.position(offset, "utf-32")


def found(doc: Document, diags: list[Diagnostic], root: str | None = None) -> list[Expected]:
    """``diags`` of ``doc`` as expectations, written as the annotations write them on any
    system: ``root`` as ``{root}`` (the path after it with ``/``), a missing file's reason
    as ``{not-found}``, the document's size as ``{size}``."""
    out = []
    size = f" {doc.utf8_size} bytes"
    for d in diags:
        message = d.message
        if root is not None:
            message = _UNDER_ROOT.sub(
                lambda m: m.group(0).replace(os.sep, "/"), message.replace(root, "{root}")
            )
            for reason in _NOT_FOUND_REASONS:
                message = message.replace(f": {reason})", ": {not-found})")
        message = message.replace(size, " {size} bytes")
        out.append(
            Expected(
                _position(doc, d.start), _position(doc, d.end), d.severity.label, d.code, message
            )
        )
    return sorted(out)


def _analyze(f: Fixture, text: str, also: Collection[str]) -> tuple[Document, list[Diagnostic]]:
    doc = Document(text)
    limit = f.directives.get("max-document-bytes")
    if limit is not None and doc.utf8_size > limit:
        return doc, pinned(size_limited(doc, limit), also)
    # Pinned before the cap, which then keeps what it kept when the fixture was written.
    diags = pinned(with_targets(doc, analyze(doc)), also)
    maximum = f.directives.get("max-diagnostics")
    return doc, limited(diags, maximum) if maximum is not None else diags


def diagnostics(
    fixture: str, newline: str = "\n", also: Collection[str] = ()
) -> list[tuple[Fixture, list[Expected]]]:
    """Each file of ``fixture`` with what bt-lsp reports for it, its line ends ``newline``:
    the diagnostics of the pinned codes (:mod:`tests.pinned`), of those the fixture
    annotates and of ``also``."""
    files = split_files(fixture)
    also = {e.code for f in files for e in f.expected} | set(also)
    if len(files) == 1 and files[0].path == "fixture.xml":
        f = files[0]
        doc, diags = _analyze(f, f.text.replace("\n", newline), also)
        return [(f, found(doc, diags))]
    out = []
    with tempfile.TemporaryDirectory() as tmp:
        root = Path(tmp).resolve()
        for f in files:
            target = root / f.path
            target.parent.mkdir(parents=True, exist_ok=True)
            target.write_bytes(f.text.replace("\n", newline).encode("utf-8"))
        ws = ProjectIndex([root], Settings())
        for f in files:
            path = normalize(root / f.path)
            if path.name in CONFIG_NAMES:  # a configuration file: its error, if any
                out.append((f, _config_found(ws, path, f.text.replace("\n", newline))))
                continue
            opened = ws.document(path)
            assert opened is not None, f.path
            diags = pinned(ws.diagnostics(path, opened), also)
            out.append((f, found(opened, diags, str(root))))
    return out


def _config_found(ws: ProjectIndex, path: Path, text: str) -> list[Expected]:
    """The ``config-error`` of a configuration file, where the server shows it."""
    loaded = ws.configs.load(path)
    if not isinstance(loaded, ConfigError):
        return []
    row, start, end = loaded.span(text)
    return [Expected((row, start), (row, end), "error", "config-error", loaded.message)]


def check(fixture: str, code: str | None = None) -> None:
    """Assert that bt-lsp reports exactly the annotated diagnostics of ``fixture``, with LF
    and with CRLF line ends (of the codes :func:`diagnostics` compares; ``code``: the code
    the fixture is named after)."""
    for newline in ("\n", "\r\n"):
        for f, got in diagnostics(fixture, newline, [code] if code else []):
            # An annotation without a message leaves the message unchecked.
            unchecked = {(e.start, e.end, e.code) for e in f.expected if not e.message}
            got = sorted(
                replace(g, message="") if (g.start, g.end, g.code) in unchecked else g for g in got
            )
            assert got == f.expected, (
                f"{f.path} ({newline!r} line ends) reports:\n{render(f.text, got)}"
            )


def render(text: str, diags: list[Expected]) -> str:
    """``text`` with ``diags`` written as annotations (the form :func:`parse` reads)."""
    lines = _lines(text)
    under: dict[int, list[str]] = {}
    for d in diags:
        (sl, sc), (el, ec) = d.start, d.end
        tail = f" {d.severity} {d.code}" + (f": {d.message}" if d.message else "") + " -->"
        if sl != el:
            marks = f" @{sl}:{sc}-{el}:{ec}"
            prefix = "<!--"
        elif sc < 4:
            marks = f" @{sc}-{ec}"
            prefix = "<!--"
        else:
            prefix = "<!--" + " " * (sc - 4)
            marks = "^" * (ec - sc) if ec > sc else "|"
        under.setdefault(sl, []).append(prefix + marks + tail)
    out: list[str] = []
    for i, line in enumerate(lines):
        out.append(line)
        out.extend(under.get(i, []))
    return "\n".join(out)


def fixes(doc: Document, also: Collection[str] = ()) -> list[Fix]:
    """Every quick fix offered for the diagnostics of ``doc`` alone, as the server offers
    them (name fixes, then the rule's own), of the pinned codes (:mod:`tests.pinned`) and
    of ``also``."""
    out: list[Fix] = []
    ctx = Context.from_document(doc)
    for d in pinned(analyze(doc), also):
        out += fixes_for_name(doc, d)
        if not d.is_name_rule:
            out += fixes_for_rule(doc, ctx, d)
    return out


def check_fix(before: str, after: str, title: str | None = None, code: str | None = None) -> None:
    """Assert that the fix called ``title`` (by default the first preferred one) turns
    ``before`` into exactly ``after`` (whole texts), with LF and with CRLF line ends.  The
    fixes are those of :func:`fixes`: of the pinned codes and of ``code``."""
    for newline in ("\n", "\r\n"):
        doc = Document(parse(before).text.replace("\n", newline))
        offered = fixes(doc, [code] if code else [])
        chosen = [f for f in offered if (f.title == title if title else f.preferred)]
        assert chosen, f"no fix {title!r} among {[f.title for f in offered]}"
        assert apply_edits(doc.text, list(chosen[0].edits)) == after.replace("\n", newline)
