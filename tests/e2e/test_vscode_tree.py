""" "bt-lsp: Show Tree" in a real VS Code (code-server driven by headless Chromium): the picture
appears beside the XML, fitted, follows an edit, a click on a node selects its element, the
cursor highlights its node, an update keeps the zoom, a node typed out of view is scrolled into
view, and a SubTree opens its tree.

Needs what tests/e2e/test_vscode.py needs (`editors/vscode/e2e/setup.sh`). Its screenshot goes
to `.e2e-artifacts/vscode/tree.png`; with BT_LSP_E2E_UPDATE_IMAGES=1 also into
`editors/vscode/images/tree.png` for the READMEs.
"""

from __future__ import annotations

import importlib.util
import os
import re
import shutil
from pathlib import Path
from types import ModuleType

import pytest

from tests.e2e.test_vscode import (
    ARTIFACTS,
    EXT_DIR,
    README_IMAGES,
    SETUP,
    CodeServer,
    _code_server,
    _missing_setup,
    run_driver,
)

pytestmark = pytest.mark.e2e

DRIVER = EXT_DIR / "e2e" / "tree.js"
DRIVER_TIMEOUT_S = 180

MISSION = """\
<root BTCPP_format="4" main_tree_to_execute="Mission">
  <BehaviorTree ID="Mission">
    <Sequence name="mission">
      <Charge level="{battery}"/>
      <Fallback name="dock if needed">
        <IsDocked/>
        <SubTree ID="Dock"/>
      </Fallback>
      <Inverter><AlwaysSuccess/><AlwaysFailure/></Inverter>
    </Sequence>
  </BehaviorTree>
  <BehaviorTree ID="Dock">
    <Sequence><Align/><Stop/></Sequence>
  </BehaviorTree>
  <TreeNodesModel>
    <Action ID="Charge"><input_port name="level"/></Action>
    <Condition ID="IsDocked"/>
    <Action ID="Align"/>
    <Action ID="Stop"/>
  </TreeNodesModel>
</root>
"""
LINES = MISSION.splitlines()
BIG_NODES = 1000


def _big_tree() -> str:
    """A tree of BIG_NODES nodes, from the renderer's benchmark."""
    path = EXT_DIR.parents[1] / "benchmarks" / "render.py"
    spec = importlib.util.spec_from_file_location("bench_render_e2e", path)
    assert spec is not None and spec.loader is not None
    module: ModuleType = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    text: str = module.big_tree(BIG_NODES)
    return text


def test_vscode_tree_view(tmp_path: Path) -> None:
    missing = _missing_setup()
    if missing:
        pytest.fail(
            f"the VS Code e2e setup is missing: {', '.join(missing)}. Run `bash {SETUP}` first.",
            pytrace=False,
        )
    missing_driver = [p for p in (EXT_DIR / "media" / "treeView.js", DRIVER) if not p.exists()]
    assert not missing_driver, missing_driver
    files = {"mission.xml": MISSION, "big.xml": _big_tree()}
    with _code_server(tmp_path, files) as code_server:
        _drive_and_check(code_server, tmp_path)


def _drive_and_check(code_server: CodeServer, tmp_path: Path) -> None:
    shots = tmp_path / "shots"
    shots.mkdir()
    charge_line = 4
    insert_col = len(LINES[charge_line - 1]) + 1  # after <Charge .../>
    fallback_line = 5
    fallback_col = LINES[fallback_line - 1].index("<Fallback") + 1
    inverter_line = 9
    assert LINES[inverter_line - 1].endswith("</Inverter>")
    config = {
        "url": code_server.url,
        "file": "mission.xml",
        "insertAt": [charge_line, insert_col],
        "insert": "<Stop/>",
        "expectType": "Stop",
        "clickType": "Fallback",
        "selectionAt": f"Ln {fallback_line}, Col {fallback_col}",
        "cursorAt": [charge_line, LINES[charge_line - 1].index("Charge") + 3],
        "cursorType": "Charge",
        "addAt": [inverter_line, len(LINES[inverter_line - 1]) + 1],  # after </Inverter>
        "add": '<Sleep msec="1"/>',
        "addType": "Sleep",
        "expandedType": "Align",
        "subtreeType": "Dock",
        "subtreeTree": "Dock",
        "big": {"file": "big.xml", "nodes": BIG_NODES},
        "shotDir": str(shots),
        "chromium": shutil.which("chromium"),
    }
    result, context = run_driver(code_server, DRIVER, config, "tree", DRIVER_TIMEOUT_S, keep=10**9)

    # The picture appears, with the kinds the models give and the Inverter's error as a badge.
    first = result["first"]
    assert first["tree"] == "Mission", context
    assert first["types"] == [
        "Mission",
        "Sequence",
        "Charge",
        "Fallback",
        "IsDocked",
        "Dock",
        "Inverter",
        "AlwaysSuccess",
        "AlwaysFailure",
    ], context
    assert first["kinds"][2:6] == ["action", "control", "condition", "subtree"], context
    assert first["badges"] == ["Inverter"], context
    assert first["stroke"] not in (None, "", "none"), context  # the SVG's styles ran under the CSP
    assert first["fits"] and first["inView"] == first["types"], context  # opened fitted
    assert result["titleButton"], context  # the editor-title button on an XML file

    # It follows an edit (after the debounce), in XML order.
    after = result["afterEdit"]["types"]
    assert after[:4] == ["Mission", "Sequence", "Charge", "Stop"], context

    # A click on a node selects its element in the XML.
    assert f"Ln {fallback_line}, Col {fallback_col}" in result["selection"], context
    assert "selected" in result["selection"], context

    # Moving the cursor highlights its node.
    assert result["highlighted"] == "Charge", context

    # The wheel zoomed in at the pointer; a drag panned by what the mouse moved (60, 40).
    def transform(t: str) -> tuple[float, float, float]:
        found = re.fullmatch(r"translate\((-?[\d.]+)px, (-?[\d.]+)px\) scale\(([\d.]+)\)", t)
        assert found, t
        return float(found[1]), float(found[2]), float(found[3])

    assert transform(result["wheel"]["after"])[2] > transform(result["wheel"]["before"])[2], context
    (x0, y0, k0), (x1, y1, k1) = map(transform, (result["drag"]["before"], result["drag"]["after"]))
    assert k1 == k0, context
    assert abs(x1 - x0 + 60) <= 1 and abs(y1 - y0 + 40) <= 1, context

    # The keyboard zoomed, and the next update kept the zoom and scroll.
    assert result["zoomed"] != result["zoomBefore"], context
    assert result["afterSecondEdit"]["transform"] == result["transformBeforeSecondEdit"], context

    # Zoomed far in, a node typed where the view did not reach was scrolled into view: the view
    # moved, at the same zoom.
    (ax, ay, ak), (bx, by, bk) = (transform(result[k]["transform"]) for k in ("added", "beforeAdd"))
    assert result["added"]["types"][-1] == "Sleep" and "Sleep" in result["added"]["inView"], context
    assert ak == bk and (ax, ay) != (bx, by), context

    # "expand SubTrees" inlines the called tree below its SubTree node; "ports" shows ports.
    assert result["expanded"]["types"][6:10] == ["Dock", "Sequence", "Align", "Stop"], context
    assert result["withPorts"]["keys"] == ["{battery}"], context

    # A double click on a SubTree node opens its tree, which the view then draws.
    assert result["subtree"]["tree"] == "Dock", context
    assert result["subtree"]["types"] == ["Dock", "Sequence", "Align", "Stop"], context
    assert "Ln 12," in result["subtreeSelection"], context

    # A tree of 1,000 nodes: the view follows the newly active editor, draws every node, opens
    # with all of it in view ('0' fits it the same way), and a click on one still selects it.
    big = result["big"]
    assert big["nodes"] == BIG_NODES + 1, context
    assert big["fits"], context
    assert big["fittedTransform"] == big["initialTransform"], context
    assert big["zoomedTransform"] != big["fittedTransform"], context
    assert "selected" in big["selection"], context

    assert (ARTIFACTS / "tree.png").stat().st_size > 10_000
    if os.environ.get("BT_LSP_E2E_UPDATE_IMAGES") == "1":
        shutil.copy(ARTIFACTS / "tree.png", README_IMAGES / "tree.png")
