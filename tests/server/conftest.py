"""End-to-end fixtures: the real server in a subprocess, driven by pytest-lsp clients.

Every test talks to ``bt-lsp serve`` through a :class:`BtClient` initialized with one of
pytest-lsp's bundled capability sets (VS Code, Neovim 0.7 and 0.11, Emacs), optionally
with its ``general.positionEncodings`` replaced.  Servers are module-scoped: one per
profile per test module.  Tests open documents under fresh URIs, and what a test opens is
closed after it (open documents form one workspace), so tests do not see each other.

Positions are computed here from code-point offsets by encoding the prefix of each line,
independently of the server's :class:`bt_lsp.syntax.text.LineIndex`, so the tests do not trust
the code under test.
"""

from __future__ import annotations

import asyncio
import concurrent.futures
import contextlib
import itertools
import json
import re
import sys
from collections.abc import AsyncIterator, Awaitable, Callable, Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, TypeVar

import pytest
import pytest_lsp
from lsprotocol import types
from pygls.protocol import default_converter
from pygls.uris import from_fs_path
from pytest_lsp import ClientServerConfig, LanguageClient
from pytest_lsp.client import DEFAULT_CLIENT_FEATURES, register_lsp_features

from bt_lsp.rules.registry import CODES
from tests.marks import unmark

# The server under test, as users start it.
SERVER_COMMAND = [sys.executable, "-m", "bt_lsp", "serve"]

TIMEOUT = 10.0  # seconds to wait for anything the server should do right away

T = TypeVar("T")

# -- client profiles ------------------------------------------------------------------------


@dataclass(frozen=True)
class Profile:
    """A client: a pytest-lsp capability set, optionally with other position encodings."""

    spec: str
    encodings: tuple[str, ...] | None = None  # replaces general.positionEncodings
    init_options: Any = field(default_factory=lambda: {"debounceMs": 0})
    configuration: Any = None  # the btLsp section answered to workspace/configuration

    def capabilities(self) -> types.ClientCapabilities:
        caps = pytest_lsp.client_capabilities(self.spec)
        if self.encodings is not None:
            if caps.general is None:
                caps.general = types.GeneralClientCapabilities()
            caps.general.position_encodings = list(self.encodings)
        return caps

    def expected_encoding(self) -> str:
        """The contract's rule: the first offered of utf-8/16/32, else utf-16."""
        caps = self.capabilities()
        offered = (caps.general.position_encodings if caps.general else None) or []
        for enc in offered:
            if enc in ("utf-8", "utf-16", "utf-32"):
                return str(enc)
        return "utf-16"


PROFILES: dict[str, Profile] = {
    "vscode": Profile("visual-studio-code"),  # push, utf-16, resolve, documentChanges
    "nvim-0.7": Profile("neovim@v0.7.0"),  # push, utf-16, resolve, plain changes
    "nvim-0.11": Profile("neovim@v0.11.0"),  # pull, utf-8, resolve, plain changes
    "emacs": Profile("emacs"),  # push, utf-32, no resolve, documentChanges
    "vscode-utf8": Profile("visual-studio-code", encodings=("utf-8",)),
    "vscode-utf32": Profile("visual-studio-code", encodings=("utf-32",)),
    "nvim-0.11-utf16": Profile("neovim@v0.11.0", encodings=("utf-16",)),
    "unknown-encodings": Profile("visual-studio-code", encodings=("latin-1", "utf-7")),
    "utf32-after-unknown": Profile("emacs", encodings=("ucs-2", "utf-32", "utf-8")),
}

# The four bundled clients: three push, one pulls; utf-16, utf-16, utf-8, utf-32.
CLIENTS = ["vscode", "nvim-0.7", "nvim-0.11", "emacs"]
PUSH_CLIENTS = ["vscode", "nvim-0.7", "emacs"]
PULL_CLIENTS = ["nvim-0.11", "nvim-0.11-utf16"]


def clients(*names: str) -> pytest.MarkDecorator:
    """Run a test once per named profile (one module-scoped server each)."""
    return pytest.mark.parametrize("client", list(names), indirect=True, scope="module")


# -- the client -----------------------------------------------------------------------------


class BtClient(LanguageClient):
    """A pytest-lsp client that records every publishDiagnostics (with its version)."""

    profile: Profile
    profile_name: str
    init_result: types.InitializeResult
    encoding: str

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self.published: dict[str, list[types.PublishDiagnosticsParams]] = {}
        self.configuration_requests = 0
        self.configuration_gate: asyncio.Event | None = None
        self.registrations: list[types.Registration] = []
        self.opened: set[str] = set()
        self._waiters: list[asyncio.Event] = []

    # notifications from the server

    def _notify_waiters(self) -> None:
        waiters, self._waiters = self._waiters, []
        for ev in waiters:
            ev.set()

    async def wait_until(self, check: Callable[[], T | None], what: str) -> T:
        """Wait until ``check()`` returns something other than ``None`` (re-checked on
        every notification or request from the server), at most :data:`TIMEOUT`."""
        loop = asyncio.get_running_loop()
        deadline = loop.time() + TIMEOUT
        while True:
            result = check()
            if result is not None:
                return result
            remaining = deadline - loop.time()
            if remaining <= 0:
                raise AssertionError(f"timed out after {TIMEOUT}s waiting for {what}")
            ev = asyncio.Event()
            self._waiters.append(ev)
            with contextlib.suppress(TimeoutError):
                await asyncio.wait_for(ev.wait(), remaining)

    # session

    async def start_session(self, name: str) -> None:
        self.profile_name = name
        self.profile = PROFILES[name]
        if self.profile.configuration is not None:
            self.set_configuration(self.profile.configuration, section="btLsp")
        self.init_result = await self.initialize_session(
            types.InitializeParams(
                capabilities=self.profile.capabilities(),
                initialization_options=self.profile.init_options,
            )
        )
        self.encoding = str(self.init_result.capabilities.position_encoding or "utf-16")

    async def start_in_workspace(self, folder: Path) -> None:
        """A VS Code session with ``folder`` as its workspace folder and no debounce (the
        project tests: C++, ROS packages)."""
        self.profile_name = "vscode"
        self.profile = PROFILES["vscode"]
        self.init_result = await self.initialize_session(
            types.InitializeParams(
                capabilities=pytest_lsp.client_capabilities("visual-studio-code"),
                initialization_options={"debounceMs": 0},
                workspace_folders=[
                    types.WorkspaceFolder(uri=from_fs_path(str(folder)) or "", name="ws")
                ],
            )
        )
        self.encoding = "utf-16"

    def open_path(self, path: Path, language: str) -> str:
        """Open the file at ``path`` with its text on disk; its URI."""
        uri = from_fs_path(str(path)) or ""
        self.text_document_did_open(
            types.DidOpenTextDocumentParams(
                text_document=types.TextDocumentItem(
                    uri=uri, language_id=language, version=1, text=path.read_text()
                )
            )
        )
        return uri

    async def diagnostics_until(
        self, uri: str, check: Callable[[Sequence[types.Diagnostic]], bool]
    ) -> list[types.Diagnostic]:
        """The first diagnostics published for ``uri`` that pass ``check`` (waits)."""

        def found() -> list[types.Diagnostic] | None:
            last = self.latest(uri)
            if last is not None and check(last.diagnostics):
                return list(last.diagnostics)
            return None

        return await self.wait_until(found, f"diagnostics of {uri}")

    @property
    def pull(self) -> bool:
        td = self.profile.capabilities().text_document
        return td is not None and td.diagnostic is not None

    # documents

    def open(
        self,
        text: str,
        *,
        version: int = 1,
        name: str = "doc",
        language: str = "xml",
        untitled: bool = False,
    ) -> str:
        """Open ``text`` under a new URI: a file URI, or an ``untitled:`` one, which is not
        part of the workspace (so it neither sees nor is seen by other documents)."""
        uri = fresh_uri(name)
        if untitled:
            uri = "untitled:" + uri.rsplit("/", 1)[1]
        self.opened.add(uri)
        self.text_document_did_open(
            types.DidOpenTextDocumentParams(
                text_document=types.TextDocumentItem(
                    uri=uri, language_id=language, version=version, text=text
                )
            )
        )
        return uri

    def change(
        self,
        uri: str,
        version: int,
        *changes: types.TextDocumentContentChangeEvent,
    ) -> None:
        self.text_document_did_change(
            types.DidChangeTextDocumentParams(
                text_document=types.VersionedTextDocumentIdentifier(uri=uri, version=version),
                content_changes=list(changes),
            )
        )

    def replace(self, uri: str, version: int, text: str) -> None:
        self.change(uri, version, types.TextDocumentContentChangeWholeDocument(text=text))

    def close(self, uri: str) -> None:
        self.opened.discard(uri)
        self.text_document_did_close(
            types.DidCloseTextDocumentParams(text_document=types.TextDocumentIdentifier(uri=uri))
        )

    async def barrier(self) -> None:
        """A request round trip: everything the server sent for earlier messages that it
        handles synchronously has arrived when this returns."""
        await self.text_document_hover_async(
            types.HoverParams(
                text_document=types.TextDocumentIdentifier(uri="file:///barrier/none.xml"),
                position=types.Position(0, 0),
            )
        )

    # diagnostics

    def latest(self, uri: str) -> types.PublishDiagnosticsParams | None:
        history = self.published.get(uri)
        return history[-1] if history else None

    async def pushed(self, uri: str, version: int | None) -> list[types.Diagnostic]:
        """The diagnostics pushed for ``uri`` at ``version`` (waits for them)."""

        def check() -> list[types.Diagnostic] | None:
            last = self.latest(uri)
            if last is not None and last.version == version:
                return list(last.diagnostics)
            return None

        return await self.wait_until(
            check,
            f"publishDiagnostics for {uri} version {version} "
            f"(got versions {[p.version for p in self.published.get(uri, [])]})",
        )

    async def pull_report(
        self, uri: str, previous: str | None = None
    ) -> types.DocumentDiagnosticReport:
        return await asyncio.wait_for(
            self.text_document_diagnostic_async(
                types.DocumentDiagnosticParams(
                    text_document=types.TextDocumentIdentifier(uri=uri),
                    previous_result_id=previous,
                )
            ),
            TIMEOUT,
        )

    async def diags(self, uri: str, version: int) -> list[types.Diagnostic]:
        """The document's diagnostics at ``version``, pushed or pulled as the client does."""
        if self.pull:
            report = await self.pull_report(uri)
            assert isinstance(report, types.RelatedFullDocumentDiagnosticReport)
            return list(report.items)
        return await self.pushed(uri, version)

    # requests

    async def code_actions(
        self,
        uri: str,
        rng: types.Range,
        *,
        only: Sequence[str] | None = None,
        diagnostics: Sequence[types.Diagnostic] = (),
    ) -> list[types.CodeAction]:
        result = await asyncio.wait_for(
            self.text_document_code_action_async(
                types.CodeActionParams(
                    text_document=types.TextDocumentIdentifier(uri=uri),
                    range=rng,
                    context=types.CodeActionContext(
                        diagnostics=list(diagnostics), only=list(only) if only else None
                    ),
                )
            ),
            TIMEOUT,
        )
        actions = list(result or [])
        assert all(isinstance(a, types.CodeAction) for a in actions), actions
        return actions  # type: ignore[return-value]

    async def with_edit(self, action: types.CodeAction) -> types.CodeAction:
        """The action with its edit: resolved when the client resolves edits lazily."""
        if action.edit is not None:
            return action
        assert action.data is not None, f"an action with neither edit nor data: {action}"
        resolved = await asyncio.wait_for(self.code_action_resolve_async(action), TIMEOUT)
        assert resolved.edit is not None, f"resolve gave no edit: {resolved}"
        return resolved

    async def hover(self, uri: str, pos: types.Position) -> types.Hover | None:
        return await asyncio.wait_for(
            self.text_document_hover_async(
                types.HoverParams(text_document=types.TextDocumentIdentifier(uri=uri), position=pos)
            ),
            TIMEOUT,
        )

    def range(self, text: str, start: int, end: int) -> types.Range:
        return lsp_range(text, start, end, self.encoding)

    def pos(self, text: str, offset: int) -> types.Position:
        return lsp_position(text, offset, self.encoding)


def _on_publish(client: BtClient, params: types.PublishDiagnosticsParams) -> None:
    client.diagnostics[params.uri] = params.diagnostics
    client.published.setdefault(params.uri, []).append(params)
    client._notify_waiters()


def _on_log(client: BtClient, params: types.LogMessageParams) -> None:
    DEFAULT_CLIENT_FEATURES[types.WINDOW_LOG_MESSAGE](client, params)
    client._notify_waiters()


async def _on_configuration(client: BtClient, params: types.ConfigurationParams) -> list[Any]:
    client.configuration_requests += 1
    result = DEFAULT_CLIENT_FEATURES[types.WORKSPACE_CONFIGURATION](client, params)
    client._notify_waiters()
    if client.configuration_gate is not None:  # a test holds the answer back
        await client.configuration_gate.wait()
    return list(result)


def _on_refresh(client: BtClient, params: None) -> None:
    client.diagnostic_refresh_count += 1
    client._notify_waiters()


def _on_register(client: BtClient, params: types.RegistrationParams) -> None:
    client.registrations.extend(params.registrations)


def _on_unregister(client: BtClient, params: types.UnregistrationParams) -> None:
    gone = {u.id for u in params.unregisterations}
    client.registrations[:] = [r for r in client.registrations if r.id not in gone]


def make_client() -> BtClient:
    client = BtClient(converter_factory=default_converter)
    features = dict(DEFAULT_CLIENT_FEATURES)
    features[types.TEXT_DOCUMENT_PUBLISH_DIAGNOSTICS] = _on_publish
    features[types.WINDOW_LOG_MESSAGE] = _on_log
    features[types.WORKSPACE_CONFIGURATION] = _on_configuration
    features[types.WORKSPACE_DIAGNOSTIC_REFRESH] = _on_refresh
    features[types.CLIENT_REGISTER_CAPABILITY] = _on_register
    features[types.CLIENT_UNREGISTER_CAPABILITY] = _on_unregister
    register_lsp_features(client, features)
    return client


CONFIG = ClientServerConfig(server_command=SERVER_COMMAND, client_factory=make_client)


@pytest.hookimpl(trylast=True)
def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    """Run each module's tests grouped by client profile, so that each module starts one
    server per profile.  (pytest groups module-scoped parameters by their index, and the
    tests here use different lists of profiles.)"""
    here = [i for i, item in enumerate(items) if item.nodeid.startswith(_NODEID_PREFIX)]
    by_module: dict[str, list[pytest.Item]] = {}
    for i in here:
        by_module.setdefault(items[i].nodeid.split("::")[0], []).append(items[i])
    ordered: list[pytest.Item] = []
    for module_items in by_module.values():
        rank: dict[object, int] = {}
        for item in module_items:
            rank.setdefault(_profile_of(item), len(rank))
        ordered.extend(sorted(module_items, key=lambda it: rank[_profile_of(it)]))
    for i, item in zip(here, ordered, strict=True):
        items[i] = item


_NODEID_PREFIX = "tests/server/"


def _profile_of(item: pytest.Item) -> object:
    callspec = getattr(item, "callspec", None)
    return callspec.params.get("client") if callspec is not None else None


@pytest_lsp.fixture(config=CONFIG, scope="module", params=CLIENTS)
async def client(lsp_client: BtClient, request: pytest.FixtureRequest) -> AsyncIterator[None]:
    """A server initialized by one client profile (``request.param``), debounce 0."""
    await lsp_client.start_session(request.param)
    assert lsp_client.encoding == lsp_client.profile.expected_encoding()
    yield
    await lsp_client.shutdown_session()


@pytest.fixture(autouse=True)
def _close_documents(request: pytest.FixtureRequest) -> Iterator[None]:
    """Close what a test opened, so that tests sharing a server do not see each other's
    documents (open documents form one workspace)."""
    client = request.getfixturevalue("client") if "client" in request.fixturenames else None
    before = set(client.opened) if isinstance(client, BtClient) else set()
    yield
    if isinstance(client, BtClient) and client.error is None:
        for uri in sorted(client.opened - before):
            client.close(uri)


_counter = itertools.count(1)


def send_raw(client: BtClient, message: dict[str, Any] | bytes) -> None:
    """Write one message as is (no validation by the client's types)."""
    body = message if isinstance(message, bytes) else json.dumps(message).encode("utf-8")
    writer = client.protocol.writer
    assert writer is not None
    writer.write(b"Content-Length: %d\r\n\r\n" % len(body) + body)


async def raw_request(client: BtClient, method: str, params: Any) -> Any:
    """Send a request whose params need not have the right shape; its response (or
    JsonRpcException) within :data:`TIMEOUT`."""
    msg_id = f"raw-{next(_counter)}"
    future: concurrent.futures.Future[Any] = concurrent.futures.Future()
    client.protocol._request_futures[msg_id] = future
    send_raw(client, {"jsonrpc": "2.0", "id": msg_id, "method": method, "params": params})
    try:
        return await asyncio.wait_for(asyncio.wrap_future(future), TIMEOUT)
    except TimeoutError:
        raise AssertionError(f"no response to {method} within {TIMEOUT}s") from None


def raw_notify(client: BtClient, method: str, params: Any) -> None:
    send_raw(client, {"jsonrpc": "2.0", "method": method, "params": params})


def fresh_uri(name: str = "doc") -> str:
    return f"file:///bt-lsp-tests/{name}-{next(_counter)}.xml"


async def eventually(
    get: Callable[[], Awaitable[T]], ok: Callable[[T], bool], what: str, tries: int = 100
) -> T:
    """Poll ``get`` until ``ok`` (for pulled results that change asynchronously)."""
    value = await get()
    for _ in range(tries):
        if ok(value):
            return value
        await asyncio.sleep(0.05)
        value = await get()
    raise AssertionError(f"{what}: last value {value!r}")


# -- positions, computed without the server's LineIndex -------------------------------------

_CODECS = {"utf-8": ("utf-8", 1), "utf-16": ("utf-16-le", 2), "utf-32": ("utf-32-le", 4)}
_EOL = re.compile(r"\r\n|\r|\n")


def units(text: str, encoding: str) -> int:
    """Length of ``text`` in code units of ``encoding``."""
    codec, width = _CODECS[encoding]
    return len(text.encode(codec, "surrogatepass")) // width


def _lines(text: str) -> list[tuple[int, int]]:
    """(start, end of content) of every line; LSP line ends only."""
    out: list[tuple[int, int]] = []
    start = 0
    for m in _EOL.finditer(text):
        out.append((start, m.start()))
        start = m.end()
    out.append((start, len(text)))
    return out


def lsp_position(text: str, offset: int, encoding: str) -> types.Position:
    assert 0 <= offset <= len(text)
    if offset and text[offset - 1] == "\r" and text[offset : offset + 1] == "\n":
        offset -= 1  # between "\r" and "\n": the end of the line
    line = len(_EOL.findall(text, 0, offset))
    start = _lines(text)[line][0]
    return types.Position(line=line, character=units(text[start:offset], encoding))


def lsp_range(text: str, start: int, end: int, encoding: str) -> types.Range:
    return types.Range(lsp_position(text, start, encoding), lsp_position(text, end, encoding))


def lsp_offset(text: str, pos: types.Position, encoding: str) -> int:
    """The code-point offset of a position that falls on a code-point boundary."""
    lines = _lines(text)
    assert pos.line < len(lines), f"{pos} past the last line"
    start, end = lines[pos.line]
    codec, width = _CODECS[encoding]
    data = text[start:end].encode(codec, "surrogatepass")
    assert pos.character * width <= len(data), f"{pos} past the end of its line"
    return start + len(data[: pos.character * width].decode(codec, "surrogatepass"))


def apply_edits(text: str, edits: Sequence[types.TextEdit], encoding: str) -> str:
    """Apply LSP text edits (all relative to ``text``; none may overlap)."""
    spans = sorted(
        (lsp_offset(text, e.range.start, encoding), lsp_offset(text, e.range.end, encoding), i)
        for i, e in enumerate(edits)
    )
    out: list[str] = []
    pos = 0
    for start, end, i in spans:
        e = edits[i]
        assert start >= pos, f"overlapping edits: {edits}"
        out.append(text[pos:start])
        out.append(e.new_text)
        pos = end
    out.append(text[pos:])
    return "".join(out)


def apply_changes(
    text: str, changes: Sequence[types.TextDocumentContentChangeEvent], encoding: str
) -> str:
    """Apply didChange content changes in order, each relative to the previous result."""
    for ch in changes:
        if isinstance(ch, types.TextDocumentContentChangePartial):
            start = lsp_offset(text, ch.range.start, encoding)
            end = lsp_offset(text, ch.range.end, encoding)
            text = text[:start] + ch.text + text[end:]
        else:
            text = ch.text
    return text


def plain(
    e: types.TextEdit | types.AnnotatedTextEdit | types.SnippetTextEdit,
) -> types.TextEdit:
    """A text edit of a ``documentChanges`` entry as a plain one (an annotated edit of
    another file is applied the same way once confirmed)."""
    if isinstance(e, types.TextEdit):
        return e
    assert isinstance(e, types.AnnotatedTextEdit), e
    return types.TextEdit(range=e.range, new_text=e.new_text)


def workspace_edits(edit: types.WorkspaceEdit, uri: str) -> list[types.TextEdit]:
    """The text edits of ``uri`` in a WorkspaceEdit (``changes`` or ``documentChanges``)."""
    out: list[types.TextEdit] = []
    if edit.changes:
        out.extend(edit.changes.get(uri, []))
    for dc in edit.document_changes or []:
        assert isinstance(dc, types.TextDocumentEdit), dc
        if dc.text_document.uri == uri:
            out.extend(plain(e) for e in dc.edits)
    return out


def partial(
    text: str, start: int, end: int, new: str, encoding: str
) -> types.TextDocumentContentChangePartial:
    """A didChange replacing ``text[start:end]`` with ``new``."""
    return types.TextDocumentContentChangePartial(
        range=lsp_range(text, start, end, encoding), text=new
    )


# -- marked documents -----------------------------------------------------------------------


@dataclass(frozen=True)
class Marked:
    """An XML snippet with ``⟦…⟧`` around the spans that diagnostics must cover exactly."""

    text: str
    spans: list[tuple[int, int]]

    def ranges(self, encoding: str) -> list[types.Range]:
        return [lsp_range(self.text, s, e, encoding) for s, e in self.spans]

    def span_of(self, needle: str, nth: int = 0) -> tuple[int, int]:
        start = -1
        for _ in range(nth + 1):
            start = self.text.index(needle, start + 1)
        return start, start + len(needle)


def marked(source: str) -> Marked:
    text, spans = unmark(source)
    return Marked(text, spans)


def key(r: types.Range) -> tuple[int, int, int, int]:
    return (r.start.line, r.start.character, r.end.line, r.end.character)


def summary(diags: Sequence[types.Diagnostic]) -> list[tuple[str, tuple[int, int, int, int]]]:
    """(code, range) of each diagnostic, sorted."""
    return sorted((str(d.code), key(d.range)) for d in diags)


# -- diagnostic families --------------------------------------------------------------------

NAME_CODES = frozenset(c for c, info in CODES.items() if info.family == "names")
XML_CODES = frozenset(c for c, info in CODES.items() if info.family == "xml")


def names_only(diags: Sequence[types.Diagnostic]) -> list[types.Diagnostic]:
    """The name-rule diagnostics (other rule families are tested elsewhere)."""
    return [d for d in diags if d.code in NAME_CODES]


def syntax_and_names(diags: Sequence[types.Diagnostic]) -> list[types.Diagnostic]:
    return [d for d in diags if d.code in NAME_CODES or d.code in XML_CODES]
