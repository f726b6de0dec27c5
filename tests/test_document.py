"""A document kept current by edits always agrees with a fresh analysis of its text."""

from __future__ import annotations

from hypothesis import given, settings
from hypothesis import strategies as st

from bt_lsp.rules.diagnostics import own_diagnostics
from bt_lsp.syntax.document import Document, looks_like_bt
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


def test_looks_like_bt() -> None:
    assert looks_like_bt("<root>")
    assert looks_like_bt("<?xml?><root BTCPP_format='4'/>")
    assert looks_like_bt("<x><BehaviorTree ID='a'/></x>")
    assert not looks_like_bt("<launch><node name='a.b'/></launch>")
    assert not looks_like_bt("<package><name>rootless</name></package>")
