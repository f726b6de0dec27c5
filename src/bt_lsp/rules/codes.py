"""What a diagnostic code is, and how a rule defines one.

A code's name, default severity, one-line summary (the README row), the titles of its
fixes and the function that makes them (``fixer``) are defined with :func:`define` in the
module of the rule that reports it, beside the rule's messages;
:mod:`bt_lsp.rules.registry` imports every such module and is the one table of all codes
(the README's code table, the server's ``codeDescription`` links and the severity
settings read it).  Codes are stable once released (see CHANGELOG.md).

Each code has a page on the documentation site (``docs/rules/<code>.md``, written by
``scripts/docs_gen.py``); the optional prose of :func:`define` (``doc``, ``why``, ``bad``,
``good``, ``since``) is what that page says beyond the summary.
"""

from __future__ import annotations

import textwrap
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from enum import Enum, IntEnum
from types import MappingProxyType
from typing import TYPE_CHECKING, Final, TypeAlias

from bt_lsp.syntax.edits import TextEdit

if TYPE_CHECKING:
    from bt_lsp.rules.context import Context
    from bt_lsp.rules.diagnostics import Diagnostic
    from bt_lsp.syntax.document import Document

#: The documentation site (MkDocs, ``mkdocs.yml``, published as the project's GitHub Pages);
#: every code's page is ``rules/<code>/`` under it (:attr:`Code.url`).
DOCS_URL: Final = "https://bt-lsp.github.io/bt-lsp/"


class Severity(IntEnum):
    """Values match LSP's ``DiagnosticSeverity``."""

    ERROR = 1
    WARNING = 2
    INFORMATION = 3
    HINT = 4

    @property
    def label(self) -> str:
        return self.name.lower()

    @classmethod
    def parse(cls, word: str) -> Severity | None:
        """A severity word from the settings; ``None`` for ``'off'``."""
        word = word.strip().lower()
        if word == "info":
            word = "information"
        for member in cls:
            if member.label == word:
                return member
        if word == "off":
            return None
        raise ValueError(f"unknown severity {word!r}")


class Applicability(Enum):
    """Whether a fix may be applied without the author looking at it, as ruff classifies
    fixes.

    * ``SAFE``: it cannot change what BehaviorTree.CPP loads and runs beyond removing the
      problem it fixes, and where the file fails to load there is exactly one thing it can
      have meant.  The editor's preferred fix, fix-all and ``check --fix`` apply it.
    * ``UNSAFE``: very likely right, but it changes what loads or runs (a typo guess that a
      node registered in C++ bt-lsp did not see could make wrong, a placeholder value, a new
      tree).  Offered in the editor marked "(unsafe)"; ``check --unsafe-fixes`` applies it.
    * ``DISPLAY_ONLY``: a suggestion for the author to judge case by case (declaring a
      model, renaming a name also registered in C++, giving a port that may be optional).
      Offered in the editor marked "(unsafe)"; never applied in bulk.
    """

    SAFE = "safe"
    UNSAFE = "unsafe"
    DISPLAY_ONLY = "display-only"


@dataclass(frozen=True, slots=True)
class FixSpec:
    """One fix of a code: its title (a :meth:`str.format` template), its class, and when
    it is offered where the code has several fixes of one title (for its page)."""

    title: str
    applicability: Applicability
    when: str = ""


def safe(title: str, when: str = "") -> FixSpec:
    """A fix that ``check --fix``, fix-all and the editor's preferred fix apply."""
    return FixSpec(title, Applicability.SAFE, when)


def unsafe(title: str, when: str = "") -> FixSpec:
    """A fix that only ``check --unsafe-fixes`` applies in bulk."""
    return FixSpec(title, Applicability.UNSAFE, when)


def display_only(title: str, when: str = "") -> FixSpec:
    """A fix offered in the editor only, one at a time."""
    return FixSpec(title, Applicability.DISPLAY_ONLY, when)


@dataclass(frozen=True, slots=True)
class FixEdits:
    """One fix a rule's ``fixer`` makes for one of its diagnostics: the key of the fix in
    the code's ``fixes`` (its title and class), the edits of the document, and the values
    the title names (``Replace <{element}> with its child``: ``element``)."""

    key: str
    edits: tuple[TextEdit, ...]
    values: Mapping[str, object] = field(default_factory=lambda: MappingProxyType({}))


#: What makes the fixes of a code's diagnostic, beside its rule: pure, from the document,
#: its context and the diagnostic (the editor asks for them when the diagnostic is shown;
#: fix-all and ``check --fix`` take the first safe one).
Fixer: TypeAlias = "Callable[[Document, Context, Diagnostic], Sequence[FixEdits]]"


@dataclass(frozen=True, slots=True, eq=False)
class Code:
    """One diagnostic code.  ``fixes`` are its quick fixes by key: each a title (a
    :meth:`str.format` template, see :meth:`fix_title`) and whether it is safe (see
    :class:`Applicability`): the one place a fix's class is defined.  The rest is the prose of the
    code's documentation page, each part optional (Markdown; ``bad`` and ``good`` are XML):
    what BehaviorTree.CPP does, why it matters, a document that gets the diagnostic and the
    same document fixed, and the BehaviorTree.CPP versions the rule applies to."""

    code: str
    severity: Severity
    summary: str
    family: str
    fixes: Mapping[str, FixSpec] = field(default_factory=lambda: MappingProxyType({}))
    doc: str = ""
    why: str = ""
    bad: str = ""
    good: str = ""
    since: str = ""
    fixer: Fixer | None = None

    @property
    def url(self) -> str:
        """The code's page on the documentation site (the ``codeDescription`` link)."""
        return f"{DOCS_URL}rules/{self.code}/"

    def fix_title(self, fix: str, **values: object) -> str:
        """The title of the fix ``fix`` with ``values`` filled in."""
        return self.fixes[fix].title.format(**values)

    def applicability(self, fix: str) -> Applicability:
        """Whether the fix ``fix`` is safe, unsafe or offered in the editor only."""
        return self.fixes[fix].applicability

    @property
    def has_safe_fix(self) -> bool:
        """Whether fix-all and ``check --fix`` may fix a diagnostic of this code."""
        return any(f.applicability is Applicability.SAFE for f in self.fixes.values())


class FixData:
    """What a diagnostic tells its quick fixes, typed per rule (a frozen dataclass beside
    the rule).  The server publishes it as the LSP diagnostic's ``data``
    (:meth:`as_json`)."""

    __slots__ = ()

    def as_json(self) -> dict[str, object]:
        raise NotImplementedError


#: The families of the README's code table.
NAMES = "names"
XML = "xml"
BT = "behaviortree"
PROJECT = "project"

# Every code defined so far, by name (the registry imports every module that defines one,
# then calls freeze(): a read-only view from then on).
_DEFINED: Mapping[str, Code] = {}


def define(
    code: str,
    severity: Severity,
    summary: str,
    family: str,
    *,
    fixes: Mapping[str, FixSpec] | None = None,
    doc: str = "",
    why: str = "",
    bad: str = "",
    good: str = "",
    since: str = "",
    fixer: Fixer | None = None,
) -> Code:
    """Define (and register) a code; a name defined twice is a programming error, and so
    is a code defined once the registry is complete (after :func:`freeze`).  The prose
    (``doc`` … ``since``, see :class:`Code`) is optional: without it the code's page says
    the summary.  ``fixer`` makes the fixes that ``fixes`` titles (see :data:`Fixer`)."""
    table = _DEFINED
    if not isinstance(table, dict):
        raise RuntimeError(
            f"diagnostic code {code!r} is defined after the registry was complete:"
            " import its module from bt_lsp.rules.registry"
        )
    if code in table:
        raise ValueError(f"diagnostic code {code!r} is defined twice")
    if fixer is not None and not fixes:
        raise ValueError(f"diagnostic code {code!r} has a fixer but no fixes= to title them")
    found = table[code] = Code(
        code,
        severity,
        summary,
        family,
        MappingProxyType(dict(fixes or {})),
        doc=_dedent(doc),
        why=_dedent(why),
        bad=_dedent(bad),
        good=_dedent(good),
        since=since.strip(),
        fixer=fixer,
    )
    return found


def _dedent(text: str) -> str:
    """Prose written as an indented triple-quoted string, without its indentation."""
    return textwrap.dedent(text).strip()


def freeze() -> None:
    """Make the registry read-only: every module that defines a code was imported
    (:mod:`bt_lsp.rules.registry` calls it once it imported them all)."""
    global _DEFINED
    if isinstance(_DEFINED, dict):
        _DEFINED = MappingProxyType(dict(_DEFINED))


def defined(code: str) -> Code:
    """The definition of ``code``; its rule's module is imported wherever it is reported."""
    return _DEFINED[code]


def all_defined() -> Mapping[str, Code]:
    """Every code defined so far (see :mod:`bt_lsp.rules.registry` for all of them)."""
    table = _DEFINED
    return MappingProxyType(table) if isinstance(table, dict) else table
