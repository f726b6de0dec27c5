"""A tolerant, position-exact, incremental scanner for BT XML.

The text is cut into a flat list of top-level tokens: text runs, start tags (with their
attributes), end tags, comments, CDATA sections, processing instructions, DOCTYPEs and
stray ``<``.  Between tokens the scanner has no state, and a token's result depends only
on the text from its start up to its ``reach``.  That makes re-scanning after an edit
cheap and exact: start again at the first token whose reach touches the edit, stop as
soon as a new token starts where an old one (shifted by the edit) started after the
edit, and reuse the rest.  A property test checks incremental == full scan.

Offsets inside a token are relative to the token's start, so reused tokens are shared
unchanged; the absolute starts are kept in blocks (:class:`bt_lsp.syntax.text.Offsets`), so an
edit moves the blocks after it, not each start.

The scanner never raises, never recurses, always advances and is linear: every loop
either consumes text or stops.  It expands nothing: entity references other than XML's
five and character references are left as written, DOCTYPEs are skipped whole.
"""

from __future__ import annotations

import re
from array import array
from dataclasses import dataclass
from types import MappingProxyType
from typing import TypeVar

from bt_lsp.syntax.tag_limits import MAX_ATTRS, MAX_TAG_PROBLEMS, TagLimits
from bt_lsp.syntax.text import Offsets
from bt_lsp.syntax.tokens import DOCTYPE_CODE, LENIENT, XML_SYNTAX, Attr, Kind, Problem, Token
from bt_lsp.syntax.values import decode_value

# Read for every start tag: a module global is quicker than a member read from its enum
# class in Python 3.11.
_START = Kind.START


# Characters that end a tag or attribute name.  Anything else is part of the name, so
# that names breaking the naming rules (``Open.Door``, ``a*b``) are still found whole.
_NAME_STOP = " \t\r\n/>=<\"'"
_NAME_RE = re.compile(r"[^ \t\r\n/>=<\"']+")
_WS_RE = re.compile(r"[ \t\r\n]*")
# Well-formed start tag, the common case, read by three anchored patterns: its name, each
# attribute, its end.  (One pattern for the whole tag, with the attributes as a repeated
# group, needs memory for every repetition: half a gigabyte for a million attributes.)
# Values may not hold '<' (the slow path handles and reports those).
_FAST_NAME_RE = re.compile(r"<([^ \t\r\n/>=<\"']+)")
_FAST_CLOSE_RE = re.compile(r"[ \t\r\n]*(/?)>")
_FAST_END_RE = re.compile(r"</([^ \t\r\n/>=<\"']+)[ \t\r\n]*>")
_FAST_ATTR_RE = re.compile(
    r"[ \t\r\n]+([^ \t\r\n/>=<\"']+)[ \t\r\n]*=[ \t\r\n]*(?:\"([^\"<]*)\"|'([^'<]*)')"
)
# An unterminated attribute value ends at its quote or before a line that starts a tag.
_VALUE_END_RE = MappingProxyType(
    {q: re.compile(q + r"|[\r\n][ \t\r\n]*<(?=[A-Za-z_:/!?]|[^\x00-\x7f])") for q in "\"'"}
)
_STRAY_QUOTE_END = MappingProxyType({q: re.compile(f"[{q}<]") for q in "\"'"})
_UNQUOTED_RE = re.compile(r"[^ \t\r\n<>]*")

# Makes a named tuple from all its fields without the Python-level constructor (three times
# quicker, for the hot paths).
_new = tuple.__new__

_SHARED_MAX = 8192
# Short attribute values are shared: blackboard keys, types and literals recur all over a
# document (a megabyte of BT XML has three times as many values as distinct ones).
_SHARED_VALUE_LENGTH = 16

_T = TypeVar("_T")


class ScanPools:
    """Equal pieces of the tokens of one scan, made once (each pool bounded): text runs by
    length, end tags and start tags without attributes by their text, tag and attribute
    names, short attribute values, and attributes (relative to their tag).  A scan makes
    its own (:func:`scan`, :func:`rescan`): never shared between threads."""

    __slots__ = (
        "attrs",
        "end_tokens",
        "names",
        "older_attrs",
        "older_names",
        "older_values",
        "start_tokens",
        "text_tokens",
        "values",
    )

    def __init__(self) -> None:
        self.text_tokens: dict[int, Token] = {}
        self.end_tokens: dict[str, Token] = {}
        self.start_tokens: dict[str, Token] = {}
        self.names: dict[str, str] = {}
        self.values: dict[str, str] = {}
        self.attrs: dict[Attr, Attr] = {}
        self.older_names: dict[str, str] = {}
        self.older_values: dict[str, str] = {}
        self.older_attrs: dict[Attr, Attr] = {}

    def text_token(self, length: int) -> Token:
        """A text run followed by '<' (its scan looked at that '<' too)."""
        pool = self.text_tokens
        tok = pool.get(length)
        if tok is None:
            if len(pool) >= _SHARED_MAX:
                pool.clear()
            tok = pool[length] = Token(Kind.TEXT, length, length + 1)
        return tok

    def name(self, name: str) -> str:
        return self.names.get(name) or _keep(self.names, self.older_names, name)

    def value(self, raw: str) -> str:
        if len(raw) > _SHARED_VALUE_LENGTH:
            return raw
        return self.values.get(raw) or _keep(self.values, self.older_values, raw)

    def attr(self, attr: Attr) -> Attr:
        return self.attrs.get(attr) or _keep(self.attrs, self.older_attrs, attr)


def _keep(pool: dict[_T, _T], older: dict[_T, _T], x: _T) -> _T:
    """The shared object equal to ``x`` (``x`` itself if none), kept in ``pool`` for the
    next equal one (``pool.get`` is the quick look-up).  A full pool becomes ``older``
    and starts again empty; what is found in ``older`` comes back into the pool, so that
    what the text being scanned shares stays shared however the pools fill."""
    found = older.pop(x, x)
    if len(pool) >= _SHARED_MAX:
        older.clear()
        older.update(pool)
        pool.clear()
    pool[found] = found
    return found


def _scan_text(text: str, pos: int, n: int, pools: ScanPools) -> Token:
    end = text.find("<", pos)
    if end == -1:
        return Token(Kind.TEXT, n - pos, n - pos)
    return pools.text_token(end - pos)


def _scan_delimited(
    text: str, pos: int, n: int, kind: Kind, opener: str, closer: str, what: str
) -> Token:
    end = text.find(closer, pos + len(opener))
    if end == -1:
        return Token(
            kind,
            n - pos,
            n - pos,
            closed=False,
            problems=(
                Problem(0, len(opener), XML_SYNTAX, f"Unterminated {what}: missing '{closer}'"),
            ),
        )
    length = end + len(closer) - pos
    name = ""
    if kind == Kind.PI:
        m = _NAME_RE.match(text, pos + 2, end)
        name = m.group(0) if m else ""
    return Token(kind, length, length, name=name)


def _scan_doctype(text: str, pos: int, n: int) -> Token:
    """Skip a DOCTYPE whole (internal subset, quoted strings); never interpret it."""
    i = pos + 9
    depth = 0
    quote = ""
    while i < n:
        c = text[i]
        if quote:
            j = text.find(quote, i)
            if j == -1:
                i = n
                break
            i = j + 1
            quote = ""
            continue
        if c in "\"'":
            quote = c
        elif c == "[":
            depth += 1
        elif c == "]":
            depth = max(0, depth - 1)
        elif c == ">" and depth == 0:
            length = i + 1 - pos
            return Token(
                Kind.DOCTYPE,
                length,
                length,
                name="DOCTYPE",
                problems=(
                    Problem(
                        0,
                        9,
                        DOCTYPE_CODE,
                        "DOCTYPE ignored: its entities and external DTDs are never "
                        "expanded or fetched",
                    ),
                ),
            )
        i += 1
    return Token(
        Kind.DOCTYPE,
        n - pos,
        n - pos,
        name="DOCTYPE",
        closed=False,
        problems=(Problem(0, 9, XML_SYNTAX, "Unterminated DOCTYPE: missing '>'"),),
    )


def _scan_end_tag(text: str, pos: int, n: int, pools: ScanPools) -> Token:
    m = _FAST_END_RE.match(text, pos)
    if m is not None:  # the common case: shared
        key = m.group(0)
        shared = pools.end_tokens
        tok = shared.get(key)
        if tok is None:
            if len(shared) >= _SHARED_MAX:
                shared.clear()
            name = pools.name(m.group(1))
            length = len(key)
            tok = shared[key] = Token(Kind.END, length, length + 1, name, 2, 2 + len(name))
        return tok
    problems: list[Problem] = []
    m = _NAME_RE.match(text, pos + 2)
    if m is None:
        name, ns, ne = "", 2, 2
        problems.append(Problem(0, 2, XML_SYNTAX, "End tag without a name"))
        i = pos + 2
    else:
        name, ns, ne = m.group(0), 2, m.end() - pos
        i = m.end()
    i = _WS_RE.match(text, i).end()  # type: ignore[union-attr]
    if i < n and text[i] == ">":
        length = i + 1 - pos
        return Token(
            Kind.END,
            length,
            length + 1,
            name=name,
            name_start=ns,
            name_end=ne,
            problems=tuple(problems),
        )
    length = i - pos
    problems.append(
        Problem(
            ns, ne if ne > ns else 2, XML_SYNTAX, f"End tag '</{name}' is not closed: expected '>'"
        )
    )
    return Token(
        Kind.END,
        length,
        length + 1,
        name=name,
        name_start=ns,
        name_end=ne,
        closed=False,
        problems=tuple(problems),
    )


def _scan_start_fast(text: str, pos: int, pools: ScanPools) -> Token | None:
    m = _FAST_NAME_RE.match(text, pos)
    if m is None:
        return None
    am = _FAST_ATTR_RE.match(text, m.end())
    if am is None:
        m = _FAST_CLOSE_RE.match(text, m.end())
        if m is None:
            return None
        key = text[pos : m.end()]
        shared = pools.start_tokens
        tok = shared.get(key)
        if tok is None:  # shared, like end tags: a document may be made of "<Frob/>"
            if len(shared) >= _SHARED_MAX:
                shared.clear()
            length = m.end() - pos
            name = pools.name(text[pos + 1 : m.start()])
            self_closing = m.group(1) == "/"
            tok = shared[key] = _new(
                Token,
                (_START, length, length + 1, name, 1, 1 + len(name), (), self_closing, True, ()),
            )
        return tok
    shared_name, shared_value, shared_attr = pools.name, pools.value, pools.attr
    name = shared_name(m.group(1))
    attrs: list[Attr] = []
    problems: list[Problem] = []
    seen: set[str] = set()
    limits = TagLimits()
    attr_match = _FAST_ATTR_RE.match
    a_end = 0
    while am is not None:
        cur = am
        a_end = cur.end()
        am = attr_match(text, a_end)
        aname, raw, raw2 = cur.groups()
        ns, ne = cur.span(1)
        if aname in seen:
            if limits.duplicate(ns - pos, ne - pos):
                continue
            problems.append(
                Problem(ns - pos, ne - pos, XML_SYNTAX, f"Duplicate attribute '{aname}'")
            )
        elif len(attrs) >= MAX_ATTRS:
            seen.add(aname)
            limits.beyond(ns - pos, ne - pos)
            continue
        seen.add(aname)
        if raw is None:
            raw = raw2
            vs, ve = cur.span(3)
            quote = "'"
        else:
            vs, ve = cur.span(2)
            quote = '"'
        vs -= pos
        attr = _new(
            Attr,
            (
                shared_name(aname),
                ns - pos,
                ne - pos,
                shared_value(raw) if "&" not in raw else decode_value(raw, vs, problems),
                vs,
                ve - pos,
                quote,
            ),
        )
        # Equal attributes at the same place in their tags are one tuple, like short values.
        attrs.append(shared_attr(attr))
    close = _FAST_CLOSE_RE.match(text, a_end)
    if close is None:
        return None
    length = close.end() - pos
    self_closing = close.group(1) == "/"
    problems.extend(Problem(*p) for p in limits.problems(name, len(attrs)))
    return _new(
        Token,
        (
            _START,
            length,
            length + 1,
            name,
            1,
            1 + len(name),
            tuple(attrs),
            self_closing,
            True,
            tuple(problems) if problems else (),
        ),
    )


def _scan_start(text: str, pos: int, n: int, pools: ScanPools) -> Token:
    fast = _scan_start_fast(text, pos, pools)
    if fast is not None:
        return fast
    problems: list[Problem] = []
    attrs: list[Attr] = []
    seen: set[str] = set()
    limits = TagLimits()
    m = _NAME_RE.match(text, pos + 1)
    assert m is not None  # the caller checked that a name character follows '<'
    name = m.group(0)
    i = m.end()
    reach = i
    self_closing = False
    closed = False
    spaced = False  # whitespace was read after an attribute without a value
    while True:
        ws_end = _WS_RE.match(text, i).end()  # type: ignore[union-attr]
        had_ws = ws_end > i or spaced
        spaced = False
        i = ws_end
        reach = max(reach, i)
        if i >= n:
            problems.append(
                Problem(
                    1,
                    1 + len(name),
                    XML_SYNTAX,
                    f"Start tag '<{name}' is not closed: expected '>' or '/>'",
                )
            )
            break
        c = text[i]
        if c == ">":
            i += 1
            closed = True
            break
        if c == "/":
            if i + 1 < n and text[i + 1] == ">":
                i += 2
                closed = self_closing = True
                break
            reach = max(reach, i + 1)
            problems.append(Problem(i - pos, i + 1 - pos, XML_SYNTAX, "Expected '/>' after '/'"))
            i += 1
            continue
        if c == "<":
            problems.append(
                Problem(
                    1,
                    1 + len(name),
                    XML_SYNTAX,
                    f"Start tag '<{name}' is not closed: expected '>' or '/>'",
                )
            )
            break
        am = _NAME_RE.match(text, i)
        if am is None:  # '=' or a quote where a name should be
            problems.append(
                Problem(i - pos, i + 1 - pos, XML_SYNTAX, f"Unexpected {c!r} in tag '<{name}'")
            )
            if c in "\"'":
                # Skip a stray quoted chunk, but never past the start of another tag.
                jm = _STRAY_QUOTE_END[c].search(text, i + 1)
                reach = max(reach, jm.end() if jm is not None else n)
                i = jm.end() if jm is not None and jm.group(0) == c else i + 1
            else:
                i += 1
                reach = max(reach, i)
            continue
        aname = am.group(0)
        ns, ne = am.start() - pos, am.end() - pos
        if not had_ws and attrs:
            problems.append(
                Problem(
                    ns,
                    ne,
                    LENIENT,
                    f"Missing whitespace before attribute '{aname}' (tinyxml2 reads it; "
                    "other XML tools reject the file)",
                )
            )
        # An attribute beyond the limits is read (its value skipped) but not kept.
        keep = attrs if limits.keeps(aname in seen, len(attrs), ns, ne) else []
        if aname in seen and keep is attrs:
            problems.append(Problem(ns, ne, XML_SYNTAX, f"Duplicate attribute '{aname}'"))
        seen.add(aname)
        i = _WS_RE.match(text, am.end()).end()  # type: ignore[union-attr]
        reach = max(reach, i + 1)
        if i >= n or text[i] != "=":
            problems.append(
                Problem(ns, ne, XML_SYNTAX, f"Attribute '{aname}' has no value: expected '=\"…\"'")
            )
            spaced = i > am.end()
            keep.append(Attr(aname, ns, ne, None, -1, -1, ""))
            continue
        i = _WS_RE.match(text, i + 1).end()  # type: ignore[union-attr]
        reach = max(reach, i + 1)
        q = text[i] if i < n else ""
        if q in ('"', "'") and q:
            vstart = i + 1
            vm = _VALUE_END_RE[q].search(text, vstart)
            if vm is not None and vm.group(0) == q:
                vend, i = vm.start(), vm.end()
                reach = max(reach, i)
            else:
                vend = vm.start() if vm is not None else n
                reach = max(reach, vm.end() if vm is not None else n)
                i = vend
                problems.append(
                    Problem(ns, ne, XML_SYNTAX, f"Value of attribute '{aname}' has no closing {q}")
                )
            raw = text[vstart:vend]
            keep.append(
                Attr(
                    aname,
                    ns,
                    ne,
                    decode_value(raw, vstart - pos, problems),
                    vstart - pos,
                    vend - pos,
                    q,
                )
            )
        else:
            # Unquoted value: XML forbids it; read up to whitespace or the tag's end.
            vm2 = _UNQUOTED_RE.match(text, i)
            vend = vm2.end() if vm2 else i
            if vend > i and text[vend - 1] == "/" and vend < n and text[vend] == ">":
                vend -= 1
            reach = max(reach, vend + 1)
            problems.append(
                Problem(ns, ne, XML_SYNTAX, f"Value of attribute '{aname}' must be quoted")
            )
            raw = text[i:vend]
            keep.append(
                Attr(aname, ns, ne, decode_value(raw, i - pos, None), i - pos, vend - pos, "")
            )
            i = vend
    length = i - pos
    if len(problems) > MAX_TAG_PROBLEMS:
        more = len(problems) - MAX_TAG_PROBLEMS
        at = problems[MAX_TAG_PROBLEMS]
        del problems[MAX_TAG_PROBLEMS:]
        problems.append(
            Problem(at.start, at.end, at.code, f"{more} more problems in tag '<{name}' from here")
        )
    problems.extend(Problem(*p) for p in limits.problems(name, len(attrs)))
    return Token(
        Kind.START,
        length,
        max(reach - pos, length) + 1,
        name=name,
        name_start=1,
        name_end=1 + len(name),
        attrs=tuple(attrs),
        self_closing=self_closing,
        closed=closed,
        problems=tuple(problems),
    )


def scan_token(text: str, pos: int, pools: ScanPools | None = None) -> Token:
    """Scan the one token that starts at ``pos`` (``pos < len(text)``); its pieces shared
    through ``pools`` (a scan of many tokens passes one)."""
    if pools is None:
        pools = ScanPools()
    n = len(text)
    if text[pos] != "<":
        return _scan_text(text, pos, n, pools)
    nxt = text[pos + 1] if pos + 1 < n else ""
    if nxt == "/":
        return _scan_end_tag(text, pos, n, pools)
    if nxt == "!":
        if text.startswith("<!--", pos):
            return _scan_delimited(text, pos, n, Kind.COMMENT, "<!--", "-->", "comment")
        if text.startswith("<![CDATA[", pos):
            return _scan_delimited(text, pos, n, Kind.CDATA, "<![CDATA[", "]]>", "CDATA section")
        if text.startswith("<!DOCTYPE", pos):
            return _scan_doctype(text, pos, n)
        end = text.find(">", pos)
        length = (end + 1 if end != -1 else n) - pos
        return Token(
            Kind.STRAY,
            length,
            max(length, 9) + 1,
            closed=False,
            problems=(Problem(0, min(2, length), XML_SYNTAX, "Unknown markup declaration"),),
        )
    if nxt == "?":
        return _scan_delimited(text, pos, n, Kind.PI, "<?", "?>", "processing instruction")
    if nxt and nxt not in _NAME_STOP:
        return _scan_start(text, pos, n, pools)
    return Token(
        Kind.STRAY,
        1,
        2,
        closed=False,
        problems=(Problem(0, 1, XML_SYNTAX, "'<' does not start a tag; write '&lt;'"),),
    )


# The token starts of a scan: offsets kept in blocks (see bt_lsp.syntax.text.Offsets).
Starts = Offsets


@dataclass(slots=True)
class Scan:
    """The tokens of a text and their absolute start offsets."""

    tokens: list[Token]
    starts: Starts

    def index_at(self, offset: int) -> int:
        """Index of the token containing ``offset`` (the last token for offsets past it)."""
        return max(0, self.starts.index_at(offset))


# A token whose scan looked this far at most is remembered for the ones that follow.
_REPEAT_REACH = 64
# Of each window of tokens looked up so, at least half must be found, or the next
# tokens are scanned without looking (where a document does not repeat itself, looking
# costs more than it finds).
_WINDOW = 256
_PAUSE = 2048


def scan(text: str) -> Scan:
    pools = ScanPools()  # for this scan
    tokens: list[Token] = []
    starts = array("q")  # machine ints: a list would hold an int object per token
    add_token, add_start = tokens.append, starts.append
    startswith = text.startswith
    pos, n = 0, len(text)
    # The text each of the last three tokens looked at: a token depends only on the text
    # from its start to its reach, so where the same text comes again, so does the token
    # (one comparison in C instead of a scan: documents repeat a tag, or a few in turn).
    s1 = s2 = s3 = ""
    t1 = t2 = t3 = _NO_TOKEN
    looked = found = pause = 0
    while pos < n:
        if pause:
            pause -= 1
            tok = scan_token(text, pos, pools)
            add_token(tok)
            add_start(pos)
            pos += tok.length
            continue
        looked += 1
        if s1 and startswith(s1, pos):
            tok = t1
            found += 1
        elif s2 and startswith(s2, pos):
            tok, s1, t1, s2, t2 = t2, s2, t2, s1, t1
            found += 1
        elif s3 and startswith(s3, pos):
            tok, s1, t1, s2, t2, s3, t3 = t3, s3, t3, s1, t1, s2, t2
            found += 1
        else:
            tok = scan_token(text, pos, pools)
            reach = tok.reach
            s3, t3, s2, t2 = s2, t2, s1, t1
            # (Not a tag with attributes: those seldom repeat whole.)
            s1 = (
                text[pos : pos + reach]
                if reach <= _REPEAT_REACH and pos + reach <= n and not tok.attrs
                else ""
            )
            t1 = tok
        if looked == _WINDOW:
            if 2 * found < _WINDOW:
                pause = _PAUSE
                s1 = s2 = s3 = ""
            looked = found = 0
        add_token(tok)
        add_start(pos)
        pos += tok.length
    return Scan(tokens, Starts.of(starts))


_NO_TOKEN = Token(Kind.TEXT, 0, 0)


@dataclass(frozen=True, slots=True)
class Rescan:
    """What an incremental re-scan replaced: old tokens ``[first, old_stop)`` became new
    tokens ``[first, new_stop)``; every other token is the same object as before."""

    first: int
    old_stop: int
    new_stop: int

    def then(self, later: Rescan) -> Rescan:
        """The tokens replaced by this re-scan followed by ``later`` (a re-scan of this
        one's result): a range that holds both, possibly with unchanged tokens too."""
        d1 = self.new_stop - self.old_stop
        d2 = later.new_stop - later.old_stop
        new_stop = max(later.new_stop, self.new_stop + d2)
        return Rescan(min(self.first, later.first), new_stop - d1 - d2, new_stop)


def rescan(old: Scan, new_text: str, start: int, old_end: int, new_len: int) -> tuple[Scan, Rescan]:
    """Update ``old`` for the edit that replaced old ``[start, old_end)`` with ``new_len``
    code points, giving ``new_text``.  Re-scans only around the edit."""
    tokens, starts = old.tokens, old.starts
    delta = new_len - (old_end - start)
    if not tokens:
        full = scan(new_text)
        return full, Rescan(0, 0, len(full.tokens))
    # First token whose scan may have looked at the edited region.
    first = old.index_at(start)
    lo = max(0, first - 8)
    for k in range(first - 1, lo - 1, -1):
        if starts[k] + tokens[k].reach > start:
            first = k
    if first > 0 and starts[first] == start:
        # An insertion at a token boundary may extend the previous token.
        first -= 1
    pos = starts[first]
    new_end = start + new_len
    n = len(new_text)
    new_tokens: list[Token] = []
    new_starts: list[int] = []
    pools = ScanPools()  # for this re-scan
    k = first  # candidate old token to resynchronise with
    nold = len(tokens)
    while pos < n:
        if pos >= new_end:
            old_pos = pos - delta
            if old_pos >= old_end:
                while k < nold and starts[k] < old_pos:
                    k += 1
                if k < nold and starts[k] == old_pos:
                    new_list = tokens[:first]
                    new_list.extend(new_tokens)
                    new_list.extend(tokens[k:])
                    result = Scan(new_list, starts.replaced(first, k, new_starts, delta))
                    return result, Rescan(first, k, first + len(new_tokens))
        tok = scan_token(new_text, pos, pools)
        new_tokens.append(tok)
        new_starts.append(pos)
        pos += tok.length
    result = Scan(tokens[:first] + new_tokens, starts.replaced(first, nold, new_starts, delta))
    return result, Rescan(first, nold, first + len(new_tokens))
