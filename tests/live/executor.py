"""A BehaviorTree.CPP executor for the live tests: a small tree ticking with a
Groot2Publisher on 127.0.0.1:PORT (and PORT + 1), for at most SECONDS.

Run as ``python executor.py PORT SECONDS [NODES]``.  It prints ``ready`` once the
publisher is up, then ``result STATUS`` each time the tree finishes (and starts it again).
With NODES, the tree is a Sequence of that many AlwaysSuccess nodes (for the CPU figure).
"""

from __future__ import annotations

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
    nodes = int(sys.argv[3]) if len(sys.argv) > 3 else 0
    factory = bt.BehaviorTreeFactory()
    factory.register_behavior_tree_from_text(wide(nodes) if nodes else TREE)
    tree = factory.create_tree("Main")
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
