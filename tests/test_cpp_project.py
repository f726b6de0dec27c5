"""A colcon workspace whose nodes are registered in C++: checked through the CLI.

``robot_nodes`` registers its nodes in ``src/``, declares them in ``include/`` and derives
one from a base of ``robot_base`` (a dependency in ``package.xml``); ``other_nodes`` is no
dependency, so its node is not visible to ``robot_nodes``' trees; ``build/`` is never read.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

from bt_lsp.project.cpp_models import CppModels
from bt_lsp.project.cpp_scan import Scanner
from tests.pinned import main  # bt-lsp as the tests know it (tests/pinned.py)

WS = Path(__file__).parent / "data" / "cpp_project"
MAIN = WS / "src" / "robot_nodes" / "trees" / "main.xml"


@pytest.fixture(autouse=True)
def _cache(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))


def _findings(capsys: pytest.CaptureFixture[str], *args: str) -> list[tuple[int, str, str, str]]:
    main(["check", *args, str(WS)])
    out = []
    for line in capsys.readouterr().out.splitlines():
        m = re.match(r"(.*?):(\d+):\d+: (\w+) ([\w-]+) (.*)", line)
        if m and m.group(1).endswith("main.xml"):
            out.append((int(m.group(2)), m.group(3), m.group(4), m.group(5)))
    return out


def test_check_learns_the_catalog_from_the_packages_cpp(capsys: pytest.CaptureFixture[str]) -> None:
    found = _findings(capsys)
    by_line = {line: (sev, code, msg) for line, sev, code, msg in found}
    # <BatteryOk min_percent="lots"/>: an int port read from include/robot_nodes/nodes.hpp.
    sev, code, msg = by_line[4]
    assert code == "invalid-port-value" and "int" in msg and sev != "hint"
    # <DriveTo speed="1.0"/>: ports from DriveTo and its base in another package.
    sev, code, msg = by_line[5]
    assert code == "undeclared-port" and "'speed'" in msg
    assert "distance, max_speed, target" in msg
    # A typo gets "did you mean" from the C++ catalog.
    assert by_line[6][1] == "unknown-node" and "did you mean 'DriveTo'" in by_line[6][2]
    # other_nodes is not a dependency of robot_nodes: its node is known, as advice only (it
    # is registered if the application loads that package's nodes), and what it says of
    # its ports is a hint at most.
    assert 7 not in by_line or by_line[7][0] == "hint"
    assert len([f for f in found if f[2] == "unknown-node"]) == 1


def test_no_cpp_keeps_the_old_behaviour(capsys: pytest.CaptureFixture[str]) -> None:
    found = _findings(capsys, "--no-cpp")
    assert sorted({code for _, _, code, _ in found}) == ["unknown-node"]
    assert all(sev == "hint" for sev, *_ in [(f[1],) for f in found])


def test_package_scope_and_build_folder() -> None:
    models = CppModels([WS], scanner=Scanner(None))
    ids = {n.id for n in models.catalog_for(MAIN).nodes}
    assert ids == {"DriveTo", "BatteryOk"}
    other = WS / "src" / "other_nodes" / "src" / "other.cpp"
    assert {n.id for n in models.catalog_for(other).nodes} == {"OtherNode"}
    # A file in no package sees the C++ of the whole workspace, build folders left out.
    files = models.files_for(WS / "x.xml")
    assert len(files) == 4 and not [f for f in files if "build" in f.parts]
    assert {n.id for n in models.catalog(files).nodes} == {"DriveTo", "BatteryOk", "OtherNode"}


def test_models_span_the_id_literal_in_the_cpp_file() -> None:
    models = CppModels([WS], scanner=Scanner(None))
    decls = models.decls(models.catalog_for(MAIN))
    d = decls["DriveTo"]
    assert d.path is not None and d.path.endswith("register.cpp")
    text = Path(d.path).read_text()
    assert text[d.start : d.end] == '"DriveTo"'
    assert d.category == "Action" and decls["BatteryOk"].category == "Condition"
    assert [p.name for p in d.ports] == ["max_speed", "target", "distance"]


def test_a_changed_cpp_file_is_read_again(tmp_path: Path) -> None:
    pkg = tmp_path / "pkg"
    (pkg / "src").mkdir(parents=True)
    (pkg / "package.xml").write_text("<package><name>pkg</name></package>")
    cpp = pkg / "src" / "n.cpp"
    cpp.write_text(
        "struct A : BT::SyncActionNode { static BT::PortsList providedPorts() { return {}; } };\n"
        'BT_REGISTER_NODES(f) { f.registerNodeType<A>("A"); }\n'
    )
    sc = Scanner(None)
    models = CppModels([tmp_path], scanner=sc)
    tree = pkg / "t.xml"
    assert {n.id for n in models.catalog_for(tree).nodes} == {"A"}
    cpp.write_text(cpp.read_text().replace('"A"', '"B"'))
    assert models.file_changed(cpp)
    assert {n.id for n in models.catalog_for(tree).nodes} == {"B"}
    assert sc.parsed == 2
    models.set_open(cpp, cpp.read_text().replace('"B"', '"C"'))
    assert {n.id for n in models.catalog_for(tree).nodes} == {"C"}


def test_check_shows_the_cpp_scan_on_a_terminal(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    import json
    import sys

    monkeypatch.setattr(sys.stderr, "isatty", lambda: True)
    main(["check", "--format", "json", str(WS)])
    captured = capsys.readouterr()
    # robot_nodes' trees read three files that may declare nodes (the others lazily).
    for i in (1, 2, 3):
        assert f"\rreading C++: {i}/3 files" in captured.err
    assert "reading C++" not in captured.out
    json.loads(captured.out)  # the report itself is untouched
    # Cleared like the files' bar: nothing of it is left on the last line.
    assert captured.err.rpartition("\r")[2] == ""


def test_no_cpp_progress_off_a_terminal(capsys: pytest.CaptureFixture[str]) -> None:
    main(["check", str(WS)])
    assert "reading C++" not in capsys.readouterr().err


def _copy_ws(tmp_path: Path) -> Path:
    import shutil

    ws = tmp_path / "ws"
    shutil.copytree(WS, ws)
    return ws


def test_a_change_links_again_only_the_nodes_it_touches(tmp_path: Path) -> None:
    from bt_lsp.cpp.catalog import link
    from bt_lsp.cpp.library import library_facts

    ws = _copy_ws(tmp_path)
    tree = ws / "src" / "robot_nodes" / "trees" / "main.xml"
    models = CppModels([ws], scanner=Scanner(None))
    first = models.catalog_for(tree)
    assert models.scanner.memo.made == 2  # DriveTo, BatteryOk
    # A port added to the base class of DriveTo (another package): DriveTo alone again.
    base = ws / "src" / "robot_base" / "include" / "robot_base" / "motion.hpp"
    base.write_text(
        base.read_text().replace(
            'BT::InputPort<double>("max_speed", 0.5, "Speed limit in m/s")',
            'BT::InputPort<double>("max_speed", 0.5, "Speed limit in m/s"), '
            'BT::InputPort<bool>("reverse", false, "Drive backwards")',
        )
    )
    models.file_changed(base)
    again = models.catalog_for(tree)
    assert models.scanner.memo.made == 1
    assert [p.name for p in again.by_id["DriveTo"].ports] == [
        "max_speed",
        "reverse",
        "target",
        "distance",
    ]
    assert again.by_id["BatteryOk"] is first.by_id["BatteryOk"]  # kept as it was
    # A line added above the registrations moves both of them: both made again.
    reg = ws / "src" / "robot_nodes" / "src" / "register.cpp"
    reg.write_text("// moved\n" + reg.read_text())
    models.file_changed(reg)
    moved = models.catalog_for(tree)
    assert models.scanner.memo.made == 2
    assert moved.by_id["DriveTo"].id_span[0] == first.by_id["DriveTo"].id_span[0] + 1
    # Whatever was kept, the catalog is the one a fresh link makes.
    sc = models.scanner
    facts = sorted((str(f), sc.facts(str(f), f.read_bytes())) for f in models.files_for(tree))
    assert link(facts, library_facts()) == moved


_PKG = (
    '<?xml version="1.0"?>\n<package format="3"><name>{}</name><version>0.1.0</version>'
    "<description>d</description><maintainer email='a@b.c'>a</maintainer>"
    "<license>MIT</license><depend>behaviortree_cpp</depend></package>\n"
)
_HEADER = """#include <behaviortree_cpp/bt_factory.h>
class SetupGroup : public BT::SyncActionNode
{
public:
  static BT::PortsList providedPorts();
};
inline void RegisterNodes(BT::BehaviorTreeFactory& factory)
{
  factory.registerNodeType<SetupGroup>("SetupGroup");
}
"""
_PLUGIN = """#include "setup_group.h"
BT_REGISTER_NODES(factory) { RegisterNodes(factory); }
BT::PortsList SetupGroup::providedPorts()
{
  return { BT::InputPort<std::string>("group_name") };
}
"""
_TREE = """<root BTCPP_format="4"><BehaviorTree ID="T">
<SetupGroup group_name="arm"/>
</BehaviorTree></root>
"""


def _plugin_ws(root: Path, with_plugin: bool = True) -> Path:
    """A package whose node is declared in ``include/`` and defined in ``plugins/``, with a
    test that registers a mock under the same ID and a package nested in it."""
    pkg = root / "src" / "arm_bt"
    (pkg / "include").mkdir(parents=True)
    (pkg / "plugins" / "action").mkdir(parents=True)
    (pkg / "test").mkdir()
    (pkg / "trees").mkdir()
    (pkg / "package.xml").write_text(_PKG.format("arm_bt"))
    (pkg / "include" / "setup_group.h").write_text(_HEADER)
    if with_plugin:
        (pkg / "plugins" / "action" / "setup_group.cpp").write_text(_PLUGIN)
    (pkg / "test" / "mock.cpp").write_text(
        "struct Mock : BT::SyncActionNode { static BT::PortsList providedPorts() { return {}; } };"
        '\nvoid f(BT::BehaviorTreeFactory& f) { f.registerNodeType<Mock>("SetupGroup"); }\n'
    )
    nested = pkg / "vendored" / "inner"
    nested.mkdir(parents=True)
    (nested / "package.xml").write_text(_PKG.format("inner"))
    (nested / "inner.cpp").write_text(
        "struct In : BT::SyncActionNode { static BT::PortsList providedPorts() { return {}; } };"
        '\nvoid f(BT::BehaviorTreeFactory& f) { f.registerNodeType<In>("Inner"); }\n'
    )
    tree = pkg / "trees" / "t.xml"
    tree.write_text(_TREE)
    return tree


def test_a_packages_cpp_is_every_folder_of_it_but_tests_and_nested_packages(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    tree = _plugin_ws(tmp_path)
    pkg = tree.parents[1]
    models = CppModels([tmp_path], scanner=Scanner(None))
    files = {f.relative_to(pkg).as_posix() for f in models.files_for(tree)}
    assert files == {"include/setup_group.h", "plugins/action/setup_group.cpp"}
    node = models.catalog_for(tree).by_id["SetupGroup"]
    assert node.authoritative and [p.name for p in node.ports] == ["group_name"]
    # A tree in the test folder sees the nodes its tests register too.
    in_test = pkg / "test" / "t.xml"
    assert "test/mock.cpp" in {f.relative_to(pkg).as_posix() for f in models.files_for(in_test)}
    # bt-lsp models reads the same files.
    main(["models", str(pkg), "--format", "json", "--no-cache"])
    ids = {n["id"]: n for n in json.loads(capsys.readouterr().out)["nodes"]}
    assert set(ids) == {"SetupGroup"} and ids["SetupGroup"]["authoritative"]


def test_a_port_list_declared_but_not_read_is_never_empty(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    tree = _plugin_ws(tmp_path, with_plugin=False)
    models = CppModels([tmp_path], scanner=Scanner(None))
    node = models.catalog_for(tree).by_id["SetupGroup"]
    assert not node.authoritative and node.ports == ()
    assert "providedPorts() is declared at" in node.notes[0]
    assert "not in the C++ read" in node.notes[0]
    main(["check", str(tmp_path)])
    lines = [ln for ln in capsys.readouterr().out.splitlines() if "undeclared-port" in ln]
    assert len(lines) == 1 and ": hint undeclared-port " in lines[0]


def test_a_node_of_a_package_not_depended_on_is_known_but_advisory(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Nav2 loads plugin libraries by name: a tree of one package may use a node that a
    package it does not depend on registers. It is not unknown; its ports are advice."""
    plugins = tmp_path / "src" / "my_plugins"
    (plugins / "src").mkdir(parents=True)
    (plugins / "package.xml").write_text(_PKG.format("my_plugins"))
    (plugins / "src" / "nodes.cpp").write_text(
        "#include <behaviortree_cpp/bt_factory.h>\n"
        "struct Hop : BT::SyncActionNode {\n"
        '  static BT::PortsList providedPorts() { return { BT::InputPort<int>("n") }; }\n};\n'
        'BT_REGISTER_NODES(factory) { factory.registerNodeType<Hop>("Hop"); }\n'
    )
    robot = tmp_path / "src" / "robot"
    (robot / "trees").mkdir(parents=True)
    (robot / "package.xml").write_text(_PKG.format("robot"))
    tree = robot / "trees" / "t.xml"
    tree.write_text(
        '<root BTCPP_format="4"><BehaviorTree ID="T"><Sequence><Hop n="1" m="2"/>'
        "<Frob/></Sequence></BehaviorTree></root>\n"
    )
    main(["check", str(tmp_path), "--format", "json", "--no-progress"])
    found = {
        (d["code"], d["severity"], d["message"].split("'")[1])
        for d in json.loads(capsys.readouterr().out)
        if d["path"].endswith("t.xml")
    }
    # Hop is known (no unknown-node); an attribute it lacks is a hint, as its package may
    # not be the one loaded; Frob, which no C++ registers, stays unknown.
    assert ("unknown-node", "hint", "Frob") in found
    assert not any(code == "unknown-node" and name == "Hop" for code, _, name in found)
    assert ("undeclared-port", "hint", "Hop") in found
