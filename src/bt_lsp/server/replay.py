"""``workspace/executeCommand`` ``bt-lsp.readLog``: a ``.btlog`` (BehaviorTree.CPP's
``FileLogger2``) mapped onto an open document, for an editor that replays it on the text
and on its picture with a timeline.

Argument: one object ``{uri, log}``: the open document and the log's ``file://`` URI (or
path).  The log's tree is mapped as ``bt-lsp.mapRunningTree`` maps a running tree.  The
answer adds to that command's ``{tree, treeLocation, nodes, mismatches}``:
``startUs`` (when the logger started, microseconds since the epoch), ``transitions``
(``[offsetUs, uid, status]`` in order, ``status`` one of idle, running, success, failure,
skipped), ``truncated`` (how many transitions after the first :data:`MAX_TRANSITIONS`
were left out) and ``partialBytes`` (a last record cut short, as a log copied while the
robot runs ends).  The file is read whole, up to :data:`MAX_LOG_BYTES`, only if it is a
regular file; a file that is not a FileLogger2 log is RequestFailed, with the reason.
"""

from __future__ import annotations

import io
from collections.abc import Mapping
from typing import Any, Final

from pygls.exceptions import JsonRpcInvalidParams
from pygls.uris import to_fs_path

from bt_lsp.live.btlog import BtLog
from bt_lsp.live.protocol import ProtocolError
from bt_lsp.project.fileio import FileError, read_bytes
from bt_lsp.server.app import BtServer
from bt_lsp.server.live import locator, map_onto, mismatch_json
from bt_lsp.server.navigation import RequestFailed

COMMAND = "bt-lsp.readLog"
MAX_LOG_BYTES: Final = 64 * 1024 * 1024
# About 2 MB of JSON; a log of a robot that ran for hours is replayed from its start.
MAX_TRANSITIONS: Final = 100_000


def _options(args: tuple[Any, ...]) -> tuple[str, str]:
    if len(args) != 1 or not isinstance(args[0], Mapping):
        raise JsonRpcInvalidParams(f"{COMMAND} takes one object: {{uri, log}}")
    uri, log = args[0].get("uri"), args[0].get("log")
    if not isinstance(uri, str):
        raise JsonRpcInvalidParams(f"{COMMAND}: 'uri' must be a string")
    if not isinstance(log, str) or not log:
        raise JsonRpcInvalidParams(f"{COMMAND}: 'log' must be the .btlog file's URI or path")
    return uri, log


def read_log(ls: BtServer, *args: Any) -> dict[str, Any]:
    uri, log = _options(args)
    od = ls.get(uri)
    if od is None:
        raise RequestFailed(f"{uri} is not an open document")
    path = to_fs_path(log) if log.startswith("file:") else log
    if not path:
        raise RequestFailed(f"{log} is not a file")
    try:
        data, _ = read_bytes(path, MAX_LOG_BYTES)
        btlog = BtLog(io.BytesIO(data))
        transitions: list[list[int | str]] = []
        truncated = 0
        for t in btlog.transitions():
            if len(transitions) < MAX_TRANSITIONS:
                transitions.append([t.offset_us, t.uid, t.status.name.lower()])
            else:
                truncated += 1
    except FileError as e:
        raise RequestFailed(str(e)) from None
    except ProtocolError as e:
        raise RequestFailed(f"{path}: {e}") from None
    tm = map_onto(ls, od, btlog.header.tree)
    location = locator(ls, od)
    nodes = []
    for uid in sorted(tm.places):
        loc = location(tm.places[uid])
        if loc is not None:
            nodes.append({"uid": uid, **loc})
    return {
        "tree": tm.tree_id,
        "treeLocation": location(tm.tree) if tm.tree is not None else None,
        "nodes": nodes,
        "mismatches": [mismatch_json(m, location) for m in tm.mismatches],
        "startUs": btlog.header.start_us,
        "transitions": transitions,
        "truncated": truncated,
        "partialBytes": btlog.partial_bytes,
    }


def register(server: BtServer) -> None:
    @server.command(COMMAND)
    def _read_log(ls: BtServer, *args: Any) -> dict[str, Any]:
        return read_log(ls, *args)
