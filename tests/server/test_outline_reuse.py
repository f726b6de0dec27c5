"""The outline after an edit is made of the sections' kept pieces: it is always the
outline of the whole document made afresh (in every encoding, with CRLF, non-BMP
characters, unclosed elements, text outside the root), and an edit rebuilds only the
sections it changed."""

from __future__ import annotations

from hypothesis import given, settings
from hypothesis import strategies as st

from bt_lsp.ide.symbols import SectionOutline, document_symbols, outline_parts
from bt_lsp.rules.context import Context
from bt_lsp.server.navigation import MAX_SYMBOL_DEPTH, document_symbols_json, outline_json
from bt_lsp.syntax.document import Document
from bt_lsp.syntax.text import Encoding
from tests.server.test_deep_nesting import deep

TREE = (
    '  <BehaviorTree ID="T{n}">\r\n'
    '    <Sequence name="s{n} 😋">\n'
    '      <Move goal="{{a}}"/><Check name="é{n}"/>\n'
    '      <SubTree ID="T0"/>\n'
    "    </Sequence>\n"
    "  </BehaviorTree>"
)
MODELS = (
    "\n  <TreeNodesModel>\n"
    '    <Action ID="Move"><input_port name="goal"/></Action>\n'
    '    <Condition ID="Check"/>\n'
    "  </TreeNodesModel>\n"
)


def document(trees: int) -> str:
    body = "\n".join(TREE.format(n=n) for n in range(trees))
    return f'<root BTCPP_format="4"><include path="x.xml"/>\n{body}{MODELS}</root>\n'


def fresh(doc: Document, enc: Encoding) -> str:
    return document_symbols_json(doc.lines, document_symbols(doc), enc)


def outlines(doc: Document) -> list[SectionOutline]:
    return [p.outline for p in outline_parts(doc, Context.from_document(doc))]


ENCODINGS: list[Encoding] = ["utf-8", "utf-16", "utf-32"]


@settings(max_examples=60, deadline=None)
@given(
    st.lists(
        st.tuples(
            st.floats(0, 1),
            st.integers(0, 12),
            st.sampled_from(["x", "\n", "\r\n", "😋", '"', "<", "/>", "</Sequence>", ""]),
        ),
        min_size=1,
        max_size=8,
    ),
    st.sampled_from(ENCODINGS),
)
def test_kept_pieces_make_the_fresh_outline(
    edits: list[tuple[float, int, str]], enc: Encoding
) -> None:
    doc = Document(document(5), "a.xml")
    assert outline_json(doc, Context.from_document(doc), enc) == fresh(doc, enc)
    for where, length, new in edits:
        start = int(where * len(doc.text))
        doc.edit(start, min(start + length, len(doc.text)), new)
        assert outline_json(doc, Context.from_document(doc), enc) == fresh(doc, enc)


def plain(text: str) -> str:
    """``text`` in ASCII with LF line ends: columns are distances, the outline's fast path."""
    return text.replace("\r\n", "\n").replace(" 😋", "").replace("é", "e")


@settings(max_examples=60, deadline=None)
@given(
    st.lists(
        st.tuples(
            st.floats(0, 1),
            st.integers(0, 12),
            st.sampled_from(["x", "\n", "  ", '"', "<", "/>", "</Sequence>", ""]),
        ),
        min_size=1,
        max_size=8,
    ),
    st.sampled_from(ENCODINGS),
)
def test_kept_pieces_make_the_fresh_outline_in_plain_text(
    edits: list[tuple[float, int, str]], enc: Encoding
) -> None:
    doc = Document(plain(document(5)), "a.xml")
    assert doc.lines.plain_columns(enc)
    assert outline_json(doc, Context.from_document(doc), enc) == fresh(doc, enc)
    for where, length, new in edits:
        start = int(where * len(doc.text))
        doc.edit(start, min(start + length, len(doc.text)), new)
        assert outline_json(doc, Context.from_document(doc), enc) == fresh(doc, enc)


def test_deeper_than_the_limit_and_outside_the_root() -> None:
    for text in (
        deep(MAX_SYMBOL_DEPTH + 5),
        "<BehaviorTree ID='Bare'><Sequence name='n'/></BehaviorTree>",  # no root
        document(2) + '<BehaviorTree ID="After"><AlwaysSuccess name="a"/></BehaviorTree>',
        document(2).replace("</root>\n", ""),  # never closed
    ):
        doc = Document(text, "a.xml")
        for enc in ENCODINGS:
            assert outline_json(doc, Context.from_document(doc), enc) == fresh(doc, enc)


def test_an_edit_rebuilds_only_the_sections_it_changed() -> None:
    doc = Document(document(12), "a.xml")
    before = outlines(doc)
    at = doc.text.index('name="é7') + len('name="é7')
    doc.edit(at, at, "x\n")
    after = outlines(doc)
    assert len(after) == len(before)
    rebuilt = [i for i, (a, b) in enumerate(zip(before, after, strict=True)) if a is not b]
    assert len(rebuilt) == 1
    (tree,) = after[rebuilt[0]].symbols
    assert [c.name for c in tree.children[0].children][:2] == ["Move", "é7x\n"]


def test_a_changed_model_category_rebuilds_the_sections_that_show_it() -> None:
    doc = Document(document(3), "a.xml")
    first = outline_json(doc, Context.from_document(doc), "utf-16")
    assert '"detail": "Condition Check"' in first
    start = doc.text.index('<Condition ID="Check"/>')
    doc.edit(start, start + len('<Condition ID="Check"/>'), '<Action ID="Check"/>')
    again = outline_json(doc, Context.from_document(doc), "utf-16")
    assert again == fresh(doc, "utf-16")
    assert '"detail": "Condition Check"' not in again and '"detail": "Action Check"' in again


def test_a_kept_outline_is_its_json_text_only() -> None:
    """What a section keeps of its outline is the JSON it was written as (no symbols, no
    pieces): an edit that moves it (new lines before it, or new text before it on its
    first line) moves the numbers in that text, and the outline is the fresh one."""
    text = (
        '<root BTCPP_format="4"><BehaviorTree ID="T"><Sequence>'
        + ("<AlwaysSuccess/>\n" * 200)
        + '</Sequence></BehaviorTree><BehaviorTree ID="U"><Sequence name="line"/>'
        + "</BehaviorTree></root>\n"
    )
    for enc in ENCODINGS:
        doc = Document(text)
        first = outline_json(doc, Context.from_document(doc), enc)
        secs = doc.model.sections
        assert all("outline" not in s.cache for s in secs)
        kept = [s.cache["outline-json"] for s in secs]
        slots = ("categories", "enc", "state")  # (text, line, column): replaced at once
        assert all(type(k).__slots__ == slots for k in kept)
        assert first == "[" + ", ".join(k.text for k in kept) + "]"
        for new in ("x😋 ", "\r\n", "\n"):  # in the first tree, on the second's first line
            at = doc.text.index("</Sequence></BehaviorTree><BehaviorTree")
            doc.edit(at, at, new)
            assert outline_json(doc, Context.from_document(doc), enc) == fresh(doc, enc)
            assert doc.model.sections[1].cache["outline-json"] is kept[1]  # moved, kept
