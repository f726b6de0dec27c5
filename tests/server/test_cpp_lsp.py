"""The C++ catalog through the server: a colcon workspace with nodes registered in C++.

The workspace (a copy of ``tests/data/cpp_project``) is the server's workspace folder;
its C++ is read in the background with work-done progress, then the trees' diagnostics,
hover, definition and completion use the learned nodes, and an edit of an open C++
document re-reads it and refreshes the XML.
"""

from __future__ import annotations

import asyncio
import os
import shutil
import tempfile
from collections.abc import AsyncIterator
from pathlib import Path

import pytest
import pytest_lsp
from lsprotocol import types
from pygls.uris import from_fs_path
from pytest_lsp import ClientServerConfig

from bt_lsp.server.background import CPP_WORKER_CHARS
from tests.server.conftest import SERVER_COMMAND, TIMEOUT, BtClient, make_client

_TMP = Path(tempfile.mkdtemp(prefix="bt-lsp-cpp-"))
WS = _TMP / "ws"
shutil.copytree(Path(__file__).parents[1] / "data" / "cpp_project", WS)
MAIN = WS / "src" / "robot_nodes" / "trees" / "main.xml"
REGISTER = WS / "src" / "robot_nodes" / "src" / "register.cpp"
NODES_HPP = WS / "src" / "robot_nodes" / "include" / "robot_nodes" / "nodes.hpp"

CONFIG = ClientServerConfig(
    server_command=SERVER_COMMAND,
    client_factory=make_client,
    server_env={**os.environ, "XDG_CACHE_HOME": str(_TMP / "cache")},
)


@pytest_lsp.fixture(config=CONFIG, scope="module")
async def cpp_client(lsp_client: BtClient) -> AsyncIterator[BtClient]:
    caps = pytest_lsp.client_capabilities("visual-studio-code")
    assert caps.window is not None and caps.window.work_done_progress
    await lsp_client.start_in_workspace(WS)
    yield lsp_client
    await lsp_client.shutdown_session()


def _pos(path: Path, needle: str, line_has: str | None = None) -> types.Position:
    lines = path.read_text().splitlines()
    row = next(i for i, t in enumerate(lines) if (line_has or needle) in t)
    return types.Position(row, lines[row].index(needle) + 1)


@pytest.mark.asyncio(loop_scope="module")
async def test_background_scan_reports_progress_and_refreshes(cpp_client: BtClient) -> None:
    uri = cpp_client.open_path(MAIN, "xml")
    diags = await cpp_client.diagnostics_until(
        uri, lambda ds: any(d.code == "undeclared-port" for d in ds)
    )
    codes = {(d.code, d.range.start.line) for d in diags}
    assert ("undeclared-port", 4) in codes  # <DriveTo speed=…>
    assert ("invalid-port-value", 3) in codes  # <BatteryOk min_percent="lots">
    typo = next(d for d in diags if d.range.start.line == 5)
    assert "did you mean 'DriveTo'" in typo.message
    kinds = [type(v).__name__ for reports in cpp_client.progress_reports.values() for v in reports]
    assert "WorkDoneProgressBegin" in kinds and "WorkDoneProgressEnd" in kinds


@pytest.mark.asyncio(loop_scope="module")
async def test_hover_shows_the_cpp_declaration(cpp_client: BtClient) -> None:
    uri = cpp_client.open_path(MAIN, "xml")
    await cpp_client.diagnostics_until(uri, lambda ds: any(d.code == "undeclared-port" for d in ds))
    hover = await cpp_client.hover(uri, _pos(MAIN, "DriveTo", 'DriveTo target="dock"'))
    assert hover is not None and isinstance(hover.contents, types.MarkupContent)
    text = hover.contents.value
    # Relative to the workspace folder, a link to the line for a Markdown client.
    link = f"[src/robot_nodes/src/register.cpp:6]({REGISTER.as_uri()}#L6)"
    assert f"Action registered in {link}." in text
    assert f"C++: Action registered in {link} (class" in text
    assert str(WS) not in text.replace(WS.as_uri(), "")  # no absolute path shown as text
    assert "robot_nodes::DriveTo" in text and "nodes.hpp:6" in text
    assert "max_speed" in text  # the port inherited from robot_base's providedBasicPorts
    port = await cpp_client.hover(uri, _pos(MAIN, "target", 'DriveTo target="dock"'))
    assert port is not None and isinstance(port.contents, types.MarkupContent)
    assert "C++: input port `target` of `DriveTo`, type `std::string`" in port.contents.value
    assert "nodes.hpp:11" in port.contents.value


@pytest.mark.asyncio(loop_scope="module")
async def test_definition_goes_into_the_cpp(cpp_client: BtClient) -> None:
    uri = cpp_client.open_path(MAIN, "xml")
    await cpp_client.diagnostics_until(uri, lambda ds: any(d.code == "undeclared-port" for d in ds))
    params = types.DefinitionParams(
        text_document=types.TextDocumentIdentifier(uri=uri),
        position=_pos(MAIN, "DriveTo", 'DriveTo target="dock"'),
    )
    found = await asyncio.wait_for(cpp_client.text_document_definition_async(params), TIMEOUT)
    assert isinstance(found, list)
    places = [(Path(loc.uri.removeprefix("file://")).name, loc.range.start.line) for loc in found]
    assert places == [("nodes.hpp", 5), ("register.cpp", 5)]
    reg = found[1].range
    line = REGISTER.read_text().splitlines()[5]
    assert reg.start.character == line.index('"DriveTo"')
    assert reg.end.character == line.index('"DriveTo"') + len('"DriveTo"')
    params.position = _pos(MAIN, "target", 'DriveTo target="dock"')
    found = await asyncio.wait_for(cpp_client.text_document_definition_async(params), TIMEOUT)
    assert isinstance(found, list) and len(found) == 1
    assert found[0].uri.endswith("nodes.hpp") and found[0].range.start.line == 10


@pytest.mark.asyncio(loop_scope="module")
async def test_completion_offers_the_cpp_nodes(cpp_client: BtClient) -> None:
    text = (
        '<root BTCPP_format="4"><BehaviorTree ID="T"><Sequence><Dri'
        "</Sequence></BehaviorTree></root>"
    )
    path = MAIN.parent / "complete.xml"
    path.write_text(text)
    uri = cpp_client.open_path(path, "xml")
    await cpp_client.diagnostics_until(uri, lambda ds: True)
    at = types.Position(0, text.index("<Dri") + 4)
    for _ in range(50):  # the catalog of this file's package may still be being read
        result = await cpp_client.text_document_completion_async(
            types.CompletionParams(text_document=types.TextDocumentIdentifier(uri=uri), position=at)
        )
        items = result.items if isinstance(result, types.CompletionList) else (result or [])
        labels = {i.label for i in items}
        if "DriveTo" in labels:
            break
        await asyncio.sleep(0.1)
    assert {"DriveTo", "BatteryOk"} <= labels


@pytest.mark.asyncio(loop_scope="module")
async def test_a_cpp_edit_refreshes_the_xml_and_gets_name_rules(cpp_client: BtClient) -> None:
    main = cpp_client.open_path(MAIN, "xml")
    await cpp_client.diagnostics_until(
        main, lambda ds: any(d.code == "undeclared-port" for d in ds)
    )
    cpp = cpp_client.open_path(REGISTER, "cpp")
    text = REGISTER.read_text()
    edited = text.replace('("BatteryOk")', '("Battery Ok")')
    cpp_client.replace(cpp, 2, edited)
    # The C++ document: its bad ID is reported at its literal.
    cpp_diags = await cpp_client.diagnostics_until(
        cpp, lambda ds: any(d.code == "cpp-model-name" for d in ds)
    )
    (d,) = cpp_diags
    line = edited.splitlines()[d.range.start.line]
    assert line[d.range.start.character : d.range.end.character] == '"Battery Ok"'
    # The tree: BatteryOk is no longer registered, so its port is no longer checked.
    diags = await cpp_client.diagnostics_until(
        main,
        lambda ds: (
            not any(d.code == "invalid-port-value" for d in ds)
            and any(d.code == "unknown-node" and d.range.start.line == 3 for d in ds)
        ),
    )
    assert any(d.code == "undeclared-port" for d in diags)  # DriveTo is still known
    cpp_client.replace(cpp, 3, text)
    await cpp_client.diagnostics_until(
        main, lambda ds: any(d.code == "invalid-port-value" for d in ds)
    )


@pytest.mark.asyncio(loop_scope="module")
async def test_a_bad_id_registered_in_cpp_is_renamed_there_first(cpp_client: BtClient) -> None:
    """The C++ registers 'Battery.Ok' and the tree calls it: renaming the XML alone would
    break the node, so the fix is not preferred and its title and the diagnostic say where
    the name must change first."""
    cpp = cpp_client.open_path(REGISTER, "cpp")
    text = REGISTER.read_text()
    cpp_client.replace(cpp, 2, text.replace('("BatteryOk")', '("Battery.Ok")'))
    main = cpp_client.open_path(MAIN, "xml")
    tree = MAIN.read_text().replace("<BatteryOk ", "<Battery.Ok ")
    cpp_client.replace(main, 2, tree)
    where = f"registered in C++ in {REGISTER}: rename it there first"
    diags = await cpp_client.diagnostics_until(
        main,
        lambda ds: any(d.code == "model-name-forbidden-char" and where in d.message for d in ds),
    )
    (diag,) = [d for d in diags if d.code == "model-name-forbidden-char"]
    assert diag.message.endswith(f"; the node type is {where}; fix-all leaves this name until then")
    actions = await cpp_client.text_document_code_action_async(
        types.CodeActionParams(
            text_document=types.TextDocumentIdentifier(uri=main),
            range=diag.range,
            context=types.CodeActionContext(diagnostics=[diag]),
        )
    )
    fixes = [
        a for a in actions or [] if isinstance(a, types.CodeAction) and "Battery.Ok" in a.title
    ]
    assert fixes and not any(a.is_preferred for a in fixes)
    assert fixes[0].title == (
        "Rename 'Battery.Ok' to 'Battery_Ok' (1 place); the node type 'Battery.Ok' is "
        "registered in C++ in register.cpp: rename it there too (unsafe)"
    )
    cpp_client.replace(cpp, 3, text)
    cpp_client.replace(main, 3, MAIN.read_text())
    await cpp_client.diagnostics_until(
        main, lambda ds: any(d.code == "invalid-port-value" for d in ds)
    )


@pytest.mark.asyncio(loop_scope="module")
async def test_a_large_cpp_document_is_read_on_the_worker(cpp_client: BtClient) -> None:
    """A C++ document of more than 32 KiB gets its name diagnostics from the worker
    thread, for its latest text, like a small one."""
    filler = "".join(f"// padding line {i}\n" for i in range(3_000))
    text = REGISTER.read_text().replace('("BatteryOk")', '("Big Battery")') + filler
    assert len(text) > CPP_WORKER_CHARS
    uri = from_fs_path(str(WS / "scratch" / "big_register.cpp")) or ""
    cpp_client.text_document_did_open(
        types.DidOpenTextDocumentParams(
            text_document=types.TextDocumentItem(uri=uri, language_id="cpp", version=1, text=text)
        )
    )
    try:
        (d,) = await cpp_client.diagnostics_until(
            uri, lambda ds: any(d.code == "cpp-model-name" for d in ds)
        )
        line = text.splitlines()[d.range.start.line]
        assert line[d.range.start.character : d.range.end.character] == '"Big Battery"'
        cpp_client.replace(uri, 2, text.replace('("Big Battery")', '("BigBattery")'))
        await cpp_client.diagnostics_until(uri, lambda ds: not ds)
    finally:
        cpp_client.close(uri)
