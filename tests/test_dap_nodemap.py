"""A tree file's lines to the running tree's uids (bt_lsp.dap.nodemap), and blackboard
values as DAP variables (bt_lsp.dap.values)."""

from __future__ import annotations

from bt_lsp.dap.nodemap import SourceMap
from bt_lsp.dap.values import MAX_CHILDREN, MAX_VALUE, References, children, show, variable
from bt_lsp.live.tree import LiveTree, parse_tree_xml

TEXT = """\
<root BTCPP_format="4" main_tree_to_execute="Main">
  <BehaviorTree ID="Main">
    <Sequence name="seq">
      <Script code="x := 1"/>
      <SubTree ID="Sub" name="sub1"/>
      <SubTree ID="Sub"/>
      <Action ID="Work" name="work"/><AlwaysSuccess name="ok"/>
      <AlwaysFailure
          name="spread"/>
    </Sequence>
  </BehaviorTree>

  <BehaviorTree ID="Sub">
    <Sleep msec="30"/>
  </BehaviorTree>
  <BehaviorTree ID="Other">
    <AlwaysSuccess/>
  </BehaviorTree>
</root>
"""

# What BehaviorTree.CPP 4.8.2 answers FULLTREE with for TEXT (a SubTree without a name is
# "ID::uid"; every node has a name attribute).
FULLTREE = """\
<root BTCPP_format="4">
  <BehaviorTree ID="Main" _fullpath="">
    <Sequence name="seq" _uid="1">
      <Script name="Script" _uid="2" code="x := 1"/>
      <SubTree ID="Sub" _fullpath="sub1" _uid="3"/>
      <SubTree ID="Sub" _fullpath="Sub::5" _uid="5"/>
      <Work name="work" _uid="7"/>
      <AlwaysSuccess name="ok" _uid="8"/>
      <AlwaysFailure name="spread" _uid="9"/>
    </Sequence>
  </BehaviorTree>
  <BehaviorTree ID="Sub" _fullpath="sub1">
    <Sleep name="Sleep" _uid="4" msec="30"/>
  </BehaviorTree>
  <BehaviorTree ID="Sub" _fullpath="Sub::5">
    <Sleep name="Sleep" _uid="6" msec="30"/>
  </BehaviorTree>
</root>
"""


def tree(xml: str = FULLTREE) -> LiveTree:
    return parse_tree_xml(xml)


def mapped(text: str = TEXT, xml: str = FULLTREE) -> SourceMap:
    smap = SourceMap(text)
    smap.match(tree(xml))
    return smap


def uids_at(smap: SourceMap, line: int, column: int | None = None) -> tuple[int, ...]:
    node = smap.node_at(line, column)
    return () if node is None else smap.uids(node.element)


def test_each_line_with_a_start_tag_stands_for_its_nodes() -> None:
    smap = mapped()
    assert uids_at(smap, 2) == (1,)  # the Sequence
    assert uids_at(smap, 1) == (1,)  # a <BehaviorTree> line: its root node
    assert uids_at(smap, 3) == (2,)
    assert uids_at(smap, 4) == (3,)  # the SubTree node itself
    assert uids_at(smap, 5) == (5,)
    assert uids_at(smap, 13) == (4, 6)  # the Sleep of a tree called twice
    assert uids_at(smap, 0) == ()  # <root>: no node
    assert smap.node_at(9) is None and smap.node_at(11) is None
    assert smap.tree_ids == ("Main", "Sub", "Other")


def test_the_column_picks_among_nodes_on_one_line() -> None:
    smap = mapped()
    assert uids_at(smap, 6) == (7,)  # the first on the line
    assert uids_at(smap, 6, 6) == (7,)
    assert uids_at(smap, 6, 37) == (8,)  # at "<AlwaysSuccess"
    node = smap.node_at(6, 40)
    assert node is not None and (node.line, node.column) == (6, 37)
    assert node.label == '<AlwaysSuccess name="ok">'


def test_a_start_tag_over_several_lines_counts_on_each() -> None:
    smap = mapped()
    first, second = smap.node_at(7), smap.node_at(8)
    assert first is not None and second is not None and first == second
    assert (first.line, first.column) == (7, 6)
    assert smap.uids(first.element) == (9,)


def test_places_of_uids() -> None:
    smap = mapped()
    assert smap.place(8) == (6, 37)
    assert smap.place(4) == smap.place(6) == (13, 4)
    assert smap.place(99) is None
    node = smap.node_at(16)
    assert node is not None and smap.uids(node.element) == ()  # Other does not run
    assert smap.tree_of(node.element) == "Other"


def test_columns_are_utf16() -> None:
    text = TEXT.replace('<Action ID="Work" name="work"/>', '<Action ID="Work" name="w😀"/>')
    xml = FULLTREE.replace('name="work"', 'name="w😀"')
    smap = mapped(text, xml)
    assert uids_at(smap, 6) == (7,)
    # "w😀" for "work": 3 UTF-16 code units (2 code points) for 4.
    assert smap.place(8) == (6, 36)


def test_where_the_text_differs_nothing_is_matched() -> None:
    # A renamed node: it stands for no running node; its siblings still match.
    renamed = mapped(TEXT.replace('name="ok"', 'name="fine"'))
    assert uids_at(renamed, 6, 37) == ()
    assert uids_at(renamed, 6) == (7,)
    # A node added to the Sequence since the executor started: it stands for none, and the
    # siblings around it keep theirs (the children are aligned, not paired by position).
    added = mapped(TEXT.replace('<Script code="x := 1"/>', '<Script code="x := 1"/><Sleep/>'))
    assert uids_at(added, 2) == (1,)
    assert uids_at(added, 3) == (2,)
    assert uids_at(added, 3, 30) == ()  # the <Sleep/> after the Script
    assert uids_at(added, 4) == (3,) and uids_at(added, 6) == (7,)
    assert uids_at(added, 13) == (4, 6)  # the subtree is matched on its own
    removed = mapped(TEXT.replace('<Script code="x := 1"/>', ""))
    assert uids_at(removed, 4) == (3,) and uids_at(removed, 6, 37) == (8,)
    retyped = mapped(TEXT.replace("AlwaysSuccess name", "AlwaysFailure name"))
    assert uids_at(retyped, 6, 37) == ()
    other_call = mapped(TEXT.replace('<SubTree ID="Sub" name="sub1"/>',
                                     '<SubTree ID="Other" name="sub1"/>'))  # fmt: skip
    assert uids_at(other_call, 4) == ()


def test_nothing_matches_before_a_tree_is_known_or_in_broken_text() -> None:
    smap = SourceMap(TEXT)
    assert uids_at(smap, 2) == ()
    smap.match(tree())
    assert uids_at(smap, 2) == (1,)
    smap.match(None)
    assert uids_at(smap, 2) == ()
    broken = mapped(TEXT[:300])  # cut inside the main tree
    assert isinstance(uids_at(broken, 2), tuple)
    assert SourceMap("").node_at(0) is None
    assert SourceMap("<<<>>>").node_at(0) is None


def test_show_values() -> None:
    assert show(None) == ("null", "null")
    assert show(True) == ("true", "bool")
    assert show(3) == ("3", "int")
    assert show(0.5) == ("0.5", "float")
    assert show(float("nan"))[0] == "nan"
    assert show("a\n") == ('"a\\n"', "string")
    assert show(b"\x01\x02") == ("bytes(2) 01 02", "bytes")
    assert show({"a": 1}) == ("{1 entries}", "map")
    assert show([1, 2]) == ("[2 items]", "array")
    assert len(show("x" * 10_000)[0]) == MAX_VALUE


def test_variables_expand_and_are_capped() -> None:
    refs = References()
    board = {"pose": {"x": 1.5, "y": [1, 2, 3]}, "n": 3, "empty": {}}
    top = children(board, refs)
    assert [v["name"] for v in top] == ["pose", "n", "empty"]
    assert top[1]["variablesReference"] == 0 and top[2]["variablesReference"] == 0
    pose = children(refs.get(top[0]["variablesReference"]), refs)
    assert pose[0] == {"name": "x", "value": "1.5", "type": "float", "variablesReference": 0}
    assert pose[1]["indexedVariables"] == 3
    ys = children(refs.get(pose[1]["variablesReference"]), refs, start=1, count=1)
    assert ys == [{"name": "[1]", "value": "2", "type": "int", "variablesReference": 0}]
    big = children(list(range(MAX_CHILDREN + 5)), refs)
    assert len(big) == MAX_CHILDREN + 1 and big[-1]["value"] == "5 more not shown"
    assert refs.get(0) is None and refs.get(10_000) is None
    refs.clear()
    assert refs.get(1) is None
    assert variable("k", [1], refs)["variablesReference"] == 1
