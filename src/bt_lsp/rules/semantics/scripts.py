"""Scripts: ``Script code``, ``ScriptCondition code``, ``Precondition if`` and the pre- and
post-condition attributes (``_skipIf`` … ``_post``) on any node.

* ``script-syntax``: the first syntax error of the script, as BehaviorTree.CPP 4.10 parses
  it (:mod:`bt_lsp.rules.script`).  An error, or a warning when the script is accepted by the
  older parser of 4.0-4.9 (double-quoted strings, non-ASCII identifiers, a backslash line
  continuation).  Range: the offending characters in the source, mapped from the decoded
  value back through entity references (``&amp;&amp;`` is one ``&&`` operator of the
  script but 10 characters of the file); an error at the end of the script covers its
  last character, an empty script the (empty) value.  A ``code``/``if`` port given as a
  blackboard reference (``{key}``) is not a script here and is not checked, nor is an
  empty ``code`` of ``Script`` (its constructor parses the code only when it differs from
  the last code parsed, which starts empty: the node does nothing).
"""

from __future__ import annotations

from functools import lru_cache
from typing import Final

from bt_lsp.rules.codes import BT, Severity, define
from bt_lsp.rules.script import ScriptError, check_script
from bt_lsp.rules.semantics.base import State
from bt_lsp.syntax.elements import Element
from bt_lsp.syntax.tokens import Attr
from bt_lsp.syntax.values import raw_span

# The codes of these rules (see bt_lsp.rules.registry).
SCRIPT_SYNTAX: Final = define(
    "script-syntax",
    Severity.ERROR,
    "a script that does not parse",
    BT,
    doc="""
        Scripts (`code` of `Script` and `ScriptCondition`, `if` of `Precondition`, and the
        `_skipIf` … `_post` attributes of any node) are parsed when the tree is created; a syntax
        error throws: `Error in the script "x == "` followed by the parser's message (`Expected
        operand at position 5`). bt-lsp parses them as BehaviorTree.CPP 4.10 does; what only the
        4.0-4.9 parser accepted (double-quoted strings, non-ASCII identifiers) is a warning.
        Remember that XML needs `&amp;&amp;` for `&&` and `&lt;` for `<`.
        """,
    why="""
        The tree is not created, or a 4.9 tree stops loading after an upgrade to 4.10.
        """,
    bad='<Script code="count = = 1"/>',
    good='<Script code="count := 1"/>',
    since="BehaviorTree.CPP 4 (3.x has no scripts).",
)


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
    st.pure = False  # reads the text (two spellings of one value may be one token)
    rs, re_ = raw_span(st.text[vs:ve], start, end)
    message = f"Script error in {a.name}: {err.message}"
    if not code and a.name in ("code", "if"):
        # ScriptCondition/Precondition skip parsing a code equal to the last one parsed,
        # which starts empty: they are created, and call their empty executor.
        message += (
            "; BehaviorTree.CPP creates the node, which fails when it ticks (bad_function_call)"
        )
    if legacy_ok:
        message += " (BehaviorTree.CPP 4.0-4.9 accepted this; 4.10 does not)"
    st.add(vs + rs, vs + re_, "script-syntax", message, Severity.WARNING if legacy_ok else None)
