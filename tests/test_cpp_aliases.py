"""Type aliases of the project's C++: read (every form), followed when port types are
compared, and what cannot be followed proves nothing."""

from __future__ import annotations

import re
import shutil
from pathlib import Path

import pytest

from bt_lsp.cpp.catalog import link
from bt_lsp.cpp.extract import extract
from bt_lsp.cpp.facts import AliasFacts
from bt_lsp.cpp.library import library_facts
from bt_lsp.project.cpp_scan import Scanner, find_cpp_files, scan
from bt_lsp.rules.port_types import canonical, is_closed
from tests.pinned import main  # bt-lsp as the tests know it (tests/pinned.py)

FLEET = Path(__file__).parent / "data" / "cpp" / "aliases"


@pytest.fixture(autouse=True)
def _cache(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))


def test_every_alias_form_is_read_with_its_scope() -> None:
    src = b"""
typedef unsigned long Big;
namespace a { namespace b {
using P = geometry_msgs::msg::PoseStamped;
typedef std::shared_ptr<Task> TaskPtr, *TaskRaw;
template <class T> using Vec = std::vector<T>;
using geometry_msgs::msg::Pose;
using namespace std;
typedef struct { int x; } Anonymous;
class Node : public BT::SyncActionNode {
  using Base = BT::SyncActionNode;
  typedef int Id;
  typedef void (*Callback)(int);
  void f() { using Local = int; typedef int AlsoLocal; struct L { using InLocal = int; }; }
};
}}
namespace c::d { typedef const a::b::Node& NodeRef; }
#ifdef WITH_E
namespace e { using Q = double; }
#endif
"""
    assert extract(src).aliases == (
        AliasFacts("Big", "unsigned long"),
        AliasFacts("a::b::P", "geometry_msgs::msg::PoseStamped"),
        AliasFacts("a::b::TaskPtr", "std::shared_ptr<Task>"),
        AliasFacts("a::b::TaskRaw", "std::shared_ptr<Task>*"),
        AliasFacts("a::b::Vec", "std::vector<T>", ("T",)),
        AliasFacts("a::b::Pose", "geometry_msgs::msg::Pose"),
        AliasFacts("a::b::Node::Base", "BT::SyncActionNode"),
        AliasFacts("a::b::Node::Id", "int"),
        AliasFacts("c::d::NodeRef", "const a::b::Node&"),
        AliasFacts("e::Q", "double"),
    )


def _ports(folder: Path) -> dict[tuple[str, str], tuple[str | None, list[str]]]:
    catalog = scan(find_cpp_files([folder]), Scanner(None))
    return {(n.id, p.name): (p.resolved, sorted(p.classes)) for n in catalog.nodes for p in n.ports}


def test_port_types_are_resolved_through_the_projects_aliases() -> None:
    ports = _ports(FLEET)
    task = ("std::shared_ptr<fleet::Task>", ["fleet::Task"])
    assert ports["Plan", "task"] == task  # using, from a header read for it
    assert ports["Run", "task"] == task  # the class's namespace, from an out-of-line body
    assert ports["Plan", "goal"] == ("geometry_msgs::msg::PoseStamped", [])
    assert ports["Plan", "mission"] == ports["Run", "mission"]  # typedef, qualified
    assert ports["Plan", "tasks"] == ports["Run", "tasks"]  # an alias template
    assert ports["Plan", "cmd"] == ("geometry_msgs::msg::Twist", [])  # using-declaration
    assert ports["Plan", "level"] == ("int", [])  # typedef in the class
    assert ports["Plan", "count"] == ("std::uint16_t", [])  # using in the class, qualified
    assert ports["Plan", "job"] == ("fleet::Task", ["fleet::Task"])
    # What cannot be known stays as it is, and names no class.
    assert ports["Spin", "error_code"] == (
        "nav2_msgs::action::Spin::Result::_error_code_type",
        [],
    )
    # A member of the base (a template parameter's), not the namespace's class fleet::Goal.
    assert ports["Spin", "goal"] == ("ActionT::Goal", [])
    assert ports["Spin", "task"] == ("ExternalPtr", [])


def test_the_header_that_defines_the_aliases_is_read_lazily() -> None:
    sc = Scanner(None)
    catalog = scan(find_cpp_files([FLEET]), sc)
    assert sc.parsed == 2  # nodes.cpp, then types.hpp for the names it defines
    assert "ExternalPtr" in catalog.missing


def _mismatches(capsys: pytest.CaptureFixture[str], root: Path) -> list[tuple[int, str, str]]:
    main(["check", str(root)])
    out = []
    for line in capsys.readouterr().out.splitlines():
        m = re.match(r".*fleet\.xml:(\d+):\d+: (\w+) blackboard-type-mismatch (.*)", line)
        if m:
            out.append((int(m.group(1)), m.group(2), m.group(3)))
    return out


def test_only_types_known_to_differ_mismatch(capsys: pytest.CaptureFixture[str]) -> None:
    found = _mismatches(capsys, FLEET)
    assert [(line, sev) for line, sev, _ in found] == [(7, "error"), (7, "error")]
    job, level = (msg for _, _, msg in found)
    # Two classes of the project: a real mismatch, shown with what the names resolve to.
    assert "'job'" in job and "Task (that is, fleet::Task)" in job
    assert "Mission (that is, fleet::Mission)" in job
    # An alias of a built-in type against another built-in type.
    assert "'level'" in level and "Level (that is, int)" in level and "double" in level
    # Spin (line 8): _error_code_type against uint16_t, ActionT::Goal against a pose, an
    # alias from outside the project against a shared pointer: nothing proven.


def test_a_changed_alias_links_its_nodes_again(tmp_path: Path) -> None:
    root = tmp_path / "fleet"
    shutil.copytree(FLEET, root)
    sc = Scanner(None)
    files = find_cpp_files([root])
    before = scan(files, sc).by_id["Plan"].port("task")
    assert before is not None and before.resolved == "std::shared_ptr<fleet::Task>"
    header = root / "include" / "fleet" / "types.hpp"
    header.write_text(
        header.read_text().replace(
            "using TaskPtr = std::shared_ptr<Task>;", "using TaskPtr = std::shared_ptr<Mission>;"
        )
    )
    after = scan(files, sc).by_id["Plan"].port("task")
    assert after is not None and after.resolved == "std::shared_ptr<fleet::Mission>"


def _resolved(src: str) -> dict[str, str | None]:
    catalog = link([("a.cpp", extract(src.encode()))], library_facts())
    return {p.name: p.resolved for n in catalog.nodes for p in n.ports}


def test_a_simple_node_finds_only_names_defined_once() -> None:
    # A port list given at the registration: its scope is not known, so a name resolves
    # only when the project defines it once at namespace scope.
    src = """
namespace a { struct Task {}; struct Pose {}; using Id = int; }
namespace b { struct Pose {}; }
void reg(BT::BehaviorTreeFactory& f) {
  f.registerSimpleAction("S", tick, { BT::InputPort<Task>("t"), BT::InputPort<Pose>("p"),
                                      BT::InputPort<Id>("i"), BT::InputPort<a::Pose>("q") });
}
"""
    assert _resolved(src) == {"t": "a::Task", "p": "Pose", "i": "int", "q": "a::Pose"}


def test_a_name_a_base_outside_the_project_may_declare_is_not_resolved() -> None:
    # RosActionNode (BehaviorTree.ROS2) is not read: `Goal` may be its member type.
    src = """
namespace a {
struct Goal {};
class Go : public BT::RosActionNode<nav2_msgs::action::Spin> {
 public:
  static BT::PortsList providedPorts() { return providedBasicPorts({BT::InputPort<Goal>("g")}); }
};
class Stay : public BT::SyncActionNode {
 public:
  static BT::PortsList providedPorts() { return {BT::InputPort<Goal>("h")}; }
};
}
BT_REGISTER_NODES(f) { f.registerNodeType<a::Go>("Go"); f.registerNodeType<a::Stay>("Stay"); }
"""
    found = _resolved(src)
    assert found["g"] == "Goal"
    assert found["h"] == "a::Goal"


def test_project_classes_are_closed_only_when_resolved() -> None:
    assert not is_closed(canonical("std::shared_ptr<fleet::Task>") or "")
    assert is_closed(canonical("std::shared_ptr<fleet::Task>") or "", frozenset({"fleet::Task"}))
    assert not is_closed(
        canonical("fleet::Task::Ptr") or "", frozenset({"fleet::Task"})
    )  # a member of a class that was not read


def test_a_class_local_to_a_function_is_not_seen_outside_it() -> None:
    src = """
namespace a {
void helper() { struct Pose { int x; }; }
class Go : public BT::SyncActionNode {
 public:
  static BT::PortsList providedPorts() { return {BT::InputPort<Pose>("p")}; }
};
}
BT_REGISTER_NODES(f) { f.registerNodeType<a::Go>("Go"); }
"""
    assert _resolved(src) == {"p": "Pose"}
