"""Checking one rule on one document: ``check(marked, only="code")`` analyses the text of a
marked fixture (``⟦…⟧`` around each expected span, :mod:`tests.marks`) and returns what
the given code(s) found as (span, code) pairs, which a test compares with
``marks(marked, "code")``::

    T = HEAD + '<⟦Inverter⟧/>' + TAIL
    assert check(T, only="child-count") == marks(T, "child-count")

The whole analysis runs (own diagnostics, semantic rules, the document as if alone, at
``path``); only the diagnostics of ``only`` are returned, so a test says what one rule
reports without listing what the others find in the same text.
"""

from __future__ import annotations

from collections.abc import Collection

from bt_lsp.rules.analysis import analyze
from bt_lsp.rules.registry import CODES
from bt_lsp.syntax.document import Document
from tests.marks import unmark

Found = list[tuple[tuple[int, int], str]]


def check(marked: str, only: str | Collection[str], path: str = "check.xml") -> Found:
    """The (span, code) pairs the codes ``only`` report in the text of ``marked`` (marks
    removed), in document order."""
    codes = {only} if isinstance(only, str) else set(only)
    unknown = codes - set(CODES)
    assert not unknown, f"no such code: {sorted(unknown)}"
    text, _ = unmark(marked)
    found = analyze(Document(text, path))
    return sorted(((d.start, d.end), d.code) for d in found if d.code in codes)


def marks(marked: str, *codes: str) -> Found:
    """The (span, code) pairs ``marked`` expects: its marked spans in order, each with the
    code of the same place in ``codes`` (one code: the code of every mark)."""
    _, spans = unmark(marked)
    if len(codes) == 1:
        codes = codes * len(spans)
    assert len(codes) == len(spans), "one code per mark"
    return sorted(zip(spans, codes, strict=True))
