"""Hostile documents through a raw stdio client: each gets its diagnostics (at least one
saying what is wrong), a request on it is answered, and the server serves on.

The inputs are those of the issue's hostile-input campaign, at sizes that keep the test
quick: very long lines, deep nesting (closed and not), huge attribute values, many
elements, many and duplicate attributes, NUL and control characters, invalid UTF-8 (raw
bytes in the JSON), byte order marks, lone surrogates (JSON escapes), stray '<' and '&',
unterminated markup, an entity bomb, non-BMP names, lone CR line ends, and a document
above ``maxDocumentBytes``.
"""

from __future__ import annotations

import json
from collections.abc import Iterator

import pytest

from tests.server.test_background import Session, answer, published
from tests.server.test_framing import frame, msg

LIMIT = 512 * 1024  # maxDocumentBytes of the session
ROOT = '<root BTCPP_format="4">\n'
TREE = ROOT + '<BehaviorTree ID="T">\n'
END = "</BehaviorTree>\n</root>\n"
BOMB = (
    '<?xml version="1.0"?>\n<!DOCTYPE lolz [\n <!ENTITY lol "lol">\n'
    + "".join(
        f' <!ENTITY lol{i} "{("&lol" + str(i - 1) + ";") * 10 if i > 1 else "&lol;" * 10}">\n'
        for i in range(1, 10)
    )
    + "]>\n"
    + TREE
    + '<AlwaysSuccess name="&lol9;"/>'
    + END
)
# Raw bytes stand in for these markers in the JSON body (invalid UTF-8).
INVALID_UTF8 = {"\ue000": b"\xff", "\ue001": b"\xc3", "\ue002": b"\xed\xa0\x80"}

CASES: dict[str, str] = {
    "long-line": TREE.replace("\n", "") + '<AlwaysSuccess name="n"/>' * 40_000 + "<Frob/>" + END,
    "deep-nesting": TREE + "<Sequence>" * 3_000 + "<Frob/>" + "</Sequence>" * 3_000 + END,
    "deep-unclosed": TREE + "<Sequence>" * 20_000,
    "huge-value": TREE + '<Frob text="' + "x" * 1_000_000 + '"/>' + END,
    "huge-script": TREE + '<Script code="' + "a:=1;" * 20_000 + '"/><Frob/>' + END,
    "many-elements": TREE + "<Sequence>\n" + "<AlwaysSuccess/>\n" * 100_000 + "<Frob/>" + END,
    "many-attributes": TREE + "<Frob" + "".join(f' a{i}="1"' for i in range(200_000)) + "/>" + END,
    "duplicate-attributes": TREE + "<Frob" + ' a="1"' * 500_000 + "/>" + END,
    "nul-bytes": TREE + '<Frob\x00 a\x00b="\x00"/>\x00' * 20_000 + END,
    "control-chars": TREE + '<AlwaysSuccess name="\x01\x02\x07"/>\x0b\x0c' * 20_000 + END,
    "invalid-utf8": TREE + '<Fr\ue000ob a="\ue001\ue002"/>' * 20_000 + END,
    "bom-first": "\ufeff" + TREE + "<Frob/>" + END,
    "bom-inside": TREE + "<Frob/>\ufeff<AlwaysSuccess name='\ufeff'/>" * 10_000 + END,
    "lone-surrogates": TREE + '<Fr\ud800ob a\udfff="\ud800x"/>' * 20_000 + END,
    "stray-lt": ROOT + "<" * 200_000,
    "raw-amp": TREE + '<Frob a="' + "&" * 200_000 + '"/>' + END,
    "unterminated-comment": TREE + "<!--" + "x" * 500_000,
    "unterminated-cdata": TREE + "<![CDATA[" + "x" * 500_000,
    "unterminated-value": ROOT + '<BehaviorTree ID="' + "x y" * 200_000,
    "entity-bomb": BOMB,
    "non-bmp": TREE + "<😋 😋='😋'/>" * 50_000 + END,
    "lone-cr": TREE.replace("\n", "\r") + "<Frob/>\r" * 100_000 + END.replace("\n", "\r"),
    "at-the-limit": TREE + "<Frob/>\n" * ((LIMIT - len(TREE) - len(END)) // 8) + END,
    "above-the-limit": TREE + "<Frob/>" * (LIMIT // 7 + 1000) + END,
}


def open_body(uri: str, text: str) -> bytes:
    item = {"uri": uri, "languageId": "xml", "version": 1, "text": text}
    body = json.dumps(msg("textDocument/didOpen", {"textDocument": item})).encode()
    for marker, raw in INVALID_UTF8.items():
        body = body.replace(json.dumps(marker)[1:-1].encode(), raw)
    return b"Content-Length: %d\r\n\r\n" % len(body) + body


@pytest.fixture(scope="module")
def session() -> Iterator[Session]:
    s = Session(limit=LIMIT)
    try:
        yield s
    finally:
        s.raw.close()


@pytest.mark.parametrize("name", list(CASES))
def test_a_hostile_document_is_answered(session: Session, name: str) -> None:
    s = session
    uri = f"untitled:hostile-{name}.xml"
    text = CASES[name]
    msg_id = 1000 + list(CASES).index(name)
    position = {"line": 1, "character": 3}
    s.raw.write(
        open_body(uri, text)
        + frame(
            msg("textDocument/hover", {"textDocument": {"uri": uri}, "position": position}, msg_id)
        )
        + frame(msg("textDocument/documentSymbol", {"textDocument": {"uri": uri}}, msg_id + 100))
    )
    assert "result" in s.log[s.until(answer(msg_id))]
    assert "result" in s.log[s.until(answer(msg_id + 100))]
    done = s.until(lambda m: published(uri, 1)(m) and bool(m["params"]["diagnostics"]))
    diagnostics = s.log[done]["params"]["diagnostics"]
    # At most 2000, then too-many-problems (and document-too-large above the limit).
    assert len(diagnostics) <= 2002
    if name == "above-the-limit":
        assert "document-too-large" in {d["code"] for d in diagnostics}
    s.raw.write(frame(msg("textDocument/didClose", {"textDocument": {"uri": uri}})))
    # Serving on: a small document opened now is analysed and hovered.
    small = f"untitled:after-{name}.xml"
    s.raw.write(open_body(small, TREE + "<Frob/>" + END))
    s.until(published(small, 1, "unknown-node"))
    s.raw.write(frame(msg("textDocument/didClose", {"textDocument": {"uri": small}})))
