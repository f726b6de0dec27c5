"""The Groot2 wire format: what the client sends is exactly what BehaviorTree.CPP parses,
and whatever an executor answers is decoded or refused with a ProtocolError, never a crash.

The replies below were captured from BehaviorTree.CPP 4.8.2 (behaviortreepy)."""

from __future__ import annotations

import contextlib
import io
import json
import struct
from typing import Any

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from bt_lsp.live import msgpack
from bt_lsp.live.btlog import BtLog
from bt_lsp.live.protocol import (
    ExecutorError,
    Hook,
    HookMode,
    NodeState,
    NodeStatus,
    Position,
    ProtocolError,
    RequestHeader,
    RequestType,
    Resume,
    blackboard_payload,
    decode_blackboards,
    decode_hooks,
    decode_notification,
    decode_reply,
    decode_status,
    decode_timestamp,
    decode_transitions,
    hook_insert_payload,
    hook_remove_payload,
    parse_address,
    unlock_payload,
)
from bt_lsp.live.tree import parse_tree_xml
from bt_lsp.live.view import draw

UUID = bytes.fromhex("5cbb91d0f69e4e22aefae1e7791fc3d5")
FULLTREE = """<root BTCPP_format="4">
    <BehaviorTree ID="Main" _fullpath="">
        <Sequence name="seq" _uid="1">
            <Script name="Script" _uid="2" code="counter := 1"/>
            <SubTree ID="Sub" _fullpath="sub1" _uid="3" value="{counter}"/>
            <AlwaysSuccess name="ok" _uid="7"/>
        </Sequence>
    </BehaviorTree>
    <BehaviorTree ID="Sub" _fullpath="sub1">
        <Sequence name="Sequence" _uid="4">
            <Sleep name="Sleep" _uid="5" msec="50"/>
            <SetBlackboard name="SetBlackboard" _uid="6" output_key="msg" value="hello"/>
        </Sequence>
    </BehaviorTree>
    <TreeNodesModel>
        <Action ID="AlwaysSuccess"/>
    </TreeNodesModel>
</root>
"""
STATUS = bytes.fromhex("01000102000203000107000c04000105000106000c")
BLACKBOARD = b"\x82\xa4Main\x81\xa7counter\x01\xa4sub1\x81\xa3msg\xa5hello"
HOOKS = b'[{"desired_status":"SKIPPED","enabled":true,"mode":0,"once":false,"position":0,"uid":7}]'


def reply_head(header: RequestHeader) -> bytes:
    return header.encode() + UUID


# ---------------------------------------------------------------- headers and replies


def test_request_header_bytes() -> None:
    # protocol 2, 'T', then the id in the executor's (little-endian) byte order
    assert RequestHeader(RequestType.FULLTREE, 1234).encode() == bytes.fromhex("0254d2040000")
    with pytest.raises(ValueError):
        RequestHeader(RequestType.STATUS, 1 << 32).encode()


def test_reply_checked_against_its_request() -> None:
    req = RequestHeader(RequestType.STATUS, 99)
    reply = decode_reply([reply_head(req), STATUS], req)
    assert reply.uuid == UUID and reply.body == (STATUS,)
    other = RequestHeader(RequestType.STATUS, 100)
    with pytest.raises(ProtocolError, match="another request"):
        decode_reply([reply_head(other), STATUS], req)
    with pytest.raises(ProtocolError, match="22 bytes"):
        decode_reply([req.encode(), STATUS], req)
    with pytest.raises(ProtocolError, match="protocol 3"):
        decode_reply([b"\x03" + reply_head(req)[1:]], req)
    with pytest.raises(ExecutorError, match="Node ID not found"):
        decode_reply([b"error", b"Node ID not found"], req)
    with pytest.raises(ProtocolError):
        decode_reply([], req)


def test_status_buffer() -> None:
    states = decode_status(STATUS)
    assert states[1] == NodeState(NodeStatus.RUNNING)
    assert states[7] == NodeState(NodeStatus.IDLE, NodeStatus.SUCCESS)
    assert str(states[7]) == "IDLE (was SUCCESS)"
    assert str(states[3]) == "RUNNING"
    assert len(states) == 7
    with pytest.raises(ProtocolError, match="multiple of 3"):
        decode_status(STATUS[:-1])
    with pytest.raises(ProtocolError, match="unknown node status 9"):
        decode_status(b"\x01\x00\x09")
    with pytest.raises(ProtocolError, match="twice"):
        decode_status(b"\x01\x00\x01\x01\x00\x02")


def test_transitions_hooks_notification_blackboard_timestamp() -> None:
    record = (1_000_001).to_bytes(6, "little") + (5).to_bytes(2, "little") + b"\x02"
    [t] = decode_transitions(record)
    assert (t.offset_us, t.uid, t.status) == (1_000_001, 5, NodeStatus.SUCCESS)
    with pytest.raises(ProtocolError):
        decode_transitions(record + b"\x00")
    assert decode_hooks(HOOKS) == [Hook(7)]
    assert decode_hooks(b"[]") == []
    head = RequestHeader(RequestType.BREAKPOINT_REACHED, 7).encode()
    assert decode_notification([head, b"7"]) == 7
    for bad in ([head, b"70000"], [head, b"-1"], [head], [b"\x02S" + head[2:], b"7"]):
        with pytest.raises(ProtocolError):
            decode_notification(bad)
    assert decode_blackboards(BLACKBOARD) == {"Main": {"counter": 1}, "sub1": {"msg": "hello"}}
    assert decode_blackboards(b"\xc0") == {}
    with pytest.raises(ProtocolError):
        decode_blackboards(b"\x91\x01")  # an array, not a map of blackboards
    assert decode_timestamp(b"1796409270948339") == 1796409270948339
    with pytest.raises(ProtocolError):
        decode_timestamp(b"soon")


@pytest.mark.parametrize(
    ("bad", "why"),
    [
        (b"{}", "not a JSON array"),
        (b"[1]", "not a JSON object"),
        (b'[{"uid": 7}]', "desired_status"),
        (HOOKS.replace(b'"uid":7', b'"uid":70000'), "cannot read"),
        (HOOKS.replace(b"true", b"1"), "enabled"),
        (HOOKS.replace(b"SKIPPED", b"DONE"), "cannot read"),
        (b"[", "not JSON"),
        (b"[" * 100_000, "not JSON"),
    ],
)
def test_malformed_hooks_dump(bad: bytes, why: str) -> None:
    with pytest.raises(ProtocolError, match=why):
        decode_hooks(bad)


# ---------------------------------------------------------------- payloads


def cpp_reads_hook(obj: Any) -> None:
    """What ``BT::Monitor::from_json`` and the HOOK_INSERT handler of 4.8.2 require: each
    key present, of the JSON type nlohmann's get<> accepts, the status one that
    convertFromString<NodeStatus> knows (anything else throws, and the executor aborts)."""
    assert isinstance(obj, dict)
    assert type(obj["enabled"]) is bool and type(obj["once"]) is bool
    assert type(obj["uid"]) is int and 0 <= obj["uid"] <= 0xFFFF
    assert type(obj["mode"]) is int and obj["mode"] in (0, 1)
    assert type(obj["position"]) is int and obj["position"] in (0, 1)
    assert obj["desired_status"] in ("IDLE", "RUNNING", "SUCCESS", "FAILURE", "SKIPPED")


def cpp_reads_unlock(obj: Any) -> None:
    assert set(obj) == {"uid", "desired_status", "position", "remove_when_done"}
    assert type(obj["uid"]) is int and 0 <= obj["uid"] <= 0xFFFF
    assert type(obj["desired_status"]) is str
    assert type(obj["position"]) is int and obj["position"] in (0, 1)
    assert type(obj["remove_when_done"]) is bool


uids = st.integers(0, 0xFFFF)
hooks = st.builds(
    Hook,
    uid=uids,
    position=st.sampled_from(Position),
    mode=st.sampled_from(HookMode),
    once=st.booleans(),
    enabled=st.booleans(),
    desired_status=st.sampled_from([NodeStatus.SUCCESS, NodeStatus.FAILURE, NodeStatus.SKIPPED]),
)


@given(st.one_of(hooks, st.lists(hooks, min_size=1, max_size=5)))
def test_hook_payloads_parse_in_btcpp(value: Hook | list[Hook]) -> None:
    data = hook_insert_payload(value)
    assert data.isascii()
    parsed = json.loads(data)
    for obj in parsed if isinstance(parsed, list) else [parsed]:
        cpp_reads_hook(obj)
        assert decode_hooks(json.dumps([obj]).encode())[0] in (
            value if isinstance(value, list) else [value]
        )


@given(uids, st.sampled_from(Resume), st.sampled_from(Position), st.booleans())
def test_unlock_and_remove_payloads_parse_in_btcpp(
    uid: int, result: Resume, position: Position, remove: bool
) -> None:
    obj = json.loads(unlock_payload(uid, result, position, remove))
    cpp_reads_unlock(obj)
    # The executor maps anything but SUCCESS and FAILURE to SKIPPED (the node ticks).
    assert obj["desired_status"] == {"CONTINUE": "SKIPPED"}.get(result.name, result.name)
    assert json.loads(hook_remove_payload(uid, position)) == {"uid": uid, "position": position}


@pytest.mark.parametrize(
    "bad",
    [
        {"uid": -1},
        {"uid": 65536},
        {"uid": True},
        {"uid": 1.0},
        {"uid": "7"},
        {"uid": 7, "position": 0},
        {"uid": 7, "mode": 1},
        {"uid": 7, "once": 1},
        {"uid": 7, "enabled": None},
        {"uid": 7, "desired_status": "SUCCESS"},
        {"uid": 7, "desired_status": NodeStatus.RUNNING},
        {"uid": 7, "desired_status": 2},
    ],
)
def test_invalid_hook_values_are_refused_before_sending(bad: dict[str, Any]) -> None:
    with pytest.raises(ValueError):
        Hook(**bad)


def test_invalid_payload_values_are_refused_before_sending() -> None:
    for call in (
        lambda: unlock_payload(70000),
        lambda: unlock_payload(7, "FAILURE"),  # type: ignore[arg-type]
        lambda: unlock_payload(7, Resume.FAILURE, 0),  # type: ignore[arg-type]
        lambda: unlock_payload(7, Resume.FAILURE, Position.PRE, 1),  # type: ignore[arg-type]
        lambda: hook_remove_payload(7, 1),  # type: ignore[arg-type]
        lambda: hook_insert_payload([]),
        lambda: blackboard_payload(["Main;sub1"]),
        lambda: blackboard_payload([""]),
        lambda: blackboard_payload([]),
    ):
        with pytest.raises(ValueError):
            call()
    assert blackboard_payload(["Main", "sub1/inner"]) == b"Main;sub1/inner"
    assert blackboard_payload("Main") == b"Main"


# ---------------------------------------------------------------- the tree


def test_fulltree_parsed_with_subtrees_expanded() -> None:
    tree = parse_tree_xml(FULLTREE)
    assert tree.tree_id == "Main" and tree.blackboards == ("Main", "sub1")
    assert sorted(tree.nodes) == [1, 2, 3, 4, 5, 6, 7]
    assert [n.path for _, n in tree.walk()] == [
        "seq", "Script", "sub1", "sub1/Sequence", "sub1/Sleep", "sub1/SetBlackboard", "ok"
    ]  # fmt: skip
    assert tree.find("sub1/Sleep")[0].uid == 5
    assert tree.find("ok")[0].uid == tree.find("7")[0].uid == 7
    assert draw(tree, decode_status(STATUS)) == [
        'Sequence "seq" #1            RUNNING',
        "├─ Script #2                 SUCCESS",
        '├─ SubTree "sub1" -> Sub #3  RUNNING',
        "│  └─ Sequence #4            RUNNING",
        "│     ├─ Sleep #5            RUNNING",
        "│     └─ SetBlackboard #6    IDLE (was SUCCESS)",
        '└─ AlwaysSuccess "ok" #7     IDLE (was SUCCESS)',
    ]


@pytest.mark.parametrize(
    ("xml", "why"),
    [
        ("<root/>", "no <BehaviorTree>"),
        ("<tree/>", "no <root>"),
        ("not xml", "not XML"),
        ('<root><BehaviorTree ID="M"><A/></BehaviorTree></root>', "no valid _uid"),
        ('<root><BehaviorTree ID="M"><A _uid="99999"/></BehaviorTree></root>', "_uid"),
        ('<root><BehaviorTree ID="M"><A _uid="1"><B _uid="1"/></A></BehaviorTree></root>', "two"),
        ('<root><BehaviorTree ID="M"/></root>', "0 root nodes"),
        (
            '<root><BehaviorTree ID="M" _fullpath=""><S _uid="1" _fullpath=""/></BehaviorTree>'
            "</root>",
            "called twice",
        ),
        (
            '<!DOCTYPE root [<!ENTITY e "x">]><root><BehaviorTree ID="M">'
            '<A _uid="&e;"/></BehaviorTree></root>',
            "_uid",
        ),
    ],
)
def test_malformed_trees(xml: str, why: str) -> None:
    with pytest.raises(ProtocolError, match=why):
        parse_tree_xml(xml)


def test_address() -> None:
    assert parse_address("127.0.0.1:1700") == ("127.0.0.1", 1700)
    assert parse_address("localhost") == ("localhost", 1667)
    assert parse_address(":1700") == ("127.0.0.1", 1700)
    assert parse_address("[::1]:1700") == ("::1", 1700)
    assert parse_address("") == ("127.0.0.1", 1667)
    for bad in ("host:65535", "host:0", "a:b:c", "host:port"):
        with pytest.raises(ValueError):
            parse_address(bad)


# ---------------------------------------------------------------- MessagePack


def test_msgpack_values_nlohmann_writes() -> None:
    cases: list[tuple[bytes, Any]] = [
        (b"\xc0", None),
        (b"\xc2", False),
        (b"\xc3", True),
        (b"\x7f", 127),
        (b"\xe0", -32),
        (b"\xcc\xff", 255),
        (b"\xcd\x01\x00", 256),
        (b"\xce\x00\x01\x00\x00", 65536),
        (b"\xcf" + (1 << 40).to_bytes(8, "big"), 1 << 40),
        (b"\xd0\x80", -128),
        (b"\xd1\x80\x00", -32768),
        (b"\xd2\xff\xff\xff\xff", -1),
        (b"\xd3" + (-(1 << 40)).to_bytes(8, "big", signed=True), -(1 << 40)),
        (b"\xca" + struct.pack(">f", 1.5), 1.5),
        (b"\xcb" + struct.pack(">d", 0.1), 0.1),
        (b"\xd9\x03abc", "abc"),
        (b"\xda\x00\x01x", "x"),
        (b"\xc4\x02\x00\x01", b"\x00\x01"),
        (b"\xdc\x00\x02\x01\x02", [1, 2]),
        (b"\xde\x00\x01\xa1k\x90", {"k": []}),
        (b"\xd4\x05\x09", b"\x09"),
        (b"\xc7\x02\x05ab", b"ab"),
    ]
    for data, value in cases:
        assert msgpack.unpackb(data) == value, data


@pytest.mark.parametrize(
    "bad",
    [
        b"",
        b"\xc1",
        b"\xa3ab",
        b"\x01\x02",
        b"\xdd\xff\xff\xff\xff",
        b"\x81\x90\x01",
        b"\xa1\xff",
        b"\x91" * 100 + b"\x01",
    ],
)
def test_msgpack_malformed(bad: bytes) -> None:
    with pytest.raises(msgpack.MsgPackError):
        msgpack.unpackb(bad)


# ---------------------------------------------------------------- fuzzing the decoders

REQ = RequestHeader(RequestType.STATUS, 5)


@settings(max_examples=300)
@given(st.binary(max_size=200))
def test_fuzz_decoders_only_raise_protocol_errors(data: bytes) -> None:
    decoders = (
        decode_status,
        decode_transitions,
        decode_hooks,
        decode_blackboards,
        decode_timestamp,
        parse_tree_xml,
        lambda d: decode_notification([d[:6], d[6:]]),
        lambda d: decode_reply([d[:22], d[22:]], REQ),
        lambda d: decode_reply([reply_head(REQ), d], REQ),
        lambda d: BtLog(io.BytesIO(d)),
    )
    for decode in decoders:
        with contextlib.suppress(ProtocolError, ExecutorError):
            decode(data)


@settings(max_examples=300)
@given(st.binary(max_size=300))
def test_fuzz_msgpack(data: bytes) -> None:
    with contextlib.suppress(msgpack.MsgPackError):
        msgpack.unpackb(data)


@settings(max_examples=200)
@given(st.integers(0, len(BLACKBOARD) - 1), st.integers(0, 255))
def test_fuzz_mutated_blackboard(at: int, byte: int) -> None:
    data = BLACKBOARD[:at] + bytes([byte]) + BLACKBOARD[at + 1 :]
    with contextlib.suppress(ProtocolError):
        decode_blackboards(data)


@settings(max_examples=200)
@given(st.integers(0, len(FULLTREE) - 1), st.sampled_from('<>"=/_ 0123456789&;'))
def test_fuzz_mutated_tree(at: int, char: str) -> None:
    with contextlib.suppress(ProtocolError):
        parse_tree_xml(FULLTREE[:at] + char + FULLTREE[at + 1 :])
