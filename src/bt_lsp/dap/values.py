"""Blackboard values (decoded MessagePack: maps, arrays, text, numbers, bytes) as DAP
variables, each container given a ``variablesReference`` to expand it by.

The values come from the executor, so they are untrusted: each shown value is cut to
:data:`MAX_VALUE` characters, a container lists at most :data:`MAX_CHILDREN` entries
(then one line saying how many more), and a stop hands out at most :data:`MAX_REFS`
references.
"""

from __future__ import annotations

import json
import math
from collections.abc import Sequence
from typing import Any, Final

MAX_VALUE: Final = 500
MAX_CHILDREN: Final = 1000
MAX_REFS: Final = 100_000


def _cut(text: str) -> str:
    return text if len(text) <= MAX_VALUE else text[: MAX_VALUE - 3] + "..."


def show(value: Any) -> tuple[str, str]:
    """The value as the debugger shows it, and its type's name."""
    if value is None:
        return "null", "null"
    if isinstance(value, bool):
        return ("true" if value else "false"), "bool"
    if isinstance(value, int):
        return str(value), "int"
    if isinstance(value, float):
        return (repr(value) if math.isfinite(value) else str(value)), "float"
    if isinstance(value, str):
        return _cut(json.dumps(value, ensure_ascii=False)), "string"
    if isinstance(value, bytes):
        return _cut(f"bytes({len(value)}) {value[:100].hex(' ')}"), "bytes"
    if isinstance(value, dict):
        return f"{{{len(value)} entries}}", "map"
    if isinstance(value, list):
        return f"[{len(value)} items]", "array"
    return _cut(repr(value)), type(value).__name__


class References:
    """The containers handed out as ``variablesReference`` during one stop (1-based)."""

    def __init__(self) -> None:
        self._items: list[Any] = []

    def add(self, item: Any) -> int:
        """A new reference for ``item``; 0 (not expandable) once the limit is reached."""
        if len(self._items) >= MAX_REFS:
            return 0
        self._items.append(item)
        return len(self._items)

    def get(self, ref: int) -> Any:
        """The item of a reference, or None for one this stop did not hand out."""
        if 1 <= ref <= len(self._items):
            return self._items[ref - 1]
        return None

    def clear(self) -> None:
        self._items.clear()


def variable(name: str, value: Any, refs: References) -> dict[str, Any]:
    text, kind = show(value)
    container = isinstance(value, (dict, list)) and len(value) > 0
    out: dict[str, Any] = {
        "name": _cut(name),
        "value": text,
        "type": kind,
        "variablesReference": refs.add(value) if container else 0,
    }
    if isinstance(value, list) and value:
        out["indexedVariables"] = len(value)
    return out


def children(value: Any, refs: References, start: int = 0, count: int = 0) -> list[dict[str, Any]]:
    """The entries of a map or array as variables (``start``/``count`` page an array)."""
    items: Sequence[tuple[str, Any]]
    if isinstance(value, dict):
        items = [(str(k), v) for k, v in value.items()]
    elif isinstance(value, list):
        items = [(f"[{i}]", v) for i, v in enumerate(value)]
    else:
        return []
    start = max(0, start)
    stop = len(items) if count <= 0 else min(len(items), start + count)
    shown = items[start : min(stop, start + MAX_CHILDREN)]
    out = [variable(name, v, refs) for name, v in shown]
    rest = stop - start - len(shown)
    if rest > 0:
        out.append({"name": "...", "value": f"{rest} more not shown", "variablesReference": 0})
    return out
