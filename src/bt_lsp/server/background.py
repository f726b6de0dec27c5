"""Analysing large documents on a worker thread, so that the event loop keeps serving.

The analysis of a document near ``maxDocumentBytes`` takes seconds; on the event loop it
would hold every other request (a hover on another document, the diagnostics of a small
document being typed in) for that long.  A document of at least :data:`WORKER_CHARS`
characters is therefore analysed by one worker thread, on a :meth:`Document.snapshot` taken
on the loop: edits arriving meanwhile change the open document, never the snapshot.  The
result is kept (and published) only if nothing it depends on changed while it ran (the
same key as :meth:`BtServer.diagnostics_of`); else the analysis that the change scheduled
follows.  Smaller documents are analysed on the loop as before: they take milliseconds and
never queue behind a large one.

Python switches threads every few milliseconds (``sys.getswitchinterval``), so the loop
keeps answering while the worker runs.  Requests on the document being analysed do not
wait for it: they use the open document, whose model is built from the last complete one
(only the sections edited since); a completed analysis hands its model and own
diagnostics to the open document when it was not edited meanwhile.  What needs the
document's diagnostics (pulled diagnostics) waits for its analysis, never the loop.
"""

from __future__ import annotations

import asyncio
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from typing import TYPE_CHECKING

from bt_lsp.rules.diagnostics import Diagnostic
from bt_lsp.server.state import OpenDocument
from bt_lsp.syntax.document import Document

if TYPE_CHECKING:
    from bt_lsp.server.app import BtServer

# From this many characters a BT document is analysed on the worker thread: a quarter of
# a megabyte takes a few hundred milliseconds to analyse the first time.
WORKER_CHARS = 256 * 1024

Key = tuple[int | None, int, int]


@dataclass(slots=True)
class _Job:
    key: Key
    snapshot: Document
    done: asyncio.Future[list[Diagnostic] | None]


class Background:
    """The worker thread and the analysis under way (or queued) for each document."""

    def __init__(self, server: BtServer) -> None:
        self._server = server
        self._pool: ThreadPoolExecutor | None = None
        self._jobs: dict[str, _Job] = {}

    def wants(self, od: OpenDocument) -> bool:
        """Whether ``od`` is analysed on the worker thread."""
        return od.is_bt and len(od.doc.text) >= WORKER_CHARS

    def busy(self, od: OpenDocument) -> bool:
        """Whether an analysis of ``od``'s current state is under way."""
        job = self._jobs.get(od.uri)
        return job is not None and job.key == self._server.diagnostics_key(od)

    def analyse(self, od: OpenDocument) -> asyncio.Future[list[Diagnostic] | None]:
        """Start analysing ``od`` as it is now (unless that is under way already); the
        future is done, on the loop, once its diagnostics are cached on ``od`` (its result)
        or are not wanted any more (``None``: the document changed or was closed)."""
        key = self._server.diagnostics_key(od)
        job = self._jobs.get(od.uri)
        if job is not None and job.key == key:
            return job.done
        loop = asyncio.get_running_loop()
        job = _Job(key, od.doc.snapshot(), loop.create_future())
        self._jobs[od.uri] = job
        if self._pool is None:
            self._pool = ThreadPoolExecutor(max_workers=1, thread_name_prefix="bt-lsp-analysis")
        work = loop.run_in_executor(self._pool, self._run, od, job)
        work.add_done_callback(lambda f: self._finished(od, job, f))
        return job.done

    def _run(self, od: OpenDocument, job: _Job) -> list[Diagnostic] | None:
        """On the worker thread: the diagnostics of the snapshot, unless a later change
        made this analysis useless before it started."""
        if self._jobs.get(od.uri) is not job:
            return None
        return self._server.compute_diagnostics(od, job.snapshot)

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
        current = server.docs.get(od.uri) is od and server.diagnostics_key(od) == job.key
        if result is not None and current:
            od.doc.adopt(job.snapshot)
            server.diagnostics_computed(od, job.key, result)
        else:
            result = None
        if not job.done.done():
            job.done.set_result(result if current else None)

    def forget(self, uri: str) -> None:
        """``uri`` was closed: its queued analysis need not run."""
        self._jobs.pop(uri, None)

    def shutdown(self) -> None:
        if self._pool is not None:
            self._pool.shutdown(wait=False, cancel_futures=True)
