"""BehaviorTree.CPP's string conversions: whether a literal attribute value would survive
the ``convertFromString<T>()`` call BehaviorTree.CPP makes for a typed input port
(:func:`convert_literal`), and what is not a literal at all (a blackboard reference,
:func:`is_blackboard_reference`)."""

from __future__ import annotations

import math
import re
from collections.abc import Mapping
from types import MappingProxyType
from typing import Final

_BOOL_WORDS: Final = frozenset({"1", "0", "true", "false", "True", "False", "TRUE", "FALSE"})
_NODE_STATUS_WORDS: Final = ("SUCCESS", "FAILURE", "RUNNING", "IDLE", "SKIPPED")

# (minimum, maximum, parsed like an unsigned 64-bit value). The narrower integer types go
# through a signed 64-bit parse plus a bound check, so "-1" is rejected by the bound check;
# the 64-bit unsigned type is parsed directly and rejects a leading "-" outright.
_INT_RANGES: Final[Mapping[str, tuple[int, int, bool]]] = MappingProxyType(
    {
        "int8": (-(2**7), 2**7 - 1, False),
        "uint8": (0, 2**8 - 1, False),
        "int16": (-(2**15), 2**15 - 1, False),
        "uint16": (0, 2**16 - 1, False),
        "int32": (-(2**31), 2**31 - 1, False),
        "uint32": (0, 2**32 - 1, False),
        "int64": (-(2**63), 2**63 - 1, False),
        "uint64": (0, 2**64 - 1, True),
    }
)

_TYPE_ALIASES: Final[Mapping[str, str]] = MappingProxyType(
    {
        "signed char": "int8",
        "int8_t": "int8",
        "unsigned char": "uint8",
        "uint8_t": "uint8",
        "short": "int16",
        "short int": "int16",
        "int16_t": "int16",
        "unsigned short": "uint16",
        "unsigned short int": "uint16",
        "uint16_t": "uint16",
        "int": "int32",
        "signed int": "int32",
        "int32_t": "int32",
        "unsigned": "uint32",
        "unsigned int": "uint32",
        "uint32_t": "uint32",
        "long": "int64",
        "long int": "int64",
        "long long": "int64",
        "long long int": "int64",
        "int64_t": "int64",
        "unsigned long": "uint64",
        "unsigned long int": "uint64",
        "unsigned long long": "uint64",
        "unsigned long long int": "uint64",
        "uint64_t": "uint64",
        "size_t": "uint64",
        "double": "double",
        "float": "float",
        "bool": "bool",
        "NodeStatus": "NodeStatus",
        "std::string": "string",
        "string": "string",
        "std::string_view": "string",
        "BT::StringView": "string",
        "StringView": "string",
        "any": "any",
        "Any": "any",
        "AnyTypeAllowed": "any",
    }
)

_FLOAT_MAX: Final = 3.4028234663852886e38
_FLOAT_MIN_NORMAL: Final = 1.1754943508222875e-38
_DOUBLE_MIN_NORMAL: Final = 2.2250738585072014e-308

# What strtod() reads (C locale), anchored at the start: optional sign, then a decimal
# float, a hexadecimal float, INF/INFINITY or NAN/NAN(chars). Leading white space is
# skipped separately.
_STRTOD_PREFIX: Final = re.compile(
    r"""
    [+-]?
    (?:
        0[xX](?:[0-9a-fA-F]+(?:\.[0-9a-fA-F]*)?|\.[0-9a-fA-F]+)(?:[pP][+-]?[0-9]+)?
      | (?:[0-9]+(?:\.[0-9]*)?|\.[0-9]+)(?:[eE][+-]?[0-9]+)?
      | [iI][nN][fF](?:[iI][nN][iI][tT][yY])?
      | [nN][aA][nN](?:\([0-9A-Za-z_]*\))?
    )
    """,
    re.VERBOSE,
)
_C_SPACE: Final = " \t\n\v\f\r"


def _normalize_type(type_: str) -> str | None:
    t = " ".join(type_.split())
    if t.startswith("BT::"):
        t = t[len("BT::") :]
    if t.startswith("std::") and t[len("std::") :] in _TYPE_ALIASES and t.endswith("_t"):
        t = t[len("std::") :]
    if t.startswith("std::vector<") and t.endswith(">"):
        inner = _normalize_type(t[len("std::vector<") : -1])
        if inner in ("int32", "double", "bool", "string"):
            return f"vector:{inner}"
        return None
    return _TYPE_ALIASES.get(t)


def is_blackboard_reference(value: str) -> bool:
    """Whether BehaviorTree.CPP reads ``value`` as a blackboard key rather than a literal
    when a node reads the port (``getInput``) and when it creates the tree's entries.

    Mirrors ``TreeNode::getRemappedKey``: exactly ``=`` or ``{=}`` (the key named like the
    port), or ``isBlackboardPointer``: after trimming the spaces around it the text has at least
    three characters and is wrapped in ``{`` ``}`` (``{}`` is a literal).  Version 4 also
    converts every literal of a typed port when it creates the tree, and there only the
    exact form ``{…}`` is a reference (:func:`is_converted_as_reference`).
    """
    if value == "=":
        return True
    stripped = value.strip(" ")
    return len(stripped) >= 3 and stripped[0] == "{" and stripped[-1] == "}"


def is_converted_as_reference(value: str) -> bool:
    """Whether BehaviorTree.CPP 4 skips ``value`` when it converts the literals of typed
    ports at tree creation: exactly ``{…}``, three characters at least, nothing around the
    braces (``XMLParser``'s own test, not ``isBlackboardPointer``).  So ``" {a} "`` and
    ``"="``, references to a string port, fail to convert for an ``int`` port."""
    return len(value) >= 3 and value[0] == "{" and value[-1] == "}"


def converted_at_creation(type_: str) -> bool:
    """Whether BehaviorTree.CPP 4 converts a literal of a port of ``type_`` when it
    creates the tree.  An enum port (``NodeStatus``) has no string converter in its
    ``PortInfo``: its literal is converted (through the registered enums) only when the
    node reads the port, where a bad one fails the node (4.8.2: ``else="xyz"`` of
    ``Precondition`` is "Missing parameter [else]" at tick)."""
    return _normalize_type(type_) != "NodeStatus"


def blackboard_key(port: str, value: str) -> str | None:
    """The blackboard key a port given ``value`` uses (``TreeNode::getRemappedKey``), or
    ``None`` for a literal: the port's own name for ``=`` and ``{=}``, else the text
    between the braces exactly as written (``{ a }`` is the key ``" a "``, not ``"a"``:
    only the spaces outside the braces are trimmed)."""
    if value in ("=", "{=}"):
        return port
    stripped = value.strip(" ")
    if len(stripped) >= 3 and stripped[0] == "{" and stripped[-1] == "}":
        return stripped[1:-1]
    return None


def _leading_int(value: str, unsigned_parse: bool) -> tuple[int | None, bool]:
    """Like ``std::from_chars`` (base 10): the leading integer and whether all was used."""
    i = 0
    negative = False
    if value.startswith("-") and not unsigned_parse:
        negative = True
        i = 1
    j = i
    while j < len(value) and "0" <= value[j] <= "9":
        j += 1
    if j == i:
        return None, False
    digits = value[i:j].lstrip("0") or "0"
    if len(digits) > 40:  # far outside any 64-bit range; avoids huge int() conversions
        digits = "9" * 40
    number = int(digits)
    return (-number if negative else number), j == len(value)


def _convert_int(value: str, kind: str, strict: bool) -> str | None:
    low, high, unsigned_parse = _INT_RANGES[kind]
    number, complete = _leading_int(value, unsigned_parse)
    if number is None:
        return f"'{value}' is not an integer"
    parse_low, parse_high = (0, 2**64 - 1) if unsigned_parse else (-(2**63), 2**63 - 1)
    if not parse_low <= number <= parse_high:
        return f"'{value}' is out of range for a 64-bit integer"
    if not low <= number <= high:
        return f"{number} is out of range [{low}, {high}]"
    if strict and not complete:
        return f"'{value}' has extra characters after the integer {number}"
    return None


def _convert_real(value: str, is_float: bool, strict: bool) -> str | None:
    text = value.lstrip(_C_SPACE)
    match = _STRTOD_PREFIX.match(text)
    if match is None:
        return f"'{value}' is not a number"
    token = match.group(0)
    lowered = token.lower().lstrip("+-")
    if not lowered.startswith(("inf", "nan")):
        try:
            number = float.fromhex(token) if lowered.startswith("0x") else float(token)
        except (ValueError, OverflowError):
            number = math.inf
        magnitude = abs(number)
        largest = _FLOAT_MAX if is_float else math.inf
        smallest = _FLOAT_MIN_NORMAL if is_float else _DOUBLE_MIN_NORMAL
        if math.isinf(number) or magnitude > largest or 0 < magnitude < smallest:
            return f"'{value}' is out of range for {'float' if is_float else 'double'}"
        if magnitude == 0 and _has_nonzero_digit(token):
            return f"'{value}' is out of range for {'float' if is_float else 'double'}"
    if strict and len(token) != len(text):
        return f"'{value}' has extra characters after the number {token}"
    return None


def _has_nonzero_digit(token: str) -> bool:
    mantissa = re.split(r"[eEpP]", token.lower().lstrip("+-"), maxsplit=1)[0]
    mantissa = mantissa.removeprefix("0x")
    return any(c not in "0." for c in mantissa)


def _convert_scalar(value: str, kind: str, strict: bool) -> str | None:
    if kind in _INT_RANGES:
        return _convert_int(value, kind, strict)
    if kind == "double":
        return _convert_real(value, False, strict)
    if kind == "float":
        return _convert_real(value, True, strict)
    if kind == "bool":
        if value in _BOOL_WORDS:
            return None
        return f"'{value}' is not a bool (use true/false, True/False, TRUE/FALSE, 1 or 0)"
    if kind == "NodeStatus":
        if value in _NODE_STATUS_WORDS:
            return None
        return f"'{value}' is not a NodeStatus (use one of {', '.join(_NODE_STATUS_WORDS)})"
    return None


def convert_literal(value: str, type: str, *, strict: bool = False) -> str | None:
    """Why a literal port value can't be converted to ``type``, or ``None`` if it can.

    Follows BehaviorTree.CPP's ``convertFromString<T>()``:

    * integers (``int``, ``unsigned int``, ``long``, ``int8_t`` ...): base 10 only, an
      optional ``-`` (no ``+``, no leading space, no ``0x``), then the type's range. Like
      ``std::from_chars``, only a leading integer has to be present: ``"12abc"`` and
      ``"1.5"`` are accepted (as 12 and 1) unless ``strict`` is true;
    * ``double`` / ``float``: what ``strtod`` reads after leading white space (decimal or
      hexadecimal float, ``inf``, ``nan``); overflow and underflow are errors; trailing
      text is accepted unless ``strict``;
    * ``bool``: exactly ``true false True False TRUE FALSE 1 0``;
    * ``NodeStatus``: exactly ``SUCCESS FAILURE RUNNING IDLE SKIPPED``;
    * ``std::vector<int|double|bool|std::string>``: each ``;``-separated item as above;
    * ``std::string``, ``any`` and every type not listed: always fine.

    Values that version 4 does not convert at tree creation (``{key}``, ``{=}``: see
    :func:`is_converted_as_reference`) and ``json:`` values give ``None``.
    """
    if is_converted_as_reference(value) or value.startswith("json:"):
        return None
    kind = _normalize_type(type)
    if kind is None or kind in ("string", "any"):
        return None
    if kind.startswith("vector:"):
        item_kind = kind.removeprefix("vector:")
        for item in _split_items(value):
            problem = _convert_scalar(item, item_kind, strict)
            if problem is not None:
                return f"item {problem}"
        return None
    return _convert_scalar(value, kind, strict)


def convert_queue(value: str, item_type: str) -> str | None:
    """Why a literal ``queue`` of ``LoopInt``/``LoopDouble``/``LoopBool`` cannot be
    converted to ``SharedQueue<item_type>``, or ``None`` if it can: each ``;``-separated
    item goes through ``convertFromString<item_type>`` (``json:`` is not special here)."""
    kind = _normalize_type(item_type)
    if kind is None or kind in ("string", "any"):
        return None
    for item in _split_items(value):
        problem = _convert_scalar(item, kind, False)
        if problem is not None:
            return f"item {problem}"
    return None


def _split_items(value: str) -> list[str]:
    """``splitString(value, ';')``: no item for an empty tail, so "1;2;" has two items."""
    items: list[str] = []
    pos = 0
    while pos < len(value):
        end = value.find(";", pos)
        if end < 0:
            end = len(value)
        items.append(value[pos:end])
        pos = end + 1
    return items
