"""Port types as BehaviorTree.CPP compares them: by the C++ type (``typeid``), not by how
the source spells it.

A port's type is the template argument as written (``TaskPtr``, ``std::string``,
``const geometry_msgs::msg::Pose&``).  :func:`canonical` folds the spellings that name
one type (spaces, ``const`` and references at the top, ``std::`` and fixed-width spellings
of built-in types, the ``string`` aliases, ROS message templates); :func:`is_closed` says
whether every name in a type is one bt-lsp knows is not an alias of something else: the
built-in types, the standard library's, BehaviorTree.CPP's and ROS interface types
(``pkg::msg::Name``), and the classes the project's C++ defines.  A port type read from
C++ is compared as :mod:`bt_lsp.cpp.types` resolves it (the project's aliases followed,
its classes qualified); any name left may be a ``using``/``typedef`` from a header bt-lsp
did not read (``TaskPtr`` is ``std::shared_ptr<Task>``), so two types prove a mismatch
only when both are closed.
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from functools import lru_cache
from types import MappingProxyType
from typing import Final

# Built-in types by their usual spellings, to one name per type, as on the LP64 platforms
# ROS runs on.  Fixed-width aliases of one width and signedness count as one type
# (``int64_t`` is ``long`` there, ``long long`` has the same width: treating them as one
# never reports a mismatch that a platform does not have).
_BUILTIN: Final[Mapping[str, str]] = MappingProxyType(
    {
        "bool": "bool",
        "char": "int8",
        "signed char": "int8",
        "int8_t": "int8",
        "unsigned char": "uint8",
        "uint8_t": "uint8",
        "short": "int16",
        "short int": "int16",
        "signed short": "int16",
        "signed short int": "int16",
        "int16_t": "int16",
        "unsigned short": "uint16",
        "unsigned short int": "uint16",
        "uint16_t": "uint16",
        "int": "int",
        "signed": "int",
        "signed int": "int",
        "int32_t": "int",
        "unsigned": "unsigned int",
        "unsigned int": "unsigned int",
        "uint32_t": "unsigned int",
        "long": "int64",
        "long int": "int64",
        "signed long": "int64",
        "signed long int": "int64",
        "long long": "int64",
        "long long int": "int64",
        "signed long long": "int64",
        "int64_t": "int64",
        "ssize_t": "int64",
        "ptrdiff_t": "int64",
        "unsigned long": "uint64",
        "unsigned long int": "uint64",
        "unsigned long long": "uint64",
        "unsigned long long int": "uint64",
        "uint64_t": "uint64",
        "size_t": "uint64",
        "float": "float",
        "double": "double",
        "long double": "long double",
        "string": "std::string",
        "std::string": "std::string",
        "std::__cxx11::string": "std::string",
        "std::basic_string<char>": "std::string",
        "std::basic_string<char, std::char_traits<char>, std::allocator<char> >": "std::string",
        "std::basic_string<char, std::char_traits<char>, std::allocator<char>>": "std::string",
        "std::__cxx11::basic_string<char, std::char_traits<char>, std::allocator<char> >": (
            "std::string"
        ),
        "std::__cxx11::basic_string<char, std::char_traits<char>, std::allocator<char>>": (
            "std::string"
        ),
        "std::string_view": "std::string_view",
        "NodeStatus": "BT::NodeStatus",
        "BT::NodeStatus": "BT::NodeStatus",
    }
)

# Weakly typed ports: BehaviorTree.CPP never compares them.
_WEAK: Final = frozenset({"", "any", "Any", "BT::Any", "AnyTypeAllowed", "BT::AnyTypeAllowed"})

# Standard templates and classes whose names are not aliases of anything else.
_STD: Final = frozenset(
    {
        "std::vector",
        "std::deque",
        "std::list",
        "std::set",
        "std::map",
        "std::unordered_map",
        "std::unordered_set",
        "std::pair",
        "std::tuple",
        "std::array",
        "std::optional",
        "std::shared_ptr",
        "std::unique_ptr",
        "std::weak_ptr",
        "std::function",
        "std::chrono::milliseconds",
        "std::chrono::seconds",
        "std::chrono::nanoseconds",
        "std::chrono::microseconds",
        "std::chrono::duration",
    }
)

# A ROS 2 interface type (``pkg::msg::Name``), as generated: never an alias.
_ROS_INTERFACE: Final = re.compile(r"[A-Za-z_]\w*::(?:msg|srv|action)::[A-Za-z_]\w*")
_ROS_TEMPLATE: Final = re.compile(r"(?P<t>[A-Za-z_]\w*::(?:msg|srv|action)::[A-Za-z_]\w*)_")
_ROS_POINTER: Final = re.compile(
    r"(?P<t>[A-Za-z_]\w*::(?:msg|srv|action)::[A-Za-z_]\w*)::(?P<p>SharedPtr|ConstSharedPtr|UniquePtr)"
)
_NAME: Final = re.compile(r"[A-Za-z_][\w:]*")
_STD_PREFIXED: Final = re.compile(r"std::((?:u?int(?:8|16|32|64)_t)|size_t|ptrdiff_t)\b")


def _split_args(inner: str) -> list[str] | None:
    """The top-level comma-separated arguments of a template argument list."""
    out: list[str] = []
    depth = 0
    start = 0
    for i, c in enumerate(inner):
        if c in "<([":
            depth += 1
        elif c in ">)]":
            depth -= 1
            if depth < 0:
                return None
        elif c == "," and depth == 0:
            out.append(inner[start:i])
            start = i + 1
    if depth != 0:
        return None
    out.append(inner[start:])
    return out


def _strip_top(t: str) -> str:
    """``t`` without top-level ``const``/``volatile``, references, ``typename`` and a
    leading ``::``."""
    t = t.strip()
    while True:
        before = t
        t = t.removesuffix("&").removesuffix("&").strip()
        for word in ("const", "volatile", "typename", "struct", "class"):
            if t.startswith(word + " "):
                t = t[len(word) + 1 :].strip()
            if t.endswith(" " + word):
                t = t[: -len(word) - 1].strip()
        t = t.removeprefix("::")
        if t == before:
            return t


@lru_cache(maxsize=4096)
def canonical(type_: str) -> str | None:
    """One spelling per C++ type, or ``None`` for a weakly typed port (``AnyTypeAllowed``,
    ``BT::Any``, no type)."""
    t = " ".join(type_.split())
    if t in _WEAK:
        return None
    return _canonical(t)


def _canonical(t: str) -> str:
    t = _strip_top(t)
    t = _STD_PREFIXED.sub(r"\1", t)
    t = re.sub(r"\s*([<>,:*&])\s*", r"\1", t).replace(",", ", ")
    if t in _BUILTIN:
        return _BUILTIN[t]
    spaced = t.replace(">>", "> >")
    if spaced in _BUILTIN:
        return _BUILTIN[spaced]
    m = _ROS_POINTER.fullmatch(t)
    if m is not None:
        inner = m.group("t")
        p = m.group("p")
        if p == "UniquePtr":
            return f"std::unique_ptr<{inner}>"
        return f"std::shared_ptr<{'const ' if p == 'ConstSharedPtr' else ''}{inner}>"
    lt = t.find("<")
    if lt > 0 and t.endswith(">"):
        name = t[:lt].strip()
        args = _split_args(t[lt + 1 : -1])
        if args is not None:
            ros = _ROS_TEMPLATE.fullmatch(name)
            if ros is not None:  # pkg::msg::Name_<std::allocator<void>> is pkg::msg::Name
                return ros.group("t")
            parts = [_canonical_arg(a) for a in args]
            if name in ("std::vector", "std::deque", "std::list") and len(parts) == 2:
                parts = parts[:1]  # the default allocator
            return f"{name}<{', '.join(parts)}>"
    return t


def _canonical_arg(a: str) -> str:
    a = " ".join(a.split())
    const = a.startswith("const ") or a.endswith(" const")
    inner = _canonical(a)
    return f"const {inner}" if const else inner


@lru_cache(maxsize=4096)
def is_closed(canon: str, classes: frozenset[str] = frozenset()) -> bool:
    """Whether every name in the canonical type ``canon`` is known not to be an alias.

    ``classes`` are class definitions the project's C++ holds (qualified names, as
    :mod:`bt_lsp.cpp.types` writes them into a resolved type): not aliases either.
    """
    if canon in _BUILTIN.values():
        return True
    for m in _NAME.finditer(canon):
        name = m.group(0)
        if name == "const":
            continue
        if name in _BUILTIN or name in _BUILTIN.values() or name in _STD or name in classes:
            continue
        if _ROS_INTERFACE.fullmatch(name):
            continue
        return False
    return True
