"""No module of the core (``syntax``, ``rules``, ``ide``) holds mutable state at module
level: the language server's event loop and its worker thread run the same core at once,
and a module-level cache, pool or registry is shared by both without a lock (and makes a
result depend on what ran before).  A cache belongs to the object whose data it derives
from (a section, a document's history, a model) or to an explicit object its owner passes.
"""

from __future__ import annotations

import collections
import functools
import importlib
import pkgutil
import types
import weakref
from collections.abc import Iterator

import bt_lsp.ide
import bt_lsp.rules
import bt_lsp.syntax

# Types that are mutable containers (a subclass of one is too).
_MUTABLE: tuple[type, ...] = (
    dict,
    list,
    set,
    bytearray,
    collections.OrderedDict,
    collections.deque,
    collections.defaultdict,
    weakref.WeakKeyDictionary,
    weakref.WeakValueDictionary,
    weakref.WeakSet,
)

# Module attributes allowed although they hold mutable state, each with why.
ALLOWED: dict[str, str] = {
    # (The registry of diagnostic codes, rules.codes._DEFINED, is filled while the rule
    # modules are imported and made a read-only view once rules.registry imported them.)
    # The one empty result, shared by every section without findings; it refuses to grow.
    "bt_lsp.rules.diagnostics.NO_DIAGNOSTICS": "empty, immutable in effect",
    # Memos of pure functions of strings with immutable results, bounded:
    # functools.lru_cache keeps its table consistent under concurrent calls (documented
    # thread-safe), and what it returns never depends on what ran before.
    "bt_lsp.rules.port_types.canonical": "pure, immutable result",
    "bt_lsp.rules.port_types.is_closed": "pure, immutable result",
    "bt_lsp.rules.script._word_pattern": "pure, compiled pattern",
    "bt_lsp.rules.script.identifier_spans": "pure, immutable result",
    "bt_lsp.rules.semantics.base.edit_distance": "pure, an int",
    "bt_lsp.rules.semantics.ports._allowed": "pure, a bool",
    "bt_lsp.rules.semantics.ports._convert": "pure, immutable result",
    "bt_lsp.rules.semantics.scripts._parse": "pure, immutable result",
    "bt_lsp.ide.blackboard._script_names": "pure, immutable result",
    "bt_lsp.ide.catalog.builtin_catalog": "built once from the built-in tables, immutable",
}


def _modules() -> Iterator[types.ModuleType]:
    for pkg in (bt_lsp.syntax, bt_lsp.rules, bt_lsp.ide):
        yield pkg
        for info in pkgutil.walk_packages(pkg.__path__, pkg.__name__ + "."):
            yield importlib.import_module(info.name)


def _mutable(value: object, depth: int = 0) -> bool:
    """Whether ``value`` is (or, for a tuple, holds) mutable state."""
    if isinstance(value, _MUTABLE) or hasattr(value, "cache_clear"):
        return True
    if isinstance(value, tuple) and depth < 3:
        return any(_mutable(v, depth + 1) for v in value)
    return False


def offenders() -> list[str]:
    """``module.attribute`` of every mutable module attribute that is not allowed, with
    the attribute where it is defined (an import of one is reported once, where it is
    defined)."""
    found: set[str] = set()
    allowed_objects: set[int] = set()
    for where in ALLOWED:
        module_name, _, attr = where.rpartition(".")
        allowed_objects.add(id(getattr(importlib.import_module(module_name), attr)))
    for module in list(_modules()):  # all imported first (the registry freezes the codes)
        for name, value in vars(module).items():
            if name.startswith("__") or isinstance(value, types.ModuleType | type):
                continue
            if not _mutable(value) or id(value) in allowed_objects:
                continue
            home: object = getattr(value, "__module__", None)
            qual: object = getattr(value, "__qualname__", None)
            where = (
                f"{home}.{qual}"
                if callable(value) and isinstance(home, str) and isinstance(qual, str)
                else f"{module.__name__}.{name}"
            )
            if where not in ALLOWED and f"{module.__name__}.{name}" not in ALLOWED:
                found.add(f"{where} ({type(value).__name__})")
    return sorted(found)


def test_no_module_level_mutable_state() -> None:
    assert offenders() == []


def test_the_check_finds_each_kind() -> None:
    """Every kind of state the check looks for is found (so that it cannot pass empty)."""
    kinds: list[object] = [
        {},
        [],
        set(),
        bytearray(),
        collections.OrderedDict(),
        collections.deque(),
        collections.defaultdict(int),
        weakref.WeakKeyDictionary(),
        weakref.WeakValueDictionary(),
        functools.lru_cache(maxsize=4)(len),
        functools.cache(len),
        ((1, []),),
    ]
    assert all(_mutable(k) for k in kinds)
    allowed: list[object] = [
        frozenset(),
        (1, "a"),
        types.MappingProxyType({}),
        "text",
        3,
        len,
    ]
    assert not any(_mutable(a) for a in allowed)


def test_the_codes_registry_is_read_only_after_import() -> None:
    from bt_lsp.rules import codes, registry  # noqa: F401  (imports every code)

    try:
        codes.define("a-late-code", codes.Severity.HINT, "defined after import", "BT")
    except RuntimeError:
        pass
    else:  # pragma: no cover - the failure
        raise AssertionError("a code defined after import was accepted")
