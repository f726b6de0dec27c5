"""A request is answered for the document as it was when the request came, even when an
edit follows it at once (in the same read of the input).  The handlers that wait for
something (code actions, pulled diagnostics: a coroutine each) started only once the loop
got to their task, after the edit read with them had been applied."""

from __future__ import annotations

import asyncio
import concurrent.futures
import itertools
import json
from typing import Any

import pytest

from tests.server.conftest import TIMEOUT, BtClient, clients

pytestmark = pytest.mark.asyncio(loop_scope="module")

TEXT = (
    '<root BTCPP_format="4">\n'
    '  <BehaviorTree ID="Main">\n'
    '    <Sequence><AlwaysSuccess a.b="1"/></Sequence>\n'
    "  </BehaviorTree>\n"
    "</root>\n"
)
_ids = itertools.count(1)


def _frame(message: dict[str, Any]) -> bytes:
    body = json.dumps(message).encode()
    return b"Content-Length: %d\r\n\r\n" % len(body) + body


async def request_then_edit(
    client: BtClient, method: str, params: Any, uri: str, version: int, text: str
) -> Any:
    """Send ``method`` and, in the same write, a didChange that replaces the text; the
    request's result."""
    msg_id = f"v-{next(_ids)}"
    future: concurrent.futures.Future[Any] = concurrent.futures.Future()
    client.protocol._request_futures[msg_id] = future
    change = {
        "textDocument": {"uri": uri, "version": version},
        "contentChanges": [{"text": text}],
    }
    data = _frame({"jsonrpc": "2.0", "id": msg_id, "method": method, "params": params})
    data += _frame({"jsonrpc": "2.0", "method": "textDocument/didChange", "params": change})
    assert client.protocol.writer is not None
    client.protocol.writer.write(data)
    return _plain(await asyncio.wait_for(asyncio.wrap_future(future), TIMEOUT))


def _plain(value: Any) -> Any:
    """A result as JSON values (pygls reads an untyped result into named tuples)."""
    if hasattr(value, "_asdict"):
        return {k: _plain(v) for k, v in value._asdict().items()}
    if isinstance(value, list | tuple):
        return [_plain(v) for v in value]
    return value


@clients("vscode", "emacs")  # code actions resolved later (with the version), and not
async def test_code_actions_are_of_the_version_asked(client: BtClient) -> None:
    uri = client.open(TEXT)
    await client.diags(uri, 1)
    at = TEXT.index("a.b")
    params = {
        "textDocument": {"uri": uri},
        "range": json.loads(
            json.dumps(client.protocol._converter.unstructure(client.range(TEXT, at, at + 3)))
        ),
        "context": {"diagnostics": []},
    }
    edited = "\n\n\n" + TEXT  # the name three lines further down
    actions = await request_then_edit(client, "textDocument/codeAction", params, uri, 2, edited)
    quick = [a for a in actions if a.get("kind") == "quickfix"]
    assert quick, actions
    for action in quick:
        if "data" in action:
            assert action["data"]["version"] == 1
        else:
            for change in action["edit"]["documentChanges"]:
                assert change["textDocument"]["version"] == 1
                for edit in change["edits"]:
                    assert edit["range"]["start"]["line"] == 2, edit
        for d in action.get("diagnostics", []):
            assert d["range"] == params["range"] or d["range"]["start"]["line"] == 2


@clients("nvim-0.11")
async def test_pulled_diagnostics_are_of_the_version_asked(client: BtClient) -> None:
    uri = client.open(TEXT)
    await client.pull_report(uri)
    report = await request_then_edit(
        client,
        "textDocument/diagnostic",
        {"textDocument": {"uri": uri}},
        uri,
        2,
        "\n\n\n" + TEXT,
    )
    assert report["resultId"].startswith("1:"), report
    lines = {d["range"]["start"]["line"] for d in report["items"]}
    assert lines == {2}, report
