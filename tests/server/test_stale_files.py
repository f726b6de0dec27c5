"""Files on disk are not seen as they were first read by a client that does not watch
files (no ``workspace.didChangeWatchedFiles``): a file whose modification time or size
changed is read again before the diagnostics use it, and on didSave and didClose."""

from __future__ import annotations

import asyncio
import os
import sys
import tempfile
from collections.abc import AsyncIterator
from pathlib import Path

import pytest
import pytest_lsp
from lsprotocol import types
from pygls.protocol import default_converter
from pygls.uris import from_fs_path
from pytest_lsp import ClientServerConfig, LanguageClient
from pytest_lsp.client import DEFAULT_CLIENT_FEATURES, register_lsp_features

from tests.pinned import LATER

pytestmark = pytest.mark.asyncio(loop_scope="module")

TIMEOUT = 30.0
A_XML = """<root BTCPP_format="4" main_tree_to_execute="Main">
  <include path="b.xml"/>
  <BehaviorTree ID="Main">
    <SubTree ID="Sub"/>
  </BehaviorTree>
</root>
"""
B_XML = """<root BTCPP_format="4">
  <BehaviorTree ID="Sub">
    <AlwaysSuccess/>
  </BehaviorTree>
</root>
"""


class Client(LanguageClient):
    ws: Path


def make_client() -> Client:
    client = Client(converter_factory=default_converter)
    register_lsp_features(client, dict(DEFAULT_CLIENT_FEATURES))
    return client


@pytest_lsp.fixture(
    config=ClientServerConfig(
        server_command=[sys.executable, "-m", "bt_lsp", "serve"], client_factory=make_client
    ),
    scope="module",
)
async def client(lsp_client: Client) -> AsyncIterator[None]:
    ws = Path(tempfile.mkdtemp(prefix="bt-lsp-stale-")).resolve()
    lsp_client.ws = ws
    caps = pytest_lsp.client_capabilities("visual-studio-code")
    assert caps.workspace is not None
    caps.workspace.did_change_watched_files = None  # this client does not watch files
    uri = from_fs_path(str(ws))
    await lsp_client.initialize_session(
        types.InitializeParams(
            capabilities=caps,
            workspace_folders=[types.WorkspaceFolder(uri=uri or "", name="ws")],
            initialization_options={"debounceMs": 0},
        )
    )
    yield
    await lsp_client.shutdown_session()


def _uri(client: Client, name: str) -> str:
    uri = from_fs_path(str(client.ws / name))
    assert uri is not None
    return uri


async def _codes(client: Client, uri: str, version: int, want: set[str]) -> None:
    """Wait until the diagnostics published for ``uri`` at ``version`` have ``want``."""

    def now() -> set[str] | None:
        found = client.diagnostics.get(uri)
        return None if found is None else {str(d.code) for d in found if d.code not in LATER}

    loop = asyncio.get_running_loop()
    deadline = loop.time() + TIMEOUT
    while now() != want:
        assert loop.time() < deadline, f"{uri}: {now()} instead of {want}"
        await asyncio.sleep(0.05)


def _change(client: Client, uri: str, version: int, text: str) -> None:
    client.text_document_did_change(
        types.DidChangeTextDocumentParams(
            text_document=types.VersionedTextDocumentIdentifier(uri=uri, version=version),
            content_changes=[types.TextDocumentContentChangeWholeDocument(text=text)],
        )
    )


async def test_a_file_changed_on_disk_is_read_again(client: Client) -> None:
    (client.ws / "a.xml").write_text(A_XML, encoding="utf-8")
    b = client.ws / "b.xml"
    b.write_text(B_XML, encoding="utf-8")
    a = _uri(client, "a.xml")
    client.text_document_did_open(
        types.DidOpenTextDocumentParams(
            text_document=types.TextDocumentItem(uri=a, language_id="xml", version=1, text=A_XML)
        )
    )
    await _codes(client, a, 1, set())
    # The called tree is renamed on disk, by another program: no notification.
    b.write_text(B_XML.replace('ID="Sub"', 'ID="Other"'), encoding="utf-8")
    await asyncio.sleep(1.2)  # the server compares with the disk at most once a second
    _change(client, a, 2, A_XML + "\n")
    await _codes(client, a, 2, {"unknown-subtree"})

    # Now in the editor: b.xml opened and fixed, then closed without saving.
    b_uri = _uri(client, "b.xml")
    on_disk = b.read_text(encoding="utf-8")
    fixed = on_disk.replace('ID="Other"', 'ID="Sub"')  # the same size
    _open(client, b_uri, on_disk)
    _change(client, b_uri, 2, fixed)
    await _codes(client, a, 2, set())  # the open document counts
    _close(client, b_uri)
    await _codes(client, a, 2, {"unknown-subtree"})  # the file on disk counts again

    # Opened, fixed and saved: written with the same size and modification time as the
    # version read before, so only didSave and didClose can tell.
    before = b.stat()
    _open(client, b_uri, on_disk)
    _change(client, b_uri, 2, fixed)
    await _codes(client, a, 2, set())
    b.write_text(fixed, encoding="utf-8")
    os.utime(b, ns=(before.st_atime_ns, before.st_mtime_ns))
    client.text_document_did_save(
        types.DidSaveTextDocumentParams(text_document=types.TextDocumentIdentifier(uri=b_uri))
    )
    _close(client, b_uri)
    await asyncio.sleep(0.5)
    await _codes(client, a, 2, set())  # the saved file, not the version first read
    _close(client, a)


def _open(client: Client, uri: str, text: str) -> None:
    client.text_document_did_open(
        types.DidOpenTextDocumentParams(
            text_document=types.TextDocumentItem(uri=uri, language_id="xml", version=1, text=text)
        )
    )


def _close(client: Client, uri: str) -> None:
    client.text_document_did_close(
        types.DidCloseTextDocumentParams(text_document=types.TextDocumentIdentifier(uri=uri))
    )


NEW_CALLER = """<root BTCPP_format="4" main_tree_to_execute="Caller">
  <BehaviorTree ID="Caller">
    <SubTree ID="Created"/>
  </BehaviorTree>
</root>
"""
CREATED = """<root BTCPP_format="4">
  <BehaviorTree ID="Created">
    <AlwaysSuccess/>
  </BehaviorTree>
</root>
"""


async def _subtree_message(client: Client, uri: str, has: str) -> None:
    """Wait until the unknown-subtree message published for ``uri`` says ``has``
    (``""``: says no file defines the tree)."""

    def message() -> str:
        found = [d.message for d in client.diagnostics.get(uri, []) if d.code == "unknown-subtree"]
        return found[0] if found else ""

    loop = asyncio.get_running_loop()
    deadline = loop.time() + TIMEOUT
    while (
        (has not in message()) if has else ("but no tree with that ID is defined" not in message())
    ):
        assert loop.time() < deadline, f"{uri}: {message()!r}"
        await asyncio.sleep(0.05)


async def test_a_file_created_or_deleted_on_disk_is_seen(client: Client) -> None:
    """A tree file created after the workspace was first walked, in a new folder, is
    found: the caller's hint says which file defines the tree it calls; deleting the file
    makes the tree unknown everywhere again."""
    (client.ws / "caller.xml").write_text(NEW_CALLER, encoding="utf-8")
    caller = _uri(client, "caller.xml")
    _open(client, caller, NEW_CALLER)
    await _subtree_message(client, caller, "")

    made = client.ws / "trees" / "created.xml"
    made.parent.mkdir()
    made.write_text(CREATED, encoding="utf-8")
    await asyncio.sleep(1.2)  # the server compares with the disk at most once a second
    _change(client, caller, 2, NEW_CALLER + "\n")
    await _subtree_message(client, caller, "defined in created.xml")

    made.unlink()
    await asyncio.sleep(1.2)
    _change(client, caller, 3, NEW_CALLER)
    await _subtree_message(client, caller, "")

    # Created again in the folder that is now known (its modification time changes, not
    # the workspace folder's).
    made.write_text(CREATED, encoding="utf-8")
    await asyncio.sleep(1.2)
    _change(client, caller, 4, NEW_CALLER + "\n")
    await _subtree_message(client, caller, "defined in created.xml")
    _close(client, caller)
    made.unlink()


UNFORMATTED = """<root main_tree_to_execute="Main">
  <BehaviorTree ID="Main">
    <AlwaysSuccess/>
  </BehaviorTree>
</root>
"""


async def test_a_configuration_file_created_changed_or_deleted_on_disk_counts(
    client: Client,
) -> None:
    """bt-lsp.toml written next to an open document after it was opened, by another
    program: its settings apply at the next check of the disk, its error is published on
    it, and deleting it brings the defaults back."""
    folder = client.ws / "configured"
    folder.mkdir()
    (folder / "tree.xml").write_text(UNFORMATTED, encoding="utf-8")
    uri = _uri(client, "configured/tree.xml")
    _open(client, uri, UNFORMATTED)
    await _codes(client, uri, 1, {"missing-format"})

    config = folder / "bt-lsp.toml"
    config_uri = _uri(client, "configured/bt-lsp.toml")
    config.write_text('[severity]\nmissing-format = "off"\n', encoding="utf-8")
    await asyncio.sleep(1.2)  # the server compares with the disk at most once a second
    _change(client, uri, 2, UNFORMATTED + "\n")
    await _codes(client, uri, 2, set())

    # Changed: an error (then the file is ignored and the defaults apply).
    config.write_text('[severity]\nmissing-format = "of"\n', encoding="utf-8")
    await asyncio.sleep(1.2)
    _change(client, uri, 3, UNFORMATTED)
    await _codes(client, uri, 3, {"missing-format"})
    await _codes(client, config_uri, 0, {"config-error"})

    config.write_text('[severity]\nmissing-format = "off"\n', encoding="utf-8")
    await asyncio.sleep(1.2)
    _change(client, uri, 4, UNFORMATTED + "\n")
    await _codes(client, uri, 4, set())
    await _codes(client, config_uri, 0, set())

    config.unlink()
    await asyncio.sleep(1.2)
    _change(client, uri, 5, UNFORMATTED)
    await _codes(client, uri, 5, {"missing-format"})
    _close(client, uri)
