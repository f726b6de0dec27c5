"""Names read from the tags that hold them, not from all a section's names: the name token
at an offset (``Section.ref_in_tag``) is the one found among all of them, wherever one tag
can tell, and a large section answers so without making its names; the names that declare
a symbol (``Model.declarations_of``) are those of all its references that declare."""

from __future__ import annotations

from bisect import bisect_right
from pathlib import Path

from hypothesis import given, settings
from hypothesis import strategies as st

from bt_lsp.syntax import sections
from bt_lsp.syntax.document import Document
from bt_lsp.syntax.elements import DECLARING_ROLES, NameRef
from bt_lsp.syntax.sections import Section

DATA = Path(__file__).parent / "data"

_PIECES = st.sampled_from(
    [
        "<AlwaysSuccess/>",
        '<SubTree ID="T1" goal="{g}"/>',
        '<Action ID="Frob" a="1"/>',
        "<Sequence name='s'><Frob/><Inverter><AlwaysFailure/></Inverter></Sequence>",
        "<Fallback>\n  <Frob a='1' b=\"&amp;x\"/>\r\n</Fallback>",
        "<Frob>text</Frob>",
        "<!-- c -->",
        "<Sequence><Frob/>",  # left open
        "</Stray>",
        "</Frob",  # unterminated end tag
        "<Frob a",  # unterminated start tag
        '<Frob a="x',  # unterminated value
        "<TreeNodesModel><Action ID='Frob'><input_port name='a'/></Action></TreeNodesModel>",
    ]
)
_BODIES = st.lists(st.lists(_PIECES, max_size=6).map("".join), min_size=1, max_size=4)


def _text(trees: list[str]) -> str:
    body = "".join(f'<BehaviorTree ID="T{i}">{t}</BehaviorTree>\n' for i, t in enumerate(trees))
    return f'<root BTCPP_format="4">\n{body}</root>\n'


def _sections(doc: Document) -> list[Section]:
    model = doc.model
    return [s for s in [model.head, *model.sections] if s is not None]


def _among_all(refs: list[NameRef], offset: int) -> NameRef | None:
    i = bisect_right([r.start for r in refs], offset) - 1
    return refs[i] if i >= 0 and refs[i].start <= offset <= refs[i].end else None


def _agrees(text: str) -> int:
    """Checks every offset of every section; how many ``ref_in_tag`` could tell."""
    told = 0
    for sec in _sections(Document(text)):
        refs = sec._make_refs()
        for offset in range(sec.length + 1):
            found = sec.ref_in_tag(offset)
            if found is sections.UNSURE:
                continue
            told += 1
            assert found == _among_all(refs, offset), (text, offset)
    return told


@settings(max_examples=150, deadline=None)
@given(_BODIES, st.integers(0, 10_000), st.integers(0, 3))
def test_the_tag_tells_what_all_names_tell(trees: list[str], cut: int, width: int) -> None:
    text = _text(trees)
    at = cut % (len(text) + 1)
    assert _agrees(text) > 0
    _agrees(text[:at] + text[at + width :])  # broken anywhere, as while typing


def test_real_files_agree() -> None:
    files = sorted((DATA / "corpus").rglob("*.xml"))[:40]
    assert files
    assert sum(_agrees(f.read_text(encoding="utf-8")) for f in files) > 10_000


def test_a_large_section_does_not_make_its_names(monkeypatch: object) -> None:
    text = _text(["<Sequence>" + '\n  <Frob a="{k}"/>' * 5_000 + "</Sequence>"])
    doc = Document(text)
    made: list[Section] = []
    original = Section._make_refs

    def counting(self: Section) -> list[NameRef]:
        made.append(self)
        return original(self)

    Section._make_refs = counting  # type: ignore[method-assign]
    try:
        at = text.index("<Frob", len(text) // 2) + 2
        ref = doc.model.ref_at(at)
        assert ref is not None and ref.text == "Frob"
        port = doc.model.ref_at(at + 4)
        assert port is not None and port.text == "a"
        end = doc.model.ref_at(text.index("</Sequence>") + 3)
        assert end is not None and end.text == "Sequence"
        assert doc.model.ref_at(at - 4) is None  # between tags
    finally:
        Section._make_refs = original  # type: ignore[method-assign]
    assert made == []


def _declarations_agree(text: str) -> int:
    """Checks every symbol of ``text``; how many declarations were found."""
    model = Document(text).model
    n = 0
    for symbol in list(model.by_symbol):
        want = [r for r in model.refs_to(symbol) if r.role in DECLARING_ROLES]
        assert model.declarations_of(symbol) == want, (text, symbol)
        n += len(want)
    return n


@settings(max_examples=100, deadline=None)
@given(_BODIES, st.integers(0, 10_000), st.integers(0, 3))
def test_declarations_are_those_among_all_references(
    trees: list[str], cut: int, width: int
) -> None:
    text = _text(trees)
    at = cut % (len(text) + 1)
    assert _declarations_agree(text) > 0  # every tree's ID at least
    _declarations_agree(text[:at] + text[at + width :])


def test_declarations_in_real_files() -> None:
    files = sorted((DATA / "corpus").rglob("*.xml"))
    assert sum(_declarations_agree(f.read_text(encoding="utf-8")) for f in files) > 500
