"""Bad input never kills the server: unknown documents, positions past the end, reversed
and overlapping changes, malformed params, unknown methods, invalid JSON.  Errors are
answered as LSP errors and logged with window/logMessage; the next request still works."""

from __future__ import annotations

import asyncio
from typing import Any

import pytest
from lsprotocol import types
from pygls.exceptions import JsonRpcException

from tests.server.conftest import (
    TIMEOUT,
    BtClient,
    apply_changes,
    clients,
    fresh_uri,
    names_only,
    raw_notify,
    raw_request,
    send_raw,
    summary,
    syntax_and_names,
)

pytestmark = pytest.mark.asyncio(loop_scope="module")

each_client = clients("vscode", "nvim-0.11", "emacs")  # utf-16 push, utf-8 pull, utf-32 push

DOC = (
    '<root BTCPP_format="4">\r\n'
    '  <BehaviorTree ID="Main Tree">\n'
    '    <Do.It 😋.p="1"/>\r'
    "  </BehaviorTree>\n"
    "</root>"
)
INVALID_PARAMS = -32602
METHOD_NOT_FOUND = -32601
REQUEST_FAILED = -32803


async def _still_serving(client: BtClient) -> None:
    """A document opened now gets its diagnostics and hover answers."""
    uri = client.open(DOC, name="alive")
    diags = names_only(await client.diags(uri, 1))
    assert {d.code for d in diags} == {"model-name-forbidden-char", "port-name-forbidden-char"}
    hover = await client.hover(uri, types.Position(1, 22))
    assert hover is not None
    client.close(uri)


def _error_code(exc: BaseException) -> int:
    assert isinstance(exc, JsonRpcException), repr(exc)
    return int(exc.code)


@each_client
async def test_unknown_documents(client: BtClient) -> None:
    uri = fresh_uri("never-opened")
    doc = types.TextDocumentIdentifier(uri=uri)
    assert await client.hover(uri, types.Position(0, 0)) is None
    rng = types.Range(types.Position(0, 0), types.Position(3, 0))
    assert await client.code_actions(uri, rng) == []
    report = await client.pull_report(uri)
    assert isinstance(report, types.RelatedFullDocumentDiagnosticReport)
    assert list(report.items) == []
    action = types.CodeAction(
        title="x", data={"uri": uri, "version": 1, "start": 0, "end": 1, "code": "x", "index": 0}
    )
    resolved = await asyncio.wait_for(client.code_action_resolve_async(action), TIMEOUT)
    assert resolved.edit is None
    # Notifications for it are ignored (and said so in the log); nothing is published.
    client.change(uri, 2, types.TextDocumentContentChangeWholeDocument(text=DOC))
    client.text_document_did_close(types.DidCloseTextDocumentParams(text_document=doc))
    await client.barrier()
    assert uri not in client.published or all(not p.diagnostics for p in client.published[uri])
    await _still_serving(client)


@each_client
async def test_positions_past_the_end(client: BtClient) -> None:
    uri = client.open(DOC)
    await client.diags(uri, 1)
    for line, char in [(0, 10_000), (2, 99), (4, 7), (5, 0), (10_000, 10_000), (2**31 - 1, 0)]:
        pos = types.Position(line, char)
        await client.hover(uri, pos)  # an answer, not an error
        actions = await client.code_actions(uri, types.Range(pos, pos))
        assert isinstance(actions, list)
    # Past the end of a line means its end; past the last line means the end of the text
    # (as LSP says), so this edit appends to line 2 and that one to the text.
    changes: list[types.TextDocumentContentChangeEvent] = [
        types.TextDocumentContentChangePartial(
            range=types.Range(types.Position(2, 500), types.Position(2, 900)), text=" <!-- a -->"
        ),
        types.TextDocumentContentChangePartial(
            range=types.Range(types.Position(99, 0), types.Position(120, 5)), text="\n<!-- b -->"
        ),
    ]
    client.change(uri, 2, *changes)
    expected = DOC.replace('"1"/>\r', '"1"/> <!-- a -->\r') + "\n<!-- b -->"
    got = syntax_and_names(await client.diags(uri, 2))
    fresh = client.open(expected, name="fresh")
    assert summary(got) == summary(syntax_and_names(await client.diags(fresh, 1)))
    # The server's copy is the expected text: an edit at its very end lands there.
    end = client.pos(expected, len(expected))
    client.change(
        uri, 3, types.TextDocumentContentChangePartial(range=types.Range(end, end), text="<x")
    )
    client.change(fresh, 2, types.TextDocumentContentChangeWholeDocument(text=expected + "<x"))
    got = syntax_and_names(await client.diags(uri, 3))
    assert summary(got) == summary(syntax_and_names(await client.diags(fresh, 2)))


@each_client
async def test_reversed_and_overlapping_changes(client: BtClient) -> None:
    uri = client.open(DOC)
    await client.diags(uri, 1)
    enc = client.encoding
    # Overlapping changes in one notification: each applies to the previous result.
    changes: list[types.TextDocumentContentChangeEvent] = [
        types.TextDocumentContentChangePartial(
            range=types.Range(types.Position(1, 20), types.Position(1, 26)), text="X.Y.Z"
        ),
        types.TextDocumentContentChangePartial(
            range=types.Range(types.Position(1, 18), types.Position(1, 23)), text="A B"
        ),
        types.TextDocumentContentChangePartial(
            range=types.Range(types.Position(1, 19), types.Position(1, 19)), text="\r\n"
        ),
    ]
    client.change(uri, 2, *changes)
    text = apply_changes(DOC, changes, enc)
    got = syntax_and_names(await client.diags(uri, 2))
    fresh = client.open(text, name="fresh")
    assert summary(got) == summary(syntax_and_names(await client.diags(fresh, 1)))
    # A reversed range (end before start) is not valid LSP: it may be refused or read
    # either way, but the server keeps serving and a full sync repairs the document.
    client.change(
        uri,
        3,
        types.TextDocumentContentChangePartial(
            range=types.Range(types.Position(2, 10), types.Position(1, 4)), text="?"
        ),
    )
    await client.barrier()
    client.change(uri, 4, types.TextDocumentContentChangeWholeDocument(text=DOC))
    want = summary(names_only(await client.diags(fresh, 1)))
    client.change(fresh, 2, types.TextDocumentContentChangeWholeDocument(text=DOC))
    want = summary(names_only(await client.diags(fresh, 2)))
    assert summary(names_only(await client.diags(uri, 4))) == want
    await _still_serving(client)


@pytest.mark.parametrize(
    ("method", "params"),
    [
        (types.TEXT_DOCUMENT_HOVER, {"textDocument": 5, "position": {"line": 0}}),
        (types.TEXT_DOCUMENT_HOVER, {"textDocument": {"uri": "file:///x.xml"}, "position": []}),
        (
            types.TEXT_DOCUMENT_HOVER,
            {"textDocument": {"uri": "file:///x.xml"}, "position": {"line": -1, "character": 0}},
        ),
        (types.TEXT_DOCUMENT_CODE_ACTION, {"textDocument": {"uri": "file:///x.xml"}}),
        (types.TEXT_DOCUMENT_CODE_ACTION, None),
        (types.TEXT_DOCUMENT_DIAGNOSTIC, {"textDocument": "file:///x.xml"}),
        (types.CODE_ACTION_RESOLVE, {"kind": "quickfix", "edit": "no"}),
        (types.CODE_ACTION_RESOLVE, [1, 2, 3]),
        # cattrs made these a URI "5" and a line 0 (answered null or as line 0).
        (
            types.TEXT_DOCUMENT_HOVER,
            {"textDocument": {"uri": 5}, "position": {"line": 0, "character": 0}},
        ),
        (
            types.TEXT_DOCUMENT_HOVER,
            {"textDocument": {"uri": "file:///x.xml"}, "position": {"line": "0", "character": 0}},
        ),
        (
            types.TEXT_DOCUMENT_DEFINITION,
            {"textDocument": {"uri": "file:///x.xml"}, "position": {"line": 0, "character": True}},
        ),
        (
            types.TEXT_DOCUMENT_REFERENCES,
            {
                "textDocument": {"uri": "file:///x.xml"},
                "position": {"line": 0, "character": 0},
                "context": {"includeDeclaration": "yes"},
            },
        ),
        (types.TEXT_DOCUMENT_DOCUMENT_SYMBOL, {"textDocument": {"uri": ["file:///x.xml"]}}),
        (
            types.TEXT_DOCUMENT_COMPLETION,
            {
                "textDocument": {"uri": "file:///x.xml"},
                "position": {"line": 0, "character": 0},
                "context": {"triggerKind": 9},
            },
        ),
    ],
)
@each_client
async def test_malformed_params_get_an_error_response(
    client: BtClient, method: str, params: Any
) -> None:
    with pytest.raises(JsonRpcException) as info:
        await raw_request(client, method, params)
    assert _error_code(info.value) == INVALID_PARAMS
    await _still_serving(client)


@each_client
async def test_malformed_notifications_are_logged(client: BtClient) -> None:
    seen = len(client.log_messages)
    raw_notify(client, types.TEXT_DOCUMENT_DID_OPEN, {"textDocument": {"uri": 1}})
    raw_notify(client, types.TEXT_DOCUMENT_DID_CHANGE, {"textDocument": None})
    raw_notify(client, types.WORKSPACE_DID_CHANGE_CONFIGURATION, [])
    await client.wait_until(
        lambda: True if len(client.log_messages) >= seen + 2 else None,
        "log messages about the malformed notifications",
    )
    # Logged as the client's mistake (a warning), not as an internal error.
    logged = client.log_messages[seen:]
    assert any(m.type == types.MessageType.Warning and "Invalid" in m.message for m in logged)
    assert not any("internal error" in m.message for m in logged), logged
    await _still_serving(client)


@each_client
async def test_unknown_methods(client: BtClient) -> None:
    with pytest.raises(JsonRpcException) as info:
        await raw_request(client, "bt-lsp/noSuchRequest", {"x": 1})
    assert _error_code(info.value) == METHOD_NOT_FOUND
    raw_notify(client, "bt-lsp/noSuchNotification", {"x": 1})
    raw_notify(client, "$/noSuchNotification", None)
    await _still_serving(client)


@each_client
async def test_invalid_json(client: BtClient) -> None:
    seen = len(client.log_messages)
    for body in [b"{not json", b'{"jsonrpc": "2.0", "id": 1', b"[]", b'"x"']:
        send_raw(client, body)
    await _still_serving(client)
    assert len(client.log_messages) > seen


@each_client
async def test_a_huge_and_deep_document(client: BtClient) -> None:
    depth = 3000
    text = (
        '<root BTCPP_format="4"><BehaviorTree ID="Deep Tree">'
        + "<Sequence>" * depth
        + '<Do.It a.b="1"/>'
        + "</Sequence>" * depth
        + "</BehaviorTree></root>"
    )
    uri = client.open(text)
    codes = {d.code for d in await client.diags(uri, 1)}
    assert {"model-name-forbidden-char", "port-name-forbidden-char"} <= codes
    actions = await client.code_actions(
        uri, types.Range(types.Position(0, 0), types.Position(0, 0)), only=["source.fixAll"]
    )
    assert len(actions) == 1
    await _still_serving(client)


# Request methods that take a document and a position, with any extra params they need.
POSITION_METHODS: dict[str, tuple[str, dict[str, Any]]] = {
    types.TEXT_DOCUMENT_HOVER: ("hover_provider", {}),
    types.TEXT_DOCUMENT_DEFINITION: ("definition_provider", {}),
    types.TEXT_DOCUMENT_REFERENCES: (
        "references_provider",
        {"context": {"includeDeclaration": True}},
    ),
    types.TEXT_DOCUMENT_DOCUMENT_HIGHLIGHT: ("document_highlight_provider", {}),
    types.TEXT_DOCUMENT_PREPARE_RENAME: ("rename_provider", {}),
    types.TEXT_DOCUMENT_RENAME: ("rename_provider", {"newName": "Renamed"}),
    types.TEXT_DOCUMENT_COMPLETION: ("completion_provider", {}),
    types.TEXT_DOCUMENT_LINKED_EDITING_RANGE: ("linked_editing_range_provider", {}),
}
DOCUMENT_METHODS: dict[str, str] = {
    types.TEXT_DOCUMENT_DOCUMENT_SYMBOL: "document_symbol_provider",
    types.TEXT_DOCUMENT_FOLDING_RANGE: "folding_range_provider",
    types.TEXT_DOCUMENT_DIAGNOSTIC: "diagnostic_provider",
}

# Half-typed tags, entity references, CR/CRLF/LF, tabs, astral characters, a CDATA section.
SWEEP = (
    '<root BTCPP_format="4" main_tree_to_execute="A&amp;B">\r\n'
    '\t<BehaviorTree ID="A&amp;B">\r'
    "\t\t<Sequence name='😋&#7;'>\n"
    '\t\t\t<SubTree ID="A&amp;B" 1p="{x}"/>\n'
    '\t\t\t<Script code="<![CDATA[ x:=1 ]]>"/>\n'
    '\t\t\t<Do.It a.b="1" <Action ID="\n'
    "\t\t</Sequence>\r\n"
    "\t</BehaviorTree>\n"
    '\t<TreeNodesModel><Action ID="Do.It"><input_port name="a.b"/></Action>\n'
    "</root"
)


@clients("vscode", "nvim-0.11")  # positions can fall inside a character
async def test_every_request_at_every_position(client: BtClient) -> None:
    """Each advertised request, on an unknown document, past the end, and at every
    position of a half-typed document, is answered without an error."""
    caps = client.init_result.capabilities
    methods = {m: extra for m, (cap, extra) in POSITION_METHODS.items() if getattr(caps, cap)}
    doc_methods = [m for m, cap in DOCUMENT_METHODS.items() if getattr(caps, cap)]
    assert types.TEXT_DOCUMENT_HOVER in methods
    uri = client.open(SWEEP)
    await client.diags(uri, 1)
    unknown = fresh_uri("unknown")
    # Every 3rd position, and every position around line ends and non-ASCII characters.
    near = {
        i + d
        for i, ch in enumerate(SWEEP)
        if ch in "\r\n" or not ch.isascii()
        for d in (-1, 0, 1, 2)
    }
    offsets = sorted(o for o in near | set(range(0, len(SWEEP) + 1, 3)) if 0 <= o <= len(SWEEP))
    positions = [client.pos(SWEEP, i) for i in offsets]
    # Positions inside a character: half a surrogate pair, the middle of a UTF-8 sequence.
    positions += [
        types.Position(p.line, p.character + 1)
        for i, p in zip(offsets, positions, strict=True)
        if i < len(SWEEP) and not SWEEP[i].isascii()
    ]
    positions += [types.Position(3, 10_000), types.Position(10_000, 0)]
    requests: list[tuple[str, Any]] = []
    for method, extra in methods.items():
        for target, where in [(unknown, positions[:3]), (uri, positions)]:
            for pos in where:
                params = {
                    "textDocument": {"uri": target},
                    "position": {"line": pos.line, "character": pos.character},
                    **extra,
                }
                requests.append((method, params))
    for method in doc_methods:
        for target in (unknown, uri):
            requests.append((method, {"textDocument": {"uri": target}}))
    failures: list[str] = []
    for i in range(0, len(requests), 200):  # pipelined, 200 at a time
        chunk = requests[i : i + 200]
        answers = await asyncio.gather(
            *(raw_request(client, m, p) for m, p in chunk), return_exceptions=True
        )
        for (method, params), answer in zip(chunk, answers, strict=True):
            # A deliberate refusal (RequestFailed, e.g. renaming a built-in) is an answer.
            if isinstance(answer, BaseException) and not (
                isinstance(answer, JsonRpcException) and answer.code == REQUEST_FAILED
            ):
                failures.append(f"{method} {params}: {answer!r}")
    assert failures == [], failures[:10]
    await _still_serving(client)


@each_client
async def test_a_nul_character_in_an_include_path(client: BtClient) -> None:
    """A path that the file system cannot even look up is an include that is not found."""
    text = (
        '<root BTCPP_format="4">\n'
        '  <include path="sub/a\x00b.xml"/>\n'
        '  <BehaviorTree ID="T"><AlwaysSuccess/></BehaviorTree>\n'
        "</root>\n"
    )
    seen = len(client.log_messages)
    uri = client.open(text)
    diags = await client.diags(uri, 1)
    assert "include-not-found" in {d.code for d in diags}
    errors = [m.message for m in client.log_messages[seen:] if m.type == types.MessageType.Error]
    assert errors == []
    await _still_serving(client)


# The states of typing ``<!--`` (or a DOCTYPE, a processing instruction) before ``<root>``:
# the document has no element, and its outline was an internal error.
HALF_DECLARATIONS = [
    "<!<root>",
    "<!-<root>",
    "<!DOCTYPE<root>",
    "<?<BehaviorTree ",
    '<!<root BTCPP_format="4"><BehaviorTree ID="A"><AlwaysSuccess/></BehaviorTree></root>',
    '<!-<root BTCPP_format="4"><BehaviorTree ID="A"/></root>',
    "<?x<root><BehaviorTree ID='A'/></root>",
    "<![CDATA[<root>",
]


@clients("vscode", "nvim-0.11")
async def test_outline_while_typing_a_declaration_before_root(client: BtClient) -> None:
    for text in HALF_DECLARATIONS:
        uri = client.open(text)
        for method in (types.TEXT_DOCUMENT_DOCUMENT_SYMBOL, types.TEXT_DOCUMENT_FOLDING_RANGE):
            answer = await raw_request(client, method, {"textDocument": {"uri": uri}})
            assert answer is None or isinstance(answer, list), (text, method, answer)
        client.close(uri)
    await _still_serving(client)
