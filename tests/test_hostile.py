"""Hostile XML: entities are never expanded, nothing is read or fetched, odd shapes end.

File and network access is observed with a Python audit hook in a child process (the
checker and the server), and a local listener that must see no connection.
"""

from __future__ import annotations

import json
import socket
import subprocess
import sys
import textwrap
import threading
import time
from collections.abc import Iterator
from pathlib import Path

import pytest

from bt_lsp.rules.analysis import analyze
from bt_lsp.syntax.document import Document

BILLION_LAUGHS = (
    '<?xml version="1.0"?>\n<!DOCTYPE lolz [\n <!ENTITY lol "lol">\n'
    + "".join(
        f' <!ENTITY lol{i} "{("&lol" + str(i - 1) + ";") * 10 if i > 1 else "&lol;" * 10}">\n'
        for i in range(1, 10)
    )
    + ']>\n<root BTCPP_format="4"><BehaviorTree ID="T"><AlwaysSuccess name="&lol9;"/>'
    "</BehaviorTree></root>\n"
)


def external(secret: Path, port: int) -> str:
    return (
        f'<?xml version="1.0"?>\n<!DOCTYPE root [\n'
        f'  <!ENTITY file SYSTEM "file://{secret}">\n'
        f'  <!ENTITY web SYSTEM "http://127.0.0.1:{port}/x">\n'
        f'  <!ENTITY % dtd SYSTEM "http://127.0.0.1:{port}/evil.dtd"> %dtd;\n'
        f"]>\n"
        '<root BTCPP_format="4"><BehaviorTree ID="T">'
        '<AlwaysSuccess name="&file;&web;"/></BehaviorTree></root>\n'
    )


def test_entity_bomb_is_not_expanded() -> None:
    start = time.perf_counter()
    doc = Document(BILLION_LAUGHS)
    diags = analyze(doc)
    assert time.perf_counter() - start < 30  # generous: it is linear, not exponential
    codes = [d.code for d in diags]
    assert "xml-doctype" in codes
    doctype = next(d for d in diags if d.code == "xml-doctype")
    assert doc.text[doctype.start : doctype.end] == "<!DOCTYPE"
    names = [r.text for r in doc.model.refs if r.role == "instance name"]
    assert names == ["&lol9;"]  # kept as written, never expanded
    assert "undefined entity" in " ".join(d.message for d in diags).lower()


class Listener:
    """A local TCP listener that records whether anything connected."""

    def __init__(self) -> None:
        self.sock = socket.socket()
        self.sock.bind(("127.0.0.1", 0))
        self.sock.listen(5)
        self.sock.settimeout(0.2)
        self.port = self.sock.getsockname()[1]
        self.connections = 0
        self.stop = False
        self.thread = threading.Thread(target=self.run, daemon=True)
        self.thread.start()

    def run(self) -> None:
        while not self.stop:
            try:
                conn, _ = self.sock.accept()
            except OSError:
                continue
            self.connections += 1
            conn.close()

    def close(self) -> None:
        self.stop = True
        self.thread.join(2)
        self.sock.close()


AUDIT = textwrap.dedent(
    """
    import os, sys
    SECRET = os.environ["BT_SECRET"]
    def hook(event, args):
        if event == "open" and args and isinstance(args[0], (str, bytes)) and (
            os.fsdecode(args[0]).endswith(os.path.basename(SECRET))
        ):
            os.write(2, b"AUDIT open " + os.fsencode(args[0]) + b"\\n")
        elif event in ("socket.connect", "socket.getaddrinfo"):
            os.write(2, ("AUDIT " + event + " " + repr(args) + "\\n").encode())
    sys.addaudithook(hook)
    """
)


@pytest.fixture
def hostile(tmp_path: Path) -> Iterator[tuple[Path, Path, Listener]]:
    secret = tmp_path / "secret-do-not-read.txt"
    secret.write_text("TOP SECRET", encoding="utf-8")
    listener = Listener()
    doc = tmp_path / "ws" / "hostile.xml"
    doc.parent.mkdir()
    doc.write_text(external(secret, listener.port), encoding="utf-8")
    yield secret, doc, listener
    listener.close()


def test_checker_reads_no_entity_file_and_connects_nowhere(
    hostile: tuple[Path, Path, Listener],
) -> None:
    secret, doc, listener = hostile
    code = AUDIT + "from bt_lsp.cli.main import main\nsys.exit(main(sys.argv[1:]))\n"
    for args in (
        ["check", str(doc.parent)],
        ["check", "--fix", str(doc)],
        ["check", "--format", "sarif", str(doc)],
    ):
        proc = subprocess.run(
            [sys.executable, "-c", code, *args],
            capture_output=True,
            text=True,
            timeout=120,
            env={"BT_SECRET": str(secret), "PATH": "/usr/bin:/bin"},
        )
        assert proc.returncode in (0, 1), proc.stderr
        assert "AUDIT" not in proc.stderr, proc.stderr
        assert "TOP SECRET" not in proc.stdout
    assert "xml-doctype" in proc.stdout
    assert listener.connections == 0


def _message(obj: dict[str, object]) -> bytes:
    body = json.dumps(obj).encode()
    return b"Content-Length: %d\r\n\r\n" % len(body) + body


def test_server_reads_no_entity_file_and_connects_nowhere(
    hostile: tuple[Path, Path, Listener],
) -> None:
    secret, doc, listener = hostile
    code = AUDIT + "from bt_lsp.server import serve\nserve()\n"
    uri = doc.as_uri()
    text = doc.read_text(encoding="utf-8")
    messages: list[dict[str, object]] = [
        {
            "jsonrpc": "2.0",
            "id": 1,
            "method": "initialize",
            "params": {
                "capabilities": {},
                "processId": None,
                "rootUri": doc.parent.as_uri(),
                "initializationOptions": {"debounceMs": 0},
            },
        },
        {"jsonrpc": "2.0", "method": "initialized", "params": {}},
        {
            "jsonrpc": "2.0",
            "method": "textDocument/didOpen",
            "params": {
                "textDocument": {"uri": uri, "languageId": "xml", "version": 1, "text": text}
            },
        },
        {
            "jsonrpc": "2.0",
            "id": 2,
            "method": "textDocument/hover",
            "params": {"textDocument": {"uri": uri}, "position": {"line": 6, "character": 50}},
        },
        {
            "jsonrpc": "2.0",
            "id": 3,
            "method": "textDocument/codeAction",
            "params": {
                "textDocument": {"uri": uri},
                "range": {"start": {"line": 0, "character": 0}, "end": {"line": 8, "character": 0}},
                "context": {"diagnostics": []},
            },
        },
        {"jsonrpc": "2.0", "id": 4, "method": "shutdown"},
        {"jsonrpc": "2.0", "method": "exit"},
    ]
    proc = subprocess.run(
        [sys.executable, "-c", code],
        input=b"".join(_message(m) for m in messages),
        capture_output=True,
        timeout=120,
        env={"BT_SECRET": str(secret), "PATH": "/usr/bin:/bin"},
    )
    out, err = proc.stdout.decode(), proc.stderr.decode()
    assert proc.returncode == 0, err
    assert "AUDIT" not in err, err
    assert "xml-doctype" in out and '"id": 4' in out
    assert "TOP SECRET" not in out
    assert listener.connections == 0


@pytest.mark.parametrize(
    "text",
    [
        "<A " + " ".join(f'a{i}="{i}"' for i in range(20_000)) + "/>",
        "<root>" + "<A>" * 20_000,
        "<" * 50_000,
        "<A b='" + "&" * 50_000 + "'/>",
        '<A b="' + "\"'" * 20_000,
        "\x00\x01\x02<\x00 a\x07='\x08'/>" * 2_000,
        "<root><BehaviorTree ID='T'>" + "<A b='1'/>" * 20_000 + "</BehaviorTree></root>",
    ],
    ids=["attrs", "deep-unclosed", "stray-lt", "raw-amp", "quotes", "controls", "long-line"],
)
def test_odd_shapes_end_with_bounded_output(text: str) -> None:
    diags = analyze(Document(text))
    assert len(diags) <= 2001
    if len(diags) == 2001:
        assert diags[-1].code == "too-many-problems"
