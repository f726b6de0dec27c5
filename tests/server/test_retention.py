"""What the protocol layer keeps between messages does not grow with the session.

pygls 2 files a future for every notification handler it runs; bt-lsp's protocol forgets
each once it is done (:meth:`bt_lsp.server.protocol.BtProtocol._execute_handler`).  The
server runs in-process here, fed through its own JSON decoding, so thousands of edits
take a second or two.
"""

from __future__ import annotations

import asyncio
import json
from typing import Any

from bt_lsp.server.app import BtServer, create_server

DOC = (
    '<root BTCPP_format="4" main_tree_to_execute="Main">\n'
    '  <BehaviorTree ID="Main">\n'
    "    <Sequence>\n"
    '      <AlwaysSuccess name="a"/>\n'
    "    </Sequence>\n"
    "  </BehaviorTree>\n"
    "</root>\n"
)


class Sink:
    """A writer that keeps the server's messages."""

    def __init__(self) -> None:
        self.messages: list[dict[str, Any]] = []

    def write(self, data: bytes) -> None:
        self.messages.append(json.loads(data.partition(b"\r\n\r\n")[2]))

    def close(self) -> None:
        pass


def feed(server: BtServer, message: dict[str, Any]) -> None:
    body = json.dumps({"jsonrpc": "2.0", **message})
    server.protocol.handle_message(json.loads(body, object_hook=server.protocol.structure_message))


async def session(edits: int) -> tuple[BtServer, Sink]:
    server = create_server()
    sink = Sink()
    server.protocol.set_writer(sink)
    feed(
        server,
        {
            "id": 1,
            "method": "initialize",
            "params": {"capabilities": {}, "initializationOptions": {"debounceMs": 0}},
        },
    )
    feed(server, {"method": "initialized", "params": {}})
    await asyncio.sleep(0)
    uri = "untitled:retained.xml"
    line = DOC.splitlines().index('      <AlwaysSuccess name="a"/>')
    col = len('      <AlwaysSuccess name="a')
    for n in range(edits):
        version = 2 * n + 1
        feed(
            server,
            {
                "method": "textDocument/didOpen",
                "params": {
                    "textDocument": {
                        "uri": uri,
                        "languageId": "xml",
                        "version": version,
                        "text": DOC,
                    }
                },
            },
        )
        where = {"line": line, "character": col}
        feed(
            server,
            {
                "method": "textDocument/didChange",
                "params": {
                    "textDocument": {"uri": uri, "version": version + 1},
                    "contentChanges": [{"range": {"start": where, "end": where}, "text": "b"}],
                },
            },
        )
        feed(server, {"method": "textDocument/didClose", "params": {"textDocument": {"uri": uri}}})
        if n % 100 == 0:
            await asyncio.sleep(0)
    feed(
        server,
        {
            "id": 2,
            "method": "textDocument/hover",
            "params": {"textDocument": {"uri": uri}, "position": {"line": 0, "character": 0}},
        },
    )
    await asyncio.sleep(0.05)
    return server, sink


async def test_thousands_of_edits_leave_nothing_behind() -> None:
    server, sink = await session(2000)
    protocol = server.protocol
    assert protocol._request_futures == {}
    assert protocol._result_types == {}
    assert server.docs == {}
    # The work really happened: every change was analysed and published.
    published = [m for m in sink.messages if m.get("method") == "textDocument/publishDiagnostics"]
    assert len(published) >= 4000
    assert any(m.get("id") == 2 for m in sink.messages)


async def test_an_answer_that_cannot_be_written_is_an_error() -> None:
    """A result the serialiser fails on (here nested far beyond the recursion limit)
    still answers its request, with InternalError, and the server serves on."""
    server = create_server()
    sink = Sink()
    server.protocol.set_writer(sink)

    @server.feature("bt-lsp/deep")
    def too_deep(ls: BtServer, params: Any) -> Any:
        nested: list[Any] = []
        for _ in range(100_000):
            nested = [nested]
        return nested

    feed(server, {"id": 1, "method": "initialize", "params": {"capabilities": {}}})
    feed(server, {"id": 2, "method": "bt-lsp/deep", "params": {}})
    feed(server, {"id": 3, "method": "shutdown", "params": None})
    await asyncio.sleep(0.05)
    answers = {m["id"]: m for m in sink.messages if "id" in m and "method" not in m}
    assert answers[2]["error"]["code"] == -32603
    assert "result" in answers[3]
