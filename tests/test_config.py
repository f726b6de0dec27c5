"""bt-lsp.toml / [tool.bt-lsp]: discovery, parsing, errors with their position, and how
the file's settings sit between the editor settings and command-line flags."""

from __future__ import annotations

from pathlib import Path

import pytest

from bt_lsp.project.config import (
    ConfigError,
    Configs,
    Layer,
    find_config,
    load_config,
)
from bt_lsp.project.index import ProjectIndex
from bt_lsp.project.settings import Settings
from bt_lsp.rules.codes import Severity


def write(path: Path, text: str) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text, encoding="utf-8")
    return path


def error_of(path: Path) -> ConfigError:
    with pytest.raises(ConfigError) as info:
        load_config(path)
    return info.value


def test_every_key_parsed_with_paths_relative_to_the_file(tmp_path: Path) -> None:
    cfg = write(
        tmp_path / "proj" / "bt-lsp.toml",
        'models = ["gen/nodes.xml", "/abs/other.btproj"]\n'
        'btcpp = "3"\n'
        'exclude = ["generated", "test/fixtures/*.xml"]\n'
        'sources = ["src/**/*.cpp"]\n'
        "[severity]\n"
        'unknown-node = "warning"\n'
        'missing-format = "off"\n'
        "[ros-packages]\n"
        'nav = "../share/nav"\n',
    )
    c = load_config(cfg)
    assert c is not None
    base = (tmp_path / "proj").as_posix()
    assert c.models == (tmp_path / "proj" / "gen" / "nodes.xml", Path("/abs/other.btproj"))
    assert c.btcpp == "3"
    assert c.severity == {"unknown-node": Severity.WARNING, "missing-format": None}
    assert c.exclude == (f"{base}/**/generated", f"{base}/test/fixtures/*.xml")
    assert c.sources == (f"{base}/src/**/*.cpp",)
    assert c.ros_packages == {"nav": str(tmp_path / "share" / "nav")}


def test_btcpp_may_be_an_integer(tmp_path: Path) -> None:
    c = load_config(write(tmp_path / "bt-lsp.toml", "btcpp = 4\n"))
    assert c is not None and c.btcpp == "4"


def test_pyproject_table(tmp_path: Path) -> None:
    py = write(
        tmp_path / "pyproject.toml",
        '[project]\nname = "x"\n\n[tool.bt-lsp]\nbtcpp = "4"\n\n[tool.bt-lsp.severity]\n'
        'unknown-node = "error"\n',
    )
    c = load_config(py)
    assert c is not None
    assert c.btcpp == "4" and c.severity == {"unknown-node": Severity.ERROR}


def test_pyproject_without_the_table_is_not_a_configuration(tmp_path: Path) -> None:
    py = write(tmp_path / "pyproject.toml", '[project]\nname = "x"\n')
    assert load_config(py) is None
    assert find_config(tmp_path) is None
    # Even a broken pyproject is not ours to report unless it has our table.
    write(tmp_path / "pyproject.toml", "[project\n")
    assert find_config(tmp_path) is None


def test_found_upward_nearest_first_and_bt_lsp_toml_before_pyproject(tmp_path: Path) -> None:
    top = write(tmp_path / "bt-lsp.toml", 'btcpp = "4"\n')
    write(tmp_path / "a" / "pyproject.toml", '[tool.bt-lsp]\nbtcpp = "3"\n')
    inner = write(tmp_path / "a" / "bt-lsp.toml", 'btcpp = "3"\n')
    deep = tmp_path / "a" / "b" / "c"
    deep.mkdir(parents=True)
    assert find_config(deep / "tree.xml") == inner
    assert find_config(tmp_path / "other" / "tree.xml") == top
    (tmp_path / "a" / "bt-lsp.toml").unlink()
    assert find_config(deep) == tmp_path / "a" / "pyproject.toml"


def test_syntax_error_has_its_line_and_column(tmp_path: Path) -> None:
    e = error_of(write(tmp_path / "bt-lsp.toml", 'btcpp = "4"\nmodels = ["a.xml"\nx = 1\n'))
    assert (e.line, e.column) == (3, 1)
    assert e.message.startswith("TOML syntax error:")
    assert "(at line" not in e.message
    assert str(e).startswith(f"{tmp_path / 'bt-lsp.toml'}:3:1: ")


def test_syntax_error_at_the_end(tmp_path: Path) -> None:
    e = error_of(write(tmp_path / "bt-lsp.toml", 'btcpp = "4'))
    assert e.line == 1
    assert e.message.startswith("TOML syntax error")


def test_wrong_type_points_at_the_key(tmp_path: Path) -> None:
    e = error_of(write(tmp_path / "bt-lsp.toml", '# models\nbtcpp = "4"\n  models = "a.xml"\n'))
    assert (e.line, e.column) == (3, 3)
    assert e.message == "'models' must be a list of strings"


def test_bad_btcpp(tmp_path: Path) -> None:
    e = error_of(write(tmp_path / "bt-lsp.toml", 'btcpp = "5"\n'))
    assert (e.line, e.column) == (1, 1)
    assert '"5"' in e.message


def test_unknown_key_suggests_the_dashed_spelling(tmp_path: Path) -> None:
    e = error_of(write(tmp_path / "bt-lsp.toml", 'btcpp = "4"\n\nros_packages = {}\n'))
    assert (e.line, e.column) == (3, 1)
    assert "unknown key 'ros_packages'" in e.message and "'ros-packages'" in e.message


def test_bad_severity_in_a_subtable_of_pyproject(tmp_path: Path) -> None:
    e = error_of(
        write(
            tmp_path / "pyproject.toml",
            '[tool.bt-lsp]\nbtcpp = "4"\n[tool.bt-lsp.severity]\nunknown-node = "warn"\n'
            '"no-such-code" = "error"\n',
        )
    )
    assert (e.line, e.column) == (4, 1)
    assert "unknown-node" in e.message
    e = error_of(
        write(tmp_path / "pyproject.toml", '[tool.bt-lsp.severity]\n"no-such-code" = "error"\n')
    )
    assert (e.line, e.column) == (2, 1)
    assert "unknown code 'no-such-code'" in e.message


def test_not_utf8(tmp_path: Path) -> None:
    p = tmp_path / "bt-lsp.toml"
    p.write_bytes(b'btcpp = "4"\nmodels = ["\xff"]\n')
    e = error_of(p)
    assert (e.line, e.column) == (2, 12)


def test_layer_precedence_flags_over_file_over_editor(tmp_path: Path) -> None:
    write(
        tmp_path / "bt-lsp.toml",
        'btcpp = "3"\nmodels = ["cat.xml"]\n[severity]\nunknown-node = "warning"\n',
    )
    editor = Settings(
        severity={"unknown-node": Severity.HINT, "missing-format": None},
        btcpp="4",
        debounce_ms=7,
    )
    ws = ProjectIndex([tmp_path], editor)
    s = ws.settings_for(tmp_path / "t.xml")
    assert s.btcpp == "3"  # the file over the editor
    assert s.models == (tmp_path / "cat.xml",)
    # Severities merge code by code: the editor's other codes stay.
    assert s.severity == {"unknown-node": Severity.WARNING, "missing-format": None}
    assert s.debounce_ms == 7  # what the file leaves unset
    flags = ProjectIndex([tmp_path], editor, overrides=Layer(btcpp="4", models=(Path("/m.xml"),)))
    s = flags.settings_for(tmp_path / "t.xml")
    assert s.btcpp == "4" and s.models == (Path("/m.xml"),)


def test_broken_file_is_an_error_and_the_editor_settings_stay(tmp_path: Path) -> None:
    write(tmp_path / "bt-lsp.toml", "btcpp = [\n")
    ws = ProjectIndex([tmp_path], Settings(btcpp="4"))
    assert ws.settings_for(tmp_path / "t.xml").btcpp == "4"
    [err] = ws.config_errors()
    assert err.path == tmp_path / "bt-lsp.toml"
    # Fixed on disk: the change is heard and the file read again.
    write(tmp_path / "bt-lsp.toml", 'btcpp = "3"\n')
    ws.file_changed(tmp_path / "bt-lsp.toml")
    assert ws.config_errors() == []
    assert ws.settings_for(tmp_path / "t.xml").btcpp == "3"


def test_explicit_file_applies_everywhere(tmp_path: Path) -> None:
    write(tmp_path / "near" / "bt-lsp.toml", 'btcpp = "4"\n')
    explicit = write(tmp_path / "elsewhere.toml", 'btcpp = "3"\n')
    configs = Configs(explicit)
    assert configs.path_for(tmp_path / "near" / "t.xml") == explicit
    ws = ProjectIndex([tmp_path], configs=configs)
    assert ws.settings_for(tmp_path / "near" / "t.xml").btcpp == "3"


def test_editor_settings_parse_btcpp_and_model_files() -> None:
    problems: list[str] = []
    s = Settings.parse({"btcpp": "3", "modelFiles": ["a.xml"]}, problems)
    assert s.btcpp == "3" and s.models == (Path("a.xml"),) and problems == []
    s = Settings.parse({"btcpp": "2"}, problems)
    assert s.btcpp == "auto" and problems and "btcpp" in problems[0]


def _touch_later(path: Path, text: str) -> None:
    """Write ``text`` with a modification time surely different from the previous one."""
    import os

    before = path.stat().st_mtime_ns if path.exists() else 0
    path.write_text(text, encoding="utf-8")
    os.utime(path, ns=(before + 10**9, before + 10**9))


def test_revalidate_finds_configuration_files_created_changed_or_deleted(tmp_path: Path) -> None:
    """For clients that do not watch files: what was looked for or read is compared with
    the disk, and only a change of the configuration that applies is reported."""
    sub = tmp_path / "pkg" / "trees"
    sub.mkdir(parents=True)
    tree = sub / "a.xml"
    tree.write_text("<root/>", encoding="utf-8")
    configs = Configs()
    assert configs.for_path(tree) is None
    assert configs.revalidate() == []

    (sub / "notes.txt").write_text("x", encoding="utf-8")  # the folder changes, no config
    assert configs.revalidate() == []

    config = tmp_path / "pkg" / "bt-lsp.toml"
    config.write_text('btcpp = "3"\n', encoding="utf-8")  # in a folder above: found
    assert configs.revalidate() == [config]
    found = configs.for_path(tree)
    assert isinstance(found, Layer) and found.btcpp == "3"

    _touch_later(config, 'btcpp = "4"\n')
    assert configs.revalidate() == [config]
    found = configs.for_path(tree)
    assert isinstance(found, Layer) and found.btcpp == "4"

    # A pyproject.toml nearer the file counts once it has a [tool.bt-lsp] table.
    pyproject = sub / "pyproject.toml"
    pyproject.write_text("[project]\nname = 'x'\n", encoding="utf-8")
    assert configs.revalidate() == []
    assert configs.path_for(tree) == config
    _touch_later(pyproject, "[tool.bt-lsp]\nbtcpp = '3'\n")
    assert configs.revalidate() == [config, pyproject]
    assert configs.path_for(tree) == pyproject

    pyproject.unlink()
    config.unlink()
    assert configs.revalidate() == [pyproject]
    assert configs.for_path(tree) is None
