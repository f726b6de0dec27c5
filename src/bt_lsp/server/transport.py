"""The read loop over stdio or TCP, with bt-lsp's framing in place of pygls's.

pygls's loop (``pygls.io_.run_async``) stops understanding the stream after one framing
error; this one reads through :class:`~bt_lsp.server.framing.Framer` and hands each body
to :meth:`~bt_lsp.server.protocol.BtProtocol.receive`.
"""

from __future__ import annotations

import asyncio
import contextlib
import logging
import sys
import threading
from collections.abc import Awaitable, Callable
from typing import TYPE_CHECKING, Any, BinaryIO

from pygls.io_ import StdoutWriter

from bt_lsp.server.framing import Framer, Stream

if TYPE_CHECKING:
    from bt_lsp.server.app import BtServer

log = logging.getLogger(__name__)


async def read_loop(
    server: BtServer,
    read: Callable[[int], Awaitable[bytes]],
    stop: threading.Event,
    read_exact: Callable[[int], Awaitable[bytes]] | None = None,
) -> None:
    protocol = server.bt_protocol
    framer = Framer(Stream(read, read_exact), protocol.log)
    while not stop.is_set():
        body = await framer.next()
        if body is None:
            return
        protocol.receive(body)
        # Let the tasks of coroutine handlers it started take their first step (read the
        # document) before the next message, an edit sent right after, is handled: with
        # that message already read, nothing above waits, and the edit came first.
        await asyncio.sleep(0)


def start_io(server: BtServer, stdin: BinaryIO | None, stdout: BinaryIO | None) -> None:
    source: Any = stdin or sys.stdin.buffer  # a BufferedReader: read1 waits for some bytes only
    server._stop_event = stop = threading.Event()
    server.protocol.set_writer(StdoutWriter(stdout or sys.stdout.buffer))

    async def read(n: int) -> bytes:
        loop = asyncio.get_running_loop()
        return await loop.run_in_executor(server.thread_pool, source.read1, n)

    async def read_exact(n: int) -> bytes:  # (a message body: n bytes are due)
        loop = asyncio.get_running_loop()
        return await loop.run_in_executor(server.thread_pool, source.read, n)

    try:
        asyncio.run(read_loop(server, read, stop, read_exact))
    except BrokenPipeError:
        log.error("the connection to the client is lost")
    except (KeyboardInterrupt, SystemExit):
        pass
    finally:
        server.shutdown()


def start_tcp(server: BtServer, host: str, port: int) -> None:
    server._stop_event = stop = threading.Event()

    async def connection(reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
        server.protocol.set_writer(writer)
        await read_loop(server, reader.read, stop)
        server.shutdown()

    async def main() -> None:
        tcp = await asyncio.start_server(connection, host, port)
        server._server = tcp
        async with tcp:
            await tcp.serve_forever()

    with contextlib.suppress(asyncio.CancelledError):
        asyncio.run(main())
