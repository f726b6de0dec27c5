"""The tokens of BT XML as the scanner makes them (:mod:`bt_lsp.syntax.scanner`): their
kinds, the attributes of a start tag and the lexical problems found in them.  Offsets are
relative to the token's start, so a token reused after an edit is shared unchanged."""

from __future__ import annotations

from enum import IntEnum
from typing import NamedTuple


class Kind(IntEnum):
    TEXT = 0
    START = 1  # start tag or empty-element tag
    END = 2  # end tag
    COMMENT = 3
    CDATA = 4
    PI = 5  # processing instruction or XML declaration
    DOCTYPE = 6
    STRAY = 7  # a '<' that starts no markup


XML_SYNTAX = "xml-syntax"
EXTRA_ROOT = "xml-extra-root"
LENIENT = "xml-lenient"
UNESCAPED = "xml-unescaped-char"
DOCTYPE_CODE = "xml-doctype"


class Problem(NamedTuple):
    """A lexical problem; offsets relative to the token start."""

    start: int
    end: int
    code: str
    message: str


class Attr(NamedTuple):
    """An attribute; offsets relative to the token start.

    ``value_start``/``value_end`` delimit the raw value between the quotes (entity
    references included).  ``value`` is the decoded value, ``None`` when the attribute
    has no value at all.
    """

    name: str
    name_start: int
    name_end: int
    value: str | None
    value_start: int
    value_end: int
    quote: str


class Token(NamedTuple):
    """A token; offsets relative to its start.  Tokens, attributes and problems are named
    tuples: immutable, small and quick to make (a document has tens of thousands).  Equal
    tokens may be one object (whitespace runs and end tags are shared)."""

    kind: Kind
    length: int
    reach: int  # how far (from the token start) the scan looked; >= length
    name: str = ""
    name_start: int = 0
    name_end: int = 0
    attrs: tuple[Attr, ...] = ()
    self_closing: bool = False
    closed: bool = True
    problems: tuple[Problem, ...] = ()
