"""What JSON-RPC 2.0 and LSP say a message must look like, checked before pygls sees it.

pygls logs and drops a body that is not a request, notification or response; a client
that sent a request then waits forever.  These are answered instead: with -32600
(InvalidRequest) and ``id: null`` when the id itself is unusable.
"""

from __future__ import annotations

from typing import Any

PARSE_ERROR = -32700
INVALID_REQUEST = -32600
SERVER_NOT_INITIALIZED = -32002
INTERNAL_ERROR = -32603


def valid_id(value: object) -> bool:
    return (
        value is None
        or isinstance(value, str)
        or (isinstance(value, int) and not isinstance(value, bool))
    )


def problem(value: object) -> tuple[Any, str] | None:
    """``(id to answer with, what is wrong)`` if ``value`` is not a JSON-RPC message."""
    if isinstance(value, list):
        return None, "a batch (LSP does not use JSON-RPC batches)"
    if not isinstance(value, dict):
        return None, f"not a JSON-RPC message object: {type(value).__name__}"
    msg_id = value.get("id")
    if not valid_id(msg_id):
        return None, f"the id must be a number or a string, not {type(msg_id).__name__}"
    if value.get("jsonrpc") != "2.0":
        return msg_id, 'no "jsonrpc": "2.0"'
    if "method" in value:
        if not isinstance(value["method"], str):
            return msg_id, "the method must be a string"
        return None
    if "id" in value and ("result" in value or "error" in value):
        return None  # a response to one of the server's requests
    return msg_id, "no method"
