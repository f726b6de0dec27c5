"""ROS workspaces: installed packages through AMENT_PREFIX_PATH, a colcon workspace's
src/ packages, <include ros_pkg>, and the catalogs of a package's dependencies."""

from __future__ import annotations

from pathlib import Path

from bt_lsp.project.index import ProjectIndex as Workspace
from bt_lsp.project.ros import is_catalog
from bt_lsp.project.settings import Settings
from bt_lsp.syntax.document import Document

CATALOG = (
    '<?xml version="1.0"?>\n<!-- generated -->\n<root BTCPP_format="4">\n  <TreeNodesModel>\n'
    '    <Action ID="ComputePathToPose"><input_port name="goal"/></Action>\n'
    "  </TreeNodesModel>\n</root>\n"
)
LIB_CATALOG = CATALOG.replace("ComputePathToPose", "LibNode")
SUB = '<root BTCPP_format="4"><BehaviorTree ID="Sub"><AlwaysSuccess/></BehaviorTree></root>\n'
MAIN = (
    '<root BTCPP_format="4" main_tree_to_execute="Main">\n'
    '  <include ros_pkg="my_trees" path="trees/sub.xml"/>\n'
    '  <BehaviorTree ID="Main">\n'
    "    <Sequence>\n"
    '      <ComputePathToPose goal="{g}"/>\n'
    '      <SubTree ID="Sub"/>\n'
    "    </Sequence>\n"
    "  </BehaviorTree>\n"
    "</root>\n"
)


def write(path: Path, text: str) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text, encoding="utf-8")
    return path


def manifest(name: str, *depends: str) -> str:
    deps = "".join(f"<exec_depend>{d}</exec_depend>" for d in depends)
    return f'<package format="3"><name>{name}</name>{deps}</package>'


def installed(tmp_path: Path) -> Path:
    prefix = tmp_path / "opt" / "ros" / "humble"
    share = prefix / "share"
    write(share / "nav2_behavior_tree" / "package.xml", manifest("nav2_behavior_tree"))
    write(share / "nav2_behavior_tree" / "nav2_tree_nodes.xml", CATALOG)
    write(share / "my_trees" / "package.xml", manifest("my_trees"))
    write(share / "my_trees" / "trees" / "sub.xml", SUB)
    (share / "not_a_package").mkdir()
    return prefix


def codes(ws: Workspace, path: Path) -> set[str]:
    doc = Document(path.read_text(encoding="utf-8"), str(path))
    return {d.code for d in ws.diagnostics(path, doc)}


def test_is_catalog(tmp_path: Path) -> None:
    assert is_catalog(write(tmp_path / "a.xml", CATALOG))
    assert not is_catalog(write(tmp_path / "b.xml", SUB))
    assert not is_catalog(write(tmp_path / "c.xml", CATALOG.replace("</root>", SUB + "</root>")))
    assert not is_catalog(write(tmp_path / "d.xml", "<package><TreeNodesModel/></package>"))
    assert not is_catalog(tmp_path / "missing.xml")


def test_installed_packages_resolve_includes_and_ship_catalogs(tmp_path: Path) -> None:
    prefix = installed(tmp_path)
    app = tmp_path / "ws" / "src" / "app"
    write(app / "package.xml", manifest("app", "nav2_behavior_tree", "my_trees"))
    main = write(app / "behavior_trees" / "main.xml", MAIN)
    ws = Workspace([tmp_path / "ws"], ament_prefix_path=[str(tmp_path / "nowhere"), str(prefix)])
    assert ws.scope.ros_package("my_trees") == prefix / "share" / "my_trees"
    assert ws.scope.catalog_files(main) == [
        prefix / "share" / "nav2_behavior_tree" / "nav2_tree_nodes.xml"
    ]
    [inc] = ws.includes.of(main)
    assert inc.target == prefix / "share" / "my_trees" / "trees" / "sub.xml"
    found = codes(ws, main)
    assert "include-ros-pkg" not in found  # resolved
    assert "unknown-subtree" not in found  # Sub comes from the included file
    assert "unknown-node" not in found  # ComputePathToPose from nav2's catalog
    # Without AMENT_PREFIX_PATH, none of it is known.
    bare = Workspace([tmp_path / "ws"], ament_prefix_path=[])
    found = codes(bare, main)
    assert {"include-ros-pkg", "unknown-node"} <= found


def test_catalogs_only_for_packages_that_depend(tmp_path: Path) -> None:
    prefix = installed(tmp_path)
    other = tmp_path / "ws" / "src" / "other"
    write(other / "package.xml", manifest("other", "rclcpp"))
    tree = write(other / "trees" / "t.xml", MAIN)
    ws = Workspace([tmp_path / "ws"], ament_prefix_path=[str(prefix)])
    assert ws.scope.catalog_files(tree) == []
    assert "unknown-node" in codes(ws, tree)


def test_colcon_src_packages_see_their_own_and_their_dependencies_catalogs(
    tmp_path: Path,
) -> None:
    src = tmp_path / "ws" / "src"
    write(src / "lib" / "package.xml", manifest("lib"))
    lib_catalog = write(src / "lib" / "lib_nodes.xml", LIB_CATALOG)
    write(src / "app" / "package.xml", manifest("app", "lib"))
    app_catalog = write(src / "app" / "models" / "app_nodes.xml", CATALOG)
    app_tree = write(src / "app" / "trees" / "t.xml", MAIN.replace("ComputePathToPose", "LibNode"))
    write(src / "solo" / "package.xml", manifest("solo"))
    solo_tree = write(src / "solo" / "t.xml", MAIN)
    # The build and install folders are never the workspace's packages.
    write(tmp_path / "ws" / "install" / "lib" / "package.xml", manifest("lib"))
    ws = Workspace([tmp_path / "ws"], ament_prefix_path=[])
    assert ws.scope.workspace_packages() == {
        "app": src / "app",
        "lib": src / "lib",
        "solo": src / "solo",
    }
    assert ws.scope.catalog_files(app_tree) == [app_catalog, lib_catalog]
    assert ws.scope.catalog_files(solo_tree) == []
    assert "unknown-node" not in codes(ws, app_tree)


def test_configured_packages_come_first(tmp_path: Path) -> None:
    prefix = installed(tmp_path)
    mine = tmp_path / "mine"
    write(mine / "trees" / "sub.xml", SUB)
    ws = Workspace(
        [tmp_path], Settings(ros_packages={"my_trees": str(mine)}), ament_prefix_path=[str(prefix)]
    )
    assert ws.scope.ros_package("my_trees", ws.settings_index.editor) == mine
    write(tmp_path / "bt-lsp.toml", '[ros-packages]\nmy_trees = "elsewhere"\n')
    f = write(tmp_path / "t.xml", MAIN)
    [inc] = ws.includes.of(f)
    assert inc.target == tmp_path / "elsewhere" / "trees" / "sub.xml"


def test_a_new_catalog_is_heard(tmp_path: Path) -> None:
    src = tmp_path / "ws" / "src"
    write(src / "app" / "package.xml", manifest("app"))
    tree = write(src / "app" / "trees" / "t.xml", MAIN)
    ws = Workspace([tmp_path / "ws"], ament_prefix_path=[])
    assert ws.scope.catalog_files(tree) == []
    cat = write(src / "app" / "nodes.xml", CATALOG)
    ws.file_changed(cat)
    assert ws.scope.catalog_files(tree) == [cat]


def severities(ws: Workspace, path: Path) -> dict[str, str]:
    doc = Document(path.read_text(encoding="utf-8"), str(path))
    return {d.code: d.severity.name.lower() for d in ws.diagnostics(path, doc)}


NAV_TREE = (
    '<root BTCPP_format="4" main_tree_to_execute="Main">\n'
    '  <BehaviorTree ID="Main">\n'
    "    <Sequence>\n"
    '      <ComputePathToPose goal="{g}" planner="GridBased"/>\n'
    "    </Sequence>\n"
    "  </BehaviorTree>\n"
    "</root>\n"
)


def test_an_installed_catalog_is_authoritative_for_its_nodes(tmp_path: Path) -> None:
    prefix = installed(tmp_path)
    app = tmp_path / "ws" / "src" / "app"
    write(app / "package.xml", manifest("app", "nav2_behavior_tree"))
    tree = write(app / "trees" / "t.xml", NAV_TREE)
    ws = Workspace([tmp_path / "ws"], ament_prefix_path=[str(prefix)])
    ctx = ws.context_for(tree, Document(tree.read_text(encoding="utf-8"), str(tree)))
    assert ctx.models["ComputePathToPose"].source == "ros"
    found = severities(ws, tree)
    assert "unknown-node" not in found
    # 'planner' is not a port of nav2's model: BehaviorTree.CPP throws at creation.
    assert found["undeclared-port"] == "error"
    # The catalog is one package's: a node it lacks is still most likely registered.
    assert not ctx.workspace_has_custom_models


def test_dependencies_are_followed_transitively_and_cycles_end(tmp_path: Path) -> None:
    prefix = installed(tmp_path)
    share = prefix / "share"
    # Installed: nav2_bt_navigator -> nav2_behavior_tree; a cycle between two others.
    write(
        share / "nav2_bt_navigator" / "package.xml",
        manifest("nav2_bt_navigator", "nav2_behavior_tree"),
    )
    write(share / "loop_a" / "package.xml", manifest("loop_a", "loop_b"))
    write(share / "loop_b" / "package.xml", manifest("loop_b", "loop_a", "nav2_bt_navigator"))
    src = tmp_path / "ws" / "src"
    # In the workspace: app -> lib -> loop_a -> loop_b -> nav2_bt_navigator -> nav2_behavior_tree.
    write(src / "lib" / "package.xml", manifest("lib", "loop_a", "app"))
    lib_catalog = write(src / "lib" / "lib_nodes.xml", LIB_CATALOG)
    write(src / "app" / "package.xml", manifest("app", "lib"))
    tree = write(src / "app" / "trees" / "t.xml", NAV_TREE)
    ws = Workspace([tmp_path / "ws"], ament_prefix_path=[str(prefix)])
    nav2 = share / "nav2_behavior_tree" / "nav2_tree_nodes.xml"
    assert ws.scope.catalog_files(tree) == [lib_catalog, nav2]
    assert ws.scope.package_folders(tree) == [
        src / "app",
        src / "lib",
        share / "loop_a",
        share / "loop_b",
        share / "nav2_bt_navigator",
        share / "nav2_behavior_tree",
    ]
    found = severities(ws, tree)
    assert "unknown-node" not in found
    assert found["undeclared-port"] == "error"


def test_a_package_sees_its_dependencies_nodes_not_every_node(tmp_path: Path) -> None:
    src = tmp_path / "ws" / "src"
    write(src / "lib" / "package.xml", manifest("lib"))
    write(src / "lib" / "lib_nodes.xml", LIB_CATALOG)
    write(src / "app" / "package.xml", manifest("app", "lib"))
    uses_lib = NAV_TREE.replace("ComputePathToPose", "LibNode").replace(' planner="GridBased"', "")
    app_tree = write(src / "app" / "trees" / "t.xml", uses_lib)
    write(src / "solo" / "package.xml", manifest("solo"))
    solo_tree = write(src / "solo" / "t.xml", uses_lib)
    ws = Workspace([tmp_path / "ws"], ament_prefix_path=[])
    assert "unknown-node" not in codes(ws, app_tree)
    solo_doc = Document(solo_tree.read_text(encoding="utf-8"), str(solo_tree))
    assert "LibNode" not in ws.context_for(solo_tree, solo_doc).models
    assert "unknown-node" in codes(ws, solo_tree)


def test_excluded_files_are_not_part_of_the_workspace(tmp_path: Path) -> None:
    write(tmp_path / "bt-lsp.toml", 'exclude = ["old/**", "scratch.xml"]\n')
    models = '<root BTCPP_format="4"><TreeNodesModel><Action ID="Go"/></TreeNodesModel></root>'
    write(tmp_path / "old" / "models.xml", models)
    write(tmp_path / "scratch.xml", models)
    kept = write(tmp_path / "trees" / "t.xml", MAIN)
    ws = Workspace([tmp_path], ament_prefix_path=[])
    assert ws.files.paths() == [kept]
    # An open excluded document is not part of the workspace either.
    scratch = tmp_path / "scratch.xml"
    ws.open(scratch, Document(models, str(scratch)))
    assert [p for p, _ in ws.bt_documents()] == [kept]
    # Editing the configuration brings them back.
    ws.config_edited(tmp_path / "bt-lsp.toml", "exclude = []\n")
    assert ws.files.paths() == [tmp_path / "old" / "models.xml", scratch, kept]


def test_catalogs_are_found_up_to_three_folders_down(tmp_path: Path) -> None:
    share = tmp_path / "opt" / "share" / "lib"
    write(share / "package.xml", manifest("lib"))
    deep = write(share / "config" / "bt" / "models" / "nodes.xml", LIB_CATALOG)
    write(share / "a" / "b" / "c" / "d" / "too_deep.xml", LIB_CATALOG)
    write(share / "build" / "copied.xml", LIB_CATALOG)
    write(share / "trees" / "tree.xml", SUB)  # a tree file, not a catalog
    app = tmp_path / "ws" / "app"
    write(app / "package.xml", manifest("app", "lib"))
    tree = write(app / "t.xml", MAIN.replace("ComputePathToPose", "LibNode"))
    ws = Workspace([tmp_path / "ws"], ament_prefix_path=[str(tmp_path / "opt")])
    assert ws.scope.catalog_files(tree) == [deep]
    # A catalog added deep inside is heard.
    later = write(share / "x" / "y" / "more.xml", CATALOG)
    ws.file_changed(later)
    assert ws.scope.catalog_files(tree) == [later, deep]
