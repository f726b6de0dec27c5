"""The scanner: tolerant, position-exact, incremental."""

from __future__ import annotations

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from bt_lsp.syntax.scanner import rescan, scan, scan_token
from bt_lsp.syntax.tag_limits import MAX_ATTRS, MAX_DUPLICATES, MAX_TAG_PROBLEMS
from bt_lsp.syntax.tokens import Kind, Token
from bt_lsp.syntax.values import decode_value

# Text built from the pieces that matter to a tag scanner, so hypothesis reaches the
# interesting states (half tags, quotes, references) far more often than with raw text.
PIECES = [
    "<",
    ">",
    "/>",
    "</",
    "<!--",
    "-->",
    "<![CDATA[",
    "]]>",
    "<?",
    "?>",
    "<!DOCTYPE r [",
    "]>",
    '"',
    "'",
    "=",
    " ",
    "\n",
    "\r\n",
    "\r",
    "\t",
    "&",
    "&amp;",
    "&#x20;",
    "&#1;",
    "&bogus;",
    "a",
    "Seq",
    "ID",
    "name",
    "x.y",
    "é",
    "😋",
    "\x00",
    "\x07",
    "<root>",
    "</root>",
    '<A b="1"/>',
    "<Sequence>",
    "</Sequence>",
    "\n  <B",
    "<1",
]
xmlish = st.lists(st.sampled_from(PIECES) | st.text(max_size=3), max_size=40).map("".join)


def check_spans(text: str) -> None:
    s = scan(text)
    pos = 0
    for start, tok in zip(s.starts, s.tokens, strict=True):
        assert start == pos and tok.length > 0 and tok.reach >= tok.length
        pos += tok.length
        if tok.kind in (Kind.START, Kind.END) and tok.name:
            assert text[start + tok.name_start : start + tok.name_end] == tok.name
        for a in tok.attrs:
            assert text[start + a.name_start : start + a.name_end] == a.name
            if a.value is not None:
                raw = text[start + a.value_start : start + a.value_end]
                assert decode_value(raw, 0, None) == a.value
        for p in tok.problems:
            assert 0 <= p.start <= p.end <= tok.length
    assert pos == len(text)


@given(xmlish)
@settings(max_examples=400)
def test_never_raises_and_spans_slice_their_token(text: str) -> None:
    check_spans(text)


@given(st.text())
def test_arbitrary_unicode(text: str) -> None:
    check_spans(text)


@given(xmlish, st.data())
@settings(max_examples=500)
def test_incremental_equals_full_scan(text: str, data: st.DataObject) -> None:
    old = scan(text)
    for _ in range(3):
        start = data.draw(st.integers(0, len(text)))
        end = data.draw(st.integers(start, len(text)))
        insert = data.draw(xmlish)
        new_text = text[:start] + insert + text[end:]
        new, _info = rescan(old, new_text, start, end, len(insert))
        full = scan(new_text)
        assert new.starts == full.starts
        assert new.tokens == full.tokens
        text, old = new_text, new


def test_incremental_reuses_tokens_far_from_the_edit() -> None:
    body = "".join(f'  <Action ID="A{i}" x="{i}"/>\n' for i in range(2000))
    text = f'<root><BehaviorTree ID="T">\n{body}</BehaviorTree></root>'
    old = scan(text)
    at = text.index('"A1000"') + 2
    new_text = text[:at] + "9" + text[at:]
    new, info = rescan(old, new_text, at, at, 1)
    assert info.new_stop - info.first <= 3
    assert new.tokens[-1] is old.tokens[-1]
    assert new.tokens == scan(new_text).tokens


def test_names_in_unterminated_tags_are_found() -> None:
    text = '<root>\n  <Open.Door door.id="x"\n  <Sequence>\n</root>'
    s = scan(text)
    starts = [t for t in s.tokens if t.kind == Kind.START]
    assert [t.name for t in starts] == ["root", "Open.Door", "Sequence"]
    assert starts[1].attrs[0].name == "door.id"
    assert not starts[1].closed


def test_unterminated_value_stops_before_next_tag_line() -> None:
    text = '<root>\n  <A name="oops\n  <B x="1"/>\n</root>'
    names = [t.name for t in scan(text).tokens if t.kind == Kind.START]
    assert names == ["root", "A", "B"]


def test_references_decoded_raw_span_kept() -> None:
    text = '<A name="a&amp;b&#x20;c&#1;"/>'
    (tok,) = scan(text).tokens
    a = tok.attrs[0]
    assert a.value == "a&b c\x01"
    assert text[a.value_start : a.value_end] == "a&amp;b&#x20;c&#1;"


def test_raw_amp_and_lt_are_warnings_not_errors() -> None:
    (tok,) = scan('<A _while="a && b<1.0"/>').tokens
    assert {p.code for p in tok.problems} == {"xml-unescaped-char"}
    assert tok.attrs[0].value == "a && b<1.0"


def test_doctype_is_skipped_not_expanded() -> None:
    text = (
        '<!DOCTYPE lolz [<!ENTITY lol "lol"><!ENTITY lol2 "&lol;&lol;">'
        '<!ENTITY x SYSTEM "file:///etc/passwd">]>\n<root a="&lol2;&x;"/>'
    )
    s = scan(text)
    assert s.tokens[0].kind == Kind.DOCTYPE
    assert s.tokens[0].problems[0].code == "xml-doctype"
    root = s.tokens[2]
    assert root.attrs[0].value == "&lol2;&x;"


def test_comments_cdata_pi_are_single_tokens() -> None:
    text = "<!-- <A/> --><![CDATA[<B/>]]><?xml version='1.0'?>"
    assert [t.kind for t in scan(text).tokens] == [Kind.COMMENT, Kind.CDATA, Kind.PI]


def test_deep_nesting_is_linear_and_never_recurses() -> None:
    depth = 100_000
    text = "<A>" * depth + "</A>" * depth
    s = scan(text)
    assert len(s.tokens) == 2 * depth


def test_stray_lt_and_nul() -> None:
    s = scan("a < b\x00<")
    assert [t.kind for t in s.tokens] == [Kind.TEXT, Kind.STRAY, Kind.TEXT, Kind.STRAY]


# -- what a tag keeps of hostile attribute counts ---------------------------------------


def _tag(text: str) -> Token:
    (tok,) = scan(text).tokens
    assert tok.kind == Kind.START and tok.length == len(text)
    return tok


@pytest.mark.parametrize("sep", [" ", "\t"])
@pytest.mark.parametrize("malformed", [False, True], ids=["fast", "slow"])
def test_duplicates_beyond_the_first_are_counted_not_kept(sep: str, malformed: bool) -> None:
    """A million duplicates keep O(1) records: the first attribute, MAX_DUPLICATES
    duplicates each with its problem, and one problem counting the rest."""
    n = 5_000
    bad = ' b="<"' if malformed else ""  # a raw '<' takes the slow path
    text = "<A" + bad + f'{sep}a="1"' * n + "/>"
    tok = _tag(text)
    kept = [a for a in tok.attrs if a.name == "a"]
    assert len(kept) == 1 + MAX_DUPLICATES
    dups = [p for p in tok.problems if p.message == "Duplicate attribute 'a'"]
    assert len(dups) == MAX_DUPLICATES
    assert [(p.start, p.end) for p in dups] == [(a.name_start, a.name_end) for a in kept[1:]]
    (rest,) = [p for p in tok.problems if "more duplicate" in p.message]
    assert rest.code == "xml-syntax"
    assert rest.message.startswith(f"{n - 1 - MAX_DUPLICATES} more duplicate attributes")
    first_left_out = text.index(f'{sep}a="1"', kept[-1].value_end) + 1
    assert (rest.start, rest.end) == (first_left_out, first_left_out + 1)


@pytest.mark.parametrize("malformed", [False, True], ids=["fast", "slow"])
def test_attributes_beyond_max_attrs_are_read_not_kept(malformed: bool) -> None:
    names = [f"p{i}" for i in range(MAX_ATTRS + 250)]
    text = "<A " + " ".join(f'{n}="1"' for n in names) + (" b" if malformed else "") + "/>"
    tok = _tag(text)
    assert [a.name for a in tok.attrs] == names[:MAX_ATTRS]
    (many,) = [p for p in tok.problems if p.code == "too-many-attributes"]
    at = text.index(f" {names[MAX_ATTRS]}=") + 1
    assert (many.start, many.end) == (at, at + len(names[MAX_ATTRS]))
    total = len(names) + (1 if malformed else 0)
    assert f"has {total} attributes" in many.message
    # A duplicate among the left-out attributes is still an error.
    dup = _tag(text[:-2] + ' p3="2"/>')
    assert any(p.message == "Duplicate attribute 'p3'" for p in dup.problems)


def test_a_malformed_tag_reports_a_bounded_number_of_problems() -> None:
    tok = _tag("<A" + " a" * 5_000 + " b" * 5_000 + ">")  # attributes without a value
    # 10,000 without a value and MAX_DUPLICATES duplicates, then what counts the rest.
    more = 10_000 + MAX_DUPLICATES - MAX_TAG_PROBLEMS
    messages = [p.message for p in tok.problems[MAX_TAG_PROBLEMS:]]
    assert messages == [
        f"{more} more problems in tag '<A' from here",
        f"{2 * 4_999 - MAX_DUPLICATES} more duplicate attributes in tag '<A' from here "
        f"(only the first {MAX_DUPLICATES} are listed)",
    ]
    assert not any(p.message.startswith("Missing whitespace") for p in tok.problems)


def _token_by_token(text: str) -> list[tuple[int, Token]]:
    out: list[tuple[int, Token]] = []
    pos = 0
    while pos < len(text):
        tok = scan_token(text, pos)
        out.append((pos, tok))
        pos += tok.length
    return out


# Pieces that repeat, and ones that repeat only up to the character after them.
_REPEATS = ["<A/>", "<A/", "<A>", "</A>", "  ", "\n", "x", "<A", "<!-- c -->", '<B a="1"/>']


@settings(max_examples=300)
@given(st.lists(st.sampled_from(_REPEATS), max_size=60).map("".join))
def test_a_repeated_token_is_the_one_a_scan_makes_there(text: str) -> None:
    # The full scan reuses one of the last three tokens where the text it looked at
    # comes again: the result is the one scanning each token gives.
    full = scan(text)
    assert list(zip(full.starts, full.tokens, strict=True)) == _token_by_token(text)


def test_repeats_are_found_again_after_text_that_does_not_repeat() -> None:
    # Where fewer than half the tokens repeat, the scan stops looking for a while, then
    # looks again: both stretches give the tokens a plain scan gives.
    varied = "".join(f'<N{k} a="{k}"/>' for k in range(3000))
    text = varied + "<A/>" * 5000 + varied
    full = scan(text)
    assert list(zip(full.starts, full.tokens, strict=True)) == _token_by_token(text)
    runs = full.tokens[3000:8000]
    assert all(t is runs[0] for t in runs)  # one token for the run


def test_equal_attributes_stay_shared_when_the_pool_fills_midway() -> None:
    # The pool of shared attributes is bounded; making room in it keeps what was added
    # last, so that one document's equal attributes stay one tuple across the trim.
    from bt_lsp.syntax import scanner

    room = scanner._SHARED_MAX - 5
    filler = "".join(f'<F z{k}="v"/>' for k in range(room))
    full = scan(filler + "".join(f'<F a="1" c="{k}"/>' for k in range(50)))
    assert len({id(t.attrs[0]) for t in full.tokens[room:]}) == 1
