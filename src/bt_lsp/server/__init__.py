"""The language server: a thin LSP front end over the pure core."""

from __future__ import annotations


def serve(tcp: bool = False, host: str = "127.0.0.1", port: int = 2087) -> None:
    """Run the server on stdio (default) or TCP until the client says ``exit``."""
    import logging

    from bt_lsp.server.app import create_server

    # pygls logs routine protocol events (a cancel for a request that already finished)
    # as warnings; on stderr the editor shows them as errors.  Real problems reach the
    # client through window/logMessage instead.
    logging.getLogger("pygls").setLevel(logging.ERROR)
    server = create_server()
    if tcp:
        server.start_tcp(host, port)
    else:
        server.start_io()
