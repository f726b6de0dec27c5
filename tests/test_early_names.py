"""The early name pass (bt_lsp.rules.early_names): what it reports is exactly what the full
analysis reports for the name rules, or it gives up."""

from __future__ import annotations

import operator
import os
import string
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from bt_lsp.rules.analysis import analyze
from bt_lsp.rules.diagnostics import Diagnostic
from bt_lsp.rules.early_names import early_name_diagnostics
from bt_lsp.rules.names import PROJECT_NAME_CODES, NameKind, all_valid_port_uses, check_name
from bt_lsp.syntax.document import Document
from tests.test_scanner import xmlish

EXAMPLES = int(os.environ.get("BT_LSP_FUZZ_EXAMPLES", "150"))
CORPUS = sorted((Path(__file__).parent / "data" / "corpus").rglob("*.xml"))


def full_names(text: str) -> list[Diagnostic]:
    """The name-rule diagnostics of the full analysis, in its order, but for those that
    depend on the project (a declared port's reserved name), which the pass leaves to it."""
    return [
        d for d in analyze(Document(text)) if d.is_name_rule and d.code not in PROJECT_NAME_CODES
    ]


def early(text: str) -> list[Diagnostic]:
    found = early_name_diagnostics(text)
    assert found is not None, "the pass gave up on a document it follows"
    return found


# -- examples ---------------------------------------------------------------------------

EVERY_ROLE = (
    '<?xml version="1.0" encoding="UTF-8"?>\r\n'
    '<root BTCPP_format="4" main_tree_to_execute="Main Tree">\r\n'
    '  <BehaviorTree ID="Main Tree">\r\n'
    '    <Sequence name="tab\there &#127;del">\r\n'
    '      <Do.It a.b="1" x-y="{v}" _skipIf="x" name="ok"/>\r\n'
    '      <Action ID="Act:ion" in="1"/>\r\n'
    '      <SubTree ID="root" _autoremap="true"/>\r\n'
    "      <!-- <Not.A.Node x.y='1'/> -->\r\n"
    "      <![CDATA[ <Nor.This/> ]]>\r\n"
    "      <?pi <Nor.That/> ?>\r\n"
    '      <Fine name="😀 \x7f" p="&lt;a&gt;"/>\r\n'
    "    </Sequence>\r\n"
    "  </BehaviorTree>\r\n"
    "  <TreeNodesModel>\r\n"
    '    <Action ID="Bad Model">\r\n'
    '      <input_port name="ID"/>\r\n'
    '      <output_port name="9lives">text</output_port>\r\n'
    '      <inout_port name="fine_port"/>\r\n'
    "    </Action>\r\n"
    '    <SubTree ID="Sub.Tree"><input_port name="a b"/></SubTree>\r\n'
    "  </TreeNodesModel>\r\n"
    "</root>\r\n"
)


def test_every_role_is_reported_as_the_full_analysis_reports_it() -> None:
    found = early(EVERY_ROLE)
    assert found == full_names(EVERY_ROLE)
    assert {EVERY_ROLE[d.start : d.end] for d in found} == {
        "Main Tree",
        "tab\there &#127;del",
        "Do.It",
        "a.b",
        "Act:ion",
        "root",
        "😀 \x7f",
        "Bad Model",
        "9lives",
        "Sub.Tree",
        "a b",
    }
    # Nothing inside the comment, the CDATA section or the processing instruction.
    assert not any("Not.A" in d.message or "Nor." in d.message for d in found)
    # The reserved port name is the full analysis's, which knows the model entry and the
    # BehaviorTree.CPP version.
    (reserved,) = [d for d in analyze(Document(EVERY_ROLE)) if d.code in PROJECT_NAME_CODES]
    assert (EVERY_ROLE[reserved.start : reserved.end], reserved.code) == (
        "ID",
        "port-name-reserved-groot2",
    )


def test_the_instance_names_checked_together_are_placed_each_on_its_node() -> None:
    """The instance names are searched in one string, joined by line feeds: a name that
    holds a line feed (a character reference) or ends the document's list is placed on
    its own node, a bad name beside a good one on the same tag too."""
    names = [f"node {i}" for i in range(300)]
    names[0] = "first\x7f"
    names[17] = "line&#10;feed"  # (the joining character, allowed)
    names[18] = "after a&#10;line feed &#127;"
    names[150] = "&#127;"
    names[-1] = "last \x7f"
    nodes = "".join(f'<Sequence name="{n}"><AlwaysSuccess name="ok"/></Sequence>' for n in names)
    text = f'<root BTCPP_format="4"><BehaviorTree ID="Main">{nodes}</BehaviorTree></root>'
    found = early(text)
    assert found == full_names(text)
    assert [text[d.start : d.end] for d in found] == [names[k] for k in (0, 18, 150, 299)]


def test_a_clean_document_has_none() -> None:
    text = '<root BTCPP_format="4"><BehaviorTree ID="Main"><AlwaysSuccess/></BehaviorTree></root>'
    assert early(text) == [] == full_names(text)


@pytest.mark.parametrize(
    "text",
    [
        pytest.param('<root><BehaviorTree ID="a b">', id="unfinished"),
        pytest.param('<root><BehaviorTree ID="a b"/></root><x/>', id="two roots"),
        pytest.param('<root><A x="1" x="2"/></root>', id="duplicate attribute"),
        pytest.param('<root><A x="&nbsp;"/></root>', id="undefined entity"),
        pytest.param('<!DOCTYPE root [<!ENTITY e "a b">]><root><A ID="&e;"/></root>', id="doctype"),
        pytest.param('<root xmlns:b="urn:b"><b:A.x/></root>', id="namespace"),
        pytest.param('<root><BehaviorTree ID="M"><b:A.x/></BehaviorTree></root>', id="prefix"),
        pytest.param('<root><A name="\ud800"/></root>', id="lone surrogate"),
        pytest.param('<root><A name="\x01"/></root>', id="not an XML character"),
        pytest.param("", id="empty"),
    ],
)
def test_gives_up_on_what_it_does_not_follow(text: str) -> None:
    assert early_name_diagnostics(text) is None


def test_gives_up_rather_than_report_a_part_of_too_many() -> None:
    body = '<Bad.Name a="1"/>' * 2500
    text = f'<root><BehaviorTree ID="M">{body}</BehaviorTree></root>'
    assert early_name_diagnostics(text) is None


def test_reads_no_file_and_no_entity() -> None:
    text = (
        '<!DOCTYPE root SYSTEM "/etc/passwd"><root><BehaviorTree ID="a b"/></root>\n'
        '<root><x y="&ext;"/></root>'
    )
    assert early_name_diagnostics(text) is None


# -- the corpus and generated documents --------------------------------------------------


def test_corpus_files_match_the_full_analysis() -> None:
    followed = 0
    for path in CORPUS:
        text = path.read_text(encoding="utf-8", errors="replace")
        found = early_name_diagnostics(text)
        if found is not None:
            followed += 1
            assert found == full_names(text), path
    assert followed >= len(CORPUS) * 0.9


# Names that are valid XML names (so the document stays well-formed) but may break the
# BT rules, and attribute values of any kind.
# (The strings of r"[A-Za-z_][A-Za-z0-9_.\-é😀]{0,5}", built from two plain strategies: drawn
# through st.from_regex they took most of the generated-document test's time.)
_NAME_START = string.ascii_letters + "_"
_XML_NAME = st.builds(
    operator.add,
    st.sampled_from(_NAME_START),
    st.text(alphabet=_NAME_START + string.digits + ".-é😀", max_size=5),
).filter(lambda s: "xml" not in s.lower())
_VALUE = st.text(alphabet="aZ_9. \t\n\r&<>\"'/\\*?|:\x7f😀é", max_size=6)
_TAGS = st.sampled_from(["Sequence", "Fallback", "Action", "Condition", "SubTree", "Inverter"])
_KEYS = st.sampled_from(["name", "ID", "_skipIf", "_autoremap", "port", "__shared_blackboard"])
# The strategies the composites below draw from, made once: a strategy made inside a draw is
# validated again at every draw, which took a good part of the generation time.
_BOOLEANS = st.booleans()
_ATTR_KEYS = st.lists(_KEYS | _XML_NAME, max_size=3, unique=True)
_ASIDE_KINDS = st.sampled_from(["comment", "cdata", "pi", "text", "none"])
_PORT_TAGS = st.sampled_from(["input_port", "output_port", "inout_port", "other"])
_TAG = _TAGS | _XML_NAME
_ID = _VALUE | _XML_NAME
_PORT_NAME = _VALUE | _KEYS | _XML_NAME
_UP_TO_3 = st.integers(0, 3)


def _escape(value: str, draw: st.DrawFn) -> str:
    out = []
    for ch in value:
        if ch in "&<\"'":
            out.append({"&": "&amp;", "<": "&lt;", '"': "&quot;", "'": "&apos;"}[ch])
        elif ch in "\t\n\r\x7f" and draw(_BOOLEANS):
            out.append(f"&#{ord(ch)};")
        else:
            out.append(ch)
    return "".join(out)


@st.composite
def _attrs(draw: st.DrawFn) -> str:
    keys = draw(_ATTR_KEYS)
    return "".join(f' {k}="{_escape(draw(_VALUE), draw)}"' for k in keys)


@st.composite
def _aside(draw: st.DrawFn) -> str:
    """Markup whose '<' does not start an element."""
    inner = f'<{draw(_XML_NAME).replace("-", "_")} a.b="1"/>'  # no "--" in a comment
    kind = draw(_ASIDE_KINDS)
    return {
        "comment": f"<!-- {inner} -->",
        "cdata": f"<![CDATA[{inner}]]>",
        "pi": f"<?pi {inner}?>",
        "text": " &lt;x.y&gt; ",
        "none": "",
    }[kind]


@st.composite
def _node(draw: st.DrawFn, depth: int = 0) -> str:
    tag = draw(_TAG)
    attrs = draw(_ATTRS)
    children = [] if depth >= 3 else draw(_CHILDREN[depth + 1])
    aside = draw(_ASIDE)
    if not children and draw(_BOOLEANS):
        return f"{aside}<{tag}{attrs}/>"
    return f"{aside}<{tag}{attrs}>\n{''.join(children)}</{tag}>"


_ATTRS = _attrs()
_ASIDE = _aside()
# _CHILDREN[d]: up to three nodes at depth d (those at depth 3 have no children).
_CHILDREN = [st.lists(_node(depth), max_size=3) for depth in range(4)]


@st.composite
def _model(draw: st.DrawFn) -> str:
    entries = []
    for _ in range(draw(_UP_TO_3)):
        tag = draw(_TAGS)
        ports = "".join(
            f'<{draw(_PORT_TAGS)} name="{_escape(draw(_PORT_NAME), draw)}"/>'
            for _ in range(draw(_UP_TO_3))
        )
        entries.append(f'<{tag} ID="{_escape(draw(_ID), draw)}">{ports}</{tag}>')
    return f"<TreeNodesModel>{''.join(entries)}</TreeNodesModel>"


_MODEL = _model()
_NEWLINES = st.sampled_from(["\n", "\r\n", "\r", ""])


@st.composite
def bt_documents(draw: st.DrawFn) -> str:
    parts = []
    for _ in range(draw(_UP_TO_3)):
        tree_id = _escape(draw(_ID), draw)
        nodes = "".join(draw(_CHILDREN[0]))
        parts.append(f'<BehaviorTree ID="{tree_id}">{nodes}</BehaviorTree>')
    if draw(_BOOLEANS):
        parts.insert(draw(st.integers(0, len(parts))), draw(_MODEL))
    if draw(_BOOLEANS):
        parts.append(f"<{draw(_XML_NAME)}{draw(_ATTRS)}/>")  # ignored by BehaviorTree.CPP
    newline = draw(_NEWLINES)
    return f'<root BTCPP_format="4">{newline}{newline.join(parts)}</root>{newline}'


@given(bt_documents())
@settings(max_examples=EXAMPLES * 2, deadline=None, suppress_health_check=[HealthCheck.too_slow])
def test_generated_documents_match_the_full_analysis(text: str) -> None:
    assert early(text) == full_names(text)


@given(st.sampled_from(CORPUS[:40]), st.data())
@settings(max_examples=EXAMPLES, deadline=None, suppress_health_check=[HealthCheck.too_slow])
def test_edited_corpus_files_match_or_give_up(path: Path, data: st.DataObject) -> None:
    text = path.read_text(encoding="utf-8", errors="replace")[:6000]
    for _ in range(data.draw(st.integers(1, 3))):
        start = data.draw(st.integers(0, len(text)))
        end = data.draw(st.integers(start, min(len(text), start + 30)))
        text = text[:start] + data.draw(xmlish) + text[end:]
    found = early_name_diagnostics(text)
    assert found is None or found == full_names(text)


@given(xmlish)
@settings(max_examples=EXAMPLES, deadline=None)
def test_never_raises(text: str) -> None:
    found = early_name_diagnostics(text)
    assert found is None or found == full_names(text)


def test_a_tag_with_more_attributes_than_the_model_keeps() -> None:
    """Only a tag's first MAX_ATTRS attributes are checked, as the model keeps them: a bad
    name after them is not reported, one among them is, and the pass stays exact."""
    many = "".join(f' a{i}="1"' for i in range(3000))
    for bad_at in (10, 2500):
        attrs = many.replace(f' a{bad_at}="1"', ' b.ad="1"')
        text = f'<root BTCPP_format="4"><BehaviorTree ID="M"><Frob{attrs}/></BehaviorTree></root>'
        found = early(text)
        assert found == full_names(text)
        assert [text[d.start : d.end] for d in found] == (["b.ad"] if bad_at < 1000 else [])


@given(st.lists(st.text(alphabet="a0.:_- \x00\x7fé😀", max_size=4), max_size=6))
def test_the_bulk_port_check_is_check_name_for_each(names: list[str]) -> None:
    expected = all(not check_name(n, NameKind.PORT) for n in names)
    assert all_valid_port_uses(names) == expected
    assert all_valid_port_uses(set(names)) == expected


def test_gives_up_on_a_tag_lxml_would_read_in_one_long_call() -> None:
    """A start tag of more than 256 Ki characters (700,000 attributes: lxml read it in one
    call of 0.8 s, holding the interpreter beside the event loop) is left to the full
    analysis; one just under that length is still read."""
    for count, gives_up in ((40_000, True), (20_000, False)):
        attrs = "".join(f' a{i}="1"' for i in range(count))
        text = f'<root BTCPP_format="4"><BehaviorTree ID="M"><Frob{attrs}/></BehaviorTree></root>'
        assert (early_name_diagnostics(text) is None) is gives_up
