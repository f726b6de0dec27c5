"""A document at ``maxDocumentBytes`` is analysed off the event loop: requests on other
documents, and the diagnostics of a small document being typed in, are answered before
its analysis ends, and its own diagnostics still arrive, of its latest version.

Through a raw stdio client, which sees every message in the order the server wrote it:
the test asserts that order, never a time."""

from __future__ import annotations

import functools
import json
import queue
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from types import SimpleNamespace
from typing import TYPE_CHECKING, Any, cast

import pytest

from bt_lsp.rules import facts
from bt_lsp.server.background import (
    CPP_WORKER_CHARS,
    WORKER_CHARS,
    Background,
    _Held,
    _prepare,
)
from bt_lsp.server.state import OpenDocument
from bt_lsp.syntax.document import Document
from tests.server.test_framing import TIMEOUT, RawServer, frame, msg

if TYPE_CHECKING:
    from bt_lsp.server.app import BtServer

SMALL_URI = "untitled:small.xml"
BIG_URI = "untitled:big.xml"
SMALL = (
    '<root BTCPP_format="4" main_tree_to_execute="Main">\n'
    '  <BehaviorTree ID="Main"><Sequence><AlwaysSuccess/></Sequence></BehaviorTree>\n'
    "</root>\n"
)
# What the tests that call the worker's functions directly give it: the smallest document it
# takes (the tests through the server keep SIZE, so that its analysis lasts).
AT_WORKER = WORKER_CHARS
# A bad name only the edit of the small document brings.
SMALL_EDITED = SMALL.replace("<AlwaysSuccess/>", '<AlwaysSuccess na.me="x"/>')
TAGS = "<AlwaysSuccess/><Fallback><AlwaysFailure/></Fallback>"
LINE = '    <Sequence name="s{i}">' + TAGS + "</Sequence>\n"
SIZE = 2 * 1024 * 1024


@functools.cache
def big_document(marker: str, size: int = SIZE) -> str:
    """About ``size`` bytes of valid trees, with one node type nobody registers
    (``unknown-node`` is a semantic diagnostic: only the complete analysis finds it)."""
    head = '<root BTCPP_format="4" main_tree_to_execute="Main">\n  <BehaviorTree ID="Main">\n'
    head += f"    <{marker}/>\n"
    tail = "  </BehaviorTree>\n</root>\n"
    body = []
    length = len(head) + len(tail)
    i = 0
    while length < size:
        line = LINE.format(i=i)
        body.append(line)
        length += len(line)
        i += 1
    return head + "".join(body) + tail


def open_params(uri: str, text: str, version: int = 1) -> dict[str, Any]:
    return {"textDocument": {"uri": uri, "languageId": "xml", "version": version, "text": text}}


def hover(uri: str, msg_id: int, line: int = 1, character: int = 30) -> bytes:
    params = {"textDocument": {"uri": uri}, "position": {"line": line, "character": character}}
    return frame(msg("textDocument/hover", params, msg_id))


class Session:
    """A server whose messages are read in order, as they were written."""

    def __init__(self, limit: int) -> None:
        self.raw = RawServer()
        self.log: list[dict[str, Any]] = []
        options = {"debounceMs": 0, "maxDocumentBytes": limit}
        init: dict[str, Any] = {"capabilities": {}, "processId": None, "rootUri": None}
        self.raw.write(frame(msg("initialize", {**init, "initializationOptions": options}, 0)))
        self.until(lambda m: m.get("id") == 0 and "method" not in m)
        self.raw.write(frame(msg("initialized", {})))

    def until(self, found: Callable[[dict[str, Any]], bool]) -> int:
        """Read messages until one is ``found``; its index in :attr:`log`."""
        for i, m in enumerate(self.log):
            if found(m):
                return i
        while True:
            try:
                m = self.raw.inbox.get(timeout=TIMEOUT)
            except queue.Empty:
                raise AssertionError(f"nothing found within {TIMEOUT}s") from None
            self.log.append(m)
            if found(m):
                return len(self.log) - 1


def answer(msg_id: int) -> Callable[[dict[str, Any]], bool]:
    return lambda m: "method" not in m and m.get("id") == msg_id


def published(
    uri: str, version: int | None = None, code: str | None = None
) -> Callable[[dict[str, Any]], bool]:
    """A publication for ``uri`` (of ``version``, holding ``code``)."""

    def found(m: dict[str, Any]) -> bool:
        if m.get("method") != "textDocument/publishDiagnostics" or m["params"]["uri"] != uri:
            return False
        if version is not None and m["params"].get("version") != version:
            return False
        return code is None or any(d.get("code") == code for d in m["params"]["diagnostics"])

    return found


@pytest.fixture
def session() -> Iterator[Session]:
    s = Session(limit=len(big_document("Frobnicate").encode()))
    try:
        s.raw.write(frame(msg("textDocument/didOpen", open_params(SMALL_URI, SMALL))))
        s.raw.write(hover(SMALL_URI, 1))  # everything is imported and ready
        s.until(answer(1))
        yield s
    finally:
        s.raw.close()


def test_other_requests_are_answered_before_a_large_document_is_analysed(
    session: Session,
) -> None:
    s = session
    big = big_document("Frobnicate")
    change = {
        "textDocument": {"uri": SMALL_URI, "version": 2},
        "contentChanges": [{"text": SMALL_EDITED}],
    }
    s.raw.write(
        frame(msg("textDocument/didOpen", open_params(BIG_URI, big)))
        + hover(SMALL_URI, 2)
        + frame(msg("textDocument/didChange", change))
    )
    hovered = s.until(answer(2))
    small_done = s.until(published(SMALL_URI, 2, "port-name-forbidden-char"))
    big_done = s.until(published(BIG_URI, 1, "unknown-node"))
    assert hovered < big_done
    assert small_done < big_done  # the small document's edit did not wait behind it
    assert "result" in s.log[hovered]
    # A request on the large document itself is answered too, and a code action, which
    # needs its diagnostics, waits for its analysis (not the loop).
    s.raw.write(hover(BIG_URI, 3, line=3))
    rng = {"start": {"line": 2, "character": 0}, "end": {"line": 2, "character": 20}}
    params = {"textDocument": {"uri": BIG_URI}, "range": rng, "context": {"diagnostics": []}}
    s.raw.write(frame(msg("textDocument/codeAction", params, 4)))
    assert "result" in s.log[s.until(answer(3))]
    assert s.log[s.until(answer(4))].get("result") is not None


def test_an_edit_during_the_analysis_is_what_gets_published(session: Session) -> None:
    """The analysis of version 1 is superseded by the edit: version 2's diagnostics are
    published, and nothing of version 1 after them."""
    s = session
    big = big_document("Frobnicate")
    edited = big.replace("<Frobnicate/>", "<Wobble/>")
    change = {"textDocument": {"uri": BIG_URI, "version": 2}, "contentChanges": [{"text": edited}]}
    s.raw.write(
        frame(msg("textDocument/didOpen", open_params(BIG_URI, big)))
        + frame(msg("textDocument/didChange", change))
        + hover(SMALL_URI, 5)
    )
    done = s.until(published(BIG_URI, 2, "unknown-node"))
    message = next(
        d["message"] for d in s.log[done]["params"]["diagnostics"] if d["code"] == "unknown-node"
    )
    assert "Wobble" in message
    s.raw.write(hover(SMALL_URI, 6))  # anything still queued was written before this answer
    s.until(answer(6))
    later = [m for m in s.log[done + 1 :] if published(BIG_URI)(m)]
    assert later == []
    assert s.until(answer(5)) < done


def symbols(uri: str, msg_id: int) -> bytes:
    return frame(msg("textDocument/documentSymbol", {"textDocument": {"uri": uri}}, msg_id))


def test_the_open_of_a_large_document_holds_only_its_own_requests(session: Session) -> None:
    """Nothing of the open runs on the event loop: a hover on another document is answered
    before the large one's first publication (its early names, found on the worker), and
    the requests on the large document wait for it to be ready, then answer correctly."""
    s = session
    big = big_document("Frobnicate")
    s.raw.write(
        frame(msg("textDocument/didOpen", open_params(BIG_URI, big)))
        + hover(SMALL_URI, 7)
        + hover(BIG_URI, 8, line=3)
        + symbols(BIG_URI, 9)
    )
    small = s.until(answer(7))
    first = s.until(published(BIG_URI))
    assert small < first
    assert s.log[first]["params"]["diagnostics"] == []  # the early names: none is bad
    assert "AlwaysSuccess" in s.log[s.until(answer(8))]["result"]["contents"]["value"]
    (tree,) = s.log[s.until(answer(9))]["result"]
    assert (tree["name"], tree["range"]["start"]["line"]) == ("Main", 1)
    assert len(tree["children"]) == big.count("<Sequence") + 1  # Frobnicate and each Sequence
    s.until(published(BIG_URI, 1, "unknown-node"))


def test_a_large_outline_and_folding_are_made_beside_the_loop(session: Session) -> None:
    """The outline and the folding ranges of a large document, asked while an edit of it
    is analysed, are made on a thread of their own: a hover on another document sent after
    them is answered first (on the loop, it waited for both), and both are of the edit."""
    s = session
    big = big_document("Frobnicate").replace(LINE.format(i=0), "", 1)  # room for the edit
    s.raw.write(frame(msg("textDocument/didOpen", open_params(BIG_URI, big))))
    s.until(published(BIG_URI, 1, "unknown-node"))
    at = {"line": 2, "character": 0}
    change = {
        "textDocument": {"uri": BIG_URI, "version": 2},
        "contentChanges": [{"range": {"start": at, "end": at}, "text": "<Sequence/>\n"}],
    }
    folding = frame(msg("textDocument/foldingRange", {"textDocument": {"uri": BIG_URI}}, 22))
    s.raw.write(frame(msg("textDocument/didChange", change)) + symbols(BIG_URI, 21) + folding)
    # Once they are under way (the first outline of 2 MB takes a few hundred ms of CPU;
    # the slower the machine, the more so): on the loop, the hover would wait for both.
    time.sleep(0.05)
    s.raw.write(hover(SMALL_URI, 23))
    hovered = s.until(answer(23))
    outlined, folded = s.until(answer(21)), s.until(answer(22))
    assert hovered < outlined and hovered < folded
    (tree,) = s.log[outlined]["result"]
    assert len(tree["children"]) == big.count("<Sequence") + 2  # the new one too
    assert tree["children"][0]["range"]["start"]["line"] == 2
    ranges = s.log[folded]["result"]
    # <root> folds to the line before its end tag, one line further down after the edit.
    assert ranges[0] == {"startLine": 0, "endLine": big.count("\n") - 1, "kind": "region"}
    s.until(published(BIG_URI, 2, "unknown-node"))
    s.raw.write(symbols(BIG_URI, 24))  # again, from what the first one kept
    assert s.log[s.until(answer(24))]["result"] == s.log[outlined]["result"]


def test_an_edit_right_after_the_open_is_not_lost(session: Session) -> None:
    """An incremental edit sent with the open waits for the document to be ready, then
    applies at the position it names; the requests after it see the edited text."""
    s = session
    big = big_document("Frobnicate")
    rng = {"start": {"line": 2, "character": 5}, "end": {"line": 2, "character": 15}}
    change = {
        "textDocument": {"uri": BIG_URI, "version": 2},
        "contentChanges": [{"range": rng, "text": "Wobble"}],
    }
    s.raw.write(
        frame(msg("textDocument/didOpen", open_params(BIG_URI, big)))
        + frame(msg("textDocument/didChange", change))
        + hover(BIG_URI, 10, line=2, character=7)
        + hover(SMALL_URI, 11)
    )
    assert s.until(answer(11)) < s.until(published(BIG_URI))
    assert "Wobble" in s.log[s.until(answer(10))]["result"]["contents"]["value"]
    done = s.until(published(BIG_URI, 2, "unknown-node"))
    (message,) = (
        d["message"] for d in s.log[done]["params"]["diagnostics"] if d["code"] == "unknown-node"
    )
    assert "Wobble" in message
    assert not [m for m in s.log if published(BIG_URI, 1, "unknown-node")(m)]


def test_a_close_right_after_the_open_waits_its_turn(session: Session) -> None:
    """The close of a document still being prepared is handled once it is ready: its
    diagnostics are cleared, it is never analysed, and opening it again works."""
    s = session
    big = big_document("Frobnicate")
    close = {"textDocument": {"uri": BIG_URI}}
    s.raw.write(
        frame(msg("textDocument/didOpen", open_params(BIG_URI, big)))
        + frame(msg("textDocument/didClose", close))
        + hover(SMALL_URI, 12)
    )
    s.until(answer(12))
    early = s.until(published(BIG_URI, 1))  # the names, found while it was prepared
    cleared = s.until(lambda m: published(BIG_URI)(m) and "version" not in m["params"])
    assert early < cleared and s.log[cleared]["params"]["diagnostics"] == []
    s.raw.write(hover(SMALL_URI, 13))
    s.until(answer(13))
    assert not [m for m in s.log if published(BIG_URI, code="unknown-node")(m)]
    s.raw.write(frame(msg("textDocument/didOpen", open_params(BIG_URI, big, version=3))))
    s.until(published(BIG_URI, 3, "unknown-node"))


def test_a_held_request_that_is_cancelled_is_answered_at_once(session: Session) -> None:
    """A request on a document still being prepared that the client cancels gets
    RequestCancelled before the document is ready (before its first publication), the
    other held requests their answers after it, in their order."""
    s = session
    big = big_document("Frobnicate")
    cancel = frame(msg("$/cancelRequest", {"id": 15}))
    s.raw.write(
        frame(msg("textDocument/didOpen", open_params(BIG_URI, big)))
        + hover(BIG_URI, 14, line=3)
        + symbols(BIG_URI, 15)
        + hover(BIG_URI, 16, line=3)
        + cancel
        + frame(msg("$/cancelRequest", {"id": 999}))  # nothing of that id: ignored
        + hover(SMALL_URI, 17)
    )
    cancelled = s.until(answer(15))
    assert s.log[cancelled]["error"]["code"] == -32800
    assert cancelled < s.until(published(BIG_URI))
    assert cancelled < s.until(answer(14)) < s.until(answer(16))
    assert "result" in s.log[s.until(answer(14))] and "result" in s.log[s.until(answer(16))]
    assert [m for m in s.log if answer(15)(m)] == [s.log[cancelled]]  # one answer only
    s.until(published(BIG_URI, 1, "unknown-node"))
    s.raw.write(hover(SMALL_URI, 18))
    s.until(answer(18))
    assert [m for m in s.log if answer(15)(m)] == [s.log[cancelled]]


def test_a_large_document_that_is_not_bt_is_told_apart_on_the_worker(session: Session) -> None:
    """Whether a large text is BT XML (a search of its head) is found while it is
    prepared: a launch file gets no diagnostics, and an edit that makes it BT XML gets
    them."""
    s = session
    uri = "untitled:launch.xml"
    body = "".join(f'  <node pkg="p{i}" exec="e" name="n{i}"/>\n' for i in range(8_000))
    text = "<launch>\n" + body + "</launch>\n"
    assert len(text) > 256 * 1024
    s.raw.write(
        frame(msg("textDocument/didOpen", open_params(uri, text)))
        + hover(uri, 19, line=1, character=5)
        + hover(SMALL_URI, 20)
    )
    assert s.log[s.until(answer(19))].get("result") is None  # not BT: nothing to say
    s.until(answer(20))
    assert all(m["params"]["diagnostics"] == [] for m in s.log if published(uri)(m))
    end = {"line": 1, "character": 0}
    change = {
        "textDocument": {"uri": uri, "version": 2},
        "contentChanges": [
            {"range": {"start": end, "end": end}, "text": '<root BTCPP_format="4">\n'}
        ],
    }
    s.raw.write(frame(msg("textDocument/didChange", change)))
    assert s.log[s.until(published(uri, 2))]["params"]["diagnostics"] != []


def test_what_is_analysed_on_the_worker() -> None:
    """Large BT documents, and C++ documents from 32 KiB (tree-sitter's parse)."""
    background = Background(cast("BtServer", None))

    def od(text: str, language: str, path: str | None = None) -> OpenDocument:
        found = OpenDocument("file:///x", Document(text), 1, language, Path(path) if path else None)
        found.refresh_kind()
        return found

    cpp = "// x\n" * (CPP_WORKER_CHARS // 5 + 1)
    assert background.wants(od(cpp, "cpp")) and background.wants(od(cpp, "plaintext", "/a.hpp"))
    assert not background.wants(od(cpp[: CPP_WORKER_CHARS - 10], "cpp"))
    assert not background.wants(od(cpp, "plaintext"))  # neither BT nor C++
    bt = '<root BTCPP_format="4">' + " " * WORKER_CHARS + "</root>"
    assert background.wants(od(bt, "xml")) and not background.wants(od(bt[:-2000], "xml"))


def test_the_worker_prepares_what_the_first_requests_read() -> None:
    """A large document's declarations are made on the worker thread with its tokens and
    model, and its name index too when a request is waiting for it, so that the first
    hover or definition does not make it on the event loop."""
    doc = Document(big_document("Frobnicate", AT_WORKER), "big.xml", scanned=False)
    _prepare(doc, True)
    assert doc._model is not None and doc._model._by_symbol is None  # nobody asked
    cached = doc.history.memo.get("facts")
    assert cached is not None and cached[0] is doc._model
    asked = Document(big_document("Frobnicate", AT_WORKER), "big.xml", scanned=False)
    _prepare(asked, True, [hover(BIG_URI, 7)])
    assert asked._model is not None and asked._model._by_symbol is not None
    other = Document("int main() {}\n" * 20_000, "big.cpp", scanned=False)
    _prepare(other, False)  # not BT: the line index only
    assert not other.scanned and other.history.memo.get("facts") is None


def test_an_outline_asked_with_the_open_is_made_on_the_worker() -> None:
    """With a documentSymbol request held for it, the worker makes the outline once the
    model is ready (its sections keep their JSON, which the request reads on the loop,
    not sharing the interpreter with the analysis); without, it makes none."""
    server = cast("BtServer", SimpleNamespace(encoding="utf-16"))
    background = Background(server)
    outline = SimpleNamespace(method="textDocument/documentSymbol", id=1)
    hover_ = SimpleNamespace(method="textDocument/hover", id=2)
    for waiting, made, index in (
        ([outline, hover_], True, True),
        ([outline], True, False),  # the name index is left for later
        ([hover_], False, True),
    ):
        doc = Document(big_document("Frobnicate", AT_WORKER), BIG_URI, scanned=False)
        od = OpenDocument(BIG_URI, doc, 1, "xml")
        od.refresh_kind()
        background._prepare_for(_Held(od, list(waiting)))
        sections = doc.model.sections
        assert len(sections) == 1
        assert ("outline-json" in sections[0].cache) is made
        assert (doc.model._by_symbol is not None) is index  # for the hover
        if made:
            text = sections[0].cache["outline-json"].text
            assert text.startswith('{"name": "Main", "detail": "BehaviorTree"')
        assert od.folding is None  # no folding request waited


def test_folding_ranges_asked_with_the_open_are_made_on_the_worker() -> None:
    """Held with the open, folding ranges are made by the worker as JSON, kept for the
    document's version, which the request then answers with."""
    background = Background(cast("BtServer", SimpleNamespace(encoding="utf-16")))
    doc = Document(big_document("Frobnicate", AT_WORKER), BIG_URI, scanned=False)
    od = OpenDocument(BIG_URI, doc, 1, "xml")
    od.refresh_kind()
    background._prepare_for(_Held(od, [SimpleNamespace(method="textDocument/foldingRange")]))
    assert od.folding is not None and od.folding[0] == 1
    folds = json.loads(od.folding[1])
    lines = doc.text.count("\n")
    assert folds[:2] == [
        {"startLine": 0, "endLine": lines - 2, "kind": "region"},  # <root>
        {"startLine": 1, "endLine": lines - 3, "kind": "region"},  # <BehaviorTree>
    ]
    assert doc.model._by_symbol is None  # only the folding ranges waited


def test_a_snapshot_continues_the_caches_of_its_document(monkeypatch: pytest.MonkeyPatch) -> None:
    """The analysis of a snapshot after an edit costs what the edit changed: it finds the
    caches the document's earlier versions left (one tree's declarations read again, not
    every tree's), and its diagnostics are those of a fresh document."""
    from bt_lsp.rules.analysis import analyze

    trees = "".join(
        f'<BehaviorTree ID="T{i}"><Sequence><Frobnicate/><SubTree ID="T{i + 1}"/></Sequence>'
        "</BehaviorTree>\n"
        for i in range(200)
    )
    text = f'<root BTCPP_format="4">\n{trees}<BehaviorTree ID="T200"/>\n</root>\n'
    doc = Document(text, "big.xml")
    first = doc.snapshot()
    analyze(first)
    doc.adopt(first)  # as the server does with a current result
    read: list[int] = []
    extract_all = facts._extract_all

    def counting(sections: Any, *args: Any) -> Any:
        read.append(len(sections))
        return extract_all(sections, *args)

    monkeypatch.setattr(facts, "_extract_all", counting)
    at = text.index("<Frobnicate") + 1
    doc.edit(at, at, "X")
    snap = doc.snapshot()
    got = analyze(snap)
    assert read == [1] and len(doc.model.sections) > 100
    assert got == analyze(Document(snap.text, "big.xml"))


def _within_lines(text: str, outline: list[dict[str, Any]]) -> list[str]:
    """The ranges of ``outline`` that are not inside the lines of ``text`` (UTF-16; the
    raw client offers no encoding)."""
    lengths = [len(line.encode("utf-16-le")) // 2 for line in text.split("\n")]
    bad: list[str] = []
    stack = list(outline)
    while stack:
        s = stack.pop()
        for key in ("range", "selectionRange"):
            for end in ("start", "end"):
                p = s[key][end]
                if p["line"] >= len(lengths) or p["character"] > lengths[p["line"]]:
                    bad.append(f"{s['name']} {key} {end} {p}")
        stack.extend(s.get("children", []))
    return bad


ADDED = '  <BehaviorTree ID="Added"><AlwaysSuccess/></BehaviorTree>\n'


@pytest.mark.parametrize("ready", [False, True], ids=["with the open", "once analysed"])
def test_an_outline_is_of_the_version_it_was_asked_of(session: Session, ready: bool) -> None:
    """An outline asked right before an edit is the outline of the text before it: it was
    made from a snapshot taken when the handler first ran, after the edit had been
    handled, and listed the edit's tree (with ranges past the lines of the text asked)."""
    s = session
    big = big_document("Frobnicate")
    at = {"line": big.count("\n") - 1, "character": 0}  # before </root>
    change = {
        "textDocument": {"uri": BIG_URI, "version": 2},
        "contentChanges": [{"range": {"start": at, "end": at}, "text": ADDED}],
    }
    opened = frame(msg("textDocument/didOpen", open_params(BIG_URI, big)))
    if ready:
        s.raw.write(opened)
        s.until(published(BIG_URI, 1, "unknown-node"))
        opened = b""
    s.raw.write(opened + symbols(BIG_URI, 31) + frame(msg("textDocument/didChange", change)))
    outline = s.log[s.until(answer(31))]["result"]
    assert [tree["name"] for tree in outline] == ["Main"]
    assert _within_lines(big, outline) == []
    s.raw.write(symbols(BIG_URI, 32))  # and the next one is of the edit
    assert [tree["name"] for tree in s.log[s.until(answer(32))]["result"]] == ["Main", "Added"]
