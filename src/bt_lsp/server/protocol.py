"""pygls's protocol without its own copy of open documents.

pygls keeps a second copy of every document and re-splits it into lines on each change
(with the line-end bugs noted in the README).  bt-lsp's :class:`~bt_lsp.syntax.document.Document`
is the only copy, updated incrementally, so the built-in sync handlers only hand the
notification on to ours.
"""

from __future__ import annotations

import asyncio
import contextlib
import inspect
import json
import os
import reprlib
import sys
from collections.abc import Generator
from typing import Any, cast

from cattrs import ClassValidationError, Converter, IterableValidationError, transform_error
from cattrs.v import format_exception
from lsprotocol import types
from lsprotocol.types import ResponseErrorMessage
from pygls.exceptions import (
    JsonRpcException,
    JsonRpcInternalError,
    JsonRpcInvalidParams,
)
from pygls.protocol import (
    JsonRPCNotification,
    JsonRPCRequestMessage,
    JsonRPCResponseMessage,
    LanguageServerProtocol,
    lsp_method,
)

from bt_lsp.server import jsonrpc
from bt_lsp.server.convert import RawJson
from bt_lsp.server.framing import Body

REQUEST_CANCELLED = types.LSPErrorCodes.RequestCancelled.value


def _json_type(value: object) -> str:
    """The JSON name of a value's type, for a message about it."""
    if value is None:
        return "null"
    if isinstance(value, bool):
        return "a boolean"
    if isinstance(value, int | float):
        return "a number"
    if isinstance(value, str):
        return "a string"
    return "an array" if isinstance(value, list) else "an object"


def _short(value: object) -> str:
    """A short quotation of a value from a message (deep or long ones elided)."""
    return reprlib.repr(value)


def _structure_str(value: object, kind: type[str]) -> str:
    if not isinstance(value, str):
        raise TypeError(f"a string was expected, not {_json_type(value)}: {_short(value)}")
    return value if kind is str else kind(value)  # a string enumeration checks its values


def _structure_int(value: object, kind: type[int]) -> int:
    if not isinstance(value, int) or isinstance(value, bool):
        raise TypeError(f"an integer was expected, not {_json_type(value)}: {_short(value)}")
    return value if kind is int else kind(value)  # an IntEnum (FileChangeType) checks its values


def _structure_bool(value: object, _: object) -> bool:
    if not isinstance(value, bool):
        raise TypeError(f"a boolean was expected, not {_json_type(value)}: {_short(value)}")
    return value


def strict(converter: Converter) -> Converter:
    """``converter`` with strings, integers and booleans taken as they are only: cattrs
    converts by calling the type, so ``"uri": 5`` became the URI ``"5"`` (a request
    answered ``null``) and ``"line": "0"`` the line 0, where LSP asks for InvalidParams.
    The hooks take the subclasses too (lsprotocol's enumerations derive from ``int`` or
    ``str``), which are made by calling the enumeration, as before."""
    converter.register_structure_hook(str, _structure_str)
    converter.register_structure_hook(int, _structure_int)
    converter.register_structure_hook(bool, _structure_bool)
    return converter


def _reason(exc: BaseException, kind: Any) -> str:
    """One failure of a value, with the validator's own words (the range a version
    must be in, the enumeration's values) where it has some."""
    if isinstance(exc, TypeError | ValueError) and str(exc):
        return str(exc)[:200]
    return format_exception(exc, kind)


def _why(exc: BaseException) -> str:
    """What is wrong with a message's params, in one line."""
    cause = exc.__cause__ if isinstance(exc, JsonRpcException) else exc
    if isinstance(cause, ClassValidationError | IterableValidationError):
        return "; ".join(transform_error(cause, format_exception=_reason))
    return repr(cause)


class BtProtocol(LanguageServerProtocol):
    def __init__(self, server: Any, converter: Converter, *args: Any, **kwargs: Any) -> None:
        super().__init__(server, strict(converter), *args, **kwargs)
        self._initialize_seen = False
        self._writes: set[asyncio.Future[Any]] = set()  # writes in flight (websockets)

    def receive(self, body: Body) -> None:
        """One message body from the framing: answered with the JSON-RPC error it
        deserves, or structured and handled.  Nothing here may end the read loop."""
        try:
            self._receive(body)
        except Exception as exc:  # (a value nested deep enough to fail a repr, a bug)
            self.log(f"bt-lsp: internal error handling a message: {exc!r}")

    def _receive(self, body: Body) -> None:
        if body.error is not None:
            self.log(f"bt-lsp: parse error: {body.error}")
            self._send_error(None, jsonrpc.PARSE_ERROR, f"Parse error: {body.error}")
            return
        bad = jsonrpc.problem(body.value)
        if bad is not None:
            msg_id, why = bad
            self.log(f"bt-lsp: invalid request: {why}")
            self._send_error(msg_id, jsonrpc.INVALID_REQUEST, f"Invalid request: {why}")
            return
        value = self._screened(cast(dict[str, Any], body.value))
        if value is None:
            return
        try:
            message = self.structure_message(value)
        except Exception as exc:  # a request is already answered (InvalidParams)
            self.refused(body.value, exc)
            return
        try:
            self.handle_message(message)
        except Exception as exc:  # a bug must not end the read loop
            self.log(f"bt-lsp: internal error handling a message: {exc!r}")

    def _screened(self, data: dict[str, Any]) -> dict[str, Any] | None:
        """The message with what would make it fail as a whole taken out: a watched-file
        event of an unknown type (or shape) is left out of its batch, whose other events
        are handled (one bad event dropped them all); a ``$/cancelRequest`` whose id is
        neither a number nor a string is ignored.  Each is logged in one line; ``None``
        when nothing is left to handle."""
        method = data.get("method")
        params = data.get("params")
        if method == types.CANCEL_REQUEST and "id" not in data:
            msg_id = params.get("id") if isinstance(params, dict) else None
            if msg_id is None or not jsonrpc.valid_id(msg_id):
                self.log(
                    "bt-lsp: $/cancelRequest ignored: the id of the request to cancel must "
                    f"be a number or a string, not {_json_type(msg_id)}"
                )
                return None
            return data
        if method != types.WORKSPACE_DID_CHANGE_WATCHED_FILES or "id" in data:
            return data
        if not isinstance(params, dict) or not isinstance(params.get("changes"), list):
            return data  # refused as a whole (see refused)
        changes: list[Any] = params["changes"]
        kept: list[Any] = []
        bad: list[str] = []
        for k, event in enumerate(changes):
            try:
                self._converter.structure(event, types.FileEvent)
            except Exception as exc:
                bad.append(f"event {k} ({_short(event)}): {_why(exc)}")
            else:
                kept.append(event)
        if bad:
            self.log(
                f"bt-lsp: workspace/didChangeWatchedFiles: {len(bad)} of {len(changes)} "
                f"events ignored, the others handled: {'; '.join(bad[:3])}"
                + (f"; and {len(bad) - 3} more" if len(bad) > 3 else "")
            )
            if not kept:
                return None
        return {**data, "params": {**params, "changes": kept}} if bad else data

    def refused(self, data: Any, exc: BaseException) -> None:
        """Say in one line of the client's log why a message whose params do not have
        its method's shape was not handled (pygls printed cattrs's tracebacks on stderr,
        and an editor shows those as a crash)."""
        method = data.get("method") if isinstance(data, dict) else None
        if method is None:
            self.log(f"bt-lsp: a response that could not be read, ignored: {_why(exc)}")
            return
        if "id" in data:  # answered InvalidParams; this is the log line
            self.log(f"bt-lsp: Invalid params for the request {method}: {_why(exc)}")
            return
        params = data.get("params")
        doc = params.get("textDocument") if isinstance(params, dict) else None
        uri = doc.get("uri") if isinstance(doc, dict) else None
        if method == types.TEXT_DOCUMENT_DID_CHANGE and isinstance(uri, str):
            self.log(
                f"bt-lsp: Invalid params for textDocument/didChange of {uri}: {_why(exc)}; "
                "the change is refused: the server's copy of the document stays as it was, "
                "and no longer follows the editor's until the document is opened again"
            )
            return
        self.log(f"bt-lsp: Invalid params for the notification {method}, ignored: {_why(exc)}")

    def log(self, message: str) -> None:
        self.notify(
            types.WINDOW_LOG_MESSAGE,
            types.LogMessageParams(type=types.MessageType.Warning, message=message),
        )

    def _send_data(self, data: Any) -> None:
        """pygls's writer, except that a response whose result cannot be serialised (a
        RecursionError, a bug) becomes an InternalError answer to the same id: pygls only
        logged it, and the request was never answered."""
        if not data or self.writer is None:
            super()._send_data(data)
            return
        try:
            result = getattr(data, "result", None)
            if isinstance(result, RawJson) and getattr(data, "error", None) is None:
                # In pieces: an outline of 8 MB is 26 MB of JSON, not copied into a body.
                head = f'{{"jsonrpc": "2.0", "id": {json.dumps(data.id)}, "result": '
                parts = [head, result, "}"]
            else:
                parts = [json.dumps(data, default=self._serialize_message)]
        except Exception as exc:
            msg_id = getattr(data, "id", None) if not isinstance(data, dict) else data.get("id")
            is_response = hasattr(data, "result") or hasattr(data, "error")
            self.log(f"bt-lsp: internal error serialising a message: {exc!r}")
            if is_response and jsonrpc.valid_id(msg_id):
                error = json.dumps(
                    {
                        "jsonrpc": "2.0",
                        "id": msg_id,
                        "error": {
                            "code": jsonrpc.INTERNAL_ERROR,
                            "message": f"the answer could not be written: {exc!r}",
                        },
                    }
                )
                parts = [error]
            else:
                return
        self._write_parts(parts)

    def notify_json(self, method: str, params: str) -> None:
        """A notification whose params are already JSON text."""
        if self.writer is not None:
            self._write(f'{{"jsonrpc": "2.0", "method": {json.dumps(method)}, "params": {params}}}')

    def _write(self, body: str) -> None:
        self._write_parts([body])

    def _write_parts(self, parts: list[str]) -> None:
        """Write one message whose body is ``parts`` joined: with headers (stdio, TCP)
        each part is written as it is encoded, so a large body is never copied into
        one; a websocket gets one frame."""
        data = [part.encode(self.CHARSET) for part in parts]
        header = (
            f"Content-Length: {sum(map(len, data))}\r\n"
            f"Content-Type: {self.CONTENT_TYPE}; charset={self.CHARSET}\r\n\r\n"
        ).encode("ascii")
        assert self.writer is not None
        try:
            if not self._include_headers:
                self._wrote(self.writer.write(b"".join(data)))
                return
            self._wrote(self.writer.write(header + data[0] if len(data) == 1 else header))
            if len(data) > 1:
                for chunk in data:
                    self._wrote(self.writer.write(chunk))
        except BrokenPipeError:
            raise
        except Exception as error:
            self._server._report_server_error(error, JsonRpcInternalError)

    def _wrote(self, res: Any) -> None:
        if inspect.isawaitable(res):
            self._writes.add(task := asyncio.ensure_future(res))
            task.add_done_callback(self._writes.discard)

    def _send_error(self, msg_id: Any, code: int, message: str) -> None:
        """An error response; ``id: null`` is written out (the converter drops None)."""
        self._send_data(
            {"jsonrpc": "2.0", "id": msg_id, "error": {"code": code, "message": message}}
        )

    def structure_message(self, data: dict[str, Any]) -> Any:
        """The message as lsprotocol's type for its method.  A request whose params do not
        have its method's shape is answered with an InvalidParams error (pygls only
        logged it, and the client would wait forever); one that the lifecycle refuses
        (:meth:`_refusal`) gets that error whatever its params.  Nothing is logged here
        (pygls wrote a traceback to stderr): :meth:`refused` says why in one line."""
        try:
            return self._structure(data)
        except Exception as exc:
            if isinstance(data, dict) and "id" in data and "method" in data:
                refusal = self._refusal(data["method"])
                if refusal is not None:
                    self._send_error(data["id"], *refusal)
                    raise
                error = JsonRpcInvalidParams(f"Invalid params for {data['method']}: {_why(exc)}")
                self._send_response(data["id"], error=error.to_response_error())
            raise

    def _structure(self, data: dict[str, Any]) -> Any:
        """pygls's ``structure_message`` without its logging."""
        if "jsonrpc" not in data:
            return data
        if "id" in data:
            if "error" in data:
                return self._converter.structure(data, ResponseErrorMessage)
            if "method" in data:
                kind = self.get_message_type(data["method"]) or JsonRPCRequestMessage
                return self._converter.structure(data, kind)
            kind = self._result_types.pop(data["id"], None) or JsonRPCResponseMessage
            return self._converter.structure(data, kind)
        kind = self.get_message_type(data.get("method", "")) or JsonRPCNotification
        return self._converter.structure(data, kind)

    @lsp_method(types.EXIT)
    def lsp_exit(self, *args: Any) -> Generator[Any, Any, None]:
        """End the process at once: status 0 after ``shutdown``, 1 otherwise (LSP).  pygls
        exits from a callback whose SystemExit can be lost, which ends the process with 0."""
        handler = self.fm.features.get(types.EXIT)
        if handler is not None:
            yield handler, args, None
        for stream in (sys.stdout, sys.stderr):
            with contextlib.suppress(OSError, ValueError):
                stream.flush()
        os._exit(0 if self._shutdown else 1)

    def _execute_handler(
        self,
        msg_id: Any,
        handler: Any,
        callback: Any,
        args: tuple[Any, ...] | None = None,
        kwargs: dict[str, Any] | None = None,
    ) -> None:
        """Forget a handler's future once it is done.  pygls files the future of every
        notification handler and of every step of a generator handler under a fresh id
        in ``_request_futures`` and removes only those of requests: the sync handlers of
        didOpen/didChange/didClose left one future (with its params, the changed text)
        per notification, a few KiB each, for the life of the process."""

        def done(future: Any) -> None:
            try:
                callback(future)
            finally:
                if self._request_futures.get(msg_id) is future:
                    del self._request_futures[msg_id]

        super()._execute_handler(msg_id, handler, done, args, kwargs)

    @lsp_method(types.SHUTDOWN)
    def lsp_shutdown(self, *args: Any) -> Generator[Any, Any, None]:
        """pygls's shutdown, over a copy of the in-flight futures: cancelling one runs
        its done callback at once, which forgets it (see :meth:`_execute_handler`)."""
        handler = self.fm.features.get(types.SHUTDOWN)
        if handler is not None:
            yield handler, args, None
        current = self.msg_id
        for msg_id, future in list(self._request_futures.items()):
            if msg_id != current and not future.done():
                future.cancel()
        self._shutdown = True

    def handle_message(self, message: Any) -> None:
        """Before ``initialize``, requests get ServerNotInitialized and notifications other
        than ``exit`` are dropped; a second ``initialize`` is refused (LSP).  After
        ``shutdown``, requests get InvalidRequest as LSP asks (pygls drops them silently,
        which leaves a client waiting); notifications other than ``exit`` are ignored."""
        method = getattr(message, "method", None)
        if method is not None and hasattr(message, "id"):  # a request
            refusal = self._refusal(method)
            if refusal is not None:
                self._send_error(message.id, *refusal)
                return
            if method == types.INITIALIZE:
                self._initialize_seen = True
        elif not self._initialize_seen and method is not None and method != types.EXIT:
            return
        background = getattr(self._server, "background", None)
        if background is not None and background.holds(message):
            return  # about a large document being prepared: handled once it is ready
        if (
            method == types.CANCEL_REQUEST
            and background is not None
            and background.cancel_held(getattr(message.params, "id", None))
        ):  # a request held for such a document: answered at once, not once it is ready
            self._send_error(message.params.id, REQUEST_CANCELLED, "the request was cancelled")
            return
        super().handle_message(message)

    def _refusal(self, method: str) -> tuple[int, str] | None:
        """The error a request for ``method`` gets from the lifecycle, whatever its params:
        before ``initialize`` ServerNotInitialized, a second ``initialize`` or any request
        after ``shutdown`` InvalidRequest (LSP); ``None`` if it is served."""
        if method == types.INITIALIZE and self._initialize_seen:
            return jsonrpc.INVALID_REQUEST, "initialize was already received"
        if not self._initialize_seen and method not in (types.INITIALIZE, types.EXIT):
            return jsonrpc.SERVER_NOT_INITIALIZED, f"{method} before initialize"
        if self._shutdown and method != types.EXIT:
            return jsonrpc.INVALID_REQUEST, "the server is shut down"
        return None

    def _forward(self, method: str, params: Any) -> Generator[Any, Any, None]:
        handler = self.fm.features.get(method)
        if handler is not None:
            yield handler, (params,), None

    @lsp_method(types.TEXT_DOCUMENT_DID_OPEN)
    def lsp_text_document__did_open(
        self, params: types.DidOpenTextDocumentParams
    ) -> Generator[Any, Any, None]:
        yield from self._forward(types.TEXT_DOCUMENT_DID_OPEN, params)

    @lsp_method(types.TEXT_DOCUMENT_DID_CHANGE)
    def lsp_text_document__did_change(
        self, params: types.DidChangeTextDocumentParams
    ) -> Generator[Any, Any, None]:
        yield from self._forward(types.TEXT_DOCUMENT_DID_CHANGE, params)

    @lsp_method(types.TEXT_DOCUMENT_DID_CLOSE)
    def lsp_text_document__did_close(
        self, params: types.DidCloseTextDocumentParams
    ) -> Generator[Any, Any, None]:
        yield from self._forward(types.TEXT_DOCUMENT_DID_CLOSE, params)
