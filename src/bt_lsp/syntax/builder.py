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
from itertools import repeat

from bt_lsp.syntax.elements import (
    EXPLICIT_TAGS,
    SELF_CLOSED,
    Element,
    Own,
    StructureProblem,
    Zone,
    of_row,
    zone_in,
)
from bt_lsp.syntax.model import Model
from bt_lsp.syntax.scanner import Rescan, Scan
from bt_lsp.syntax.sections import CLOSED, EOF, OPEN, Section
from bt_lsp.syntax.table import ZONES as _ZONES
from bt_lsp.syntax.table import Columns, ElementTable, Growing, keeps, offsets_code
from bt_lsp.syntax.tokens import EXTRA_ROOT, LENIENT, XML_SYNTAX, Kind, Token
from bt_lsp.syntax.values import decode_value
from bt_lsp.syntax.xmlnames import XmlNameMemo, cached_xml_name_problem

_ZONE_OUTSIDE = Zone.OUTSIDE
_ZONE_TREE = Zone.TREE
_ZONE_PORT_DECL = Zone.PORT_DECL
_ZONE_ROOT = Zone.ROOT


def _name_problems(tok: Token, checked: bool, memo: XmlNameMemo) -> tuple[tuple[int, str], ...]:
    """The XML-name problems of a start tag's names, relative to the tag's start."""
    found: list[tuple[int, str]] = []
    xp = cached_xml_name_problem(tok.name, checked and tok.name not in EXPLICIT_TAGS, False, memo)
    if xp is not None:
        found.append((1 + xp[0], xp[1]))
    for a in tok.attrs:
        xp = cached_xml_name_problem(a.name, checked, True, memo)
        if xp is not None:
            found.append((a.name_start + xp[0], xp[1]))
    return tuple(found)


_NON_SPACE = re.compile(r"[^ \t\r\n]")

_HEAD, _SECTION, _TAIL = 0, 1, 2


class _Builder:
    """Runs the element stack over tokens, writing each element as a row of ``cols``.
    Offsets are stored relative to ``origin``, token indexes relative to ``tok_origin``
    (for a section or the tail, row 0 is the root)."""

    __slots__ = (
        "cols",
        "has_root",
        "kids",
        "lexical",
        "names",
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
        cols: Growing,
        stack: list[int],
        has_root: bool,
        names: XmlNameMemo,
    ) -> None:
        self.text = text
        self.names = names  # the XML-name checks of this build
        self.origin = origin
        self.tok_origin = tok_origin
        self.cols = cols
        self.stack = stack
        # The children of each open element so far (closed into cols.flat).
        self.kids: list[array[int]] = [array("i") for _ in stack]
        self.has_root = has_root
        self.problems: list[StructureProblem] = []
        self.lexical: list[StructureProblem] = []

    def run(self, tokens: list[Token], starts: Sequence[int], i: int, mode: int) -> tuple[int, int]:
        """Process tokens from ``i``; returns where it stopped and how (``OPEN``: at a
        start tag with only the root open, or, for a section, at the root's end tag;
        ``CLOSED``: a section closed the root; ``EOF``)."""
        n = len(tokens)
        text, origin, tok_origin = self.text, self.origin, self.tok_origin
        cols, stack, kids = self.cols, self.stack, self.kids
        problems, lexical = self.problems, self.lexical
        tags, zones = cols.tags, cols.zones
        add_tag, add_zone, add_start = tags.append, zones.append, cols.starts.append
        add_tindex, add_parent = cols.tindex.append, cols.parents.append
        add_depth, add_extent = cols.depths.append, cols.extents.append
        add_name_at, add_child_at = cols.names_at.append, cols.child_at.append
        add_child_n = cols.child_n.append
        first = i
        start_kind, end_kind, text_kind = Kind.START, Kind.END, Kind.TEXT
        node_zone, port_decl = Zone.NODE, _ZONE_PORT_DECL
        # The last start tag and parent zone seen, with its zone and name problems: a
        # document of many equal tags is checked once per run of them.
        last_tok: Token | None = None
        last_pz = -1
        last_zone = node_zone
        last_names: tuple[tuple[int, str], ...] = ()
        while i < n:
            tok = tokens[i]
            kind = tok.kind
            if kind == start_kind:
                if tok.name == "BehaviorTree" and len(stack) > 1 and zones[stack[1]] == _ZONE_TREE:
                    # A tree starts while the one above is not closed yet (it is being
                    # typed): a <BehaviorTree> can only be a child of <root>, so the open
                    # elements end here, and it starts the next tree.
                    while len(stack) > 1:
                        self._report_unclosed(self._pop(), before="<BehaviorTree>")
                if (
                    len(stack) == 1
                    and stack[0] == 0
                    and mode != _TAIL
                    and (mode == _HEAD or i != first)
                ):
                    return i, OPEN
                tstart = starts[i] - origin
                if tok.problems:
                    for p in tok.problems:
                        lexical.append(
                            StructureProblem(tstart + p.start, tstart + p.end, p.code, p.message)
                        )
                idx = len(tags)
                if stack:
                    parent = stack[-1]
                    pz = zones[parent]
                    if tok is not last_tok or pz != last_pz:
                        last_zone = zone_in(tok.name, _ZONES[pz])
                        last_names = _name_problems(tok, last_zone == node_zone, self.names)
                        last_tok, last_pz = tok, pz
                    zone = last_zone
                    names = last_names
                    kids[-1].append(idx)
                else:
                    parent = -1
                    if self.has_root:
                        zone = _ZONE_OUTSIDE
                        problems.append(
                            StructureProblem(
                                tstart + 1,
                                tstart + 1 + len(tok.name),
                                EXTRA_ROOT,
                                f"Extra top-level element '<{tok.name}>' after the root: "
                                "tinyxml2 accepts it, and BehaviorTree.CPP reads the first "
                                "element only, so this one is ignored",
                            )
                        )
                    else:
                        zone = _ZONE_ROOT
                    self.has_root = True
                    names = _name_problems(tok, False, self.names)
                add_tag(tok)
                add_zone(zone)
                add_start(tstart)
                add_tindex(i - tok_origin)
                add_parent(parent)
                add_depth(len(stack))
                add_name_at(-1)
                add_child_at(0)
                add_child_n(0)
                if names:
                    for at, message in names:
                        problems.append(
                            StructureProblem(tstart + at, tstart + at + 1, XML_SYNTAX, message)
                        )
                if tok.self_closing:
                    add_extent(SELF_CLOSED)
                    i += 1
                    if (
                        i < n
                        and tokens[i] is tok
                        and parent >= 0
                        and (parent > 0 or mode == _TAIL)  # (the root's child ends a part)
                        and not tok.problems
                        and tok.name != "BehaviorTree"
                    ):
                        i = self._run_of(tok, zone, names, tokens, starts, i, n)
                    continue
                add_extent(-1)
                stack.append(idx)
                kids.append(array("i"))
                i += 1
                continue
            if (
                mode == _SECTION
                and kind == end_kind
                and len(stack) == 1
                and stack[0] == 0
                and tok.name == tags[0].name
            ):
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
                                LENIENT,
                                (
                                    "Text outside the root element"
                                    if self.has_root
                                    else "Text before the root element"
                                )
                                + " (tinyxml2 skips it; other XML tools reject the file)",
                            )
                        )
            elif kind == end_kind:
                closed = self._close(tstart, tok)
                if closed >= 0 and zones[closed] == port_decl:
                    cols.contents[closed] = _content(
                        tokens, starts, text, cols.tindex[closed] + tok_origin, i
                    )
                if mode == _SECTION and not stack:
                    return i + 1, CLOSED
            i += 1
        return i, EOF

    def _run_of(
        self,
        tok: Token,
        zone: int,
        names: tuple[tuple[int, str], ...],
        tokens: list[Token],
        starts: Sequence[int],
        i: int,
        n: int,
    ) -> int:
        """Add the empty elements of ``tok`` that follow from token ``i`` (siblings of
        the one just added, in ``zone``), as many as there are in a row, all at once;
        returns the token after them."""
        j = i + 1
        while j < n and tokens[j] is tok:
            j += 1
        k = j - i
        cols, stack = self.cols, self.stack
        idx = len(cols.tags)
        origin = self.origin
        cols.tags.extend(repeat(tok, k))
        cols.zones.extend(bytes((zone,)) * k)
        run = starts[i:j]
        cols.starts.extend(map((-origin).__add__, run) if origin else iter(run))
        cols.tindex.extend(range(i - self.tok_origin, j - self.tok_origin))
        cols.parents.extend(array("i", (stack[-1],)) * k)
        cols.depths.extend(array("i", (len(stack),)) * k)
        code = cols.extents.typecode
        cols.extents.extend(array(code, (SELF_CLOSED,)) * k)
        cols.names_at.extend(array(code, (-1,)) * k)
        zeros = array("i", (0,)) * k
        cols.child_at.extend(zeros)
        cols.child_n.extend(zeros)
        self.kids[-1].extend(range(idx, idx + k))
        if names:
            problems = self.problems
            for s in run:
                tstart = s - origin
                for at, message in names:
                    problems.append(
                        StructureProblem(tstart + at, tstart + at + 1, XML_SYNTAX, message)
                    )
        return j

    def _pop(self) -> int:
        """Close the innermost open element's list of children; its row."""
        idx = self.stack.pop()
        kids = self.kids.pop()
        if kids:
            cols = self.cols
            cols.child_at[idx] = len(cols.flat)
            cols.child_n[idx] = len(kids)
            cols.flat.extend(kids)
        return idx

    def _close(self, tstart: int, tok: Token) -> int:
        """Match an end tag to an open element, tolerating a few missing end tags; the
        row of the element it closed, -1 if none."""
        stack, tags = self.stack, self.cols.tags
        name_s, name_e = tstart + tok.name_start, tstart + tok.name_end
        match = -1
        for depth in range(len(stack) - 1, max(-1, len(stack) - 65), -1):
            if tags[stack[depth]].name == tok.name:
                match = depth
                break
        if match == -1:
            expected = f"; expected '</{tags[stack[-1]].name}>'" if stack else ""
            after_root = not stack and self.has_root
            self.problems.append(
                StructureProblem(
                    name_s if tok.name else tstart,
                    name_e if tok.name else tstart + 2,
                    EXTRA_ROOT if after_root else XML_SYNTAX,
                    f"Unexpected end tag '</{tok.name}>' after the root: tinyxml2 stops "
                    "reading here, and BehaviorTree.CPP ignores the rest of the file"
                    if after_root
                    else f"Unexpected end tag '</{tok.name}>'{expected}",
                )
            )
            return -1
        while len(stack) > match + 1:
            self._report_unclosed(self._pop(), closed_by=tok.name)
        idx = self._pop()
        cols = self.cols
        at = cols.starts[idx]
        cols.extents[idx] = tstart + tok.length - at
        cols.names_at[idx] = name_s - at  # its ref: see Section.refs
        return idx

    def _report_unclosed(
        self, idx: int, closed_by: str | None = None, before: str | None = None
    ) -> None:
        tag = self.cols.tags[idx]
        if not tag.closed:
            return  # its start tag already has an error; do not cascade
        where = f" before '</{closed_by}>'" if closed_by is not None else ""
        if before is not None:
            where = f" before the next '{before}'"
        at = self.cols.starts[idx] + 1
        self.problems.append(
            StructureProblem(
                at, at + len(tag.name), XML_SYNTAX, f"Element '<{tag.name}>' is not closed{where}"
            )
        )

    def finish(self, keep_root: bool) -> None:
        """Report the elements left open at the end (the root too unless ``keep_root``)."""
        stack = self.stack
        while len(stack) > (1 if keep_root else 0):
            self._report_unclosed(self._pop(), closed_by=None)

    def section(self, ntokens: int, length: int, end: int, root: Element | None = None) -> Section:
        root_end = None
        cols = self.cols
        if end == CLOSED:
            at = cols.starts[0]
            root_end = (at + cols.extents[0], at + cols.names_at[0])
        # A small section's columns cost more than its rows unless packed (see table.py).
        done: Columns = cols.packed() if cols.packs() else cols
        return Section(
            ntokens,
            length,
            ElementTable(done, 0, 0, 1, keep=keeps(length, len(cols) - 1)),
            self.problems or (),  # (an empty tuple is shared)
            self.lexical or (),
            end,
            root_end,
            root,
        )


def _stand_in(
    cols: Growing, tag: Token, start: int, tindex: int, extent: int, name_at: int
) -> None:
    """Write row 0: the root, as a section or the tail is built with it."""
    cols.tags.append(tag)
    cols.zones.append(_ZONE_ROOT)
    cols.starts.append(start)
    cols.tindex.append(tindex)
    cols.parents.append(-1)
    cols.depths.append(0)
    cols.extents.append(extent)
    cols.names_at.append(name_at)
    cols.child_at.append(0)
    cols.child_n.append(0)


def _section(
    tokens: list[Token],
    starts: Sequence[int],
    text: str,
    i: int,
    root_tag: Token,
    code: str,
    names: XmlNameMemo,
) -> tuple[Section, int, int]:
    """The section that starts at token ``i`` (a start tag with only the root open)."""
    origin = starts[i]
    cols = Growing(code)
    _stand_in(cols, root_tag, -origin, -i, -1, -1)
    b = _Builder(text, origin, i, cols, [0], True, names)
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
    starts: Sequence[int] = scan.starts if change is not None else scan.starts.toarray()
    n = len(tokens)
    code = offsets_code(len(text))
    hcols = Growing(code)
    xml_names: XmlNameMemo = {}  # for this build
    hb = _Builder(text, 0, 0, hcols, [], False, xml_names)
    i, state = hb.run(tokens, starts, 0, _HEAD)
    root_tag = hcols.tags[0] if hcols.tags else None
    model = Model([], [], [])
    model._elements = model._refs = model._problems = None
    model.head_ntokens = i
    root: Element | None = None
    sections: list[Section] = []
    origins: array[int] = array("q")
    firsts: array[int] = array("q")
    bases: array[int] = array("q")
    names: list[str] = []
    if state == OPEN and root_tag is not None:
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
            sec, j, state = _section(tokens, starts, text, i, root_tag, code, xml_names)
            sections.append(sec)
            origins.append(starts[i])
            firsts.append(i)
            bases.append(base)
            names.append(sec.top_name)
            base += len(sec.elements)
            i = j
        model.sections, model.origins, model.firsts, model.bases = sections, origins, firsts, bases
        model.top_names = names
        model.sections_end = i
        root_start, root_tindex = hcols.starts[0], hcols.tindex[0]
        extent = name_at = -1
        if state == CLOSED:
            re_ = sections[-1].root_end
            assert re_ is not None
            o = origins[-1] - root_start
            extent, name_at = re_[0] + o, re_[1] + o if re_[1] >= 0 else -1
        tcols = Growing(code)
        _stand_in(tcols, root_tag, root_start, root_tindex, extent, name_at)
        tb = _Builder(text, 0, 0, tcols, [0] if state != CLOSED else [], True, xml_names)
        tb.run(tokens, starts, i, _TAIL)
        tb.finish(keep_root=False)
        model.tail_start = starts[i] if i < n else len(text)
        model.tail = tb.section(n - i, len(text) - model.tail_start, EOF)
        model.tail_base = base
        # The root's children are the sections' tops, and any the tail adds.
        children = array("i", bases)
        at, count = tcols.child_at[0], tcols.child_n[0]
        children.extend(map((base - 1).__add__, tcols.flat[at : at + count]))
        root = of_row(
            root_tag,
            _ZONE_ROOT,
            root_start,
            root_tindex,
            -1,
            0,
            tcols.extents[0],
            tcols.names_at[0],
            Own(children, None),
            0,
        )
    else:
        hb.finish(keep_root=False)
        root = hcols.element(0) if root_tag is not None else None
    model.root_element = root
    model.head = hb.section(i if sections else n, 0, EOF, root)
    return model


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
