"""Navigation, completion and hover end to end: ``bt-lsp serve`` in a workspace folder of
two files, ``a.xml`` including ``b.xml``, driven by pytest-lsp clients with VS Code's,
Neovim 0.11's and Emacs's capabilities (UTF-16, UTF-8 and UTF-32 positions; snippets or
not; ``documentChanges`` or ``changes``).

Positions are computed here by encoding line prefixes, independently of the server."""

from __future__ import annotations

import os
import re
import shutil
import sys
import tempfile
from collections.abc import AsyncIterator, Sequence
from pathlib import Path
from typing import Any

import pytest
import pytest_lsp
from lsprotocol import types
from pygls.exceptions import JsonRpcException
from pygls.protocol import default_converter
from pygls.uris import from_fs_path, to_fs_path
from pytest_lsp import ClientServerConfig, LanguageClient
from pytest_lsp.client import DEFAULT_CLIENT_FEATURES, register_lsp_features

from tests.server.conftest import plain

pytestmark = pytest.mark.asyncio(loop_scope="module")

# The built-in catalog is written to the cache folder: keep it out of the user's.
CACHE = os.path.join(tempfile.gettempdir(), f"bt-lsp-nav-test-cache-{os.getpid()}")

B_XML = """\
<root BTCPP_format="4">
  <!-- Docking 🚀 -->
  <BehaviorTree ID="Dock">
    <Sequence>
      <MoveBase goal="{pose}"/>
      <AlwaysSuccess/>
    </Sequence>
  </BehaviorTree>
  <TreeNodesModel>
    <Action ID="MoveBase">
      <input_port name="goal" type="Pose" description="Where to go"/>
      <input_port name="speed" type="double" default="0.5">How
        &amp; fast</input_port>
    </Action>
    <SubTree ID="Dock"><input_port name="pose"/></SubTree>
  </TreeNodesModel>
</root>
"""

A_XML = """\
<root BTCPP_format="4" main_tree_to_execute="Main">
  <include path="b.xml"/>
  <BehaviorTree ID="Main">
    <Fallback name="ünïcode 🚀">
      <SubTree ID="Dock" pose="{target}"/>
      <MoveBase goal="{target}" speed="1"/>
    </Fallback>
  </BehaviorTree>
</root>
"""


class NavClient(LanguageClient):
    """A client that knows its workspace, its documents' texts and its encoding."""

    ws: Path
    encoding: str
    spec: str
    init_result: types.InitializeResult

    def uri(self, name: str) -> str:
        uri = from_fs_path(str(self.ws / name))
        assert uri is not None
        return uri

    def text_of(self, uri: str) -> str:
        path = to_fs_path(uri)
        assert path is not None
        return Path(path).read_text(encoding="utf-8")

    def _item_caps(self) -> types.ClientCompletionItemOptions | None:
        td = pytest_lsp.client_capabilities(self.spec).text_document
        return td.completion.completion_item if td and td.completion else None

    @property
    def snippets(self) -> bool:
        item = self._item_caps()
        return bool(item and item.snippet_support)

    @property
    def markdown(self) -> bool:
        item = self._item_caps()
        return types.MarkupKind.Markdown in ((item.documentation_format if item else None) or [])


def _on_register(client: NavClient, params: types.RegistrationParams) -> None:
    """Accept dynamic registrations (the server watches ``*.xml`` files)."""


def make_client() -> NavClient:
    client = NavClient(converter_factory=default_converter)
    features = dict(DEFAULT_CLIENT_FEATURES)
    features[types.CLIENT_REGISTER_CAPABILITY] = _on_register
    register_lsp_features(client, features)
    return client


CONFIG = ClientServerConfig(
    server_command=[sys.executable, "-m", "bt_lsp", "serve"],
    client_factory=make_client,
    server_env={**os.environ, "XDG_CACHE_HOME": CACHE},
)


@pytest_lsp.fixture(
    config=CONFIG, scope="module", params=["visual-studio-code", "neovim@v0.11.0", "emacs"]
)
async def lsp(lsp_client: NavClient, request: pytest.FixtureRequest) -> AsyncIterator[None]:
    await start_in_folder(lsp_client, request.param, {"a.xml": A_XML, "b.xml": B_XML})
    open_doc(lsp_client, "a.xml", A_XML)
    yield
    await stop_in_folder(lsp_client)


async def start_in_folder(
    client: NavClient,
    spec: str,
    files: dict[str, str],
    capabilities: types.ClientCapabilities | None = None,
) -> None:
    """Writes ``files`` to a fresh workspace folder and initializes the session on it as
    the client ``spec`` (with its capabilities unless given), diagnostics undelayed."""
    ws = Path(tempfile.mkdtemp(prefix="bt-lsp-nav-ws-")).resolve()
    for name, text in files.items():
        (ws / name).write_text(text, encoding="utf-8")
    client.ws = ws
    client.spec = spec
    folder_uri = from_fs_path(str(ws))
    assert folder_uri is not None
    client.init_result = await client.initialize_session(
        types.InitializeParams(
            capabilities=capabilities or pytest_lsp.client_capabilities(spec),
            workspace_folders=[types.WorkspaceFolder(uri=folder_uri, name="ws")],
            root_uri=folder_uri,
            initialization_options={"debounceMs": 0},
        )
    )
    client.encoding = str(client.init_result.capabilities.position_encoding or "utf-16")


async def stop_in_folder(client: NavClient) -> None:
    """Ends the session of :func:`start_in_folder` and removes its folder and the cache."""
    await client.shutdown_session()
    shutil.rmtree(client.ws, ignore_errors=True)
    shutil.rmtree(CACHE, ignore_errors=True)


# --- positions, computed without the server's code ----------------------------------------

_UNIT = {"utf-8": ("utf-8", 1), "utf-16": ("utf-16-le", 2), "utf-32": ("utf-32-le", 4)}


def position(text: str, offset: int, enc: str) -> types.Position:
    line = text.count("\n", 0, offset)
    start = text.rfind("\n", 0, offset) + 1
    codec, width = _UNIT[enc]
    return types.Position(line, len(text[start:offset].encode(codec)) // width)


def offset_of(text: str, pos: types.Position, enc: str) -> int:
    lines = text.split("\n")
    start = sum(len(line) + 1 for line in lines[: pos.line])
    codec, width = _UNIT[enc]
    data = lines[pos.line].encode(codec)[: pos.character * width]
    return start + len(data.decode(codec))


def span(text: str, needle: str, nth: int = 0, *, inner: int = 0) -> tuple[int, int]:
    """Span of the ``nth`` occurrence of ``needle``, shrunk by ``inner`` on both sides."""
    start = -1
    for _ in range(nth + 1):
        start = text.index(needle, start + 1)
    return start + inner, start + len(needle) - inner


def rng(client: NavClient, text: str, s: tuple[int, int]) -> types.Range:
    return types.Range(position(text, s[0], client.encoding), position(text, s[1], client.encoding))


def cut(client: NavClient, text: str, r: types.Range) -> str:
    return text[offset_of(text, r.start, client.encoding) : offset_of(text, r.end, client.encoding)]


def apply(client: NavClient, text: str, edits: Sequence[types.TextEdit]) -> str:
    spans = sorted(
        (
            offset_of(text, e.range.start, client.encoding),
            offset_of(text, e.range.end, client.encoding),
            e.new_text,
        )
        for e in edits
    )
    out, pos = [], 0
    for s, e, new in spans:
        assert s >= pos, "overlapping edits"
        out += [text[pos:s], new]
        pos = e
    return "".join([*out, text[pos:]])


def edits_by_uri(edit: types.WorkspaceEdit) -> dict[str, list[types.TextEdit]]:
    out: dict[str, list[types.TextEdit]] = {}
    for uri, edits in (edit.changes or {}).items():
        out.setdefault(uri, []).extend(edits)
    for dc in edit.document_changes or []:
        assert isinstance(dc, types.TextDocumentEdit)
        out.setdefault(dc.text_document.uri, []).extend(plain(e) for e in dc.edits)
    return out


def open_doc(client: NavClient, name: str, text: str, version: int = 1) -> str:
    uri = client.uri(name)
    client.text_document_did_open(
        types.DidOpenTextDocumentParams(
            text_document=types.TextDocumentItem(
                uri=uri, language_id="xml", version=version, text=text
            )
        )
    )
    return uri


def close_doc(client: NavClient, uri: str) -> None:
    client.text_document_did_close(
        types.DidCloseTextDocumentParams(text_document=types.TextDocumentIdentifier(uri=uri))
    )


def doc_pos(
    client: NavClient, text: str, needle: str, nth: int = 0, into: int = 1
) -> types.Position:
    return position(text, span(text, needle, nth)[0] + into, client.encoding)


def ident(uri: str) -> types.TextDocumentIdentifier:
    return types.TextDocumentIdentifier(uri=uri)


# --- rename -------------------------------------------------------------------------------


async def test_prepare_rename_gives_the_name(lsp: NavClient) -> None:
    a = lsp.uri("a.xml")
    where = doc_pos(lsp, A_XML, '"Dock"', into=2)
    got = await lsp.text_document_prepare_rename_async(
        types.PrepareRenameParams(text_document=ident(a), position=where)
    )
    assert isinstance(got, types.PrepareRenamePlaceholder)
    assert got.placeholder == "Dock"
    assert got.range == rng(lsp, A_XML, span(A_XML, '"Dock"', inner=1))


async def test_rename_a_tree_across_both_files(lsp: NavClient) -> None:
    a, b = lsp.uri("a.xml"), lsp.uri("b.xml")
    edit = await lsp.text_document_rename_async(
        types.RenameParams(
            text_document=ident(a),
            position=doc_pos(lsp, A_XML, '"Dock"', into=3),
            new_name="Docking",
        )
    )
    assert edit is not None
    by_uri = edits_by_uri(edit)
    assert set(by_uri) == {a, b}
    new_a = apply(lsp, A_XML, by_uri[a])
    new_b = apply(lsp, B_XML, by_uri[b])
    assert new_a == A_XML.replace('"Dock"', '"Docking"')
    assert new_b == B_XML.replace('"Dock"', '"Docking"')
    if edit.document_changes:  # versioned: the open a.xml at version 1, b.xml on disk
        versions = {dc.text_document.uri: dc.text_document.version for dc in edit.document_changes}  # type: ignore[union-attr]
        assert versions == {a: 1, b: None}


async def test_rename_a_node_type_across_both_files(lsp: NavClient) -> None:
    a, b = lsp.uri("a.xml"), lsp.uri("b.xml")
    edit = await lsp.text_document_rename_async(
        types.RenameParams(
            text_document=ident(a),
            position=doc_pos(lsp, A_XML, "<MoveBase", into=4),
            new_name="Drive",
        )
    )
    assert edit is not None
    by_uri = edits_by_uri(edit)
    assert apply(lsp, A_XML, by_uri[a]) == A_XML.replace("MoveBase", "Drive")
    assert apply(lsp, B_XML, by_uri[b]) == B_XML.replace("MoveBase", "Drive")


async def test_rename_a_port_from_its_declaration(lsp: NavClient) -> None:
    a, b = lsp.uri("a.xml"), lsp.uri("b.xml")
    b_doc = open_doc(lsp, "b.xml", B_XML)
    try:
        edit = await lsp.text_document_rename_async(
            types.RenameParams(
                text_document=ident(b_doc),
                position=doc_pos(lsp, B_XML, 'name="goal"', into=7),
                new_name="target",
            )
        )
    finally:
        close_doc(lsp, b_doc)
    assert edit is not None
    by_uri = edits_by_uri(edit)
    assert apply(lsp, A_XML, by_uri[a]) == A_XML.replace("goal=", "target=")
    assert apply(lsp, B_XML, by_uri[b]) == B_XML.replace("goal=", "target=").replace(
        '"goal"', '"target"'
    )


async def test_rename_uses_the_open_text_of_other_documents(lsp: NavClient) -> None:
    """b.xml is open with unsaved lines above: its edits are at the open text's positions."""
    a = lsp.uri("a.xml")
    edited = "<!-- 𝔘𝔫𝔰𝔞𝔳𝔢𝔡 -->\n<!-- é̃ -->\n" + B_XML
    b = open_doc(lsp, "b.xml", edited, version=7)
    try:
        edit = await lsp.text_document_rename_async(
            types.RenameParams(
                text_document=ident(a),
                position=doc_pos(lsp, A_XML, "<MoveBase", into=2),
                new_name="Go",
            )
        )
    finally:
        close_doc(lsp, b)
    assert edit is not None
    by_uri = edits_by_uri(edit)
    assert apply(lsp, edited, by_uri[b]) == edited.replace("MoveBase", "Go")
    if edit.document_changes:
        versions = {dc.text_document.uri: dc.text_document.version for dc in edit.document_changes}  # type: ignore[union-attr]
        assert versions[b] == 7


@pytest.mark.parametrize(
    ("needle", "into", "new", "reason"),
    [
        ('"Dock"', 2, "Dock.2", r"forbidden character: '\.' \(period\)"),
        ('"Dock"', 2, "Main", "already exists"),
        ("<MoveBase", 3, "Root", "reserved"),
        ('speed="1"', 2, "1speed", "cannot start with a digit"),
        ('speed="1"', 2, "_skipIf", "reserved attribute name"),
    ],
)
async def test_rename_refuses_a_bad_new_name_with_the_reason(
    lsp: NavClient, needle: str, into: int, new: str, reason: str
) -> None:
    with pytest.raises(JsonRpcException) as info:
        await lsp.text_document_rename_async(
            types.RenameParams(
                text_document=ident(lsp.uri("a.xml")),
                position=doc_pos(lsp, A_XML, needle, into=into),
                new_name=new,
            )
        )
    assert info.value.code == types.LSPErrorCodes.RequestFailed.value
    assert re.search(reason, info.value.message), info.value.message
    assert info.value.message.startswith(f"Cannot rename to '{new}'")


async def test_prepare_rename_refuses_a_builtin_with_the_reason(lsp: NavClient) -> None:
    with pytest.raises(JsonRpcException) as info:
        await lsp.text_document_prepare_rename_async(
            types.PrepareRenameParams(
                text_document=ident(lsp.uri("a.xml")),
                position=doc_pos(lsp, A_XML, "<Fallback", into=3),
            )
        )
    assert info.value.code == types.LSPErrorCodes.RequestFailed.value
    assert "'Fallback' is a built-in node type" in info.value.message


async def test_prepare_rename_outside_a_name_is_null(lsp: NavClient) -> None:
    got = await lsp.text_document_prepare_rename_async(
        types.PrepareRenameParams(
            text_document=ident(lsp.uri("a.xml")),
            position=doc_pos(lsp, A_XML, "BTCPP_format", into=2),
        )
    )
    assert got is None


# --- blackboard keys ----------------------------------------------------------------------

# Tree "Keys" uses the key "target" in a precondition, a script and two port values, after
# characters outside the BMP on the same lines; tree "Other" has a "target" of its own, and
# so has "Main" in a.xml.
K_XML = """\
<root BTCPP_format="4">
  <BehaviorTree ID="Keys">
    <Sequence name="🚀 départ" _skipIf="target == '🚀 target' &amp;&amp; ok">
      <Script name="𝔖𝔠𝔯𝔦𝔭𝔱 🚀" code="target := 'target' .. target"/>
      <MoveBase name="🚀🚀" goal="{target}" speed="1"/>
      <SubTree ID="Dock" pose="{ target }"/>
    </Sequence>
  </BehaviorTree>
  <BehaviorTree ID="Other">
    <MoveBase goal="{target}"/>
  </BehaviorTree>
</root>
"""

# Where "target" is the key of tree "Keys": (needle, offset of the key in the needle).
K_USES = [
    ('_skipIf="target', 9),
    ('code="target', 6),
    ("'target' .. target", 12),
    ('goal="{target}"', 7),
]
# `{ target }` is another key, " target " (spaces inside the braces belong to the key, as
# BehaviorTree.CPP 4 reads it): a rename of "target" leaves it alone.


def key_spans() -> list[tuple[int, int]]:
    out = []
    for needle, into in K_USES:
        start = K_XML.index(needle) + into
        assert K_XML[start : start + 6] == "target"
        out.append((start, start + 6))
    return out


def sorted_ranges(ranges: Sequence[types.Range]) -> list[types.Range]:
    return sorted(ranges, key=lambda r: (r.start.line, r.start.character))


async def test_rename_a_blackboard_key_in_its_tree(lsp: NavClient) -> None:
    uri = open_doc(lsp, "keys.xml", K_XML)
    try:
        where = doc_pos(lsp, K_XML, 'goal="{target}"', into=9)
        prepared = await lsp.text_document_prepare_rename_async(
            types.PrepareRenameParams(text_document=ident(uri), position=where)
        )
        edit = await lsp.text_document_rename_async(
            types.RenameParams(text_document=ident(uri), position=where, new_name="goal_pose")
        )
    finally:
        close_doc(lsp, uri)
    assert isinstance(prepared, types.PrepareRenamePlaceholder)
    assert prepared.placeholder == "target"
    assert prepared.range == rng(lsp, K_XML, key_spans()[3])
    assert edit is not None
    expected = [types.TextEdit(range=rng(lsp, K_XML, s), new_text="goal_pose") for s in key_spans()]
    if edit.document_changes:
        (change,) = edit.document_changes
        assert isinstance(change, types.TextDocumentEdit)
        assert change.text_document.uri == uri and change.text_document.version == 1
        got = [e for e in change.edits if isinstance(e, types.TextEdit)]
        assert len(got) == len(change.edits)
    else:
        assert edit.changes is not None and set(edit.changes) == {uri}
        got = list(edit.changes[uri])
    assert sorted(got, key=lambda e: (e.range.start.line, e.range.start.character)) == expected
    new = apply(lsp, K_XML, got)
    assert new.count("goal_pose") == 4
    assert '"{ target }"' in new
    assert "'🚀 target'" in new and "'target'" in new
    assert '<MoveBase goal="{target}"/>' in new  # tree "Other"


async def test_references_and_highlights_of_a_key_from_a_script(lsp: NavClient) -> None:
    uri = open_doc(lsp, "keys.xml", K_XML)
    try:
        where = doc_pos(lsp, K_XML, 'code="target', into=8)
        refs = await lsp.text_document_references_async(
            types.ReferenceParams(
                text_document=ident(uri),
                position=where,
                context=types.ReferenceContext(include_declaration=True),
            )
        )
        marks = await lsp.text_document_document_highlight_async(
            types.DocumentHighlightParams(text_document=ident(uri), position=where)
        )
        with pytest.raises(JsonRpcException) as info:
            await lsp.text_document_rename_async(
                types.RenameParams(text_document=ident(uri), position=where, new_name="goal pose")
            )
    finally:
        close_doc(lsp, uri)
    expected = [rng(lsp, K_XML, s) for s in key_spans()]
    assert refs is not None and {loc.uri for loc in refs} == {uri}
    assert sorted_ranges([loc.range for loc in refs]) == expected
    assert marks is not None
    assert sorted_ranges([h.range for h in marks]) == expected
    assert all(h.kind == types.DocumentHighlightKind.Read for h in marks)
    assert info.value.code == types.LSPErrorCodes.RequestFailed.value
    assert info.value.message.startswith("Cannot rename to 'goal pose'")
    assert "used in a script" in info.value.message


# --- definition, references, highlights ---------------------------------------------------


async def definition(lsp: NavClient, needle: str, into: int, nth: int = 0) -> list[types.Location]:
    got = await lsp.text_document_definition_async(
        types.DefinitionParams(
            text_document=ident(lsp.uri("a.xml")), position=doc_pos(lsp, A_XML, needle, nth, into)
        )
    )
    assert isinstance(got, list)
    return [loc for loc in got if isinstance(loc, types.Location)]


async def test_definition_across_files(lsp: NavClient) -> None:
    b = lsp.uri("b.xml")
    # SubTree ID -> its BehaviorTree in b.xml.
    (loc,) = await definition(lsp, '"Dock"', 2)
    assert loc.uri == b and loc.range == rng(lsp, B_XML, span(B_XML, '"Dock"', inner=1))
    # A node -> its TreeNodesModel entry in b.xml.
    (loc,) = await definition(lsp, "<MoveBase", 3)
    assert loc.uri == b and loc.range == rng(lsp, B_XML, span(B_XML, '"MoveBase"', inner=1))
    # A port attribute -> its declaration.
    (loc,) = await definition(lsp, "goal=", 1)
    assert loc.uri == b and loc.range == rng(lsp, B_XML, span(B_XML, '"goal"', inner=1))
    # main_tree_to_execute -> the tree in this file.
    (loc,) = await definition(lsp, '"Main"', 1)
    assert loc.uri == lsp.uri("a.xml")
    assert loc.range == rng(lsp, A_XML, span(A_XML, '"Main"', 1, inner=1))
    # The include path -> the file.
    (loc,) = await definition(lsp, "b.xml", 1)
    assert loc.uri == b and loc.range == types.Range(types.Position(0, 0), types.Position(0, 0))


async def test_definition_of_a_builtin_is_its_description_in_the_catalog(lsp: NavClient) -> None:
    (loc,) = await definition(lsp, "<Fallback", 2)
    path = to_fs_path(loc.uri)
    assert path is not None and path.startswith(CACHE)
    text = Path(path).read_text(encoding="utf-8")
    assert cut(lsp, text, loc.range) == "Fallback"
    line = text.split("\n")[loc.range.start.line - 1]
    assert "Ticks children in order until one succeeds" in line


async def test_references_across_files(lsp: NavClient) -> None:
    a, b = lsp.uri("a.xml"), lsp.uri("b.xml")
    got = await lsp.text_document_references_async(
        types.ReferenceParams(
            text_document=ident(a),
            position=doc_pos(lsp, A_XML, "<MoveBase", into=1),
            context=types.ReferenceContext(include_declaration=True),
        )
    )
    assert got is not None
    found = sorted((loc.uri, cut(lsp, A_XML if loc.uri == a else B_XML, loc.range)) for loc in got)
    assert found == [(a, "MoveBase"), (b, "MoveBase"), (b, "MoveBase")]
    got = await lsp.text_document_references_async(
        types.ReferenceParams(
            text_document=ident(a),
            position=doc_pos(lsp, A_XML, "<MoveBase", into=1),
            context=types.ReferenceContext(include_declaration=False),
        )
    )
    assert got is not None and len(got) == 2


async def test_highlights_of_a_key_and_of_a_tag(lsp: NavClient) -> None:
    a = lsp.uri("a.xml")
    got = await lsp.text_document_document_highlight_async(
        types.DocumentHighlightParams(
            text_document=ident(a), position=doc_pos(lsp, A_XML, "{target}", into=2)
        )
    )
    assert got is not None
    assert [h.range for h in got] == [
        rng(lsp, A_XML, span(A_XML, "{target}", 0, inner=1)),
        rng(lsp, A_XML, span(A_XML, "{target}", 1, inner=1)),
    ]
    assert {h.kind for h in got} == {types.DocumentHighlightKind.Read}
    got = await lsp.text_document_document_highlight_async(
        types.DocumentHighlightParams(
            text_document=ident(a), position=doc_pos(lsp, A_XML, "<Fallback", into=2)
        )
    )
    assert got is not None
    assert [cut(lsp, A_XML, h.range) for h in got] == ["Fallback", "Fallback"]
    got = await lsp.text_document_document_highlight_async(
        types.DocumentHighlightParams(
            text_document=ident(a), position=doc_pos(lsp, A_XML, '"Main"', 1, into=2)
        )
    )
    assert got is not None
    assert [(cut(lsp, A_XML, h.range), h.kind) for h in got] == [
        ("Main", types.DocumentHighlightKind.Read),
        ("Main", types.DocumentHighlightKind.Write),
    ]


# --- symbols ------------------------------------------------------------------------------


def tree_of(lsp: NavClient, text: str, symbols: Sequence[Any]) -> list[Any]:
    out: list[Any] = []
    for s in symbols:
        assert isinstance(s, types.DocumentSymbol)
        entry = (s.name, s.kind, cut(lsp, text, s.selection_range))
        out.append((*entry, tree_of(lsp, text, s.children)) if s.children else entry)
    return out


async def test_document_symbols_are_a_hierarchy(lsp: NavClient) -> None:
    got = await lsp.text_document_document_symbol_async(
        types.DocumentSymbolParams(text_document=ident(lsp.uri("a.xml")))
    )
    assert got is not None
    K = types.SymbolKind
    assert tree_of(lsp, A_XML, got) == [
        ("b.xml", K.File, "b.xml"),
        (
            "Main",
            K.Class,
            "Main",
            [
                (
                    "ünïcode 🚀",
                    K.Function,
                    "Fallback",
                    [("Dock", K.Module, "Dock"), ("MoveBase", K.Function, "MoveBase")],
                )
            ],
        ),
    ]
    main = got[1]
    assert isinstance(main, types.DocumentSymbol)
    start = A_XML.index('<BehaviorTree ID="Main">')
    end = A_XML.index("</BehaviorTree>") + len("</BehaviorTree>")
    assert main.range == rng(lsp, A_XML, (start, end))
    fallback = main.children[0] if main.children else None
    assert fallback is not None and fallback.detail == "Control Fallback"


async def test_workspace_symbols(lsp: NavClient) -> None:
    a, b = lsp.uri("a.xml"), lsp.uri("b.xml")
    got = await lsp.workspace_symbol_async(types.WorkspaceSymbolParams(query=""))
    assert got is not None
    found = sorted((s.name, s.location.uri, s.kind) for s in got)
    K = types.SymbolKind
    assert found == [
        ("Dock", b, K.Class),
        ("Dock", b, K.Interface),
        ("Main", a, K.Class),
        ("MoveBase", b, K.Interface),
    ]
    got = await lsp.workspace_symbol_async(types.WorkspaceSymbolParams(query="mvb"))
    assert got is not None and [s.name for s in got] == ["MoveBase"]
    loc = got[0].location
    assert isinstance(loc, types.Location)
    assert loc.range == rng(lsp, B_XML, span(B_XML, '"MoveBase"', inner=1))


# --- completion ---------------------------------------------------------------------------

C_XML = """\
<root BTCPP_format="4" main_tree_to_execute="">
  <include path="b.xml"/>
  <BehaviorTree ID="Cé">
    <Sequence name="🚀">
      <MoveBase goal="{here}"/>
      <
      <MoveBase ⎵
      <SubTree ID=""/>
      <MoveBase goal="{
    </Sequence>
  </BehaviorTree>
</root>
""".replace("⎵", "")  # the line "<MoveBase " ends with a space


async def complete_at(lsp: NavClient, uri: str, text: str, offset: int) -> types.CompletionList:
    got = await lsp.text_document_completion_async(
        types.CompletionParams(
            text_document=ident(uri), position=position(text, offset, lsp.encoding)
        )
    )
    assert isinstance(got, types.CompletionList)
    for it in got.items:
        assert isinstance(it.text_edit, types.TextEdit)
        assert it.text_edit.range.start.line == it.text_edit.range.end.line
    return got


def by_label(got: types.CompletionList) -> dict[str, types.CompletionItem]:
    return {it.label: it for it in got.items}


async def test_completion_in_each_context(lsp: NavClient) -> None:
    uri = open_doc(lsp, "c.xml", C_XML)  # not saved: only the editor has it
    try:
        # After '<': node types, the declared ones (from b.xml) with their required ports.
        at = C_XML.index("      <\n") + 7
        items = by_label(await complete_at(lsp, uri, C_XML, at))
        move = items["MoveBase"]
        assert isinstance(move.text_edit, types.TextEdit)
        assert move.text_edit.range == rng(lsp, C_XML, (at, at))
        if lsp.snippets:
            assert move.insert_text_format == types.InsertTextFormat.Snippet
            assert move.text_edit.new_text == 'MoveBase goal="${1}"/>'
        else:  # no tab stops, so no empty value: the missing port is then reported
            assert move.insert_text_format == types.InsertTextFormat.PlainText
            assert move.text_edit.new_text == "MoveBase/>"
        assert {"Sequence", "Fallback", "SubTree", "SubTree Dock", "SubTree Main"} <= set(items)
        doc = move.documentation
        if lsp.markdown:
            assert isinstance(doc, types.MarkupContent) and doc.kind == types.MarkupKind.Markdown
            doc = doc.value
        assert isinstance(doc, str)  # plain text for clients without Markdown (Emacs)
        assert "`goal`" in doc and "Where to go" in doc
        # Ports of the node at the cursor and reserved attributes.
        at = C_XML.index("<MoveBase \n") + 10
        items = by_label(await complete_at(lsp, uri, C_XML, at))
        assert {"goal", "speed", "name", "_skipIf", "_onSuccess"} <= set(items)
        assert items["speed"].detail == "input port: double"
        speed = items["speed"].text_edit
        assert isinstance(speed, types.TextEdit)  # its default, to accept or overwrite
        assert speed.new_text == ('speed="${1:0.5}"' if lsp.snippets else 'speed="0.5"')
        # Tree IDs in SubTree ID (not the tree itself) and main_tree_to_execute.
        at = C_XML.index('<SubTree ID=""') + 13
        got = await complete_at(lsp, uri, C_XML, at)
        assert sorted(by_label(got)) == ["Dock", "Main"]
        at = C_XML.index('main_tree_to_execute=""') + 22
        got = await complete_at(lsp, uri, C_XML, at)
        assert sorted(by_label(got)) == ["Cé", "Dock", "Main"]
        # Blackboard keys of this tree after '{'.
        at = C_XML.index('goal="{\n') + 7
        items = by_label(await complete_at(lsp, uri, C_XML, at))
        assert set(items) == {"here"}
        assert items["here"].text_edit.new_text == "here}"  # type: ignore[union-attr]
        # Between elements, no '<' typed (Ctrl+Space at the end of a line): the node
        # types, each with its '<', inserted at the cursor.
        at = C_XML.index('<SubTree ID=""/>') + len('<SubTree ID=""/>')
        items = by_label(await complete_at(lsp, uri, C_XML, at))
        move = items["MoveBase"]
        assert isinstance(move.text_edit, types.TextEdit)
        assert move.text_edit.range == rng(lsp, C_XML, (at, at))
        assert move.filter_text == "MoveBase"
        expected = '<MoveBase goal="${1}"/>' if lsp.snippets else "<MoveBase/>"
        assert move.text_edit.new_text == expected
        assert {"Sequence", "Fallback", "SubTree Dock"} <= set(items)
    finally:
        close_doc(lsp, uri)


INDENTED = """\
<root BTCPP_format="4">
  <BehaviorTree ID="T">
    <Fallback>
      <Sequence>
        <AlwaysSuccess/>

      </Sequence>
    </Fallback>
  </BehaviorTree>
</root>
"""


async def test_completion_in_the_indentation_and_on_an_empty_line(lsp: NavClient) -> None:
    uri = open_doc(lsp, "indented.xml", INDENTED)
    try:
        td = pytest_lsp.client_capabilities(lsp.spec).text_document
        item_caps = td.completion.completion_item if td and td.completion else None
        modes = item_caps.insert_text_mode_support if item_caps else None
        as_is = bool(modes and types.InsertTextMode.AsIs in modes.value_set)
        # Ctrl+Space at column 0, 2 and 6 of `      <Sequence>`: node types with their
        # '<', the edit ending where the tag starts, so that the tag stays.
        line_at = INDENTED.index("      <Sequence>")
        tag_at = line_at + 6
        for column in (0, 2, 6):
            at = line_at + column
            items = by_label(await complete_at(lsp, uri, INDENTED, at))
            sleep = items["Sleep"]
            assert isinstance(sleep.text_edit, types.TextEdit)
            assert sleep.text_edit.range == rng(lsp, INDENTED, (at, tag_at))
            lead = " " * (6 - column)
            body = '<Sleep msec="${1}"/>' if lsp.snippets else "<Sleep/>"
            if as_is:  # VS Code: the new node on its own line, the tag on the next
                tail = ("$0" if lsp.snippets else "") + "\n      "
                assert sleep.text_edit.new_text == lead + body + tail
                assert sleep.insert_text_mode == types.InsertTextMode.AsIs
            else:  # before the tag, on its line
                assert sleep.text_edit.new_text == lead + body
                assert sleep.insert_text_mode is None
            assert {"Sequence", "Fallback", "AlwaysFailure"} <= set(items)
        # An empty line between tags inside the Sequence: inserted at the cursor.
        at = INDENTED.index("\n\n") + 1
        items = by_label(await complete_at(lsp, uri, INDENTED, at))
        sleep = items["Sleep"]
        assert isinstance(sleep.text_edit, types.TextEdit)
        assert sleep.text_edit.range == rng(lsp, INDENTED, (at, at))
        assert sleep.text_edit.new_text == ('<Sleep msec="${1}"/>' if lsp.snippets else "<Sleep/>")
        assert sleep.insert_text_mode is None
    finally:
        close_doc(lsp, uri)


async def test_completion_capability(lsp: NavClient) -> None:
    opts = lsp.init_result.capabilities.completion_provider
    assert (
        opts is not None
        and "<" in (opts.trigger_characters or [])
        and "{" in (opts.trigger_characters or [])
    )


# --- folding, linked editing, hover -------------------------------------------------------


async def test_folding_ranges(lsp: NavClient) -> None:
    got = await lsp.text_document_folding_range_async(
        types.FoldingRangeParams(text_document=ident(lsp.uri("a.xml")))
    )
    assert got is not None
    assert sorted((f.start_line, f.end_line, f.kind) for f in got) == [
        (0, 7, types.FoldingRangeKind.Region),
        (2, 6, types.FoldingRangeKind.Region),
        (3, 5, types.FoldingRangeKind.Region),
    ]


async def test_linked_editing_of_start_and_end_tag(lsp: NavClient) -> None:
    got = await lsp.text_document_linked_editing_range_async(
        types.LinkedEditingRangeParams(
            text_document=ident(lsp.uri("a.xml")), position=doc_pos(lsp, A_XML, "<Fallback", into=4)
        )
    )
    assert got is not None
    start, end = A_XML.index("<Fallback") + 1, A_XML.index("</Fallback") + 2
    assert list(got.ranges) == [
        rng(lsp, A_XML, (start, start + len("Fallback"))),
        rng(lsp, A_XML, (end, end + len("Fallback"))),
    ]


async def test_hover_shows_the_ports_of_a_model_declared_in_another_file(lsp: NavClient) -> None:
    got = await lsp.text_document_hover_async(
        types.HoverParams(
            text_document=ident(lsp.uri("a.xml")), position=doc_pos(lsp, A_XML, "<MoveBase", into=2)
        )
    )
    assert got is not None and isinstance(got.contents, types.MarkupContent)
    md = got.contents.value
    assert "Action declared in the TreeNodesModel of" in md and "b.xml" in md
    # A list, one port a line, narrow enough for any hover (a wide table is cut off).
    assert "\n- `goal`: input, `Pose`, no default; Where to go\n" in md
    assert md.endswith("\n- `speed`: input, `double`, default `0.5`; How & fast")
    assert "|" not in md
    assert got.range == rng(lsp, A_XML, span(A_XML, "MoveBase"))
