"""Authority of the nodes learned from C++, and when their registrations are all known.

``tests/data/cpp_app``: ``robot_app`` creates the factory and registers its nodes, and
every dependency that could register more is visible, so a node type it lacks is an error
(BehaviorTree.CPP fails with "Node not recognized"); ``robot_ext`` also depends on a
package that is nowhere to be found, so the same types are hints or warnings.  A node whose
port list could not be read completely stays advisory in both.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from bt_lsp.project.cpp_models import CppModels
from bt_lsp.project.cpp_scan import Scanner
from tests.pinned import main  # bt-lsp as the tests know it (tests/pinned.py)

WS = Path(__file__).parent / "data" / "cpp_app"
APP = WS / "src" / "robot_app"
EXT = WS / "src" / "robot_ext"

Finding = tuple[str, str, str]  # severity, code, message


@pytest.fixture(autouse=True)
def _cache(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    monkeypatch.delenv("AMENT_PREFIX_PATH", raising=False)


def _check(capsys: pytest.CaptureFixture[str], ws: Path, name: str) -> dict[int, Finding]:
    main(["check", str(ws)])
    out: dict[int, Finding] = {}
    for line in capsys.readouterr().out.splitlines():
        m = re.match(r"(.*?):(\d+):\d+: (\w+) ([\w-]+) (.*)", line)
        if m and m.group(1).endswith(name):
            out[int(m.group(2))] = (m.group(3), m.group(4), m.group(5))
    return out


def test_complete_registrations_make_unknown_nodes_errors(
    capsys: pytest.CaptureFixture[str],
) -> None:
    found = _check(capsys, WS, "app.xml")
    # <Dock station="A" speed="1.0"/>: BehaviorTree.CPP 4 throws at createTree.
    assert found[4] == (
        "error",
        "undeclared-port",
        "'Dock' declares no port 'speed' (registered in src/robot_app/src/main.cpp:21; ports: "
        "station, timeout); BehaviorTree.CPP refuses to create the tree: the attribute is not "
        "in the node's providedPorts()",
    )
    assert found[5][:2] == ("error", "invalid-port-value")
    assert "(a port of 'Dock', registered in src/robot_app/src/main.cpp:21)" in found[5][2]
    # A typo gets "did you mean" from the real catalog, and is an error.
    assert found[6][:2] == ("error", "unknown-node")
    assert "did you mean 'Charge'?" in found[6][2]
    assert 7 not in found  # <Charge until_percent="80"/>, registered by robot_lib
    # <Scan range="5"/>: Scan's port list is built by code: advisory.
    assert found[8][:2] == ("hint", "undeclared-port")
    assert "ports read: none" in found[8][2]
    # Only the tree file's own <TreeNodesModel> declares Ghost: not registered.
    assert found[9][:2] == ("error", "unknown-node")
    assert "not in the C++ of this package and of its dependencies" in found[9][2]
    assert found[10] == (
        "error",
        "unknown-node",
        "Node type 'Teleport' is not registered: it is not a built-in node, and the C++ of "
        "this package and of its dependencies registers no such node (BehaviorTree.CPP fails "
        "with 'Node not recognized')",
    )


def test_a_dependency_not_visible_keeps_unknown_nodes_advisory(
    capsys: pytest.CaptureFixture[str],
) -> None:
    found = _check(capsys, WS, "ext.xml")
    assert found[4][:2] == ("error", "undeclared-port")  # Dock itself is read completely
    # One typo away from a known C++ node: a warning; anything else a hint.
    assert found[6][:2] == ("warning", "unknown-node")
    assert "did you mean 'Charge'?" in found[6][2]
    assert found[10][0] == "hint"
    assert "(dependency vendor_nodes of robot_ext is not found)" in found[10][2]
    assert 9 not in found  # Ghost may be one of vendor_nodes' nodes


def _ws(tmp_path: Path, main_cpp: str, depends: str = "") -> Path:
    pkg = tmp_path / "ws" / "src" / "app"
    (pkg / "src").mkdir(parents=True)
    (pkg / "package.xml").write_text(
        "<package><name>app</name><depend>behaviortree_cpp</depend>"
        f"<depend>geometry_msgs</depend><exec_depend>ament_index_cpp</exec_depend>{depends}"
        "</package>"
    )
    (pkg / "src" / "main.cpp").write_text(
        "struct A : BT::SyncActionNode { static BT::PortsList providedPorts() { return {}; } };\n"
        + main_cpp
    )
    return pkg / "t.xml"


def _completeness(tree: Path, resolve=None):  # type: ignore[no-untyped-def]
    models = CppModels([tree.parents[2]], scanner=Scanner(None))
    files = models.files_for(tree)
    return models.completeness(tree, files, models.catalog(files), resolve)


FACTORY = 'int main() { BT::BehaviorTreeFactory f; f.registerNodeType<A>("A"); }\n'


def test_what_makes_the_registrations_all_known(tmp_path: Path) -> None:
    assert _completeness(_ws(tmp_path / "1", FACTORY)).complete
    # A plugin without the application: the trees run where bt-lsp does not look.
    plugin_cpp = 'BT_REGISTER_NODES(f) { f.registerNodeType<A>("A"); }'
    plugin = _completeness(_ws(tmp_path / "2", plugin_cpp))
    assert not plugin.complete and "creates a BehaviorTreeFactory" in plugin.why
    loads = 'void g() { f.registerFromPlugin("x.so"); }'
    dynamic = _completeness(_ws(tmp_path / "3", FACTORY + loads))
    assert not dynamic.complete and "loads node plugins chosen at run time" in dynamic.why
    reg = (
        "template <class T> void reg(BT::BehaviorTreeFactory& f, const char* name)"
        " { f.registerNodeType<T>(name); }\n"
    )
    # A helper of the project registers for its callers: each call names its node.
    called = _completeness(_ws(tmp_path / "4", FACTORY + reg + 'void g() { reg<A>(f, "B"); }'))
    assert called.complete
    helper = _completeness(_ws(tmp_path / "5", FACTORY + reg + "void g() { reg<A>(f, name); }"))
    assert not helper.complete and "is not known statically" in helper.why
    # No call read: it registers from code bt-lsp does not see.
    uncalled = _completeness(_ws(tmp_path / "6", FACTORY + reg))
    assert not uncalled.complete and "is not known statically" in uncalled.why


def test_dependencies_outside_the_workspace(tmp_path: Path) -> None:
    from bt_lsp.project.packages import Manifest

    tree = _ws(tmp_path, FACTORY, "<depend>nav_plugins</depend><depend>utils</depend>")
    none: tuple[Path, ...] = ()
    found = {
        "utils": (Manifest("utils", tmp_path, frozenset({"rclcpp"})), none),
        "nav_plugins": (Manifest("nav_plugins", tmp_path, frozenset({"behaviortree_cpp"})), none),
    }
    missing = _completeness(tree)
    assert not missing.complete and "nav_plugins" in missing.why
    no_catalog = _completeness(tree, lambda name: found[name])
    assert not no_catalog.complete
    assert "nav_plugins of app depends on BehaviorTree.CPP" in no_catalog.why
    catalog = tmp_path / "nav_plugins.xml"
    found["nav_plugins"] = (found["nav_plugins"][0], (catalog,))
    shipped = _completeness(tree, lambda name: found[name])
    assert shipped.complete and shipped.shipped == {str(catalog)}


def test_an_installed_dependency_counts_through_its_shipped_catalog(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    tree = _ws(tmp_path, FACTORY, "<depend>nav_plugins</depend>")
    tree.write_text(
        '<root BTCPP_format="4"><BehaviorTree ID="T"><Sequence>\n'
        '<Spin spin_dist="1.57"/>\n<A/>\n<Teleport/>\n'
        "</Sequence></BehaviorTree></root>\n"
    )
    share = tmp_path / "install" / "share" / "nav_plugins"
    share.mkdir(parents=True)
    (share / "package.xml").write_text(
        "<package><name>nav_plugins</name><depend>behaviortree_cpp</depend></package>"
    )
    (share / "nav_plugins.xml").write_text(
        '<root BTCPP_format="4"><TreeNodesModel><Action ID="Spin">'
        '<input_port name="spin_dist" type="double"/></Action></TreeNodesModel></root>'
    )
    monkeypatch.setenv("AMENT_PREFIX_PATH", str(tmp_path / "install"))
    found = _check(capsys, tree.parents[2], "t.xml")
    assert 2 not in found and 3 not in found  # Spin from the catalog, A from the C++
    assert found[4][:2] == ("error", "unknown-node")
    # Without the installed package, its nodes may be anything: not an error.
    monkeypatch.delenv("AMENT_PREFIX_PATH")
    found = _check(capsys, tree.parents[2], "t.xml")
    assert found[4][0] == "hint" and "nav_plugins of app is not found" in found[4][2]


def test_a_registering_macro_not_read_leaves_the_registrations_unknown(tmp_path: Path) -> None:
    read = "#define REG(T) f.registerNodeType<T>(#T);\n"
    assert _completeness(_ws(tmp_path / "1", read + FACTORY)).complete
    composed = "#define REG_NS(ns, Name) \\\n  f.registerNodeType<ns::Name>(#Name);\n"
    assert _completeness(_ws(tmp_path / "2", composed + FACTORY)).complete
    pasted = "#define REG_P(Name) \\\n  f.registerNodeType<Name##Node>(#Name);\n"
    found = _completeness(_ws(tmp_path / "3", pasted + FACTORY))
    assert not found.complete
    assert found.why == "macro REG_P of src/app/src/main.cpp registers nodes in a form not read"


_SLEEP_CPP = """#include <behaviortree_cpp_v3/bt_factory.h>

class Sleep : public BT::SyncActionNode
{
public:
  Sleep(const std::string& name, const BT::NodeConfiguration& config)
    : BT::SyncActionNode(name, config) {}
  static BT::PortsList providedPorts() { return { BT::InputPort<int>("ms", "How long") }; }
  BT::NodeStatus tick() override { return BT::NodeStatus::SUCCESS; }
};

int main()
{
  BT::BehaviorTreeFactory factory;
  factory.registerNodeType<Sleep>("Sleep");
  auto tree = factory.createTreeFromFile("trees/nap.xml");
  return 0;
}
"""


def test_a_v3_projects_own_sleep_is_its_c_plus_plus_node(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    """BehaviorTree.CPP 3.8 has no built-in ``Sleep`` (4.x does), so a v3 project's C++
    ``Sleep`` is the node its trees use, with the C++'s ports and authority."""
    pkg = tmp_path / "ws" / "src" / "napper"
    (pkg / "src").mkdir(parents=True)
    (pkg / "trees").mkdir()
    (pkg / "package.xml").write_text(
        '<?xml version="1.0"?>\n<package format="3"><name>napper</name><version>0.1.0</version>'
        "<description>d</description><maintainer email='a@b.c'>a</maintainer>"
        "<license>MIT</license><depend>behaviortree_cpp_v3</depend></package>\n"
    )
    (pkg / "src" / "main.cpp").write_text(_SLEEP_CPP)
    (pkg / "trees" / "nap.xml").write_text(
        '<root main_tree_to_execute="T">\n'
        '  <BehaviorTree ID="T">\n'
        '    <Sleep ms="5" msec="5"/>\n'
        "  </BehaviorTree>\n"
        "</root>\n"
    )
    found = _check(capsys, tmp_path / "ws", "nap.xml")
    # msec is 4.x's Sleep port, not the C++ node's: 3.8 refuses it at tree creation.
    assert set(found) == {3}
    severity, code, message = found[3]
    assert (severity, code) == ("error", "undeclared-port")
    assert "'Sleep' declares no port 'msec' (registered in src/napper/src/main.cpp:" in message


def test_a_catalogs_port_types_win_over_the_spelling_of_the_cpp(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Nav2 writes ``uint16`` in its catalog and ``ActionResult::_error_code_type`` in its
    C++: with the C++ read, the two spellings of one type must not make a mismatch."""
    nodes = (
        "struct Plan : BT::SyncActionNode { static BT::PortsList providedPorts() {\n"
        '  return { BT::OutputPort<ActionResult::_error_code_type>("error_code_id") }; } };\n'
        "struct Help : BT::ConditionNode { static BT::PortsList providedPorts() {\n"
        '  return { BT::InputPort<uint16_t>("error_code") }; } };\n'
        'int main() { BT::BehaviorTreeFactory f; f.registerNodeType<Plan>("Plan");\n'
        'f.registerNodeType<Help>("Help"); }\n'
    )
    tree = _ws(tmp_path, nodes)
    (tree.parent / "tree_nodes.xml").write_text(
        '<root BTCPP_format="4"><TreeNodesModel>'
        '<Action ID="Plan"><output_port name="error_code_id" type="uint16_t"/></Action>'
        "</TreeNodesModel></root>\n"
    )
    tree.write_text(
        '<root BTCPP_format="4"><BehaviorTree ID="T"><Sequence>\n'
        '<Plan error_code_id="{code}"/>\n<Help error_code="{code}"/>\n'
        "</Sequence></BehaviorTree></root>\n"
    )
    found = _check(capsys, tree.parents[2], "t.xml")
    assert not [f for f in found.values() if f[1] == "blackboard-type-mismatch"]


def test_an_id_two_classes_register_has_no_authoritative_port_list(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Two programs register their own ``Takeoff`` (one of them not built): a catalog
    exported from one says what that program registered, not what the program that
    loads this tree does, so a port it lacks is a hint."""
    tree = _ws(tmp_path, FACTORY)
    src = tree.parent / "src"
    (src / "takeoff.cpp").write_text(
        "struct Takeoff : BT::SyncActionNode { static BT::PortsList providedPorts() "
        '{ return { BT::InputPort<double>("goal") }; } };\n'
        'void reg(BT::BehaviorTreeFactory& f) { f.registerNodeType<Takeoff>("Takeoff"); }\n'
    )
    (src / "old_mission.cpp").write_text(
        "struct Takeoff : BT::SyncActionNode { static BT::PortsList providedPorts() "
        '{ return { BT::InputPort<double>("takeoff_target") }; } };\n'
        'void old(BT::BehaviorTreeFactory& f) { f.registerNodeType<Takeoff>("Takeoff"); }\n'
    )
    (tree.parent / "all_nodes.xml").write_text(
        '<root BTCPP_format="4"><TreeNodesModel>'
        '<Action ID="Takeoff"><input_port name="goal" type="double"/></Action>'
        "</TreeNodesModel></root>\n"
    )
    tree.write_text(
        '<root BTCPP_format="4"><BehaviorTree ID="T"><Sequence>\n'
        '<Takeoff speed="1"/>\n'
        '<SubTree ID="Takeoff"/>\n'
        "</Sequence></BehaviorTree></root>\n"
    )
    found = _check(capsys, tree.parents[2], "t.xml")
    assert found[2][:2] == ("hint", "undeclared-port")
    # Which ports are not known, but the ID is registered: VerifyXML refuses the name.
    assert found[3][:2] == ("error", "registered-name-as-tree-id")
    assert "registered in src/app/src/old_mission.cpp:2" in found[3][2]


def test_a_node_only_a_source_file_not_built_registers(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The CMake lists its targets' sources and not ``old.cpp``: its node is a node of no
    program built, so its name as a tree ID is a hint that says so."""
    tree = _ws(tmp_path, FACTORY)
    pkg = tree.parent
    (pkg / "CMakeLists.txt").write_text("project(app)\nadd_executable(app src/main.cpp)\n")
    (pkg / "src" / "old.cpp").write_text(
        "struct Old : BT::SyncActionNode { static BT::PortsList providedPorts() "
        "{ return {}; } };\n"
        'int main() { BT::BehaviorTreeFactory f; f.registerNodeType<Old>("Old"); }\n'
    )
    tree.write_text(
        '<root BTCPP_format="4" main_tree_to_execute="Old">\n'
        '<BehaviorTree ID="Old"><Old/></BehaviorTree></root>\n'
    )
    found = _check(capsys, tree.parents[2], "t.xml")
    assert found[2] == (
        "hint",
        "registered-name-as-tree-id",
        "'Old' is a node type registered in src/app/src/old.cpp:2 (not built); "
        "BehaviorTree.CPP refuses a <BehaviorTree> ID that names a registered node, if the "
        "program that loads this file registers it",
    )
