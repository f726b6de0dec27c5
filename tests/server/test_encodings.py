"""Position encodings: negotiation, and exact ranges in UTF-8, UTF-16 and UTF-32 for text
with CRLF and lone CR line ends, tabs, characters outside the BMP and combining marks."""

from __future__ import annotations

import re

import pytest
from lsprotocol import types

from tests.server.conftest import (
    PROFILES,
    BtClient,
    apply_edits,
    clients,
    key,
    marked,
    names_only,
    partial,
    summary,
    syntax_and_names,
    workspace_edits,
)

pytestmark = pytest.mark.asyncio(loop_scope="module")

# utf-16 (offered nothing, or only it), utf-8 and utf-32; push and pull.
PROFILES_UNDER_TEST = [
    "vscode",
    "vscode-utf8",
    "vscode-utf32",
    "nvim-0.11",
    "nvim-0.11-utf16",
    "emacs",
]
each_encoding = clients(*PROFILES_UNDER_TEST)

NEGOTIATED = {
    "vscode": "utf-16",
    "vscode-utf8": "utf-8",
    "vscode-utf32": "utf-32",
    "nvim-0.7": "utf-16",
    "nvim-0.11": "utf-8",
    "nvim-0.11-utf16": "utf-16",
    "emacs": "utf-32",
    "unknown-encodings": "utf-16",
    "utf32-after-unknown": "utf-32",
}

# CRLF, lone CR and LF line ends; tabs; astral characters before and inside names;
# a combining mark; entity references.
DOC = marked(
    '<root BTCPP_format="4" main_tree_to_execute="😋 Tree">\r\n'
    "<!-- 𝔘𝔫𝔦 -->\r"
    '\t<BehaviorTree ID="⟦😋 Tree⟧">\r\n'
    '\t\t<Sequence name="é̃😋\tok">\r'
    "\t\t\t<⟦𝔘.x⟧ 😋='1' ⟦😋.p⟧=\"&#128523;\"/>\n"
    '\t\t\t<Action ID="⟦𝔘𝔫:𝔦⟧" name="⟦𝔘&#1;😋⟧"/>\r\n'
    "\t\t\t<SubTree ID='⟦😋 Tree⟧'/>\r"
    "\t\t</Sequence>\n"
    "\t</BehaviorTree>\r\n"
    "</root>"
)
DOC_CODES = [
    "model-name-forbidden-char",
    "model-name-forbidden-char",
    "port-name-forbidden-char",
    "model-name-forbidden-char",
    "instance-name-control-char",
    "model-name-forbidden-char",
]


# (Every client fixture also checks the negotiated encoding, in every module.)
@clients(*PROFILES_UNDER_TEST, "unknown-encodings", "utf32-after-unknown")
async def test_the_encoding_is_negotiated(client: BtClient) -> None:
    want = NEGOTIATED[client.profile_name]
    assert PROFILES[client.profile_name].expected_encoding() == want
    assert client.encoding == want
    got = client.init_result.capabilities.position_encoding
    assert got in (want, None) if want == "utf-16" else got == want


@each_encoding
async def test_diagnostic_ranges_are_exact(client: BtClient) -> None:
    uri = client.open(DOC.text)
    diags = names_only(await client.diags(uri, 1))
    want = sorted((c, key(r)) for c, r in zip(DOC_CODES, DOC.ranges(client.encoding), strict=True))
    assert summary(diags) == want


@each_encoding
async def test_edits_after_astral_characters_and_lone_cr(client: BtClient) -> None:
    text = DOC.text
    uri = client.open(text)
    await client.diags(uri, 1)
    enc = client.encoding
    version = 1
    # Insert right after an astral character, in the middle of a line ended by a lone CR,
    # at the end of a CRLF line and at the very end of the text.
    for needle, offset, new in [
        ("😋\tok", 1, "."),
        ("𝔘𝔫𝔦 -->", 2, "😋"),
        ('ID="😋 Tree">\r\n', len('ID="😋 Tree">'), "<!-- x -->"),
        ("</root>", len("</root>"), "\r\n"),
        ("𝔘&#1;😋", len("𝔘&#1;"), "\t"),
    ]:
        at = text.index(needle) + offset
        version += 1
        client.change(uri, version, partial(text, at, at, new, enc))
        text = text[:at] + new + text[at:]
        got = syntax_and_names(await client.diags(uri, version))
        other = client.open(text, name="fresh")
        want = syntax_and_names(await client.diags(other, 1))
        client.close(other)
        assert summary(got) == summary(want)
    # The instance name now holds a period after an astral character: a valid instance name,
    # but the range of the still-broken names moved exactly.
    assert "é̃😋.\tok" in text
    start = text.index("𝔘&#1;\t😋")
    inst = [d for d in got if d.code == "instance-name-control-char"]
    assert [d.range for d in inst] == [client.range(text, start, start + len("𝔘&#1;\t😋"))]


@each_encoding
async def test_a_replacement_spanning_lines(client: BtClient) -> None:
    text = DOC.text
    uri = client.open(text)
    await client.diags(uri, 1)
    # Replace from inside the comment (lone CR line) to inside the tree ID (CRLF line).
    start = text.index("𝔫𝔦 -->")
    end = text.index('ID="😋 Tree">') + len('ID="😋')
    new = '-->\r\n\t<BehaviorTree ID="𝔘'
    client.change(uri, 2, partial(text, start, end, new, client.encoding))
    text = text[:start] + new + text[end:]
    diags = names_only(await client.diags(uri, 2))
    s = text.index("𝔘 Tree")
    tree = [d for d in diags if d.range.start == client.pos(text, s)]
    assert len(tree) == 1
    assert tree[0].range == client.range(text, s, s + len("𝔘 Tree"))
    assert "'𝔘 Tree'" in tree[0].message


@each_encoding
async def test_hover_ranges_and_positions(client: BtClient) -> None:
    text = DOC.text
    uri = client.open(text)
    await client.diags(uri, 1)
    for name in ["😋.p", "𝔘𝔫:𝔦", "𝔘.x"]:
        start = text.index(name)
        # Every position inside the name (in whole code points) hovers the whole name.
        for i in range(len(name) + 1):
            hover = await client.hover(uri, client.pos(text, start + i))
            assert hover is not None, (name, i)
            assert hover.range == client.range(text, start, start + len(name))
    # Before the name (on "<" or the tab) there is nothing to say.
    start = text.index("𝔘.x")
    assert await client.hover(uri, client.pos(text, start - 2)) is None


@each_encoding
async def test_quick_fix_edits_are_exact(client: BtClient) -> None:
    text = DOC.text
    uri = client.open(text)
    diags = names_only(await client.diags(uri, 1))
    s = text.index("😋.p")
    rng = client.range(text, s, s + 3)
    actions = await client.code_actions(
        uri, rng, only=[types.CodeActionKind.QuickFix], diagnostics=diags
    )
    # The node type is declared nowhere (registered in C++): its port's fix is offered,
    # not preferred, and says so.
    assert not any(a.is_preferred for a in actions)
    action = await client.with_edit(actions[0])
    assert action.edit is not None
    m = re.fullmatch(
        r"Rename '😋\.p' to '(.+)' \(1 place\); the port '😋\.p' of the node type '𝔘\.x' "
        r"is registered outside the workspace: rename it there too \(unsafe\)",
        action.title,
    )
    assert m is not None, action.title
    new = apply_edits(text, workspace_edits(action.edit, uri), client.encoding)
    assert new == text[:s] + m.group(1) + text[s + 3 :]
