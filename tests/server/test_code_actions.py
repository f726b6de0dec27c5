"""Quick fixes and fix-all through real clients: titles, what they rename, resolve vs
inline edits, versioned document changes, and the text after applying them."""

from __future__ import annotations

import re

import pytest
from lsprotocol import types
from lxml import etree

from tests.server.conftest import (
    BtClient,
    apply_edits,
    clients,
    names_only,
    partial,
    workspace_edits,
)

pytestmark = pytest.mark.asyncio(loop_scope="module")

FIX_ALL = "source.fixAll.bt-lsp"

TREES = (
    '<root BTCPP_format="4" main_tree_to_execute="Main Tree">\n'
    '  <BehaviorTree ID="Main Tree">\n'
    "    <Sequence>\n"
    '      <SubTree ID="Sub Tree" goal="{g}"/>\n'
    '      <AlwaysSuccess name="ok"/>\n'
    "    </Sequence>\n"
    "  </BehaviorTree>\n"
    '  <BehaviorTree ID="Sub Tree">\n'
    '    <SubTree ID="Leaf"/>\n'
    "  </BehaviorTree>\n"
    '  <BehaviorTree ID="Leaf">\n'
    '    <AlwaysSuccess name="leaf"/>\n'
    "  </BehaviorTree>\n"
    "  <TreeNodesModel>\n"
    '    <SubTree ID="Sub Tree">\n'
    '      <input_port name="goal"/>\n'
    "    </SubTree>\n"
    "  </TreeNodesModel>\n"
    "</root>\n"
)

MODELS = (
    '<root BTCPP_format="4">\n'
    '  <BehaviorTree ID="Main">\n'
    "    <Sequence>\n"
    '      <Do.It the.msg="hi"/>\n'
    '      <Action ID="Do.It" the.msg="{m}"/>\n'
    '      <Inverter><Do.It the.msg="x"></Do.It></Inverter>\n'
    '      <Other the.msg="not this one"/>\n'
    '      <SubTree ID="Sub" in.x="{v}"/>\n'
    "    </Sequence>\n"
    "  </BehaviorTree>\n"
    '  <BehaviorTree ID="Sub">\n'
    '    <AlwaysSuccess name="s"/>\n'
    "  </BehaviorTree>\n"
    "  <TreeNodesModel>\n"
    '    <Action ID="Do.It">\n'
    '      <input_port name="the.msg" default="hello"/>\n'
    "    </Action>\n"
    '    <Action ID="Other">\n'
    '      <input_port name="the.msg"/>\n'
    "    </Action>\n"
    '    <SubTree ID="Sub">\n'
    '      <input_port name="in.x"/>\n'
    "    </SubTree>\n"
    "  </TreeNodesModel>\n"
    "</root>\n"
)

TITLE = re.compile(r"Rename '(.*)' to '(.*)' \((\d+) places?\)")


def _at(client: BtClient, text: str, needle: str, nth: int = 0) -> types.Range:
    start = -1
    for _ in range(nth + 1):
        start = text.index(needle, start + 1)
    return client.range(text, start, start + len(needle))


async def _preferred(
    client: BtClient, uri: str, text: str, needle: str, nth: int = 0
) -> types.CodeAction:
    """The preferred name fix for the ``nth`` occurrence of the name ``needle``."""
    actions = await client.code_actions(uri, _at(client, text, needle, nth))
    named = [
        a
        for a in actions
        if a.kind == types.CodeActionKind.QuickFix
        and any(
            d.code in {"model-name-forbidden-char", "port-name-forbidden-char"}
            for d in a.diagnostics or []
        )
    ]
    preferred = [a for a in named if a.is_preferred]
    assert len(preferred) == 1, [a.title for a in named]
    assert named[0] is preferred[0], "the preferred fix comes first"
    return preferred[0]


async def _apply(client: BtClient, uri: str, text: str, action: types.CodeAction) -> str:
    action = await client.with_edit(action)
    assert action.edit is not None
    return apply_edits(text, workspace_edits(action.edit, uri), client.encoding)


async def _send_edits(
    client: BtClient, uri: str, version: int, text: str, action: types.CodeAction
) -> list[types.Diagnostic]:
    """Apply the action's edits in the server's copy too (as one didChange, last edit
    first, as editors do) and return the next diagnostics."""
    action = await client.with_edit(action)
    assert action.edit is not None
    edits = workspace_edits(action.edit, uri)
    order = sorted(edits, key=lambda e: (e.range.start.line, e.range.start.character), reverse=True)
    changes = [
        types.TextDocumentContentChangePartial(range=e.range, text=e.new_text) for e in order
    ]
    client.change(uri, version, *changes)
    return await client.diags(uri, version)


def _replace_nth(text: str, old: str, new: str, which: set[int]) -> str:
    parts = text.split(old)
    out = parts[0]
    for i, part in enumerate(parts[1:]):
        out += (new if i in which else old) + part
    return out


async def test_tree_rename_covers_subtree_calls_and_main_tree(client: BtClient) -> None:
    uri = client.open(TREES)
    await client.diags(uri, 1)
    action = await _preferred(client, uri, TREES, "Sub Tree")
    assert action.title == "Rename 'Sub Tree' to 'Sub_Tree' (3 places)"
    new = await _apply(client, uri, TREES, action)
    assert new == TREES.replace('"Sub Tree"', '"Sub_Tree"')
    diags = await _send_edits(client, uri, 2, TREES, action)
    assert all("Sub Tree" not in d.message for d in names_only(diags))

    # (main_tree_to_execute is a reference, not a diagnostic: ask on the tree's ID.)
    main = await _preferred(client, uri, new, "Main Tree", 1)
    assert main.title == "Rename 'Main Tree' to 'Main_Tree' (2 places)"
    newer = await _apply(client, uri, new, main)
    assert newer == new.replace('"Main Tree"', '"Main_Tree"')
    assert names_only(await _send_edits(client, uri, 3, new, main)) == []


async def test_model_and_port_renames(client: BtClient) -> None:
    uri = client.open(MODELS)
    await client.diags(uri, 1)
    model = await _preferred(client, uri, MODELS, "Do.It")
    # Compact elements (start and end tags), the explicit ID and the model entry.
    assert model.title == "Rename 'Do.It' to 'Do_It' (5 places)"
    text = await _apply(client, uri, MODELS, model)
    assert text == MODELS.replace("Do.It", "Do_It")
    await _send_edits(client, uri, 2, MODELS, model)

    port = await _preferred(client, uri, text, "the.msg")
    # The declaration and the attribute on the three nodes of that model, not on <Other>.
    assert port.title == "Rename 'the.msg' to 'the_msg' (4 places)"
    after = await _apply(client, uri, text, port)
    # Occurrences 0-2 are nodes of Do_It, 3 is <Other>, 4 declares Do_It's, 5 Other's.
    assert after == _replace_nth(text, "the.msg", "the_msg", {0, 1, 2, 4})
    await _send_edits(client, uri, 3, text, port)
    text = after

    sub = await _preferred(client, uri, text, "in.x")
    # A SubTree model port: the declaration and the attribute on the SubTree call.
    assert sub.title == "Rename 'in.x' to 'in_x' (2 places)"
    after = await _apply(client, uri, text, sub)
    assert after == text.replace("in.x", "in_x")


async def test_replacement_is_unique(client: BtClient) -> None:
    text = (
        '<root BTCPP_format="4" main_tree_to_execute="Main_Tree">\n'
        '  <BehaviorTree ID="Main_Tree"><SubTree ID="Main Tree"/></BehaviorTree>\n'
        '  <BehaviorTree ID="Main Tree"><AlwaysSuccess/></BehaviorTree>\n'
        '  <BehaviorTree ID="Main_Tree_2"><AlwaysSuccess/></BehaviorTree>\n'
        "</root>\n"
    )
    uri = client.open(text)
    await client.diags(uri, 1)
    action = await _preferred(client, uri, text, "Main Tree")
    assert action.title == "Rename 'Main Tree' to 'Main_Tree_3' (2 places)"
    assert await _apply(client, uri, text, action) == text.replace('"Main Tree"', '"Main_Tree_3"')


async def test_one_preferred_fix_then_alternatives(client: BtClient) -> None:
    text = (
        '<root BTCPP_format="4">\n'
        '  <BehaviorTree ID="T">\n'
        '    <Sequence name="a&#7;b">\n'
        "      <AlwaysSuccess/>\n"
        "    </Sequence>\n"
        "  </BehaviorTree>\n"
        "  <TreeNodesModel>\n"
        '    <Action ID="Go"><input_port name="1st.goal"/></Action>\n'
        "  </TreeNodesModel>\n"
        "</root>\n"
    )
    uri = client.open(text)
    diags = names_only(await client.diags(uri, 1))
    # A port name that breaks two rules has two diagnostics over the same span ...
    assert sorted(str(d.code) for d in diags) == [
        "instance-name-control-char",
        "port-name-forbidden-char",
        "port-name-leading-digit",
    ]
    actions = await client.code_actions(uri, _at(client, text, "1st.goal"))
    quick = [a for a in actions if a.kind == types.CodeActionKind.QuickFix]
    # ... but one preferred fix, with both diagnostics; alternatives are not preferred.
    preferred = [a for a in quick if a.is_preferred]
    assert len(preferred) == 1, [a.title for a in quick]
    assert quick[0] is preferred[0]
    assert {d.code for d in preferred[0].diagnostics or []} == {
        "port-name-forbidden-char",
        "port-name-leading-digit",
    }
    titles = [a.title for a in quick]
    assert len(titles) == len(set(titles)), titles
    for a in quick:
        m = TITLE.fullmatch(a.title)
        assert m is not None and m.group(1) == "1st.goal", a.title
        new = await _apply(client, uri, text, a)
        assert new == text.replace("1st.goal", m.group(2))
    # The instance name fix removes the control character.
    inst = [
        a for a in await client.code_actions(uri, _at(client, text, "a&#7;b")) if a.is_preferred
    ]
    assert [a.title for a in inst] == ["Rename 'aU+0007b' to 'a b' (1 place)"]
    assert await _apply(client, uri, text, inst[0]) == text.replace("a&#7;b", "a b")


async def test_resolve_or_inline_edits(client: BtClient) -> None:
    uri = client.open(TREES)
    await client.diags(uri, 1)
    actions = await client.code_actions(uri, _at(client, TREES, "Main Tree", 1))
    assert actions
    caps = client.profile.capabilities().text_document
    ca = caps.code_action if caps else None
    lazy = bool(ca and ca.resolve_support and "edit" in ca.resolve_support.properties)
    assert client.init_result.capabilities.code_action_provider is not None
    for a in actions:
        if lazy:
            assert a.edit is None and a.data is not None
            resolved = await client.code_action_resolve_async(a)
            assert resolved.edit is not None
            assert resolved.title == a.title
        else:
            assert a.edit is not None


async def test_versioned_document_changes_when_supported(client: BtClient) -> None:
    uri = client.open(TREES, version=3)
    client.change(uri, 8, partial(TREES, 0, 0, "<!-- x -->\n", client.encoding))
    text = "<!-- x -->\n" + TREES
    await client.diags(uri, 8)
    action = await client.with_edit(await _preferred(client, uri, text, "Sub Tree"))
    assert action.edit is not None
    ws = client.profile.capabilities().workspace
    if ws and ws.workspace_edit and ws.workspace_edit.document_changes:
        assert not action.edit.changes
        assert action.edit.document_changes is not None
        (dc,) = action.edit.document_changes
        assert isinstance(dc, types.TextDocumentEdit)
        assert dc.text_document.uri == uri
        assert dc.text_document.version == 8
    else:
        assert not action.edit.document_changes
        assert action.edit.changes is not None and set(action.edit.changes) == {uri}


async def test_fixes_come_from_the_servers_diagnostics(client: BtClient) -> None:
    """Clients' copies of diagnostics are ignored (Neovim 0.7 sends byte columns)."""
    text = '<root>\n  <BehaviorTree ID="😋😋 A.B">\n    <X.Y/>\n  </BehaviorTree>\n</root>\n'
    uri = client.open(text)
    diags = await client.diags(uri, 1)
    rng = _at(client, text, "😋😋 A.B")
    plain = await client.code_actions(uri, rng)
    bogus = [
        types.Diagnostic(
            range=types.Range(types.Position(1, 30), types.Position(1, 99)),
            message="from the client",
            code="model-name-forbidden-char",
            source="bt-lsp",
        ),
        *[types.Diagnostic(range=d.range, message="x", code="nonsense") for d in diags],
    ]
    with_bogus = await client.code_actions(uri, rng, diagnostics=bogus)
    assert [a.title for a in with_bogus] == [a.title for a in plain]
    assert all("X.Y" not in a.title for a in plain)
    assert any(a.title.startswith("Rename '😋😋 A.B' to ") for a in plain)
    # A range on the other name gets only its fixes; an empty range after it too.
    other = await client.code_actions(uri, _at(client, text, "X.Y"))
    assert other and all("'X.Y'" in a.title for a in other if a.kind == "quickfix")
    end = _at(client, text, "X.Y").end
    touching = await client.code_actions(uri, types.Range(end, end))
    assert [a.title for a in touching] == [a.title for a in other]


MANY = (
    '<root BTCPP_format="4" main_tree_to_execute="Main Tree">\n'
    '  <BehaviorTree ID="Main Tree">\n'
    '    <Sequence name="seq&#1;">\n'
    '      <Do.It the.msg="a" 2nd="b" a:b="c"/>\n'
    '      <Action ID="Do It" x.y="1"/>\n'
    '      <Action ID="Do_It"/>\n'
    '      <SubTree ID="root" _autoremap="true"/>\n'
    '      <SubTree ID="Sub/Tree"/>\n'
    "      <Say\ttext='&lt;hi&gt;'/>\n"
    '      <Action ID=""/>\n'
    "      <Fallback>\n"
    "        <Check&#x3F;/>\n"
    "        <AlwaysSuccess/>\n"
    "      </Fallback>\n"
    "    </Sequence>\n"
    "  </BehaviorTree>\n"
    '  <BehaviorTree ID="root">\n'
    '    <AlwaysSuccess name="r\x7f"/>\n'
    "  </BehaviorTree>\n"
    '  <BehaviorTree ID="Sub/Tree">\n'
    '    <Wait.For ms="1"/>\n'
    "  </BehaviorTree>\n"
    "  <TreeNodesModel>\n"
    '    <Action ID="Do.It">\n'
    '      <input_port name="the.msg"/>\n'
    '      <input_port name="2nd"/>\n'
    '      <input_port name="a:b"/>\n'
    '      <output_port name="name"/>\n'
    "    </Action>\n"
    '    <Action ID="Do It"><input_port name="x.y"/></Action>\n'
    '    <Condition ID="Say &amp; Go"/>\n'
    '    <SubTree ID="root"/>\n'
    "  </TreeNodesModel>\n"
    "</root>\n"
)


def _names(diags: list[types.Diagnostic]) -> list[str]:
    """The names that the name diagnostics are about, in order."""
    return [str(d.data["name"]) for d in names_only(diags) if isinstance(d.data, dict)]


def _ids(text: str) -> tuple[set[str], set[str]]:
    """Tree IDs, and IDs of explicit Action/Condition nodes and models."""
    root = etree.fromstring(text.encode("utf-8"))
    trees = {str(e.get("ID")) for e in root.iter("BehaviorTree")}
    models = {str(e.get("ID")) for e in root.iter("Action", "Condition")}
    return trees, models


@pytest.mark.parametrize("only", [[FIX_ALL], ["source.fixAll"], ["source"], None])
async def test_fix_all(client: BtClient, only: list[str] | None) -> None:
    # Not well-formed XML to begin with ("&#1;", attribute "2nd"), but it will be.
    text = MANY.replace("<Check&#x3F;/>", "<Check/>")
    uri = client.open(text)
    before = names_only(await client.diags(uri, 1))
    assert len(before) >= 12
    actions = await client.code_actions(
        uri, types.Range(types.Position(0, 0), types.Position(0, 0)), only=only
    )
    fix_all = [a for a in actions if a.kind == FIX_ALL]
    assert len(fix_all) == 1
    if only == [FIX_ALL] or only == ["source.fixAll"]:
        assert actions == fix_all
    new = await _apply(client, uri, text, fix_all[0])
    trees, models = _ids(new)  # well-formed now
    # Consistent: as many distinct names as before (MANY has 3 tree IDs and 5 model IDs,
    # "Do.It", "Do It" and "Do_It" among them), and references follow their targets.
    assert len(trees) == 3 and len(models) == 5, (trees, models)
    root = etree.fromstring(new.encode("utf-8"))
    assert root.get("main_tree_to_execute") in trees
    fixed = client.open(new, name="fixed")
    # Left as it is: the node type that no <TreeNodesModel> declares (registered in code
    # bt-lsp cannot see, under its old name).
    assert _names(await client.diags(fixed, 1)) == ["Wait.For"]
    # The same through the server's own copy, as one didChange.
    assert _names(await _send_edits(client, uri, 2, text, fix_all[0])) == ["Wait.For"]


async def test_quickfix_only_excludes_fix_all(client: BtClient) -> None:
    uri = client.open(MANY)
    await client.diags(uri, 1)
    whole = types.Range(types.Position(0, 0), types.Position(100, 0))
    quick = await client.code_actions(uri, whole, only=[types.CodeActionKind.QuickFix])
    assert quick and all(a.kind == types.CodeActionKind.QuickFix for a in quick)
    assert await client.code_actions(uri, whole, only=[types.CodeActionKind.Refactor]) == []


async def test_fix_all_on_a_document_that_is_not_well_formed(client: BtClient) -> None:
    text = MANY.replace("</root>\n", "")  # and <Check&#x3F;/> is not an XML name
    uri = client.open(text)
    await client.diags(uri, 1)
    actions = await client.code_actions(
        uri, types.Range(types.Position(0, 0), types.Position(0, 0)), only=[FIX_ALL]
    )
    assert len(actions) == 1
    new = await _apply(client, uri, text, actions[0])
    fixed = client.open(new, name="fixed")
    assert _names(await client.diags(fixed, 1)) == ["Check&#x3F;", "Wait.For"]


@clients("vscode", "nvim-0.11")
async def test_stale_resolve_is_harmless(client: BtClient) -> None:
    uri = client.open(TREES)
    await client.diags(uri, 1)
    (action, *_) = await client.code_actions(uri, _at(client, TREES, "Sub Tree"))
    assert action.edit is None
    client.replace(uri, 2, TREES.replace("Sub Tree", "Sub Trees"))
    await client.diags(uri, 2)
    resolved = await client.code_action_resolve_async(action)
    assert resolved.edit is None or workspace_edits(resolved.edit, uri) == []


# Tree "Greet" has a bad port "who.m": the call in "Main" gives it with "{=}" (Main's key
# "who.m"), and inside Greet it is the key {who.m}.  😋 (two UTF-16 code units, four UTF-8
# bytes) sits before the key on its line, so that its columns are in the client's encoding.
TREE_PORT = (
    '<root BTCPP_format="4" main_tree_to_execute="Main">\n'
    '  <BehaviorTree ID="Main">\n'
    '    <SubTree ID="Greet" who.m="{=}"/>\n'
    "  </BehaviorTree>\n"
    '  <BehaviorTree ID="Greet">\n'
    '    <SetBlackboard name="😋" output_key="out" value="{who.m}"/>\n'
    "  </BehaviorTree>\n"
    "  <TreeNodesModel>\n"
    '    <SubTree ID="Greet"><input_port name="who.m"/></SubTree>\n'
    "  </TreeNodesModel>\n"
    "</root>\n"
)


async def test_tree_port_fix_renames_its_key_inside_the_tree(client: BtClient) -> None:
    text = TREE_PORT
    uri = client.open(text)
    await client.diags(uri, 1)
    action = await _preferred(client, uri, text, "who.m", 2)  # on the declaration
    assert action.title == "Rename 'who.m' to 'who_m' (4 places)"
    action = await client.with_edit(action)

    def edit(needle: str, into: int, length: int, new: str) -> types.TextEdit:
        start = text.index(needle) + into
        return types.TextEdit(range=client.range(text, start, start + length), new_text=new)

    expected = [
        edit('who.m="{=}"', 0, 5, "who_m"),  # the call's attribute ...
        edit('who.m="{=}"', 8, 1, "who.m"),  # ... whose "{=}" keeps Main's key, written out
        edit("{who.m}", 1, 5, "who_m"),  # the key inside Greet
        edit('name="who.m"', 6, 5, "who_m"),  # the declaration
    ]
    found = action.edit
    assert found is not None
    ws = client.profile.capabilities().workspace
    if ws and ws.workspace_edit and ws.workspace_edit.document_changes:
        assert not found.changes and found.document_changes is not None
        (dc,) = found.document_changes
        assert isinstance(dc, types.TextDocumentEdit)
        assert dc.text_document == types.OptionalVersionedTextDocumentIdentifier(uri=uri, version=1)
        assert list(dc.edits) == expected
    else:
        assert not found.document_changes and found.changes is not None
        assert {u: list(e) for u, e in found.changes.items()} == {uri: expected}
    new = await _apply(client, uri, text, action)
    assert new == (
        text.replace('who.m="{=}"', 'who_m="{who.m}"')
        .replace('value="{who.m}"', 'value="{who_m}"')
        .replace('name="who.m"', 'name="who_m"')
    )
    assert names_only(await _send_edits(client, uri, 2, text, action)) == []


# A typo of a built-in, a built-in without its required port, a call of a missing tree
# and a raw '&': one safe fix (the escape), the others unsafe.
UNSAFE = (
    '<root BTCPP_format="4" main_tree_to_execute="Main">\n'
    '  <BehaviorTree ID="Main">\n'
    '    <Fallbak name="a&b">\n'
    "      <Repeat><AlwaysSuccess/></Repeat>\n"
    '      <SubTree ID="Charge"/>\n'
    "    </Fallbak>\n"
    "  </BehaviorTree>\n"
    "</root>\n"
)


async def test_unsafe_fixes_say_so_and_fix_all_leaves_them(client: BtClient) -> None:
    text = UNSAFE
    uri = client.open(text)
    await client.diags(uri, 1)

    async def quick(needle: str) -> list[types.CodeAction]:
        found = await client.code_actions(
            uri, _at(client, text, needle), only=[types.CodeActionKind.QuickFix]
        )
        return [a for a in found if isinstance(a, types.CodeAction)]

    (typo, *_) = await quick("Fallbak")
    assert typo.title == "Rename 'Fallbak' to 'Fallback' (unsafe)" and not typo.is_preferred
    (port,) = await quick("Repeat")
    assert port.title == 'Add num_cycles="" (unsafe)' and not port.is_preferred
    assert 'Repeat num_cycles=""' in await _apply(client, uri, text, port)
    (create,) = await quick("Charge")
    assert create.title == "Create the tree 'Charge' that fails until it is written (unsafe)"
    created = await _apply(client, uri, text, create)
    assert created.endswith(
        '  <BehaviorTree ID="Charge">\n'
        "    <!-- TODO: write this tree; until then it fails when it runs -->\n"
        "    <AlwaysFailure/>\n"
        "  </BehaviorTree>\n"
        "</root>\n"
    )
    (escape,) = await quick("&")
    assert escape.title == "Escape '&' as '&amp;'" and escape.is_preferred

    (fix_all,) = await client.code_actions(
        uri, types.Range(types.Position(0, 0), types.Position(0, 0)), only=[FIX_ALL]
    )
    assert fix_all.title == "Apply all safe bt-lsp fixes"
    # The safe fix only, as `bt-lsp check --fix` makes it.
    assert await _apply(client, uri, text, fix_all) == text.replace("a&b", "a&amp;b")
