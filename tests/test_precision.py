"""False alarms that real projects met: type aliases bt-lsp cannot see, checks of one
BehaviorTree.CPP version applied to another, and an author's models read as the truth."""

from __future__ import annotations

from pathlib import Path

import pytest

from bt_lsp.project.index import ProjectIndex
from bt_lsp.rules import semantics
from bt_lsp.rules.codes import Severity
from bt_lsp.rules.context import Context
from bt_lsp.rules.decls import ModelDecl
from bt_lsp.rules.port_types import canonical, is_closed
from bt_lsp.syntax.document import Document
from tests.pinned import pinned

E, W, H = Severity.ERROR, Severity.WARNING, Severity.HINT


def found(doc: Document, ctx: Context) -> list[tuple[str, Severity]]:
    return sorted((d.code, d.severity) for d in pinned(semantics.check(doc, ctx)))


def write(path: Path, text: str) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text, encoding="utf-8")
    return path


def manifest(name: str, *depends: str) -> str:
    deps = "".join(f"<depend>{d}</depend>" for d in depends)
    return f'<?xml version="1.0"?><package format="3"><name>{name}</name>{deps}</package>'


def with_models(body: str, models: str, root: str = 'BTCPP_format="4"') -> str:
    return (
        f'<root {root} main_tree_to_execute="Main"><BehaviorTree ID="Main">{body}'
        f"</BehaviorTree><TreeNodesModel>{models}</TreeNodesModel></root>"
    )


def catalog_ctx(doc: Document, models: str, version: str | None = "4") -> Context:
    """``doc`` with ``models`` as an authoritative catalog learned from C++ (``where``)."""
    cat = Document(f'<root BTCPP_format="4"><TreeNodesModel>{models}</TreeNodesModel></root>')
    ctx = Context.combine(
        doc, [], model_files=[("/w/nodes.xml", cat)], btcpp_version=version, path="/w/t.xml"
    )
    # Models read from C++ say where they are registered: their types are as written.
    cpp = {
        k: m._replace(where="src/nodes.cpp:1") if isinstance(m, ModelDecl) else m
        for k, m in ctx.models.items()
    }
    return Context(
        path=ctx.path,
        models=cpp,
        trees=ctx.trees,
        btcpp_version=version,
        workspace_has_custom_models=True,
    )


# --- types ----------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("a", "b"),
    [
        ("std::string", "string"),
        ("int", "int32_t"),
        ("std::int32_t", "const int&"),
        ("unsigned", "unsigned int"),
        ("std::vector<double>", "std::vector< double >"),
        ("geometry_msgs::msg::Pose::SharedPtr", "std::shared_ptr<geometry_msgs::msg::Pose>"),
        ("geometry_msgs::msg::Pose_<std::allocator<void> >", "geometry_msgs::msg::Pose"),
        ("std::size_t", "uint64_t"),
    ],
)
def test_spellings_of_one_type_are_one(a: str, b: str) -> None:
    assert canonical(a) == canonical(b)


def test_only_names_that_cannot_be_aliases_are_closed() -> None:
    assert canonical("double") != canonical("float")
    assert is_closed(canonical("std::shared_ptr<geometry_msgs::msg::Pose>") or "")
    assert not is_closed(canonical("moveit::task_constructor::TaskPtr") or "")
    assert not is_closed(canonical("PoseStamped") or "")


MTC = (
    '<Action ID="Task"><output_port name="task" type="moveit::task_constructor::TaskPtr"/>'
    "</Action>"
    '<Action ID="Plan"><input_port name="task" '
    'type="std::shared_ptr&lt;moveit::task_constructor::Task&gt;"/></Action>'
    '<Action ID="Pub"><input_port name="pose" type="PoseStamped"/></Action>'
    '<Action ID="Make"><output_port name="pose" type="geometry_msgs::msg::PoseStamped"/>'
    "</Action>"
    '<Action ID="Count"><output_port name="n" type="int"/></Action>'
    '<Action ID="Say"><input_port name="text" type="std::string"/></Action>'
    '<Action ID="Half"><input_port name="x" type="float"/></Action>'
    '<Action ID="Wide"><input_port name="n" type="int32_t"/></Action>'
)


def test_an_alias_bt_lsp_cannot_resolve_proves_nothing() -> None:
    # TaskPtr comes from MOVEIT_CLASS_FORWARD in a header outside the project.
    doc = Document(
        with_models(
            '<Sequence><Task task="{t}"/><Plan task="{t}"/>'
            '<Make pose="{p}"/><Pub pose="{p}"/><Count n="{n}"/><Wide n="{n}"/></Sequence>',
            "",
        )
    )
    assert found(doc, catalog_ctx(doc, MTC)) == []


def test_known_types_that_differ_still_mismatch() -> None:
    doc = Document(
        with_models(
            '<Sequence><Count n="{n}"/><Say text="{n}"/><Count n="{m}"/><Half x="{m}"/></Sequence>',
            "",
        )
    )
    assert found(doc, catalog_ctx(doc, MTC)) == [
        ("blackboard-type-mismatch", E),
        ("blackboard-type-mismatch", E),
    ]


# --- versions -------------------------------------------------------------------------------


def test_v3_empty_value_is_not_given_and_v3_converts_only_when_read() -> None:
    models = '<Action ID="Go"><input_port name="side" type="int" default="0"/></Action>'
    doc = Document(with_models('<Go side=""/>', "", root=""))
    assert found(doc, catalog_ctx(doc, models, "3")) == []
    doc = Document(with_models('<Go side="left"/>', "", root=""))
    assert found(doc, catalog_ctx(doc, models, "3")) == [("invalid-port-value", H)]
    doc = Document(with_models('<Go side="left"/>', ""))
    assert found(doc, catalog_ctx(doc, models, "4")) == [("invalid-port-value", E)]


def test_duplicate_subtree_name_is_a_warning_and_not_for_v3() -> None:
    text = (
        '<root {root} main_tree_to_execute="Main"><BehaviorTree ID="Main"><Sequence>'
        '<SubTree ID="Sub" name="s"/><SubTree ID="Sub" name="s"/></Sequence></BehaviorTree>'
        '<BehaviorTree ID="Sub"><AlwaysSuccess/></BehaviorTree></root>'
    )
    doc = Document(text.format(root='BTCPP_format="4"'))
    diags = pinned(semantics.check(doc, Context.from_document(doc)))
    assert [(d.code, d.severity) for d in diags] == [("duplicate-subtree-name", W)]
    assert "January 2026" in diags[0].message
    doc = Document(text.format(root=""))
    assert found(doc, Context.combine(doc, [], btcpp_version="3")) == []


def test_missing_format_names_the_version() -> None:
    doc = Document(
        '<root main_tree_to_execute="T"><BehaviorTree ID="T"><AlwaysSuccess/></BehaviorTree></root>'
    )
    v4 = pinned(semantics.check(doc, Context.combine(doc, [], btcpp_version="4")))
    assert [(d.code, d.severity) for d in v4] == [("missing-format", W)]
    assert "BehaviorTree.CPP 4 loads the file and prints a warning" in v4[0].message
    unknown = semantics.check(doc, Context.combine(doc, [], btcpp_version=None))
    assert "version was not detected" in unknown[0].message
    assert found(doc, Context.combine(doc, [], btcpp_version="3")) == []


def test_a_package_gets_the_version_of_the_package_it_depends_on(tmp_path: Path) -> None:
    write(tmp_path / "lib" / "package.xml", manifest("lib", "behaviortree_cpp_v3"))
    write(tmp_path / "tutorials" / "package.xml", manifest("tutorials", "lib"))
    tree = write(
        tmp_path / "tutorials" / "config" / "t.xml",
        '<root main_tree_to_execute="T"><BehaviorTree ID="T"><AlwaysSuccess/></BehaviorTree>'
        "</root>",
    )
    ws = ProjectIndex([tmp_path])
    assert ws.btcpp_for(tree).version == "3"
    doc = ws.document(tree)
    assert doc is not None
    assert found(doc, ws.context_for(tree, doc)) == []  # no missing-format for a v3 package


# --- an author's models ---------------------------------------------------------------------


def test_editable_is_not_a_port() -> None:
    doc = Document(
        with_models(
            '<Go x="1"/>',
            '<Action ID="Go" editable="true"><input_port name="x"/></Action>',
        )
    )
    assert found(doc, Context.from_document(doc)) == []
    assert Context.from_document(doc).models["Go"].port("editable") is None


def test_an_authors_model_makes_an_undeclared_port_a_hint() -> None:
    doc = Document(
        with_models('<Say msg1="hi"/>', '<Action ID="Say"><input_port name="msg"/></Action>')
    )
    assert found(doc, Context.from_document(doc)) == [
        ("missing-port-without-default", H),
        ("undeclared-port", H),
    ]


def test_a_subtree_model_without_ports_says_nothing_of_them() -> None:
    doc = Document(
        '<root BTCPP_format="4" main_tree_to_execute="Main"><BehaviorTree ID="Main">'
        '<SubTree ID="planner" goal="{g}"/></BehaviorTree>'
        '<BehaviorTree ID="planner"><AlwaysSuccess/></BehaviorTree>'
        '<TreeNodesModel><SubTree ID="planner"/></TreeNodesModel></root>'
    )
    assert found(doc, Context.from_document(doc)) == [("undeclared-port", H)]


def test_another_packages_models_do_not_apply(tmp_path: Path) -> None:
    # A robot's own FollowPath model must not decide about Nav2's FollowPath.
    write(tmp_path / "robot" / "package.xml", manifest("robot", "behaviortree_cpp"))
    write(tmp_path / "nav" / "package.xml", manifest("nav", "behaviortree_cpp"))
    write(
        tmp_path / "robot" / "trees" / "r.xml",
        '<root BTCPP_format="4"><BehaviorTree ID="R"><FollowPath speed="1"/></BehaviorTree>'
        '<TreeNodesModel><Action ID="FollowPath"><input_port name="speed"/></Action>'
        "</TreeNodesModel></root>",
    )
    nav = write(
        tmp_path / "nav" / "trees" / "n.xml",
        '<root BTCPP_format="4"><BehaviorTree ID="N"><FollowPath path="{p}"/></BehaviorTree>'
        "</root>",
    )
    ws = ProjectIndex([tmp_path])
    doc = ws.document(nav)
    assert doc is not None
    ctx = ws.context_for(nav, doc)
    assert "FollowPath" not in ctx.models
    assert ("undeclared-port", H) not in found(doc, ctx)
    # A package that depends on the robot package sees its models.
    write(tmp_path / "nav" / "package.xml", manifest("nav", "behaviortree_cpp", "robot"))
    ws = ProjectIndex([tmp_path])
    doc = ws.document(nav)
    assert doc is not None
    assert "FollowPath" in ws.context_for(nav, doc).models


# --- placeholders ----------------------------------------------------------------------------


def test_a_placeholder_replaced_before_loading_is_not_converted() -> None:
    """PlanSys2 fills `${arg}` in its action trees, launch files `$(arg x)`, before
    BehaviorTree.CPP reads the text: such a value is not a literal of the port's type."""
    models = '<Action ID="Go"><input_port name="n" type="int"/></Action>'
    for value, codes in (
        ("${goal_reached}", []),
        ("$(arg count)", []),
        ("many", [("invalid-port-value", E)]),
    ):
        doc = Document(with_models(f'<Go n="{value}"/>', ""))
        assert found(doc, catalog_ctx(doc, models)) == codes, value
