"""Base classes of libraries that projects derive their nodes from, as C++ for the reader.

BehaviorTree.ROS2's bases add one port through ``providedBasicPorts`` (the port names
and defaults of its 0.x releases); its ``CreateRosNodePlugin`` macro registers a class.
Nav2's ``BtActionNode``, ``BtServiceNode`` and ``BtCancelActionNode`` are actions whose
basic ports differ between Nav2 releases: their kind is known, their ports are not (a
node built on them is advisory unless Nav2's own sources are read).  The project's own
classes of the same name win over these.
"""

from __future__ import annotations

from functools import cache
from typing import Final

from bt_lsp.cpp.extract import extract
from bt_lsp.cpp.facts import FileFacts

LIBRARY_PATH: Final = "<library bases>"

# (class, template parameter, BehaviorTree.CPP base, port, description)
_ROS2_BASES: Final = (
    ("RosActionNode", "ActionT", "ActionNodeBase", "action_name", "Action server name"),
    ("RosServiceNode", "ServiceT", "ActionNodeBase", "service_name", "Service name"),
    ("RosTopicSubNode", "TopicT", "ConditionNode", "topic_name", "Topic name"),
    ("RosTopicPubNode", "TopicT", "ConditionNode", "topic_name", "Topic name"),
)
_NAV2_BASES: Final = (
    ("BtActionNode", "ActionT"),
    ("BtServiceNode", "ServiceT"),
    ("BtCancelActionNode", "ActionT"),
)
# Bases of BehaviorTree.ROS2 forks (RoboMaster sentry projects): a stateful action whose
# basic ports are the fork's, not known here.
_FORK_BASES: Final = (("RosTopicPubStatefulActionNode", "TopicT", "StatefulActionNode"),)


def _source() -> bytes:
    out = [
        "#define CreateRosNodePlugin(TYPE, REGISTRATION_NAME) \\",
        "  factory.registerNodeType<TYPE>(REGISTRATION_NAME, params);",
        "namespace BT {",
    ]
    for cls, param, base, port, desc in _ROS2_BASES:
        out += [
            f"template <class {param}> class {cls} : public {base} {{",
            "  static PortsList providedBasicPorts(PortsList addition) {",
            f'    PortsList basic = {{InputPort<std::string>("{port}",',
            f'      "__default__placeholder__", "{desc}")}};',
            "    basic.insert(addition.begin(), addition.end());",
            "    return basic;",
            "  }",
            "  static PortsList providedPorts() { return providedBasicPorts({}); }",
            "};",
        ]
    for cls, param, base in _FORK_BASES:
        out += [
            f"template <class {param}> class {cls} : public {base} {{",
            "  static PortsList providedBasicPorts(PortsList addition) {",
            "    return basic_ports_of_the_fork_built(addition);",
            "  }",
            "  static PortsList providedPorts() { return providedBasicPorts({}); }",
            "};",
        ]
    out += ["}", "namespace nav2_behavior_tree {"]
    for cls, param in _NAV2_BASES:
        out += [
            f"template <class {param}> class {cls} : public BT::ActionNodeBase {{",
            "  static PortsList providedBasicPorts(PortsList addition) {",
            "    return basic_ports_of_the_nav2_release_built(addition);",
            "  }",
            "  static PortsList providedPorts() { return providedBasicPorts({}); }",
            "};",
        ]
    out.append("}")
    return "\n".join(out).encode()


@cache
def library_facts() -> tuple[tuple[str, FileFacts], ...]:
    """The library bases' facts, read once per process."""
    return ((LIBRARY_PATH, extract(_source())),)
