"""A fix never breaks a working reference, end to end: ``bt-lsp serve`` in a workspace
folder where some SubTree targets are missing (MoveIt Pro objectives call trees of the
installation), driven by VS Code's capabilities (versioned edits with change annotations)
and Neovim 0.11's (plain ``changes``)."""

from __future__ import annotations

import asyncio
from collections.abc import AsyncIterator

import pytest
import pytest_lsp
from lsprotocol import types
from pygls.exceptions import JsonRpcException

from tests.server.test_navigation_lsp import (
    CONFIG,
    NavClient,
    apply,
    doc_pos,
    edits_by_uri,
    ident,
    open_doc,
    position,
    span,
    start_in_folder,
    stop_in_folder,
)
from tests.test_fixes_elsewhere import FIXED, HELPER, OBJECTIVE, OUTSIDE_TREE

pytestmark = pytest.mark.asyncio(loop_scope="module")


def _capabilities(spec: str) -> types.ClientCapabilities:
    """The client's capabilities; ``eglot-plain`` is Emacs's eglot without markdown-mode,
    which asks for plain-text hovers only."""
    if spec != "eglot-plain":
        return pytest_lsp.client_capabilities(spec)
    caps = pytest_lsp.client_capabilities("emacs")
    assert caps.text_document is not None and caps.text_document.hover is not None
    caps.text_document.hover.content_format = [types.MarkupKind.PlainText]
    return caps


@pytest_lsp.fixture(
    config=CONFIG, scope="module", params=["visual-studio-code", "neovim@v0.11.0", "eglot-plain"]
)
async def lsp(lsp_client: NavClient, request: pytest.FixtureRequest) -> AsyncIterator[None]:
    files = {"pick.xml": OBJECTIVE, "helper.xml": HELPER}
    await start_in_folder(lsp_client, request.param, files, _capabilities(request.param))
    open_doc(lsp_client, "pick.xml", OBJECTIVE)
    yield
    await stop_in_folder(lsp_client)


async def _actions(
    lsp: NavClient, needle: str, only: list[str] | None = None
) -> list[types.CodeAction]:
    s, e = span(OBJECTIVE, needle)
    got = await lsp.text_document_code_action_async(
        types.CodeActionParams(
            text_document=ident(lsp.uri("pick.xml")),
            range=types.Range(
                position(OBJECTIVE, s, lsp.encoding), position(OBJECTIVE, e, lsp.encoding)
            ),
            context=types.CodeActionContext(diagnostics=[], only=only),
        )
    )
    out = [a for a in got or [] if isinstance(a, types.CodeAction)]
    resolved = []
    for a in out:
        if a.edit is None and a.data is not None:
            a = await lsp.code_action_resolve_async(a)
        resolved.append(a)
    return resolved


async def test_a_call_of_a_tree_defined_elsewhere_gets_no_fix(lsp: NavClient) -> None:
    actions = await _actions(lsp, "Open Right Gripper")
    assert [a.title for a in actions if "Open Right Gripper" in a.title] == []


async def test_the_diagnostic_says_where_the_name_must_change_first(lsp: NavClient) -> None:
    uri = lsp.uri("pick.xml")
    caps = pytest_lsp.client_capabilities(lsp.spec.replace("eglot-plain", "emacs"))
    if caps.text_document is not None and caps.text_document.diagnostic is not None:
        report = await lsp.text_document_diagnostic_async(
            types.DocumentDiagnosticParams(text_document=ident(uri))
        )
        assert isinstance(report, types.RelatedFullDocumentDiagnosticReport)
        found = report.items
    else:
        for _ in range(100):  # published after the debounce (0 ms here)
            if lsp.diagnostics.get(uri):
                break
            await asyncio.sleep(0.05)
        found = lsp.diagnostics.get(uri, [])
    messages = {
        d.message.split(" contains ")[0]: d.message
        for d in found
        if d.code == "model-name-forbidden-char"
    }
    assert messages["Model name 'Open Right Gripper'"].endswith(
        "; the tree is not defined in this workspace: rename it where it is defined first; "
        "this call keeps its ID until then"
    )
    assert messages["Model name 'Say.Hi'"].endswith(
        "; the node type is registered in C++ that bt-lsp cannot see (no <TreeNodesModel> of "
        "the workspace declares it): rename it there first; fix-all leaves this name until then"
    )
    # The workspace's own tree, defined in helper.xml: renamed with its call, no clause.
    assert messages["Model name 'Pick Object Helper'"].endswith(
        "whitespace breaks XML element/attribute names"
    )


async def test_rename_of_a_call_of_a_tree_defined_elsewhere_is_refused(lsp: NavClient) -> None:
    with pytest.raises(JsonRpcException) as info:
        await lsp.text_document_rename_async(
            types.RenameParams(
                text_document=ident(lsp.uri("pick.xml")),
                position=doc_pos(lsp, OBJECTIVE, "Open Right Gripper", into=3),
                new_name="Open_Right_Gripper",
            )
        )
    assert f"Cannot rename the tree 'Open Right Gripper': {OUTSIDE_TREE}" in str(info.value)


async def test_a_node_type_registered_elsewhere_gets_no_preferred_fix(lsp: NavClient) -> None:
    actions = await _actions(lsp, "Say.Hi")
    named = [a for a in actions if a.kind == types.CodeActionKind.QuickFix]
    assert named and not any(a.is_preferred for a in named)
    assert named[0].title.endswith(
        "is registered outside the workspace: rename it there too (unsafe)"
    )


async def test_edits_of_other_files_need_confirmation(lsp: NavClient) -> None:
    pick, helper = lsp.uri("pick.xml"), lsp.uri("helper.xml")
    (fix, *_) = await _actions(lsp, "Pick Object Helper")
    assert fix.is_preferred and fix.edit is not None
    by_uri = edits_by_uri(fix.edit)
    assert apply(lsp, HELPER, by_uri[helper]) == HELPER.replace(
        "Pick Object Helper", "Pick_Object_Helper"
    )
    if lsp.spec == "visual-studio-code":  # documentChanges and change annotations
        changes = fix.edit.document_changes or []
        kinds = {
            dc.text_document.uri: {type(e).__name__ for e in dc.edits}
            for dc in changes
            if isinstance(dc, types.TextDocumentEdit)
        }
        assert kinds == {pick: {"TextEdit"}, helper: {"AnnotatedTextEdit"}}
        annotations = fix.edit.change_annotations or {}
        (annotation,) = annotations.values()
        assert annotation.needs_confirmation is True
        # Which file, and why it changes.
        assert annotation.label == "Other file: helper.xml"
        assert annotation.description == (
            f"{fix.title}: helper.xml uses the same name, so its references there are renamed "
            f"too (1 edit in {lsp.ws / 'helper.xml'}, not the file you are in)"
        )
        for dc in changes:
            assert isinstance(dc, types.TextDocumentEdit)
            for e in dc.edits:
                if isinstance(e, types.AnnotatedTextEdit):
                    assert e.annotation_id in annotations
    elif lsp.spec == "neovim@v0.11.0":  # no documentChanges: plain edits
        assert fix.edit.change_annotations is None
        assert set((fix.edit.changes or {}).keys()) == {pick, helper}
    else:  # documentChanges without annotation support: plain edits
        assert fix.edit.change_annotations is None
        for dc in fix.edit.document_changes or []:
            assert isinstance(dc, types.TextDocumentEdit)
            assert all(type(e) is types.TextEdit for e in dc.edits)


async def test_fix_all_keeps_calls_of_trees_defined_elsewhere(lsp: NavClient) -> None:
    pick, helper = lsp.uri("pick.xml"), lsp.uri("helper.xml")
    (action,) = await _actions(lsp, "<root", only=["source.fixAll.bt-lsp"])
    assert action.edit is not None
    by_uri = edits_by_uri(action.edit)
    assert apply(lsp, OBJECTIVE, by_uri[pick]) == FIXED
    assert apply(lsp, HELPER, by_uri[helper]) == HELPER.replace(
        "Pick Object Helper", "Pick_Object_Helper"
    )


async def _hover(lsp: NavClient, needle: str) -> types.MarkupContent:
    got = await lsp.text_document_hover_async(
        types.HoverParams(
            text_document=ident(lsp.uri("pick.xml")),
            position=doc_pos(lsp, OBJECTIVE, needle, into=2),
        )
    )
    assert got is not None and isinstance(got.contents, types.MarkupContent)
    plain = lsp.spec == "eglot-plain"
    kind = types.MarkupKind.PlainText if plain else types.MarkupKind.Markdown
    assert got.contents.kind == kind
    if plain:
        assert "**" not in got.contents.value and "`" not in got.contents.value
    return got.contents


async def test_hover_counts_the_places_the_quick_fix_renames(lsp: NavClient) -> None:
    (fix, *_) = await _actions(lsp, "Pick Object Helper")
    assert fix.title.endswith("(2 places, 1 other file)")
    hover = await _hover(lsp, "Pick Object Helper")
    new = "'Pick_Object_Helper'" if lsp.spec == "eglot-plain" else "`Pick_Object_Helper`"
    assert f"Suggested replacement: {new} (the quick fix renames 2 places, 1 other file)" in (
        hover.value
    )


async def test_hover_says_why_a_call_of_a_tree_defined_elsewhere_has_no_fix(
    lsp: NavClient,
) -> None:
    hover = await _hover(lsp, "Open Right Gripper")
    assert f"No quick fix renames it: {OUTSIDE_TREE}." in hover.value


async def test_a_rename_says_in_each_other_file_what_renames_it(lsp: NavClient) -> None:
    pick, helper = lsp.uri("pick.xml"), lsp.uri("helper.xml")
    edit = await lsp.text_document_rename_async(
        types.RenameParams(
            text_document=ident(pick),
            position=doc_pos(lsp, OBJECTIVE, "Pick Object Helper", into=3),
            new_name="Pick_Helper",
        )
    )
    assert edit is not None
    assert apply(lsp, HELPER, edits_by_uri(edit)[helper]) == HELPER.replace(
        "Pick Object Helper", "Pick_Helper"
    )
    if lsp.spec != "visual-studio-code":  # no change annotations
        assert edit.change_annotations is None
        return
    (annotation,) = (edit.change_annotations or {}).values()
    assert annotation.label == "Other file: helper.xml"
    assert annotation.needs_confirmation is True
    assert annotation.description == (
        "Rename 'Pick Object Helper' to 'Pick_Helper': helper.xml uses the same name, so its "
        f"references there are renamed too (1 edit in {lsp.ws / 'helper.xml'}, not the file "
        "you are in)"
    )
