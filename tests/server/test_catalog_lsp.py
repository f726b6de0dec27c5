"""A node catalog named in the settings (``modelFiles``), end to end: its findings are
errors, a node only the tree file declares is unregistered, and hover says where a model
came from."""

from __future__ import annotations

from pathlib import Path

import pytest
from lsprotocol import types

from tests.server.conftest import PROFILES, BtClient, Profile, clients

pytestmark = pytest.mark.asyncio(loop_scope="module")

CATALOG = Path(__file__).parent.parent / "data" / "catalogs" / "robot_nodes.xml"
PROFILES["catalog"] = Profile(
    "visual-studio-code", init_options={"debounceMs": 0, "modelFiles": [str(CATALOG)]}
)

DOC = (
    '<root BTCPP_format="4">\n'
    '  <BehaviorTree ID="Main">\n'
    "    <Sequence>\n"
    '      <MoveBase goal="1" gaol="2"/>\n'
    "      <OnlyHere/>\n"
    "    </Sequence>\n"
    "  </BehaviorTree>\n"
    '  <TreeNodesModel><Action ID="OnlyHere"/></TreeNodesModel>\n'
    "</root>\n"
)


@clients("catalog")
async def test_catalog_from_the_settings(client: BtClient) -> None:
    uri = client.open(DOC)
    diags = await client.diags(uri, 1)
    got = {(str(d.code), d.severity) for d in diags}
    assert got == {
        ("undeclared-port", types.DiagnosticSeverity.Error),
        ("unknown-node", types.DiagnosticSeverity.Error),
    }
    hover = await client.hover(uri, client.pos(DOC, DOC.index("MoveBase") + 3))
    assert hover is not None and isinstance(hover.contents, types.MarkupContent)
    assert "node catalog named in the settings (authoritative)" in hover.contents.value
    assert "no default" in hover.contents.value
