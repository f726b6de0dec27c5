"""The C++ reader: every registration and port form, each limit's flag, the cache."""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any

import pytest

from bt_lsp.cpp.catalog import link
from bt_lsp.cpp.extract import extract
from bt_lsp.cpp.facts import from_json, to_json
from bt_lsp.cpp.library import library_facts
from bt_lsp.project.cpp_scan import Scanner, find_cpp_files, scan

DATA = Path(__file__).parent / "data" / "cpp"
FIXTURES = sorted(d.name for d in DATA.iterdir() if d.is_dir())


def _summary(catalog: Any) -> dict[str, Any]:
    return {
        n.id: {
            "kind": n.kind,
            "flags": list(n.flags),
            "ports": [[p.name, p.direction, p.type, p.default, p.description] for p in n.ports],
        }
        for n in catalog.nodes
    }


@pytest.mark.parametrize("name", FIXTURES)
def test_fixture_catalog(name: str) -> None:
    folder = DATA / name
    catalog = scan(find_cpp_files([folder]), Scanner(None))
    expected = json.loads((folder / "expected.json").read_text())
    assert _summary(catalog) == expected


def test_every_form_has_a_fixture() -> None:
    assert set(FIXTURES) >= {
        "register_node_type",
        "register_builder",
        "macro",
        "ros2",
        "simple",
        "manifest",
        "port_lists",
        "inheritance",
        "constants",
        "limits",
        "declared_only",
        "helper",
        "manifest_local",
        "basic_ports",
        "literal_defaults",
        "macro_composed",
        "registrar",
        "template_base",
    }


def test_limits_say_why() -> None:
    catalog = scan(find_cpp_files([DATA / "limits"]), Scanner(None))
    notes = {n.id: " ".join(n.notes) for n in catalog.nodes}
    assert "vendor::FancyAction" in notes["Vendored"]
    assert "makePorts<Built>()" in notes["Built"]
    assert "nav2_release" in notes["Spin"]
    assert "expression" in notes["Wait"]
    assert "also registered" in notes["Twin"]
    by_id = catalog.by_id
    # Every flag makes a node advisory, a default written as an expression too.
    assert not by_id["Wait"].authoritative
    assert not by_id["Built"].authoritative
    assert not by_id["Twin"].authoritative
    # A template helper called with an ID that is not a literal: not guessed.
    assert [u.text for u in catalog.unresolved] == ["computed_name"]


def test_unregistered_class_is_not_in_the_catalog() -> None:
    catalog = scan(find_cpp_files([DATA / "register_node_type"]), Scanner(None))
    assert "NeverRegistered" not in catalog.by_id
    assert all(n.cls != "demo::NeverRegistered" for n in catalog.nodes)


def test_positions_of_registration_class_and_port() -> None:
    catalog = scan(find_cpp_files([DATA / "register_node_type"]), Scanner(None))
    node = catalog.by_id["SaySomething"]
    assert node.path.endswith("nodes.cpp")
    lines = (DATA / "register_node_type" / "nodes.cpp").read_text().splitlines()

    def at(needle: str, line_has: str) -> tuple[int, int]:
        row = next(i for i, t in enumerate(lines) if line_has in t)
        return row, lines[row].index(needle)

    assert node.id_span[:2] == at('"SaySomething"', "registerNodeType<demo::SaySomething>")
    assert node.class_span is not None
    assert node.class_span[:2] == at("SaySomething", "class SaySomething")
    message = node.port("message")
    assert message is not None and message.span[:2] == at('"message"', '"message"')


def test_columns_count_code_points() -> None:
    src = (
        "// é 𝄞\nstruct A : BT::SyncActionNode { static BT::PortsList providedPorts() "
        '{ return {}; } };\nvoid f(F& f) { /* 𝄞é */ f.registerNodeType<A>("A"); }\n'
    ).encode()
    node = link([("a.cpp", extract(src))]).by_id["A"]
    line = src.decode().splitlines()[2]
    assert node.id_span == (2, line.index('"A"'), 2, line.index('"A"') + 3)


def test_lazy_base_from_a_file_without_registrations(tmp_path: Path) -> None:
    (tmp_path / "base.hpp").write_text(
        "class Mover : public BT::StatefulActionNode { public: int speed; };\n"
    )
    (tmp_path / "node.cpp").write_text(
        "class Go : public Mover { public: static BT::PortsList providedPorts() "
        '{ return { BT::InputPort<int>("to") }; } };\n'
        'BT_REGISTER_NODES(factory) { factory.registerNodeType<Go>("Go"); }\n'
    )
    sc = Scanner(None)
    catalog = scan(find_cpp_files([tmp_path]), sc)
    assert catalog.by_id["Go"].kind == "Action"
    assert catalog.by_id["Go"].authoritative
    assert sc.parsed == 2  # base.hpp was read only because Go's base was missing


def test_facts_round_trip_through_json() -> None:
    for folder in FIXTURES:
        for f in find_cpp_files([DATA / folder]):
            facts = extract(f.read_bytes())
            assert from_json(json.loads(json.dumps(to_json(facts)))) == facts


def test_cache_reused_across_scanners_and_corrupt_entries_rewritten(tmp_path: Path) -> None:
    cache = tmp_path / "cache"
    files = find_cpp_files([DATA / "ros2"])
    first = Scanner(cache)
    expected = _summary(scan(files, first))
    assert first.parsed == 1
    entries = [p for p in cache.rglob("*.json")]
    assert len(entries) == 1
    second = Scanner(cache)
    assert _summary(scan(files, second)) == expected
    assert second.parsed == 0  # read from the cache
    entries[0].write_text('{"not": "facts"')
    third = Scanner(cache)
    assert _summary(scan(files, third)) == expected
    assert third.parsed == 1
    assert from_json(json.loads(entries[0].read_text())) is not None  # rewritten
    assert not [p for p in cache.rglob(".tmp-*")]


def test_unwritable_cache_only_costs_time(tmp_path: Path) -> None:
    blocker = tmp_path / "file"
    blocker.write_text("")
    catalog = scan(find_cpp_files([DATA / "simple"]), Scanner(blocker / "cache"))
    assert set(catalog.by_id) == {"Say", "CheckBattery", "Twice"}


def test_find_cpp_files_skips_build_folders_and_excludes(tmp_path: Path) -> None:
    for rel in ("src/a.cpp", "include/p/a.hpp", "build/gen.cpp", "log/x.cc", "src/t/x_test.cpp"):
        p = tmp_path / rel
        p.parent.mkdir(parents=True, exist_ok=True)
        p.write_text("")
    (tmp_path / "src" / "notes.txt").write_text("")
    found = [p.relative_to(tmp_path).as_posix() for p in find_cpp_files([tmp_path])]
    assert found == ["include/p/a.hpp", "src/a.cpp", "src/t/x_test.cpp"]
    kept = find_cpp_files([tmp_path], exclude=["*_test.cpp"])
    assert [p.name for p in kept] == ["a.hpp", "a.cpp"]


def test_library_bases_lose_to_the_projects_own(tmp_path: Path) -> None:
    (tmp_path / "own.hpp").write_text(
        "namespace BT { template <class A> class RosActionNode : public BT::ActionNodeBase {\n"
        "public: static PortsList providedBasicPorts(PortsList addition) {\n"
        '  PortsList basic = { InputPort<std::string>("server_name") };\n'
        "  basic.insert(addition.begin(), addition.end()); return basic; } }; }\n"
        "class Nav : public BT::RosActionNode<X> { public: static BT::PortsList providedPorts()"
        " { return providedBasicPorts({}); } };\n"
        'CreateRosNodePlugin(Nav, "Nav")\n'
    )
    node = scan(find_cpp_files([tmp_path]), Scanner(None)).by_id["Nav"]
    assert [p.name for p in node.ports] == ["server_name"]
    assert library_facts()[0][1].classes  # the library is still there for others


def test_hostile_text_never_raises() -> None:
    for src in (
        b"",
        b"\xff\xfe\x00garbage",
        b"class {",
        b"providedPorts(" * 500,
        b"#define X(" * 50,
    ):
        link([("x.cpp", extract(src))], library_facts())


def test_cache_dir_follows_xdg(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    from bt_lsp.project.cpp_scan import default_cache_dir

    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    assert default_cache_dir() == tmp_path / "bt-lsp" / "cpp"
    monkeypatch.delenv("XDG_CACHE_HOME")
    assert default_cache_dir() == Path(os.path.expanduser("~")) / ".cache" / "bt-lsp" / "cpp"


def test_a_source_file_no_target_builds_comes_after_the_built_one() -> None:
    """``not_built``: the plugin's Takeoff (its class in a header, ports out of line) is
    the ID's node; the copy that no target builds is flagged, and, as it registers
    another class under the same ID, neither port list is authoritative."""
    catalog = scan(find_cpp_files([DATA / "not_built"]), Scanner(None))
    node = catalog.by_id["Takeoff"]
    assert node.path.endswith("takeoff.cpp")
    assert node.class_path is not None and node.class_path.endswith("takeoff.h")
    assert [p.name for p in node.ports] == ["goal", "is_rc"]
    assert node.flags == ("duplicate-id",)
    assert "(a file that is not built)" in " ".join(node.notes)
    assert not node.authoritative
    copy = next(n for n in catalog.nodes if n.id == "Takeoff" and n is not node)
    assert copy.path.endswith("mission (copy).cpp")
    assert "lists mission (copy).cpp among its sources" in copy.notes[0]
    assert "CMakeLists.txt" in copy.notes[0]
    assert not catalog.by_id["MoveUp"].authoritative


def test_a_class_defined_in_another_source_file_is_not_the_one_registered(
    tmp_path: Path,
) -> None:
    """Two classes of one name: the registering file sees its header's, never one that
    another source file defines for itself."""
    (tmp_path / "go.h").write_text(
        "class Go : public BT::SyncActionNode { public: static BT::PortsList providedPorts(); };\n"
    )
    (tmp_path / "a_old.cpp").write_text(
        "class Go : public BT::StatefulActionNode { public: static BT::PortsList "
        'providedPorts() { return { BT::InputPort<int>("old") }; } };\n'
    )
    (tmp_path / "go.cpp").write_text(
        '#include "go.h"\nBT::PortsList Go::providedPorts() '
        '{ return { BT::InputPort<int>("to") }; }\n'
        'BT_REGISTER_NODES(factory) { factory.registerNodeType<Go>("Go"); }\n'
    )
    node = scan(find_cpp_files([tmp_path]), Scanner(None)).by_id["Go"]
    assert node.class_path is not None and node.class_path.endswith("go.h")
    assert [p.name for p in node.ports] == ["to"]
    assert node.flags == ()


def test_simple_nodes_registered_alike_by_two_programs_are_one_node(tmp_path: Path) -> None:
    program = (
        "int main() { BT::BehaviorTreeFactory f; "
        'BT::PortsList ports = { BT::InputPort<std::string>("message") };\n'
        'f.registerSimpleAction("Log", Log, ports); }\n'
    )
    (tmp_path / "a.cpp").write_text(program)
    (tmp_path / "b.cpp").write_text(program)
    (tmp_path / "c.cpp").write_text(
        'int main() { BT::BehaviorTreeFactory f; f.registerSimpleAction("Log", Log, '
        '{ BT::InputPort<int>("level") }); }\n'
    )
    catalog = scan(find_cpp_files([tmp_path / "a.cpp", tmp_path / "b.cpp"]), Scanner(None))
    assert catalog.by_id["Log"].flags == ()
    catalog = scan(find_cpp_files([tmp_path]), Scanner(None))
    assert catalog.by_id["Log"].flags == ("duplicate-id",)
