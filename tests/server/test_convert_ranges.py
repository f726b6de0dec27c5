"""Ranges converted together are those converted one at a time."""

from __future__ import annotations

from hypothesis import given, settings
from hypothesis import strategies as st

from bt_lsp.server.convert import to_range, to_ranges, to_text_edits
from bt_lsp.syntax.edits import TextEdit
from bt_lsp.syntax.text import Encoding, LineIndex

_SPANS = st.lists(st.tuples(st.integers(-3, 45), st.integers(-3, 45)), max_size=20)


@settings(max_examples=400)
@given(
    st.text(st.sampled_from(list("ab\r\n\t😋é\u2028")), max_size=40),
    _SPANS,
    st.sampled_from(["utf-8", "utf-16", "utf-32"]),
)
def test_ranges_together_are_each_range(
    text: str, spans: list[tuple[int, int]], encoding: Encoding
) -> None:
    lines = LineIndex(text)
    each = [to_range(lines, s, e, encoding) for s, e in spans]
    assert to_ranges(lines, spans, encoding) == each
    edits = [TextEdit(s, e, f"x{i}") for i, (s, e) in enumerate(spans)]
    converted = to_text_edits(lines, edits, encoding)
    assert [(c.range, c.new_text) for c in converted] == [(r, f"x{i}") for i, r in enumerate(each)]
