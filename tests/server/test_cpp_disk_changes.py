"""C++ files changed on disk while the server runs, with and without watched files.

With watched files, ``register.cpp`` deleted and created again stayed out of the
catalog for good (every node it registers "not registered"); a batch of watched-file
events with one event of an unknown type was dropped as a whole.  Without watched files,
C++ changed on disk was never seen: it is now revalidated by its stamps when the
diagnostics are computed (at most once a second), as the XML files are.
"""

from __future__ import annotations

import asyncio
import os
import shutil
import tempfile
from collections.abc import AsyncIterator, Sequence
from pathlib import Path

import pytest
import pytest_lsp
from lsprotocol import types
from pygls.uris import from_fs_path
from pytest_lsp import ClientServerConfig

from tests.server.conftest import SERVER_COMMAND, BtClient, make_client, raw_notify

pytestmark = pytest.mark.asyncio(loop_scope="module")

_TMP = Path(tempfile.mkdtemp(prefix="bt-lsp-cpp-disk-"))
SOURCE = Path(__file__).parents[1] / "data" / "cpp_project"

CONFIG = ClientServerConfig(
    server_command=SERVER_COMMAND,
    client_factory=make_client,
    server_env={**os.environ, "XDG_CACHE_HOME": str(_TMP / "cache")},
)


def _workspace(name: str) -> Path:
    ws = _TMP / name
    shutil.copytree(SOURCE, ws)
    return ws


def _main(ws: Path) -> Path:
    return ws / "src" / "robot_nodes" / "trees" / "main.xml"


def _register(ws: Path) -> Path:
    return ws / "src" / "robot_nodes" / "src" / "register.cpp"


def _port_checked(ds: Sequence[types.Diagnostic]) -> bool:
    """BatteryOk is registered (read from register.cpp): its port value is checked."""
    return any(d.code == "invalid-port-value" and d.range.start.line == 3 for d in ds)


def _unregistered(ds: Sequence[types.Diagnostic]) -> bool:
    """BatteryOk is not registered any more: it is an unknown node, its port unchecked."""
    return not _port_checked(ds) and any(
        d.code == "unknown-node" and d.range.start.line == 3 for d in ds
    )


def _event(path: Path, kind: int) -> dict[str, object]:
    return {"uri": from_fs_path(str(path)), "type": kind}


@pytest_lsp.fixture(config=CONFIG, scope="module")
async def watching(lsp_client: BtClient) -> AsyncIterator[BtClient]:
    ws = _workspace("watched")
    await lsp_client.start_in_workspace(ws)
    lsp_client.ws = ws  # type: ignore[attr-defined]
    yield lsp_client
    await lsp_client.shutdown_session()


async def test_a_watched_cpp_file_deleted_and_created_again(watching: BtClient) -> None:
    client = watching
    ws: Path = client.ws  # type: ignore[attr-defined]
    reg = _register(ws)
    text = reg.read_text()
    for _ in range(200):  # (registered once the session is initialized)
        if any(r.method == "workspace/didChangeWatchedFiles" for r in client.registrations):
            break
        await asyncio.sleep(0.05)
    else:
        raise AssertionError("the server did not register for watched files")
    main = client.open_path(_main(ws), "xml")
    await client.diagnostics_until(main, _port_checked)
    reg.unlink()
    raw_notify(client, "workspace/didChangeWatchedFiles", {"changes": [_event(reg, 3)]})
    await client.diagnostics_until(main, _unregistered)
    reg.write_text(text)
    seen = len(client.log_messages)
    # With an event of an unknown type in the batch: the others are handled all the same.
    changes = [_event(ws / "src" / "x.cpp", 4), _event(reg, 1), {"uri": 5, "type": 2}]
    raw_notify(client, "workspace/didChangeWatchedFiles", {"changes": changes})
    await client.diagnostics_until(main, _port_checked)
    logged = [m.message for m in client.log_messages[seen:]]
    assert any("2 of 3 events ignored" in m for m in logged), logged
    client.close(main)


@pytest_lsp.fixture(config=CONFIG, scope="module")
async def unwatching(lsp_client: BtClient) -> AsyncIterator[BtClient]:
    ws = _workspace("unwatched")
    caps = pytest_lsp.client_capabilities("visual-studio-code")
    assert caps.workspace is not None
    caps.workspace.did_change_watched_files = None  # this client does not watch files
    lsp_client.profile_name = "vscode"
    await lsp_client.initialize_session(
        types.InitializeParams(
            capabilities=caps,
            workspace_folders=[types.WorkspaceFolder(uri=from_fs_path(str(ws)) or "", name="ws")],
            initialization_options={"debounceMs": 0},
        )
    )
    lsp_client.ws = ws  # type: ignore[attr-defined]
    yield lsp_client
    await lsp_client.shutdown_session()


async def test_cpp_changed_on_disk_without_watching(unwatching: BtClient) -> None:
    client = unwatching
    ws: Path = client.ws  # type: ignore[attr-defined]
    reg = _register(ws)
    text = reg.read_text()
    path = _main(ws)
    main = client.open_path(path, "xml")
    await client.diagnostics_until(main, _port_checked)
    version = 1

    async def after_a_second(check: object) -> None:
        nonlocal version
        await asyncio.sleep(1.2)  # the server looks at the disk at most once a second
        version += 1
        client.replace(main, version, path.read_text() + "\n" * (version % 2))
        await client.diagnostics_until(main, check)  # type: ignore[arg-type]

    # Changed: BatteryOk registered under another ID.
    reg.write_text(text.replace('"BatteryOk"', '"BatteryLow"'))
    await after_a_second(_unregistered)
    # Deleted, then created again with the original registrations.
    reg.write_text(text)
    await after_a_second(_port_checked)
    reg.unlink()
    await after_a_second(_unregistered)
    reg.write_text(text)
    await after_a_second(_port_checked)
    client.close(main)
