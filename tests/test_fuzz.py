"""Fuzzing the whole engine (scanner, model, name and semantic rules, fixes, hover).

CI runs a bounded number of examples; ``BT_LSP_FUZZ_EXAMPLES=100000`` runs more locally.
Inputs are real corpus files mutated by random edits, and XML-ish random text.
"""

from __future__ import annotations

import os
from pathlib import Path

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from bt_lsp.ide.hover import hover_at
from bt_lsp.ide.name_fixes import fix_all, fixes_for_name
from bt_lsp.rules.analysis import analyze
from bt_lsp.syntax.document import Document
from bt_lsp.syntax.edits import apply_edits
from tests.test_scanner import xmlish

EXAMPLES = int(os.environ.get("BT_LSP_FUZZ_EXAMPLES", "150"))
CORPUS = sorted((Path(__file__).parent / "data" / "corpus").rglob("*.xml"))
SEEDS = [p.read_text(encoding="utf-8", errors="replace")[:6000] for p in CORPUS[:40]]


def exercise(doc: Document) -> None:
    diags = analyze(doc)
    n = len(doc.text)
    for d in diags:
        assert 0 <= d.start <= d.end <= n
        for fix in fixes_for_name(doc, d):
            apply_edits(doc.text, fix.edits)
    apply_edits(doc.text, fix_all(doc, diags).edits)
    for offset in range(0, n + 1, max(1, n // 25)):
        hover_at(doc, offset)


@given(seed=st.sampled_from(SEEDS), data=st.data())
@settings(max_examples=EXAMPLES, deadline=None, suppress_health_check=[HealthCheck.too_slow])
def test_mutated_corpus_files(seed: str, data: st.DataObject) -> None:
    doc = Document(seed)
    for _ in range(data.draw(st.integers(1, 4))):
        n = len(doc.text)
        start = data.draw(st.integers(0, n))
        end = data.draw(st.integers(start, min(n, start + 40)))
        doc.edit(start, end, data.draw(xmlish))
    exercise(doc)
    assert analyze(doc) == analyze(Document(doc.text))


@given(xmlish)
@settings(max_examples=EXAMPLES, deadline=None)
def test_random_xmlish_text(text: str) -> None:
    exercise(Document(text))
