"""Node catalogs with authority: where a model comes from decides what a finding is worth.

A catalog that says what BehaviorTree.CPP registers (a file named in the settings or with
``--models``, a workspace file that is nothing but an exported ``<TreeNodesModel>``) makes
what BehaviorTree.CPP would throw for an error; a ``<TreeNodesModel>`` inside a tree file
or a Groot2 palette is advisory (a warning at most), and what rests on code nobody can see
is a hint.
"""

from __future__ import annotations

import io
import json
from pathlib import Path

import pytest

from bt_lsp.cli import check
from bt_lsp.ide.completion import complete
from bt_lsp.ide.hover import hover_at
from bt_lsp.rules import semantics
from bt_lsp.rules.codes import Severity
from bt_lsp.rules.context import Context, is_generated_catalog
from bt_lsp.syntax.document import Document
from tests.pinned import later_severities, main, pinned  # bt-lsp as the tests know it

E, W, H = Severity.ERROR, Severity.WARNING, Severity.HINT
DATA = Path(__file__).parent / "data"
CATALOG = DATA / "catalogs" / "robot_nodes.xml"


def R(children: str) -> str:
    return f'<root BTCPP_format="4">\n{children}\n</root>\n'


def T(body: str, extra: str = "") -> str:
    return R(f'<BehaviorTree ID="Main">\n{body}\n</BehaviorTree>\n{extra}')


def catalog() -> tuple[str, Document]:
    return str(CATALOG), Document(CATALOG.read_text(encoding="utf-8"), str(CATALOG))


def found(text: str, **kw: object) -> list[tuple[str, Severity, str]]:
    doc = Document(text, "/w/tree.xml")
    ctx = Context.combine(doc, [], path="/w/tree.xml", **kw)  # type: ignore[arg-type]
    return [(d.code, d.severity, d.message) for d in pinned(semantics.check(doc, ctx))]


def codes(text: str, **kw: object) -> list[tuple[str, Severity]]:
    return [(c, s) for c, s, _ in found(text, **kw)]


OWN_MODEL = (
    '<TreeNodesModel><Action ID="MoveBase"><input_port name="goal"/></Action>'
    '<Action ID="OnlyHere"/></TreeNodesModel>'
)


def test_models_carry_their_source_and_authority() -> None:
    doc = Document(T("<MoveBase goal='1'/><OnlyHere/>", OWN_MODEL), "/w/tree.xml")
    ctx = Context.combine(doc, [], path="/w/tree.xml", model_files=[catalog()])
    move, only = ctx.models["MoveBase"], ctx.models["OnlyHere"]
    # The catalog's model wins over the tree file's own entry.
    assert (move.source, move.authoritative, move.path) == ("catalog", True, str(CATALOG))
    assert len(move.ports) == 2
    assert (only.source, only.authoritative, only.path) == ("tree", False, "/w/tree.xml")
    assert ctx.workspace_has_custom_models


def test_a_node_only_the_tree_file_declares_is_unregistered_with_a_catalog() -> None:
    text = T("<Sequence><OnlyHere/><MoveBase goal='1'/></Sequence>", OWN_MODEL)
    got = found(text, model_files=[catalog()])
    assert [(c, s) for c, s, _ in got] == [("unknown-node", E)]
    assert "only the <TreeNodesModel> of this document declares it" in got[0][2]
    # Without a catalog the same tree is fine: the tree file's model is all there is.
    assert codes(text) == []


def test_an_empty_catalog_still_says_nothing_custom_is_registered() -> None:
    empty = Document(R("<TreeNodesModel/>"), "/w/empty.xml")
    assert codes(T("<Whatever/>"), model_files=[("/w/empty.xml", empty)]) == [("unknown-node", E)]
    assert codes(T("<Whatever/>")) == [("unknown-node", H)]


@pytest.mark.parametrize(
    ("body", "code", "advisory"),
    [
        # An author's model: BehaviorTree.CPP reads the C++ registration, not it.
        ('<MoveBase goal="1" gaol="2"/>', "undeclared-port", [("undeclared-port", H)]),
        (
            '<MoveBase goal="1" speed="fast"/>',
            "invalid-port-value",
            [("invalid-port-value", W)],
        ),
        # `Pose` and `Cat::Ptr` as an author wrote them may be aliases: nothing proven.
        (
            '<Sequence><SpawnCat cat="{c}"/><MoveBase goal="{c}"/></Sequence>',
            "blackboard-type-mismatch",
            [],
        ),
    ],
)
def test_catalog_findings_are_errors_and_advisory_ones_less(
    body: str, code: str, advisory: list[tuple[str, Severity]]
) -> None:
    assert codes(T(body), model_files=[catalog()]) == [(code, E)]
    # The same models, written in the tree file's own <TreeNodesModel>: advisory.
    own = CATALOG.read_text(encoding="utf-8").split('<root BTCPP_format="4">')[1]
    own = own.rsplit("</root>", 1)[0]
    assert codes(T(body, own)) == advisory


def test_registered_name_as_tree_id_is_an_error_against_a_catalog() -> None:
    text = R(
        '<BehaviorTree ID="BatteryLow"><AlwaysSuccess/></BehaviorTree>'
        '<BehaviorTree ID="Main"><SubTree ID="BatteryLow"/></BehaviorTree>'
    ).replace("<root ", '<root main_tree_to_execute="Main" ')
    assert codes(text, model_files=[catalog()]) == [
        ("registered-name-as-tree-id", E),
        ("registered-name-as-tree-id", E),
    ]
    own = R(
        '<BehaviorTree ID="BatteryLow"><AlwaysSuccess/></BehaviorTree>'
        '<TreeNodesModel><Condition ID="BatteryLow"/></TreeNodesModel>'
    )
    assert codes(own) == [("registered-name-as-tree-id", H)]


def test_missing_port_of_a_custom_node_is_a_hint_that_says_why() -> None:
    got = found(T("<MoveBase/>"), model_files=[catalog()])
    assert [(c, s) for c, s, _ in got] == [("missing-port-without-default", H)]
    assert "does not check ports when it loads or creates the tree" in got[0][2]
    assert "may be optional in the node's code" in got[0][2]
    # A built-in whose C++ throws keeps its error.
    assert codes(T("<Sleep/>")) == [("missing-required-port", E)]


def test_shared_pointers_of_two_classes_depend_on_registered_casts() -> None:
    upcast = T('<Sequence><SpawnCat cat="{pet}"/><FeedAnimal animal="{pet}"/></Sequence>')
    got = found(upcast, model_files=[catalog()])
    assert [(c, s) for c, s, _ in got] == [("blackboard-type-mismatch", H)]
    assert "registerPolymorphicCast" in got[0][2]
    # An inout port takes no cast: BehaviorTree.CPP refuses to create the tree.
    inout = T('<Sequence><SpawnCat cat="{pet}"/><GroomAnimal animal="{pet}"/></Sequence>')
    assert codes(inout, model_files=[catalog()]) == [("blackboard-type-mismatch", E)]


def test_unknown_attribute_says_what_btcpp_does_with_it() -> None:
    got = found(T('<AlwaysSuccess _color="red"/>'))
    assert [(c, s) for c, s, _ in got] == [("unknown-attribute", H)]
    assert "other_attributes" in got[0][2]
    assert codes(T('<AlwaysSuccess _skipif="x"/>')) == [("unknown-attribute", W)]


def test_a_node_one_typo_from_a_known_one_is_a_warning() -> None:
    own = '<TreeNodesModel><Action ID="NavigateTo"/></TreeNodesModel>'
    got = found(T("<NavigateTp/>", own))
    assert [(c, s) for c, s, _ in got] == [("unknown-node", W)]
    assert "did you mean 'NavigateTo'" in got[0][2]
    assert codes(T("<SomethingElse/>", own)) == [("unknown-node", H)]


def test_which_files_read_as_an_exported_catalog() -> None:
    assert is_generated_catalog(Document(CATALOG.read_text(encoding="utf-8")))
    for text in (
        R("<!-- kept by hand -->\n<TreeNodesModel><Action ID='A'/></TreeNodesModel>"),
        R("<TreeNodesModel/>\n<BehaviorTree ID='T'><AlwaysSuccess/></BehaviorTree>"),
        "<root><TreeNodesModel><Action ID='A'/></TreeNodesModel></root>",
    ):
        assert not is_generated_catalog(Document(text)), text


def test_an_exported_catalog_in_the_workspace_is_authoritative_but_not_complete() -> None:
    path, cat = catalog()
    text = T('<Sequence><MoveBase goal="1" gaol="2"/><Other/></Sequence>')
    doc = Document(text, "/w/tree.xml")
    ctx = Context.combine(doc, [(path, cat, False)], path="/w/tree.xml")
    assert ctx.models["MoveBase"].source == "generated"
    assert not ctx.workspace_has_custom_models
    got = [(d.code, d.severity) for d in semantics.check(doc, ctx)]
    assert got == [("undeclared-port", E), ("unknown-node", H)]


def test_a_palette_is_advisory() -> None:
    palette = Document(
        '<root BTCPP_format="4"><TreeNodesModel><Action ID="MoveBase">'
        '<input_port name="goal"/></Action></TreeNodesModel></root>',
        "/w/project.btproj",
    )
    text = T('<MoveBase goal="1" gaol="2"/>')
    assert codes(text, model_files=[("/w/project.btproj", palette)]) == [("undeclared-port", H)]


def test_hover_and_completion_say_where_a_model_came_from() -> None:
    text = T("<MoveBase goal='1'/>")
    doc = Document(text, "/w/tree.xml")
    ctx = Context.combine(doc, [], path="/w/tree.xml", model_files=[catalog()])
    h = hover_at(doc, text.index("MoveBase") + 2, ctx)
    assert h is not None
    assert "a node catalog named in the settings (authoritative)" in h.text
    assert "- `goal`: input, `Pose`, no default" in h.text
    assert "required" not in h.text
    offset = text.index("<MoveBase") + 1
    completions = complete(doc, offset, ctx)
    assert completions is not None
    items = {i.label: i for i in completions.items}
    assert items["MoveBase"].detail == "Action (node catalog)"
    assert "(authoritative)" in (items["MoveBase"].documentation or "")


def test_unknown_subtree_says_where_it_looked() -> None:
    doc = Document(T('<SubTree ID="Nowhere"/>'), "/w/main.xml")
    lib = Document(R('<BehaviorTree ID="Lib"><AlwaysSuccess/></BehaviorTree>'), "/w/lib.xml")
    other = Document(R('<BehaviorTree ID="X"><AlwaysSuccess/></BehaviorTree>'), "/w/x.xml")
    ctx = Context.combine(
        doc, [("/w/lib.xml", lib, True), ("/w/x.xml", other, False)], path="/w/main.xml"
    )
    (d,) = semantics.check(doc, ctx)
    assert d.code == "unknown-subtree"
    assert "in this document, in the 1 file it includes (lib.xml)" in d.message
    assert "the 1 other BehaviorTree.CPP file of the workspace" in d.message


def test_cli_models_flag_makes_the_catalog_authoritative(tmp_path: Path) -> None:
    (tmp_path / "tree.xml").write_text(T('<MoveBase goal="1" gaol="2"/>'), encoding="utf-8")
    out, err = io.StringIO(), io.StringIO()
    opts = check.Options(format="json", progress=False, severities=later_severities())
    assert check.run([str(tmp_path)], opts, out, err) == 0  # nothing known: no error
    assert [(d["code"], d["severity"]) for d in json.loads(out.getvalue())] == [
        ("unknown-node", "hint")
    ]
    out = io.StringIO()
    opts = check.Options(
        format="json", progress=False, models=(str(CATALOG),), severities=later_severities()
    )
    assert check.run([str(tmp_path)], opts, out, err) == 1
    (d,) = json.loads(out.getvalue())
    assert (d["code"], d["severity"]) == ("undeclared-port", "error")
    assert main(["check", str(tmp_path), "--models", str(CATALOG), "--no-progress"]) == 1
