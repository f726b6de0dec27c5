"""The project around the documents through the server: a colcon workspace whose packages
depend (transitively) on an installed package found through AMENT_PREFIX_PATH, the
configuration's ``exclude``, ``modelFiles`` and ``btcpp`` answered to
``workspace/configuration``, and the BehaviorTree.CPP version logged once per change.

The server process gets its own AMENT_PREFIX_PATH (a fake ROS installation in a temporary
folder) and the workspace folder below it.
"""

from __future__ import annotations

import os
import shutil
import tempfile
from collections.abc import AsyncIterator
from pathlib import Path
from typing import Any

import pytest
import pytest_lsp
from lsprotocol import types
from pygls.exceptions import JsonRpcException
from pygls.uris import from_fs_path
from pytest_lsp import ClientServerConfig

from tests.pinned import LATER
from tests.server.conftest import PROFILES, SERVER_COMMAND, BtClient, make_client

pytestmark = pytest.mark.asyncio(loop_scope="module")

Sev = types.DiagnosticSeverity

_TMP = Path(tempfile.mkdtemp(prefix="bt-lsp-project-")).resolve()
PREFIX = _TMP / "opt" / "ros" / "humble"
WS = _TMP / "ws"
SRC = WS / "src"


def write(path: Path, text: str) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text, encoding="utf-8")
    return path


def manifest(name: str, *depends: str) -> str:
    deps = "".join(f"<depend>{d}</depend>" for d in depends)
    return f'<package format="3"><name>{name}</name>{deps}</package>'


NAV2_CATALOG = (
    '<?xml version="1.0"?>\n<root BTCPP_format="4">\n  <TreeNodesModel>\n'
    '    <Action ID="FollowPath">\n'
    '      <input_port name="path" type="nav_msgs::msg::Path"/>\n'
    '      <input_port name="controller_id" type="std::string"/>\n'
    "    </Action>\n"
    "  </TreeNodesModel>\n</root>\n"
)
APP_CATALOG = (
    '<root BTCPP_format="4"><TreeNodesModel>'
    '<Action ID="Dock"><input_port name="station" type="int"/></Action>'
    "</TreeNodesModel></root>\n"
)
LEGACY = (
    '<root BTCPP_format="4">\n'
    '  <BehaviorTree ID="OldTree"><AlwaysSuccess/></BehaviorTree>\n'
    '  <TreeNodesModel><Action ID="Legacy"/></TreeNodesModel>\n'
    "</root>\n"
)

# Installed: nav2_behavior_tree with its shipped catalog.  Workspace: app -> lib ->
# nav2_behavior_tree (app sees nav2's nodes through lib), and v3pkg on BehaviorTree.CPP 3.
write(PREFIX / "share" / "nav2_behavior_tree" / "package.xml", manifest("nav2_behavior_tree"))
write(PREFIX / "share" / "nav2_behavior_tree" / "nav2_tree_nodes.xml", NAV2_CATALOG)
write(SRC / "lib" / "package.xml", manifest("lib", "nav2_behavior_tree"))
write(SRC / "app" / "package.xml", manifest("app", "lib"))
write(SRC / "app" / "old" / "legacy.xml", LEGACY)
write(SRC / "v3pkg" / "package.xml", manifest("v3pkg", "behaviortree_cpp_v3"))
write(SRC / "humble_app" / "package.xml", manifest("humble_app", "behaviortree_cpp_v3"))
CATALOG = write(_TMP / "catalogs" / "app_nodes.xml", APP_CATALOG)
write(WS / "bt-lsp.toml", 'exclude = ["src/app/old/**"]\n')

CONFIG = ClientServerConfig(
    server_command=SERVER_COMMAND,
    client_factory=make_client,
    server_env={
        **os.environ,
        "AMENT_PREFIX_PATH": f"{_TMP / 'nowhere'}{os.pathsep}{PREFIX}",
        "XDG_CACHE_HOME": str(_TMP / "cache"),
    },
)


@pytest_lsp.fixture(config=CONFIG, scope="module")
async def client(lsp_client: BtClient) -> AsyncIterator[BtClient]:
    lsp_client.profile_name = "vscode"
    lsp_client.profile = PROFILES["vscode"]
    lsp_client.set_configuration({"debounceMs": 0}, section="btLsp")
    lsp_client.init_result = await lsp_client.initialize_session(
        types.InitializeParams(
            capabilities=PROFILES["vscode"].capabilities(),
            initialization_options={"debounceMs": 0},
            workspace_folders=[types.WorkspaceFolder(uri=from_fs_path(str(WS)) or "", name="ws")],
        )
    )
    lsp_client.encoding = "utf-16"
    yield lsp_client
    await lsp_client.shutdown_session()
    shutil.rmtree(_TMP, ignore_errors=True)


def open_file(client: BtClient, path: Path, text: str) -> str:
    write(path, text)
    uri = from_fs_path(str(path)) or ""
    client.opened.add(uri)
    client.text_document_did_open(
        types.DidOpenTextDocumentParams(
            text_document=types.TextDocumentItem(uri=uri, language_id="xml", version=1, text=text)
        )
    )
    return uri


def close(client: BtClient, uri: str) -> None:
    client.close(uri)


def found(diags: list[types.Diagnostic]) -> set[tuple[str, Any]]:
    """The pinned codes among ``diags`` (tests/pinned.py), with their severities."""
    return {(str(d.code), d.severity) for d in diags if d.code not in LATER}


async def until(client: BtClient, uri: str, ok: Any, what: str) -> list[types.Diagnostic]:
    def check() -> list[types.Diagnostic] | None:
        last = client.latest(uri)
        if last is not None and ok(found(list(last.diagnostics))):
            return list(last.diagnostics)
        return None

    return await client.wait_until(check, what)


def configure(client: BtClient, section: dict[str, Any]) -> None:
    """Change what the client answers to workspace/configuration and tell the server."""
    client.set_configuration(section, section="btLsp")
    client.workspace_did_change_configuration(types.DidChangeConfigurationParams(settings=None))


FOLLOW = (
    '<root BTCPP_format="4" main_tree_to_execute="T">\n'
    '  <BehaviorTree ID="T">\n'
    '    <FollowPath path="{path}" controller_id="FollowPath" goal_checker="x"/>\n'
    "  </BehaviorTree>\n"
    "</root>\n"
)


async def test_an_installed_dependency_catalog_is_authoritative(client: BtClient) -> None:
    uri = open_file(client, SRC / "app" / "trees" / "follow.xml", FOLLOW)
    diags = await client.pushed(uri, 1)
    assert found(diags) == {("undeclared-port", Sev.Error)}
    [d] = diags
    assert "goal_checker" in d.message
    hover = await client.hover(uri, client.pos(FOLLOW, FOLLOW.index("FollowPath") + 2))
    assert hover is not None and isinstance(hover.contents, types.MarkupContent)
    assert "the node catalog a ROS package ships (authoritative)" in (hover.contents.value)
    close(client, uri)
    # A package that does not depend on nav2 does not see its nodes.
    other = open_file(client, SRC / "v3pkg" / "trees" / "follow.xml", FOLLOW)
    codes = {c for c, _ in found(await client.pushed(other, 1))}
    assert "unknown-node" in codes and "undeclared-port" not in codes


USES_EXCLUDED = (
    '<root BTCPP_format="4" main_tree_to_execute="T">\n'
    '  <BehaviorTree ID="T"><Sequence><Legacy/><SubTree ID="OldTree"/></Sequence></BehaviorTree>\n'
    "</root>\n"
)


async def test_excluded_files_are_not_the_workspace_but_an_open_one_is_checked(
    client: BtClient,
) -> None:
    legacy = from_fs_path(str(SRC / "app" / "old" / "legacy.xml")) or ""
    uri = open_file(client, SRC / "app" / "trees" / "uses.xml", USES_EXCLUDED)
    diags = await client.pushed(uri, 1)
    codes = {c for c, _ in found(diags)}
    # Neither the excluded file's model nor its tree is known.
    assert {"unknown-node", "unknown-subtree"} <= codes
    assert all("legacy.xml" not in d.message for d in diags)
    symbols = await client.workspace_symbol_async(types.WorkspaceSymbolParams(query="OldTree"))
    assert not symbols
    assert client.latest(legacy) is None  # never diagnosed while closed
    # Opened, it is checked like any document (an empty Sequence, say).
    text = LEGACY.replace("<AlwaysSuccess/>", "<Sequence/>")
    opened = open_file(client, SRC / "app" / "old" / "legacy.xml", text)
    assert "child-count" in {c for c, _ in found(await client.pushed(opened, 1))}
    write(SRC / "app" / "old" / "legacy.xml", LEGACY)


MODELS = (
    '<root BTCPP_format="4" main_tree_to_execute="T">\n'
    '  <BehaviorTree ID="T"><Sequence><Dock station="1" statoin="2"/><Script code="x:=1"/>'
    "</Sequence></BehaviorTree>\n"
    "</root>\n"
)


async def test_model_files_and_btcpp_through_workspace_configuration(client: BtClient) -> None:
    uri = open_file(client, WS / "loose" / "models.xml", MODELS)
    before = found(await client.pushed(uri, 1))
    assert ("undeclared-port", Sev.Error) not in before
    try:
        configure(client, {"debounceMs": 0, "modelFiles": [str(CATALOG)]})
        # The catalog named in the settings is authoritative: the misspelt port is an error.
        await until(
            client, uri, lambda f: ("undeclared-port", Sev.Error) in f, "undeclared-port error"
        )
        configure(client, {"debounceMs": 0, "modelFiles": [str(CATALOG)], "btcpp": "3"})
        # BehaviorTree.CPP 3.8 has no Script node (and checks remapped ports too).
        diags = await until(
            client,
            uri,
            lambda f: ("undeclared-port", Sev.Error) in f and "unknown-node" in {c for c, _ in f},
            "v3 findings",
        )
        assert any("Script" in d.message for d in diags if d.code == "unknown-node")
    finally:
        configure(client, {"debounceMs": 0})
    await until(client, uri, lambda f: f == before, "the findings without the settings")


HUMBLE = (
    '<root main_tree_to_execute="T">\n'
    '  <BehaviorTree ID="T">\n'
    "    <SequenceStar>\n"
    '      <Parallel success_threshold="1"><AlwaysSuccess/></Parallel>\n'
    '      <Script code="x := 1"/>\n'
    "      \n"
    "    </SequenceStar>\n"
    "  </BehaviorTree>\n"
    "</root>\n"
)


async def test_a_v3_package_gets_3_8s_nodes_in_diagnostics_completion_and_hover(
    client: BtClient,
) -> None:
    uri = open_file(client, SRC / "humble_app" / "trees" / "t.xml", HUMBLE)
    diags = [d for d in await client.pushed(uri, 1) if d.code not in LATER]
    # No advice to add BTCPP_format="4"; SequenceStar and Parallel's thresholds are
    # 3.8's; Script is version 4's only.
    assert found(diags) == {("unknown-node", Sev.Warning)}
    [d] = diags
    assert "'Script'" in d.message and "BehaviorTree.CPP 3" in d.message
    at = HUMBLE.index("      \n") + 6
    result = await client.text_document_completion_async(
        types.CompletionParams(
            text_document=types.TextDocumentIdentifier(uri=uri),
            position=client.pos(HUMBLE, at),
        )
    )
    items = result.items if isinstance(result, types.CompletionList) else result or []
    labels = {i.label for i in items}
    assert {"SequenceStar", "BlackboardCheckString"} <= labels
    assert not labels & {"Script", "SequenceWithMemory", "Sleep"}
    hover = await client.hover(uri, client.pos(HUMBLE, HUMBLE.index("Parallel") + 1))
    assert hover is not None and isinstance(hover.contents, types.MarkupContent)
    text = hover.contents.value
    assert "BehaviorTree.CPP 3.8" in text
    assert "success_threshold" in text and "failure_threshold" in text
    assert "success_count" not in text
    # Go to definition leads to 3.8's built-in catalog.
    defined = await client.text_document_definition_async(
        types.DefinitionParams(
            text_document=types.TextDocumentIdentifier(uri=uri),
            position=client.pos(HUMBLE, HUMBLE.index("SequenceStar") + 2),
        )
    )
    assert isinstance(defined, list) and len(defined) == 1
    assert isinstance(defined[0], types.Location)
    assert defined[0].uri.endswith("/builtins-v3.xml")
    # 3.8's SequenceStar keeps its name: a rename is refused.
    with pytest.raises(JsonRpcException) as info:
        await client.text_document_prepare_rename_async(
            types.PrepareRenameParams(
                text_document=types.TextDocumentIdentifier(uri=uri),
                position=client.pos(HUMBLE, HUMBLE.index("SequenceStar") + 2),
            )
        )
    assert "'SequenceStar' is a built-in node type" in str(info.value)


async def test_the_version_is_logged_once_per_change(client: BtClient) -> None:
    folder = SRC / "v3pkg"

    def lines() -> list[str]:
        return [
            m.message
            for m in client.log_messages
            if f"bt-lsp: {folder}: BehaviorTree.CPP" in m.message
        ]

    tree = (
        '<root main_tree_to_execute="T"><BehaviorTree ID="T">'
        "<SequenceStar><AlwaysSuccess/></SequenceStar></BehaviorTree></root>\n"
    )
    uri = open_file(client, folder / "trees" / "a.xml", tree)
    await client.pushed(uri, 1)
    other = open_file(client, folder / "trees" / "b.xml", tree)
    await client.pushed(other, 1)
    for version in (2, 3):
        client.replace(uri, version, tree.replace("T", f"T{version}"))
        await client.pushed(uri, version)
    configure(client, {"debounceMs": 0})
    manifest_uri = from_fs_path(str(folder / "package.xml")) or ""
    client.workspace_did_change_watched_files(
        types.DidChangeWatchedFilesParams(
            changes=[types.FileEvent(uri=manifest_uri, type=types.FileChangeType.Changed)]
        )
    )
    client.replace(uri, 4, tree)
    await client.pushed(uri, 4)
    await client.barrier()
    assert len(lines()) == 1 and "BehaviorTree.CPP 3 (" in lines()[0]
    # The package moves to BehaviorTree.CPP 4: said once more.
    write(folder / "package.xml", manifest("v3pkg", "behaviortree_cpp"))
    client.workspace_did_change_watched_files(
        types.DidChangeWatchedFilesParams(
            changes=[types.FileEvent(uri=manifest_uri, type=types.FileChangeType.Changed)]
        )
    )

    def twice() -> list[str] | None:
        return lines() if len(lines()) >= 2 else None

    logged = await client.wait_until(twice, "the new version in the log")
    client.replace(uri, 5, tree.replace("T", "T5"))
    await client.pushed(uri, 5)
    await client.barrier()
    assert len(lines()) == 2 and "BehaviorTree.CPP 4 (" in logged[1]
