"""A port default written as a C++ number or bool literal, as BehaviorTree.CPP shows it.

``InputPort<T>(name, default, description)`` stores the default converted to ``T`` and
its text as ``BT::toStr`` writes it (4.x ``PortInfo::setDefaultValue``; 3.x the same
through ``toStr``): ``std::to_string`` of an arithmetic value, so ``0.7f`` for a
``double`` port is ``0.700000``, ``1e3`` for an ``int`` port ``1000``, and ``true``
stays ``true``.  A port of another type (an enum, a ``std::chrono`` duration, a custom
type) keeps the literal as written: what its conversion prints is not known here.
"""

from __future__ import annotations

import re
import struct
from typing import Final

_FLOATS: Final = frozenset({"double", "float", "long double"})
# Integer types and their width in bits (LP64), for a negative value in an unsigned type.
_SIGNED: Final = frozenset(
    {
        "int",
        "signed",
        "signed int",
        "long",
        "long int",
        "long long",
        "long long int",
        "short",
        "short int",
        "int8_t",
        "int16_t",
        "int32_t",
        "int64_t",
        "ssize_t",
        "ptrdiff_t",
    }
)
_UNSIGNED: Final[dict[str, int]] = {
    "unsigned": 32,
    "unsigned int": 32,
    "uint32_t": 32,
    "unsigned long": 64,
    "unsigned long int": 64,
    "unsigned long long": 64,
    "unsigned long long int": 64,
    "uint64_t": 64,
    "size_t": 64,
    # to_string promotes these to int: the value modulo their width
    "unsigned short": 16,
    "uint16_t": 16,
    "uint8_t": 8,
}
_UNTYPED: Final = frozenset({"", "AnyTypeAllowed", "BT::AnyTypeAllowed", "std::string", "string"})
_INT: Final = re.compile(r"([-+]?)(0[xX][0-9a-fA-F]+|0[bB][01]+|0[0-7]*|[1-9][0-9]*)([uUlLzZ]*)")
_FLOAT: Final = re.compile(
    r"([-+]?)((?:[0-9]+\.[0-9]*|\.[0-9]+|[0-9]+)(?:[eE][-+]?[0-9]+)?)([fFlL]?)"
)


def _number(text: str) -> tuple[int | float, bool] | None:
    """The value of a number literal and whether it is a ``float`` (``f`` suffix)."""
    t = text.replace("'", "")
    m = _INT.fullmatch(t)
    if m is not None:
        digits = m.group(2)
        if digits[:2] in ("0x", "0X"):
            v = int(digits[2:], 16)
        elif digits[:2] in ("0b", "0B"):
            v = int(digits[2:], 2)
        elif digits.startswith("0") and len(digits) > 1:
            v = int(digits[1:], 8)
        else:
            v = int(digits)
        return (-v if m.group(1) == "-" else v), False
    m = _FLOAT.fullmatch(t)
    if m is not None and ("." in m.group(2) or "e" in m.group(2).lower()):
        f = float(m.group(2))
        f = -f if m.group(1) == "-" else f
        return f, m.group(3) in ("f", "F")
    return None


def _f32(v: float) -> float:
    return float(struct.unpack("f", struct.pack("f", v))[0])


def _normal(type_: str) -> str:
    t = re.sub(r"\bconst\b", "", type_).strip()
    return re.sub(r"^(?:::)?std::", "", t).strip()


def to_str(literal: str, type_: str) -> str:
    """``literal`` (a C++ number or ``true``/``false``) as BehaviorTree.CPP shows the default
    of a port of ``type_``; the literal itself when that is not known."""
    t = _normal(type_)
    if literal in ("true", "false"):
        if t in _UNTYPED or t == "bool":
            return literal
        if t in _FLOATS:
            return "%f" % (1.0 if literal == "true" else 0.0)
        if t in _SIGNED or t in _UNSIGNED:
            return "1" if literal == "true" else "0"
        return literal
    found = _number(literal)
    if found is None:
        return literal
    value, single = found
    if t in _UNTYPED:  # the literal's own type
        if isinstance(value, float):
            return "%f" % (_f32(value) if single else value)
        return str(value)
    if t == "bool":
        return "true" if value else "false"
    if t in _FLOATS:
        return "%f" % (_f32(float(value)) if t == "float" else float(value))
    if t in _SIGNED or t in _UNSIGNED:
        n = int(value)  # a float converted to an integer drops its fraction
        if t in _UNSIGNED and n < 0:
            n %= 1 << _UNSIGNED[t]
        return str(n)
    return literal
