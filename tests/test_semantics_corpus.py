"""No false errors on real BT XML.

Every well-formed file of the corpus is checked the way the workspace layer would check it:
the other files of the same project are workspace documents (their models count, their
trees are known but not included).  No error-severity semantic diagnostic may appear
except the known findings in ``data/semantics/corpus_known_errors.tsv``, each a real
problem that BehaviorTree.CPP 4 raises (the reason column says which), and
``unknown-subtree`` errors for trees that no file of the project in the corpus defines
(the corpus is a sample: those trees live in files that were not copied, and
BehaviorTree.CPP raises "Can't find a tree" when the file is loaded without them).

The sample in ``data/corpus`` and the whole corpus in ``data/corpus_real`` both run.
"""

from __future__ import annotations

import csv
import time
from collections import defaultdict
from pathlib import Path

from bt_lsp.project.fileio import read_text
from bt_lsp.rules import semantics
from bt_lsp.rules.codes import Severity
from bt_lsp.rules.context import Context
from bt_lsp.syntax.document import Document

HERE = Path(__file__).parent
LOCAL = HERE / "data" / "corpus"
FULL = HERE / "data" / "corpus_real"
KNOWN_FILE = HERE / "data" / "semantics" / "corpus_known_errors.tsv"

KNOWN: dict[str, set[tuple[int, str, str]]] = defaultdict(set)
REASONS: dict[tuple[str, int, str, str], str] = {}
for _row in csv.DictReader(KNOWN_FILE.open(encoding="utf-8"), delimiter="\t"):
    _key = (int(_row["line"]), _row["code"], _row["text"])
    KNOWN[_row["file"]].add(_key)
    REASONS[(_row["file"], *_key)] = _row["reason"]


def load(corpus: Path) -> dict[str, Document]:
    rows = csv.DictReader((corpus / "FINDINGS.tsv").open(encoding="utf-8"), delimiter="\t")
    files = [r["file"] for r in rows if r["well_formed"] == "yes" and r["file"].endswith(".xml")]
    return {f: Document(read_text(str(corpus / f)).text, f) for f in files}


def errors(docs: dict[str, Document]) -> dict[str, set[tuple[int, str, str]]]:
    """Unexplained error-severity semantic diagnostics, per file."""
    by_project: dict[str, list[tuple[str, Document]]] = defaultdict(list)
    for f, d in docs.items():
        by_project[f.split("/")[0]].append((f, d))
    out: dict[str, set[tuple[int, str, str]]] = {}
    for f, doc in docs.items():
        project = by_project[f.split("/")[0]]
        others = [(g, d, False) for g, d in project if g != f]
        ctx = Context.combine(doc, others, path=f)
        found = set()
        for diag in semantics.check(doc, ctx):
            if diag.severity != Severity.ERROR:
                continue
            text = doc.text[diag.start : diag.end]
            if diag.code == "unknown-subtree":
                # Allowed only when no file of the project defines the tree.
                assert text not in ctx.workspace_trees
                continue
            found.add((doc.lines.line_of(diag.start) + 1, diag.code, text))
        if found:
            out[f] = found
    return out


def test_known_findings_have_reasons() -> None:
    assert REASONS and all(r and r != "?" for r in REASONS.values())


def test_local_corpus_has_only_known_errors() -> None:
    docs = load(LOCAL)
    assert len(docs) > 90
    found = errors(docs)
    expected = {f: KNOWN[f] for f in docs if KNOWN.get(f)}
    assert found == expected


def test_full_corpus_has_only_known_errors() -> None:
    docs = load(FULL)
    found = errors(docs)
    assert found == {f: v for f, v in KNOWN.items() if v}


def test_local_corpus_diagnoses_quickly() -> None:
    docs = load(LOCAL)
    start = time.perf_counter()
    for doc in docs.values():
        semantics.check(doc, Context.from_document(doc))
    assert time.perf_counter() - start < 5
