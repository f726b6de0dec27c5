"""Syntax check for BehaviorTree.CPP's scripting language.

The language is used by ``<Script code>``, ``<ScriptCondition code>``, ``<Precondition if>``
and the ``_skipIf _successIf _failureIf _while _onSuccess _onFailure _onHalted _post``
attributes. :func:`check_script` reports the first syntax error that BehaviorTree.CPP 4.10
(the hand-written tokenizer + Pratt parser that replaced the lexy grammar) would report,
as a code-point range into the script text.

Grammar, as BehaviorTree.CPP 4.10 reads it:

* a script is one or more expressions separated by ``;``; extra ``;`` between statements
  and after the last one are allowed, a leading ``;`` is not; an empty script is an error;
* white space is space, TAB, LF and CR only, anywhere between tokens;
* operands: integers (``42``, ``0x1F``), reals (``3.14``, ``1e3``, ``2.5E-3``), strings in
  single quotes (no escapes; anything but ``'`` inside), ``true``/``false``, identifiers
  (ASCII letter, ``_`` or ``@`` first, then ASCII letters, digits and ``_``: blackboard
  keys, ``@root_keys`` and enum names), and parenthesised expressions;
* prefix operators ``-`` ``!`` ``~``; binary operators ``* /``, ``+ -``, ``..`` (string
  concatenation), ``& | ^``, ``== != < <= > >=`` (chainable), ``&& ||``, the ternary
  ``c ? a : b`` and the assignments ``:= = += -= *= /=``;
* everything else is an error: double quotes, ``%``, ``,``, ``.5``, ``and``/``or``/``not``
  used as operators (they are identifiers), a backslash, non-ASCII characters outside
  strings, numbers with a suffix (``3foo``, ``65.``, ``0x``).

Precedence decides the shape of the tree, never whether a script parses, so the check is
a linear, non-recursive state machine (operand expected / operator expected) with an
explicit stack for ``(`` and ``?``. The messages follow BehaviorTree.CPP's form, e.g.
``Expected operand at position 4 (got '==')``; "position" there is BehaviorTree.CPP's
byte offset into the UTF-8 script, while :class:`ScriptError` offsets are code points.

``legacy=True`` also accepts what the lexy-based parser of BehaviorTree.CPP 4.0-4.9
accepted and 4.10 rejects: ``"double-quoted"`` strings, non-ASCII identifiers and a
backslash-newline line continuation (a backslash followed by any white space, since an XML
parser normalizes a newline inside an attribute value to a space). A caller can check
strictly first and re-check with ``legacy=True`` to tell "breaks with 4.10" from "broken
everywhere".
"""

from __future__ import annotations

import re
from collections.abc import Iterator
from dataclasses import dataclass
from functools import lru_cache
from types import MappingProxyType
from typing import Final

from bt_lsp.rules.names import POSTCONDITIONS, PRECONDITIONS

__all__ = ["CONDITION_ATTRS", "SCRIPT_PORTS", "ScriptError", "check_script", "identifiers"]

#: Attributes whose value is a script on every node.
CONDITION_ATTRS: Final[frozenset[str]] = frozenset((*PRECONDITIONS, *POSTCONDITIONS))
#: Built-in (node type, port) pairs whose value is a script.
SCRIPT_PORTS: Final[frozenset[tuple[str, str]]] = frozenset(
    {("Script", "code"), ("ScriptCondition", "code"), ("Precondition", "if")}
)


@dataclass(frozen=True, slots=True)
class ScriptError:
    """A syntax error: ``code[offset:end]`` is the offending character or token.

    At the end of the script ``offset == end == len(code)``.
    """

    offset: int
    end: int
    message: str


# Token kinds
_ATOM: Final = 0  # number, string, true/false, identifier
_LPAREN: Final = 1
_RPAREN: Final = 2
_QUESTION: Final = 3
_COLON: Final = 4
_SEMI: Final = 5
_BINARY: Final = 6  # every binary operator except '-'
_MINUS: Final = 7  # binary or prefix
_PREFIX: Final = 8  # '!' and '~'
_EOF: Final = 9
_ERROR: Final = 10

_WHITESPACE: Final = frozenset(" \t\n\r")
_DIGITS: Final = frozenset("0123456789")
_HEX_DIGITS: Final = frozenset("0123456789abcdefABCDEF")
_ASCII_LETTERS: Final = frozenset("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ")
_IDENT_START: Final = _ASCII_LETTERS | {"_", "@"}
_IDENT_CHAR: Final = _ASCII_LETTERS | _DIGITS | {"_"}

_TWO_CHAR_OPS: Final = MappingProxyType(
    {
        "..": _BINARY,
        "&&": _BINARY,
        "||": _BINARY,
        "==": _BINARY,
        "!=": _BINARY,
        "<=": _BINARY,
        ">=": _BINARY,
        ":=": _BINARY,
        "+=": _BINARY,
        "-=": _BINARY,
        "*=": _BINARY,
        "/=": _BINARY,
    }
)
_ONE_CHAR_OPS: Final = MappingProxyType(
    {
        "+": _BINARY,
        "-": _MINUS,
        "*": _BINARY,
        "/": _BINARY,
        "&": _BINARY,
        "|": _BINARY,
        "^": _BINARY,
        "~": _PREFIX,
        "!": _PREFIX,
        "<": _BINARY,
        ">": _BINARY,
        "=": _BINARY,
        "?": _QUESTION,
        ":": _COLON,
        "(": _LPAREN,
        ")": _RPAREN,
        ";": _SEMI,
    }
)

_MAX_SHOWN: Final = 24
_WORD_OPERATORS: Final = MappingProxyType({"and": "&&", "or": "||"})
_LITERAL_WORDS: Final = frozenset({"true", "false"})


_IDENT: Final = 11  # an identifier: an operand (_ATOM) the blackboard reads as a name
_SLOW: Final = 12  # not a token of the fast pattern: read by _Checker.slow_token

#: A token: (kind, start, end), and for _ERROR also what is wrong (the position is added
#: after it) and a hint appended after the position.
_Token = tuple[int, int, int] | tuple[int, int, int, str, str]

# The common tokens, white space before them included, read by one C regular expression;
# anything else (a lexical error, a backslash, a non-ASCII character, a double quote) is
# one _SLOW character that _Checker.slow_token reads as the character loop always did.
# Numbers are matched only when valid (possessive, so no shorter prefix matches), with the
# same rules as _Checker.scan_number.
_NUMBER: Final = (
    r"0[xX][0-9a-fA-F]++(?![.A-Za-z0-9_])"
    r"|[0-9]++(?:\.[0-9]++|(?=\.\.)|(?!\.))(?:[eE][+-]?+[0-9]++|(?![eE]))(?![A-Za-z_@])"
)
_FAST_GROUPS: Final = (
    (_IDENT, r"[A-Za-z_@][A-Za-z0-9_]*+{ident_end}"),
    (_ATOM, _NUMBER + r"|'[^']*+'{double_quoted}"),
    (_BINARY, r"\.\.|&&|\|\||==|!=|<=|>=|:=|\+=|-=|\*=|/=|[+*/&|^<>=]"),
    (_MINUS, r"-"),
    (_PREFIX, r"[~!]"),
    (_QUESTION, r"\?"),
    (_COLON, r":"),
    (_LPAREN, r"\("),
    (_RPAREN, r"\)"),
    (_SEMI, r";"),
    (_SLOW, r"[^ \t\n\r]"),
)


def _fast_pattern(legacy: bool) -> re.Pattern[str]:
    alternatives = "|".join(f"({body})" for _, body in _FAST_GROUPS)
    return re.compile(
        "[ \t\n\r]*+(?:"
        + alternatives.format(
            # legacy: an identifier may go on with a non-ASCII letter: the slow path reads it
            ident_end=r"(?![^\x00-\x7f])" if legacy else "",
            double_quoted='|"[^"]*+"' if legacy else "",
        )
        + ")"
    )


_FAST: Final = (_fast_pattern(False), _fast_pattern(True))
#: The token kind of each group of the fast pattern, by group number.
_GROUP_KINDS: Final = (_ERROR, *(kind for kind, _ in _FAST_GROUPS))

# A script of operands and binary operators only (no parentheses and no ternary outside
# strings): a regular language, so one C regular expression tells that it parses, without
# a Python step per token.  It accepts nothing the checker rejects: the tokens are read
# the same (an operator is the longest one, an identifier or number never a shorter
# prefix); any script it does not match (errors, parentheses, ``?``) goes to the checker.
_WS: Final = r"[ \t\n\r]*+"
_OPERAND: Final = rf"(?:[-!~]{_WS})*+(?:[A-Za-z_@][A-Za-z0-9_]*+|{_NUMBER}|'[^']*+')"
_OPERATOR: Final = r"(?>\.\.|&&|\|\||==|!=|<=|>=|:=|\+=|-=|\*=|/=|[-+*/&|^<>=])"
_STATEMENT: Final = rf"{_OPERAND}(?:{_WS}{_OPERATOR}{_WS}{_OPERAND})*+"
_PLAIN_SCRIPT: Final = re.compile(
    rf"{_WS}{_STATEMENT}(?:{_WS};(?:{_WS};)*+{_WS}{_STATEMENT})*+(?:{_WS};)*+{_WS}"
)


# A script the 4.0-4.9 tokenizer reads without a lexical error and without the character
# loop (no backslash, no non-ASCII character outside strings): all of it is tokens of the
# fast pattern.  Each match of _NAMES is then one identifier, after the strings, numbers,
# operators and white space before it, all skipped in C; the last match (no identifier)
# takes what follows the last one, so that no search starts inside a string.
_LEGACY_TOKENS: Final = re.compile(
    r"(?:[ \t\n\r]*+(?:[A-Za-z_@][A-Za-z0-9_]*+(?![^\x00-\x7f])|"
    + _NUMBER
    + r"""|'[^']*+'|"[^"]*+"|\.\.|&&|\|\||[=!<>:+*/-]=|[-+*/&|^<>=~!?:();]))*+[ \t\n\r]*+"""
)
_NAMES: Final = re.compile(
    r"""(?:'[^']*+'|"[^"]*+"|"""
    + _NUMBER
    + r"""|[^A-Za-z_@'"0-9]++)*+(?:([A-Za-z_@][A-Za-z0-9_]*+)|\Z)"""
)


def check_script(code: str, *, legacy: bool = False) -> ScriptError | None:
    """The first syntax error in ``code``, or ``None`` if BehaviorTree.CPP parses it.

    ``code`` is the decoded attribute value (XML entities already replaced). Never raises;
    time and memory are linear in ``len(code)``.
    """
    if _PLAIN_SCRIPT.fullmatch(code):
        return None  # the common case, read in C (the legacy parser accepts it too)
    try:
        return _Checker(code, legacy).run()
    except Exception as exc:  # pragma: no cover - defensive: a checker must never crash
        return ScriptError(0, len(code), f"Internal error while checking the script: {exc}")


def identifiers(code: str) -> tuple[list[tuple[int, int]], int]:
    """The identifier tokens of ``code`` as code-point spans, and how far ``code`` could be
    tokenized: ``len(code)``, or the offset of the lexical error where BehaviorTree.CPP
    stops reading it (what follows is unknown).

    Identifiers are what the grammar reads as names: blackboard keys, ``@root`` keys and
    enum names (registered in C++, so no syntax tells them from keys).  The literals
    ``true`` and ``false`` are left out, and nothing inside a string is ever an identifier.
    ``code`` is tokenized as the 4.0-4.9 parser reads it, a superset of 4.10: a
    double-quoted string stays one string and a non-ASCII letter stays inside its
    identifier, so neither is split into identifiers that are not there.
    """
    if _LEGACY_TOKENS.fullmatch(code):
        names = _NAMES.finditer(code)
        return [
            m.span(1) for m in names if (word := m.group(1)) and word not in _LITERAL_WORDS
        ], len(code)
    checker = _Checker(code, True)
    found: list[tuple[int, int]] = []
    for token in checker.tokens():
        kind = token[0]
        if kind == _IDENT:
            if code[token[1] : token[2]] not in _LITERAL_WORDS:
                found.append((token[1], token[2]))
        elif kind == _EOF:
            return found, len(code)
        elif kind == _ERROR:
            return found, token[1]
    return found, len(code)  # pragma: no cover - tokens() always ends with _EOF


_WORD: Final = re.compile(r"[A-Za-z_@][A-Za-z0-9_]*+")


@lru_cache(maxsize=64)
def _word_pattern(word: str) -> re.Pattern[str]:
    """Like :data:`_NAMES`, but every identifier other than ``word`` is skipped in C too."""
    w = re.escape(word)
    return re.compile(
        r"""(?:'[^']*+'|"[^"]*+"|"""
        + _NUMBER
        + rf"""|[^A-Za-z_@'"0-9]++|(?!{w}(?![A-Za-z0-9_]))[A-Za-z_@][A-Za-z0-9_]*+)*+"""
        + rf"(?:({w})(?![A-Za-z0-9_])|\Z)"
    )


@lru_cache(maxsize=8)  # a hover finds the key under the cursor, then its uses
def identifier_spans(code: str, word: str) -> tuple[tuple[tuple[int, int], ...], int]:
    """The spans of :func:`identifiers` of ``code`` that are ``word``, and how far ``code``
    could be tokenized.  A script of 200,000 statements has 200,000 identifiers: a lookup
    of one key finds its few in C instead of making a span of each."""
    if word in _LITERAL_WORDS:
        return (), _tokenized(code)
    if _WORD.fullmatch(word) and _LEGACY_TOKENS.fullmatch(code):
        found = _word_pattern(word).finditer(code)
        return tuple(m.span(1) for m in found if m.group(1) is not None), len(code)
    spans, stop = identifiers(code)
    return tuple((s, e) for s, e in spans if code[s:e] == word), stop


def _tokenized(code: str) -> int:
    """How far ``code`` could be tokenized (see :func:`identifiers`)."""
    if _LEGACY_TOKENS.fullmatch(code):
        return len(code)
    return identifiers(code)[1]


class _Checker:
    def __init__(self, code: str, legacy: bool) -> None:
        self.code = code
        self.legacy = legacy

    # -- reporting ---------------------------------------------------------------------

    def position(self, offset: int) -> int:
        """BehaviorTree.CPP's position: the UTF-8 byte offset of ``offset``."""
        return len(self.code[:offset].encode("utf-8", "surrogatepass"))

    def shown(self, token: _Token) -> str:
        if token[0] == _EOF:
            return "end of input"
        text = self.code[token[1] : token[2]]
        if len(text) > _MAX_SHOWN:
            text = text[: _MAX_SHOWN - 3] + "..."
        return "'" + text.replace("\n", "\\n").replace("\r", "\\r").replace("\t", "\\t") + "'"

    def error(self, token: _Token, what: str, extra: str = "") -> ScriptError:
        message = f"{what} at position {self.position(token[1])} (got {self.shown(token)})"
        return ScriptError(token[1], token[2], message + extra)

    def lexical_error(self, token: _Token) -> ScriptError:
        assert len(token) == 5
        _, start, end, problem, hint = token
        return ScriptError(start, end, f"{problem} at position {self.position(start)}{hint}")

    def unclosed(self, token: _Token, stack: list[tuple[int, int]]) -> ScriptError:
        kind, start = stack[-1]
        if kind == _LPAREN:
            return self.error(
                token, "Expected ')'", f"; '(' at position {self.position(start)} is not closed"
            )
        return self.error(
            token, "Expected ':'", f"; '?' at position {self.position(start)} has no ':'"
        )

    # -- parsing -----------------------------------------------------------------------

    def run(self) -> ScriptError | None:
        tokens = self.tokens()
        stack: list[tuple[int, int]] = []  # (_LPAREN or _QUESTION, start offset)
        expect_operand = True
        first = True
        token = next(tokens)
        while True:
            kind = token[0]
            if expect_operand:
                if kind in (_IDENT, _ATOM):
                    expect_operand = False
                elif kind == _LPAREN:
                    stack.append((_LPAREN, token[1]))
                elif kind in (_MINUS, _PREFIX):
                    pass
                elif kind == _ERROR:
                    return self.lexical_error(token)
                elif kind == _EOF and first:
                    return ScriptError(0, len(self.code), "Empty Script")
                else:
                    return self.error(token, "Expected operand")
            elif kind in (_BINARY, _MINUS):
                expect_operand = True
            elif kind in (_SEMI, _EOF):
                if stack:
                    return self.unclosed(token, stack)
                while kind == _SEMI:
                    token = next(tokens)
                    kind = token[0]
                if kind == _EOF:
                    return None
                expect_operand = True
                continue  # the token after the ';' starts the next statement
            elif kind == _ERROR:
                return self.lexical_error(token)
            elif kind == _QUESTION:
                stack.append((_QUESTION, token[1]))
                expect_operand = True
            elif kind == _COLON:
                if not stack or stack[-1][0] != _QUESTION:
                    if stack:
                        return self.unclosed(token, stack)
                    return self.error(token, "Expected ';' or end of script")
                stack.pop()
                expect_operand = True
            elif kind == _RPAREN:
                if not stack:
                    return ScriptError(
                        token[1],
                        token[2],
                        f"Unmatched ')' at position {self.position(token[1])}",
                    )
                if stack[-1][0] != _LPAREN:
                    return self.unclosed(token, stack)
                stack.pop()
            elif stack:
                return self.unclosed(token, stack)
            else:
                word = self.code[token[1] : token[2]]
                hint = f"; use '{_WORD_OPERATORS[word]}' instead" if word in _WORD_OPERATORS else ""
                return self.error(token, "Expected ';' or end of script", hint)
            first = False
            token = next(tokens)

    # -- tokenizing --------------------------------------------------------------------

    def tokens(self) -> Iterator[_Token]:
        """Tokens of ``code``, then ``_EOF`` forever.

        The common tokens come from one regular expression; at any other character the
        character loop of :meth:`slow_token` reads one token, then the expression goes on.
        """
        code = self.code
        n = len(code)
        i = 0
        finditer = _FAST[self.legacy].finditer
        kinds = _GROUP_KINDS
        while True:
            for m in finditer(code, i):
                group = m.lastindex
                assert group is not None
                kind = kinds[group]
                if kind == _SLOW:
                    i = m.start(group)
                    break
                yield (kind, m.start(group), m.end())
            else:
                break  # only white space is left
            token, i = self.slow_token(i)
            if token is None:
                break
            yield token
            if token[0] == _ERROR:
                return
        eof = (_EOF, n, n)
        while True:
            yield eof

    def slow_tokens(self) -> Iterator[_Token]:
        """The tokens of ``code`` read by the character loop alone (what :meth:`tokens`
        must give), then ``_EOF`` forever."""
        i = 0
        while True:
            token, i = self.slow_token(i)
            if token is None:
                break
            yield token
            if token[0] == _ERROR:
                return
        n = len(self.code)
        while True:
            yield (_EOF, n, n)

    def slow_token(self, i: int) -> tuple[_Token | None, int]:
        """The token at or after white space from ``code[i]``, and where it ends; ``None``
        at the end of ``code``."""
        code = self.code
        n = len(code)
        while i < n:
            c = code[i]
            if c in _WHITESPACE:
                i += 1
                continue
            if c == "\\" and self.legacy and code[i + 1 : i + 2] in _WHITESPACE:
                i += 2  # line continuation (an XML parser may have turned its LF into a space)
                continue
            start = i
            if c == "'" or (c == '"' and self.legacy):
                close = code.find(c, i + 1)
                if close < 0:
                    return (_ERROR, start, n, "Unterminated string", ""), n
                return (_ATOM, start, close + 1), close + 1
            if c in _DIGITS:
                i, bad = self.scan_number(i)
                if bad:
                    return (_ERROR, start, i, f"Invalid number '{code[start:i]}'", ""), i
                return (_ATOM, start, i), i
            if self.is_ident_start(c):
                i += 1
                while i < n and self.is_ident_char(code[i]):
                    i += 1
                return (_IDENT, start, i), i
            if code[i : i + 2] in _TWO_CHAR_OPS:
                return (_TWO_CHAR_OPS[code[start : i + 2]], start, i + 2), i + 2
            if c in _ONE_CHAR_OPS:
                return (_ONE_CHAR_OPS[c], start, i + 1), i + 1
            shown = f"'{c}'" if c.isprintable() else f"U+{ord(c):04X}"
            hint = self.invalid_character_hint(c, start)
            return (_ERROR, start, start + 1, f"Invalid character {shown}", hint), start + 1
        return None, n

    def is_ident_start(self, c: str) -> bool:
        if c in _IDENT_START:
            return True
        return self.legacy and c > "\x7f" and c.isidentifier()

    def is_ident_char(self, c: str) -> bool:
        if c in _IDENT_CHAR:
            return True
        return self.legacy and c > "\x7f" and ("a" + c).isidentifier()

    def invalid_character_hint(self, c: str, offset: int) -> str:
        if c == '"':
            return "; strings are written in single quotes"
        if c == "\\" and self.code[offset + 1 : offset + 2] in _WHITESPACE:
            return "; a backslash line continuation is not needed, remove it"
        if c == "." and self.code[offset + 1 : offset + 2] in _DIGITS:
            return "; write a number as 0.5, not .5"
        return ""

    def scan_number(self, i: int) -> tuple[int, bool]:
        """Scan a number starting at ``code[i]`` (a digit): (end, malformed)."""
        code = self.code
        n = len(code)
        if code[i] == "0" and code[i + 1 : i + 2] in ("x", "X"):
            i += 2
            bad = i >= n or code[i] not in _HEX_DIGITS
            while i < n and code[i] in _HEX_DIGITS:
                i += 1
            if i < n and (code[i] == "." or code[i] in _IDENT_CHAR):
                bad = True
                i = self.skip_garbage(i)
            return i, bad
        bad = False
        while i < n and code[i] in _DIGITS:
            i += 1
        if i < n and code[i] == ".":
            following = code[i + 1 : i + 2]
            if following == ".":
                pass  # "65..x" is 65 followed by the '..' operator
            elif following != "" and following in _DIGITS:
                i += 1
                while i < n and code[i] in _DIGITS:
                    i += 1
            else:
                bad = True  # "65." or "65.x"
                i = self.skip_garbage(i + 1)
        if not bad and i < n and code[i] in "eE":
            i += 1
            if i < n and code[i] in "+-":
                i += 1
            if i >= n or code[i] not in _DIGITS:
                bad = True
            while i < n and code[i] in _DIGITS:
                i += 1
        if not bad and i < n and code[i] in _IDENT_START:
            bad = True  # "3foo"
            while i < n and code[i] in _IDENT_CHAR:
                i += 1
        return i, bad

    def skip_garbage(self, i: int) -> int:
        code = self.code
        while i < len(code) and (code[i] in _IDENT_CHAR or code[i] == "."):
            i += 1
        return i
