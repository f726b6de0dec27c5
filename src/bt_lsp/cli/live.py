"""``bt-lsp replay FILE.btlog`` and ``bt-lsp monitor HOST:PORT``: watching a tree run.

``replay`` steps through a FileLogger2 log: each transition's time, node and statuses.
``monitor`` connects to a running executor's Groot2Publisher (it never listens) and draws
the tree with live statuses; ``--once`` prints one snapshot, ``--map PATH`` the
``file:line`` each node comes from and where the text differs (``cli.live_map``).
``monitor`` needs pyzmq (``pip install 'bt-lsp[live]'``); it uses rich for the live view
when installed.

Exit status: 0; 1 when ``monitor`` cannot reach the executor or gets a malformed answer;
2 for a usage error or a log that cannot be read.
"""

from __future__ import annotations

import argparse
import datetime
import json
import os
import sys
import time
from collections.abc import Callable, Mapping
from typing import TYPE_CHECKING, Any, TextIO

from bt_lsp.cli.live_map import SourceMap
from bt_lsp.live.btlog import BtLog
from bt_lsp.live.protocol import LiveError, NodeState, NodeStatus, parse_address
from bt_lsp.live.tree import LiveNode, LiveTree
from bt_lsp.live.view import draw

if TYPE_CHECKING:
    from bt_lsp.live.client import Groot2Client


def _rate(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        value = -1.0
    if not 0.1 <= value <= 100:
        raise argparse.ArgumentTypeError(f"invalid rate {text!r} (0.1 to 100 per second)")
    return value


def _seconds(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        value = -1.0
    if not 0 < value <= 86400:
        raise argparse.ArgumentTypeError(f"invalid duration {text!r} (seconds)")
    return value


def add_parsers(sub: Any) -> None:
    """Add ``replay`` and ``monitor`` to the ``bt-lsp`` subcommands."""
    replay = sub.add_parser(
        "replay",
        help="step through a FileLogger2 .btlog file",
        description=(
            "Print the transitions that BT::FileLogger2 recorded: the time since the log "
            "started, the node (subtree path and name) and its status before and after. "
            "Exit status: 0, or 2 for a file that cannot be read or is not a .btlog."
        ),
    )
    replay.add_argument("file", metavar="FILE", help="the .btlog file")
    replay.add_argument(
        "--format", choices=("text", "json"), default="text", help="output (default: %(default)s)"
    )
    replay.add_argument(
        "--node", metavar="NODE", help="only this node's transitions (uid, path or name)"
    )

    monitor = sub.add_parser(
        "monitor",
        help="draw a running tree with live statuses (Groot2 protocol)",
        description=(
            "Connect to a BehaviorTree.CPP executor's Groot2Publisher (BT::Groot2Publisher"
            "(tree, PORT)) and draw its tree with each node's status, polled at --rate. "
            "Exit status: 0, 1 when the executor cannot be reached or answers malformed "
            "data, 2 for a usage error."
        ),
    )
    monitor.add_argument(
        "address",
        nargs="?",
        default="127.0.0.1:1667",
        metavar="HOST:PORT",
        help="the executor's Groot2 server (default: %(default)s)",
    )
    monitor.add_argument(
        "--rate", type=_rate, default=10.0, help="status polls per second (default: %(default)s)"
    )
    monitor.add_argument("--once", action="store_true", help="print one snapshot and exit")
    monitor.add_argument(
        "--plain", action="store_true", help="plain text, also on a terminal (no rich)"
    )
    monitor.add_argument(
        "--blackboard", action="store_true", help="show the blackboards' entries too"
    )
    monitor.add_argument(
        "--timeout",
        type=_seconds,
        default=1.0,
        metavar="SECONDS",
        help="how long to wait for each answer (default: %(default)s)",
    )
    monitor.add_argument(
        "--duration", type=_seconds, metavar="SECONDS", help="stop after this long"
    )
    monitor.add_argument(
        "--map",
        metavar="FILE_OR_DIR",
        help=(
            "show where each node comes from (file:line) in the tree file the executor "
            "loaded, or in the file of a folder that declares the running tree, and what "
            "the text changed since"
        ),
    )


# ---------------------------------------------------------------------------- replay


def _node_json(node: LiveNode) -> dict[str, Any]:
    return {
        "uid": node.uid,
        "tag": node.tag,
        "name": node.name,
        "path": node.path,
        "subtree": node.subtree,
    }


def replay(
    path: str,
    *,
    format: str = "text",
    node: str | None = None,
    out: TextIO | None = None,
    err: TextIO | None = None,
) -> int:
    out = out if out is not None else sys.stdout
    err = err if err is not None else sys.stderr
    try:
        with open(path, "rb") as stream:
            log = BtLog(stream)
            tree = log.header.tree
            only: set[int] | None = None
            if node is not None:
                found = tree.find(node)
                if not found:
                    err.write(f"bt-lsp: {path}: no node {node!r} in the logged tree\n")
                    return 2
                only = {n.uid for n in found}
            write = _replay_json if format == "json" else _replay_text
            write(path, log, only, out)
            if log.partial_bytes:
                err.write(
                    f"bt-lsp: {path}: the last {log.partial_bytes} bytes are a partial "
                    "record (the log was still being written), left out\n"
                )
    except OSError as e:
        err.write(f"bt-lsp: {path}: {e.strerror or e}\n")
        return 2
    except LiveError as e:
        err.write(f"bt-lsp: {path}: {e}\n")
        return 2
    return 0


def _start(us: int) -> str:
    try:
        moment = datetime.datetime.fromtimestamp(us / 1e6, tz=datetime.UTC)
    except (OverflowError, OSError, ValueError):
        return f"{us} us since the epoch"
    return moment.isoformat(timespec="milliseconds").replace("+00:00", "Z")


def _replay_text(path: str, log: BtLog, only: set[int] | None, out: TextIO) -> None:
    tree = log.header.tree
    out.write(f"{path}: tree {tree.tree_id}, {len(tree.nodes)} nodes, ")
    out.write(f"started {_start(log.header.start_us)}\n")
    count = 0
    for step in log.steps():
        if only is not None and step.node.uid not in only:
            continue
        count += 1
        n = step.node
        name = n.path if n.name == n.tag else f"{n.path} ({n.tag})"
        out.write(
            f"{step.offset_us / 1e6:>12.6f}s  #{n.uid:<4} {name}  "
            f"{step.before.name} -> {step.after.name}\n"
        )
    out.write(f"{count} transitions\n")


def _replay_json(path: str, log: BtLog, only: set[int] | None, out: TextIO) -> None:
    tree = log.header.tree
    head = {
        "file": path,
        "version": log.header.version,
        "tree": tree.tree_id,
        "start_us": log.header.start_us,
        "nodes": [_node_json(n) for _, n in tree.walk()],
    }
    # Streamed: one transition a line, so a long log needs no memory.
    text = json.dumps(head, ensure_ascii=False)
    out.write(text[:-1] + ', "transitions": [')
    first = True
    for step in log.steps():
        if only is not None and step.node.uid not in only:
            continue
        item = {
            "offset_us": step.offset_us,
            "time_us": step.time_us,
            "uid": step.node.uid,
            "path": step.node.path,
            "name": step.node.name,
            "tag": step.node.tag,
            "from": step.before.name,
            "to": step.after.name,
        }
        out.write(("\n  " if first else ",\n  ") + json.dumps(item, ensure_ascii=False))
        first = False
    out.write(f'\n], "partial_bytes": {log.partial_bytes}}}\n')


# ---------------------------------------------------------------------------- monitor


def _snapshot(
    address: str,
    client: Groot2Client,
    tree: LiveTree,
    states: Mapping[int, NodeState],
    blackboards: Mapping[str, Any] | None,
    sources: SourceMap | None = None,
) -> list[str]:
    uuid = client.uuid.hex() if client.uuid else "?"
    lines = [f"{tree.tree_id} at {address}  (tree {uuid}, executor run {client.generation})"]
    if sources is None:
        lines += draw(tree, states)
    else:
        located = sources.locate(tree)
        lines += draw(tree, states, located.where)
        lines += sources.lines(located)
    for name, entries in (blackboards or {}).items():
        lines.append(f"blackboard {name}:")
        if isinstance(entries, dict) and entries:
            lines += [f"  {k} = {json.dumps(v, default=repr)}" for k, v in entries.items()]
        else:
            lines.append("  (empty)")
    return lines


def monitor(
    address: str,
    *,
    rate: float = 10.0,
    once: bool = False,
    plain: bool = False,
    blackboard: bool = False,
    timeout: float = 1.0,
    duration: float | None = None,
    map_path: str | None = None,
    out: TextIO | None = None,
    err: TextIO | None = None,
) -> int:
    out = out if out is not None else sys.stdout
    err = err if err is not None else sys.stderr
    try:
        host, port = parse_address(address)
    except ValueError as e:
        err.write(f"bt-lsp: monitor: {e}\n")
        return 2
    sources: SourceMap | None = None
    if map_path is not None:
        if not os.path.exists(map_path):
            err.write(f"bt-lsp: monitor: --map {map_path}: no such file or folder\n")
            return 2
        sources = SourceMap(map_path)
    try:
        from bt_lsp.live.client import Groot2Client
    except ImportError:
        err.write("bt-lsp: monitor needs pyzmq: pip install 'bt-lsp[live]'\n")
        return 2
    shown = f"{host}:{port}"
    with Groot2Client(host, port, timeout=timeout) as client:
        if once:
            try:
                tree = client.read_tree()
                states = client.status()
                boards = client.blackboards(tree.blackboards) if blackboard else None
            except LiveError as e:
                err.write(f"bt-lsp: monitor: {e}\n")
                return 1
            lines = _snapshot(shown, client, tree, states, boards, sources)
            out.write("\n".join(lines) + "\n")
            return 0
        return _watch(shown, client, rate, plain, blackboard, duration, sources, out, err)


def _watch(
    shown: str,
    client: Groot2Client,
    rate: float,
    plain: bool,
    blackboard: bool,
    duration: float | None,
    sources: SourceMap | None,
    out: TextIO,
    err: TextIO,
) -> int:
    """Poll until Ctrl-C (or ``duration``); a lost executor is waited for, not fatal."""
    end = None if duration is None else time.monotonic() + duration
    use_rich = not plain and out.isatty()
    if use_rich:
        try:
            from rich.console import Console
            from rich.live import Live
        except ImportError:
            use_rich = False
    tree: LiveTree | None = None
    seen_generation = -1
    last: list[str] = []

    def frame() -> list[str]:
        nonlocal tree, seen_generation
        try:
            states = client.status()
            if tree is None or client.generation != seen_generation:
                # The first answer, or a new executor run: its tree may differ.
                seen_generation = client.generation
                tree = client.read_tree()
                states = client.status()
            boards = client.blackboards(tree.blackboards) if blackboard else None
        except LiveError as e:
            return [f"{shown}: {e}; retrying"]
        return _snapshot(shown, client, tree, states, boards, sources)

    def run(show: Callable[[list[str]], None]) -> int:
        period = 1.0 / rate
        try:
            while end is None or time.monotonic() < end:
                started = time.monotonic()
                show(frame())
                time.sleep(max(0.0, period - (time.monotonic() - started)))
        except KeyboardInterrupt:
            pass
        return 0

    if use_rich:
        console = Console(file=out)
        with Live(console=console, auto_refresh=False, transient=False) as live:
            return run(lambda lines: live.update(_rich(lines), refresh=True))

    def show_plain(lines: list[str]) -> None:
        nonlocal last
        if lines == last:
            return
        last = lines
        if out.isatty():
            out.write("\x1b[H\x1b[2J")
        out.write("\n".join(lines) + "\n\n")
        out.flush()

    del err
    return run(show_plain)


_STYLES = {
    NodeStatus.RUNNING.name: "bold yellow",
    NodeStatus.SUCCESS.name: "bold green",
    NodeStatus.FAILURE.name: "bold red",
    NodeStatus.SKIPPED.name: "blue",
}


def _rich(lines: list[str]) -> Any:
    """The snapshot's lines with each status coloured (rich Text)."""
    from rich.text import Text

    text = Text()
    for line in lines:
        for name, style in _STYLES.items():
            if line.endswith(name):
                text.append(line[: -len(name)])
                text.append(name, style=style)
                break
        else:
            text.append(line, style="dim" if "IDLE" in line else "")
        text.append("\n")
    return text
