"""Replacement names for names that break the rules of :mod:`bt_lsp.rules.names`.

Pure and deterministic; never raises for any ``str``.

Model and port names are also written as XML names (a model as the element name of the
compact form, a port as an attribute name), so a replacement is always a valid XML 1.0
(5th edition) ``Name`` as well as passing every rule. Ports also pass BehaviorTree.CPP's
``IsAllowedPortName`` (first character an ASCII letter), the rule that decides whether an
attribute can be a port at all.

Preferred replacement, by kind:

* **model**: every run of characters that are forbidden or not valid in an XML name
  (whitespace, ``. : < > & " ' / \\ * ? |``, control characters, and also
  ``( ) # ! @ { } + , ; = [ ] $ % ^ ~`` and backtick, non-breaking and ideographic spaces,
  ...) becomes one ``_``, and runs at either end are dropped; no ``_`` is added next to a
  ``_`` or ``-`` the name already has there. Other Unicode is kept: ``Move to Pose (JTC)``
  gives ``Move_to_Pose_JTC``, ``检查 门`` gives ``检查_门``. A result that cannot start an
  XML name (a digit, ``-``, a combining mark) gets the prefix ``_`` (``9 Tree`` gives
  ``_9_Tree``). Reserved names are spelled out: ``Root`` gives ``RootTree``, ``root`` gives
  ``root_tree``. Nothing left (an empty name, or only forbidden characters) gives
  ``Unnamed``.
* **port**: as for models, then leading ``_`` and ``-`` are dropped (``_goal`` gives
  ``goal``, ``__shared_blackboard`` gives ``shared_blackboard``), and a name that still does
  not start with an ASCII letter gets the prefix ``p_`` (``1port`` gives ``p_1port``,
  ``检查`` gives ``p_检查``). A reserved attribute name gets a trailing ``_`` (``name`` gives
  ``name_``). Nothing left gives ``port``.
* **instance**: each run of control characters (ASCII 0-8, 11, 12, 14-31, 127) becomes a
  space when it sits between two non-space characters and is dropped otherwise
  (``test<BEL>bell`` gives ``test bell``). Characters that cannot appear in an XML document
  at all (lone surrogates, U+FFFE, U+FFFF) are dropped the same way. The result may be
  empty: an empty instance name means the model name.

A name that already passes every rule (and for models and ports is a valid XML name, and
for ports an allowed port name) is returned unchanged. Uniqueness: when the result is in
``taken``, ``_2``, ``_3``, ... is appended (to the result without its trailing ``_``), the
first that is not taken wins. ``taken`` should hold the other names in scope, not the name
being replaced. An empty instance name is never suffixed.

The result is plain text: escaping it for an attribute value is the writer's job.
"""

from __future__ import annotations

import re
from collections.abc import Collection, Mapping
from collections.abc import Set as AbstractSet
from types import MappingProxyType
from typing import Final

from bt_lsp.rules.names import (
    RESERVED_MODEL_NAMES,
    RESERVED_PORT_NAMES,
    NameKind,
    check_name,
    is_allowed_port_name,
)
from bt_lsp.syntax.lazyre import LazyPattern

__all__ = ["candidates", "is_xml_name", "sanitize"]

# XML 1.0 (5th edition) productions [4] NameStartChar and [4a] NameChar, as class bodies.
_NAME_START_CHARS: Final = (
    r":A-Z_a-z\xC0-\xD6\xD8-\xF6\xF8-\u02FF\u0370-\u037D\u037F-\u1FFF\u200C-\u200D"
    r"\u2070-\u218F\u2C00-\u2FEF\u3001-\uD7FF\uF900-\uFDCF\uFDF0-\uFFFD\U00010000-\U000EFFFF"
)
_NAME_CHARS: Final = _NAME_START_CHARS + r"\-.0-9\xB7\u0300-\u036F\u203F-\u2040"

# Compiled on first use (each takes milliseconds to compile).
_XML_NAME_RE: Final = LazyPattern(f"[{_NAME_START_CHARS}][{_NAME_CHARS}]*")
_NAME_START_RE: Final = LazyPattern(f"[{_NAME_START_CHARS}]")
# Characters kept in a model or port name: XML name characters except ':' and '.'.
_BAD_RUN_RE: Final = LazyPattern(f"(?:[^{_NAME_CHARS}]|[:.])+")
# Word separators for the alternatives: bad runs, '_' and '-'.
_WORD_SEP_RE: Final = LazyPattern(f"(?:[^{_NAME_CHARS}]|[:._-])+")
# Characters removed from an instance name.
_INSTANCE_BAD_RE: Final = re.compile(r"[\x00-\x08\x0b\x0c\x0e-\x1f\x7f\ud800-\udfff\ufffe\uffff]+")
_ASCII_LETTERS: Final = frozenset("ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz")
_JOINERS: Final = ("_", "-")

_RESERVED_MODEL_REPLACEMENTS: Final[Mapping[str, str]] = MappingProxyType(
    {"Root": "RootTree", "root": "root_tree"}
)
_EMPTY_MODEL: Final = "Unnamed"
_EMPTY_PORT: Final = "port"
_PORT_PREFIX: Final = "p_"
_MODEL_PREFIX: Final = "_"


def is_xml_name(text: str) -> bool:
    """Whether ``text`` is an XML 1.0 (5th edition) ``Name``."""
    return _XML_NAME_RE.fullmatch(text) is not None


def sanitize(name: str, kind: NameKind, taken: Collection[str] = frozenset()) -> str:
    """The preferred replacement for ``name`` (see the module documentation for the rules)."""
    return _unique(_preferred(name, kind), kind, taken)


def candidates(name: str, kind: NameKind, taken: Collection[str] = frozenset()) -> list[str]:
    """Replacements for ``name``, best first; the first is :func:`sanitize`'s.

    Up to two alternatives follow: for models and ports the words of the name joined in
    camel case (the first word as written, the others capitalized) and joined with ``-``;
    for instances the name with its control characters dropped rather than spaced. An
    alternative is listed only when it passes every rule, is not in ``taken`` and differs
    from the ones before it.
    """
    result = [sanitize(name, kind, taken)]
    if kind is NameKind.INSTANCE:
        alternatives = [_INSTANCE_BAD_RE.sub("", name)]
    else:
        words = [word for word in _WORD_SEP_RE.split(name) if word]
        if not words:
            return result
        camel = words[0] + "".join(word[:1].upper() + word[1:] for word in words[1:])
        alternatives = [_preferred(camel, kind), _preferred("-".join(words), kind)]
    for alternative in alternatives:
        if alternative not in result and alternative not in taken and _passes(alternative, kind):
            result.append(alternative)
    return result


def _preferred(name: str, kind: NameKind) -> str:
    if kind is NameKind.INSTANCE:
        return _INSTANCE_BAD_RE.sub(_instance_gap, name)
    text = _join(name)
    if kind is NameKind.PORT:
        text = text.lstrip("_-")
        if not text:
            return _EMPTY_PORT
        if text[0] not in _ASCII_LETTERS:
            text = _PORT_PREFIX + text
        if text in RESERVED_PORT_NAMES:
            text += "_"
        return text
    if not text:
        return _EMPTY_MODEL
    if _NAME_START_RE.match(text) is None:
        text = _MODEL_PREFIX + text
    if text in RESERVED_MODEL_NAMES:
        text = _RESERVED_MODEL_REPLACEMENTS[text]
    return text


def _join(name: str) -> str:
    """``name`` with each run of bad characters turned into one ``_``, trimmed at the ends."""
    if _BAD_RUN_RE.search(name) is None:
        return name
    parts = [part for part in _BAD_RUN_RE.split(name) if part]
    if not parts:
        return ""
    out = [parts[0]]
    for part in parts[1:]:
        if not (out[-1].endswith(_JOINERS) or part.startswith(_JOINERS)):
            out.append("_")
        out.append(part)
    return "".join(out)


def _instance_gap(match: re.Match[str]) -> str:
    text = match.string
    start, end = match.span()
    between_words = (
        start > 0 and end < len(text) and not text[start - 1].isspace() and not text[end].isspace()
    )
    return " " if between_words else ""


def _unique(base: str, kind: NameKind, taken: Collection[str]) -> str:
    if base not in taken or (kind is NameKind.INSTANCE and not base):
        return base
    lookup: Collection[str] = taken if isinstance(taken, AbstractSet) else set(taken)
    stem = base.rstrip("_") or base
    number = 2
    while f"{stem}_{number}" in lookup:
        number += 1
    return f"{stem}_{number}"


def _passes(text: str, kind: NameKind) -> bool:
    if check_name(text, kind, declaration=True):
        return False
    if kind is NameKind.INSTANCE:
        return _INSTANCE_BAD_RE.search(text) is None
    if kind is NameKind.PORT and not is_allowed_port_name(text):
        return False
    return is_xml_name(text)
