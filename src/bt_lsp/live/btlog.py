"""Reading ``.btlog`` files, the format ``BT::FileLogger2`` writes and Groot2 replays.

Layout (``bt_file_logger_v2.cpp``, little-endian)::

    "BTCPP4-FileLogger2" | uint8 version (1) | int32 xml size | the tree's XML
    | int64 first timestamp (microseconds since the epoch)
    | 9-byte records: uint48 microseconds since the first timestamp | uint16 uid | uint8 status

The logger writes from a thread every 10 ms, so a file copied while the robot runs may end
in a partial record: it is left out and counted (``BtLog.partial_bytes``).  Records are
read in chunks, so a long log is replayed without holding it in memory.
"""

from __future__ import annotations

import struct
from collections.abc import Iterator
from dataclasses import dataclass
from typing import BinaryIO, Final

from bt_lsp.live.protocol import (
    TRANSITION_RECORD_SIZE,
    NodeStatus,
    ProtocolError,
    Transition,
    decode_transition,
)
from bt_lsp.live.tree import MAX_XML_BYTES, LiveNode, LiveTree, parse_tree_xml

MAGIC: Final = b"BTCPP4-FileLogger2"
VERSION: Final = 1
_CHUNK: Final = TRANSITION_RECORD_SIZE * 4096


@dataclass(frozen=True, slots=True)
class BtLogHeader:
    version: int
    tree: LiveTree
    start_us: int  # the system clock when the logger started, microseconds since the epoch


@dataclass(frozen=True, slots=True)
class Step:
    """One transition with what it means: when, which node, from which status to which."""

    offset_us: int
    time_us: int
    node: LiveNode
    before: NodeStatus
    after: NodeStatus


def read_header(stream: BinaryIO) -> BtLogHeader:
    """Read up to the first record; raise ProtocolError for a file of another kind."""
    head = stream.read(len(MAGIC) + 5)
    if head[: len(MAGIC)] != MAGIC:
        raise ProtocolError("not a FileLogger2 .btlog (no BTCPP4-FileLogger2 magic)")
    if len(head) < len(MAGIC) + 5:
        raise ProtocolError("the file ends inside its header")
    version = head[len(MAGIC)]
    if version != VERSION:
        raise ProtocolError(f"FileLogger2 version {version}, this reader knows {VERSION}")
    (size,) = struct.unpack_from("<i", head, len(MAGIC) + 1)
    if not 0 < size <= MAX_XML_BYTES:
        raise ProtocolError(f"the tree's XML size {size} is not in 1..{MAX_XML_BYTES}")
    xml = stream.read(size)
    if len(xml) != size:
        raise ProtocolError("the file ends inside the tree's XML")
    tree = parse_tree_xml(xml)
    stamp = stream.read(8)
    if len(stamp) != 8:
        raise ProtocolError("the file ends before its first timestamp")
    (start,) = struct.unpack("<q", stamp)
    return BtLogHeader(version, tree, start)


class BtLog:
    """An open .btlog: the header, then the transitions as they are read."""

    def __init__(self, stream: BinaryIO) -> None:
        self._stream = stream
        self.header = read_header(stream)
        self.partial_bytes = 0

    def transitions(self) -> Iterator[Transition]:
        """Each record in order; an unknown uid or status is a ProtocolError."""
        nodes = self.header.tree.nodes
        rest = b""
        while True:
            chunk = self._stream.read(_CHUNK)
            if not chunk:
                break
            data = rest + chunk
            whole = len(data) - len(data) % TRANSITION_RECORD_SIZE
            for i in range(0, whole, TRANSITION_RECORD_SIZE):
                t = decode_transition(data[i : i + TRANSITION_RECORD_SIZE])
                if t.uid not in nodes:
                    raise ProtocolError(f"a transition of node {t.uid}, which the tree lacks")
                yield t
            rest = data[whole:]
        self.partial_bytes = len(rest)

    def steps(self) -> Iterator[Step]:
        """The transitions with each node's previous status (every node starts IDLE)."""
        nodes = self.header.tree.nodes
        state: dict[int, NodeStatus] = {}
        start = self.header.start_us
        for t in self.transitions():
            before = state.get(t.uid, NodeStatus.IDLE)
            state[t.uid] = t.status
            yield Step(t.offset_us, start + t.offset_us, nodes[t.uid], before, t.status)
