"""The rules on documents of very many small elements or trees: equal start tags are
checked once, what a semantic run remembers per section stays small, and a lookup that
missed is looked at again when the context comes to hold it.

(Times and bytes are measured by ``benchmarks/hostile.py``; these tests check what
makes them bounded, and that it changes no diagnostic.)
"""

from __future__ import annotations

import gc
import tracemalloc

from bt_lsp.rules.analysis import analyze
from bt_lsp.rules.context import Context
from bt_lsp.rules.diagnostics import NO_DIAGNOSTICS, own_diagnostics
from bt_lsp.syntax.document import Document
from tests.pinned import pinned
from tests.rulecheck import check, marks

HEAD = '<root BTCPP_format="4">\n<BehaviorTree ID="T">\n<Sequence>\n'
TAIL = "</Sequence>\n</BehaviorTree>\n</root>\n"


def _codes_at(text: str, code: str) -> list[int]:
    return [d.start for d in analyze(Document(text)) if d.code == code]


def test_equal_tags_are_reported_at_each_place() -> None:
    node = '<Frob ID="x"/><Fr.ob/>'
    text = HEAD + node * 3 + TAIL
    first = len(HEAD)
    starts = [first + k * len(node) for k in range(3)]
    assert _codes_at(text, "unknown-node") == [s + 1 for s in starts]
    assert _codes_at(text, "id-on-compact-node") == [s + 6 for s in starts]
    assert _codes_at(text, "model-name-forbidden-char") == [s + 15 for s in starts]


def test_a_tag_whose_findings_depend_on_its_children_is_checked_each_time() -> None:
    two_async = (
        "<⟦ReactiveSequence⟧><AsyncSequence><AlwaysSuccess/></AsyncSequence>"
        "<AsyncSequence><AlwaysSuccess/></AsyncSequence></ReactiveSequence>"
    )
    plain = "<ReactiveSequence><AlwaysSuccess/><AlwaysSuccess/></ReactiveSequence>"
    text = HEAD + two_async * 3 + plain + two_async + TAIL
    code = "reactive-async-children"
    assert check(text, only=code) == marks(text, code)


def test_a_tag_with_another_number_of_children_is_checked_again() -> None:
    two = '<Parallel success_count="⟦3⟧"><Frob/><Frob/></Parallel>'
    three = '<Parallel success_count="3"><Frob/><Frob/><Frob/></Parallel>'
    text = HEAD + two + two + three + three + two + TAIL
    assert check(text, only="parallel-threshold") == marks(text, "parallel-threshold")


def test_the_first_use_of_a_key_decides_for_equal_tags() -> None:
    retry = '<RetryUntilSuccessful num_attempts="{k}"><AlwaysSuccess/></RetryUntilSuccessful>'
    delay = '<Delay delay_msec="⟦{k}⟧"><AlwaysSuccess/></Delay>'
    text = HEAD + retry + delay + retry + delay + TAIL
    # The key is an int from its first use on: each Delay (unsigned int) is a mismatch.
    code = "blackboard-type-mismatch"
    assert check(text, only=code) == marks(text, code)


def test_a_lookup_that_missed_counts_when_another_document_declares_it() -> None:
    trees = "".join(
        f'<BehaviorTree ID="T{i}"><Sequence><Frob/><AlwaysSuccess/></Sequence></BehaviorTree>\n'
        for i in range(30)
    )
    main = Document(
        f'<root BTCPP_format="4" main_tree_to_execute="T0">\n{trees}</root>\n', "/w/main.xml"
    )
    declared = '<root BTCPP_format="4"><TreeNodesModel><Action ID="Frob"/></TreeNodesModel></root>'
    models = Document(declared, "/w/models.xml")
    empty = Document('<root BTCPP_format="4"><TreeNodesModel/></root>', "/w/models.xml")

    def unknown(other: Document) -> int:
        ctx = Context.combine(main, [("/w/models.xml", other, False)])
        return sum(d.code == "unknown-node" for d in analyze(main, ctx))

    assert unknown(empty) == 30
    assert unknown(models) == 0  # every section looked Frob up and missed: checked again
    assert unknown(empty) == 30


def test_findings_that_depend_on_the_context_are_not_shared_between_trees() -> None:
    # In T1 the second tag of type Frob (written otherwise: another token) finds the type
    # already resolved in the run; T2's must still look it up itself, so that declaring
    # Frob later checks T2 again.
    trees = (
        '<BehaviorTree ID="T1"><Sequence><Frob/><Frob /></Sequence></BehaviorTree>\n'
        '<BehaviorTree ID="T2"><Sequence><Frob /><AlwaysSuccess/></Sequence></BehaviorTree>\n'
    )
    main = Document(
        f'<root BTCPP_format="4" main_tree_to_execute="T1">\n{trees}</root>\n', "/w/m.xml"
    )
    declared = Document(
        '<root BTCPP_format="4"><TreeNodesModel><Action ID="Frob"><input_port name="a"/>'
        "</Action></TreeNodesModel></root>",
        "/w/models.xml",
    )
    empty = Document('<root BTCPP_format="4"><TreeNodesModel/></root>', "/w/models.xml")

    def codes(other: Document) -> list[str]:
        ctx = Context.combine(main, [("/w/models.xml", other, False)])
        return sorted(d.code for d in pinned(analyze(main, ctx)) if d.code != "no-main-tree")

    assert codes(empty) == ["unknown-node"] * 3
    assert codes(declared) == ["missing-port-without-default"] * 3  # a hint: a is not given
    assert codes(empty) == ["unknown-node"] * 3


def test_a_section_without_findings_keeps_the_shared_empty_result() -> None:
    # The simplest tree there is: no rule may find anything in it.
    doc = Document(
        '<root BTCPP_format="4">\n<BehaviorTree ID="T"><AlwaysSuccess/></BehaviorTree>\n</root>\n'
    )
    assert analyze(doc) == []
    (section,) = doc.model.sections
    assert section.cache["diagnostics"] is NO_DIAGNOSTICS
    assert section.cache["semantics"].out is NO_DIAGNOSTICS
    assert own_diagnostics(doc) == []


def _cycle(trees: int) -> str:
    body = "".join(
        f'<BehaviorTree ID="T{i}"><Sequence><SubTree ID="T{i + 1}"/><AlwaysSuccess/>'
        "</Sequence></BehaviorTree>\n"
        for i in range(trees)
    )
    return (
        f'<root BTCPP_format="4" main_tree_to_execute="T0">{body}'
        f'<BehaviorTree ID="T{trees}"><SubTree ID="T0"/></BehaviorTree></root>\n'
    )


def _rules_blocks(trees: int) -> int:
    """Memory blocks the rules keep for a document of ``trees`` small trees calling each
    other in a cycle, once analysed (the model's own are counted before)."""
    doc = Document(_cycle(trees), "/w/cycle.xml")
    _ = doc.model
    gc.collect()
    tracemalloc.start()
    try:
        before = sum(s.count for s in tracemalloc.take_snapshot().statistics("filename"))
        diags = analyze(doc)
        gc.collect()
        after = sum(s.count for s in tracemalloc.take_snapshot().statistics("filename"))
    finally:
        tracemalloc.stop()
    assert [d.code for d in pinned(diags)] == ["subtree-recursion"]
    return after - before


def test_each_tree_costs_the_rules_a_bounded_number_of_objects() -> None:
    small, large = _rules_blocks(500), _rules_blocks(5_000)
    per_tree = (large - small) / 4_500
    # Per tree: its declaration twice (in the section and placed in the document, with
    # its start and end and its calls), the section's remembered run (its lookups in one
    # tuple), the signature of the tree it calls, its symbols and the cache that holds
    # them.  A dict of lookups, a result list per section or a set of all sections would
    # add more than one each.
    assert per_tree < 13, per_tree


def _too_many(text: str) -> str:
    diags = analyze(Document(text))
    assert len(diags) == 2001
    return diags[-1].message


def test_a_repeated_tag_past_the_cap_is_counted_exactly() -> None:
    # Each <Frob/> is unknown-node: 5,000 findings, 2,000 kept; each of 4,500 <Fr.ob/>
    # breaks a name rule (which the name rules count without making it).
    assert _too_many(HEAD + "<Frob/>" * 5000 + TAIL).startswith("3000 more problems")
    mixed = HEAD + "<Frob/><Fr.ob/>" * 1500 + "<AlwaysSuccess/>" * 10 + "<Fr.ob/>" * 3000 + TAIL
    # 1,500 unknown-node, 4,500 model-name-forbidden-char.
    assert _too_many(mixed).startswith(f"{1500 + 4500 - 2000} more problems")


def test_depth_over_the_limit_is_flagged_on_a_repeated_tag_in_each_tree() -> None:
    # Every <Inverter> has one child: from the second on, each is remembered by its tag.
    deep = "<Inverter>" * 300 + "<AlwaysSuccess/>" + "</Inverter>" * 300
    text = (
        '<root BTCPP_format="4" main_tree_to_execute="A">'
        f'<BehaviorTree ID="A">{deep}</BehaviorTree>'
        f'<BehaviorTree ID="B">{deep}</BehaviorTree></root>'
    )
    a = text.index(">", text.index('ID="A"')) + 1
    b = text.index(">", text.index('ID="B"')) + 1
    step = len("<Inverter>")
    # Depth: <root> 0, <BehaviorTree> 1, the first <Inverter> 2; flagged past 257.
    expected = [a + 256 * step + 1, b + 256 * step + 1]
    assert _codes_at(text, "nesting-depth") == expected


def test_findings_of_repeated_tags_move_with_their_section_after_an_edit() -> None:
    body = "<Sequence>" + "<Frob/><Fr.ob/>" * 50 + "</Sequence>"
    text = (
        '<root BTCPP_format="4" main_tree_to_execute="A">'
        f'<BehaviorTree ID="A">{body}</BehaviorTree>\n'
        f'<BehaviorTree ID="B">{body}</BehaviorTree></root>'
    )
    doc = Document(text)
    before = [(d.start, d.code) for d in analyze(doc)]
    at = text.index("<Frob/>")
    doc.edit(at, at, "<Frob/>")
    after = [(d.start, d.code) for d in analyze(doc)]
    fresh = [(d.start, d.code) for d in analyze(Document(doc.text))]
    assert after == fresh
    b = text.index('ID="B"')
    moved = [(s + 7, c) for s, c in before if s > b]
    assert [x for x in after if x[0] > b + 7] == moved
    assert len([c for _, c in moved if c == "unknown-node"]) == 50
    assert len([c for _, c in moved if c == "model-name-forbidden-char"]) == 50
