"""Which BehaviorTree.CPP a package builds against when its files disagree or say nothing,
and what a version 3 project, a palette and a workspace package's own catalog are spared.

Minimal copies of real layouts: a package whose only evidence is its C++ includes
(``robocup_behavior_trees``), a package.xml left at ``behaviortree_cpp_v3`` after a move to
version 4 (``suave_bt``), Nav2 Humble's hand-kept ``nav2_tree_nodes.xml`` that lacks a port
of the C++ node, and Groot palette files.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from bt_lsp.project.index import ProjectIndex
from tests.pinned import main  # bt-lsp without the codes defined later

Found = list[tuple[int, str, str, str]]  # line, severity, code, message


@pytest.fixture(autouse=True)
def _cache(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    monkeypatch.delenv("AMENT_PREFIX_PATH", raising=False)


def write(path: Path, text: str) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text, encoding="utf-8")
    return path


def manifest(name: str, *depends: str) -> str:
    deps = "".join(f"<depend>{d}</depend>" for d in depends)
    return f'<?xml version="1.0"?><package format="3"><name>{name}</name>{deps}</package>'


def check(capsys: pytest.CaptureFixture[str], ws: Path, *flags: str) -> dict[str, Found]:
    """``bt-lsp check WS --format json``: the findings by file name."""
    main(["check", str(ws), "--format", "json", "--no-progress", *flags])
    out: dict[str, Found] = {}
    for d in json.loads(capsys.readouterr().out):
        out.setdefault(Path(d["path"]).name, []).append(
            (d["line"], d["severity"], d["code"], d["message"])
        )
    return out


def codes(found: Found, *severities: str) -> list[tuple[int, str]]:
    return [(line, code) for line, sev, code, _ in found if sev in severities]


# A package.xml with no BehaviorTree.CPP dependency, a CMakeLists.txt that finds none: the
# application's C++ includes version 3's headers.
V3_TREE = """<root main_tree_to_execute="Main">
  <BehaviorTree ID="Main">
    <SequenceStar>
      <ReactiveSequence>
        <Condition ID="IsReady"/>
        <Action ID="Go"/>
      </ReactiveSequence>
      <RetryUntilSuccesful num_attempts="2"><Action ID="Go"/></RetryUntilSuccesful>
      <SubTree ID="Sub" __shared_blackboard="true" distance="{d}"/>
    </SequenceStar>
  </BehaviorTree>
  <BehaviorTree ID="Sub"><AlwaysSuccess/></BehaviorTree>
  <TreeNodesModel>
    <SubTree ID="Sub"><input_port name="target"/></SubTree>
  </TreeNodesModel>
</root>
"""


def _v3_by_includes(root: Path) -> Path:
    pkg = root / "robocup"
    write(pkg / "package.xml", manifest("robocup", "rclcpp"))
    write(pkg / "CMakeLists.txt", "find_package(ament_cmake REQUIRED)\n")
    write(
        pkg / "src" / "main.cpp",
        '// #include "behaviortree_cpp/bt_factory.h"\n'
        '#include "behaviortree_cpp_v3/bt_factory.h"\nint main() {}\n',
    )
    return write(pkg / "xml" / "mission.xml", V3_TREE)


def test_the_cpp_includes_say_version_3(tmp_path: Path) -> None:
    tree = _v3_by_includes(tmp_path)
    d = ProjectIndex([tmp_path]).btcpp_for(tree)
    assert d.version == "3" and not d.conflict
    assert "main.cpp includes <behaviortree_cpp_v3/…>" in d.source


def test_a_v3_project_gets_v3_behaviour(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    _v3_by_includes(tmp_path)
    found = check(capsys, tmp_path)["mission.xml"]
    # No BTCPP_format advice, SequenceStar known, explicit ReactiveSequence children load in
    # 3.8, and a <SubTree> model is an editor's note in 3.8.
    assert codes(found, "error", "warning") == [(8, "unknown-node")]
    (msg,) = [m for line, sev, _, m in found if line == 8 and sev == "warning"]
    assert "BehaviorTree.CPP 3.8 does not register" in msg and "4 calls" not in msg
    assert (9, "undeclared-port") in codes(found, "hint")


def test_v3_behaviour_whatever_says_version_3(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    pkg = tmp_path / "can_do_challenge"
    write(pkg / "package.xml", manifest("can_do_challenge", "behaviortree_cpp_v3"))
    write(pkg / "bt_xml" / "main.xml", V3_TREE)
    found = check(capsys, tmp_path)["main.xml"]
    assert codes(found, "error", "warning") == [(8, "unknown-node")]
    assert (9, "undeclared-port") in codes(found, "hint")


def test_verbose_says_where_the_version_comes_from(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    _v3_by_includes(tmp_path)
    main(["check", str(tmp_path), "--verbose", "--no-progress"])
    err = capsys.readouterr().err
    assert "BehaviorTree.CPP 3: 1 file (" in err and "includes <behaviortree_cpp_v3/…>" in err


V4_TREE = """<root BTCPP_format="4" main_tree_to_execute="Main">
  <BehaviorTree ID="Main">
    <SequenceWithMemory><AlwaysSuccess/></SequenceWithMemory>
  </BehaviorTree>
</root>
"""


def test_the_build_beats_a_stale_package_xml(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    pkg = tmp_path / "suave_bt"
    write(pkg / "package.xml", manifest("suave_bt", "behaviortree_cpp_v3"))
    write(pkg / "CMakeLists.txt", "find_package(behaviortree_cpp REQUIRED)\n")
    write(pkg / "src" / "a.cpp", "#include <behaviortree_cpp/bt_factory.h>\n")
    tree = write(pkg / "bts" / "suave.xml", V4_TREE)
    d = ProjectIndex([tmp_path]).btcpp_for(tree)
    assert d.version == "4"
    assert "finds behaviortree_cpp" in d.source and "not what the build uses" in d.source
    assert codes(check(capsys, tmp_path).get("suave.xml", []), "error", "warning") == []


CONFLICT_TREE = """<root BTCPP_format="4" main_tree_to_execute="Main">
  <BehaviorTree ID="Main">
    <Sequence>
      <SequenceStar><AlwaysSuccess/></SequenceStar>
      <Parallel success_threshold="1"><AlwaysSuccess/></Parallel>
    </Sequence>
  </BehaviorTree>
</root>
"""


def test_a_build_naming_both_versions_leaves_the_version_unclear(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    pkg = tmp_path / "mixed"
    write(pkg / "package.xml", manifest("mixed"))
    write(pkg / "CMakeLists.txt", "find_package(behaviortree_cpp REQUIRED)\n")
    write(pkg / "src" / "old.cpp", "#include <behaviortree_cpp_v3/bt_factory.h>\n")
    tree = write(pkg / "trees" / "t.xml", CONFLICT_TREE)
    ws = ProjectIndex([tmp_path])
    d = ws.btcpp_for(tree)
    assert d.version is None and d.conflict
    assert "(BehaviorTree.CPP 3)" in d.source and "(BehaviorTree.CPP 4)" in d.source
    found = check(capsys, tmp_path)["t.xml"]
    # What depends on the version is a warning at most, and says why; no error although
    # the document declares BTCPP_format="4".
    assert codes(found, "error") == []
    assert codes(found, "warning") == [(4, "unknown-node"), (5, "undeclared-port")]
    assert all("names both BehaviorTree.CPP 3 and 4" in m for _, s, _, m in found if s != "hint")
    main(["check", str(tmp_path), "--verbose", "--no-progress"])
    assert "BehaviorTree.CPP version unclear: 1 file" in capsys.readouterr().err


def test_both_find_package_calls_leave_the_version_unclear(tmp_path: Path) -> None:
    write(
        tmp_path / "CMakeLists.txt",
        "find_package(behaviortree_cpp QUIET)\nfind_package(behaviortree_cpp_v3 QUIET)\n",
    )
    tree = write(tmp_path / "t.xml", V4_TREE)
    d = ProjectIndex([tmp_path]).btcpp_for(tree)
    assert d.version is None and d.conflict


def test_the_hover_on_root_says_the_version_is_unclear() -> None:
    from bt_lsp.ide.hover import root_hover
    from bt_lsp.syntax.document import Document

    doc = Document(V4_TREE, "t.xml")
    h = root_hover(doc, 2, None, "a (BehaviorTree.CPP 3); b (BehaviorTree.CPP 4)", True, True)
    assert h is not None and "unclear" in h.text and "a (BehaviorTree.CPP 3)" in h.text


PALETTE = """<root>
  <TreeNodesModel>
    <Action ID="TakeOff"><input_port name="height"/></Action>
  </TreeNodesModel>
</root>
"""


def test_a_palette_gets_no_format_warning(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    pkg = tmp_path / "as2_behavior_tree"
    write(pkg / "package.xml", manifest("as2_behavior_tree", "behaviortree_cpp"))
    write(pkg / "resource" / "actions.xml", PALETTE)
    write(pkg / "resource" / "mission.xml", V4_TREE.replace(' BTCPP_format="4"', ""))
    found = check(capsys, tmp_path)
    assert "actions.xml" not in found  # BehaviorTree.CPP never loads it as a tree file
    assert codes(found["mission.xml"], "warning") == [(1, "missing-format")]


def test_format_advice_for_an_unknown_version_is_a_hint(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    write(tmp_path / "t.xml", V4_TREE.replace(' BTCPP_format="4"', ""))
    found = check(capsys, tmp_path)["t.xml"]
    assert [(line, sev, code) for line, sev, code, _ in found] == [(1, "hint", "missing-format")]
    assert "version was not detected" in found[0][3]


# Nav2 Humble: the package ships a hand-kept catalog that lacks a port its C++ declares; the
# registration sits where it was not read.
NAV_CATALOG = """<?xml version="1.0"?>
<!-- For Groot: written by hand. -->
<root>
  <TreeNodesModel>
    <Action ID="Spin">
      <input_port name="spin_dist">Spin distance</input_port>
    </Action>
  </TreeNodesModel>
</root>
"""
NAV_TREE = """<root main_tree_to_execute="Main">
  <BehaviorTree ID="Main">
    <Spin spin_dist="1.57" is_recovery="false"/>
  </BehaviorTree>
</root>
"""


def test_a_workspace_packages_own_catalog_does_not_overrule_its_cpp(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bt = tmp_path / "nav2_behavior_tree"
    write(bt / "package.xml", manifest("nav2_behavior_tree", "behaviortree_cpp_v3"))
    write(bt / "nav2_tree_nodes.xml", NAV_CATALOG)
    write(
        bt / "src" / "engine.cpp",
        "#include <behaviortree_cpp_v3/bt_factory.h>\n"
        'void load(BT::BehaviorTreeFactory& f) { f.registerFromPlugin("libspin.so"); }\n',
    )
    nav = tmp_path / "nav2_bt_navigator"
    write(nav / "package.xml", manifest("nav2_bt_navigator", "nav2_behavior_tree"))
    write(nav / "behavior_trees" / "odometry_calibration.xml", NAV_TREE)
    found = check(capsys, tmp_path)["odometry_calibration.xml"]
    assert codes(found, "error", "warning") == []
    assert (3, "undeclared-port") in codes(found, "hint")


def test_an_installed_catalog_stays_authoritative(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    share = tmp_path / "opt" / "share" / "nav2_behavior_tree"
    write(share / "package.xml", manifest("nav2_behavior_tree", "behaviortree_cpp_v3"))
    write(share / "nav2_tree_nodes.xml", NAV_CATALOG)
    monkeypatch.setenv("AMENT_PREFIX_PATH", str(tmp_path / "opt"))
    ws = tmp_path / "ws"
    nav = ws / "nav2_bt_navigator"
    write(nav / "package.xml", manifest("nav2_bt_navigator", "nav2_behavior_tree"))
    write(nav / "behavior_trees" / "odometry_calibration.xml", NAV_TREE)
    found = check(capsys, ws)["odometry_calibration.xml"]
    assert (3, "undeclared-port") in codes(found, "error")
