"""Nodes learned from C++ with authority, through the server (``tests/data/cpp_app``).

In ``robot_app`` every registration is visible, so an unknown node type is an error with
"did you mean" from the C++ catalog and an undeclared port says where the node is
registered; in ``robot_ext`` a dependency is nowhere to be found, so the same unknown
types stay advisory.  An edit of the C++ that registers the missing node clears its error.
"""

from __future__ import annotations

import os
import shutil
import tempfile
from collections.abc import AsyncIterator
from pathlib import Path

import pytest
import pytest_lsp
from lsprotocol import types
from pytest_lsp import ClientServerConfig

from tests.server.conftest import SERVER_COMMAND, BtClient, make_client

_TMP = Path(tempfile.mkdtemp(prefix="bt-lsp-cpp-app-"))
WS = _TMP / "ws"
shutil.copytree(Path(__file__).parents[1] / "data" / "cpp_app", WS)
APP = WS / "src" / "robot_app" / "trees" / "app.xml"
EXT = WS / "src" / "robot_ext" / "trees" / "ext.xml"
MAIN_CPP = WS / "src" / "robot_app" / "src" / "main.cpp"

CONFIG = ClientServerConfig(
    server_command=SERVER_COMMAND,
    client_factory=make_client,
    server_env={**os.environ, "XDG_CACHE_HOME": str(_TMP / "cache"), "AMENT_PREFIX_PATH": ""},
)


@pytest_lsp.fixture(config=CONFIG, scope="module")
async def app_client(lsp_client: BtClient) -> AsyncIterator[BtClient]:
    await lsp_client.start_in_workspace(WS)
    yield lsp_client
    await lsp_client.shutdown_session()


def _at(diags: list[types.Diagnostic], line: int, code: str) -> types.Diagnostic | None:
    return next((d for d in diags if d.range.start.line == line and d.code == code), None)


def _teleport_is(severity: types.DiagnosticSeverity):  # type: ignore[no-untyped-def]
    def check(ds) -> bool:  # type: ignore[no-untyped-def]
        d = _at(list(ds), 9, "unknown-node")
        return d is not None and d.severity == severity

    return check


@pytest.mark.asyncio(loop_scope="module")
async def test_complete_registrations_make_errors(app_client: BtClient) -> None:
    uri = app_client.open_path(APP, "xml")
    diags = await app_client.diagnostics_until(uri, _teleport_is(types.DiagnosticSeverity.Error))
    port = _at(diags, 3, "undeclared-port")
    assert port is not None and port.severity == types.DiagnosticSeverity.Error
    assert "(registered in src/robot_app/src/main.cpp:21;" in port.message
    typo = _at(diags, 5, "unknown-node")
    assert typo is not None and typo.severity == types.DiagnosticSeverity.Error
    assert "did you mean 'Charge'?" in typo.message
    scan = _at(diags, 7, "undeclared-port")  # Scan's ports are built by code: advisory
    assert scan is not None and scan.severity == types.DiagnosticSeverity.Hint


@pytest.mark.asyncio(loop_scope="module")
async def test_a_dependency_not_found_keeps_them_advisory(app_client: BtClient) -> None:
    uri = app_client.open_path(EXT, "xml")

    def read(ds) -> bool:  # type: ignore[no-untyped-def]
        d = _at(list(ds), 9, "unknown-node")
        return d is not None and "dependency vendor_nodes of robot_ext" in d.message

    # Once the C++ is read (before, nothing is known of it), the hint says why.
    diags = await app_client.diagnostics_until(uri, read)
    teleport = _at(diags, 9, "unknown-node")
    assert teleport is not None and teleport.severity == types.DiagnosticSeverity.Hint
    typo = _at(diags, 5, "unknown-node")
    assert typo is not None and typo.severity == types.DiagnosticSeverity.Warning


@pytest.mark.asyncio(loop_scope="module")
async def test_registering_the_node_in_cpp_clears_its_error(app_client: BtClient) -> None:
    uri = app_client.open_path(APP, "xml")
    await app_client.diagnostics_until(uri, _teleport_is(types.DiagnosticSeverity.Error))
    cpp_uri = app_client.open_path(MAIN_CPP, "cpp")
    text = MAIN_CPP.read_text().replace(
        '  factory.registerNodeType<Dock>("Dock");',
        '  factory.registerNodeType<Dock>("Dock");\n  factory.registerNodeType<Dock>("Teleport");',
    )
    app_client.text_document_did_change(
        types.DidChangeTextDocumentParams(
            text_document=types.VersionedTextDocumentIdentifier(uri=cpp_uri, version=2),
            content_changes=[types.TextDocumentContentChangeWholeDocument(text=text)],
        )
    )
    diags = await app_client.diagnostics_until(
        uri, lambda ds: _at(list(ds), 9, "unknown-node") is None
    )
    assert _at(diags, 5, "unknown-node") is not None  # the typo is still one
