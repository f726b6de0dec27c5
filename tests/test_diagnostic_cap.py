"""The publication cap (at most MAX_DIAGNOSTICS diagnostics, then too-many-problems) keeps
errors before warnings before information and hints: a document with thousands of hints
before its one real error still shows the error."""

from __future__ import annotations

from bt_lsp.rules.analysis import analyze
from bt_lsp.rules.codes import Severity
from bt_lsp.rules.diagnostics import MAX_DIAGNOSTICS, Diagnostic, capped, limited
from bt_lsp.syntax.document import Document


def _hints_then(*last: Diagnostic, n: int = MAX_DIAGNOSTICS + 500) -> list[Diagnostic]:
    hints = [Diagnostic(k, k + 1, "unknown-node", "h", Severity.HINT) for k in range(n)]
    return [*hints, *last]


def test_limited_keeps_the_error_and_the_warning_after_many_hints() -> None:
    error = Diagnostic(10**6, 10**6 + 1, "child-count", "e", Severity.ERROR)
    warning = Diagnostic(10**6 + 5, 10**6 + 6, "unknown-port", "w", Severity.WARNING)
    kept = limited(_hints_then(error, warning))
    assert len(kept) == MAX_DIAGNOSTICS + 1 and kept[-1].code == "too-many-problems"
    assert error in kept and warning in kept
    shown = kept[:-1]
    assert [d.start for d in shown] == sorted(d.start for d in shown)  # still by position
    assert "502 more problems" in kept[-1].message


def test_capped_keeps_the_most_severe_and_counts_the_rest() -> None:
    error = Diagnostic(10**6, 10**6 + 1, "child-count", "e", Severity.ERROR)
    found = capped(_hints_then(error), more=3)
    assert error in found and len(found) == MAX_DIAGNOSTICS
    assert found.more == 3 + 501
    assert [d.start for d in found] == sorted(d.start for d in found)


def test_an_error_after_thousands_of_hints_is_published() -> None:
    """End to end: unknown node types are hints (registered in C++ we cannot see); the
    Inverter without a child at the end is an error BehaviorTree.CPP refuses to load, and
    the name error of a bad node type among the hints is kept too."""
    nodes = "".join(f'    <Action ID="Custom{k}"/>\n' for k in range(MAX_DIAGNOSTICS + 200))
    text = f"""<root BTCPP_format="4">
  <BehaviorTree ID="Main">
   <Sequence>
{nodes}    <Action ID="bad name"/>
    <Inverter/>
   </Sequence>
  </BehaviorTree>
</root>
"""
    found = analyze(Document(text, "cap.xml"))
    codes = [d.code for d in found]
    assert codes[-1] == "too-many-problems"
    assert "child-count" in codes
    assert "model-name-forbidden-char" in codes
    assert sum(d.severity == Severity.HINT for d in found) == MAX_DIAGNOSTICS - 2
