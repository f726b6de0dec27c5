"""Every diagnostic code bt-lsp emits, with its default severity and README anchor.

This table is the single source for codes: the README's code table, the server's
``codeDescription`` links and the severity settings all read it. Codes are stable once
released.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import IntEnum

DOCS_URL = "https://github.com/bt-lsp/bt-lsp/blob/main/README.md"


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


@dataclass(frozen=True, slots=True)
class Code:
    code: str
    severity: Severity
    summary: str
    family: str

    @property
    def url(self) -> str:
        return f"{DOCS_URL}#{self.code}"


_NAME = "names"
_XML = "xml"
_BT = "behaviortree"

CODES: dict[str, Code] = {
    c.code: c
    for c in (
        # Name rules (the contract's table).
        Code("model-name-empty", Severity.ERROR, "a model name is empty", _NAME),
        Code("model-name-reserved", Severity.ERROR, "a model name is `Root` or `root`", _NAME),
        Code(
            "model-name-forbidden-char",
            Severity.ERROR,
            "a model name contains a forbidden character",
            _NAME,
        ),
        Code("port-name-empty", Severity.ERROR, "a port name is empty", _NAME),
        Code(
            "port-name-leading-digit",
            Severity.ERROR,
            "a port name starts with an ASCII digit",
            _NAME,
        ),
        Code(
            "port-name-reserved",
            Severity.ERROR,
            "a port declared in `<TreeNodesModel>` uses a reserved attribute name",
            _NAME,
        ),
        Code(
            "port-name-forbidden-char",
            Severity.ERROR,
            "a port name contains a forbidden character",
            _NAME,
        ),
        Code(
            "instance-name-control-char",
            Severity.ERROR,
            "an instance name contains a control character",
            _NAME,
        ),
        # XML well-formedness.
        Code("xml-syntax", Severity.ERROR, "the document is not well-formed XML", _XML),
        Code(
            "xml-unescaped-char",
            Severity.WARNING,
            "a raw `&` or `<` in an attribute value (tinyxml2 accepts it, XML does not)",
            _XML,
        ),
        Code(
            "xml-doctype",
            Severity.WARNING,
            "a DOCTYPE; its entities and external DTDs are never expanded or fetched",
            _XML,
        ),
        Code(
            "document-too-large",
            Severity.INFORMATION,
            "analysis limited because the document is larger than the configured maximum",
            _XML,
        ),
        # Includes, resolved by the workspace layer.
        Code(
            "include-not-found",
            Severity.ERROR,
            "an included file does not exist or cannot be read",
            _BT,
        ),
        Code("include-cycle", Severity.ERROR, "files include each other in a cycle", _BT),
    )
}


def code_info(code: str) -> Code:
    return CODES[code]
