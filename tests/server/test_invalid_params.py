"""Params that do not have their method's shape, through a raw stdio client whose stderr
is read too: a request gets InvalidParams, a notification one clear line in the client's
log (pygls printed cattrs's tracebacks on stderr, which an editor shows as a crash), a
``$/cancelRequest`` of an object id is ignored, and a change whose version is outside
LSP's integer range is refused, the document staying as it was."""

from __future__ import annotations

import queue
import subprocess
import threading
from collections.abc import Iterator
from typing import Any

import pytest

from tests.server.test_framing import DOC, SERVER, RawServer, frame, msg


class Server(RawServer):
    """A raw server whose stderr is kept."""

    def __init__(self) -> None:
        self.proc = subprocess.Popen(
            SERVER, stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.PIPE
        )
        self.inbox: queue.Queue[dict[str, Any]] = queue.Queue()
        self.seen: list[dict[str, Any]] = []
        self.stderr: list[bytes] = []
        threading.Thread(target=self._read, daemon=True).start()
        threading.Thread(target=self._read_stderr, daemon=True).start()

    def _read_stderr(self) -> None:
        err = self.proc.stderr
        assert err is not None
        for line in err:
            self.stderr.append(line)


@pytest.fixture(scope="module")
def server() -> Iterator[Server]:
    s = Server()
    try:
        s.initialize()
        yield s
    finally:
        s.close()


URI = "untitled:params.xml"


def _hover(s: Server, msg_id: int, character: int = 50) -> dict[str, Any]:
    params = {"textDocument": {"uri": URI}, "position": {"line": 0, "character": character}}
    return s.answer_to(msg("textDocument/hover", params, msg_id))


def test_bad_notifications_are_one_line_each(server: Server) -> None:
    s = server
    item = {"uri": URI, "languageId": "xml", "version": 1, "text": DOC}
    s.write(frame(msg("textDocument/didOpen", {"textDocument": item})))
    assert "AlwaysSuccess" in _hover(s, 1)["result"]["contents"]["value"]
    s.logs()
    s.seen.clear()
    s.write(frame(msg("textDocument/didOpen", {"textDocument": {"uri": 7}})))
    s.write(frame(msg("textDocument/didClose", {"textDocument": {"uri": ["x"]}})))
    s.write(frame(msg("workspace/didChangeConfiguration", [])))
    s.write(frame(msg("$/cancelRequest", {"id": {"a": 1}})))
    s.write(frame(msg("$/cancelRequest", {"id": [1]})))
    s.write(frame(msg("$/cancelRequest", {"id": 12345})))  # unknown, valid: nothing said
    assert "result" in _hover(s, 2)
    logs = s.logs()
    assert len(logs) == 5, logs
    assert all("\n" not in m for m in logs), logs
    assert sum("Invalid params for the notification" in m for m in logs) == 3, logs
    assert sum("$/cancelRequest ignored" in m for m in logs) == 2, logs
    assert not any("internal error" in m for m in logs), logs
    assert "didClose" in logs[1] and "a string was expected, not an array" in logs[1]


def test_a_version_outside_the_integer_range_refuses_the_change(server: Server) -> None:
    s = server
    s.logs()
    s.seen.clear()
    for version in (2**31, -(2**31) - 1, "2", 1.5):
        change = {
            "textDocument": {"uri": URI, "version": version},
            "contentChanges": [{"text": DOC.replace("AlwaysSuccess", "AlwaysFailure")}],
        }
        s.write(frame(msg("textDocument/didChange", change)))
    # The document is as it was: the hover still finds the node of version 1.
    assert "AlwaysSuccess" in _hover(s, 3)["result"]["contents"]["value"]
    logs = s.logs()
    refused = [m for m in logs if "the change is refused" in m]
    assert len(refused) == 4, logs
    assert "should be in range [-2147483648:2147483647], but was 2147483648" in refused[0]
    change = {
        "textDocument": {"uri": URI, "version": 2**31 - 1},  # the largest: accepted
        "contentChanges": [{"text": DOC.replace("AlwaysSuccess", "AlwaysFailure")}],
    }
    s.write(frame(msg("textDocument/didChange", change)))
    assert "AlwaysFailure" in _hover(s, 4)["result"]["contents"]["value"]


def test_deeply_nested_params_are_refused_not_fatal(server: Server) -> None:
    """Values nested as deep as the decoder reads, where a string or a number is due."""
    s = server
    deep: Any = 1
    for _ in range(800):
        deep = [deep]
    params = {"textDocument": {"uri": deep}, "position": {"line": 0, "character": 0}}
    answer = s.answer_to(msg("textDocument/hover", params, 20))
    assert answer["error"]["code"] == -32602
    changes = [{"uri": deep, "type": 1}, {"uri": "file:///nowhere/a.xml", "type": deep}]
    s.write(frame(msg("workspace/didChangeWatchedFiles", {"changes": changes})))
    s.write(frame(msg("$/cancelRequest", {"id": deep})))
    s.write(frame(msg("workspace/didChangeConfiguration", {"settings": {"btLsp": deep}})))
    assert "result" in _hover(s, 21)


def test_nothing_was_written_to_stderr(server: Server) -> None:
    """(Runs last.) None of the bad messages above printed a traceback."""
    s = server
    s.write(frame(msg("textDocument/didOpen", {"textDocument": {"uri": 8}})))
    assert "result" in _hover(s, 5)
    text = b"".join(s.stderr).decode("utf-8", "replace")
    assert "Traceback" not in text, text[-2000:]
    assert "Unable to deserialize" not in text, text[-2000:]
