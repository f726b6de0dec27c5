"""The debug adapter's framing and messages: Content-Length frames read from untrusted
bytes, one bad frame costing only itself; requests checked; responses and events made."""

from __future__ import annotations

import io
import json
from typing import Any

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from bt_lsp.dap.framing import (
    MAX_HEADER_LINE,
    FrameError,
    FrameReader,
    FrameWriter,
    decode,
    encode,
)
from bt_lsp.dap.messages import Args, Channel, InvalidArguments, Request, parse_request


def frames(data: bytes, max_body: int = 1 << 20) -> list[bytes | FrameError]:
    reader = FrameReader(io.BytesIO(data).read, max_body)
    out: list[bytes | FrameError] = []
    while (item := reader.next()) is not None:
        out.append(item)
        assert len(out) < 100
    return out


def frame(body: bytes) -> bytes:
    return b"Content-Length: %d\r\n\r\n" % len(body) + body


class Trickle(io.RawIOBase):
    """A pipe that hands out one byte per read (frames split anywhere)."""

    def __init__(self, data: bytes) -> None:
        self.data = data

    def read(self, n: int = -1) -> bytes:
        chunk, self.data = self.data[:1], self.data[1:]
        return chunk


def test_frames_round_trip_whatever_the_reads() -> None:
    messages: list[dict[str, Any]] = [
        {"seq": 1, "type": "request", "command": "initialize"},
        {"é": "ü" * 100},
    ]
    data = b"".join(encode(m) for m in messages)
    assert [json.loads(b) for b in frames(data)] == messages  # type: ignore[arg-type]
    reader = FrameReader(Trickle(data).read)
    assert decode(reader.next()) == messages[0]  # type: ignore[arg-type]
    assert decode(reader.next()) == messages[1]  # type: ignore[arg-type]
    assert reader.next() is None


def test_headers_as_http_allows_them() -> None:
    data = (
        b"content-length:2\n\n{}"  # lower case, LF alone, no space
        + b"\r\n"  # a blank line between messages
        + b"Content-Type: application/vscode-jsonrpc; charset=utf-8\r\n"
        + b"CONTENT-LENGTH :  7 \r\n\r\n"
        + b'{"a":1}'
    )
    assert frames(data) == [b"{}", b'{"a":1}']


def test_a_body_over_the_limit_is_skipped_and_the_next_one_read() -> None:
    data = frame(b"x" * 5000) + frame(b'{"ok":1}')
    got = frames(data, max_body=4096)
    assert isinstance(got[0], FrameError) and "5000 bytes" in got[0].message
    assert got[1:] == [b'{"ok":1}']


def test_garbage_before_a_message_is_reported_then_the_message_read() -> None:
    got = frames(b"hello there\r\n" + b"\x00\x01: x\r\n" + frame(b"{}"))
    assert isinstance(got[0], FrameError) and "not a header" in got[0].message
    assert got[1:] == [b"{}"]


def test_a_header_line_over_the_limit() -> None:
    got = frames(b"X-Long: " + b"a" * (3 * MAX_HEADER_LINE) + b"\r\n" + frame(b"[]"))
    assert isinstance(got[0], FrameError)
    assert got[1:] == [b"[]"]


def test_a_message_without_length_and_an_input_that_ends_early() -> None:
    got = frames(b"Content-Type: x\r\n\r\n" + frame(b"{}") + b"Content-Length: 10\r\n\r\n{}")
    assert isinstance(got[0], FrameError) and "Content-Length" in got[0].message
    assert got[1] == b"{}"
    assert isinstance(got[2], FrameError) and "8 bytes into" in got[2].message
    assert len(got) == 3
    got = frames(b"Content-Length: 10\r\n")
    assert len(got) == 1 and isinstance(got[0], FrameError)


def test_a_length_of_a_terabyte_is_refused_without_reading_it() -> None:
    got = frames(b"Content-Length: 999999999999\r\n\r\n{}" + frame(b"{}"))
    assert isinstance(got[0], FrameError) and "over" in got[0].message
    assert len(got) == 1  # the rest was read as part of it: the input ended


@settings(max_examples=200, deadline=None)
@given(st.binary(max_size=300), st.binary(max_size=300))
def test_any_bytes_give_frames_or_errors_never_an_exception(head: bytes, tail: bytes) -> None:
    got = frames(head + frame(b'{"seq":1}') + tail, max_body=1000)
    for item in got:
        assert isinstance(item, (bytes, FrameError))
        if isinstance(item, bytes):
            assert isinstance(decode(item), (dict, FrameError))


def test_decode_refuses_what_is_not_an_object() -> None:
    assert isinstance(decode(b"[1]"), FrameError)
    assert isinstance(decode(b"\xff"), FrameError)
    assert isinstance(decode(b"{"), FrameError)
    assert isinstance(decode(b"[" * 100_000 + b"]" * 100_000), FrameError)
    assert decode(b'{"a":[1]}') == {"a": [1]}


def test_encode_refuses_nan_and_writes_whole_frames() -> None:
    with pytest.raises(ValueError):
        encode({"x": float("nan")})
    out = io.BytesIO()
    FrameWriter(out).write({"a": "é"})
    assert out.getvalue() == b'Content-Length: 10\r\n\r\n{"a":"\xc3\xa9"}'


def test_parse_request() -> None:
    request = parse_request({"seq": 3, "type": "request", "command": "threads"})
    assert isinstance(request, Request) and request.arguments.raw == {}
    assert parse_request({"seq": "3", "type": "request", "command": "x"})[0] is None  # type: ignore[index]
    assert parse_request({"seq": True, "type": "request", "command": "x"})[0] is None  # type: ignore[index]
    assert parse_request({"seq": 4, "type": "event", "event": "x"})[0] is None  # type: ignore[index]
    assert parse_request({"seq": 5, "type": "request"}) == (None, "", "request 5 has no command")
    assert parse_request({"seq": 6, "type": "request", "command": "c", "arguments": [1]}) == (
        6,
        "c",
        "the arguments are not a JSON object",
    )


def test_args_check_types() -> None:
    args = Args({"port": 5, "host": "h", "flag": True, "t": 0.5, "n": None, "o": {"x": 1}})
    assert args.integer("port") == 5 and args.text("host") == "h" and args.flag("flag", False)
    assert args.number("t") == 0.5 and args.number("port") == 5.0
    assert args.integer("missing", 7) == 7 and args.integer("n") is None
    assert args.mapping("o") is not None and args.array("missing") is None
    for bad in (lambda: args.integer("host"), lambda: args.integer("flag"),
                lambda: args.text("port"), lambda: args.number("flag"),
                lambda: args.flag("port", True), lambda: args.array("o")):  # fmt: skip
        with pytest.raises(InvalidArguments):
            bad()


def test_channel_numbers_and_shapes() -> None:
    sent: list[dict[str, Any]] = []
    channel = Channel(sent.append)
    request = parse_request({"seq": 9, "type": "request", "command": "threads"})
    assert isinstance(request, Request)
    channel.respond(request, {"threads": []})
    channel.fail(10, "attach", "no " * 2000)
    channel.event("stopped", {"reason": "breakpoint"})
    channel.output("hello")
    assert [m["seq"] for m in sent] == [1, 2, 3, 4]
    assert sent[0] == {"seq": 1, "type": "response", "request_seq": 9, "success": True,
                       "command": "threads", "body": {"threads": []}}  # fmt: skip
    assert sent[1]["success"] is False and len(sent[1]["message"]) <= 2000
    assert sent[1]["body"]["error"]["showUser"] is True
    assert sent[3]["body"] == {"category": "console", "output": "hello\n"}
