"""Analysing large documents on a worker thread, so that the event loop keeps serving.

The analysis of a document near ``maxDocumentBytes`` takes seconds; on the event loop it
would hold every other request (a hover on another document, the diagnostics of a small
document being typed in) for that long.  A document of at least :data:`WORKER_CHARS`
characters is therefore analysed by one worker thread, on a :meth:`Document.snapshot` taken
on the loop: edits arriving meanwhile change the open document, never the snapshot.  The
result is kept (and published) only if nothing it depends on changed while it ran (the
same key as :meth:`bt_lsp.server.diagnostics_cache.DiagnosticsCache.of`); else the analysis
that the change scheduled follows.  Smaller documents are analysed on the loop as before:
they take milliseconds and never queue behind a large one.

Python switches threads every few milliseconds (``sys.getswitchinterval``), so the loop
keeps answering while the worker runs.  Requests on the document being analysed do not
wait for it: they use the open document, whose model is built from the last complete one
(only the sections edited since); a completed analysis hands its model and own
diagnostics to the open document when it was not edited meanwhile.  What needs the
document's diagnostics (pulled diagnostics) waits for its analysis, never the loop.

Even the open of such a document does nothing on the loop in proportion to its text: the
worker finds its early name diagnostics (published while nothing newer is known) and then
makes its line index, tokens and model (:meth:`Background.prepare`).  Meanwhile every
message about the document (a request, an edit, its close) is held, and handled in the
order it came once the document is ready; messages about other documents are handled at
once.
"""

from __future__ import annotations

import asyncio
import threading
from collections.abc import Awaitable, Callable, Mapping, Sequence
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, TypeVar

from bt_lsp.rules.context import facts_of
from bt_lsp.rules.diagnostics import Diagnostic
from bt_lsp.rules.early_names import early_name_diagnostics
from bt_lsp.server.cpp import is_cpp
from bt_lsp.server.lookup import context_of
from bt_lsp.server.navigation import folding_json, outline_json
from bt_lsp.server.state import OpenDocument
from bt_lsp.syntax.document import Document
from bt_lsp.syntax.text import positions_of

if TYPE_CHECKING:
    from bt_lsp.server.app import BtServer

# From this many characters a BT document is analysed on the worker thread: a quarter of
# a megabyte takes a few hundred milliseconds to analyse the first time.
WORKER_CHARS = 256 * 1024

# A C++ document's diagnostics (tree-sitter's parse, then its string literals) take
# about 0.6 ms per KiB: from this size they are found on the worker thread too.
CPP_WORKER_CHARS = 32 * 1024

Key = tuple[int | None, int, int]
R = TypeVar("R")
PUBLISH_DIAGNOSTICS = "textDocument/publishDiagnostics"
_EARLY_WAIT = 1.0  # seconds the worker waits at most for the loop to publish the names


def _prepare(doc: Document, is_bt: bool, waiting: Sequence[object] = ()) -> None:
    """On the worker thread: the document's line index, tokens and model and, for a BT
    document, what it declares (the analysis reads it next).  With messages ``waiting``
    for it (a request sent with the open), its name index too, which a hover or a
    definition reads first: made on the loop it took about 1 s at 8 MB.  Without, it is
    made on first use, as the analysis does not need it (it would double the memory of a
    document of many small elements)."""
    doc.prepare(is_bt)
    if is_bt:
        facts_of(doc)
        if waiting:
            _ = doc.model.by_symbol


@dataclass(slots=True)
class _Job:
    key: Key
    snapshot: Document
    done: asyncio.Future[list[Diagnostic] | None]


@dataclass(slots=True)
class _Held:
    """A document being prepared on the worker, and the messages about it since."""

    od: OpenDocument
    messages: list[Any] = field(default_factory=list)


def target_uri(message: Any) -> str | None:
    """The document a client message is about: its ``textDocument``, the ``uri`` of a
    command's argument (``bt-lsp.renderTree``) or of a code action's data."""
    params = getattr(message, "params", None)
    if params is None:
        return None
    uri = getattr(getattr(params, "text_document", None), "uri", None)
    if isinstance(uri, str):
        return uri
    data = getattr(params, "data", None)  # codeAction/resolve
    if isinstance(data, Mapping) and isinstance(data.get("uri"), str):
        return str(data["uri"])
    args = getattr(params, "arguments", None)  # workspace/executeCommand
    if args and isinstance(args[0], Mapping) and isinstance(args[0].get("uri"), str):
        return str(args[0]["uri"])
    return None


# Requests about the whole document, made on the worker when they wait for its open.
_OUTLINE, _FOLDING = "textDocument/documentSymbol", "textDocument/foldingRange"
_WHOLE = frozenset({_OUTLINE, _FOLDING})


class Background:
    """The worker thread and the analysis under way (or queued) for each document."""

    def __init__(self, server: BtServer) -> None:
        self._server = server
        self._pool: ThreadPoolExecutor | None = None
        self._jobs: dict[str, _Job] = {}
        self._held: dict[str, _Held] = {}  # documents being prepared, by URI
        self._aside: ThreadPoolExecutor | None = None

    def _worker(self) -> ThreadPoolExecutor:
        if self._pool is None:
            self._pool = ThreadPoolExecutor(max_workers=1, thread_name_prefix="bt-lsp-analysis")
        return self._pool

    def aside(self, func: Callable[..., R], *args: Any) -> asyncio.Future[R]:
        """``func(*args)`` on a thread of its own (not the worker's, which may be busy with
        an analysis for seconds): a request about the whole of a large document (its
        outline, its folding ranges), made from a snapshot taken on the loop.  On the loop
        it held every other request for as long (a second at 8 MB, two while an analysis
        shared the interpreter); there, the loop answers them meanwhile."""
        if self._aside is None:
            self._aside = ThreadPoolExecutor(max_workers=1, thread_name_prefix="bt-lsp-requests")
        return asyncio.get_running_loop().run_in_executor(self._aside, func, *args)

    def beside(
        self, func: Callable[..., R], *args: Any
    ) -> tuple[Callable[..., Awaitable[R]], tuple[Any, ...], None]:
        """What a generator handler yields to have ``func(*args)`` run :meth:`aside`
        (pygls runs the yielded coroutine and sends its result back into the handler).

        A coroutine handler runs only once the loop gets to its task, and the messages
        read meanwhile (an edit sent right after the request, or held with it for a
        document being prepared) are handled first: a snapshot taken there was of a
        later version than the request's.  A generator handler runs at once, up to its
        ``yield``, so its arguments here are taken when the request arrives."""
        return self._aside_awaited, (func, *args), None

    async def _aside_awaited(self, func: Callable[..., R], *args: Any) -> R:
        return await self.aside(func, *args)

    # -- preparing a large document --------------------------------------------------------

    def prepare(self, od: OpenDocument, ready: Callable[[], None]) -> bool:
        """Whether ``od`` (just opened, or replaced by a new text, and not yet scanned) is
        large enough to be prepared on the worker thread; if so, its early name
        diagnostics are found there first (pushed to clients that do not pull), then its
        line index, tokens and model are made, and on the loop ``ready`` runs, followed by
        the messages about ``od`` that came meanwhile, in their order."""
        if len(od.doc.text) < WORKER_CHARS or od.uri in self._held:
            return False
        loop = asyncio.get_running_loop()
        self._held[od.uri] = held = _Held(od)
        pool = self._worker()
        early = loop.run_in_executor(pool, self._kind_and_early_names, held, loop)
        early.add_done_callback(lambda f: self._early_failed(held, f))
        work = loop.run_in_executor(pool, self._prepare_for, held)
        work.add_done_callback(lambda f: self._prepared(held, f, ready))
        return True

    def _prepare_for(self, held: _Held) -> None:
        """On the worker thread: :func:`_prepare`, and the outline (the folding ranges)
        when a request for it waits; the request then reads what the worker kept. Made
        on the loop while the analysis ran on the worker, the two shared the interpreter
        and the outline of 8 MB took 6 s to come."""
        od = held.od
        _prepare(od.doc, od.is_bt)  # the name index after these, if another waits
        if not od.is_bt:
            return
        # Read once the model is made: the requests sent with the open have come by then.
        methods = {getattr(m, "method", None) for m in list(held.messages)}
        if _OUTLINE in methods:
            server = self._server
            outline_json(od.doc, context_of(server, od), server.encoding)
        if _FOLDING in methods:
            folding_json(od)
        if methods - _WHOLE:
            _ = od.doc.model.by_symbol

    def _kind_and_early_names(self, held: _Held, loop: asyncio.AbstractEventLoop) -> None:
        """On the worker thread: whether the document is BT XML (a search of its whole
        text when it is not) and, for clients that are pushed diagnostics, its early name
        diagnostics, their positions (a line index of the text when it has CR) and the
        JSON of their publication, which the loop then only writes.  The worker waits
        for it (a moment) before it goes on: the loop does not share the interpreter
        with the scan meanwhile, and the first diagnostics come that much sooner."""
        od = held.od
        od.refresh_kind()
        server = self._server
        if not od.is_bt or not server.publisher.wants_early_names(od):
            return
        text = od.doc.text
        found = early_name_diagnostics(text)
        if found is None:
            return
        at = positions_of(text, [o for d in found for o in (d.start, d.end)], server.encoding)
        params = server.publisher.early_names_json(od, found, at)
        written = threading.Event()
        loop.call_soon_threadsafe(self._early, held, params, written)
        written.wait(_EARLY_WAIT)

    def cancel_held(self, msg_id: object) -> bool:
        """Whether a request with ``msg_id`` was held for a document being prepared (it
        is dropped: the caller answers it RequestCancelled at once)."""
        for held in self._held.values():
            for k, message in enumerate(held.messages):
                if getattr(message, "id", None) == msg_id and hasattr(message, "method"):
                    del held.messages[k]
                    return True
        return False

    def holds(self, message: Any) -> bool:
        """Hold ``message`` if it is about a document being prepared (handled, in order,
        once it is ready)."""
        if not self._held:
            return False
        uri = target_uri(message)
        held = self._held.get(uri) if uri is not None else None
        if held is None:
            return False
        held.messages.append(message)
        return True

    def preparing(self, uri: str) -> bool:
        return uri in self._held

    def _early(self, held: _Held, params: str, written: threading.Event) -> None:
        """On the loop: publish the early names while the document is still being
        prepared (nothing newer about it is known until then)."""
        try:
            if self._held.get(held.od.uri) is held:
                self._server.bt_protocol.notify_json(PUBLISH_DIAGNOSTICS, params)
        finally:
            written.set()

    def _early_failed(self, held: _Held, work: asyncio.Future[None]) -> None:
        if work.cancelled():
            return
        exc = work.exception()
        if exc is not None:  # the complete set follows anyway
            self._server.log_message(
                f"bt-lsp: error finding the early name diagnostics of {held.od.uri}: {exc!r}"
            )

    def _prepared(self, held: _Held, work: asyncio.Future[None], ready: Callable[[], None]) -> None:
        """On the loop: the document is ready; then the messages held for it."""
        if work.cancelled():  # shut down
            return
        if self._held.get(held.od.uri) is held:
            del self._held[held.od.uri]
        exc = work.exception()
        if exc is not None:  # what is missing is made when first used
            self._server.log_message(f"bt-lsp: error preparing {held.od.uri}: {exc!r}")
        server = self._server
        try:
            ready()
        except Exception:
            server.log_error(f"opening {held.od.uri}")
        protocol = server.bt_protocol
        for message in held.messages:
            try:
                protocol.handle_message(message)
            except Exception as exc:  # as BtProtocol.receive does
                protocol.log(f"bt-lsp: internal error handling a message: {exc!r}")

    # -- analysing ---------------------------------------------------------------------------

    def wants(self, od: OpenDocument) -> bool:
        """Whether ``od`` is analysed on the worker thread: a large BT document, or a C++
        document of :data:`CPP_WORKER_CHARS` (its tree-sitter parse and literals)."""
        if od.is_bt:
            return len(od.doc.text) >= WORKER_CHARS
        return len(od.doc.text) >= CPP_WORKER_CHARS and is_cpp(od)

    def busy(self, od: OpenDocument) -> bool:
        """Whether an analysis of ``od``'s current state is under way (or ``od`` is being
        prepared: once it is ready its diagnostics are due)."""
        if od.uri in self._held:
            return True
        job = self._jobs.get(od.uri)
        return job is not None and job.key == self._server.diagnostics.key(od)

    def analyse(self, od: OpenDocument) -> asyncio.Future[list[Diagnostic] | None]:
        """Start analysing ``od`` as it is now (unless that is under way already); the
        future is done, on the loop, once its diagnostics are cached on ``od`` (its result)
        or are not wanted any more (``None``: the document changed or was closed)."""
        key = self._server.diagnostics.key(od)
        job = self._jobs.get(od.uri)
        if job is not None and job.key == key:
            return job.done
        loop = asyncio.get_running_loop()
        job = _Job(key, od.doc.snapshot(), loop.create_future())
        self._jobs[od.uri] = job
        work = loop.run_in_executor(self._worker(), self._run, od, job)
        work.add_done_callback(lambda f: self._finished(od, job, f))
        return job.done

    def _run(self, od: OpenDocument, job: _Job) -> list[Diagnostic] | None:
        """On the worker thread: the diagnostics of the snapshot, unless a later change
        made this analysis useless before it started."""
        if self._jobs.get(od.uri) is not job:
            return None
        return self._server.diagnostics.compute(od, job.snapshot)

    def _finished(
        self, od: OpenDocument, job: _Job, work: asyncio.Future[list[Diagnostic] | None]
    ) -> None:
        """On the loop: keep the result if it is still current, and say so."""
        if self._jobs.get(od.uri) is job:
            del self._jobs[od.uri]
        server = self._server
        result: list[Diagnostic] | None = None
        if work.cancelled():
            pass
        elif work.exception() is not None:
            exc = work.exception()
            server.log_message(f"bt-lsp: error computing diagnostics for {od.uri}: {exc!r}")
        else:
            result = work.result()
        current = server.docs.get(od.uri) is od and server.diagnostics.key(od) == job.key
        if result is not None and current:
            if od.is_bt:  # (a C++ document has no model to hand on)
                od.doc.adopt(job.snapshot)
            server.diagnostics.computed(od, job.key, result)
        else:
            result = None
        if not job.done.done():
            job.done.set_result(result if current else None)

    def forget(self, uri: str) -> None:
        """``uri`` was closed: its queued analysis need not run."""
        self._jobs.pop(uri, None)

    def shutdown(self) -> None:
        for pool in (self._pool, self._aside):
            if pool is not None:
                pool.shutdown(wait=False, cancel_futures=True)
