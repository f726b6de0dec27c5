"""Nav2's stock trees with Nav2's node catalog (``nav2_tree_nodes.xml``) given as the
authoritative catalog, as ``bt-lsp check DIR --models`` does: nothing but real defects.

Nav2 reads most ports without a default as optional (``getInput`` returning false,
``getInputOrBlackboard``), and BehaviorTree.CPP does not check ports at load: the ports
the trees leave out are hints, never warnings.
"""

from __future__ import annotations

import io
import json
from collections import Counter
from pathlib import Path

from bt_lsp.cli import check
from tests.pinned import later_severities

NAV2 = Path(__file__).parent / "data" / "corpus" / "ros-navigation__navigation2"
CATALOG = NAV2 / "nav2_behavior_tree__nav2_tree_nodes.xml"

# The real defects: a file without BTCPP_format, and a misspelled built-in.
DEFECTS = {
    (
        "nav2_docking__opennav_docking_bt__behavior_trees__application_example.xml",
        "warning",
        "missing-format",
    ),
    (
        "nav2_docking__opennav_docking_bt__behavior_trees__application_example.xml",
        "error",
        "unknown-node",
    ),
}


def test_stock_trees_with_the_nav2_catalog() -> None:
    out, err = io.StringIO(), io.StringIO()
    # Nav2 Rolling builds against BehaviorTree.CPP 4 (its package.xml and CMakeLists.txt
    # are not part of this copy of its trees).
    opts = check.Options(
        format="json",
        progress=False,
        models=(str(CATALOG),),
        btcpp="4",
        severities=later_severities(),  # the codes this test was written against
    )
    status = check.run([str(NAV2)], opts, out, err)
    found = json.loads(out.getvalue())
    loud = {
        (Path(d["path"]).name, d["severity"], d["code"])
        for d in found
        if d["severity"] in ("error", "warning")
    }
    assert loud == DEFECTS
    assert status == 1  # the misspelled built-in
    hints = Counter(d["code"] for d in found if d["severity"] == "hint")
    assert set(hints) == {"missing-port-without-default"}
    assert len({Path(d["path"]).name for d in found}) <= 17
    assert len(list(NAV2.glob("*.xml"))) == 17
