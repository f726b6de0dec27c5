"""Tests for bt_lsp.syntax.text: line index and LSP position conversion."""

from __future__ import annotations

import enum
from typing import get_args

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from bt_lsp.syntax.text import Encoding, LineIndex, Offsets, normalize_encoding, positions_of

ENCODINGS: tuple[Encoding, ...] = get_args(Encoding)
CODECS = {"utf-8": ("utf-8", 1), "utf-16": ("utf-16-le", 2), "utf-32": ("utf-32-le", 4)}


# -- an independent reference model ------------------------------------------------------


def ref_lines(text: str) -> list[tuple[int, int]]:
    """(start, end) of every line, end excluding the terminator, by a plain char loop."""
    lines: list[tuple[int, int]] = []
    start = 0
    i = 0
    while i < len(text):
        ch = text[i]
        if ch == "\r" and i + 1 < len(text) and text[i + 1] == "\n":
            lines.append((start, i))
            i += 2
            start = i
        elif ch in "\r\n":
            lines.append((start, i))
            i += 1
            start = i
        else:
            i += 1
    lines.append((start, len(text)))
    return lines


def ref_line_end_count(text: str) -> int:
    # Every "\r" and every "\n" is a line end, except that a "\r\n" pair is only one.
    return text.count("\r") + text.count("\n") - text.count("\r\n")


def units(s: str, enc: str) -> int:
    codec, unit = CODECS[enc]
    return len(s.encode(codec, "surrogatepass")) // unit


def in_crlf(text: str, offset: int) -> bool:
    return 0 < offset < len(text) and text[offset - 1] == "\r" and text[offset] == "\n"


# -- normalize_encoding ------------------------------------------------------------------


def test_normalize_encoding_plain_strings() -> None:
    assert normalize_encoding("utf-8") == "utf-8"
    assert normalize_encoding("utf-16") == "utf-16"
    assert normalize_encoding("utf-32") == "utf-32"
    assert normalize_encoding("UTF-8") == "utf-8"
    assert normalize_encoding("utf8") == "utf-8"


def test_normalize_encoding_unknown_is_utf16() -> None:
    assert normalize_encoding("latin-1") == "utf-16"
    assert normalize_encoding("") == "utf-16"
    assert normalize_encoding(None) == "utf-16"
    assert normalize_encoding(8) == "utf-16"


def test_normalize_encoding_enum_members() -> None:
    class Kind(enum.StrEnum):
        Utf8 = "utf-8"
        Utf16 = "utf-16"
        Utf32 = "utf-32"

    assert normalize_encoding(Kind.Utf8) == "utf-8"
    assert normalize_encoding(Kind.Utf16) == "utf-16"
    assert normalize_encoding(Kind.Utf32) == "utf-32"


def test_normalize_encoding_lsprotocol() -> None:
    types = pytest.importorskip("lsprotocol.types")
    kind = types.PositionEncodingKind
    assert normalize_encoding(kind.Utf8) == "utf-8"
    assert normalize_encoding(kind.Utf16) == "utf-16"
    assert normalize_encoding(kind.Utf32) == "utf-32"


# -- lines -------------------------------------------------------------------------------


def test_empty_text() -> None:
    idx = LineIndex("")
    assert idx.line_count == 1
    assert idx.line_start(0) == 0
    assert idx.line_end(0) == 0
    for enc in ENCODINGS:
        assert idx.position(0, enc) == (0, 0)
        assert idx.position(5, enc) == (0, 0)
        assert idx.position(-5, enc) == (0, 0)
        assert idx.offset(0, 0, enc) == 0
        assert idx.offset(3, 7, enc) == 0
        assert idx.offset(0, 7, enc) == 0


def test_lf_lines() -> None:
    idx = LineIndex("ab\ncd\n")
    assert idx.line_count == 3
    assert idx.line_starts == (0, 3, 6)
    assert [idx.line_end(i) for i in range(3)] == [2, 5, 6]
    assert [idx.line_text(i) for i in range(3)] == ["ab", "cd", ""]


def test_crlf_is_one_line_end() -> None:
    text = "ab\r\ncd\r\n"
    idx = LineIndex(text)
    assert idx.line_count == 3
    assert idx.line_starts == (0, 4, 8)
    assert [idx.line_end(i) for i in range(3)] == [2, 6, 8]
    assert idx.position(2, "utf-16") == (0, 2)  # on the "\r"
    assert idx.position(3, "utf-16") == (0, 2)  # between "\r" and "\n": end of line 0
    assert idx.position(4, "utf-16") == (1, 0)
    assert idx.offset(0, 2, "utf-16") == 2
    assert idx.offset(0, 99, "utf-16") == 2  # never into the terminator
    assert idx.offset(1, 1, "utf-16") == 5


def test_lone_cr() -> None:
    idx = LineIndex("a\rb\rc")
    assert idx.line_count == 3
    assert idx.line_starts == (0, 2, 4)
    assert idx.position(3, "utf-8") == (1, 1)
    assert idx.offset(2, 1, "utf-8") == 5


def test_mixed_line_ends() -> None:
    text = "a\nb\r\nc\rd\n\re\r\r\nf"
    idx = LineIndex(text)
    assert [idx.line_text(i) for i in range(idx.line_count)] == [
        "a",
        "b",
        "c",
        "d",
        "",
        "e",
        "",
        "f",
    ]
    assert idx.line_count == 8


def test_cr_then_crlf_and_lf_then_cr() -> None:
    # "\n\r" is two line ends; "\r\r\n" is "\r" then "\r\n".
    assert LineIndex("\n\r").line_count == 3
    assert LineIndex("\r\r\n").line_count == 3
    assert LineIndex("\r\n").line_count == 2


@pytest.mark.parametrize(
    "sep", ["\u2028", "\u2029", "\x85", "\x0b", "\x0c", "\x1c", "\x1d", "\x1e"]
)
def test_splitlines_separators_are_not_line_ends(sep: str) -> None:
    text = f"a{sep}b\nc"
    assert len(text.splitlines()) == 3  # what pygls gets wrong
    idx = LineIndex(text)
    assert idx.line_count == 2
    assert idx.line_text(0) == f"a{sep}b"
    assert idx.position(3, "utf-32") == (0, 3)
    assert idx.position(3, "utf-16") == (0, 3)
    assert idx.position(3, "utf-8") == (0, 2 + len(sep.encode()))
    assert idx.position(4, "utf-16") == (1, 0)


def test_tabs_are_one_unit() -> None:
    idx = LineIndex("\t\t<a>")
    for enc in ENCODINGS:
        assert idx.position(3, enc) == (0, 3)
        assert idx.offset(0, 3, enc) == 3


def test_line_clamping() -> None:
    idx = LineIndex("ab\ncd")
    assert idx.line_start(-1) == 0
    assert idx.line_start(9) == 3
    assert idx.line_end(-1) == 2
    assert idx.line_end(9) == 5


# -- positions ---------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("enc", "expected"),
    [
        ("utf-8", [0, 1, 5, 6, 10, 11]),
        ("utf-16", [0, 1, 3, 4, 6, 7]),
        ("utf-32", [0, 1, 2, 3, 4, 5]),
    ],
)
def test_astral_characters(enc: Encoding, expected: list[int]) -> None:
    text = "x😋y𝄞z"
    idx = LineIndex("first\n" + text)
    for offset, col in enumerate(expected):
        assert idx.position(6 + offset, enc) == (1, col)
        assert idx.offset(1, col, enc) == 6 + offset


def test_bmp_non_ascii() -> None:
    idx = LineIndex("é<a b='ü'/>")
    assert idx.position(1, "utf-8") == (0, 2)
    assert idx.position(1, "utf-16") == (0, 1)
    assert idx.position(9, "utf-8") == (0, 11)
    assert idx.offset(0, 11, "utf-8") == 9
    assert idx.offset(0, 1, "utf-8") == 0  # inside "é": round down


def test_inside_surrogate_pair_rounds_down() -> None:
    idx = LineIndex("a😋b")
    assert idx.offset(0, 2, "utf-16") == 1  # between the two halves of 😋
    assert idx.offset(0, 3, "utf-16") == 2
    for col in (2, 3, 4):
        assert idx.offset(0, col, "utf-8") == 1  # inside the 4-byte sequence
    assert idx.offset(0, 5, "utf-8") == 2


def test_eof_without_trailing_newline() -> None:
    idx = LineIndex("ab\ncd😋")
    assert idx.position(6, "utf-16") == (1, 4)
    assert idx.position(6, "utf-8") == (1, 6)
    assert idx.position(6, "utf-32") == (1, 3)
    assert idx.offset(1, 4, "utf-16") == 6


def test_eof_after_trailing_newline() -> None:
    for text in ("ab\n", "ab\r\n", "ab\r"):
        idx = LineIndex(text)
        assert idx.line_count == 2
        assert idx.position(len(text), "utf-16") == (1, 0)
        assert idx.offset(1, 0, "utf-16") == len(text)


def test_offset_clamping() -> None:
    idx = LineIndex("ab\r\ncd\nef")
    for enc in ENCODINGS:
        assert idx.offset(-1, 0, enc) == 0
        assert idx.offset(-1, 5, enc) == 0
        assert idx.offset(0, -3, enc) == 0
        assert idx.offset(1, -3, enc) == 4
        assert idx.offset(3, 0, enc) == len(idx.text)
        assert idx.offset(99, 99, enc) == len(idx.text)
        assert idx.offset(0, 99, enc) == 2
        assert idx.offset(1, 99, enc) == 6
        assert idx.offset(2, 99, enc) == 9


def test_position_clamping() -> None:
    idx = LineIndex("ab\ncd")
    assert idx.position(-4, "utf-16") == (0, 0)
    assert idx.position(99, "utf-16") == (1, 2)
    assert idx.line_of(99) == 1
    assert idx.line_of(-1) == 0


def test_lone_surrogates_do_not_raise() -> None:
    text = "a\ud83db\ude0b😋c"
    idx = LineIndex(text)
    for enc in ENCODINGS:
        for offset in range(len(text) + 1):
            line, col = idx.position(offset, enc)
            assert col == units(text[:offset], enc)
            assert idx.offset(line, col, enc) == offset
    assert idx.offset(0, 5, "utf-16") == 4  # inside 😋
    assert idx.offset(0, 9, "utf-8") == 4


def test_ranges() -> None:
    idx = LineIndex("a😋\r\nbc")
    assert idx.offsets_to_range(1, 5, "utf-16") == (0, 1, 1, 1)
    assert idx.range_to_offsets(0, 1, 1, 1, "utf-16") == (1, 5)
    assert idx.offsets_to_range(2, 2, "utf-8") == (0, 5, 0, 5)
    assert idx.range_to_offsets(0, 3, 0, 5, "utf-8") == (1, 2)


# -- edited ------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("text", "start", "end", "new"),
    [
        ("a\rb", 2, 2, "\n"),  # "\r" before + "\n" inserted
        ("a\r", 2, 2, "\nb"),
        ("a\nb", 1, 1, "\r"),  # "\r" inserted before "\n"
        ("a\rxb\n", 2, 3, ""),  # delete between "\r" and "\n": they merge
        ("a\r\nb", 2, 2, "x"),  # split a "\r\n"
        ("a\r\nb", 2, 2, ""),
        ("a\r\nb", 1, 2, ""),  # delete the "\r"
        ("a\r\nb", 2, 3, ""),  # delete the "\n"
        ("a\r\nb", 1, 3, "\n\r"),
        ("", 0, 0, "\r\n\r"),
        ("\r\n\r\n", 0, 4, ""),
        ("ab\ncd\nef", 3, 5, "x\ny\r"),
        ("ab\ncd\nef", 0, 8, "z"),
    ],
)
def test_edited_cases(text: str, start: int, end: int, new: str) -> None:
    full = text[:start] + new + text[end:]
    assert LineIndex(text).edited(start, end, new, full) == LineIndex(full)


def test_edited_rejects_inconsistent_arguments() -> None:
    idx = LineIndex("abc")
    with pytest.raises(ValueError):
        idx.edited(2, 1, "", "abc")
    with pytest.raises(ValueError):
        idx.edited(0, 4, "", "")
    with pytest.raises(ValueError):
        idx.edited(0, 1, "x", "abc")


# -- properties --------------------------------------------------------------------------

ALPHABET = ["\r", "\n", "\u2028", "\x85", "é", "😋", "a", "\t", "\x0b"]
texts = st.text(alphabet=st.sampled_from(ALPHABET), max_size=40)
encodings = st.sampled_from(ENCODINGS)


@given(texts)
def test_line_count_matches_line_ends(text: str) -> None:
    idx = LineIndex(text)
    assert idx.line_count == ref_line_end_count(text) + 1
    expected = ref_lines(text)
    assert idx.line_count == len(expected)
    for line, (start, end) in enumerate(expected):
        assert idx.line_start(line) == start
        assert idx.line_end(line) == end


@given(texts, encodings)
def test_position_round_trips(text: str, enc: Encoding) -> None:
    idx = LineIndex(text)
    for offset in range(len(text) + 1):
        line, col = idx.position(offset, enc)
        if in_crlf(text, offset):
            assert idx.offset(line, col, enc) == offset - 1
        else:
            assert idx.offset(line, col, enc) == offset


@given(texts, encodings)
def test_position_matches_reference(text: str, enc: Encoding) -> None:
    idx = LineIndex(text)
    lines = ref_lines(text)
    for offset in range(len(text) + 1):
        line = max(i for i, (start, _) in enumerate(lines) if start <= offset)
        start, end = lines[line]
        line_text = text[start:end]
        col = min(offset, end) - start
        assert idx.position(offset, enc) == (
            line,
            len(line_text[:col].encode(CODECS[enc][0])) // CODECS[enc][1],
        )


@given(texts, encodings, st.integers(-3, 12), st.integers(-3, 100))
def test_offset_is_clamped_and_rounds_down(text: str, enc: Encoding, line: int, char: int) -> None:
    idx = LineIndex(text)
    offset = idx.offset(line, char, enc)
    assert 0 <= offset <= len(text)
    if 0 <= line < idx.line_count:
        start, end = idx.line_start(line), idx.line_end(line)
        assert start <= offset <= end
        # The largest offset on the line whose column does not exceed `char`.
        expected = start
        for o in range(start, end + 1):
            if units(text[start:o], enc) <= char:
                expected = o
        assert offset == expected


@settings(max_examples=300)
@given(texts, st.data())
def test_edited_equals_fresh_index(text: str, data: st.DataObject) -> None:
    start = data.draw(st.integers(0, len(text)))
    end = data.draw(st.integers(start, len(text)))
    new = data.draw(texts)
    full = text[:start] + new + text[end:]
    assert LineIndex(text).edited(start, end, new, full) == LineIndex(full)


@given(st.lists(st.tuples(texts, st.integers(0, 1000), st.integers(0, 1000)), max_size=8))
def test_edited_chain(edits: list[tuple[str, int, int]]) -> None:
    text = "a\r\nb\rc\nd"
    idx = LineIndex(text)
    for new, a, b in edits:
        start, end = sorted((a % (len(text) + 1), b % (len(text) + 1)))
        text = text[:start] + new + text[end:]
        idx = idx.edited(start, end, new, text)
        assert idx == LineIndex(text)


def test_large_text_builds_fast() -> None:
    import time

    line = '  <Action ID="Say" message="héllo 😋"/>\r\n'
    text = line * (4_000_000 // len(line))
    t0 = time.perf_counter()
    idx = LineIndex(text)
    elapsed = time.perf_counter() - t0
    assert idx.line_count == text.count("\n") + 1
    assert elapsed < 1.0  # generous bound for slow CI; typically a few milliseconds


@given(texts, encodings, st.lists(st.integers(-3, 50), max_size=6))
def test_positions_of_a_few_offsets_match_the_index(
    text: str, enc: Encoding, offsets: list[int]
) -> None:
    found = positions_of(text, offsets, enc)
    idx = LineIndex(text)
    assert found == {o: idx.position(o, enc) for o in offsets}


def test_positions_of_count_lines_without_an_index() -> None:
    text = "a\n😋b\n\ncé\n"
    assert positions_of(text, [12, 0, 5, 2, 3], "utf-16") == {
        0: (0, 0),
        2: (1, 0),
        3: (1, 2),
        5: (2, 0),
        12: (4, 0),
    }
    assert positions_of(text, [8], "utf-8") == {8: (3, 3)}


@settings(max_examples=500)
@given(
    st.text(st.sampled_from(list("ab\r\n\t😋é\u2028")), max_size=40),
    st.lists(st.integers(-3, 45), max_size=20),
    st.sampled_from(["utf-8", "utf-16", "utf-32"]),
)
def test_positions_in_one_pass_are_position_of_each(
    text: str, offsets: list[int], encoding: Encoding
) -> None:
    lines = LineIndex(text)
    assert lines.positions(offsets, encoding) == {o: lines.position(o, encoding) for o in offsets}


@settings(max_examples=300)
@given(
    st.text(st.sampled_from(list("ab\n\t ")), max_size=60),
    st.lists(st.integers(-3, 65), max_size=30),
    st.sampled_from(["utf-8", "utf-16", "utf-32"]),
    st.integers(0, 60),
)
def test_positions_of_ascii_text_are_position_of_each(
    text: str, offsets: list[int], encoding: Encoding, cut: int
) -> None:
    """Without a CR or a non-ASCII character a column is the distance from the line
    start (the fast path), also after an edit (line starts in shifted blocks)."""
    lines = LineIndex(text)
    cut = min(cut, len(text))
    edited_text = text[:cut] + "x\ny" + text[cut:]
    edited = lines.edited(cut, cut, "x\ny", edited_text)
    for idx in (lines, edited):
        assert idx.positions(offsets, encoding) == {o: idx.position(o, encoding) for o in offsets}


@settings(max_examples=200, deadline=None)
@given(
    st.lists(st.integers(0, 5_000), min_size=1, max_size=2_000).map(sorted),
    st.lists(st.integers(0, 6_000), max_size=300),
    st.integers(0, 2_100),
    st.integers(0, 2_100),
)
def test_offsets_sweeps_are_their_searches(
    starts: list[int], probes: list[int], first: int, stop: int
) -> None:
    """``floors`` (one sweep over sorted offsets) is ``floor`` of each, and ``between``
    the slice, over several blocks."""
    offsets = Offsets.of(starts)
    assert len(offsets._blocks) == -(-len(starts) // Offsets.BLOCK)
    probes = sorted(p for p in probes if p >= starts[0])
    assert offsets.floors(probes) == [offsets.floor(p) for p in probes]
    assert offsets.between(first, stop) == starts[first:stop]


@given(texts, st.integers(0, 45), st.integers(0, 45), encodings)
def test_starts_between_are_the_lines_of_a_span(
    text: str, start: int, end: int, enc: Encoding
) -> None:
    lines = LineIndex(text)
    start, end = min(start, len(text)), min(max(start, end), len(text))
    first, starts = lines.starts_between(start, end)
    assert first == lines.position(start, "utf-32")[0]
    assert starts == [
        lines.line_start(k) for k in range(first, lines.position(end, "utf-32")[0] + 1)
    ]
    plain = text.isascii() and "\r" not in text
    assert lines.plain_columns(enc) == (plain or (enc == "utf-32" and "\r" not in text))
