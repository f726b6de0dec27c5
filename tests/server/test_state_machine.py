"""Random incremental edits through the real server: after each one, the diagnostics it
pushes equal those of the same text opened fresh (as an untitled document, which is not
part of the workspace, so the two documents cannot see each other)."""

from __future__ import annotations

import asyncio
import os
import threading
from collections.abc import Callable, Coroutine, Iterator
from typing import Any, TypeVar

import pytest
from hypothesis import HealthCheck, settings
from hypothesis import strategies as st
from hypothesis.stateful import (
    RuleBasedStateMachine,
    initialize,
    invariant,
    rule,
    run_state_machine_as_test,
)
from lsprotocol import types
from pygls.exceptions import JsonRpcException

from tests.server.conftest import CONFIG, TIMEOUT, BtClient, apply_changes, key, lsp_range

T = TypeVar("T")

REQUESTS = [
    "hover",
    "codeAction",
    "completion",
    "definition",
    "references",
    "documentSymbol",
    "foldingRange",
    "prepareRename",
    "rename",
]
NEW_NAMES = ["Good", "bad name", "a.b", "", "Root", "x😋", "1st"]

SEEDS = [
    (
        '<root BTCPP_format="4" main_tree_to_execute="Main Tree">\r\n'
        '  <BehaviorTree ID="Main Tree">\r\n'
        '    <Sequence name="seq&#7;">\n'
        '      <Do.It a.b="1" name="😋"/>\n'
        '      <SubTree ID="Sub" in.x="{v}"/>\n'
        "    </Sequence>\n"
        "  </BehaviorTree>\r"
        '  <BehaviorTree ID="Sub"><AlwaysSuccess/></BehaviorTree>\n'
        "  <TreeNodesModel>\n"
        '    <Action ID="Do.It"><input_port name="a.b"/><input_port name="name"/></Action>\n'
        '    <SubTree ID="Sub"><input_port name="in.x"/></SubTree>\n'
        "  </TreeNodesModel>\n"
        "</root>\n"
    ),
    "<root>\n\t<BehaviorTree ID='𝔘 tree'>\n\t\t<Fallback><Check&amp;Go/></Fallback>\n",
    '<launch>\n  <node name="a.b" pkg="x y"/>\n</launch>\n',
    "",
]

SNIPPETS = st.one_of(
    st.sampled_from(
        [
            "<",
            ">",
            "/>",
            "</",
            '"',
            "'",
            "=",
            " ",
            "\t",
            "\r\n",
            "\r",
            "\n",
            "😋",
            "𝔘",
            "é",
            "&amp;",
            "&#7;",
            "&",
            ";",
            ".",
            ":",
            "\x01",
            "<!--",
            "-->",
            "<![CDATA[",
            "]]>",
            "<?xml version='1.0'?>",
            "<root>",
            "</root>",
            '<BehaviorTree ID="',
            "</BehaviorTree>",
            "<TreeNodesModel>",
            '<Action ID="A.B"/>',
            '<SubTree ID="Main Tree"/>',
            '<input_port name="1x"/>',
            '<Sequence name="',
            ' a.b="1"',
            " _skipIf='x'",
            'main_tree_to_execute="',
            "<Do.It>",
            "</Do.It>",
        ]
    ),
    st.text(alphabet=st.sampled_from(list("<>/=\"' \t\r\nab.&;#😋:_1")), max_size=6),
)


class ServerThread:
    """Language-server sessions on an event loop of their own, for synchronous callers
    (hypothesis state machines are synchronous)."""

    def __init__(self) -> None:
        self.loop = asyncio.new_event_loop()
        self.thread = threading.Thread(target=self.loop.run_forever, daemon=True)
        self.thread.start()

    def run(self, coro: Coroutine[Any, Any, T], timeout: float = 4 * TIMEOUT) -> T:
        return asyncio.run_coroutine_threadsafe(coro, self.loop).result(timeout)

    def start_client(self, profile: str) -> BtClient:
        async def start() -> BtClient:
            client = await CONFIG.start()
            assert isinstance(client, BtClient)
            await client.start_session(profile)
            return client

        return self.run(start())

    def stop_client(self, client: BtClient) -> None:
        async def stop() -> None:
            await client.shutdown_session()
            await client.stop()

        self.run(stop())

    def close(self) -> None:
        self.loop.call_soon_threadsafe(self.loop.stop)
        self.thread.join(TIMEOUT)


@pytest.fixture(scope="module", params=["vscode", "vscode-utf8"])
def server(request: pytest.FixtureRequest) -> Iterator[tuple[ServerThread, BtClient]]:
    """A server for one client profile (utf-16 or utf-8 positions), on its own loop."""
    thread = ServerThread()
    client = thread.start_client(request.param)
    try:
        yield thread, client
    finally:
        thread.stop_client(client)
        thread.close()


def _full(diags: list[types.Diagnostic]) -> list[tuple[Any, ...]]:
    return sorted((str(d.code), key(d.range), d.message, d.severity) for d in diags)


def test_random_edits_match_a_fresh_open(server: tuple[ServerThread, BtClient]) -> None:
    thread, edited = server
    fresh = edited
    enc = edited.encoding

    class Edits(RuleBasedStateMachine):
        def __init__(self) -> None:
            super().__init__()
            self.text = ""
            self.uri = ""
            self.version = 0

        # -- helpers ----------------------------------------------------------------------

        def _offset(self, data: st.DataObject) -> int:
            at = data.draw(st.integers(0, len(self.text)), label="offset")
            if 0 < at < len(self.text) and self.text[at - 1 : at + 1] == "\r\n":
                at -= 1  # no LSP position lies between "\r" and "\n"
            return at

        def _span(self, data: st.DataObject) -> tuple[int, int]:
            a, b = self._offset(data), self._offset(data)
            return min(a, b), max(a, b)

        def _send(self, changes: list[types.TextDocumentContentChangeEvent]) -> None:
            self.version += 1
            edited.change(self.uri, self.version, *changes)
            self.text = apply_changes(self.text, changes, enc)

        def _change(self, start: int, end: int, new: str) -> types.TextDocumentContentChangePartial:
            return types.TextDocumentContentChangePartial(
                range=lsp_range(self.text, start, end, enc), text=new
            )

        # -- rules ------------------------------------------------------------------------

        @initialize(text=st.sampled_from(SEEDS))
        def open(self, text: str) -> None:
            self.text = text
            self.version = 1
            self.uri = edited.open(text, name="edited")

        @rule(data=st.data(), new=SNIPPETS)
        def insert(self, data: st.DataObject, new: str) -> None:
            at = self._offset(data)
            self._send([self._change(at, at, new)])

        @rule(data=st.data())
        def delete(self, data: st.DataObject) -> None:
            start, end = self._span(data)
            self._send([self._change(start, end, "")])

        @rule(data=st.data(), new=SNIPPETS)
        def replace(self, data: st.DataObject, new: str) -> None:
            start, end = self._span(data)
            self._send([self._change(start, end, new)])

        @rule(data=st.data(), news=st.lists(SNIPPETS, min_size=2, max_size=4))
        def several_in_one_notification(self, data: st.DataObject, news: list[str]) -> None:
            changes: list[types.TextDocumentContentChangeEvent] = []
            text = self.text
            for new in news:
                start, end = self._span(data)
                change = self._change(start, end, new)
                changes.append(change)
                self.text = apply_changes(self.text, [change], enc)
            self.text = text
            self._send(changes)

        @rule(text=st.sampled_from(SEEDS))
        def whole_document(self, text: str) -> None:
            self._send([types.TextDocumentContentChangeWholeDocument(text=text)])

        @rule()
        def close_and_reopen(self) -> None:
            edited.close(self.uri)
            self.version = 1
            self.uri = edited.open(self.text, name="edited")

        @rule(data=st.data(), method=st.sampled_from(REQUESTS))
        def request(self, data: st.DataObject, method: str) -> None:
            """Every request at a random position answers: a result, or (rename only) a
            refusal with a reason; never an internal error."""
            start, end = self._span(data)
            rng = lsp_range(self.text, start, end, enc)
            doc = types.TextDocumentIdentifier(uri=self.uri)
            pos = rng.start
            calls: dict[str, Callable[[], Coroutine[Any, Any, Any]]] = {
                "hover": lambda: edited.text_document_hover_async(
                    types.HoverParams(text_document=doc, position=pos)
                ),
                "codeAction": lambda: edited.text_document_code_action_async(
                    types.CodeActionParams(
                        text_document=doc,
                        range=rng,
                        context=types.CodeActionContext(diagnostics=[]),
                    )
                ),
                "completion": lambda: edited.text_document_completion_async(
                    types.CompletionParams(text_document=doc, position=pos)
                ),
                "definition": lambda: edited.text_document_definition_async(
                    types.DefinitionParams(text_document=doc, position=pos)
                ),
                "references": lambda: edited.text_document_references_async(
                    types.ReferenceParams(
                        text_document=doc,
                        position=pos,
                        context=types.ReferenceContext(include_declaration=True),
                    )
                ),
                "documentSymbol": lambda: edited.text_document_document_symbol_async(
                    types.DocumentSymbolParams(text_document=doc)
                ),
                "foldingRange": lambda: edited.text_document_folding_range_async(
                    types.FoldingRangeParams(text_document=doc)
                ),
                "prepareRename": lambda: edited.text_document_prepare_rename_async(
                    types.PrepareRenameParams(text_document=doc, position=pos)
                ),
                "rename": lambda: edited.text_document_rename_async(
                    types.RenameParams(
                        text_document=doc,
                        position=pos,
                        new_name=data.draw(st.sampled_from(NEW_NAMES)),
                    )
                ),
            }
            try:
                thread.run(calls[method]())
            except JsonRpcException as e:
                assert method in ("rename", "prepareRename"), (method, e)
                assert e.code == types.LSPErrorCodes.RequestFailed, (method, e)

        # -- the property -----------------------------------------------------------------

        @invariant()
        def same_as_a_fresh_open(self) -> None:
            if not self.uri:
                return
            got = thread.run(edited.pushed(self.uri, self.version))

            async def fresh_diagnostics() -> list[types.Diagnostic]:
                uri = fresh.open(self.text, name="fresh", untitled=True)
                try:
                    return await fresh.pushed(uri, 1)
                finally:
                    fresh.close(uri)

            want = thread.run(fresh_diagnostics())
            assert _full(got) == _full(want), repr(self.text)

        def teardown(self) -> None:
            if self.uri:
                edited.close(self.uri)

    run_state_machine_as_test(
        Edits,
        settings=settings(
            max_examples=int(os.environ.get("BT_LSP_SERVER_FUZZ_EXAMPLES", "25")),
            stateful_step_count=15,
            deadline=None,
            suppress_health_check=[HealthCheck.too_slow],
        ),
    )
    assert edited.error is None
