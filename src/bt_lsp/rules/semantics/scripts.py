"""Scripts: ``Script code``, ``ScriptCondition code``, ``Precondition if`` and the pre- and
post-condition attributes (``_skipIf`` … ``_post``) on any node.

* ``script-syntax``: the first syntax error of the script, as BehaviorTree.CPP 4.10 parses
  it (:mod:`bt_lsp.rules.script`).  An error, or a warning when the script is accepted by the
  older parser of 4.0-4.9 (double-quoted strings, non-ASCII identifiers, a backslash line
  continuation).  Range: the offending characters in the source, mapped from the decoded
  value back through entity references (``&amp;&amp;`` is one ``&&`` operator of the
  script but 10 characters of the file); an error at the end of the script covers its
  last character, an empty script the (empty) value.  A ``code``/``if`` port given as a
  blackboard reference (``{key}``) is not a script here and is not checked.
"""

from __future__ import annotations

import re
from functools import lru_cache
from typing import Final

from bt_lsp.rules.codes import Severity
from bt_lsp.rules.names import POSTCONDITIONS, PRECONDITIONS
from bt_lsp.rules.script import ScriptError, check_script
from bt_lsp.rules.semantics.base import State
from bt_lsp.syntax.model import Element
from bt_lsp.syntax.scanner import Attr, decode_value

#: Attributes whose value is a script on every node.
CONDITION_ATTRS: Final[frozenset[str]] = frozenset((*PRECONDITIONS, *POSTCONDITIONS))
#: Built-in (node type, port) pairs whose value is a script.
SCRIPT_PORTS: Final[frozenset[tuple[str, str]]] = frozenset(
    {("Script", "code"), ("ScriptCondition", "code"), ("Precondition", "if")}
)

# An entity or character reference, exactly as the scanner recognises one.
_REF: Final = re.compile(r"&(#[0-9]+|#x[0-9A-Fa-f]+|[A-Za-z_:][A-Za-z0-9_.:-]*);")


def raw_offsets(raw: str) -> list[int]:
    """Where each code point of the decoded value starts in ``raw``, plus ``len(raw)``.

    ``raw`` is an attribute value as written; decoding follows
    :func:`bt_lsp.syntax.scanner.decode_value`: a reference it replaces becomes one code point,
    anything it keeps as written (a raw ``&``, an unknown entity, an invalid character
    reference) stays one code point per character.
    """
    out: list[int] = []
    n = len(raw)
    pos = 0
    while pos < n:
        amp = raw.find("&", pos)
        if amp == -1:
            out.extend(range(pos, n))
            break
        out.extend(range(pos, amp))
        m = _REF.match(raw, amp)
        if m is None:
            out.append(amp)
            pos = amp + 1
            continue
        if len(decode_value(m.group(0), 0, None)) == 1:
            out.append(amp)
        else:
            out.extend(range(amp, m.end()))
        pos = m.end()
    out.append(n)
    return out


def raw_span(raw: str, start: int, end: int) -> tuple[int, int]:
    """The span of ``raw`` (relative to it) that decodes to ``decoded[start:end]``."""
    if "&" not in raw:
        return start, end
    offs = raw_offsets(raw)
    last = len(offs) - 1
    return offs[min(start, last)], offs[min(end, last)]


@lru_cache(maxsize=16384)
def _parse(code: str) -> tuple[ScriptError | None, bool]:
    """The first syntax error of ``code`` and whether the 4.0-4.9 parser accepts it."""
    err = check_script(code)
    if err is None:
        return None, True
    return err, check_script(code, legacy=True) is None


def check(st: State, el: Element, a: Attr) -> None:
    """Check one attribute value as a script."""
    code = a.value
    if code is None:
        return
    err, legacy_ok = _parse(code)
    if err is None:
        return
    start, end = err.offset, err.end
    if start == end and code.strip():
        # An error at the end of the script: show it on the last character written.
        stripped = code.rstrip(" \t\r\n")
        start, end = len(stripped) - 1, len(stripped)
    vs, ve = el.span_of_value(a)
    rs, re_ = raw_span(st.text[vs:ve], start, end)
    message = f"Script error in {a.name}: {err.message}"
    if legacy_ok:
        message += " (BehaviorTree.CPP 4.0-4.9 accepted this; 4.10 does not)"
    st.add(vs + rs, vs + re_, "script-syntax", message, Severity.WARNING if legacy_ok else None)
