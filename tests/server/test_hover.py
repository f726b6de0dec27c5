"""Hover: why a bad name breaks the rules (each character, its column, category and
reason, the rule, the replacement); what a good name is and where it is declared."""

from __future__ import annotations

import re

import pytest
import pytest_asyncio
from lsprotocol import types

from tests.server.conftest import BtClient, clients

pytestmark = [
    pytest.mark.asyncio(loop_scope="module"),
    clients("vscode", "nvim-0.11", "emacs"),  # utf-16, utf-8 and utf-32
]

DOC = (
    '<root BTCPP_format="4" main_tree_to_execute="Main Tree">\n'  # line 1
    '  <BehaviorTree ID="Main Tree">\n'  # 2
    '    <Sequence name="seq&#7;uence">\n'  # 3
    '      <Say the.msg:x="hi" name="hello"/>\n'  # 4
    '      <SubTree ID="Helper" goal="{g}"/>\n'  # 5
    "    </Sequence>\n"  # 6
    "  </BehaviorTree>\n"  # 7
    '  <BehaviorTree ID="Helper">\n'  # 8
    "    <😋Check/>\n"  # 9
    "  </BehaviorTree>\n"  # 10
    "  <TreeNodesModel>\n"  # 11
    '    <Action ID="Say">\n'  # 12
    '      <input_port name="the.msg:x"/>\n'  # 13
    '      <input_port name="name"/>\n'  # 14
    "    </Action>\n"  # 15
    '    <SubTree ID="Helper">\n'  # 16
    '      <input_port name="goal"/>\n'  # 17
    "    </SubTree>\n"  # 18
    "  </TreeNodesModel>\n"  # 19
    "</root>\n"
)


def _find(text: str, needle: str, nth: int) -> int:
    start = -1
    for _ in range(nth + 1):
        start = text.index(needle, start + 1)
    return start


async def _hover(
    client: BtClient, uri: str, needle: str, nth: int = 0, into: int = 1
) -> types.Hover:
    start = _find(DOC, needle, nth)
    hover = await client.hover(uri, client.pos(DOC, start + into))
    assert hover is not None, needle
    assert isinstance(hover.contents, types.MarkupContent)
    assert hover.contents.kind == types.MarkupKind.Markdown
    assert hover.range == client.range(DOC, start, start + len(needle))
    return hover


def _text(hover: types.Hover) -> str:
    assert isinstance(hover.contents, types.MarkupContent)
    return hover.contents.value


def _row(md: str, column: int) -> str:
    """The list item of the offending character at (1-based) ``column`` of the name."""
    rows = [line for line in md.splitlines() if re.match(rf"- column {column} \(", line)]
    assert len(rows) == 1, md
    assert not any(line.startswith("|") for line in md.splitlines())  # no table
    return rows[0]


@pytest_asyncio.fixture(scope="module", loop_scope="module")
async def uri(client: BtClient) -> str:
    uri = client.open(DOC, name="hover")
    await client.diags(uri, 1)
    return uri


async def test_bad_model_name(client: BtClient, uri: str) -> None:
    md = _text(await _hover(client, uri, "Main Tree", nth=1))
    assert "model-name-forbidden-char" in md
    assert "A model name cannot contain" in md  # the rule
    row = _row(md, 5)
    assert "' ' (space)" in row and "whitespace" in row
    assert "breaks XML element/attribute names" in row
    assert "`Main_Tree`" in md and "replacement" in md.lower()
    assert "2 places" in md


async def test_each_offending_character_of_a_port(client: BtClient, uri: str) -> None:
    for nth in (0, 1):  # on the node and in the TreeNodesModel
        md = _text(await _hover(client, uri, "the.msg:x", nth=nth, into=4))
        assert "port-name-forbidden-char" in md
        period, colon = _row(md, 4), _row(md, 8)
        assert "'.' (period)" in period and "period" in period
        assert "ambiguous" in period
        assert "':' (colon)" in colon and "path separator" in colon
        assert "filesystem" in colon
        assert "`the_msg_x`" in md


async def test_instance_name_with_a_character_reference(client: BtClient, uri: str) -> None:
    md = _text(await _hover(client, uri, "seq&#7;uence"))
    assert "instance-name-control-char" in md
    row = _row(md, 4)  # "seq\x07uence": the reference is the name's 4th character
    assert "U+0007" in row and "control character" in row and "non-printable" in row
    assert "`seq uence`" in md


async def test_reserved_port_declaration(client: BtClient, uri: str) -> None:
    # The 5th "name" is the value of <input_port name="name"/>.
    assert DOC.index('name="name"') + len('name="') == _find(DOC, "name", 4)
    md = _text(await _hover(client, uri, "name", nth=4, into=0))
    # An <Action> entry, which BehaviorTree.CPP does not read: only the name rules reserve it.
    assert "port-name-reserved-groot2" in md
    assert "Groot2" in md
    assert "`name_`" in md


async def test_a_name_after_an_astral_character(client: BtClient, uri: str) -> None:
    md = _text(await _hover(client, uri, "😋Check", into=1))
    assert "**" in md  # a valid (if unknown) node type still gets a description
    assert "breaks" not in md


async def test_good_names_say_what_and_where(client: BtClient, uri: str) -> None:
    tree = _text(await _hover(client, uri, "Helper", nth=1))  # its definition
    assert "Helper" in tree and "tree" in tree.lower()
    assert "line 8" in tree
    call = _text(await _hover(client, uri, "Helper", nth=0))  # a SubTree call
    assert "SubTree" in call and "line 8" in call
    model = _text(await _hover(client, uri, "Say"))
    assert "Say" in model and "line 12" in model
    port = _text(await _hover(client, uri, "goal", nth=0))
    assert "goal" in port and "port" in port.lower() and "line 17" in port
    inst = _text(await _hover(client, uri, "hello"))
    assert "instance" in inst.lower()
    for h in (tree, call, model, port, inst):
        assert "breaks" not in h


async def test_nothing_to_say(client: BtClient, uri: str) -> None:
    assert await client.hover(uri, types.Position(5, 2)) is None  # indentation
    assert await client.hover(uri, client.pos(DOC, DOC.index("BTCPP_format") + 2)) is None
    other = client.open("<launch>\n  <node name='a.b' pkg='x y'/>\n</launch>\n", name="launch")
    assert await client.hover(other, types.Position(1, 15)) is None
