"""What an edit reuses gives what a fresh analysis gives.

An edit re-scans the tokens around it, rebuilds the model's sections around them, and
re-checks only the sections whose inputs changed (see ``bt_lsp.syntax.builder`` and
``bt_lsp.rules.semantics.sections``).  These tests edit documents at random places, with text
that changes the structure, names and declarations, and compare every step with a fresh
document: tokens, the model (elements, name tokens, problems, lookups), the document's own
diagnostics, the semantic ones alone and in a workspace of two documents that include and
declare for each other.
"""

from __future__ import annotations

import random
from pathlib import Path
from typing import Any

import pytest

from bt_lsp.project.index import ProjectIndex
from bt_lsp.rules.analysis import analyze
from bt_lsp.rules.context import facts_of
from bt_lsp.rules.diagnostics import own_diagnostics
from bt_lsp.rules.semantics.base import edit_distance
from bt_lsp.syntax import scanner
from bt_lsp.syntax.document import Document
from bt_lsp.syntax.model import Model
from bt_lsp.syntax.scanner import rescan, scan
from bt_lsp.syntax.text import LineIndex, Offsets

MAIN = """<?xml version="1.0"?>
<!-- a comment -->
<root BTCPP_format="4" main_tree_to_execute="Main">
  <include path="models.xml"/>
  <BehaviorTree ID="Main">
    <Sequence name="main sequence">
      <MoveTo goal="{goal}" speed="1.5"/>
      <SubTree ID="Helper" target="{goal}" name="helper"/>
      <Action ID="Grab" object="cup"/>
      <Check.It/>
      <RetryUntilSuccessful num_attempts="3"><Fallback><Open door="d"/><Wait/></Fallback>
      </RetryUntilSuccessful>
      <Script code="x := 1"/>
    </Sequence>
  </BehaviorTree>
  <BehaviorTree ID="Helper">
    <ReactiveSequence><MoveTo goal="{target}"/><SubTree ID="Main"/></ReactiveSequence>
  </BehaviorTree>
  <BehaviorTree ID="Main Tree"><AlwaysSuccess name="a&#7;b"/></BehaviorTree>
  <TreeNodesModel>
    <Action ID="Grab"><input_port name="object" type="std::string"/></Action>
    <Condition ID="Check.It"/>
    <SubTree ID="Helper"><input_port name="target"/></SubTree>
  </TreeNodesModel>
</root>
"""

MODELS = """<root BTCPP_format="4">
  <BehaviorTree ID="Other"><AlwaysSuccess/></BehaviorTree>
  <TreeNodesModel>
    <Action ID="MoveTo"><input_port name="goal" type="int"/>
      <input_port name="speed" type="double"/></Action>
    <Action ID="Open"><input_port name="door"/></Action>
  </TreeNodesModel>
</root>
"""

PIECES = [
    "x", "", " ", "\n", "<", ">", '"', "/>", "</", "=", "&amp;", "😋",
    "<A/>", "<B>", "</B>", "</Sequence>", "</BehaviorTree>", "</root>", "<root>",
    "<BehaviorTree ID='Q'><Wait/></BehaviorTree>", "<SubTree ID='Q'/>", "<!--", "-->",
    "Main", "Helper", "MoveTo", "Grab", "ID", "name", "int", "double", "Open",
    ' BTCPP_format="4"', "<TreeNodesModel><Action ID='Wait'/></TreeNodesModel>",
]  # fmt: skip


def _edit(rng: random.Random, doc: Document) -> None:
    text = doc.text
    start = rng.randint(0, len(text))
    end = min(len(text), start + rng.choice((0, 0, 1, 3, 12)))
    doc.edit(start, end, rng.choice(PIECES))


def _model_view(model: Model) -> Any:
    elements = [
        (e.name, e.zone, e.token_start, e.token_index, e.parent, e.depth, e.attrs,
         e.self_closing, e.closed, e.end, e.end_name_start, e.end_name_end, e.children)
        for e in model.elements
    ]  # fmt: skip
    refs = list(model.refs)
    problems = sorted(model.problems)
    return elements, refs, problems, dict(model.by_symbol)


@pytest.mark.parametrize("seed", range(6))
def test_model_after_edits_equals_a_fresh_one(seed: int) -> None:
    rng = random.Random(seed)
    doc = Document(MAIN)
    for _ in range(25):
        _ = doc.model
        for _ in range(rng.randint(1, 3)):  # several edits may come before a model
            _edit(rng, doc)
        fresh = Document(doc.text)
        assert doc.scan.tokens == fresh.scan.tokens
        assert doc.scan.starts == fresh.scan.starts
        assert _model_view(doc.model) == _model_view(fresh.model)
        for offset in range(0, len(doc.text) + 1, 7):
            assert doc.model.ref_at(offset) == fresh.model.ref_at(offset)
        assert own_diagnostics(doc) == own_diagnostics(fresh)


@pytest.mark.parametrize("seed", range(6))
def test_semantic_diagnostics_after_edits_equal_fresh_ones(seed: int) -> None:
    rng = random.Random(100 + seed)
    doc = Document(MAIN)
    analyze(doc)
    for _ in range(25):
        _edit(rng, doc)
        assert analyze(doc) == analyze(Document(doc.text))


@pytest.mark.parametrize("seed", range(4))
def test_workspace_diagnostics_after_edits_equal_fresh_ones(seed: int, tmp_path: Path) -> None:
    rng = random.Random(200 + seed)
    main, models = tmp_path / "main.xml", tmp_path / "models.xml"
    main.write_text(MAIN, encoding="utf-8")
    models.write_text(MODELS, encoding="utf-8")
    ws = ProjectIndex([tmp_path])
    docs = {main: Document(MAIN, str(main)), models: Document(MODELS, str(models))}
    for path, doc in docs.items():
        ws.open(path, doc)
        ws.diagnostics(path, doc)
    for _ in range(15):
        _edit(rng, docs[rng.choice((main, models))])
        fresh_ws = ProjectIndex([tmp_path])
        fresh = {p: Document(d.text, str(p)) for p, d in docs.items()}
        for p, d in fresh.items():
            fresh_ws.open(p, d)
        for path, doc in docs.items():
            assert ws.diagnostics(path, doc) == fresh_ws.diagnostics(path, fresh[path])


@pytest.mark.parametrize("seed", range(6))
def test_workspace_diagnostics_of_snapshots_equal_fresh_ones(seed: int, tmp_path: Path) -> None:
    """As the server analyses a large document: a snapshot of the open document, on which
    the project's caches are kept, handed back to the open document afterwards; sometimes
    the open document is edited again before (its snapshot's analysis is then of an older
    text), and the other document's analysis follows an edit of either."""
    rng = random.Random(400 + seed)
    main, models = tmp_path / "main.xml", tmp_path / "models.xml"
    main.write_text(MANY, encoding="utf-8")
    models.write_text(MODELS, encoding="utf-8")
    ws = ProjectIndex([tmp_path])
    docs = {main: Document(MANY, str(main)), models: Document(MODELS, str(models))}
    for path, doc in docs.items():
        ws.open(path, doc)
        ws.diagnostics(path, doc)
    for _ in range(20):
        edited = rng.choice((main, main, models))
        doc = docs[edited]
        _edit(rng, doc)
        snap = doc.snapshot()
        fresh_snap = Document(snap.text, str(edited))
        if rng.random() < 0.3:
            _edit(rng, doc)  # while the snapshot is analysed
        got = ws.diagnostics(edited, snap)
        doc.adopt(snap)
        assert got == _fresh_diagnostics(tmp_path, docs, edited, fresh_snap)
        other = models if edited == main else main
        got = ws.diagnostics(other, docs[other].snapshot())
        assert got == _fresh_diagnostics(
            tmp_path, docs, other, Document(docs[other].text, str(other))
        )


def test_a_lookup_that_missed_counts_when_declared_after_other_changes() -> None:
    """A tree's lookup that found nothing (the ``<SubTree>`` model of T3) still counts
    once the entry is declared, after edits that re-checked other trees only (the check
    keeps what the results it did not look at again missed)."""
    text = (
        '<root BTCPP_format="4" main_tree_to_execute="T0">\n'
        '<BehaviorTree ID="T0"><Sequence><SubTree ID="T3" y="1"/><Wait/></Sequence>'
        "</BehaviorTree>\n"
        '<BehaviorTree ID="T1"><Sequence><SubTree ID="T4"/><Wait/></Sequence></BehaviorTree>\n'
        '<BehaviorTree ID="T3"><AlwaysSuccess/></BehaviorTree>\n'
        '<BehaviorTree ID="T4"><AlwaysSuccess/></BehaviorTree>\n'
        '<TreeNodesModel><Action ID="Wait"/></TreeNodesModel>\n'
        "</root>\n"
    )
    doc = Document(text)
    assert analyze(doc) == []
    tree4 = '<BehaviorTree ID="T4"><AlwaysSuccess/>'
    for edit in ('<SubTree ID="T1"/>', "<Wait/>"):  # T4's calls change (T1 reads them)
        at = doc.text.index(tree4) + len(tree4)
        doc.edit(at, at, edit)
        assert analyze(doc) == analyze(Document(doc.text))
    at = doc.text.index('<Action ID="Wait"/>')
    doc.edit(at, at, '<SubTree ID="T3"><input_port name="x"/></SubTree>')
    found = analyze(doc)
    assert found == analyze(Document(doc.text))
    assert {"missing-required-port", "undeclared-port"} <= {d.code for d in found}


def _fresh_diagnostics(
    folder: Path, docs: dict[Path, Document], path: Path, doc: Document
) -> list[Any]:
    """The diagnostics of ``doc`` at ``path`` in a new workspace of ``folder`` where the
    other documents are open with their texts now."""
    ws = ProjectIndex([folder])
    for p, d in docs.items():
        ws.open(p, doc if p == path else Document(d.text, str(p)))
    return ws.diagnostics(path, doc)


@pytest.mark.parametrize("block", [1, 2, 3, 7])
def test_token_starts_in_small_blocks(block: int, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(scanner.Starts, "BLOCK", block)
    rng = random.Random(block)
    text = MAIN
    old = scan(text)
    for _ in range(60):
        start = rng.randint(0, len(text))
        end = min(len(text), start + rng.randint(0, 20))
        insert = rng.choice(PIECES)
        new_text = text[:start] + insert + text[end:]
        old, _ = rescan(old, new_text, start, end, len(insert))
        text = new_text
        full = scan(text)
        assert old.tokens == full.tokens
        assert old.starts.tolist() == full.starts.tolist() == list(old.starts)
        assert len(old.starts) == len(full.starts)
        for offset in range(0, len(text) + 1, 5):
            assert old.index_at(offset) == full.index_at(offset)


@pytest.mark.parametrize("block", [1, 2, 5])
def test_line_starts_in_small_blocks(block: int, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(Offsets, "BLOCK", block)
    rng = random.Random(block)
    text = "a\nb\r\nc\rd\n\n" * 4
    lines = LineIndex(text)
    for _ in range(300):
        start = rng.randint(0, len(text))
        end = min(len(text), start + rng.randint(0, 6))
        insert = rng.choice(["", "\n", "\r", "\r\n", "x", "\n\n", "ab\rc"])
        new_text = text[:start] + insert + text[end:]
        lines = lines.edited(start, end, insert, new_text)
        text = new_text
        fresh = LineIndex(text)
        assert lines == fresh and lines.line_starts == fresh.line_starts
        for offset in range(0, len(text) + 1, 3):
            assert lines.position(offset, "utf-16") == fresh.position(offset, "utf-16")


def _levenshtein(a: str, b: str) -> int:
    prev = list(range(len(b) + 1))
    for i, ca in enumerate(a, 1):
        cur = [i]
        for j, cb in enumerate(b, 1):
            cur.append(min(prev[j] + 1, cur[j - 1] + 1, prev[j - 1] + (ca != cb)))
        prev = cur
    return prev[-1]


def test_edit_distance_is_levenshtein_up_to_the_limit() -> None:
    rng = random.Random(5)
    for _ in range(3000):
        a = "".join(rng.choice("abc") for _ in range(rng.randint(0, 8)))
        b = "".join(rng.choice("abc") for _ in range(rng.randint(0, 8)))
        limit = rng.randint(0, 3)
        assert edit_distance(a, b, limit) == min(_levenshtein(a, b), limit + 1)


# Trees enough that most edits have sections before and after them.
MANY = MAIN.replace(
    "  <TreeNodesModel>",
    "".join(
        f'  <BehaviorTree ID="T{i}"><Sequence><SubTree ID="T{i + 1}"/><Wait/></Sequence>'
        "</BehaviorTree>\n"
        for i in range(12)
    )
    + "  <TreeNodesModel>",
)


@pytest.mark.parametrize("seed", range(8))
def test_declarations_after_edits_equal_fresh_ones(seed: int) -> None:
    """The facts of an edited document are made from those of its last version (the
    sections before and after the edit kept or moved): they equal a fresh extraction,
    with several edits between two extractions too."""
    rng = random.Random(300 + seed)
    doc = Document(MANY, "/w/main.xml")
    facts_of(doc)
    for step in range(30):
        for _ in range(rng.randint(1, 3) if step % 2 else 1):
            _edit(rng, doc)
        got, want = facts_of(doc), facts_of(Document(doc.text, "/w/main.xml"))
        assert got == want
        assert [t.call_spans for t in got.trees] == [t.call_spans for t in want.trees]
        if want.layout is not None:
            assert got.layout is not None
            assert list(got.layout.origins) == list(want.layout.origins)
            assert got.layout.trees_at == want.layout.trees_at
            assert got.layout.models_at == want.layout.models_at
            assert got.layout.subtree_models_at == want.layout.subtree_models_at


def test_declarations_of_an_edit_are_made_from_the_last_version() -> None:
    """Typing inside one tree keeps the declarations before it and moves those after it,
    without making them again from their sections."""
    doc = Document(MANY, "/w/main.xml")
    before = facts_of(doc)
    at = doc.text.index("<Wait/>", doc.text.index('<BehaviorTree ID="T5">')) + len("<Wait")
    doc.edit(at, at, " ")
    after = facts_of(doc)
    k = [t.id for t in before.trees].index("T5")
    assert after.trees[:k] == before.trees[:k]
    assert all(a is b for a, b in zip(after.trees[:k], before.trees[:k], strict=True))
    assert after.trees[k] == before.trees[k]  # the edit is after its ID
    assert [t.start for t in after.trees[k + 1 :]] == [t.start + 1 for t in before.trees[k + 1 :]]
    assert after.models[0].start == before.models[0].start + 1
    assert facts_of(doc) is after


def test_a_cycle_found_before_an_edit_is_reported_where_it_now_is() -> None:
    """The walk for cycles is used again while the calls between trees are the same; its
    report follows the call it names when an edit before the call moves it."""
    doc = Document(MANY)
    first = [d for d in analyze(doc) if d.code == "subtree-recursion"]
    assert len(first) == 1
    at = doc.text.index("<Sequence")
    doc.edit(at, at, "<!-- moved -->")
    (moved,) = [d for d in analyze(doc) if d.code == "subtree-recursion"]
    assert (moved.start, moved.end) == (first[0].start + 14, first[0].end + 14)
    assert doc.text[moved.start : moved.end] == "Main"
    # A change of the calls is walked again: with Helper's call gone, no cycle is left.
    call = doc.text.index('<SubTree ID="Main"/>')
    doc.edit(call, call + len('<SubTree ID="Main"/>'), "<Wait/>")
    assert not [d for d in analyze(doc) if d.code == "subtree-recursion"]
