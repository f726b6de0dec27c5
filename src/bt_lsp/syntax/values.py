"""Where the decoded code points of an attribute value are written in the source: a
reference that :func:`bt_lsp.syntax.scanner.decode_value` replaces is one code point of the
value but several characters of the file (``&amp;&amp;`` is one ``&&``), so a range in
the decoded value (a script error, a blackboard key) maps back through these offsets."""

from __future__ import annotations

from bt_lsp.syntax.scanner import REFERENCE_RE, decode_value


def raw_offsets(raw: str) -> list[int]:
    """Where each code point of the decoded value starts in ``raw``, plus ``len(raw)``.

    ``raw`` is an attribute value as written; decoding follows
    :func:`bt_lsp.syntax.scanner.decode_value`: a reference it replaces becomes one code point,
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
