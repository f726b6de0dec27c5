"""A document kept current by edits always agrees with a fresh analysis of its text."""

from __future__ import annotations

from typing import Any

from hypothesis import given, settings
from hypothesis import strategies as st

from bt_lsp.rules.diagnostics import own_diagnostics
from bt_lsp.syntax.document import Document, looks_like_bt
from bt_lsp.syntax.kind import HEAD_CHARS
from bt_lsp.syntax.text import LineIndex

BASE = (
    '<root BTCPP_format="4" main_tree_to_execute="Main Tree">\r\n'
    '  <BehaviorTree ID="Main Tree">\n'
    '    <Sequence name="s&#7;">\t<Open.Door door.id="{d}" 😋="1"/>\r'
    '      <SubTree ID="Sub" p="1"/></Sequence>\n'
    "  </BehaviorTree>\n"
    '  <TreeNodesModel><Action ID="Open.Door"><input_port name="door.id"/></Action>'
    "</TreeNodesModel>\n</root>\n"
)
INSERTS = [
    "<",
    ">",
    '"',
    " ",
    ".",
    "\r\n",
    "\n",
    "<A ",
    "</Sequence>",
    "&amp;",
    "😋",
    "x",
    '="',
    "<!--",
    "-->",
    "/>",
]


@given(st.data())
@settings(max_examples=200, deadline=None)
def test_edits_equal_fresh_analysis(data: st.DataObject) -> None:
    doc = Document(BASE)
    for _ in range(data.draw(st.integers(1, 6))):
        n = len(doc.text)
        start = data.draw(st.integers(0, n))
        end = data.draw(st.integers(start, min(n, start + 8)))
        new = data.draw(st.sampled_from(INSERTS) | st.text(max_size=3))
        _ = own_diagnostics(doc)  # force the cached state before editing
        doc.edit(start, end, new)
        fresh = Document(doc.text)
        assert doc.lines == LineIndex(doc.text)
        assert doc.scan.tokens == fresh.scan.tokens
        assert own_diagnostics(doc) == own_diagnostics(fresh)


def test_every_diagnostic_range_slices_its_token() -> None:
    doc = Document(BASE)
    spans = {doc.text[d.start : d.end] for d in own_diagnostics(doc)}
    assert {"Main Tree", "s&#7;", "Open.Door", "door.id"} <= spans


_KIND_PIECES = st.sampled_from(
    [
        "<root",
        " ",
        ">",
        "/",
        "x",
        "<ro",
        "ot ",
        "\n",
        "<Behavior",
        "Tree>",
        "<TreeNodesModel",
        "<include/>",
        "BTCPP_format=",
        "<!--",
        "-->",
    ]
)
_KIND_TEXT = st.lists(_KIND_PIECES, max_size=8).map("".join)


@settings(max_examples=300, deadline=None)
@given(
    _KIND_TEXT,
    st.booleans(),
    st.lists(st.tuples(st.floats(0, 1), st.floats(0, 1), _KIND_TEXT), max_size=6),
)
def test_the_kind_after_edits_is_that_of_the_text(
    text: str, scanned: bool, edits: list[tuple[float, float, str]]
) -> None:
    """An edit finds whether the text is still BT XML around itself (a marker before it
    stays, one may appear only around it): always what a search of the whole text says."""
    doc = Document(text, scanned=scanned)
    assert doc.is_bt == looks_like_bt(text)
    for a, b, new in edits:
        start = int(a * len(text))
        end = start + int(b * (len(text) - start))
        doc.edit(start, end, new)
        text = text[:start] + new + text[end:]
        assert doc.is_bt == looks_like_bt(text), text


def test_looks_like_bt() -> None:
    """BT XML by its own content: a tree, a catalog or BTCPP_format anywhere in the head
    (a misspelt top element still tries to be BT), or a <root> that includes others."""
    assert looks_like_bt("<?xml?><root BTCPP_format='4'/>")
    assert looks_like_bt("<x><BehaviorTree ID='a'/></x>")
    assert looks_like_bt("<roo><BehaviorTree ID='a'/></roo>")
    assert looks_like_bt("<Root><TreeNodesModel/></Root>")
    assert looks_like_bt("<root><include path='a.xml'/></root>")
    assert looks_like_bt("<root main_tree_to_execute = 'M'/>")
    assert not looks_like_bt("<root>")  # another tool's generic <root>
    assert not looks_like_bt("<root><Sequence/></root>")
    assert not looks_like_bt("<Sequence name='ACTION_ID'><Action/></Sequence>")  # a fragment
    assert not looks_like_bt("<profiles><root><include path='x'/></root></profiles>")
    assert not looks_like_bt("<!-- <root BTCPP_format> --><server description='x'/>")
    assert not looks_like_bt("<launch><node name='a.b'/></launch>")
    assert not looks_like_bt("<package><name>rootless</name></package>")
    # Only the head counts: what a sniff of a file's first bytes sees.
    assert not looks_like_bt("<x>" + " " * HEAD_CHARS + "<BehaviorTree ID='a'/></x>")


def test_an_edit_past_the_head_keeps_the_kind() -> None:
    text = "<x>" + " " * HEAD_CHARS
    doc = Document(text)
    assert not doc.is_bt
    doc.edit(HEAD_CHARS + 2, HEAD_CHARS + 2, "<BehaviorTree ID='a'/>")
    assert not doc.is_bt
    doc.edit(0, 0, "<root BTCPP_format='4'>")
    assert doc.is_bt


def _fresh_model(text: str) -> list[tuple[str, int, int]]:
    return [(e.name, e.token_start, e.end) for e in Document(text).model.elements]


def test_a_snapshot_is_left_alone_by_later_edits() -> None:
    doc = Document(BASE)
    doc.model  # noqa: B018 - the edit below then builds from a base model
    snap = doc.snapshot()
    doc.edit(0, 0, "<!-- x -->")
    assert snap.text == BASE and doc.text.startswith("<!-- x -->")
    assert [(e.name, e.token_start, e.end) for e in snap.model.elements] == _fresh_model(BASE)
    assert [(e.name, e.token_start, e.end) for e in doc.model.elements] == _fresh_model(doc.text)
    assert own_diagnostics(snap) == own_diagnostics(Document(BASE))


def test_adopt_keeps_what_a_snapshot_built_only_if_unedited() -> None:
    doc = Document(BASE)
    snap = doc.snapshot()
    own = own_diagnostics(snap)
    doc.adopt(snap)
    assert doc.model is snap.model and doc.own_diagnostics is own
    edited = Document(BASE)
    later = edited.snapshot()
    later.model  # noqa: B018
    edited.edit(0, 0, " ")
    edited.adopt(later)
    assert edited.model is not later.model
    assert edited.model.elements[0].token_start == 1


def test_a_model_built_while_an_edit_came_in_is_not_kept(monkeypatch: Any) -> None:
    """Another thread may edit the document while its model is built (outside the
    lock): that model answers the caller who asked, and the next one is of the edit."""
    import bt_lsp.syntax.document as document

    doc = Document(BASE)
    real = document.build  # type: ignore[attr-defined]
    calls: list[int] = []

    def build_with_an_edit(*args: Any) -> Any:
        calls.append(1)
        if len(calls) == 1:
            doc.edit(0, 0, "  ")  # what the other thread does meanwhile
        return real(*args)

    monkeypatch.setattr(document, "build", build_with_an_edit)
    stale = doc.model
    assert stale.elements[0].token_start == 0  # built from the state before the edit
    fresh = doc.model
    assert fresh is not stale and fresh.elements[0].token_start == 2
    assert doc.model is fresh and len(calls) == 2


@given(st.data())
@settings(max_examples=100, deadline=None)
def test_an_unscanned_document_is_the_same_once_used(data: st.DataObject) -> None:
    """``scanned=False`` only delays the line index and tokens: edited before or after
    :meth:`Document.prepare`, the document equals one scanned at once."""
    lazy = Document(BASE, scanned=False)
    eager = Document(BASE)
    assert not lazy.scanned
    if data.draw(st.booleans()):
        lazy.prepare()
        assert lazy.scanned
    for _ in range(data.draw(st.integers(0, 3))):
        n = len(lazy.text)
        start = data.draw(st.integers(0, n))
        end = data.draw(st.integers(start, min(n, start + 8)))
        new = data.draw(st.sampled_from(INSERTS))
        lazy.edit(start, end, new)
        eager.edit(start, end, new)
    assert lazy.text == eager.text
    assert lazy.lines == eager.lines
    assert lazy.scan.tokens == eager.scan.tokens
    assert own_diagnostics(lazy) == own_diagnostics(eager)


def test_prepare_makes_what_the_loop_would_otherwise_make() -> None:
    doc = Document(BASE, scanned=False)
    doc.prepare(model=False)
    assert doc._lines is not None and not doc.scanned  # a text that is not BT: no tokens
    doc.prepare()
    assert doc.scanned and doc._model is not None
    doc.replace_all(BASE + " ", scanned=False)
    assert not doc.scanned and doc.lines == LineIndex(BASE + " ")


def test_an_edit_of_a_document_never_scanned_does_not_scan_it() -> None:
    """A text that is not BT (a large C++ or launch file) is never scanned as XML: its
    edits update the text and line index only."""
    doc = Document(BASE, scanned=False)
    doc.edit(0, 0, " ")
    doc.edit(5, 9, "")
    assert not doc.scanned
    text = (" " + BASE)[:5] + (" " + BASE)[9:]
    assert doc.text == text and doc.lines == LineIndex(text)
    assert doc.scan.tokens == Document(text).scan.tokens


def test_a_whole_new_text_keeps_the_document_history() -> None:
    """A client that sends the whole text at every change edits the same document: the
    rules' caches, keyed by its history, continue; its snapshots share that history."""
    doc = Document(BASE)
    history = doc.history
    doc.replace_all(BASE + " ")
    assert doc.history is history and doc.snapshot().history is history
    assert doc.text == BASE + " " and doc.lines == LineIndex(BASE + " ")
