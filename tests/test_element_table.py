"""Elements kept as columns and read as views (:mod:`bt_lsp.syntax.table`): whichever way
an element is read (iterated, indexed, sliced, in a section's coordinates or the
document's), it is the same element, and equal to one made on its own."""

from __future__ import annotations

from array import array

from bt_lsp.syntax.document import Document
from bt_lsp.syntax.elements import Element, Zone
from bt_lsp.syntax.table import ElementTable

TEXT = (
    '<root BTCPP_format="4" main_tree_to_execute="T">\n'
    '  <BehaviorTree ID="T">\n'
    "    <Sequence>" + "<Frob/>" * 700 + '<Frob a="1"/><Frob a="1"/>\n'
    '      <SubTree ID="U"/>\n'
    "    </Sequence>\n"
    "  </BehaviorTree>\n"
    '  <BehaviorTree ID="U"><Fallback><A/><B></B></Fallback></BehaviorTree>\n'
    "  <TreeNodesModel>\n"
    '    <Action ID="A"><input_port name="x">the <![CDATA[x]]> port</input_port></Action>\n'
    "  </TreeNodesModel>\n"
    "</root>\n"
    "<Stray/>\n"
)


def _view(el: Element) -> tuple[object, ...]:
    return (
        el.name, el.zone, el.token_start, el.token_index, el.parent, el.depth, el.attrs,
        el.self_closing, el.closed, el.end, el.end_name_start, el.end_name_end,
        list(el.children), el.content,
    )  # fmt: skip


def test_iterated_indexed_and_sliced_elements_are_the_same() -> None:
    els = Document(TEXT).model.elements
    listed = list(els)
    assert len(listed) == len(els) > 700
    assert [_view(e) for e in listed] == [_view(els[i]) for i in range(len(els))]
    assert _view(els[-1]) == _view(listed[-1])
    assert [_view(e) for e in els[3:9]] == [_view(e) for e in listed[3:9]]


def test_the_tree_is_exact_in_document_coordinates() -> None:
    doc = Document(TEXT)
    els = list(doc.model.elements)
    for i, el in enumerate(els):
        # Each child names its parent, in order, and starts where the text says.
        assert [els[c].parent for c in el.children] == [i] * len(el.children)
        assert doc.text.startswith("<" + el.name, el.token_start)
        if el.end >= 0:
            assert doc.text[el.end - 1] == ">"
        if el.end_name_start >= 0:
            assert doc.text[el.end_name_start : el.end_name_end] == el.name
        assert doc.scan.starts[el.token_index] == el.token_start
    port = next(e for e in els if e.zone == Zone.PORT_DECL)
    assert port.content == "the x port"
    assert els[0].zone == Zone.ROOT and els[-1].zone == Zone.OUTSIDE
    assert els[-1].parent == -1 and len(els[0].children) == 3


def test_a_section_read_in_its_coordinates_and_placed() -> None:
    model = Document(TEXT).model
    for k, sec in enumerate(model.sections):
        table = sec.elements
        assert isinstance(table, ElementTable)
        placed = model.part(k).elements()
        base = model.bases[k]
        for j, (local, el) in enumerate(zip(table, placed, strict=True)):
            assert el.token_start == local.token_start + model.origins[k]
            assert el.token_index == local.token_index + model.firsts[k]
            assert el.parent == (local.parent + base - 1 if local.parent > 0 else 0)
            assert list(el.children) == [c + base - 1 for c in local.children]
            assert _view(el) == _view(model.elements[base + j])


def test_an_element_read_equals_one_made_alone() -> None:
    el = Document('<root><BehaviorTree ID="T"><A x="1"></A></BehaviorTree></root>').model.elements[
        2
    ]
    alone = Element("A", Zone.NODE, 27, 2, 1, 2, el.attrs, False, True, 40, 38, length=9)
    assert el == alone
    assert not el.__ne__(alone)  # != is the same comparison, not the tuples'
    assert alone.children == () and alone.content is None
    assert Element("R", Zone.ROOT, 0, 0, -1, 0, (), False, True, children=array("i", [1])) != el


def test_a_section_of_thousands_is_iterated_whole() -> None:
    doc = Document(
        '<root><BehaviorTree ID="T"><Sequence>'
        + "<A/>" * 5000
        + "</Sequence></BehaviorTree></root>"
    )
    (sec,) = doc.model.sections
    it = iter(sec.elements)
    first = next(it)
    assert first.name == "BehaviorTree" and len(sec.elements) == 5002
    assert sum(1 for _ in it) == 5001


def test_a_run_of_equal_empty_elements_is_built_like_any_other() -> None:
    # Equal tags in a row are added at once: each still has its own offset, token index
    # and problems, and each child of <root> still starts a section.
    body = "<A§/>" * 3
    text = (
        f'<root><BehaviorTree ID="T"><Sequence>{body}</Sequence></BehaviorTree>{"<X/>" * 3}</root>'
    )
    model = Document(text).model
    at = text.index("<A§/>")
    assert [(p.start, p.code) for p in model.problems] == [
        (at + 2 + 5 * k, "xml-syntax") for k in range(3)
    ]
    assert [s.top_name for s in model.sections] == ["BehaviorTree", "X", "X", "X"]
    els = list(model.elements)
    assert [(e.name, e.token_start, e.token_index, e.parent, e.end) for e in els[3:6]] == [
        ("A§", at + 5 * k, 3 + k, 2, at + 5 * k + 5) for k in range(3)
    ]
    assert list(els[2].children) == [3, 4, 5]
    assert list(els[0].children) == [1, 6, 7, 8]


def test_elements_that_stand_for_enough_text_are_kept_and_tiny_ones_are_not() -> None:
    dense = Document(
        '<root><BehaviorTree ID="T"><Sequence>'
        + '<SetBlackboard output_key="{key}" value="a value of some length"/>' * 50
        + "</Sequence></BehaviorTree></root>"
    )
    tiny = Document(
        '<root><BehaviorTree ID="T"><Sequence>' + "<A/>" * 50 + "</Sequence></BehaviorTree></root>"
    )
    (kept,) = (s.elements for s in dense.model.sections)
    (made,) = (s.elements for s in tiny.model.sections)
    assert kept.kept and not made.kept
    assert next(iter(kept)) is next(iter(kept)) and kept[3] is kept[3]  # made once
    assert next(iter(made)) is not next(iter(made))  # made when read, not kept
    assert [_view(e) for e in kept] == [_view(kept[i]) for i in range(len(kept))]
