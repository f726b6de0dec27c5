"""DAP messages as JSON values: requests read and checked, responses and events made.

The protocol's shapes only (``seq``, ``type``, ``request_seq``, ``success``, ``body``);
what a request does is :mod:`bt_lsp.dap.session`'s.  A request's arguments are read
through :class:`Args`, whose getters raise :class:`InvalidArguments` with a message for
the user instead of letting a wrong type reach the session.
"""

from __future__ import annotations

import itertools
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, Final

MAX_TEXT: Final = 2000  # characters of a message or an output line shown to the user


class InvalidArguments(ValueError):
    """A request's arguments are missing or of the wrong type (said to the user)."""


@dataclass(frozen=True, slots=True)
class Request:
    seq: int
    command: str
    arguments: Args


def parse_request(message: dict[str, Any]) -> Request | tuple[int | None, str, str]:
    """A request, or ``(seq, command, why)`` for a message that is not a usable one
    (``seq`` is None when it cannot be answered)."""
    seq = message.get("seq")
    command = message.get("command")
    if isinstance(seq, bool) or not isinstance(seq, int):
        return None, "", f"a message without an integer seq: {str(message)[:120]}"
    if message.get("type") != "request":
        return None, "", f"a message of type {str(message.get('type'))[:40]!r} (not a request)"
    if not isinstance(command, str) or not command:
        return None, "", f"request {seq} has no command"
    command = command[:100]
    arguments = message.get("arguments", {})
    if arguments is None:
        arguments = {}
    if not isinstance(arguments, dict):
        return seq, command, "the arguments are not a JSON object"
    return Request(seq, command, Args(arguments))


class Args:
    """A request's arguments, read with a type check each."""

    __slots__ = ("raw",)

    def __init__(self, raw: dict[str, Any]) -> None:
        self.raw = raw

    def _get(self, key: str, kind: type | tuple[type, ...], what: str, default: Any) -> Any:
        value = self.raw.get(key, default)
        if value is None and default is None:
            return None
        if not isinstance(value, kind) or (isinstance(value, bool) and kind is not bool):
            raise InvalidArguments(f"{key!r} must be {what}, not {str(value)[:60]!r}")
        return value

    def text(self, key: str, default: str | None = None) -> str | None:
        value: str | None = self._get(key, str, "a string", default)
        return value

    def integer(self, key: str, default: int | None = None) -> int | None:
        value: int | None = self._get(key, int, "an integer", default)
        return value

    def number(self, key: str, default: float | None = None) -> float | None:
        value = self._get(key, (int, float), "a number", default)
        return None if value is None else float(value)

    def flag(self, key: str, default: bool) -> bool:
        value: bool = self._get(key, bool, "true or false", default)
        return value

    def mapping(self, key: str) -> Args | None:
        value = self._get(key, dict, "an object", None)
        return None if value is None else Args(value)

    def array(self, key: str) -> list[Any] | None:
        value: list[Any] | None = self._get(key, list, "an array", None)
        return value


def _text(text: str) -> str:
    return text if len(text) <= MAX_TEXT else text[: MAX_TEXT - 3] + "..."


class Channel:
    """Sends responses and events with their own ``seq`` numbers, through ``write``."""

    def __init__(self, write: Callable[[dict[str, Any]], None]) -> None:
        self._write = write
        self._seq = itertools.count(1)

    def _send(self, message: dict[str, Any]) -> None:
        self._write({"seq": next(self._seq), **message})

    def respond(self, request: Request, body: dict[str, Any] | None = None) -> None:
        message: dict[str, Any] = {
            "type": "response",
            "request_seq": request.seq,
            "success": True,
            "command": request.command,
        }
        if body is not None:
            message["body"] = body
        self._send(message)

    def fail(self, request_seq: int, command: str, text: str) -> None:
        """An error response; the text is shown to the user."""
        text = _text(text)
        self._send(
            {
                "type": "response",
                "request_seq": request_seq,
                "success": False,
                "command": command,
                "message": text,
                "body": {"error": {"id": 1, "format": text, "showUser": True}},
            }
        )

    def event(self, name: str, body: dict[str, Any] | None = None) -> None:
        message: dict[str, Any] = {"type": "event", "event": name}
        if body is not None:
            message["body"] = body
        self._send(message)

    def output(self, text: str, category: str = "console") -> None:
        """An ``output`` event: a line for the debug console (``stderr`` for trouble,
        ``important`` for what the user must see)."""
        self.event("output", {"category": category, "output": _text(text) + "\n"})
