"""Incremental sync and diagnostics, pushed and pulled, through real LSP clients."""

from __future__ import annotations

import io
import json
from pathlib import Path

import pytest
from lsprotocol import types

from bt_lsp.cli.check import Options, run
from tests.pinned import LATER
from tests.server.conftest import (
    PULL_CLIENTS,
    PUSH_CLIENTS,
    BtClient,
    Marked,
    apply_changes,
    clients,
    key,
    marked,
    names_only,
    partial,
    summary,
    syntax_and_names,
)

pytestmark = pytest.mark.asyncio(loop_scope="module")

DOCS = "https://bt-lsp.github.io/bt-lsp/"

TREE = marked(
    '<root BTCPP_format="4" main_tree_to_execute="Main Tree">\n'
    '  <BehaviorTree ID="⟦Main Tree⟧">\n'
    '    <Sequence name="seq">\n'
    '      <⟦Do.It⟧ ⟦a.b⟧="1" name="⟦x\x07⟧"/>\n'
    '      <SubTree ID="⟦Main Tree⟧"/>\n'
    "    </Sequence>\n"
    "  </BehaviorTree>\n"
    "</root>\n"
)
TREE_CODES = [
    "model-name-forbidden-char",
    "model-name-forbidden-char",
    "port-name-forbidden-char",
    "instance-name-control-char",
    "model-name-forbidden-char",
]

CLEAN = (
    '<root BTCPP_format="4">\n'
    '  <BehaviorTree ID="MainTree">\n'
    '    <Sequence name="seq">\n'
    '      <AlwaysSuccess name="ok"/>\n'
    "    </Sequence>\n"
    "  </BehaviorTree>\n"
    "</root>\n"
)

LAUNCH = (
    "<launch>\n"
    '  <arg name="use.sim time" default="false"/>\n'
    '  <node pkg="nav2.bringup" exec="a b" name="x.y">\n'
    '    <param name="Root" value="1"/>\n'
    "  </node>\n"
    "</launch>\n"
)


def expected(
    client: BtClient, doc: Marked, codes: list[str]
) -> list[tuple[str, tuple[int, int, int, int]]]:
    return sorted((c, key(r)) for c, r in zip(codes, doc.ranges(client.encoding), strict=True))


async def fresh(client: BtClient, text: str) -> list[types.Diagnostic]:
    """The diagnostics of ``text`` opened as a new document (closed again afterwards)."""
    uri = client.open(text, name="fresh")
    try:
        return await client.diags(uri, 1)
    finally:
        client.close(uri)


async def test_open_reports_exact_name_diagnostics(client: BtClient) -> None:
    uri = client.open(TREE.text)
    every = await client.diags(uri, 1)
    diags = names_only(every)
    assert summary(diags) == expected(client, TREE, TREE_CODES)
    pages = Path(__file__).resolve().parents[2] / "docs" / "rules"
    td = client.profile.capabilities().text_document
    described = bool(
        td
        and (
            (td.publish_diagnostics and td.publish_diagnostics.code_description_support)
            or (td.diagnostic and td.diagnostic.code_description_support)
        )
    )
    for d in every:
        assert d.source == "bt-lsp"
        if not described:  # the client cannot show it
            assert d.code_description is None
            continue
        assert d.code_description is not None
        # The link goes to the code's page on the documentation site.
        assert d.code_description.href == f"{DOCS}rules/{d.code}/"
        assert (pages / f"{d.code}.md").is_file(), d.code
    for d in diags:
        assert d.severity == types.DiagnosticSeverity.Error
        assert isinstance(d.data, dict)
    by_code = {(d.code, d.range.start.line): d for d in diags}
    period = by_code[("model-name-forbidden-char", 3)]
    assert "'Do.It'" in period.message
    assert "'.' (period)" in period.message
    assert "column 3" in period.message
    assert isinstance(period.data, dict) and period.data["name"] == "Do.It"
    space = by_code[("model-name-forbidden-char", 1)]
    assert "' ' (space)" in space.message and "whitespace" in space.message
    bell = by_code[("instance-name-control-char", 3)]
    assert "U+0007" in bell.message and "control" in bell.message
    assert isinstance(bell.data, dict) and bell.data["name"] == "x\x07"


async def test_incremental_edits(client: BtClient) -> None:
    uri = client.open(CLEAN)
    assert names_only(await client.diags(uri, 1)) == []
    # Type a period into the tree ID.
    at = CLEAN.index("MainTree") + 4
    client.change(uri, 2, partial(CLEAN, at, at, ".", client.encoding))
    text = CLEAN[:at] + "." + CLEAN[at:]
    diags = names_only(await client.diags(uri, 2))
    start = text.index("Main.Tree")
    assert summary(diags) == [
        ("model-name-forbidden-char", _key(client, text, start, start + len("Main.Tree")))
    ]
    # And delete it again.
    client.change(uri, 3, partial(text, at, at + 1, "", client.encoding))
    assert names_only(await client.diags(uri, 3)) == []


def _key(client: BtClient, text: str, start: int, end: int) -> tuple[int, int, int, int]:
    r = client.range(text, start, end)
    return (r.start.line, r.start.character, r.end.line, r.end.character)


async def test_several_changes_in_one_notification(client: BtClient) -> None:
    uri = client.open(CLEAN)
    await client.diags(uri, 1)
    enc = client.encoding
    changes: list[types.TextDocumentContentChangeEvent] = []
    text = CLEAN
    # Each change is relative to the text left by the previous one.
    for needle, new in [
        ('name="ok"', 'name="o\x01k" bad.port="1"'),
        ("MainTree", "Main Tree 😋"),
        ("<Sequence", '<Sequence\tfoo:bar="2"'),
        ("</root>\n", "</root>\r\n<!-- 𝔘 -->\r\n"),
    ]:
        start = text.index(needle)
        change = partial(text, start, start + len(needle), new, enc)
        changes.append(change)
        text = apply_changes(text, [change], enc)
    client.change(uri, 2, *changes)
    assert apply_changes(CLEAN, changes, enc) == text
    diags = syntax_and_names(await client.diags(uri, 2))
    assert {d.code for d in diags} >= {
        "instance-name-control-char",
        "port-name-forbidden-char",
        "model-name-forbidden-char",
    }
    start = text.index("Main Tree 😋")
    tree_id = [d for d in diags if d.code == "model-name-forbidden-char"]
    assert [d.range for d in tree_id] == [client.range(text, start, start + len("Main Tree 😋"))]
    assert summary(diags) == summary(syntax_and_names(await fresh(client, text)))


async def test_edit_inserting_crlf(client: BtClient) -> None:
    uri = client.open(CLEAN)
    await client.diags(uri, 1)
    at = CLEAN.index("MainTree") + 4
    client.change(uri, 2, partial(CLEAN, at, at, "\r\n", client.encoding))
    text = CLEAN[:at] + "\r\n" + CLEAN[at:]
    diags = names_only(await client.diags(uri, 2))
    assert len(diags) == 1
    d = diags[0]
    assert d.code == "model-name-forbidden-char"
    # The name spans two lines: "Main" at the end of line 1, "Tree" at the start of line 2.
    start = text.index("Main\r\nTree")
    assert d.range == client.range(text, start, start + len("Main\r\nTree"))
    assert (d.range.start.line, d.range.end.line, d.range.end.character) == (1, 2, 4)
    assert "U+000D" in d.message and "U+000A" in d.message
    # A later edit on a following line lands where the client means it.
    at2 = text.index('name="ok"') + len('name="')
    client.change(uri, 3, partial(text, at2, at2 + 2, "a\x02b", client.encoding))
    text = text[:at2] + "a\x02b" + text[at2 + 2 :]
    diags = names_only(await client.diags(uri, 3))
    inst = [d for d in diags if d.code == "instance-name-control-char"]
    assert [d.range for d in inst] == [client.range(text, at2, at2 + 3)]


async def test_whole_document_change(client: BtClient) -> None:
    uri = client.open(CLEAN)
    assert names_only(await client.diags(uri, 1)) == []
    client.replace(uri, 2, TREE.text)
    diags = names_only(await client.diags(uri, 2))
    assert summary(diags) == expected(client, TREE, TREE_CODES)
    client.replace(uri, 3, CLEAN)
    assert names_only(await client.diags(uri, 3)) == []


async def test_non_bt_xml_gets_no_diagnostics(client: BtClient) -> None:
    uri = client.open(LAUNCH)
    if client.pull:
        assert await client.diags(uri, 1) == []
    else:
        await client.barrier()
        last = client.latest(uri)
        assert last is None or list(last.diagnostics) == []
    # Editing it keeps it quiet.
    at = LAUNCH.index("x.y")
    client.change(uri, 2, partial(LAUNCH, at, at, "<!", client.encoding))
    if client.pull:
        assert await client.diags(uri, 2) == []
    else:
        await client.barrier()
        assert all(list(p.diagnostics) == [] for p in client.published.get(uri, []))


MISSPELT_ROOT = (
    '<roo BTCPP_format="4">\n  <BehaviorTree ID="M"><AlwaysSuccess/></BehaviorTree>\n</roo>\n'
)
GENERIC_ROOT = "<root>\n  <item>1</item>\n</root>\n"


async def test_the_editor_and_check_agree_on_what_is_bt(client: BtClient, tmp_path: Path) -> None:
    """One decision: a tree under a misspelt <roo> gets its root-element error, another
    tool's <root> nothing, in the editor as from ``bt-lsp check`` over its folder."""
    for i, text in enumerate((MISSPELT_ROOT, GENERIC_ROOT)):
        folder = tmp_path / str(i)
        folder.mkdir()
        (folder / "t.xml").write_text(text)
        out, err = io.StringIO(), io.StringIO()
        run([str(folder)], Options(format="json", progress=False, cpp=False), out, err)
        from_check = sorted(d["code"] for d in json.loads(out.getvalue() or "[]"))
        from_check = [c for c in from_check if c not in LATER]  # the codes it was written for
        uri = client.open(text, name=f"kind{i}")
        if client.pull or from_check:
            shown = await client.diags(uri, 1)
        else:
            await client.barrier()
            last = client.latest(uri)
            shown = [] if last is None else list(last.diagnostics)
        assert sorted(str(d.code) for d in shown if d.code not in LATER) == from_check
        assert from_check == (["root-element"] if i == 0 else [])


async def test_document_becoming_bt_and_back(client: BtClient) -> None:
    uri = client.open(LAUNCH)
    if client.pull:
        assert await client.diags(uri, 1) == []
    client.replace(uri, 2, TREE.text)
    diags = names_only(await client.diags(uri, 2))
    assert summary(diags) == expected(client, TREE, TREE_CODES)
    # An incremental edit over the whole text that makes it a launch file again.
    client.change(uri, 3, partial(TREE.text, 0, len(TREE.text), LAUNCH, client.encoding))
    assert await client.diags(uri, 3) == []


@clients(*PUSH_CLIENTS)
async def test_close_clears_pushed_diagnostics(client: BtClient) -> None:
    uri = client.open(TREE.text)
    assert names_only(await client.pushed(uri, 1))
    client.close(uri)
    await client.wait_until(
        lambda: True if (p := client.latest(uri)) and not p.diagnostics else None,
        f"empty diagnostics for {uri} after didClose",
    )
    await client.barrier()
    assert list(client.published[uri][-1].diagnostics) == []


@clients(*PUSH_CLIENTS)
async def test_push_carries_the_document_version(client: BtClient) -> None:
    uri = client.open(TREE.text, version=7)
    assert names_only(await client.pushed(uri, 7))
    client.replace(uri, 42, CLEAN)
    assert names_only(await client.pushed(uri, 42)) == []
    assert all(p.version in (7, 42) for p in client.published[uri])


@clients(*PULL_CLIENTS)
async def test_pull_client_gets_no_pushes_and_unchanged_reports(client: BtClient) -> None:
    uri = client.open(TREE.text)
    first = await client.pull_report(uri)
    assert isinstance(first, types.RelatedFullDocumentDiagnosticReport)
    assert summary(names_only(first.items)) == expected(client, TREE, TREE_CODES)
    assert first.result_id
    again = await client.pull_report(uri, previous=first.result_id)
    assert isinstance(again, types.RelatedUnchangedDocumentDiagnosticReport)
    assert again.result_id == first.result_id
    # A change gives a new report with a new resultId; the old one no longer matches.
    client.replace(uri, 2, CLEAN)
    changed = await client.pull_report(uri, previous=first.result_id)
    assert isinstance(changed, types.RelatedFullDocumentDiagnosticReport)
    assert changed.result_id and changed.result_id != first.result_id
    assert names_only(changed.items) == []
    client.close(uri)
    await client.barrier()
    assert uri not in client.published  # never pushed, not even on close


@clients(*PULL_CLIENTS)
async def test_pulled_reports_after_edits_match_a_fresh_open(client: BtClient) -> None:
    """Pulled reports are written as JSON reusing the unchanged diagnostics' parts (see
    test_publication_reuse.py): after an edit that moves, adds or removes diagnostics,
    every field of every item is what a fresh open of the same text reports."""
    trees = "".join(
        f'  <BehaviorTree ID="T{i}"><Sequence name="s&#7;{i}"><Do.It{i} a.b="1"/>'
        f'<SubTree ID="Missing"/></Sequence></BehaviorTree>\n'
        for i in range(12)
    )
    text = f'<root BTCPP_format="4" main_tree_to_execute="T0">\n{trees}</root>\n'
    uri = client.open(text)

    def order(items: list[types.Diagnostic]) -> list[types.Diagnostic]:
        return sorted(items, key=lambda d: (key(d.range), str(d.code), d.message))

    for old, new in (('name="s&#7;3"', 'name="😋 s3"'), ("<Do.It5 ", "<DoIt5 "), ("T7", "T.7")):
        assert (await client.pull_report(uri)).kind == "full"  # what the edit may reuse
        at = text.index(old)
        client.change(uri, 2, partial(text, at, at + len(old), new, client.encoding))
        text = text[:at] + new + text[at + len(old) :]
        edited = await client.pull_report(uri)
        client.close(uri)
        uri = client.open(text)  # alone in the workspace, as the edited one was
        opened = await client.pull_report(uri)
        assert isinstance(edited, types.RelatedFullDocumentDiagnosticReport)
        assert isinstance(opened, types.RelatedFullDocumentDiagnosticReport)
        assert order(list(edited.items)) == order(list(opened.items)), old
        assert len(edited.items) > 30
    client.close(uri)


async def test_half_typed_tags_match_a_fresh_open(client: BtClient) -> None:
    """Typing an element character by character: after each keystroke the diagnostics are
    those of the same text opened fresh."""
    base = CLEAN
    uri = client.open(base)
    await client.diags(uri, 1)
    at = base.index("      <AlwaysSuccess")
    typed = '<Action ID="Go &amp; 😋\tback" a.b=\'1\' name="n&#7;"/>\r'
    text = base
    version = 1
    for i, ch in enumerate(typed):
        version += 1
        client.change(uri, version, partial(text, at + i, at + i, ch, client.encoding))
        text = text[: at + i] + ch + text[at + i :]
        if i % 4 == 3 or i == len(typed) - 1:
            got = syntax_and_names(await client.diags(uri, version))
            assert summary(got) == summary(syntax_and_names(await fresh(client, text))), text
    codes = {d.code for d in names_only(await client.diags(uri, version))}
    assert codes == {
        "model-name-forbidden-char",
        "port-name-forbidden-char",
        "instance-name-control-char",
    }


async def test_entity_references_are_part_of_the_range(client: BtClient) -> None:
    doc = marked(
        '<root BTCPP_format="4">\n'
        '\t<BehaviorTree ID="⟦A&amp;B&#9;C⟧">\n'
        "\t\t<Sequence name='⟦n&#x1;x⟧'>\n"
        '\t\t\t<Action ID="⟦a&lt;b⟧"/>\n'
        "\t\t</Sequence>\n"
        "\t</BehaviorTree>\n"
        "</root>\n"
    )
    uri = client.open(doc.text)
    diags = names_only(await client.diags(uri, 1))
    assert summary(diags) == expected(
        client,
        doc,
        ["model-name-forbidden-char", "instance-name-control-char", "model-name-forbidden-char"],
    )
    tree = next(d for d in diags if d.range.start.line == 1)
    # Columns count characters of the name as BehaviorTree.CPP sees it ("A&B\tC").
    assert "'&' (ampersand) at column 2" in tree.message
    assert "U+0009 (tab) at column 4" in tree.message


@clients(*PULL_CLIENTS)
async def test_unchanged_only_when_nothing_changed(client: BtClient) -> None:
    """Another document can change a document's diagnostics (models declared elsewhere
    count): a report is "unchanged" only if the items really are the same."""
    user = client.open(
        '<root BTCPP_format="4"><BehaviorTree ID="T"><MyAction/></BehaviorTree></root>\n',
        name="user",
    )
    first = await client.pull_report(user)
    assert isinstance(first, types.RelatedFullDocumentDiagnosticReport)
    client.open(
        '<root BTCPP_format="4"><TreeNodesModel><Action ID="MyAction">'
        '<input_port name="target"/></Action></TreeNodesModel></root>\n',
        name="models",
    )
    again = await client.pull_report(user, previous=first.result_id)
    now = await client.pull_report(user)
    assert isinstance(now, types.RelatedFullDocumentDiagnosticReport)
    if isinstance(again, types.RelatedUnchangedDocumentDiagnosticReport):
        assert summary(now.items) == summary(first.items)
    else:
        assert summary(again.items) == summary(now.items)


async def test_requests_at_a_position_of_non_bt_xml_answer_nothing(client: BtClient) -> None:
    """The shared preamble of position requests: a document that is not BT XML gets no
    answer from any of them (on a name that would be one in a BT document)."""
    uri = client.open(LAUNCH)
    line = LAUNCH.splitlines().index('  <node pkg="nav2.bringup" exec="a b" name="x.y">')
    td = types.TextDocumentIdentifier(uri=uri)
    at = types.Position(line=line, character=LAUNCH.splitlines()[line].index("node"))
    c = client
    assert await c.text_document_hover_async(types.HoverParams(td, at)) is None
    assert await c.text_document_definition_async(types.DefinitionParams(td, at)) is None
    context = types.ReferenceContext(include_declaration=True)
    refs = types.ReferenceParams(context=context, text_document=td, position=at)
    assert await c.text_document_references_async(refs) is None
    highlights = types.DocumentHighlightParams(td, at)
    assert await c.text_document_document_highlight_async(highlights) is None
    prepare = types.PrepareRenameParams(td, at)
    assert await c.text_document_prepare_rename_async(prepare) is None
    rename = types.RenameParams(text_document=td, position=at, new_name="n")
    assert await c.text_document_rename_async(rename) is None
    linked = types.LinkedEditingRangeParams(td, at)
    assert await c.text_document_linked_editing_range_async(linked) is None
    assert await c.text_document_completion_async(types.CompletionParams(td, at)) is None
