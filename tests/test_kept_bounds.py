"""What a document keeps stays in proportion to it: diagnostics beyond the publication cap
are counted, not kept, and each element costs a bounded number of objects.

(Memory in bytes depends on the machine; ``benchmarks/hostile.py`` measures it in the
server.  These tests check the structure that keeps it bounded.)
"""

from __future__ import annotations

import gc
import tracemalloc

from bt_lsp.rules.analysis import analyze
from bt_lsp.rules.diagnostics import MAX_DIAGNOSTICS, own_diagnostics
from bt_lsp.syntax.document import Document

TREE = '<root BTCPP_format="4">\n<BehaviorTree ID="T">\n<Sequence>'
END = "</Sequence>\n</BehaviorTree>\n</root>\n"
# An unknown node type (a semantic hint) and a bad model name (a name rule of the
# document's own diagnostics), one after the other.
PAIR = "<Frob/><Fr.ob/>"


def test_the_most_severe_diagnostics_are_kept_from_both_sources() -> None:
    """Errors before hints, then the first by position: the bad names (errors, of the
    document's own diagnostics) push out the unknown node types (hints, semantic)."""
    n = 3000  # 6,000 findings: more than twice the cap in each source
    doc = Document(TREE + PAIR * n + END)
    diags = analyze(doc)
    assert len(diags) == MAX_DIAGNOSTICS + 1
    first = len(TREE)
    expected = []
    for k in range(MAX_DIAGNOSTICS):
        at = first + k * len(PAIR)
        expected.append((at + 8, at + 13, "model-name-forbidden-char"))
    assert [(d.start, d.end, d.code) for d in diags[:-1]] == expected
    assert diags[-1].code == "too-many-problems"
    assert diags[-1].message.startswith(f"{2 * n - MAX_DIAGNOSTICS} more problems")


def test_what_is_kept_beyond_the_cap_is_a_count() -> None:
    n = 5000
    doc = Document(TREE + PAIR * n + END)
    analyze(doc)
    own = own_diagnostics(doc)
    assert len(own) == MAX_DIAGNOSTICS and own.more == n - MAX_DIAGNOSTICS
    (section,) = doc.model.sections
    assert len(section.cache["diagnostics"]) == MAX_DIAGNOSTICS
    entry = section.cache["semantics"]
    assert len(entry.out) == MAX_DIAGNOSTICS and entry.more == n - MAX_DIAGNOSTICS


def test_an_edit_keeps_the_count_right() -> None:
    n = 3000
    doc = Document(TREE + PAIR * n + END)
    analyze(doc)
    at = len(TREE) + 10 * len(PAIR)
    doc.edit(at, at + len(PAIR), "")  # one pair fewer, before the cap
    diags = analyze(doc)
    assert diags[-1].message.startswith(f"{2 * (n - 1) - MAX_DIAGNOSTICS} more problems")
    assert [d.code for d in diags[:4]] == ["model-name-forbidden-char"] * 4


def _retained(elements: int) -> tuple[int, int, int]:
    """Memory blocks and bytes a document of ``elements`` empty elements holds once
    analysed, and the peak bytes while it is scanned, built and analysed."""
    text = TREE + "<Frob/>" * elements + END
    gc.collect()
    tracemalloc.start()
    try:
        doc = Document(text)
        analyze(doc)
        gc.collect()
        stats = tracemalloc.take_snapshot().statistics("filename")
        blocks = sum(s.count for s in stats)
        size = sum(s.size for s in stats)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert doc.model.sections
    return blocks, size, peak


def test_each_element_costs_a_few_machine_integers() -> None:
    (b1, s1, p1), (b2, s2, p2) = _retained(2_000), _retained(20_000)
    blocks, size, peak = ((x2 - x1) / 18_000 for x1, x2 in ((b1, b2), (s1, s2), (p1, p2)))
    # An element is a row of columns (its start tag, shared by equal tags, and machine
    # integers), not an object: one object per element, or an int object for its offset,
    # would add a block each.  Its token (a pointer, shared) and token start take 16
    # bytes, its row about 45: an element object with two int objects took 180.
    assert blocks < 0.05, blocks
    assert size < 100, size
    # Nothing makes all the elements at once on the way (a list of them, or of their
    # name tokens, would cost more than 100 bytes an element).
    assert peak < 120, peak


def test_equal_start_tags_are_one_token() -> None:
    doc = Document(TREE + "<Frob/>" * 100 + '<Frob a="1"/>' * 2 + END)
    tags = [el.tag for el in doc.model.elements if el.name == "Frob"]
    assert len(tags) == 102
    assert len({id(t) for t in tags[:100]}) == 1  # shared
    assert tags[100] is not tags[101]  # a tag with attributes is its own
    assert [el.end - el.token_start for el in doc.model.elements if el.name == "Frob"] == [
        7
    ] * 100 + [13] * 2


def test_equal_attributes_at_one_place_are_one_tuple() -> None:
    doc = Document(TREE + "".join(f'<Frob a="1" c="{k}"/>' for k in range(50)) + END)
    frobs = [el for el in doc.model.elements if el.name == "Frob"]
    assert len({id(el.attrs[0]) for el in frobs}) == 1  # a="1" everywhere: shared
    assert len({id(el.attrs[1]) for el in frobs}) == 50  # c differs
    assert [el.value("c") for el in frobs] == [str(k) for k in range(50)]
