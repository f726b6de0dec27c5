"""Real BT XML from public robotics projects (tests/data/corpus, see LICENSES.md there).

The engine must read every file without a crash, report exactly the name-rule violations
recorded in FINDINGS.tsv, and report XML syntax errors exactly for the files that are not
well-formed for a reason other than tinyxml2's tolerance of raw '&' and '<' in values.
"""

from __future__ import annotations

import csv
import re
from pathlib import Path

import pytest

from bt_lsp.project.fileio import read_text
from bt_lsp.rules.analysis import analyze
from bt_lsp.rules.diagnostics import own_diagnostics
from bt_lsp.rules.names import PROJECT_NAME_CODES
from bt_lsp.syntax.document import Document

CORPUS = Path(__file__).parent / "data" / "corpus"
ROWS = list(csv.DictReader((CORPUS / "FINDINGS.tsv").open(encoding="utf-8"), delimiter="\t"))
FINDING = re.compile(r"(model|port) (\S+) '(.*)': (\w+)")
_RESERVED_DECLARATION_CODES = PROJECT_NAME_CODES | {"port-name-groot1"}


def recorded_names(row: dict[str, str], *, reserved: bool = False) -> set[str]:
    """The names recorded as breaking a rule: but for the reserved names of declared
    ports, or (``reserved``) only those."""
    names = set()
    for part in filter(None, (p.strip() for p in row["rule_violations"].split("|"))):
        m = FINDING.match(part)
        assert m, part
        if (m.group(4) == "reserved") == reserved:
            names.add(m.group(3))
    return names


@pytest.mark.parametrize("row", ROWS, ids=[r["file"] for r in ROWS])
def test_corpus_file(row: dict[str, str]) -> None:
    doc = Document(read_text(str(CORPUS / row["file"])).text)
    diags = own_diagnostics(doc)
    flagged = {doc.text[d.start : d.end] for d in diags if d.is_name_rule}
    assert flagged == recorded_names(row)
    # A declared port's reserved name is reported by the full analysis, as the project's
    # BehaviorTree.CPP version reads the entry.
    reserved = {
        doc.text[d.start : d.end] for d in analyze(doc) if d.code in _RESERVED_DECLARATION_CODES
    }
    assert reserved == recorded_names(row, reserved=True)
    syntax = [d for d in diags if d.code == "xml-syntax"]
    unescaped = [d for d in diags if d.code == "xml-unescaped-char"]
    if row["well_formed"] == "yes":
        assert not syntax and not unescaped
    elif "invalid token" in row["parse_error"]:
        # tinyxml2 (and so BehaviorTree.CPP) loads these: a warning, not an error.
        assert not syntax and unescaped
    elif "junk after document element" in row["parse_error"]:
        # tinyxml2 reads what follows the root and BehaviorTree.CPP ignores it: a warning.
        assert not syntax and any(d.code == "xml-extra-root" for d in diags)
    else:
        assert syntax


def test_corpus_has_the_interesting_cases() -> None:
    assert len(ROWS) >= 90
    assert sum(1 for r in ROWS if r["rule_violations"]) >= 30
    assert sum(1 for r in ROWS if r["well_formed"] != "yes") >= 5
