"""Builds the model of a scanned text: one pass over the tokens with an explicit element
stack (no recursion), section by section.  After an edit, :func:`build` re-runs only the
sections from the first changed token until a section boundary lines up with an old one
again; it also reports what is wrong with the structure (unclosed and unexpected tags,
text outside the root, invalid XML names)."""

from __future__ import annotations

import re
from array import array
from bisect import bisect_left
from collections.abc import Sequence

from bt_lsp.syntax.elements import EXPLICIT_TAGS, Element, StructureProblem, Zone, zone_in
from bt_lsp.syntax.model import Model
from bt_lsp.syntax.scanner import Rescan, Scan
from bt_lsp.syntax.sections import CLOSED, EOF, OPEN, Section
from bt_lsp.syntax.tokens import XML_SYNTAX, Kind, Token
from bt_lsp.syntax.values import decode_value
from bt_lsp.syntax.xmlnames import cached_xml_name_problem

_ZONE_OUTSIDE = Zone.OUTSIDE
_ZONE_TREE = Zone.TREE
_ZONE_PORT_DECL = Zone.PORT_DECL
_ZONE_ROOT = Zone.ROOT


def _zone_of(name: str, parent: Element | None, has_root: bool) -> Zone:
    if parent is None:
        return _ZONE_OUTSIDE if has_root else _ZONE_ROOT
    return zone_in(name, parent.zone)


def _check_xml_names(
    tstart: int, tok: Token, checked: bool, problems: list[StructureProblem]
) -> None:
    xp = cached_xml_name_problem(tok.name, checked and tok.name not in EXPLICIT_TAGS, False)
    if xp is not None:
        at = tstart + 1 + xp[0]
        problems.append(StructureProblem(at, at + 1, XML_SYNTAX, xp[1]))
    for a in tok.attrs:
        xp = cached_xml_name_problem(a.name, checked, True)
        if xp is not None:
            at = tstart + a.name_start + xp[0]
            problems.append(StructureProblem(at, at + 1, XML_SYNTAX, xp[1]))


_NON_SPACE = re.compile(r"[^ \t\r\n]")

_HEAD, _SECTION, _TAIL = 0, 1, 2


class _Builder:
    """Runs the element stack over tokens.  Offsets are stored relative to ``origin``,
    token indexes relative to ``tok_origin``; elements are numbered in ``els`` (where,
    for a section or the tail, element 0 is the root)."""

    __slots__ = (
        "els",
        "has_root",
        "lexical",
        "origin",
        "problems",
        "stack",
        "text",
        "tok_origin",
    )

    def __init__(
        self,
        text: str,
        origin: int,
        tok_origin: int,
        els: list[Element],
        stack: list[int],
        has_root: bool,
    ) -> None:
        self.text = text
        self.origin = origin
        self.tok_origin = tok_origin
        self.els = els
        self.stack = stack
        self.has_root = has_root
        self.problems: list[StructureProblem] = []
        self.lexical: list[StructureProblem] = []

    def run(self, tokens: list[Token], starts: Sequence[int], i: int, mode: int) -> tuple[int, int]:
        """Process tokens from ``i``; returns where it stopped and how (``OPEN``: at a
        start tag with only the root open, or, for a section, at the root's end tag;
        ``CLOSED``: a section closed the root; ``EOF``)."""
        n = len(tokens)
        text, origin = self.text, self.origin
        els, stack, problems, lexical = self.els, self.stack, self.problems, self.lexical
        first = i
        start_kind, end_kind, text_kind = Kind.START, Kind.END, Kind.TEXT
        node_zone = Zone.NODE
        while i < n:
            tok = tokens[i]
            kind = tok.kind
            if (
                kind == start_kind
                and tok.name == "BehaviorTree"
                and len(stack) > 1
                and els[stack[1]].zone == _ZONE_TREE
            ):
                # A tree starts while the one above is not closed yet (it is being typed):
                # a <BehaviorTree> can only be a child of <root>, so the open elements end
                # here, and it starts the next tree.
                while len(stack) > 1:
                    _report_unclosed(els[stack.pop()], problems, before="<BehaviorTree>")
            at_root = len(stack) == 1 and stack[0] == 0
            if at_root and mode != _TAIL:
                if kind == start_kind and (mode == _HEAD or i != first):
                    return i, OPEN
                if mode == _SECTION and kind == end_kind and tok.name == els[0].name:
                    return i, OPEN
            tstart = starts[i] - origin
            if tok.problems:
                for p in tok.problems:
                    lexical.append(
                        StructureProblem(tstart + p.start, tstart + p.end, p.code, p.message)
                    )
            if kind == text_kind:
                if not stack:
                    a = starts[i]
                    if not text[a : a + tok.length].isspace():
                        m = _NON_SPACE.search(text, a, a + tok.length)
                        at = (m.start() if m else a) - origin
                        problems.append(
                            StructureProblem(
                                at,
                                tstart + tok.length,
                                XML_SYNTAX,
                                "Text outside the root element"
                                if self.has_root
                                else "Text before the root element",
                            )
                        )
            elif kind == start_kind:
                parent = els[stack[-1]] if stack else None
                zone = _zone_of(tok.name, parent, self.has_root)
                if parent is None:
                    if self.has_root:
                        problems.append(
                            StructureProblem(
                                tstart + 1,
                                tstart + 1 + len(tok.name),
                                XML_SYNTAX,
                                f"Extra top-level element '<{tok.name}>'; a document has one root",
                            )
                        )
                    self.has_root = True
                idx = len(els)
                el = Element.of_tag(
                    tok, zone, tstart, i - self.tok_origin, stack[-1] if stack else -1, len(stack)
                )
                els.append(el)
                if parent is not None:
                    children = parent.children
                    if children:
                        children.append(idx)  # type: ignore[attr-defined]  # an array
                    else:  # ints in an array: a Python int would cost four times <A/>
                        parent.children = array("q", (idx,))
                _check_xml_names(tstart, tok, zone == node_zone, problems)
                if not tok.self_closing:
                    stack.append(idx)
            elif kind == end_kind:
                closed = _close(tstart, tok, els, stack, problems)
                if closed >= 0 and els[closed].zone == _ZONE_PORT_DECL:
                    el = els[closed]
                    el.content = _content(tokens, starts, text, el.token_index + self.tok_origin, i)
                if mode == _SECTION and not stack:
                    return i + 1, CLOSED
            i += 1
        return i, EOF

    def finish(self, keep_root: bool) -> None:
        """Report the elements left open at the end (the root too unless ``keep_root``)."""
        stack = self.stack
        while len(stack) > (1 if keep_root else 0):
            _report_unclosed(self.els[stack.pop()], self.problems, closed_by=None)

    def section(self, ntokens: int, length: int, end: int, head: bool = False) -> Section:
        root_end = None
        if end == CLOSED:
            root = self.els[0]
            root_end = (root.end, root.end_name_start)
        return Section(
            ntokens,
            length,
            self.els[1:],
            self.problems,
            self.lexical,
            end,
            root_end,
            self.els[0] if head and self.els else None,
        )


def _section(
    tokens: list[Token], starts: Sequence[int], text: str, i: int, root_name: str
) -> tuple[Section, int, int]:
    """The section that starts at token ``i`` (a start tag with only the root open)."""
    origin = starts[i]
    stand_in = Element(root_name, Zone.ROOT, -origin, -i, -1, 0, (), False, True)
    b = _Builder(text, origin, i, [stand_in], [0], True)
    j, end = b.run(tokens, starts, i, _SECTION)
    if end == EOF:
        b.finish(keep_root=True)
    length = (starts[j] if j < len(starts) else len(text)) - origin
    return b.section(j - i, length, end), j, end


def build(scan: Scan, text: str, old: Model | None = None, change: Rescan | None = None) -> Model:
    """The model of a scanned text.  One pass, an explicit stack, no recursion.

    With the model ``old`` of the previous text and ``change``, the tokens an edit
    replaced since (see :func:`bt_lsp.syntax.scanner.rescan`), the sections that the edit cannot
    have changed are reused.
    """
    tokens = scan.tokens
    # A full build reads every start: from one array of machine ints (a list would hold an
    # int object per token while the elements are made); an update reads a few.
    starts: Sequence[int] = scan.starts if change is not None else array("q", scan.starts)
    n = len(tokens)
    hb = _Builder(text, 0, 0, [], [], False)
    i, state = hb.run(tokens, starts, 0, _HEAD)
    root = hb.els[0] if hb.els else None
    model = Model([], [], [])
    model._elements = model._refs = model._problems = None
    model.root_element = root
    model.head_ntokens = i
    sections: list[Section] = []
    origins: list[int] = []
    firsts: list[int] = []
    bases: list[int] = []
    names: list[str] = []
    if state == OPEN and root is not None:
        base = 1
        shift = 0
        reuse = (
            old is not None
            and change is not None
            and bool(old.sections)
            and change.first >= old.head_ntokens
        )
        if reuse:
            assert old is not None and change is not None
            ends = old.firsts[1:]
            ends.append(old.sections_end)
            k = bisect_left(ends, change.first)
            if k:
                sections = old.sections[:k]
                origins = old.origins[:k]
                firsts = old.firsts[:k]
                bases = old.bases[:k]
                names = old.top_names[:k]
                i = ends[k - 1]
                state = sections[-1].end
                base = bases[-1] + len(sections[-1].elements)
            shift = change.new_stop - change.old_stop
        while state == OPEN and i < n and tokens[i].kind == Kind.START:
            if reuse and i >= change.new_stop:  # type: ignore[union-attr]
                assert old is not None
                m = bisect_left(old.firsts, i - shift)
                if m < len(old.firsts) and old.firsts[m] == i - shift:
                    # The rest lines up with the old sections again.
                    dchar = starts[i] - old.origins[m]
                    dbase = base - old.bases[m]
                    sections.extend(old.sections[m:])
                    origins.extend(map(dchar.__add__, old.origins[m:]))
                    firsts.extend(map(shift.__add__, old.firsts[m:]))
                    bases.extend(map(dbase.__add__, old.bases[m:]))
                    names.extend(old.top_names[m:])
                    i = old.sections_end + shift
                    state = old.sections[-1].end
                    base = bases[-1] + len(sections[-1].elements)
                    break
            sec, j, state = _section(tokens, starts, text, i, root.name)
            sections.append(sec)
            origins.append(starts[i])
            firsts.append(i)
            bases.append(base)
            names.append(sec.elements[0].name)
            base += len(sec.elements)
            i = j
        model.sections, model.origins, model.firsts, model.bases = sections, origins, firsts, bases
        model.top_names = names
        model.sections_end = i
        root.children = list(bases)
        if state == CLOSED:
            re_ = sections[-1].root_end
            assert re_ is not None
            o = origins[-1]
            root.end, root.end_name_start = re_[0] + o, re_[1] + o if re_[1] >= 0 else -1
        tb = _Builder(text, 0, 0, [root], [0] if state != CLOSED else [], True)
        tb.run(tokens, starts, i, _TAIL)
        tb.finish(keep_root=False)
        model.tail_start = starts[i] if i < n else len(text)
        model.tail = tb.section(n - i, len(text) - model.tail_start, EOF)
        model.tail_base = base
    else:
        hb.finish(keep_root=False)
    model.head = hb.section(i if sections else n, 0, EOF, head=True)
    return model


def _close(
    tstart: int,
    tok: Token,
    elements: list[Element],
    stack: list[int],
    problems: list[StructureProblem],
) -> int:
    """Match an end tag to an open element, tolerating a few missing end tags; the index
    of the element it closed, -1 if none."""
    name_s, name_e = tstart + tok.name_start, tstart + tok.name_end
    match = -1
    for depth in range(len(stack) - 1, max(-1, len(stack) - 65), -1):
        if elements[stack[depth]].name == tok.name:
            match = depth
            break
    if match == -1:
        expected = f"; expected '</{elements[stack[-1]].name}>'" if stack else ""
        problems.append(
            StructureProblem(
                name_s if tok.name else tstart,
                name_e if tok.name else tstart + 2,
                XML_SYNTAX,
                f"Unexpected end tag '</{tok.name}>'{expected}",
            )
        )
        return -1
    while len(stack) > match + 1:
        _report_unclosed(elements[stack.pop()], problems, closed_by=tok.name)
    idx = stack.pop()
    el = elements[idx]
    el.end = tstart + tok.length
    el.end_name_start = name_s  # its ref: see Section.refs
    return idx


def _content(tokens: list[Token], starts: Sequence[int], text: str, first: int, stop: int) -> str:
    """The text of tokens ``first + 1 .. stop - 1`` (an element's content): its text runs
    with references decoded and its CDATA sections, whitespace runs made single spaces."""
    parts: list[str] = []
    for k in range(first + 1, stop):
        tok = tokens[k]
        s = starts[k]
        if tok.kind == Kind.TEXT:
            parts.append(decode_value(text[s : s + tok.length], 0, None))
        elif tok.kind == Kind.CDATA and tok.closed:
            parts.append(text[s + 9 : s + tok.length - 3])
    return " ".join("".join(parts).split())


def _report_unclosed(
    el: Element,
    problems: list[StructureProblem],
    closed_by: str | None = None,
    before: str | None = None,
) -> None:
    if not el.closed:
        return  # its start tag already has an error; do not cascade
    where = f" before '</{closed_by}>'" if closed_by is not None else ""
    if before is not None:
        where = f" before the next '{before}'"
    problems.append(
        StructureProblem(
            el.name_start, el.name_end, XML_SYNTAX, f"Element '<{el.name}>' is not closed{where}"
        )
    )
