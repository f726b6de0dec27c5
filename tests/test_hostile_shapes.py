"""Shapes that a recursive walk or a per-tree search would break: trees nested far
beyond BehaviorTree.CPP's 256 levels and long chains of SubTree calls (each tree calling
the next, or one tree calling thousands).  Each gives exactly its diagnostics, and the
outline, folding, hover, definition and the tree picture answer, with no RecursionError
(the sizes are well past Python's recursion limit of 1,000)."""

from __future__ import annotations

import json
import sys
from collections.abc import Iterator

import pytest

from bt_lsp.ide.definition import definition
from bt_lsp.ide.folding import folding_ranges
from bt_lsp.ide.hover import hover_at
from bt_lsp.ide.references import references
from bt_lsp.ide.symbols import document_symbols
from bt_lsp.render import render
from bt_lsp.render.picture import build_picture, main_tree
from bt_lsp.rules.analysis import analyze
from bt_lsp.rules.context import Context
from bt_lsp.server.navigation import outline_json
from bt_lsp.syntax.document import Document
from tests.pinned import pinned

DEPTH = 5_000  # nested Sequences
TREES = 3_000  # trees in a chain of calls


@pytest.fixture(autouse=True)
def _no_deep_recursion() -> Iterator[None]:
    """Python's default limit, whatever an earlier test set: deeper recursion fails."""
    limit = sys.getrecursionlimit()
    sys.setrecursionlimit(1_000)
    yield
    sys.setrecursionlimit(limit)


def deep(depth: int) -> str:
    return (
        '<root BTCPP_format="4">\n<BehaviorTree ID="Deep">\n'
        + "".join(f'<Sequence name="s{i}">\n' for i in range(depth))
        + '<AlwaysSuccess name="leaf"/>\n'
        + "</Sequence>\n" * depth
        + "</BehaviorTree>\n</root>\n"
    )


def chain(n: int, *, cycle: bool = False) -> str:
    """Trees T0 .. Tn, each Ti calling T(i+1); with ``cycle`` the last calls T0."""
    body = "".join(
        f'<BehaviorTree ID="T{i}"><Sequence><SubTree ID="T{i + 1}"/><AlwaysSuccess/>'
        "</Sequence></BehaviorTree>\n"
        for i in range(n)
    )
    last = '<SubTree ID="T0"/>' if cycle else "<AlwaysSuccess/>"
    return (
        '<root BTCPP_format="4" main_tree_to_execute="T0">\n'
        f'{body}<BehaviorTree ID="T{n}">{last}</BehaviorTree>\n</root>\n'
    )


def fan_out(n: int) -> str:
    """A main tree calling n trees, each of which calls the same leaf tree."""
    calls = "".join(f'<SubTree ID="T{i}"/>' for i in range(n))
    trees = "".join(
        f'<BehaviorTree ID="T{i}"><SubTree ID="Leaf"/></BehaviorTree>\n' for i in range(n)
    )
    return (
        '<root BTCPP_format="4" main_tree_to_execute="Main">\n'
        f'<BehaviorTree ID="Main"><Sequence>{calls}</Sequence></BehaviorTree>\n{trees}'
        '<BehaviorTree ID="Leaf"><AlwaysSuccess/></BehaviorTree>\n</root>\n'
    )


def test_nesting_far_beyond_the_limit() -> None:
    text = deep(DEPTH)
    doc = Document(text)
    ctx = Context.from_document(doc)
    (diag,) = pinned(analyze(doc, ctx))
    assert diag.code == "nesting-depth"
    # The first element too deep: the 257th level below <BehaviorTree>.
    assert diag.start == text.index('<Sequence name="s256"') + 1
    assert "257 levels" in diag.message
    symbols = document_symbols(doc, ctx)
    depth, node = 0, symbols[0]
    while node.children:
        (node,) = node.children
        depth += 1
    assert (depth, node.name) == (DEPTH + 1, "leaf")
    outline = json.loads(outline_json(doc, ctx, "utf-16"))
    assert outline[0]["name"] == "Deep"
    assert len(folding_ranges(doc)) >= DEPTH
    leaf = text.index("AlwaysSuccess")
    hover = hover_at(doc, leaf, ctx)
    assert hover is not None and "AlwaysSuccess" in hover.text
    tree = main_tree(doc.model)
    assert tree is not None
    picture = build_picture(doc.model, tree, ctx=ctx)
    assert len(picture.nodes) == DEPTH + 2
    svg, _ = render(doc.model, tree, "svg", ctx=ctx)
    assert svg.count("s4999") >= 1


def test_a_long_chain_of_subtree_calls() -> None:
    text = chain(TREES)
    doc = Document(text)
    ctx = Context.from_document(doc)
    assert pinned(analyze(doc, ctx)) == []
    last_call = text.index(f'<SubTree ID="T{TREES}"') + len('<SubTree ID="')
    (place,) = definition(doc, last_call, ctx=ctx)
    assert place.start == text.index(f'<BehaviorTree ID="T{TREES}"') + len('<BehaviorTree ID="')
    assert len(references(doc, last_call)) == 2
    tree = main_tree(doc.model)
    assert tree is not None
    picture = build_picture(doc.model, tree, ctx=ctx, expand_subtrees=True)
    calls = [n for n in picture.nodes if n.kind == "subtree"]
    assert len(calls) == TREES and all(n.expanded and not n.recursive for n in calls)
    assert max(n.depth for n in picture.nodes) == 2 * TREES + 1
    mermaid, _ = render(doc.model, tree, "mermaid", ctx=ctx, expand_subtrees=True)
    assert f"T{TREES}" in mermaid


def test_a_chain_that_closes_a_cycle() -> None:
    text = chain(TREES, cycle=True)
    doc = Document(text)
    ctx = Context.from_document(doc)
    (diag,) = pinned(analyze(doc, ctx))
    assert diag.code == "subtree-recursion"
    call = text.rindex('<SubTree ID="T0"') + len('<SubTree ID="')
    assert (diag.start, diag.end) == (call, call + 2)
    assert f"T{TREES - 1} → T{TREES} → T0" in diag.message
    tree = main_tree(doc.model)
    assert tree is not None
    picture = build_picture(doc.model, tree, ctx=ctx, expand_subtrees=True)
    calls = [n for n in picture.nodes if n.kind == "subtree"]
    assert len(calls) == TREES + 1
    assert [n.subtree for n in calls if n.recursive] == ["T0"]


def test_one_tree_calling_thousands() -> None:
    text = fan_out(TREES)
    doc = Document(text)
    ctx = Context.from_document(doc)
    assert pinned(analyze(doc, ctx)) == []
    broken = Document(text.replace('<BehaviorTree ID="Leaf">', '<BehaviorTree ID="Lef">'))
    found = pinned(analyze(broken))  # every call of the missing tree, up to the cap
    assert [d.code for d in found] == ["unknown-subtree"] * 2000 + ["too-many-problems"]
    tree = main_tree(doc.model)
    assert tree is not None
    picture = build_picture(doc.model, tree, ctx=ctx, expand_subtrees=True)
    assert sum(n.type == "AlwaysSuccess" for n in picture.nodes) == TREES
