"""The language server: a thin LSP front end over the pure core."""

from __future__ import annotations

# Allocations between two collections of the youngest generation in the server.
GC_THRESHOLD = 100_000


def serve(tcp: bool = False, host: str = "127.0.0.1", port: int = 2087) -> None:
    """Run the server on stdio (default) or TCP until the client says ``exit``."""
    import gc
    import logging

    # Importing pygls and lsprotocol makes a few hundred thousand objects that live as
    # long as the process: without the cyclic collector they import about a tenth faster
    # (it would scan them again and again while they grow), and frozen they are never
    # scanned again by the collections of the documents' work either.
    gc.disable()
    try:
        from bt_lsp.server.app import create_server

        server = create_server()
    finally:
        gc.freeze()
        gc.enable()
    # The analysis of a large document makes hundreds of thousands of objects, almost
    # none in reference cycles (reference counting frees them).  With the default
    # threshold (a collection every 700 allocations) the collector ran 150 times in ten
    # edits of a 4 MB document, about 20 ms of CPU an edit, and scanned the document's
    # objects again and again during its first analysis; every 100,000 it does not run
    # in those edits.  Cyclic garbage (asyncio's futures and tracebacks) is still
    # collected, a little later.  The core itself leaves the collector alone.
    gc.set_threshold(GC_THRESHOLD, 10, 10)

    # pygls logs routine protocol events (a cancel for a request that already finished)
    # as warnings; on stderr the editor shows them as errors.  Real problems reach the
    # client through window/logMessage instead.
    logging.getLogger("pygls").setLevel(logging.ERROR)
    # A deliberate error answer (a refused rename says why) is no failure of the server:
    # pygls would log it with its traceback, which an editor's log shows as a crash.
    logging.getLogger("pygls.protocol.json_rpc").addFilter(_deliberate_errors_unlogged)
    if tcp:
        server.start_tcp(host, port)
    else:
        server.start_io()


def _deliberate_errors_unlogged(record: object) -> bool:
    """A logging filter: drop the records of requests answered with a deliberate JSON-RPC
    error (anything but an internal error), keep everything else."""
    from pygls.exceptions import JsonRpcException, JsonRpcInternalError

    exc_info = getattr(record, "exc_info", None)
    error = exc_info[1] if exc_info else None
    return not (isinstance(error, JsonRpcException) and not isinstance(error, JsonRpcInternalError))
