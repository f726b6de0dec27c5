"""How fast the C++ catalog is read: cold, warm from the on-disk cache, one file changed.

Generates a synthetic Nav2-like colcon workspace (no network, no Nav2 checkout: the shapes
are Nav2's, the code is made up): a ``bt_core`` package with action/service/condition
bases whose ``providedBasicPorts`` the plugins extend, plugin packages with one header
and one source per node (license header, declarations, a ``tick()`` body of ordinary
robot code, ``BT_REGISTER_NODES`` with a builder lambda), and many other C++ files of
the same style that register nothing (planners, controllers, utilities); a few of them
say ``register`` in passing, as real code does, and so are parsed too.

```sh
python benchmarks/cpp_catalog.py                  # ~7 MB, 3 runs each
python benchmarks/cpp_catalog.py --mb 2 --repeat 5 --json out.json
```

Rows: ``cold`` (an empty cache: every candidate file parsed, facts written), ``warm``
(a new scanner on the same cache: files read and hashed, facts loaded, linked), and
``one changed`` (a scanner that has read everything, after one 50 KB node source
changed: that file parsed again; when its facts are the same, as for typing inside a
function, the catalog is kept, else it is linked again).
"""

from __future__ import annotations

import argparse
import json
import random
import shutil
import statistics
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "src"))

from bt_lsp.project.cpp_models import CppModels  # noqa: E402
from bt_lsp.project.cpp_scan import Scanner, find_cpp_files, scan  # noqa: E402

LICENSE = "".join(
    f"// {line}\n"
    for line in (
        "Copyright (c) 2026 Synthetic Robotics",
        "",
        "Licensed under the Apache License, Version 2.0 (the 'License');",
        "you may not use this file except in compliance with the License.",
        "Unless required by applicable law or agreed to in writing, software",
        "distributed under the License is distributed on an 'AS IS' BASIS,",
        "WITHOUT WARRANTIES OR CONDITIONS OF ANY KIND, either express or implied.",
    )
)

BASES = """{license}
#pragma once
#include <behaviortree_cpp/action_node.h>
#include <rclcpp/rclcpp.hpp>

namespace bt_core
{{
template<class ActionT>
class BtActionNode : public BT::ActionNodeBase
{{
public:
  static BT::PortsList providedBasicPorts(BT::PortsList addition)
  {{
    BT::PortsList basic = {{
      BT::InputPort<std::string>("server_name", "Action server name"),
      BT::InputPort<std::chrono::milliseconds>("server_timeout"),
    }};
    basic.insert(addition.begin(), addition.end());
    return basic;
  }}
  static BT::PortsList providedPorts() {{ return providedBasicPorts({{}}); }}
}};

template<class ServiceT>
class BtServiceNode : public BT::ActionNodeBase
{{
public:
  static BT::PortsList providedBasicPorts(BT::PortsList addition)
  {{
    BT::PortsList basic = {{
      BT::InputPort<std::string>("service_name", "please_set_service_name_in_BT_Node"),
      BT::InputPort<std::chrono::milliseconds>("server_timeout"),
    }};
    basic.insert(addition.begin(), addition.end());
    return basic;
  }}
}};
}}  // namespace bt_core
"""

_TYPES = (
    "double",
    "int",
    "bool",
    "std::string",
    "geometry_msgs::msg::PoseStamped",
    "std::chrono::milliseconds",
    "unsigned int",
    "nav_msgs::msg::Path",
)
_KINDS = (
    ("BtActionNode<msgs::action::{n}>", "bt_core/bases.hpp"),
    ("BtServiceNode<msgs::srv::{n}>", "bt_core/bases.hpp"),
    ("BT::ConditionNode", "behaviortree_cpp/condition_node.h"),
    ("BT::DecoratorNode", "behaviortree_cpp/decorator_node.h"),
)


def _body(rng: random.Random, lines: int) -> str:
    """Ordinary robot code: a function of roughly ``lines`` lines."""
    out = []
    for i in range(lines // 6):
        v = f"value_{i}"
        out += [
            f"  double {v} = msg->data[{i}] * {rng.uniform(0.1, 9.9):.3f};",
            f"  if ({v} > threshold_ && !std::isnan({v})) {{",
            f'    RCLCPP_DEBUG(logger_, "step {i}: %f", {v});',
            f"    accumulated_ += std::min({v}, limit_);",
            "  }",
            f"  history_.push_back({v});",
        ]
    return "\n".join(out)


def _node(rng: random.Random, i: int, pad_to: int = 0) -> tuple[str, str, str]:
    name = f"Node{i:03d}"
    base, include = _KINDS[i % len(_KINDS)]
    base = base.format(n=name)
    ports = []
    for j in range(rng.randint(1, 6)):
        t = rng.choice(_TYPES)
        form = rng.randint(0, 3)
        if form == 0:
            ports.append(f'BT::InputPort<{t}>("in_{j}")')
        elif form == 1:
            ports.append(f'BT::InputPort<{t}>("in_{j}", "Input {j} of {name}")')
        elif form == 2 and t in ("double", "int", "bool", "unsigned int"):
            default = {"double": "0.5", "int": "3", "bool": "true", "unsigned int": "2"}[t]
            ports.append(f'BT::InputPort<{t}>("in_{j}", {default}, "Input {j}")')
        else:
            ports.append(f'BT::OutputPort<{t}>("out_{j}", "Output {j} of {name}")')
    plist = ",\n      ".join(ports)
    uses_basic = "Bt" in base
    body = (
        f"providedBasicPorts({{\n      {plist}\n    }})"
        if uses_basic
        else f"{{\n      {plist}\n    }}"
    )
    header = f"""{LICENSE}
#pragma once
#include <{include}>

namespace plugins
{{
class {name} : public {base if base.startswith("BT::") else "bt_core::" + base}
{{
public:
  {name}(const std::string & xml_tag_name, const BT::NodeConfiguration & conf);
  static BT::PortsList providedPorts()
  {{
    return {body};
  }}
  BT::NodeStatus tick() override;

private:
  double threshold_{{0.0}};
  double limit_{{1.0}};
  double accumulated_{{0.0}};
  std::vector<double> history_;
  rclcpp::Logger logger_{{rclcpp::get_logger("{name}")}};
}};
}}  // namespace plugins
"""
    source = f"""{LICENSE}
#include "plugins/{name.lower()}.hpp"

namespace plugins
{{
{name}::{name}(const std::string & xml_tag_name, const BT::NodeConfiguration & conf)
{{
  (void)xml_tag_name;
  (void)conf;
}}

BT::NodeStatus {name}::tick()
{{
  auto msg = latest_;
{_body(rng, rng.randint(60, 200))}
  return BT::NodeStatus::SUCCESS;
}}
}}  // namespace plugins

#include "behaviortree_cpp/bt_factory.h"
BT_REGISTER_NODES(factory)
{{
  BT::NodeBuilder builder =
    [](const std::string & name, const BT::NodeConfiguration & config)
    {{
      return std::make_unique<plugins::{name}>(name, config);
    }};
  factory.registerBuilder<plugins::{name}>("{name}", builder);
}}
"""
    if pad_to and len(source) < pad_to:
        extra = _body(rng, (pad_to - len(source)) // 40)
        source = source.replace(
            "  return BT::NodeStatus::SUCCESS;", extra + "\n  return BT::NodeStatus::SUCCESS;", 1
        )
    return name, header, source


def _other(rng: random.Random, i: int, size: int) -> str:
    mention = "  // callbacks register with the executor\n" if rng.random() < 0.15 else ""
    parts = [LICENSE, f'#include "util/thing_{i}.hpp"\n\nnamespace util\n{{\n']
    n = 0
    while sum(map(len, parts)) < size:
        step = f"void Thing{i}::step_{n}(const Msg::SharedPtr msg)\n"
        parts.append(f"{step}{{\n{mention}{_body(rng, 40)}\n}}\n\n")
        n += 1
    parts.append("}  // namespace util\n")
    return "".join(parts)


@dataclass
class Tree:
    root: Path
    nodes: int
    files: int
    bytes: int
    changed: Path


def make_tree(root: Path, mb: float = 7.0, nodes: int = 81, seed: int = 1) -> Tree:
    """A Nav2-sized workspace under ``root`` (``mb`` megabytes of C++ in all)."""
    rng = random.Random(seed)
    core = root / "src" / "bt_core"
    (core / "include" / "bt_core").mkdir(parents=True)
    (core / "package.xml").write_text("<package format='3'><name>bt_core</name></package>\n")
    (core / "include" / "bt_core" / "bases.hpp").write_text(BASES.format(license=LICENSE))
    plugins = root / "src" / "bt_plugins"
    (plugins / "include" / "plugins").mkdir(parents=True)
    (plugins / "src").mkdir(parents=True)
    (plugins / "package.xml").write_text(
        "<package format='3'><name>bt_plugins</name><depend>bt_core</depend></package>\n"
    )
    changed = plugins / "src" / "node000.cpp"
    for i in range(nodes):
        name, header, source = _node(rng, i, pad_to=51_500 if i == 0 else 0)
        (plugins / "include" / "plugins" / f"{name.lower()}.hpp").write_text(header)
        (plugins / "src" / f"{name.lower()}.cpp").write_text(source)
    total = sum(f.stat().st_size for f in root.rglob("*.?pp"))
    util = root / "src" / "util" / "src"
    util.mkdir(parents=True)
    i = 0
    target = int(mb * 1024 * 1024)
    while total < target:
        text = _other(rng, i, rng.randint(4_000, 20_000))
        (util / f"thing_{i}.cpp").write_text(text)
        total += len(text)
        i += 1
    files = find_cpp_files([root])
    return Tree(root, nodes, len(files), total, changed)


def measure(tree: Tree, cache: Path) -> dict[str, float]:
    files = find_cpp_files([tree.root])
    shutil.rmtree(cache, ignore_errors=True)
    t0 = time.perf_counter()
    cold = scan(files, Scanner(cache))
    t1 = time.perf_counter()
    assert len(cold.nodes) == tree.nodes, len(cold.nodes)
    warm_scanner = Scanner(cache)
    t2 = time.perf_counter()
    warm = scan(files, warm_scanner)
    t3 = time.perf_counter()
    assert warm_scanner.parsed == 0 and len(warm.nodes) == tree.nodes
    # As the server keeps it: the files' bytes kept by modification time and size, and a
    # change reported for one file (watched files, or an open document's edit).
    models = CppModels([tree.root], scanner=Scanner(cache))
    models.watched = True  # the editor reports every change (watched files)
    scope = tuple(files)
    models.catalog(scope)
    text = tree.changed.read_text()
    figures = {}
    edits = {
        # typing inside a function: no fact changes (same lines), the catalog is kept
        "one changed, in a body": text.replace("accumulated_ +=", "accumulated_ -=", 1),
        # a line added above the registration: its position moves, the catalog is linked
        "one changed, a line added": text.replace(
            "  auto msg = latest_;", "  auto msg = latest_;\n  ++ticks_;", 1
        ),
    }
    for name, edited in edits.items():
        parsed = models.scanner.parsed
        tree.changed.write_text(edited)
        t4 = time.perf_counter()
        models.file_changed(tree.changed)
        again = models.catalog(scope)
        t5 = time.perf_counter()
        figures[name] = t5 - t4
        assert models.scanner.parsed == parsed + 1 and len(again.nodes) == tree.nodes
    tree.changed.write_text(text)
    return {"cold": t1 - t0, "warm": t3 - t2, **figures}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--mb", type=float, default=7.0, help="megabytes of C++ (default 7)")
    ap.add_argument("--nodes", type=int, default=81, help="registered nodes (default 81)")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--json", help="also write the figures here")
    args = ap.parse_args(argv)
    with tempfile.TemporaryDirectory(prefix="bt-lsp-cpp-bench-") as tmp:
        tree = make_tree(Path(tmp) / "ws", args.mb, args.nodes)
        runs = [measure(tree, Path(tmp) / "cache") for _ in range(args.repeat)]
    print(
        f"{tree.files} files, {tree.bytes / 1e6:.1f} MB, {tree.nodes} nodes; "
        f"median of {args.repeat} runs"
    )
    print("| phase | seconds |\n|---|---|")
    out = {}
    for key in runs[0]:
        value = statistics.median(r[key] for r in runs)
        out[key] = value
        print(f"| {key} | {value:.3f} |")
    if args.json:
        Path(args.json).write_text(json.dumps({"files": tree.files, "bytes": tree.bytes, **out}))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
