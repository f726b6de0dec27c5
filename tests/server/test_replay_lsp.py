"""``bt-lsp.readLog`` end to end: a ``.btlog`` of the tree of tests/test_live_mapping.py
mapped by the real server onto the open document and its include (as
``bt-lsp.mapRunningTree`` maps a running tree), with its transitions for a timeline."""

from __future__ import annotations

import asyncio
import os
import struct
from pathlib import Path
from typing import Any

import pytest
from lsprotocol import types
from pygls.exceptions import JsonRpcException
from pygls.uris import from_fs_path

from tests.server.conftest import TIMEOUT, BtClient, clients
from tests.server.test_live_map_lsp import _map, _open_pair
from tests.test_live_mapping import FULLTREE

pytestmark = [pytest.mark.asyncio(loop_scope="module"), clients("vscode", "nvim-0.11")]

COMMAND = "bt-lsp.readLog"
START = 1_700_000_000_000_000


def _record(us: int, uid: int, status: int) -> bytes:
    return us.to_bytes(6, "little") + uid.to_bytes(2, "little") + bytes([status])


def _btlog(records: bytes, xml: str = FULLTREE) -> bytes:
    data = xml.encode()
    head = b"BTCPP4-FileLogger2" + b"\x01" + struct.pack("<i", len(data)) + data
    return head + struct.pack("<q", START) + records


async def _read(client: BtClient, args: Any) -> Any:
    return await asyncio.wait_for(
        client.workspace_execute_command_async(
            types.ExecuteCommandParams(command=COMMAND, arguments=[args])
        ),
        TIMEOUT,
    )


async def test_command_is_declared(client: BtClient) -> None:
    provider = client.init_result.capabilities.execute_command_provider
    assert provider is not None and COMMAND in provider.commands


async def test_a_log_is_mapped_as_a_running_tree_with_its_transitions(
    client: BtClient, tmp_path: Path
) -> None:
    main_uri, _, _ = _open_pair(client)
    await client.diags(main_uri, 1)
    log = tmp_path / "run.btlog"
    # A last record cut short, as in a log copied while the robot runs.
    log.write_bytes(_btlog(_record(10, 1, 1) + _record(12, 2, 1) + _record(30, 2, 2) + b"\x01\x02"))
    result = await _read(client, {"uri": main_uri, "log": from_fs_path(str(log))})
    mapped = await _map(client, {"uri": main_uri, "tree": FULLTREE})
    for key in ("tree", "treeLocation", "nodes", "mismatches"):
        assert result[key] == mapped[key], key
    assert result["nodes"]  # the same places as the running tree's
    assert result["startUs"] == START
    assert result["transitions"] == [[10, 1, "running"], [12, 2, "running"], [30, 2, "success"]]
    assert result["truncated"] == 0 and result["partialBytes"] == 2
    # A path works as well as a URI.
    again = await _read(client, {"uri": main_uri, "log": str(log)})
    assert again["transitions"] == result["transitions"]


async def test_a_long_log_is_cut_and_says_how_much(client: BtClient, tmp_path: Path) -> None:
    main_uri, _, _ = _open_pair(client)
    log = tmp_path / "long.btlog"
    log.write_bytes(_btlog(b"".join(_record(i, 1, 1 + i % 2) for i in range(100_010))))
    result = await _read(client, {"uri": main_uri, "log": str(log)})
    assert len(result["transitions"]) == 100_000 and result["truncated"] == 10
    assert result["transitions"][-1] == [99_999, 1, "success"]


async def test_what_is_not_a_log_is_refused_with_the_reason(
    client: BtClient, tmp_path: Path
) -> None:
    main_uri, _, _ = _open_pair(client)
    other = tmp_path / "tree.xml"
    other.write_text("<root/>")
    unknown = _btlog(_record(1, 999, 1))  # a node the log's tree lacks
    (tmp_path / "bad.btlog").write_bytes(unknown)
    fifo = tmp_path / "fifo.btlog"
    os.mkfifo(fifo)  # never opened for a blocking read
    cases = {
        str(other): "no BTCPP4-FileLogger2 magic",
        str(tmp_path / "bad.btlog"): "the tree lacks",
        str(tmp_path / "missing.btlog"): "cannot read",
        str(fifo): "FIFO",
    }
    for path, reason in cases.items():
        with pytest.raises(JsonRpcException) as e:
            await _read(client, {"uri": main_uri, "log": path})
        assert reason in str(e.value), (path, str(e.value))
    with pytest.raises(JsonRpcException) as e:
        await _read(client, {"uri": main_uri})
    assert "'log' must be" in str(e.value)
    with pytest.raises(JsonRpcException) as e:
        await _read(client, {"uri": "file:///nowhere/x.xml", "log": str(other)})
    assert "not an open document" in str(e.value)
    # The server keeps serving.
    assert (await _map(client, {"uri": main_uri, "tree": FULLTREE}))["tree"] == "Main"
