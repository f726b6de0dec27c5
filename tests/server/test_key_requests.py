"""Hover, references and highlights on a blackboard key of a script of many statements,
through the server, before and after an edit of the script: each request looks for the
key under the cursor and its uses only, not for every identifier of the script."""

from __future__ import annotations

import pytest
from lsprotocol import types

from bt_lsp.ide.completion_attrs import MAX_KEY_ITEMS
from tests.server.conftest import BtClient, clients

pytestmark = [pytest.mark.asyncio(loop_scope="module"), clients("vscode", "emacs")]

CODE = "".join(f"a{i}:=1; " for i in range(40_000))  # a third of a megabyte: the worker's
HEAD = '<root BTCPP_format="4">\n  <BehaviorTree ID="T">\n    <Sequence>\n      <Script code="'
TEXT = (
    HEAD
    + CODE
    + '"/>\n      <SetBlackboard value="1" output_key="{a7}"/>\n    </Sequence>\n'
    + "  </BehaviorTree>\n</root>\n"
)


def _ranges(client: BtClient, text: str, *starts: int) -> list[types.Range]:
    return [client.range(text, s, s + 2) for s in starts]


def _sorted(ranges: list[types.Range]) -> list[types.Range]:
    return sorted(ranges, key=lambda r: (r.start.line, r.start.character))


async def test_a_key_of_a_large_script(client: BtClient) -> None:
    uri = client.open(TEXT, name="script")
    await client.diags(uri, 1)
    in_script = TEXT.index("a7:=")
    in_port = TEXT.index("{a7}") + 1
    doc = types.TextDocumentIdentifier(uri=uri)

    hover = await client.hover(uri, client.pos(TEXT, in_script + 1))
    assert hover is not None and isinstance(hover.contents, types.MarkupContent)
    assert hover.range == client.range(TEXT, in_script, in_script + 2)
    md = hover.contents.value
    assert "Blackboard key `a7` of the tree `T`" in md
    assert "In scripts:" in md and "`Script` `code` (line 4)" in md
    assert "Written by:" in md and "`SetBlackboard` port `output_key` (line 5" in md
    assert "a70" not in md  # another key of the script

    refs = await client.text_document_references_async(
        types.ReferenceParams(
            text_document=doc,
            position=client.pos(TEXT, in_script + 2),  # the key's end counts
            context=types.ReferenceContext(include_declaration=True),
        )
    )
    assert refs is not None
    assert _sorted([r.range for r in refs]) == _ranges(client, TEXT, in_script, in_port)
    marks = await client.text_document_document_highlight_async(
        types.DocumentHighlightParams(text_document=doc, position=client.pos(TEXT, in_port))
    )
    assert marks is not None
    assert _sorted([m.range for m in marks]) == _ranges(client, TEXT, in_script, in_port)

    # The script gains a use of the key at its end: the next requests see it.
    end = TEXT.index('"/>')
    edited = TEXT[:end] + "a7:=2; " + TEXT[end:]
    client.change(
        uri,
        2,
        types.TextDocumentContentChangePartial(range=client.range(TEXT, end, end), text="a7:=2; "),
    )
    refs = await client.text_document_references_async(
        types.ReferenceParams(
            text_document=doc,
            position=client.pos(edited, in_script),
            context=types.ReferenceContext(include_declaration=True),
        )
    )
    assert refs is not None
    assert _sorted([r.range for r in refs]) == _ranges(client, edited, in_script, end, in_port + 7)
    hover = await client.hover(uri, client.pos(edited, end + 1))
    assert hover is not None and isinstance(hover.contents, types.MarkupContent)
    assert hover.range == client.range(edited, end, end + 2)
    assert hover.contents.value.count("`Script` `code` (line 4)") == 2
    between = await client.hover(uri, client.pos(edited, in_script + 3))  # on ':='
    assert between is None or "Blackboard key" not in str(between.contents)


async def test_key_completion_in_the_tree_of_a_large_script(client: BtClient) -> None:
    """40,000 keys: the first MAX_KEY_ITEMS, those typed first, marked incomplete so that
    the client asks again as the key is typed (not 40,000 items at every keystroke)."""
    typed = '"/>\n      <SetBlackboard value="1" output_key="{a7}"/>'
    text = TEXT.replace(typed, typed + '\n      <SetBlackboard value="2" output_key="{a399')
    uri = client.open(text, name="script-completion")
    await client.diags(uri, 1)
    at = text.index("{a399") + len("{a399")
    found = await client.text_document_completion_async(
        types.CompletionParams(
            text_document=types.TextDocumentIdentifier(uri=uri), position=client.pos(text, at)
        )
    )
    assert isinstance(found, types.CompletionList)
    assert found.is_incomplete
    labels = [i.label for i in found.items]
    assert len(labels) == MAX_KEY_ITEMS
    assert {f"a399{d}" for d in range(10)} <= set(labels)  # every key as typed
    assert "a7" not in labels  # past the cap, and not as typed
    item = next(i for i in found.items if i.label == "a3990")
    assert item.detail == "used in a script of this tree"
    assert isinstance(item.text_edit, types.TextEdit)
    assert item.text_edit.new_text == "a3990}"
    assert item.text_edit.range == client.range(text, at - 4, at)
