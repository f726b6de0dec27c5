"""``bt-lsp check`` with the project around it: configuration files, --config, --models,
--btcpp, --verbose."""

from __future__ import annotations

from pathlib import Path

import pytest

from tests.pinned import main  # bt-lsp as the tests know it (tests/pinned.py)

TREE = (
    '<root main_tree_to_execute="T">\n'
    '  <BehaviorTree ID="T"><Sequence><Go/></Sequence></BehaviorTree>\n'
    "</root>\n"
)
CATALOG = '<root BTCPP_format="4"><TreeNodesModel><Action ID="Go"/></TreeNodesModel></root>\n'


def write(path: Path, text: str) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text, encoding="utf-8")
    return path


def run(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    code = main(["check", "--no-progress", *argv])
    out, err = capsys.readouterr()
    return code, out, err


def codes(out: str) -> list[str]:
    return [line.split()[2] for line in out.splitlines() if line.strip()]


def test_broken_configuration_exits_2_with_its_position(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    cfg = write(tmp_path / "bt-lsp.toml", 'btcpp = "4"\nexclude = "build"\n')
    write(tmp_path / "t.xml", TREE)
    code, out, err = run(capsys, str(tmp_path))
    assert code == 2
    # Checked without it: its btcpp = "4" does not count, so the version is not known and
    # the missing BTCPP_format is a hint.
    assert codes(out) == ["missing-format", "unknown-node"]
    assert err.splitlines() == [
        f"{cfg}:2:1: error config-error 'exclude' must be a list of strings",
        "0 errors, 0 warnings, 2 hints in 1 file; 1 configuration file could not be used",
    ]


def test_discovered_configuration_severity_and_version(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    write(tmp_path / "t.xml", TREE)
    code, out, _ = run(capsys, str(tmp_path))
    assert "missing-format" in codes(out)
    write(tmp_path / "pyproject.toml", '[tool.bt-lsp.severity]\nmissing-format = "error"\n')
    code, out, _ = run(capsys, str(tmp_path / "t.xml"))
    assert code == 1
    assert any(" error missing-format " in line for line in out.splitlines())
    # --severity over the file.
    code, out, _ = run(capsys, "--severity", "missing-format=off", str(tmp_path))
    assert "missing-format" not in codes(out)


def test_btcpp_flag_over_the_file_and_verbose(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    write(tmp_path / "bt-lsp.toml", 'btcpp = "4"\n')
    write(tmp_path / "t.xml", TREE)
    code, out, err = run(capsys, "--verbose", str(tmp_path))
    assert code == 0
    assert "missing-format" in codes(out)
    assert "bt-lsp: BehaviorTree.CPP 4: 1 file (the btcpp setting)" in err.splitlines()
    code, out, err = run(capsys, "--verbose", "--btcpp", "3", str(tmp_path))
    assert code == 0
    assert "missing-format" not in codes(out)
    assert "bt-lsp: BehaviorTree.CPP 3: 1 file (the btcpp setting)" in err.splitlines()


def test_verbose_names_the_package(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    manifest = write(
        tmp_path / "pkg" / "package.xml",
        "<package><name>pkg</name><exec_depend>behaviortree_cpp_v3</exec_depend></package>",
    )
    write(tmp_path / "pkg" / "trees" / "t.xml", TREE)
    _, out, err = run(capsys, "--verbose", str(tmp_path / "pkg" / "trees"))
    assert "missing-format" not in codes(out)
    assert (
        f"bt-lsp: BehaviorTree.CPP 3: 1 file ({manifest} depends on behaviortree_cpp_v3)"
        in err.splitlines()
    )


def test_models_flag_and_key(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    tree = write(tmp_path / "trees" / "t.xml", TREE)
    cat = write(tmp_path / "catalog" / "nodes.xml", CATALOG)
    _, out, _ = run(capsys, str(tree))
    assert "unknown-node" in codes(out)
    _, out, _ = run(capsys, "--models", str(cat), str(tree))
    assert "unknown-node" not in codes(out)
    write(tmp_path / "bt-lsp.toml", 'models = ["catalog/nodes.xml"]\n')
    _, out, _ = run(capsys, str(tree))
    assert "unknown-node" not in codes(out)


def test_explicit_config(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    write(tmp_path / "t.xml", TREE)
    other = write(tmp_path / "elsewhere" / "mine.toml", '[severity]\nmissing-format = "off"\n')
    _, out, _ = run(capsys, "--config", str(other), str(tmp_path / "t.xml"))
    assert "missing-format" not in codes(out)
    code, _, err = run(capsys, "--config", str(tmp_path / "none.toml"), str(tmp_path))
    assert code == 2 and "config-error cannot read the file" in err
    py = write(tmp_path / "pyproject.toml", '[project]\nname = "x"\n')
    code, _, err = run(capsys, "--config", str(py), str(tmp_path))
    assert code == 2 and "has no [tool.bt-lsp] table" in err


def test_an_installed_dependency_catalog_is_authoritative(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """A ROS package depending (through another) on an installed package found through
    AMENT_PREFIX_PATH gets its shipped catalog: its nodes are known, and an attribute that
    is not one of their ports is an error (BehaviorTree.CPP throws at tree creation)."""
    share = tmp_path / "opt" / "share"
    write(
        share / "nav2_behavior_tree" / "package.xml",
        "<package><name>nav2_behavior_tree</name></package>",
    )
    write(
        share / "nav2_behavior_tree" / "nav2_tree_nodes.xml",
        "<root>\n  <!-- nodes -->\n  <TreeNodesModel>\n"
        '    <Action ID="Go"><input_port name="speed"/></Action>\n'
        "  </TreeNodesModel>\n</root>\n",
    )
    src = tmp_path / "ws" / "src"
    write(
        src / "lib" / "package.xml",
        "<package><name>lib</name><depend>nav2_behavior_tree</depend></package>",
    )
    write(
        src / "app" / "package.xml",
        "<package><name>app</name><exec_depend>lib</exec_depend></package>",
    )
    write(src / "app" / "launch" / "a.launch.xml", "<launch/>")
    tree = write(
        src / "app" / "trees" / "t.xml",
        '<root BTCPP_format="4" main_tree_to_execute="T">\n'
        '  <BehaviorTree ID="T"><Sequence><Go speed="1" sped="2"/></Sequence></BehaviorTree>\n'
        "</root>\n",
    )
    monkeypatch.setenv("AMENT_PREFIX_PATH", str(tmp_path / "opt"))
    code, out, _ = run(capsys, str(tmp_path / "ws"))
    assert code == 1
    assert [line.split(": ", 1)[1].split()[:2] for line in out.splitlines()] == [
        ["error", "undeclared-port"]
    ]
    assert out.startswith(f"{tree}:2:")
    monkeypatch.setenv("AMENT_PREFIX_PATH", "")
    code, out, _ = run(capsys, str(tmp_path / "ws"))
    assert "undeclared-port" not in codes(out)  # nothing is known of Go
