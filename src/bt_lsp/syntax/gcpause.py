"""Making many objects at once without the cyclic garbage collector in the way.

Scanning and analysing a large document makes hundreds of thousands of small objects
(tokens, attributes, elements, names), none of them in reference cycles, so reference
counting frees them.  With the collector on, every few hundred allocations start a
collection, and the older generations are scanned again and again while they grow: a
third of the time of a first analysis, and a full collection of a 4 MB document's objects
takes a third of a second.  :func:`gc_paused` pauses the collector for such a phase.  When it
made a large document's worth of objects, they are moved to the permanent generation
(``gc.freeze()`` moves lists), which the collector never scans again: they are still
freed by reference counting, only garbage in cycles would stay, and the core makes none.
"""

from __future__ import annotations

import gc
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from functools import wraps
from typing import ParamSpec, TypeVar

__all__ = ["gc_paused", "with_gc_paused"]

P = ParamSpec("P")
R = TypeVar("R")


@contextmanager
def gc_paused() -> Iterator[None]:
    """Pause the cyclic garbage collector (nested uses and a collector turned off by the
    program are left alone)."""
    if not gc.isenabled():
        yield
        return
    gc.disable()
    try:
        yield
    finally:
        if gc.get_count()[0] >= LARGE:
            gc.freeze()
        gc.enable()


# New objects (tracked by the collector) that make a bulk phase large.
LARGE = 100_000


def with_gc_paused(func: Callable[P, R]) -> Callable[P, R]:
    """``func`` with the collector paused (see :func:`gc_paused`)."""

    @wraps(func)
    def wrapper(*args: P.args, **kwargs: P.kwargs) -> R:
        with gc_paused():
            return func(*args, **kwargs)

    return wrapper
