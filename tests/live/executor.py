"""A BehaviorTree.CPP executor for the live tests: a small tree ticking with a
Groot2Publisher on 127.0.0.1:PORT (and PORT + 1), for at most SECONDS.

Run as ``python executor.py PORT SECONDS [NODES | FILE.xml]``.  It prints ``ready`` once
the publisher is up, then ``result STATUS`` each time the tree finishes (and starts it
again).  With NODES, the tree is a Sequence of that many AlwaysSuccess nodes (for the CPU
figure); with FILE.xml, the main tree of that file (``main_tree_to_execute``), its
``<include>`` paths relative to the file.
"""

from __future__ import annotations

import os
import re
import sys
import time

import behaviortreepy as bt

TREE = """<root BTCPP_format="4" main_tree_to_execute="Main">
  <BehaviorTree ID="Main">
    <Sequence name="seq">
      <Script code="counter := counter + 1"/>
      <SubTree ID="Sub" name="sub1" _autoremap="true"/>
      <AlwaysSuccess name="ok"/>
    </Sequence>
  </BehaviorTree>
  <BehaviorTree ID="Sub">
    <Sequence>
      <Sleep msec="30"/>
      <SetBlackboard output_key="msg" value="hello"/>
    </Sequence>
  </BehaviorTree>
</root>"""


def wide(nodes: int) -> str:
    leaves = "".join(f'<AlwaysSuccess name="n{i}"/>' for i in range(nodes - 1))
    return (
        '<root BTCPP_format="4" main_tree_to_execute="Main"><BehaviorTree ID="Main">'
        f"<Sequence>{leaves}</Sequence></BehaviorTree></root>"
    )


def main() -> None:
    port, seconds = int(sys.argv[1]), float(sys.argv[2])
    extra = sys.argv[3] if len(sys.argv) > 3 else ""
    nodes = int(extra) if extra.isdigit() else 0
    text = wide(nodes) if nodes else TREE
    if extra.endswith(".xml"):
        # The binding's register_behavior_tree_from_file does not take a str: the text is
        # registered from the file's folder, where BehaviorTree.CPP resolves its includes
        # (the folder its factory was made in).
        path = os.path.abspath(extra)
        os.chdir(os.path.dirname(path))
        with open(path, encoding="utf-8") as f:
            text = f.read()
    found = re.search(r'main_tree_to_execute="([^"]+)"', text)
    factory = bt.BehaviorTreeFactory()
    factory.register_behavior_tree_from_text(text)
    main_tree = found.group(1) if found else "Main"
    tree = factory.create_tree(main_tree)
    tree.root_blackboard().set_int("counter", 0)
    publisher = bt.Groot2Publisher(tree, port)
    print("ready", flush=True)
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        status = tree.tick_once()
        if status != bt.NodeStatus.RUNNING:
            print("result", str(status).rsplit(".", 1)[-1], flush=True)
            tree.halt_tree()
        time.sleep(0.01 if not nodes else 0.1)
    del publisher


if __name__ == "__main__":
    main()
