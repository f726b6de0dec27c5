"""Random edits and requests on real trees, checked against what LSP promises.

Each example opens a tree of ``tests/data/corpus`` (as it is, with CRLF line ends, or
with astral characters in it), then sends incremental changes at random positions (mid
line, inside names and values, never inside a character of the position encoding nor
between a CR and its LF) and, after each, random requests at random positions, without
waiting for their answers.  It checks that:

- every request is answered exactly once, and never with an internal error (-32603);
- every range an answer holds (locations, highlights, symbols, folds, edits of a rename,
  a completion or a fix) lies in the document of the version the request was sent at,
  and edits that say a version say that one;
- the diagnostics published after the last change are those of a fresh open of the same
  text (incremental analysis equals a full one).

A fixed seed and a fixed budget in CI; ``BT_LSP_FUZZ_EXAMPLES`` sets the number of
examples per client (and ``BT_LSP_FUZZ_SEED`` the seed) for a longer run.
"""

from __future__ import annotations

import asyncio
import concurrent.futures
import itertools
import json
import os
import random
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pytest

from tests.server.conftest import (
    TIMEOUT,
    BtClient,
    clients,
    lsp_position,
    send_raw,
    units,
)

pytestmark = pytest.mark.asyncio(loop_scope="module")

CORPUS = Path(__file__).parents[1] / "data" / "corpus"
EXAMPLES = int(os.environ.get("BT_LSP_FUZZ_EXAMPLES", "4"))
SEED = int(os.environ.get("BT_LSP_FUZZ_SEED", "20240611"))
STEPS = 12  # changes per example
REQUESTS = 3  # requests after each change
MAX_CHARS = 12_000  # trees of at most this size (the larger ones cost time, not cases)
INTERNAL_ERROR = -32603

# What is typed: tags and their parts, quotes, entities, comments, line ends, astral
# characters (two UTF-16 units, four UTF-8 bytes).
SNIPPETS = [
    "<",
    "</",
    "/>",
    ">",
    '"',
    "'",
    "=",
    " ",
    "<Sequence>",
    "</Sequence>",
    "<AlwaysSuccess/>",
    '<SubTree ID="Main"/>',
    '<BehaviorTree ID="Fuzz">',
    "</BehaviorTree>",
    '<Action ID="Do.It" a.b="{key}"/>',
    '<Script code="x:=1"/>',
    "<!--",
    "-->",
    "<!",
    "<?",
    "&amp;",
    "&#7;",
    "\n",
    "\r\n",
    "\r",
    "\t",
    "😋",
    "é",
    "{bb}",
    "name",
    'ID="',
]


def _corpus() -> list[Path]:
    found = sorted(CORPUS.rglob("*.xml"))
    return [p for p in found if p.stat().st_size <= MAX_CHARS]


def _variant(text: str, rng: random.Random) -> str:
    """The tree as it is, with CRLF line ends, or with astral characters in it."""
    kind = rng.randrange(3)
    if kind == 1:
        return text.replace("\r\n", "\n").replace("\n", "\r\n")
    if kind == 2:
        return text.replace('name="', 'name="😋', 3).replace("<!--", "<!-- 𝄞", 2)
    return text


def _boundary(text: str, offset: int) -> int:
    """``offset`` moved off the middle of a CR LF pair (a position there names the end of
    the line, which is not that offset)."""
    if 0 < offset < len(text) and text[offset - 1] == "\r" and text[offset] == "\n":
        return offset - 1
    return offset


def _change(text: str, rng: random.Random) -> tuple[int, int, str]:
    """A random change: an insertion, a deletion or a replacement, mid-line as often as
    not; offsets are code points, so never inside a character of any encoding."""
    n = len(text)
    start = _boundary(text, rng.randrange(n + 1))
    kind = rng.randrange(3)
    end = start
    if kind and n:
        end = _boundary(text, min(n, start + rng.randrange(1, 40)))
        end = max(end, start)
    new = "" if kind == 1 else "".join(rng.choice(SNIPPETS) for _ in range(rng.randrange(1, 4)))
    return start, end, new


@dataclass
class Sent:
    """A request sent: what it was, at which version of which text."""

    method: str
    params: dict[str, Any]
    version: int
    text: str
    future: concurrent.futures.Future[Any]


_ids = itertools.count(1)


def _request(
    client: BtClient, method: str, params: dict[str, Any]
) -> concurrent.futures.Future[Any]:
    msg_id = f"fuzz-{next(_ids)}"
    future: concurrent.futures.Future[Any] = concurrent.futures.Future()
    client.protocol._request_futures[msg_id] = future
    send_raw(client, {"jsonrpc": "2.0", "id": msg_id, "method": method, "params": params})
    return future


def _pos(text: str, offset: int, enc: str) -> dict[str, int]:
    p = lsp_position(text, offset, enc)
    return {"line": p.line, "character": p.character}


def _random_request(
    uri: str, text: str, enc: str, rng: random.Random
) -> tuple[str, dict[str, Any]]:
    doc = {"uri": uri}
    at = _pos(text, _boundary(text, rng.randrange(len(text) + 1)), enc)
    method = rng.choice(
        [
            "textDocument/hover",
            "textDocument/definition",
            "textDocument/references",
            "textDocument/documentSymbol",
            "textDocument/codeAction",
            "textDocument/completion",
            "textDocument/rename",
            "textDocument/prepareRename",
            "textDocument/foldingRange",
            "textDocument/documentHighlight",
        ]
    )
    params: dict[str, Any] = {"textDocument": doc}
    if method in ("textDocument/documentSymbol", "textDocument/foldingRange"):
        return method, params
    if method == "textDocument/codeAction":
        a = _boundary(text, rng.randrange(len(text) + 1))
        b = _boundary(text, min(len(text), a + rng.randrange(60)))
        params["range"] = {"start": _pos(text, a, enc), "end": _pos(text, max(a, b), enc)}
        params["context"] = {"diagnostics": []}
        return method, params
    params["position"] = at
    if method == "textDocument/references":
        params["context"] = {"includeDeclaration": rng.random() < 0.5}
    if method == "textDocument/rename":
        params["newName"] = rng.choice(["Renamed", "x", "key2", "New_Tree"])
    return method, params


def _plain(value: Any) -> Any:
    """A result as JSON values (pygls reads an untyped result into named tuples)."""
    if hasattr(value, "_asdict"):
        return {k: _plain(v) for k, v in value._asdict().items()}
    if isinstance(value, list | tuple):
        return [_plain(v) for v in value]
    return value


_RANGE_KEYS = frozenset(
    {"range", "selectionRange", "targetRange", "targetSelectionRange", "insert", "replace"}
)


def _ranges(value: Any, uri: str, path: str = "$") -> Iterator[tuple[str, dict[str, Any]]]:
    """Every range of ``uri``'s document in an answer: ``range``, ``selectionRange``,
    ``targetRange``…, the edits of a WorkspaceEdit for ``uri``, the folding ranges' lines
    (as a range of whole lines); a location of another document is left out."""
    if isinstance(value, list):
        for k, v in enumerate(value):
            yield from _ranges(v, uri, f"{path}[{k}]")
        return
    if not isinstance(value, dict):
        return
    if "uri" in value and value["uri"] != uri and "range" in value:
        return  # a location in another file (the built-in catalog, say)
    if "startLine" in value and "endLine" in value:
        start = {"line": value["startLine"], "character": 0}
        yield path, {"start": start, "end": {"line": value["endLine"], "character": 0}}
    for key, v in value.items():
        if key == "changes" and isinstance(v, dict):
            for doc_uri, edits in v.items():
                if doc_uri == uri:
                    yield from _ranges(edits, uri, f"{path}.changes")
            continue
        if key == "documentChanges" and isinstance(v, list):
            for k, dc in enumerate(v):
                if dc.get("textDocument", {}).get("uri") == uri:
                    yield from _ranges(dc.get("edits", []), uri, f"{path}.documentChanges[{k}]")
            continue
        if key in _RANGE_KEYS and isinstance(v, dict) and "start" in v:
            yield f"{path}.{key}", v
            continue
        yield from _ranges(v, uri, f"{path}.{key}")


def _versions(value: Any, uri: str) -> Iterator[int | None]:
    """The versions an answer's edits of ``uri`` say they apply to."""
    if isinstance(value, list):
        for v in value:
            yield from _versions(v, uri)
    elif isinstance(value, dict):
        doc = value.get("textDocument")
        if isinstance(doc, dict) and doc.get("uri") == uri and "edits" in value:
            yield doc.get("version")
        data = value.get("data")
        if isinstance(data, dict) and data.get("uri") == uri and "version" in data:
            yield data["version"]
        for v in value.values():
            yield from _versions(v, uri)


def _out_of(text: str, enc: str, rng: dict[str, Any]) -> str | None:
    """Why ``rng`` is not a range of ``text`` (``None`` if it is)."""
    lines = text.replace("\r\n", "\n").replace("\r", "\n").split("\n")
    ends = []
    for end in ("start", "end"):
        p = rng[end]
        line, ch = p["line"], p["character"]
        if not 0 <= line < len(lines):
            return f"{end} line {line} of {len(lines)} lines"
        width = units(lines[line], enc)
        if not 0 <= ch <= width:
            return f"{end} character {ch} past line {line} ({width} units)"
        if enc == "utf-16":
            head = lines[line].encode("utf-16-le", "surrogatepass")[: 2 * ch]
            if head and 0xD800 <= int.from_bytes(head[-2:], "little") < 0xDC00:
                return f"{end} inside a surrogate pair"
        ends.append((line, ch))
    if ends[0] > ends[1]:
        return "start after end"
    return None


def _check(sent: Sent, uri: str, enc: str, answer: Any) -> list[str]:
    where = f"{sent.method} at version {sent.version} {json.dumps(sent.params)[:200]}"
    code = getattr(answer, "code", None)
    if isinstance(answer, BaseException):
        if code == INTERNAL_ERROR or code is None:
            return [f"{where}: {answer!r}"]
        return []  # a deliberate refusal (RequestFailed: renaming a built-in, say)
    problems = []
    for path, rng in _ranges(answer, uri):
        why = _out_of(sent.text, enc, rng)
        if why is not None:
            problems.append(f"{where}: {path} {rng}: {why}")
    for version in _versions(answer, uri):
        if version is not None and version != sent.version:
            problems.append(f"{where}: an edit of version {version}")
    return problems


def _summary(diags: Any) -> list[tuple[Any, ...]]:
    return sorted(
        (
            str(d.code),
            d.range.start.line,
            d.range.start.character,
            d.range.end.line,
            d.range.end.character,
            d.message,
            int(d.severity or 0),
        )
        for d in diags
    )


async def _example(client: BtClient, source: Path, rng: random.Random) -> list[str]:
    enc = client.encoding
    text = _variant(source.read_text(encoding="utf-8"), rng)
    uri = client.open(text, untitled=True, name="fuzz")
    sent: list[Sent] = []
    version = 1
    for _ in range(STEPS):
        start, end, new = _change(text, rng)
        version += 1
        change = {
            "range": {"start": _pos(text, start, enc), "end": _pos(text, end, enc)},
            "text": new,
        }
        send_raw(
            client,
            {
                "jsonrpc": "2.0",
                "method": "textDocument/didChange",
                "params": {
                    "textDocument": {"uri": uri, "version": version},
                    "contentChanges": [change],
                },
            },
        )
        text = text[:start] + new + text[end:]
        for _ in range(REQUESTS):
            method, params = _random_request(uri, text, enc, rng)
            sent.append(Sent(method, params, version, text, _request(client, method, params)))
    problems: list[str] = []
    done = await asyncio.gather(
        *(asyncio.wait_for(asyncio.wrap_future(s.future), TIMEOUT) for s in sent),
        return_exceptions=True,
    )
    for s, answer in zip(sent, done, strict=True):
        if isinstance(answer, TimeoutError):
            problems.append(f"{s.method} at version {s.version}: no answer within {TIMEOUT}s")
            continue
        problems.extend(_check(s, uri, enc, _plain(answer)))
    # The diagnostics after the last change are those of the same text opened afresh.
    incremental = _summary(await client.pushed(uri, version))
    fresh_uri = client.open(text, untitled=True, name="fresh")
    fresh = _summary(await client.pushed(fresh_uri, 1))
    if incremental != fresh:
        only_inc = [d for d in incremental if d not in fresh]
        only_fresh = [d for d in fresh if d not in incremental]
        problems.append(
            f"diagnostics after the edits differ from a fresh open: only incremental "
            f"{only_inc[:3]}, only fresh {only_fresh[:3]}; text {text[:300]!r}"
        )
    client.close(uri)
    client.close(fresh_uri)
    return [f"{source.name}: {p}" for p in problems]


@clients("vscode", "vscode-utf8")  # utf-16 and utf-8 positions
async def test_random_edits_and_requests(client: BtClient) -> None:
    answers: dict[Any, int] = {}
    handle = client.protocol._handle_response

    def counted(msg_id: Any, result: Any = None, error: Any = None) -> None:
        answers[msg_id] = answers.get(msg_id, 0) + 1
        handle(msg_id, result, error)

    client.protocol._handle_response = counted  # type: ignore[method-assign]
    try:
        rng = random.Random(f"{SEED}-{client.encoding}")
        files = _corpus()
        assert files, "no corpus trees"
        problems: list[str] = []
        for _ in range(EXAMPLES):
            problems += await _example(client, rng.choice(files), rng)
        await client.barrier()
    finally:
        client.protocol._handle_response = handle  # type: ignore[method-assign]
    twice = {k: n for k, n in answers.items() if str(k).startswith("fuzz-") and n != 1}
    assert twice == {}, f"answered more than once: {twice}"
    assert problems == [], "\n".join(problems[:15])
