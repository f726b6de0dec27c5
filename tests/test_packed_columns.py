"""A small section's columns are packed into one array once built (``table.Packed``): its
elements read exactly as from the columns the builder wrote, before and after edits that
move or rebuild sections."""

from __future__ import annotations

from typing import Any

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from bt_lsp.syntax import table
from bt_lsp.syntax.document import Document
from bt_lsp.syntax.elements import Element

_NODES = st.sampled_from(
    [
        "<AlwaysSuccess/>",
        '<SubTree ID="T1" goal="{g}"/>',
        "<Sequence><Frob/><Inverter><AlwaysFailure/></Inverter></Sequence>",
        "<Fallback>\n  <Frob a='1'/>\r\n</Fallback>",
        "<!-- c --><Frob>text</Frob>",
        "<Sequence><Frob/>",  # left open
        "</Stray>",
    ]
)
_TREES = st.lists(st.lists(_NODES, max_size=4).map("".join), min_size=1, max_size=6)
_MODELS = (
    '<TreeNodesModel><Action ID="Frob"><input_port name="a">the a</input_port>'
    "</Action></TreeNodesModel>"
)


def _text(trees: list[str]) -> str:
    body = "".join(f'<BehaviorTree ID="T{i}">{t}</BehaviorTree>\n' for i, t in enumerate(trees))
    return f'<root BTCPP_format="4">\n{body}{_MODELS}</root>\n'


def _read(el: Element) -> tuple[Any, ...]:
    return (
        el.tag,
        el.name,
        el.zone,
        el.token_start,
        el.token_index,
        el.parent,
        el.depth,
        el.end,
        el.end_name_start,
        list(el.children),
        el.content,
    )


def _all(doc: Document) -> list[tuple[Any, ...]]:
    els = doc.model.elements
    return [_read(el) for el in els] + [_read(els[i]) for i in range(len(els))]


def _unpacked(text: str, monkeypatch: pytest.MonkeyPatch) -> list[tuple[Any, ...]]:
    with monkeypatch.context() as m:
        m.setattr(table, "PACKED_ROWS", 0)
        return _all(Document(text))


@settings(max_examples=80, deadline=None)
@given(_TREES, st.data())
def test_packed_sections_read_as_the_columns_written(trees: list[str], data: st.DataObject) -> None:
    monkeypatch = pytest.MonkeyPatch()
    text = _text(trees)
    doc = Document(text)
    packed = [p.section.elements.columns for p in doc.model.parts()]
    assert any(isinstance(c, table.Packed) for c in packed)
    assert _all(doc) == _unpacked(text, monkeypatch)
    # An edit somewhere: moved sections and rebuilt ones read as a fresh build's.
    at = data.draw(st.integers(0, len(text)))
    new = data.draw(st.sampled_from(["", "\n", "<Frob/>", '<BehaviorTree ID="N"><Frob/>']))
    doc.edit(at, at, new)
    edited = text[:at] + new + text[at:]
    assert _all(doc) == _unpacked(edited, monkeypatch)


def _columns(cols: table.Columns) -> tuple[Any, ...]:
    n = len(cols)
    named = (
        cols.tags,
        cols.zones,
        cols.starts,
        cols.tindex,
        cols.parents,
        cols.depths,
        cols.extents,
        cols.names_at,
        cols.child_at,
        cols.child_n,
        cols.flat,
    )
    return (
        [list(c) for c in named],
        [list(cols.row(k)) for k in range(n)],
        [[list(c) for c in cols.window(a, n)] for a in range(n)],
        [list(cols.window(0, b)[1]) for b in range(n + 1)],
        [list(cols.children_of(k)) for k in range(n)],
        dict(cols.contents),
    )


def test_short_and_long_packed_columns_read_as_written(monkeypatch: pytest.MonkeyPatch) -> None:
    """Two bytes an integer where they fit: trees far (over 32 KiB) from the root's start
    keep the root's offsets apart; a tree of a few rows over 32 KiB long keeps four."""
    far = "<!--" + "x" * 40_000 + "-->"
    text = _text(
        [f"<Sequence><Frob/>{far}</Sequence>", "<Frob/>", '<SubTree ID="T1"/><Frob/>', "<Frob/>"]
    )
    doc = Document(text)
    sections = [p.section for p in doc.model.parts()]
    packed = [s.elements.columns for s in sections]
    kinds = {c._ints.typecode for c in packed if isinstance(c, table.Packed)}
    assert kinds == {"h", "i"}
    with monkeypatch.context() as m:
        m.setattr(table, "PACKED_ROWS", 0)
        plain = [p.section.elements.columns for p in Document(text).model.parts()]
    assert all(isinstance(c, table.Growing) for c in plain)
    assert [_columns(c) for c in packed] == [_columns(c) for c in plain]
    root_starts = [c.starts[0] for c in packed[1:]]
    assert min(root_starts) < -(1 << 15)  # the root's start, kept apart, read back whole
    assert _all(doc) == _unpacked(text, monkeypatch)
