"""The BehaviorTree.CPP version of each file: package.xml, CMakeLists.txt, the
configuration, BTCPP_format; and what a v3 project is spared."""

from __future__ import annotations

from pathlib import Path

from bt_lsp.project.index import ProjectIndex
from bt_lsp.project.packages import Packages, cmake_btcpp, read_manifest
from bt_lsp.project.settings import Settings
from bt_lsp.syntax.document import Document

TREE = '<root main_tree_to_execute="T"><BehaviorTree ID="T"><AlwaysSuccess/></BehaviorTree></root>'


def manifest(name: str, *depends: str, tag: str = "depend") -> str:
    deps = "".join(f"<{tag}>{d}</{tag}>" for d in depends)
    return f'<?xml version="1.0"?><package format="3"><name>{name}</name>{deps}</package>'


def write(path: Path, text: str) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text, encoding="utf-8")
    return path


def test_manifest_read(tmp_path: Path) -> None:
    m = read_manifest(
        write(tmp_path / "p" / "package.xml", manifest("p", "rclcpp", "behaviortree_cpp_v3"))
    )
    assert m is not None
    assert m.name == "p" and m.btcpp == "3" and "rclcpp" in m.depends
    assert read_manifest(write(tmp_path / "bad.xml", "<package><name>")) is None
    # Entities are never expanded.
    evil = (
        '<!DOCTYPE p [<!ENTITY x SYSTEM "file:///etc/passwd">]><package><name>&x;</name></package>'
    )
    m = read_manifest(write(tmp_path / "q" / "package.xml", evil))
    assert m is None or "root" not in m.name


def test_cmake_find_package(tmp_path: Path) -> None:
    cm = write(tmp_path / "CMakeLists.txt", "find_package( behaviortree_cpp REQUIRED)\n")
    assert cmake_btcpp(cm) == "4"
    write(cm, "# find_package(behaviortree_cpp)\nfind_package(behaviortree_cpp_v3)\n")
    assert cmake_btcpp(cm) == "3"
    write(cm, "find_package(rclcpp)\n")
    assert cmake_btcpp(cm) is None


def test_v3_and_v4_packages_in_one_workspace(tmp_path: Path) -> None:
    write(tmp_path / "src" / "old" / "package.xml", manifest("old", "behaviortree_cpp_v3"))
    write(
        tmp_path / "src" / "new" / "package.xml",
        manifest("new", "behaviortree_cpp", tag="exec_depend"),
    )
    old = write(tmp_path / "src" / "old" / "trees" / "a.xml", TREE)
    new = write(tmp_path / "src" / "new" / "behavior_trees" / "b.xml", TREE)
    ws = ProjectIndex([tmp_path])
    d = ws.btcpp_for(old)
    assert d.version == "3" and "behaviortree_cpp_v3" in d.source and "package.xml" in d.source
    assert ws.btcpp_for(new).version == "4"
    codes_old = {x.code for x in ws.diagnostics(old, Document(TREE, str(old)))}
    codes_new = {x.code for x in ws.diagnostics(new, Document(TREE, str(new)))}
    assert "missing-format" not in codes_old  # no v4 advice for a v3 package
    assert "missing-format" in codes_new


def test_package_without_btcpp_dependency_uses_its_cmake(tmp_path: Path) -> None:
    write(tmp_path / "p" / "package.xml", manifest("p", "rclcpp"))
    write(tmp_path / "p" / "CMakeLists.txt", "find_package(behaviortree_cpp_v3 REQUIRED)\n")
    # A CMakeLists.txt above the package does not decide for it.
    write(tmp_path / "CMakeLists.txt", "find_package(behaviortree_cpp)\n")
    f = write(tmp_path / "p" / "t.xml", TREE)
    d = ProjectIndex([tmp_path]).btcpp_for(f)
    assert d.version == "3" and "CMakeLists.txt" in d.source


def test_package_boundary_stops_the_search(tmp_path: Path) -> None:
    write(tmp_path / "CMakeLists.txt", "find_package(behaviortree_cpp)\n")
    write(tmp_path / "p" / "package.xml", manifest("p", "rclcpp"))
    f = write(tmp_path / "p" / "t.xml", TREE)
    assert ProjectIndex([tmp_path]).btcpp_for(f).version is None
    g = write(tmp_path / "plain" / "t.xml", TREE)
    assert ProjectIndex([tmp_path]).btcpp_for(g).version == "4"


def test_btcpp_format_when_nothing_else_says(tmp_path: Path) -> None:
    f = write(tmp_path / "t.xml", TREE.replace("<root ", '<root BTCPP_format="3" '))
    d = ProjectIndex([tmp_path]).btcpp_for(f)
    assert d.version == "3" and "BTCPP_format" in d.source
    assert ProjectIndex([tmp_path]).btcpp_for(write(tmp_path / "u.xml", TREE)).version is None


def test_configuration_wins(tmp_path: Path) -> None:
    write(tmp_path / "package.xml", manifest("p", "behaviortree_cpp"))
    f = write(tmp_path / "t.xml", TREE)
    write(tmp_path / "bt-lsp.toml", 'btcpp = "3"\n')
    d = ProjectIndex([tmp_path]).btcpp_for(f)
    assert d.version == "3" and d.source == "the btcpp setting"
    assert ProjectIndex([tmp_path], Settings(btcpp="3")).btcpp_for(f).version == "3"
    write(tmp_path / "bt-lsp.toml", 'btcpp = "auto"\n')
    assert ProjectIndex([tmp_path], Settings(btcpp="3")).btcpp_for(f).version == "4"


def test_manifest_change_is_heard(tmp_path: Path) -> None:
    pkg = write(tmp_path / "package.xml", manifest("p", "behaviortree_cpp_v3"))
    f = write(tmp_path / "t.xml", TREE)
    ws = ProjectIndex([tmp_path])
    assert ws.btcpp_for(f).version == "3"
    write(pkg, manifest("p", "behaviortree_cpp"))
    ws.file_changed(pkg)
    assert ws.btcpp_for(f).version == "4"
    assert Packages().package_of(tmp_path / "deeper" / "x") is not None
