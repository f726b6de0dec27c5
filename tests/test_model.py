"""The BT document model: which token is which kind of name, and what it refers to."""

from __future__ import annotations

import pytest

from bt_lsp.rules.codes import Severity
from bt_lsp.rules.diagnostics import own_diagnostics
from bt_lsp.rules.names import NameKind
from bt_lsp.syntax.document import Document
from bt_lsp.syntax.elements import (
    NameSymbol,
    PortSymbol,
    Role,
    Symbol,
    Zone,
    model_symbol,
    port_symbol,
    tree_symbol,
)
from tests.marks import unmark

# Every checked name position of the contract is marked; nothing else may be a checked name.
POSITIONS = [
    # compact node element names inside trees; their attributes are ports
    '<root><BehaviorTree ID="⟦T⟧"><⟦MoveBase⟧ ⟦goal⟧="{g}" ⟦speed⟧="1"/></BehaviorTree></root>',
    # explicit IDs and SubTree IDs; attributes of SubTree calls are ports
    '<root><BehaviorTree ID="⟦T⟧"><⟦Sequence⟧><Action ID="⟦Go⟧" ⟦to⟧="x"/>'
    '<SubTree ID="⟦Sub⟧" ⟦target⟧="{t}" _autoremap="true"/></Sequence></BehaviorTree></root>',
    # instance names are values of name=
    '<root><BehaviorTree ID="⟦T⟧"><⟦Foo⟧ name="⟦my foo⟧"/></BehaviorTree></root>',
    # reserved attributes on nodes are not ports
    '<root><BehaviorTree ID="⟦T⟧"><⟦Foo⟧ _skipIf="a" _while="b" _onSuccess="c" _post="d" '
    '_description="x" __shared_blackboard="y" _autoremap="1"/></BehaviorTree></root>',
    # TreeNodesModel entry IDs and port declarations
    '<root><TreeNodesModel><Action ID="⟦Go⟧"><input_port name="⟦to⟧" type="int"/>'
    '<output_port name="⟦out⟧"/></Action><SubTree ID="⟦Sub⟧">'
    '<inout_port name="⟦io⟧" default="1"/></SubTree></TreeNodesModel></root>',
    # not names: root attributes, include path, comments, CDATA, BehaviorTree attributes
    '<root BTCPP_format="4" main_tree_to_execute="T"><include path="a b.xml"/>'
    '<!-- <Bad.Name/> --><BehaviorTree ID="⟦T⟧" _description="d.e"><![CDATA[<X.Y/>]]>'
    "<⟦AlwaysSuccess⟧/></BehaviorTree></root>",
    # entity references stay inside the span
    '<root><BehaviorTree ID="⟦Main&#x20;Tree⟧"><⟦A⟧ name="⟦a&amp;b⟧"/></BehaviorTree></root>',
]


@pytest.mark.parametrize("marked", POSITIONS)
def test_checked_names_are_exactly_the_contract_positions(marked: str) -> None:
    text, spans = unmark(marked)
    model = Document(text).model
    got = sorted((r.start, r.end) for r in model.refs if r.kind is not None)
    assert got == spans, [text[s:e] for s, e in got]


def roles(marked: str) -> list[tuple[str, Role, NameKind | None, tuple[str, ...] | None]]:
    text, _ = unmark(marked)
    return [(r.text, r.role, r.kind, r.symbol) for r in Document(text).model.refs]


def test_symbols_link_references_to_their_targets() -> None:
    text = (
        '<root main_tree_to_execute="Main"><BehaviorTree ID="Main"><Sequence>'
        '<Go to="x"></Go><SubTree ID="Sub" p="1"/></Sequence></BehaviorTree>'
        '<BehaviorTree ID="Sub"><Action ID="Go" to="y"/></BehaviorTree>'
        '<TreeNodesModel><Action ID="Go"><input_port name="to"/></Action>'
        '<SubTree ID="Sub"><input_port name="p"/></SubTree></TreeNodesModel></root>'
    )
    model = Document(text).model
    by_symbol: dict[Symbol, list[Role]] = {}
    for r in model.refs:
        if r.symbol is not None:
            by_symbol.setdefault(r.symbol, []).append(r.role)
    assert by_symbol[tree_symbol("Main")] == [Role.MAIN_TREE, Role.TREE_DEF]
    assert by_symbol[tree_symbol("Sub")] == [Role.SUBTREE_CALL, Role.TREE_DEF, Role.MODEL_DEF]
    assert by_symbol[model_symbol("Go")] == [
        Role.NODE_TYPE,
        Role.NODE_TYPE_END,
        Role.NODE_ID,
        Role.MODEL_DEF,
    ]
    assert by_symbol[port_symbol(model_symbol("Go"), "to")] == [
        Role.PORT_USE,
        Role.PORT_USE,
        Role.PORT_DECL,
    ]
    assert by_symbol[port_symbol(tree_symbol("Sub"), "p")] == [Role.PORT_USE, Role.PORT_DECL]
    port = next(s for s in by_symbol if s.kind == "port" and s.owner_kind == "tree")
    assert isinstance(port, PortSymbol)
    assert (port.owner, port.name, port.owner_symbol) == ("Sub", "p", tree_symbol("Sub"))
    assert all(isinstance(s, NameSymbol | PortSymbol) for s in by_symbol)


def test_zones() -> None:
    text = (
        "<root><include path='x'/><BehaviorTree ID='T'><A><B/></A></BehaviorTree>"
        "<TreeNodesModel><Action ID='A'><input_port name='p'/><MetadataFields/></Action>"
        "</TreeNodesModel><Other/></root>"
    )
    zones = [(e.name, e.zone) for e in Document(text).model.elements]
    assert zones == [
        ("root", Zone.ROOT),
        ("include", Zone.INCLUDE),
        ("BehaviorTree", Zone.TREE),
        ("A", Zone.NODE),
        ("B", Zone.NODE),
        ("TreeNodesModel", Zone.MODELS),
        ("Action", Zone.MODEL_ENTRY),
        ("input_port", Zone.PORT_DECL),
        ("MetadataFields", Zone.OTHER),
        ("Other", Zone.OTHER),
    ]


def xml_errors(text: str) -> list[tuple[str, str]]:
    doc = Document(text)
    return [
        (doc.text[d.start : d.end], d.message)
        for d in own_diagnostics(doc)
        if d.code == "xml-syntax"
    ]


def test_structure_errors_do_not_cascade() -> None:
    # A missing end tag is one error, at the unclosed element.
    errs = xml_errors("<root><BehaviorTree ID='T'><Sequence><A/></BehaviorTree></root>")
    assert [e[0] for e in errs] == ["Sequence"]
    # An unterminated start tag is reported once, not again when its parent closes.
    errs = xml_errors('<root><BehaviorTree ID="T">\n<Open door="x"\n<B/></BehaviorTree></root>')
    assert [e[0] for e in errs] == ["Open"]
    # A stray end tag.
    errs = xml_errors("<root></Nope></root>")
    assert [e[0] for e in errs] == ["Nope"]


def test_well_formed_documents_have_no_syntax_errors() -> None:
    text = (
        '<?xml version="1.0" encoding="UTF-8"?>\n<!-- c -->\n<root BTCPP_format="4">\n'
        '  <BehaviorTree ID="T"><Script code="a := 1; b = &apos;x&apos;"/></BehaviorTree>\n'
        "</root>\n"
    )
    assert xml_errors(text) == []


def test_raw_amp_and_lt_in_values_are_warnings_only() -> None:
    doc = Document(
        '<root><BehaviorTree ID="T"><A _while="a && b&lt;1" _skipIf="x<1.0"/></BehaviorTree></root>'
    )
    assert {d.code for d in own_diagnostics(doc)} == {"xml-unescaped-char"}


def test_invalid_xml_name_characters_not_covered_by_the_name_rules() -> None:
    errs = xml_errors('<root><BehaviorTree ID="T"><Move(JTC) a="1"/></BehaviorTree></root>')
    assert errs and errs[0][0] == "("
    # '.' is a valid XML name character: only the name rule reports it.
    assert xml_errors('<root><BehaviorTree ID="T"><Open.Door/></BehaviorTree></root>') == []


def test_text_outside_root() -> None:
    doc = Document("<root/>\ntrailing")
    found = [(doc.text[d.start : d.end], d.code, d.severity) for d in own_diagnostics(doc)]
    assert found == [("trailing", "xml-lenient", Severity.WARNING)]


def test_what_tinyxml2_accepts_is_a_warning_not_an_error() -> None:
    """tinyxml2 (BehaviorTree.CPP's parser) reads text before the root, attributes without
    white space between them and elements after the root; at a stray end tag after the root
    it stops reading. None of it fails the load, so none of it is an error."""
    text = (
        'preamble\n<root BTCPP_format="4"><BehaviorTree ID="T"><A a="1"b="2"/></BehaviorTree>'
        "</root>\n<Extra/>\n</Sequence>"
    )
    doc = Document(text)
    found = [(doc.text[d.start : d.end], d.code) for d in own_diagnostics(doc)]
    assert found == [
        ("preamble\n", "xml-lenient"),
        ("b", "xml-lenient"),
        ("Extra", "xml-extra-root"),
        ("Sequence", "xml-extra-root"),
    ]
    assert all(d.severity == Severity.WARNING for d in own_diagnostics(doc))
    # A mismatched end tag inside the root is still an error: tinyxml2 fails there.
    assert xml_errors('<root><BehaviorTree ID="T"></Sequence></BehaviorTree></root>')
