"""The ``text`` format: ``path:line:col: severity code message``, one line per
diagnostic (``concise``), or with the source line and a caret under the range after it
(``full``, as ruff's full format); colours on a terminal; and the ``--statistics`` table."""

from __future__ import annotations

import unicodedata
from collections import Counter
from collections.abc import Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass
from typing import Final, Literal

from bt_lsp.cli.results import Finding
from bt_lsp.rules.codes import Severity

OutputFormat = Literal["concise", "full"]
OUTPUT_FORMATS: Final[tuple[OutputFormat, ...]] = ("concise", "full")

# SGR sequences: bold, and a colour per severity (red, yellow, blue, cyan).
_RESET: Final = "\x1b[0m"
_BOLD: Final = "\x1b[1m"
_DIM: Final = "\x1b[2m"
_SEVERITY: Final[dict[Severity, str]] = {
    Severity.ERROR: "\x1b[1;31m",
    Severity.WARNING: "\x1b[1;33m",
    Severity.INFORMATION: "\x1b[1;34m",
    Severity.HINT: "\x1b[1;36m",
}
_TAB: Final = 4  # columns a tab takes in the quoted source line


def visible(text: str) -> str:
    """``text`` on one line with control characters written as ``U+XXXX``, so that a
    message can never move the cursor or change the terminal."""
    if text.isprintable():
        return text
    return "".join(
        f"U+{ord(c):04X}" if unicodedata.category(c) in ("Cc", "Zl", "Zp") else c for c in text
    )


@dataclass(frozen=True, slots=True)
class Style:
    """How findings are written: colours (SGR sequences) or none."""

    color: bool = False

    def paint(self, text: str, sgr: str) -> str:
        return f"{sgr}{text}{_RESET}" if self.color and text else text


def use_color(choice: str, is_tty: bool, env: Mapping[str, str]) -> bool:
    """Whether to colour the text output: ``--color always|never``, else (``auto``) on a
    terminal unless ``NO_COLOR`` is set, or off a terminal when ``FORCE_COLOR`` is
    (https://no-color.org, https://force-color.org; an empty value does not count)."""
    if choice in ("always", "never"):
        return choice == "always"
    if env.get("NO_COLOR"):
        return False
    if env.get("FORCE_COLOR"):
        return True
    return is_tty


def _header(f: Finding, style: Style) -> str:
    where = style.paint(f"{visible(f.path)}:{f.line}:{f.column}:", _BOLD)
    severity = style.paint(f.severity.label, _SEVERITY[f.severity])
    code = style.paint(f.code, _BOLD)
    return f"{where} {severity} {code} {visible(f.message)}"


def _width(c: str) -> int:
    """The columns a character takes in a terminal (wide East Asian characters two)."""
    if c == "\t":
        return _TAB
    if unicodedata.combining(c):
        return 0
    return 2 if unicodedata.east_asian_width(c) in ("W", "F") else 1


def _snippet(f: Finding, source: Sequence[str], style: Style) -> list[str]:
    """The finding's first line of source and a caret under its range (to the end of the
    line when the range goes on), ruff's way: ``3 |     <Fallbak>``."""
    if not 1 <= f.line <= len(source):
        return []
    text = source[f.line - 1]
    start = min(f.column - 1, len(text))
    end = f.end_column - 1 if f.end_line == f.line else len(text)
    end = max(min(end, len(text)), start)
    shown = "".join(" " * _TAB if c == "\t" else visible(c) for c in text)
    before = sum(_width(c) if c.isprintable() or c == "\t" else 6 for c in text[:start])
    under = sum(_width(c) if c.isprintable() or c == "\t" else 6 for c in text[start:end])
    number = str(f.line)
    pad = " " * len(number)
    bar = style.paint("|", _DIM)
    caret = style.paint("^" * max(under, 1), _SEVERITY[f.severity])
    return [
        f"{pad} {bar}",
        f"{style.paint(number, _DIM)} {bar} {shown}",
        f"{pad} {bar} {' ' * before}{caret}",
        f"{pad} {bar}",
    ]


def format_text(
    findings: Iterable[Finding],
    style: Style = Style(),
    source: Sequence[str] | None = None,
) -> Iterator[str]:
    """The lines of ``findings``; with ``source`` (the file's lines), each finding is
    followed by its line of source and a caret under its range (``--output-format full``)."""
    for f in findings:
        yield _header(f, style)
        if source is not None:
            yield from _snippet(f, source, style)


def statistics(
    findings: Iterable[Finding], summaries: Mapping[str, str], style: Style = Style()
) -> list[str]:
    """The ``--statistics`` table, ruff's: one line per code, most frequent first: the
    count, the code, ``[*]`` when a fix the run applies fixes every one of them (``[-]``:
    some), and the code's summary."""
    count: Counter[str] = Counter()
    fixable: Counter[str] = Counter()
    for f in findings:
        count[f.code] += 1
        fixable[f.code] += f.fixable
    if not count:
        return []
    rows = sorted(count.items(), key=lambda item: (-item[1], item[0]))
    n_width = max(len(str(n)) for _, n in rows)
    c_width = max(len(code) for code, _ in rows)
    out: list[str] = []
    for code, n in rows:
        mark = "[*] " if fixable[code] == n else "[-] " if fixable[code] else ""
        shown = style.paint(code.ljust(c_width), _BOLD)
        out.append(f"{str(n).rjust(n_width)}\t{shown}\t{mark}{summaries.get(code, '')}")
    return out
