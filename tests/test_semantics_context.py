"""The workspace context of one document: what documents declare and how they combine."""

from __future__ import annotations

import dataclasses

import pytest

from bt_lsp.rules.builtins import PortModel
from bt_lsp.rules.context import Context, ModelDecl, TreeDecl, facts_of
from bt_lsp.syntax.document import Document

MAIN = """<root BTCPP_format="4" main_tree_to_execute="Main">
  <BehaviorTree ID="Main">
    <Sequence>
      <SubTree ID="Dock"/>
      <Fallback><SubTree ID="Charge"/><SubTree ID=""/></Fallback>
    </Sequence>
  </BehaviorTree>
  <BehaviorTree><AlwaysSuccess/></BehaviorTree>
  <TreeNodesModel>
    <Action ID="MoveBase">
      <input_port name="goal" type="Pose">Where to go</input_port>
      <output_port name="result"/>
      <MetadataFields><Metadata subcategory="nav"/></MetadataFields>
      <inout_port name="state" default="idle"/>
    </Action>
    <Condition ID="Old" message="hello"/>
    <Action ID="Sequence"/>
    <SubTree ID="Dock"><input_port name="target"/></SubTree>
    <Unknown ID="Skipped"/>
  </TreeNodesModel>
</root>
"""


def test_facts_of_a_document() -> None:
    doc = Document(MAIN, "/w/main.xml")
    facts = facts_of(doc)
    assert facts.path == "/w/main.xml"
    (main,) = facts.trees  # a tree without ID is not part of the namespace
    assert main.id == "Main" and MAIN[main.start : main.end] == "Main"
    assert main.calls == ("Dock", "Charge")
    assert [MAIN[s:e] for s, e in main.call_spans] == ["Dock", "Charge"]
    assert [m.id for m in facts.models] == ["MoveBase", "Old", "Sequence"]
    move = facts.models[0]
    assert move.category == "Action" and MAIN[move.start : move.end] == "MoveBase"
    assert move.ports == (
        PortModel("goal", "input", "Pose", None, "Where to go"),
        PortModel("result", "output", "", None, ""),
        PortModel("state", "inout", "", "idle", ""),
    )
    assert move.port("state") is not None and move.port("nope") is None
    # The attribute form of very old models: each attribute a port with that default.
    assert facts.models[1].ports == (PortModel("message", "input", "", "hello", ""),)
    assert [m.id for m in facts.subtree_models] == ["Dock"]
    assert facts_of(doc) is facts  # cached while the model is the same
    doc.edit(0, 0, " ")
    assert facts_of(doc) is not facts


def test_from_document() -> None:
    doc = Document(MAIN)
    ctx = Context.from_document(doc, "/w/main.xml")
    assert ctx.path == "/w/main.xml"
    assert set(ctx.models) == {"MoveBase", "Old"}  # a built-in ID is never a custom model
    assert set(ctx.subtree_models) == {"Dock"}
    assert set(ctx.trees) == {"Main"} and ctx.workspace_trees == {}
    assert not ctx.workspace_has_custom_models
    assert ctx.is_own(ctx.trees["Main"][0])
    with pytest.raises(dataclasses.FrozenInstanceError):
        ctx.path = "x"  # type: ignore[misc]


def test_child_range_by_category() -> None:
    def decl(cat: str) -> ModelDecl:
        return ModelDecl("X", cat, (), None, 0, 1)  # type: ignore[arg-type]

    assert decl("Action").child_range == (0, 0)
    assert decl("Condition").child_range == (0, 0)
    assert decl("Decorator").child_range == (1, 1)
    assert decl("Control").child_range == (1, None)


def test_combine() -> None:
    own = Document(
        '<root BTCPP_format="4"><include path="a.xml"/>'
        '<BehaviorTree ID="Main"><SubTree ID="A"/></BehaviorTree>'
        '<TreeNodesModel><Action ID="Mine"/><Action ID="Both"/></TreeNodesModel>'
        "</root>"
    )
    a = Document(
        '<root BTCPP_format="4"><BehaviorTree ID="A"><AlwaysSuccess/></BehaviorTree>'
        '<BehaviorTree ID="Main"><AlwaysSuccess/></BehaviorTree>'
        '<TreeNodesModel><Condition ID="Both"/><SubTree ID="A"/></TreeNodesModel></root>'
    )
    b = Document(
        '<root BTCPP_format="4"><BehaviorTree ID="B"><AlwaysSuccess/></BehaviorTree>'
        '<TreeNodesModel><Action ID="FromB"/></TreeNodesModel></root>'
    )
    catalog = Document(
        '<root BTCPP_format="4"><TreeNodesModel><Action ID="Cat"/></TreeNodesModel></root>'
    )
    ctx = Context.combine(
        own,
        [("/w/a.xml", a, True), ("/w/b.xml", b, False), ("/w/main.xml", own, True)],
        path="/w/main.xml",
        model_files=[("/w/models.xml", catalog)],
        ros_pkg_paths={"pkg": "/opt/pkg"},
        included_by=["/w/top.xml"],
    )
    assert set(ctx.models) == {"Mine", "Both", "FromB", "Cat"}
    assert ctx.models["Both"].category == "Action"  # this document's declaration first
    assert ctx.models["Cat"].path == "/w/models.xml"
    assert set(ctx.trees) == {"Main", "A"}
    # Load order: included documents first, this document last.
    assert [t.path for t in ctx.trees["Main"]] == ["/w/a.xml", "/w/main.xml"]
    assert set(ctx.workspace_trees) == {"B"}
    assert ctx.workspace_has_custom_models
    assert ctx.ros_pkg_paths == {"pkg": "/opt/pkg"}
    assert ctx.included_by == ("/w/top.xml",)
    assert not ctx.is_own(ctx.trees["A"][0])
    forced = Context.combine(own, [], workspace_has_custom_models=True)
    assert forced.workspace_has_custom_models


def test_tree_decl_defaults() -> None:
    t = TreeDecl("X", None, 0, 1)
    assert t.calls == () and t.call_spans == ()


def test_port_description_written_as_text() -> None:
    """BehaviorTree.CPP and Groot2 write a port's description as the element's text."""
    doc = Document(
        '<root BTCPP_format="4"><TreeNodesModel><Action ID="Move">\n'
        '<input_port name="goal" type="Pose">Where &amp; how\n   far <![CDATA[<x>]]>'
        "<!-- not this --></input_port>\n"
        '<input_port name="speed" description="attr wins">text</input_port>\n'
        '<output_port name="done"/><inout_port name="empty">  </inout_port>\n'
        "</Action></TreeNodesModel></root>"
    )
    ports = {p.name: p.description for p in facts_of(doc).models[0].ports}
    assert ports == {
        "goal": "Where & how far <x>",
        "speed": "attr wins",
        "done": "",
        "empty": "",
    }
    # The description follows edits of the text (the section is rebuilt).
    at = doc.text.index("Where")
    doc.edit(at, at + 5, "When")
    assert facts_of(doc).models[0].ports[0].description == "When & how far <x>"
