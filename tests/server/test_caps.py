"""Every path is capped: a document above ``maxDocumentBytes`` gets at most
``MAX_DIAGNOSTICS`` diagnostics too, plus the two that say what was left out."""

from __future__ import annotations

import pytest

from bt_lsp.rules.diagnostics import MAX_DIAGNOSTICS
from tests.server.conftest import PROFILES, BtClient, Profile, clients

pytestmark = pytest.mark.asyncio(loop_scope="module")

PROFILES["small-limit"] = Profile(
    "visual-studio-code", init_options={"debounceMs": 0, "maxDocumentBytes": 10_000}
)
PROFILES["small-limit-pull"] = Profile(
    "neovim@v0.11.0", init_options={"debounceMs": 0, "maxDocumentBytes": 10_000}
)


@clients("small-limit", "small-limit-pull")
async def test_a_too_large_document_is_capped(client: BtClient) -> None:
    # One line of 1,200 bad node and port names: 2,400 name problems, 20 KB.
    text = (
        '<root BTCPP_format="4"><BehaviorTree ID="T"><Sequence>'
        + '<Do.It x.y="1"/>' * 1200
        + "</Sequence></BehaviorTree></root>"
    )
    uri = client.open(text)
    diags = await client.diags(uri, 1)
    codes = [d.code for d in diags]
    assert len(diags) == MAX_DIAGNOSTICS + 2
    assert codes.count("too-many-problems") == 1
    assert codes.count("document-too-large") == 1
    named = [d for d in diags if d.code == "model-name-forbidden-char"]
    assert len(named) > MAX_DIAGNOSTICS // 3
    # The first by position are the ones kept: one line, increasing columns.
    cols = [d.range.start.character for d in named]
    assert cols == sorted(cols)
    assert named[0].range.start.line == 0
    client.close(uri)
