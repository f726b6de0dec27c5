"""BehaviorTree.CPP's Groot2 wire format: headers, payloads and reply decoders.

Pure functions on bytes, no sockets (``client`` sends them).  Facts from
``groot2_protocol.h`` and ``groot2_publisher.cpp`` of BehaviorTree.CPP 4 (checked against
4.8.2): every request is a ZeroMQ multipart message whose first part is a 6-byte header
(protocol ``2``, the request type as one ASCII letter, a random 32-bit id, all in the
executor's byte order, little-endian on every platform BehaviorTree.CPP ships for); the
reply repeats it and adds the tree's 16-byte UUID; an executor that refuses a request
answers ``["error", message]``.

The executor parses the JSON payloads with nlohmann::json and, in 4.8.2, does not catch a
parse or type error: one malformed HOOK_INSERT, HOOK_REMOVE or BREAKPOINT_UNLOCK aborts the
whole robot program.  So every payload here is built from typed, validated values, and
nothing else is ever sent.  Replies are untrusted input: every decoder checks sizes and
shapes and raises :class:`ProtocolError`, never anything else.
"""

from __future__ import annotations

import enum
import json
import re
import struct
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any, Final

from bt_lsp.live import msgpack

PROTOCOL: Final = 2
REQUEST_HEADER: Final = struct.Struct("<BBI")
REQUEST_HEADER_SIZE: Final = REQUEST_HEADER.size  # 6
UUID_SIZE: Final = 16
REPLY_HEADER_SIZE: Final = REQUEST_HEADER_SIZE + UUID_SIZE  # 22
MAX_UID: Final = 0xFFFF
# A status record: uint16 uid, uint8 status; a transition: uint48 microseconds, uid, status.
STATUS_RECORD: Final = struct.Struct("<HB")
TRANSITION_RECORD_SIZE: Final = 9
# Bounds on what a reply may hold (an executor is not trusted to stay reasonable).
MAX_NODES: Final = MAX_UID + 1
MAX_HOOKS: Final = 4 * MAX_NODES
MAX_JSON_BYTES: Final = 16 * 1024 * 1024
MAX_ERROR_TEXT: Final = 500


class LiveError(Exception):
    """Anything that went wrong talking to an executor."""


class ProtocolError(LiveError, ValueError):
    """A reply or file that does not follow the format (untrusted input, refused)."""


class ExecutorError(LiveError):
    """The executor answered ``error`` (e.g. ``Node ID not found``)."""


class RequestType(enum.Enum):
    """The request letters of ``BT::Monitor::RequestType``."""

    FULLTREE = "T"
    STATUS = "S"
    BLACKBOARD = "B"
    HOOK_INSERT = "I"
    HOOK_REMOVE = "R"
    BREAKPOINT_REACHED = "N"
    BREAKPOINT_UNLOCK = "U"
    HOOKS_DUMP = "D"
    REMOVE_ALL_HOOKS = "A"
    DISABLE_ALL_HOOKS = "X"
    TOGGLE_RECORDING = "r"
    GET_TRANSITIONS = "t"

    @property
    def code(self) -> int:
        return ord(self.value)


class NodeStatus(enum.IntEnum):
    """``BT::NodeStatus`` as the executor numbers it."""

    IDLE = 0
    RUNNING = 1
    SUCCESS = 2
    FAILURE = 3
    SKIPPED = 4


class Position(enum.IntEnum):
    """Where a hook runs: before the node's tick (PRE) or after it (POST).

    BehaviorTree.CPP 4.8.2 runs a POST hook before the tick too and cannot unlock it by
    position POST ("Node ID not found"): use PRE with 4.8.2."""

    PRE = 0
    POST = 1


class HookMode(enum.IntEnum):
    """BREAKPOINT stops the tree until unlocked; REPLACE returns a status without ticking."""

    BREAKPOINT = 0
    REPLACE = 1


class Resume(enum.Enum):
    """How an unlocked breakpoint goes on: tick the node, or skip it with a result.

    The executor maps any other text than SUCCESS and FAILURE to SKIPPED, which makes the
    pre-tick hook step aside so that the node ticks normally."""

    CONTINUE = "SKIPPED"
    SUCCESS = "SUCCESS"
    FAILURE = "FAILURE"


# The statuses a hook may return (convertFromString<NodeStatus> accepts them; others throw).
HOOK_RESULTS: Final = (NodeStatus.SUCCESS, NodeStatus.FAILURE, NodeStatus.SKIPPED)


@dataclass(frozen=True, slots=True)
class NodeState:
    """A node's status in a STATUS reply; ``was`` is the status it left for IDLE.

    The executor writes ``10 + previous`` for a node that went back to IDLE."""

    status: NodeStatus
    was: NodeStatus | None = None

    def __str__(self) -> str:
        if self.was is None:
            return self.status.name
        return f"IDLE (was {self.was.name})"


@dataclass(frozen=True, slots=True)
class RequestHeader:
    type: RequestType
    request_id: int

    def encode(self) -> bytes:
        if not 0 <= self.request_id <= 0xFFFFFFFF:
            raise ValueError(f"request id {self.request_id} is not a uint32")
        return REQUEST_HEADER.pack(PROTOCOL, self.type.code, self.request_id)


@dataclass(frozen=True, slots=True)
class Reply:
    """A checked reply: the tree's UUID and the parts after the header."""

    uuid: bytes
    body: tuple[bytes, ...]


@dataclass(frozen=True, slots=True)
class Hook:
    """One hook (HOOK_INSERT's JSON object), validated so the executor can parse it."""

    uid: int
    position: Position = Position.PRE
    mode: HookMode = HookMode.BREAKPOINT
    once: bool = False
    enabled: bool = True
    desired_status: NodeStatus = NodeStatus.SKIPPED

    def __post_init__(self) -> None:
        _check_uid(self.uid)
        if not isinstance(self.position, Position):
            raise ValueError(f"position must be a Position, not {self.position!r}")
        if not isinstance(self.mode, HookMode):
            raise ValueError(f"mode must be a HookMode, not {self.mode!r}")
        if not isinstance(self.once, bool) or not isinstance(self.enabled, bool):
            raise ValueError("once and enabled must be bool")
        if self.desired_status not in HOOK_RESULTS or not isinstance(
            self.desired_status, NodeStatus
        ):
            raise ValueError(
                f"a hook returns SUCCESS, FAILURE or SKIPPED, not {self.desired_status}"
            )

    def to_json(self) -> dict[str, Any]:
        return {
            "enabled": self.enabled,
            "uid": self.uid,
            "mode": int(self.mode),
            "once": self.once,
            "desired_status": self.desired_status.name,
            "position": int(self.position),
        }


def _check_uid(uid: object) -> int:
    if isinstance(uid, bool) or not isinstance(uid, int) or not 0 <= uid <= MAX_UID:
        raise ValueError(f"a node uid is an integer in 0..{MAX_UID}, not {uid!r}")
    return uid


def _dumps(value: object) -> bytes:
    # ASCII only, no NaN: nlohmann::json parses exactly this subset.
    return json.dumps(value, ensure_ascii=True, allow_nan=False, separators=(",", ":")).encode(
        "ascii"
    )


# ---------------------------------------------------------------------------- payloads


def hook_insert_payload(hooks: Hook | Sequence[Hook]) -> bytes:
    """HOOK_INSERT's body: one hook object, or an array of them."""
    if isinstance(hooks, Hook):
        return _dumps(hooks.to_json())
    items = list(hooks)
    if not items or not all(isinstance(h, Hook) for h in items):
        raise ValueError("insert at least one Hook")
    return _dumps([h.to_json() for h in items])


def hook_remove_payload(uid: int, position: Position = Position.PRE) -> bytes:
    _check_uid(uid)
    if not isinstance(position, Position):
        raise ValueError(f"position must be a Position, not {position!r}")
    return _dumps({"uid": uid, "position": int(position)})


def unlock_payload(
    uid: int,
    result: Resume = Resume.CONTINUE,
    position: Position = Position.PRE,
    remove: bool = False,
) -> bytes:
    """BREAKPOINT_UNLOCK's body: all four keys, each of the type the executor reads."""
    _check_uid(uid)
    if not isinstance(result, Resume):
        raise ValueError(f"result must be a Resume, not {result!r}")
    if not isinstance(position, Position):
        raise ValueError(f"position must be a Position, not {position!r}")
    if not isinstance(remove, bool):
        raise ValueError("remove must be bool")
    return _dumps(
        {
            "uid": uid,
            "desired_status": result.value,
            "position": int(position),
            "remove_when_done": remove,
        }
    )


def blackboard_payload(names: Sequence[str]) -> bytes:
    """BLACKBOARD's body: blackboard names joined by ``;`` (so a name cannot hold one)."""
    if isinstance(names, str):
        names = [names]
    out = []
    for name in names:
        if not isinstance(name, str) or not name or ";" in name or "\0" in name:
            raise ValueError(f"a blackboard name is a non-empty text without ';': {name!r}")
        out.append(name)
    if not out:
        raise ValueError("name at least one blackboard")
    return ";".join(out).encode("utf-8")


def recording_payload(start: bool) -> bytes:
    return b"start" if start else b"stop"


# ---------------------------------------------------------------------------- decoders


def decode_reply(parts: Sequence[bytes], request: RequestHeader) -> Reply:
    """Check a reply against its request; raise ExecutorError for an ``error`` answer."""
    if not parts or len(parts) > 3:
        raise ProtocolError(f"a reply has 1 to 3 parts, not {len(parts)}")
    head = parts[0]
    if head == b"error":
        text = parts[1] if len(parts) > 1 else b""
        raise ExecutorError(_text(text[:MAX_ERROR_TEXT]) or "error")
    if len(head) != REPLY_HEADER_SIZE:
        raise ProtocolError(f"a reply header has {REPLY_HEADER_SIZE} bytes, not {len(head)}")
    protocol, type_code, request_id = REQUEST_HEADER.unpack_from(head)
    if protocol != PROTOCOL:
        raise ProtocolError(f"protocol {protocol}, expected {PROTOCOL}")
    if type_code != request.type.code or request_id != request.request_id:
        raise ProtocolError("the reply answers another request")
    return Reply(uuid=bytes(head[REQUEST_HEADER_SIZE:]), body=tuple(bytes(p) for p in parts[1:]))


def _text(data: bytes) -> str:
    return data.decode("utf-8", errors="replace")


def _status(code: int) -> NodeStatus:
    try:
        return NodeStatus(code)
    except ValueError:
        raise ProtocolError(f"unknown node status {code}") from None


def decode_state(code: int) -> NodeState:
    if 10 <= code <= 14:
        return NodeState(NodeStatus.IDLE, _status(code - 10))
    return NodeState(_status(code))


def decode_status(body: bytes) -> dict[int, NodeState]:
    """STATUS's body: ``(uint16 uid, uint8 status)`` for every node of the tree."""
    if len(body) % STATUS_RECORD.size:
        raise ProtocolError(f"a status buffer is a multiple of 3 bytes, not {len(body)}")
    out: dict[int, NodeState] = {}
    for uid, code in STATUS_RECORD.iter_unpack(body):
        if uid in out:
            raise ProtocolError(f"node {uid} twice in a status buffer")
        out[uid] = decode_state(code)
    return out


@dataclass(frozen=True, slots=True)
class Transition:
    """A status change: microseconds since the recording (or log) started."""

    offset_us: int
    uid: int
    status: NodeStatus


def decode_transition(record: bytes) -> Transition:
    if len(record) != TRANSITION_RECORD_SIZE:
        raise ProtocolError(f"a transition has 9 bytes, not {len(record)}")
    offset = int.from_bytes(record[:6], "little")
    uid = int.from_bytes(record[6:8], "little")
    return Transition(offset, uid, _status(record[8]))


def decode_transitions(body: bytes) -> list[Transition]:
    """GET_TRANSITIONS's body: 9-byte records (uint48 us, uint16 uid, uint8 status)."""
    if len(body) % TRANSITION_RECORD_SIZE:
        raise ProtocolError(f"transitions are a multiple of 9 bytes, not {len(body)}")
    return [
        decode_transition(body[i : i + TRANSITION_RECORD_SIZE])
        for i in range(0, len(body), TRANSITION_RECORD_SIZE)
    ]


def _json(body: bytes) -> Any:
    if len(body) > MAX_JSON_BYTES:
        raise ProtocolError(f"a JSON reply of {len(body)} bytes is over the limit")
    try:
        return json.loads(body.decode("utf-8"))
    except (UnicodeDecodeError, ValueError, RecursionError) as e:
        raise ProtocolError(f"not JSON: {e}") from None


def _typed(obj: Mapping[str, Any], key: str, kind: type) -> Any:
    value = obj.get(key)
    if not isinstance(value, kind) or (kind is int and isinstance(value, bool)):
        raise ProtocolError(f"hook {key!r} is not {kind.__name__}: {value!r}"[:200])
    return value


def decode_hooks(body: bytes) -> list[Hook]:
    """HOOKS_DUMP's body: a JSON array of hook objects."""
    data = _json(body)
    if not isinstance(data, list) or len(data) > MAX_HOOKS:
        raise ProtocolError("HOOKS_DUMP is not a JSON array of hooks")
    hooks = []
    for item in data:
        if not isinstance(item, dict):
            raise ProtocolError("a hook is not a JSON object")
        try:
            status = NodeStatus[_typed(item, "desired_status", str)]
            hooks.append(
                Hook(
                    uid=_typed(item, "uid", int),
                    position=Position(_typed(item, "position", int)),
                    mode=HookMode(_typed(item, "mode", int)),
                    once=_typed(item, "once", bool),
                    enabled=_typed(item, "enabled", bool),
                    desired_status=status,
                )
            )
        except (KeyError, ValueError) as e:
            if isinstance(e, ProtocolError):
                raise
            raise ProtocolError(f"a hook the client cannot read: {e}"[:200]) from None
    return hooks


def decode_notification(parts: Sequence[bytes]) -> int:
    """A BREAKPOINT_REACHED message on the publisher socket: header, then the uid as text."""
    if len(parts) != 2:
        raise ProtocolError(f"a notification has 2 parts, not {len(parts)}")
    head, text = parts
    if len(head) != REQUEST_HEADER_SIZE:
        raise ProtocolError(f"a notification header has 6 bytes, not {len(head)}")
    protocol, type_code, _ = REQUEST_HEADER.unpack_from(head)
    if protocol != PROTOCOL or type_code != RequestType.BREAKPOINT_REACHED.code:
        raise ProtocolError("not a BREAKPOINT_REACHED notification")
    if not re.fullmatch(rb"[0-9]{1,5}", text) or int(text) > MAX_UID:
        raise ProtocolError(f"a notification names node {text[:20]!r}")
    return int(text)


def decode_blackboards(body: bytes) -> dict[str, Any]:
    """BLACKBOARD's body: MessagePack of ``{blackboard: {key: value}}`` (nil when empty)."""
    try:
        data = msgpack.unpackb(body)
    except msgpack.MsgPackError as e:
        raise ProtocolError(f"blackboard dump: {e}") from None
    if data is None:
        return {}
    if not isinstance(data, dict) or not all(isinstance(k, str) for k in data):
        raise ProtocolError("a blackboard dump is not a map of blackboard names")
    return data


def decode_timestamp(body: bytes) -> int:
    """TOGGLE_RECORDING start's answer: the executor's clock, microseconds as text."""
    if not re.fullmatch(rb"-?[0-9]{1,20}", body):
        raise ProtocolError(f"not a timestamp: {body[:30]!r}")
    return int(body)


# ---------------------------------------------------------------------------- addresses

DEFAULT_HOST: Final = "127.0.0.1"
DEFAULT_PORT: Final = 1667


def parse_address(text: str) -> tuple[str, int]:
    """``HOST:PORT``, ``HOST``, ``:PORT`` or ``[v6]:PORT`` (defaults 127.0.0.1 and 1667).

    The publisher also binds PORT + 1, so PORT is at most 65534."""
    text = text.strip()
    m = re.fullmatch(r"\[([0-9A-Fa-f:.]+)\](?::(\d{1,5}))?|([^:\s\[\]]*)(?::(\d{1,5}))?", text)
    if m is None:
        raise ValueError(f"not HOST:PORT: {text!r}")
    host = m.group(1) or m.group(3) or DEFAULT_HOST
    port_text = m.group(2) or m.group(4)
    port = int(port_text) if port_text else DEFAULT_PORT
    if not 1 <= port <= 65534:
        raise ValueError(f"port {port} is not in 1..65534")
    return host, port
