"""Every diagnostic code, as its rule reads: ``tests/fixtures/<code>.xml`` reports it (and
everything else it reports is annotated too), ``<code>.ok.xml`` is the near miss that
must not, and its ``<!-- fixed: TITLE -->`` sections are what its fixes make (see
:mod:`tests.annotated` for the form)."""

from __future__ import annotations

from pathlib import Path

import pytest

from bt_lsp.rules.codes import Severity
from bt_lsp.rules.diagnostics import Diagnostic
from bt_lsp.rules.registry import CODES
from bt_lsp.syntax.document import Document
from tests.annotated import (
    check,
    check_fix,
    diagnostics,
    found,
    parse,
    render,
    split_files,
    split_fixed,
)

FIXTURES = Path(__file__).parent / "fixtures"
FILES = sorted(FIXTURES.glob("*.xml"))


def _text(path: Path) -> str:
    """The fixture without its fixed sections."""
    return split_fixed(path.read_text(encoding="utf-8"))[0]


def _codes(path: Path) -> set[str]:
    return {e.code for f in split_files(_text(path)) for e in f.expected}


@pytest.mark.parametrize("path", FILES, ids=[p.name for p in FILES])
def test_fixture(path: Path) -> None:
    named = path.name.removesuffix(".xml").removesuffix(".ok")
    code = named if named in CODES else None
    text, fixed = split_fixed(path.read_text(encoding="utf-8"))
    check(text, code)
    if fixed:
        assert len(split_files(text)) == 1, "a fixed section follows a one-file fixture"
    for title, after in fixed:
        check_fix(text, after, title, code)


# A fixture may hold its near miss itself, after this line (instead of a ``.ok.xml``).
NEAR_MISS = "<!-- near miss -->"


@pytest.mark.parametrize("code", list(CODES))
def test_every_code_has_a_positive_and_a_negative_fixture(code: str) -> None:
    positive, negative = FIXTURES / f"{code}.xml", FIXTURES / f"{code}.ok.xml"
    assert positive.is_file(), f"write {positive.name}"
    assert code in _codes(positive)
    if negative.is_file():
        assert code not in _codes(negative)
        return
    # The near miss in the same file: nothing of ``code`` reported after the line (every
    # finding of a fixture is annotated, so the fixture's own check proves it).
    files = [f for f in split_files(_text(positive)) if NEAR_MISS in f.text]
    assert files, f"write {negative.name}, or a near miss after '{NEAR_MISS}' in {positive.name}"
    for f in files:
        line = f.text[: f.text.index(NEAR_MISS)].count("\n")
        assert "<" in f.text[f.text.index(NEAR_MISS) + len(NEAR_MISS) :], "an empty near miss"
        assert all(e.start[0] < line for e in f.expected if e.code == code), (
            f"{positive.name} reports {code} after its near miss"
        )


def test_no_fixture_without_a_code() -> None:
    names = {p.name.removesuffix(".ok.xml").removesuffix(".xml") for p in FILES}
    assert names <= set(CODES)


# -- the fixture form itself ------------------------------------------------------------


MARKED = """<root BTCPP_format="4">
  <BehaviorTree ID="Main Tree">
<!--                ^^^^^^^^^ error model-name-forbidden-char -->
    <AlwaysSuccess/>
  </BehaviorTree>
</root>"""


def test_annotations_are_removed_and_read_by_line_and_column() -> None:
    f = parse(MARKED)
    assert "<!--" not in f.text
    assert f.text.splitlines()[1] == '  <BehaviorTree ID="Main Tree">'
    (e,) = f.expected
    assert (e.start, e.end, e.severity, e.code, e.message) == (
        (1, 20),
        (1, 29),
        "error",
        "model-name-forbidden-char",
        "",
    )


def test_other_forms_of_ranges() -> None:
    f = parse(
        "ab\n<!-- @0-2 hint c -->\nxyz\n<!-- @0:1-1:2 hint d -->\n        w\n<!--    | hint e -->"
    )
    assert [(e.start, e.end, e.code) for e in f.expected] == [
        ((0, 0), (0, 2), "c"),
        ((0, 1), (1, 2), "d"),
        ((2, 8), (2, 8), "e"),
    ]


def test_render_writes_what_parse_reads() -> None:
    for path in FILES[:10]:
        for f in split_files(_text(path)):
            assert parse(render(f.text, f.expected)).expected == f.expected


def test_a_wrong_annotation_fails_and_shows_what_is_reported() -> None:
    wrong = MARKED.replace("^^^^^^^^^", "^^^^^^^^")
    with pytest.raises(AssertionError, match="model-name-forbidden-char: Model name"):
        check(wrong)


@pytest.mark.parametrize(
    "reason",
    ["No such file or directory", "The system cannot find the path specified"],
)
def test_a_missing_file_reads_the_same_on_every_system(
    reason: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr("tests.annotated.os.sep", "\\")
    root = "C:\\tmp\\fx"
    message = f"Included file 'trees/dock.xml' not found ({root}\\trees\\dock.xml: {reason})"
    diag = Diagnostic(0, 1, "include-not-found", message, Severity.ERROR)
    (e,) = found(Document("<root/>"), [diag], root)
    assert e.message == (
        "Included file 'trees/dock.xml' not found ({root}/trees/dock.xml: {not-found})"
    )


def test_crlf_positions_are_the_same_lines_and_columns() -> None:
    (lf,) = diagnostics(MARKED, "\n")
    (crlf,) = diagnostics(MARKED, "\r\n")
    assert lf[1] == crlf[1] and lf[1]


def test_non_bmp_characters_count_one_column() -> None:
    check(
        """<root BTCPP_format="4">
  <BehaviorTree ID="Main">
    <AlwaysSuccess name="🙂" _skipif="1"/>
<!--                        ^^^^^^^ warning unknown-attribute -->
  </BehaviorTree>
</root>"""
    )


def test_a_fixed_section_is_the_whole_document_after_the_fix() -> None:
    title = "Rename 'Main Tree' to 'Main_Tree' (1 place)"
    after = (
        '<root BTCPP_format="4">\n  <BehaviorTree ID="Main_Tree">\n    <AlwaysSuccess/>\n'
        "  </BehaviorTree>\n</root>\n"
    )
    text, fixed = split_fixed(f"{MARKED}\n<!-- fixed: {title} -->\n{after}")
    assert (text, fixed) == (MARKED + "\n", [(title, after)])
    check_fix(text, after, title)
    with pytest.raises(AssertionError):
        check_fix(text, after.replace("Main_Tree", "MainTree"), title)  # not what it makes
    assert split_fixed(MARKED) == (MARKED, [])


# -- fixes, whole texts before and after ---------------------------------------------------


def T(body: str) -> str:
    """A document with one tree around ``body``."""
    return f'<root BTCPP_format="4"><BehaviorTree ID="M">{body}</BehaviorTree></root>'


def test_fix_escapes_a_raw_ampersand() -> None:
    check_fix(
        T('<AlwaysSuccess name="a & b"/>'),
        T('<AlwaysSuccess name="a &amp; b"/>'),
        "Escape '&' as '&amp;'",
    )


def test_fix_adds_the_format() -> None:
    check_fix(
        '<root>\n  <BehaviorTree ID="M">\n    <AlwaysSuccess/>\n  </BehaviorTree>\n</root>\n',
        '<root BTCPP_format="4">\n'
        '  <BehaviorTree ID="M">\n    <AlwaysSuccess/>\n  </BehaviorTree>\n</root>\n',
        'Add BTCPP_format="4" to <root>',  # unsafe with no version known: not preferred
    )


def test_fix_removes_the_id_of_a_compact_node() -> None:
    check_fix(
        T('<AlwaysSuccess ID="x"/>'),
        T("<AlwaysSuccess/>"),
        "Remove ID from <AlwaysSuccess>",
    )


def test_fix_renames_a_misspelt_reserved_attribute() -> None:
    check_fix(
        T('<AlwaysSuccess _skipif="1"/>'),
        T('<AlwaysSuccess _skipIf="1"/>'),
        "Did you mean '_skipIf'? Rename '_skipif'",
    )


def test_fix_renames_a_version_3_node_type_with_its_end_tag() -> None:
    check_fix(
        T("<SequenceStar><AlwaysSuccess/></SequenceStar>"),
        T("<SequenceWithMemory><AlwaysSuccess/></SequenceWithMemory>"),
        "Rename 'SequenceStar' to 'SequenceWithMemory'",
    )


def test_fix_renames_a_bad_tree_id_with_its_calls() -> None:
    check_fix(
        '<root BTCPP_format="4" main_tree_to_execute="Main Tree">\n'
        '  <BehaviorTree ID="Main Tree">\n    <AlwaysSuccess/>\n  </BehaviorTree>\n</root>\n',
        '<root BTCPP_format="4" main_tree_to_execute="Main_Tree">\n'
        '  <BehaviorTree ID="Main_Tree">\n    <AlwaysSuccess/>\n  </BehaviorTree>\n</root>\n',
        "Rename 'Main Tree' to 'Main_Tree' (2 places)",
    )
