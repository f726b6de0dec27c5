"""Attribute values: their references decoded as tinyxml2 does (:func:`decode_value`), and
where the decoded code points are written in the source (:func:`raw_offsets`): a reference
that :func:`decode_value` replaces is one code point of the value but several characters
of the file (``&amp;&amp;`` is one ``&&``), so a range in the decoded value (a script
error, a blackboard key) maps back through these offsets."""

from __future__ import annotations

import re
from types import MappingProxyType

from bt_lsp.syntax.tokens import UNESCAPED, XML_SYNTAX, Problem

# An entity or character reference (the one definition: the value offsets follow it too).
REFERENCE_RE = re.compile(r"&(#[0-9]+|#x[0-9A-Fa-f]+|[A-Za-z_:][A-Za-z0-9_.:-]*);")
_PREDEFINED = MappingProxyType({"lt": "<", "gt": ">", "amp": "&", "quot": '"', "apos": "'"})


def _char_ref(body: str) -> str | None:
    try:
        cp = int(body[2:], 16) if body[1] == "x" else int(body[1:])
    except ValueError:
        return None
    if cp == 0 or cp > 0x10FFFF or 0xD800 <= cp <= 0xDFFF:
        return None
    return chr(cp)


def _is_nul_ref(body: str) -> bool:
    digits = body[2:] if body[1:2] == "x" else body[1:]
    return digits != "" and set(digits) == {"0"}


def decode_value(raw: str, base: int, problems: list[Problem] | None) -> str:
    """Decode references in an attribute value.

    ``base`` is the raw value's offset (relative to its token) for problem positions.
    BehaviorTree.CPP's tinyxml2 keeps a raw ``&`` or ``<`` as written, so they are
    reported as warnings and kept.  Unknown entities are kept as written: bt-lsp never
    expands DOCTYPE entities.
    """
    if "&" not in raw and "<" not in raw:
        return raw
    if problems is not None:
        pos = raw.find("<")
        while pos != -1:
            problems.append(
                Problem(
                    base + pos,
                    base + pos + 1,
                    UNESCAPED,
                    "Raw '<' in an attribute value; XML requires '&lt;'",
                )
            )
            pos = raw.find("<", pos + 1)
    if "&" not in raw:
        return raw
    out: list[str] = []
    pos = 0
    while True:
        amp = raw.find("&", pos)
        if amp == -1:
            out.append(raw[pos:])
            break
        out.append(raw[pos:amp])
        m = REFERENCE_RE.match(raw, amp)
        if m is None:
            if problems is not None:
                problems.append(
                    Problem(
                        base + amp,
                        base + amp + 1,
                        UNESCAPED,
                        "Raw '&' in an attribute value; XML requires '&amp;'",
                    )
                )
            out.append("&")
            pos = amp + 1
            continue
        body = m.group(1)
        if body[0] == "#":
            ch = _char_ref(body)
            if ch is None:
                if problems is not None:
                    problems.append(
                        Problem(
                            base + amp,
                            base + m.end(),
                            XML_SYNTAX,
                            f"Invalid character reference '{m.group(0)}'",
                        )
                    )
                # A reference to NUL stands for that character in the names it is in (so
                # the name's own rule reports it, as for '&#1;'); others stay as written.
                out.append("\x00" if _is_nul_ref(body) else m.group(0))
            else:
                out.append(ch)
        elif body in _PREDEFINED:
            out.append(_PREDEFINED[body])
        else:
            if problems is not None:
                problems.append(
                    Problem(
                        base + amp,
                        base + m.end(),
                        XML_SYNTAX,
                        f"Undefined entity '&{body};' (bt-lsp never expands DOCTYPE entities)",
                    )
                )
            out.append(m.group(0))
        pos = m.end()
    return "".join(out)


def raw_offsets(raw: str) -> list[int]:
    """Where each code point of the decoded value starts in ``raw``, plus ``len(raw)``.

    ``raw`` is an attribute value as written; decoding follows
    :func:`decode_value`: a reference it replaces becomes one code point,
    anything it keeps as written (a raw ``&``, an unknown entity, an invalid character
    reference) stays one code point per character.
    """
    out: list[int] = []
    n = len(raw)
    pos = 0
    while pos < n:
        amp = raw.find("&", pos)
        if amp == -1:
            out.extend(range(pos, n))
            break
        out.extend(range(pos, amp))
        m = REFERENCE_RE.match(raw, amp)
        if m is None:
            out.append(amp)
            pos = amp + 1
            continue
        if len(decode_value(m.group(0), 0, None)) == 1:
            out.append(amp)
        else:
            out.extend(range(amp, m.end()))
        pos = m.end()
    out.append(n)
    return out


def raw_span(raw: str, start: int, end: int) -> tuple[int, int]:
    """The span of ``raw`` (relative to it) that decodes to ``decoded[start:end]``."""
    if "&" not in raw:
        return start, end
    offs = raw_offsets(raw)
    last = len(offs) - 1
    return offs[min(start, last)], offs[min(end, last)]
