"""The running tree mapped onto the text (``bt_lsp.live.mapping``).

``data/live_map/main.fulltree.xml`` is what BehaviorTree.CPP 4.8.2 (behaviortreepy)
answered to FULLTREE for ``main.xml``, which includes ``inc.xml``: nested SubTrees, a
SubTree instance without a name (BehaviorTree.CPP names it ``Sub::11``), an explicit
``<Action ID>`` and a tree of the included file.  Expected places are written as a
snippet of the text with ``|`` where the start tag's name begins.
"""

from __future__ import annotations

import contextlib
from collections.abc import Mapping
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from bt_lsp.live import tree as live_tree
from bt_lsp.live.mapping import LOOKAHEAD, TreeMap, align, map_tree, map_tree_xml
from bt_lsp.live.protocol import ProtocolError
from bt_lsp.live.tree import LiveTree, parse_tree_xml
from bt_lsp.render import Resolver, workspace_resolver
from bt_lsp.rules.context import Context
from bt_lsp.syntax.document import Document

DATA = Path(__file__).parent / "data" / "live_map"
MAIN = (DATA / "main.xml").read_text(encoding="utf-8")
INC = (DATA / "inc.xml").read_text(encoding="utf-8")
FULLTREE = (DATA / "main.fulltree.xml").read_text(encoding="utf-8")
LIVE = parse_tree_xml(FULLTREE)

# uid -> (file, snippet): where each running node's element is in the unedited files.
EXPECTED = {
    1: ("main.xml", '<|Sequence name="seq"'),
    2: ("main.xml", "<|Script"),
    3: ("main.xml", '<|SubTree ID="Sub" name="sub1"'),
    4: ("main.xml", '<BehaviorTree ID="Sub">\n    <|Sequence'),
    5: ("main.xml", '<|SubTree ID="Inner"'),
    6: ("inc.xml", '<|Sequence name="inner_seq"'),
    7: ("inc.xml", "<|AlwaysSuccess/>"),
    8: ("inc.xml", "<|Sleep"),
    9: ("main.xml", "<|Inverter"),
    10: ("main.xml", "<Inverter><|AlwaysFailure"),
    11: ("main.xml", '<|SubTree ID="Sub"/>'),
    19: ("main.xml", '<|Action ID="AlwaysSuccess"'),
    20: ("main.xml", "<|Fallback"),
    21: ("main.xml", "<Fallback><|AlwaysFailure"),
    22: ("main.xml", '<|AlwaysSuccess name="ok"'),
}
# The second instance of Sub (uids 12 to 18) comes from the same elements as the first.
EXPECTED.update({uid + 8: EXPECTED[uid] for uid in range(4, 11)})


def at(text: str, snippet: str) -> int:
    """The offset the ``|`` of ``snippet`` marks in ``text`` (the snippet is unique)."""
    plain = snippet.replace("|", "")
    assert text.count(plain) == 1, snippet
    return text.index(plain) + snippet.index("|")


def docs_of(texts: Mapping[str, str]) -> dict[str, Document]:
    return {path: Document(text, path) for path, text in texts.items()}


def resolver(own: str, docs: Mapping[str, Document], included: set[str]) -> Resolver:
    """The trees ``own`` sees: its own, its includes' (``included``), the others'."""
    others = [(p, d, p in included) for p, d in docs.items() if p != own]
    ctx = Context.combine(docs[own], others, path=own)
    return workspace_resolver(docs[own].model, ctx, {p: d.model for p, d in docs.items()})


def mapped(
    texts: Mapping[str, str],
    own: str = "main.xml",
    included: set[str] | None = None,
    live: LiveTree = LIVE,
) -> tuple[TreeMap, dict[int, tuple[str, int]]]:
    """The map of ``live`` onto ``own`` and each uid's place as (file, offset)."""
    docs = docs_of(texts)
    tm = map_tree(live, docs[own].model, resolver(own, docs, included or {"inc.xml"}))
    places: dict[int, tuple[str, int]] = {}
    for uid, p in tm.places.items():
        path = p.path or own
        text = docs[path].text
        assert text[p.start - 1] == "<" and text[p.start : p.end].isidentifier()
        places[uid] = (path, p.start)
    # Every uid has a place or is missing, never both.
    assert set(tm.places) | tm.missing == set(live.nodes)
    assert not set(tm.places) & tm.missing
    return tm, places


def expected(
    texts: Mapping[str, str], table: Mapping[int, tuple[str, str]]
) -> dict[int, tuple[str, int]]:
    return {uid: (path, at(texts[path], snippet)) for uid, (path, snippet) in table.items()}


def kinds(tm: TreeMap) -> list[tuple[str, int | None]]:
    return [(m.kind, m.uid) for m in tm.mismatches]


# ---------------------------------------------------------------- the text as it ran


def test_every_uid_maps_through_nested_subtrees_and_an_include() -> None:
    texts = {"main.xml": MAIN, "inc.xml": INC}
    tm, places = mapped(texts)
    assert tm.mismatches == ()
    assert places == expected(texts, EXPECTED)
    assert tm.tree is not None and tm.tree.path is None
    assert tm.tree.start == at(MAIN, '<|BehaviorTree ID="Main"')


def test_the_open_document_may_hold_only_a_subtree_of_the_running_tree() -> None:
    """inc.xml is open; Main and Sub are in another workspace file it does not include:
    tree IDs resolve across the workspace."""
    texts = {"main.xml": MAIN, "inc.xml": INC}
    tm, places = mapped(texts, own="inc.xml", included=set())
    assert tm.mismatches == ()
    assert places == expected(texts, EXPECTED)
    assert tm.tree is not None and tm.tree.path == "main.xml"
    assert tm.places[8].path is None  # the open document's own element


def test_a_document_alone_maps_what_it_has() -> None:
    """Without its include, the Inner instances are missing and say why."""
    docs = docs_of({"main.xml": MAIN})
    tm = map_tree(LIVE, docs["main.xml"].model)
    assert tm.missing == {6, 7, 8, 14, 15, 16}
    first = next(m for m in tm.mismatches if m.uid == 6)
    assert first.kind == "missing" and "tree 'Inner' is not in the text" in first.message
    assert first.place is None
    assert tm.places[5].start == at(MAIN, '<|SubTree ID="Inner"')


# ---------------------------------------------------------------- an edited text

EDITED = (
    MAIN.replace('<Script code="x := 1"/>', '<Script code="x := 1"/>\n      <Delay name="new"/>')
    .replace('      <Action ID="AlwaysSuccess" name="act"/>\n', "")
    .replace('name="ok"', 'name="fine"')
)


def test_inserted_removed_and_renamed_nodes_are_reported_and_the_rest_still_maps() -> None:
    texts = {"main.xml": EDITED, "inc.xml": INC}
    tm, places = mapped(texts)
    table = dict(EXPECTED)
    del table[19]
    table[22] = ("main.xml", '<|AlwaysSuccess name="fine"')
    assert places == expected(texts, table)
    assert kinds(tm) == [("added", None), ("missing", 19), ("renamed", 22)]
    added, missing, renamed = tm.mismatches
    assert added.place is not None and added.place.start == at(EDITED, '<|Delay name="new"')
    assert added.message == 'Delay "new" of the text is not in the running tree'
    assert missing.place is None
    assert missing.message == '#19 AlwaysSuccess "act" (act) is not in the text'
    assert renamed.place is not None and renamed.place.start == places[22][1]
    assert renamed.message == '#22 AlwaysSuccess "ok" (ok) is AlwaysSuccess "fine" in the text'


def test_a_node_of_another_type_with_the_same_children_keeps_them() -> None:
    """Fallback -> ReactiveFallback, a Sequence "seq" -> Fallback "seq": paired by their
    children and by their name, reported as changed."""
    edited = MAIN.replace("<Fallback>", "<ReactiveFallback>").replace(
        "</Fallback>", "</ReactiveFallback>"
    )
    edited = edited.replace('<Sequence name="seq">', '<Fallback name="seq">').replace(
        '    </Sequence>\n  </BehaviorTree>\n  <BehaviorTree ID="Sub">',
        '    </Fallback>\n  </BehaviorTree>\n  <BehaviorTree ID="Sub">',
    )
    texts = {"main.xml": edited, "inc.xml": INC}
    tm, places = mapped(texts)
    table = dict(EXPECTED)
    table[1] = ("main.xml", '<|Fallback name="seq"')
    table[20] = ("main.xml", "<|ReactiveFallback")
    table[21] = ("main.xml", "<ReactiveFallback><|AlwaysFailure")
    assert places == expected(texts, table)
    assert kinds(tm) == [("changed", 1), ("changed", 20)]
    assert tm.mismatches[1].message == (
        "#20 Fallback (Fallback) runs where the text has ReactiveFallback"
    )


def test_a_removed_node_among_equal_siblings() -> None:
    """Three equal leaves, the middle one removed: difflib pairs two of them."""
    live = parse_tree_xml(fulltree(["AlwaysSuccess"] * 3))
    text = tree_text(["AlwaysSuccess"] * 2)
    tm, places = mapped({"main.xml": text}, live=live)
    assert len(tm.missing) == 1 and len(places) == 3


def test_a_subtree_calling_a_renamed_tree() -> None:
    """Inner renamed Inner2 in both places: the running nodes map onto Inner2."""
    inc = INC.replace('ID="Inner"', 'ID="Inner2"')
    edited = MAIN.replace('ID="Inner"', 'ID="Inner2"')
    texts = {"main.xml": edited, "inc.xml": inc}
    tm, places = mapped(texts)
    table = dict(EXPECTED)
    table[5] = table[13] = ("main.xml", '<|SubTree ID="Inner2"')
    assert places == expected(texts, table)
    assert kinds(tm) == [("changed", 5), ("changed", 13)]
    assert 'runs where the text has SubTree "inner" -> Inner2' in tm.mismatches[0].message


def test_a_tree_removed_from_the_include() -> None:
    inc = '<root BTCPP_format="4">\n</root>\n'
    tm, places = mapped({"main.xml": MAIN, "inc.xml": inc})
    assert tm.missing == {6, 7, 8, 14, 15, 16}
    assert kinds(tm) == [("missing", u) for u in (6, 7, 8, 14, 15, 16)]
    assert {5, 13} <= set(places)


def test_a_renamed_main_tree_is_still_mapped() -> None:
    edited = MAIN.replace('"Main"', '"Robot"')
    tm, places = mapped({"main.xml": edited, "inc.xml": INC})
    assert kinds(tm) == [("tree", None)]
    assert tm.mismatches[0].message == (
        "the executor runs tree 'Main', which the text does not declare; mapped onto 'Robot'"
    )
    assert len(places) == len(LIVE.nodes)


def test_a_text_without_trees() -> None:
    tm, places = mapped({"main.xml": '<root BTCPP_format="4"/>'})
    assert places == {} and tm.missing == set(LIVE.nodes) and tm.tree is None
    assert tm.mismatches[0].message.endswith("is not in the text: it has no tree")


def test_an_added_subtree_body_is_reported_once() -> None:
    """Sub runs twice; a node added to its definition is one difference, not two."""
    edited = MAIN.replace("<Inverter>", '<Delay name="late"/>\n      <Inverter>')
    tm, _ = mapped({"main.xml": edited, "inc.xml": INC})
    assert kinds(tm) == [("added", None)]


# ---------------------------------------------------------------- sizes and alignment


def fulltree(tags: list[str]) -> str:
    """A flat tree as BehaviorTree.CPP writes it: a Sequence (uid 1) and its leaves."""
    leaves = "".join(f'<{t} name="{t}" _uid="{i + 2}"/>' for i, t in enumerate(tags))
    return (
        '<root BTCPP_format="4"><BehaviorTree ID="Main" _fullpath="">'
        f'<Sequence name="Sequence" _uid="1">{leaves}</Sequence></BehaviorTree></root>'
    )


def tree_text(tags: list[str]) -> str:
    leaves = "\n".join(f"      <{t}/>" for t in tags)
    return (
        '<root BTCPP_format="4">\n  <BehaviorTree ID="Main">\n    <Sequence>\n'
        f"{leaves}\n    </Sequence>\n  </BehaviorTree>\n</root>\n"
    )


def test_a_large_tree_with_one_node_inserted_and_one_removed() -> None:
    tags = [f"N{i}" for i in range(5000)]
    live = parse_tree_xml(fulltree(tags))
    edited = ["Fresh", *tags[:2500], *tags[2501:]]
    text = tree_text(edited)
    tm, places = mapped({"main.xml": text}, live=live)
    assert kinds(tm) == [("added", None), ("missing", 2502)]
    for i in (0, 2499, 2501, 4999):
        assert places[i + 2] == ("main.xml", at(text, f"<|N{i}/>"))


def test_lists_too_long_for_difflib_are_aligned_greedily() -> None:
    """3000 equal leaves against 3000 others: no pair, every node reported (bounded)."""
    live = parse_tree_xml(fulltree(["A"] * 3000))
    tm, places = mapped({"main.xml": tree_text(["B"] * 3000)}, live=live)
    assert len(places) == 1 and len(tm.missing) == 3000
    assert sum(m.kind == "added" for m in tm.mismatches) == 3000


def test_align_pairs_in_order() -> None:
    a = [("A", None, "a"), ("B", None, "b"), ("C", None, "c")]
    b = [("A", None, "a"), ("X", None, "x"), ("B", None, "b2"), ("C", None, "c")]
    same_type = lambda i, j: a[i][0] == b[j][0]  # noqa: E731
    assert list(align(a, b, same_type)) == [(0, 0), (None, 1), (1, 2), (2, 3)]
    # A counterpart is looked for LOOKAHEAD items ahead at most.
    far = [("Z", None, "z")] * LOOKAHEAD + [("A", None, "renamed")]
    pairs = list(align(a[:1], far, lambda i, j: far[j][0] == "A"))
    assert (0, None) in pairs and len(pairs) == LOOKAHEAD + 2


# ---------------------------------------------------------------- untrusted input


@pytest.mark.parametrize(
    ("xml", "why"),
    [
        ("", "not XML"),
        ("\x00\x01garbage", "not XML"),
        (FULLTREE[: len(FULLTREE) // 2], "not XML"),
        ('<root><BehaviorTree ID="Main"><A/></BehaviorTree></root>', "no valid _uid"),
        (
            '<!DOCTYPE r [<!ENTITY x SYSTEM "file:///etc/passwd">]><root>'
            '<BehaviorTree ID="M" _fullpath=""><A _uid="1" name="&x;"/></BehaviorTree></root>',
            "external entity",
        ),
        (
            "<!DOCTYPE r ["
            '<!ENTITY l0 "lollollollollollol">'
            + "".join(f'<!ENTITY l{i} "{f"&l{i - 1};" * 10}">' for i in range(1, 10))
            + ']><root><BehaviorTree ID="M" _fullpath=""><A _uid="1" name="&l9;"/>'
            "</BehaviorTree></root>",
            "amplification",
        ),
        (
            '<root><BehaviorTree ID="M" _fullpath="">'
            + "".join(f'<A _uid="{i}">' for i in range(1, 2000))
            + "</A>" * 1999
            + "</BehaviorTree></root>",
            "depth",
        ),
    ],
)
def test_malformed_fulltree_is_a_clear_error(xml: str, why: str) -> None:
    model = Document(MAIN).model
    with pytest.raises(ProtocolError, match=why):
        map_tree_xml(xml, model)


def test_an_oversized_fulltree_is_refused(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(live_tree, "MAX_XML_BYTES", 1000)
    with pytest.raises(ProtocolError, match="over the limit"):
        map_tree_xml(FULLTREE, Document(MAIN).model)


@settings(max_examples=150, deadline=None)
@given(st.integers(0, len(FULLTREE) - 1), st.sampled_from('<>"=/_ 0123456789&;'))
def test_fuzz_mutated_fulltree(at_: int, char: str) -> None:
    model = Document(MAIN).model
    with contextlib.suppress(ProtocolError):
        tm = map_tree_xml(FULLTREE[:at_] + char + FULLTREE[at_ + 1 :], model)
        assert tm.places or tm.missing


@settings(max_examples=150, deadline=None)
@given(st.integers(0, len(MAIN)), st.integers(0, 40), st.sampled_from(["", "<A/>", "</", "<B>"]))
def test_fuzz_edited_text_maps_every_uid_or_reports_it(start: int, size: int, new: str) -> None:
    text = MAIN[:start] + new + MAIN[start + size :]
    mapped({"main.xml": text, "inc.xml": INC})
