"""Diagnostics that depend on one document alone: lexical problems, XML structure and
the name rules.  They are cached on the document; rules that also need the rest of the
workspace live in :mod:`bt_lsp.rules.semantics` and are combined in :mod:`bt_lsp.rules.analysis`.
"""

from __future__ import annotations

from array import array
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field, replace
from itertools import chain, compress, count, islice
from operator import or_
from typing import TYPE_CHECKING, Any, Final

from bt_lsp.rules.codes import NAMES, XML, FixData, Severity, define, defined, safe
from bt_lsp.rules.names import NameData, NameKind, Violation, check_name
from bt_lsp.rules.section_diff import common_ends
from bt_lsp.syntax.elements import Element, NameRef, Role, Symbol, Zone
from bt_lsp.syntax.model import Model
from bt_lsp.syntax.nametokens import SymbolPool, name_refs
from bt_lsp.syntax.scanner import Scan
from bt_lsp.syntax.sections import Section
from bt_lsp.syntax.tokens import Token

if TYPE_CHECKING:
    from bt_lsp.syntax.document import Document

# The codes of these rules (see bt_lsp.rules.registry).
XML_SYNTAX: Final = define(
    "xml-syntax",
    Severity.ERROR,
    "the document is not well-formed XML",
    XML,
    doc="""
        The document is not well-formed XML, and tinyxml2, the parser BehaviorTree.CPP uses,
        rejects it too: `Error parsing the XML: Error=XML_ERROR_MISMATCHED_ELEMENT …`. bt-lsp
        reports the first such error where it is, with one diagnostic per problem, and keeps
        checking what it can. What tinyxml2 accepts but XML does not (a raw `&` in an attribute,
        text after the root) is a warning instead (`xml-unescaped-char`, `xml-lenient`).
        """,
    why="The file does not load at all.",
    bad="""
        <Sequence>
          <AlwaysSuccess>
        </Sequence>
        """,
    good="""
        <Sequence>
          <AlwaysSuccess/>
        </Sequence>
        """,
    since="Every version.",
)
XML_EXTRA_ROOT: Final = define(
    "xml-extra-root",
    Severity.WARNING,
    "an element after the root element (tinyxml2 accepts it; BehaviorTree.CPP ignores it)",
    XML,
    doc="""
        tinyxml2, BehaviorTree.CPP's XML parser, accepts elements after the root element
        (and stops quietly at a stray end tag), and BehaviorTree.CPP reads only the first
        element, `<root>`: everything after it is ignored. bt-lsp reads it as written and warns:
        `Extra top-level element '<BehaviorTree>' after the root: tinyxml2 accepts it, and
        BehaviorTree.CPP reads the first element only, so this one is ignored`.
        """,
    why="""
        The trees after the root are never loaded, though the author believes they are; often
        a `</root>` too early or a comment broken by a nested `<!--`.
        """,
    bad="""
        <root BTCPP_format="4">
          <BehaviorTree ID="Main">
            <AlwaysSuccess/>
          </BehaviorTree>
        </root>
        <BehaviorTree ID="Other">
          <AlwaysFailure/>
        </BehaviorTree>
        """,
    good="""
        <root BTCPP_format="4">
          <BehaviorTree ID="Main">
            <AlwaysSuccess/>
          </BehaviorTree>
          <BehaviorTree ID="Other">
            <AlwaysFailure/>
          </BehaviorTree>
        </root>
        """,
    since="Every version.",
)
XML_LENIENT: Final = define(
    "xml-lenient",
    Severity.WARNING,
    "not well-formed XML that tinyxml2, BehaviorTree.CPP's parser, accepts (text outside "
    "the root, attributes without white space between them)",
    XML,
    doc="""
        Not well-formed XML that tinyxml2, BehaviorTree.CPP's parser, reads anyway: text before
        or after the root element (`Text outside the root element (tinyxml2 skips it; other XML
        tools reject the file)`), or an attribute written right after the previous value with
        no white space (`Missing whitespace before attribute 'name'`). BehaviorTree.CPP loads
        the file, so it is a warning, not an error.
        """,
    why="""
        Groot2, editors and every other XML tool reject the file; stray text is often a
        leftover of an edit.
        """,
    bad='<Sleep msec="500"name="wait"/>',
    good='<Sleep msec="500" name="wait"/>',
    since="Every version.",
)
XML_UNESCAPED_CHAR: Final = define(
    "xml-unescaped-char",
    Severity.WARNING,
    "a raw `&` or `<` in an attribute value (tinyxml2 accepts it, XML does not)",
    XML,
    # tinyxml2 reads the escaped character as it read the raw one: the value is the same.
    fixes={"escape": safe("Escape '{char}' as '{escaped}'")},
    doc="""
        XML requires `&lt;` and `&amp;` for `<` and `&` in an attribute value. tinyxml2,
        BehaviorTree.CPP's parser, accepts them raw and reads the same value, so BehaviorTree.CPP
        loads the file: `Raw '<' in an attribute value; XML requires '&lt;'`. The fix escapes
        the character, which changes nothing for BehaviorTree.CPP. Most often in scripts and
        conditions (`count < 3`, `a && b`).
        """,
    why="""
        Groot2 and other XML tools reject the file.
        """,
    bad='<ScriptCondition code="count < 3"/>',
    good='<ScriptCondition code="count &lt; 3"/>',
    since="Every version.",
)
XML_DOCTYPE: Final = define(
    "xml-doctype",
    Severity.WARNING,
    "a DOCTYPE; its entities and external DTDs are never expanded or fetched",
    XML,
    doc="""
        A `<!DOCTYPE …>` declaration. tinyxml2, BehaviorTree.CPP's parser, skips it and
        never expands the entities it defines nor fetches an external DTD, so an `&entity;`
        it defines stays undefined. bt-lsp does the same, never fetching anything (no XML
        external entity attack), and warns: `DOCTYPE ignored: its entities and external DTDs are
        never expanded or fetched`.
        """,
    why="""
        Whatever the DOCTYPE was meant to provide (entities, defaults) does not reach
        BehaviorTree.CPP; delete it.
        """,
    bad="""
        <?xml version="1.0"?>
        <!DOCTYPE root>
        <root BTCPP_format="4">
          <BehaviorTree ID="Main">
            <AlwaysSuccess/>
          </BehaviorTree>
        </root>
        """,
    good="""
        <?xml version="1.0"?>
        <root BTCPP_format="4">
          <BehaviorTree ID="Main">
            <AlwaysSuccess/>
          </BehaviorTree>
        </root>
        """,
    since="Every version.",
)
DOCUMENT_TOO_LARGE: Final = define(
    "document-too-large",
    Severity.INFORMATION,
    "analysis limited because the document is larger than the configured maximum",
    XML,
    doc="""
        Not about BehaviorTree.CPP: a document larger than the editor setting
        `btLsp.maxDocumentBytes` (8 MiB by default) gets only the XML and name checks, which
        stay fast, so the editor stays responsive: `Document is … bytes, above
        btLsp.maxDocumentBytes (…): only XML and name checks run`. Raise the setting to check
        such a file fully.
        """,
    why="""
        Unknown nodes, ports and subtrees of the file are not checked while it is reported.
        """,
    since="Every version of bt-lsp.",
)
TOO_MANY_ATTRIBUTES: Final = define(
    "too-many-attributes",
    Severity.INFORMATION,
    "a tag with more attributes than any node has ports; only the first 1000 are checked",
    XML,
    doc="""
        Not about BehaviorTree.CPP: a start tag with more than 1000 attributes (no node has
        that many ports; a generated or damaged file) has only its first 1000 read: `Tag '<…'
        has … attributes: only the first 1000 are read, the … from here are not checked`. It
        bounds the time and memory one tag costs; the example would need 1001 attributes.
        """,
    why="""
        The attributes beyond the first 1000 are not checked at all.
        """,
    since="Every version of bt-lsp.",
)
TOO_MANY_PROBLEMS: Final = define(
    "too-many-problems",
    Severity.INFORMATION,
    "more problems than a client can usefully show; only the most severe are reported",
    XML,
    doc="""
        Not about BehaviorTree.CPP: a document with more than 2000 problems gets the 2000 most
        severe (errors first, then warnings, information and hints) and this one, at its
        start: `… more problems are not shown (only 2000 are reported: errors first, then
        warnings, information and hints)`. No editor shows more usefully, and a hostile
        document would otherwise cost memory in proportion to its findings.
        """,
    why="""
        Fix the first problems (often one XML error or a wrong catalog causes them all) and
        the others appear.
        """,
    since="Every version of bt-lsp.",
)


@dataclass(frozen=True, slots=True)
class Diagnostic:
    """A finding over code-point offsets ``[start, end)`` of the document text."""

    start: int
    end: int
    code: str
    message: str
    severity: Severity
    data: FixData | None = field(default=None, compare=True)

    @property
    def is_name_rule(self) -> bool:
        return defined(self.code).family == NAMES


def make(start: int, end: int, code: str, message: str, data: FixData | None = None) -> Diagnostic:
    return Diagnostic(start, end, code, message, defined(code).severity, data)


MAX_DIAGNOSTICS = 2000


class Capped(list[Diagnostic]):
    """Diagnostics sorted by position, at most :data:`MAX_DIAGNOSTICS` of them (the most
    severe, the first by position among equals: :func:`cap_key`), and in ``more`` how many
    others were found and not kept.  What lies beyond the
    publication cap is never published, so it is not kept either: a hostile document has
    hundreds of thousands of findings, each costing more memory than its text."""

    __slots__ = ("more",)

    def __init__(self, kept: Iterable[Diagnostic] = (), more: int = 0) -> None:
        super().__init__(kept)
        self.more = more


class _NoDiagnostics(Capped):
    """The empty result, shared: it refuses to grow (it is read, never changed)."""

    __slots__ = ()

    def _refuse(self, *args: object, **kwargs: object) -> Any:
        raise TypeError("NO_DIAGNOSTICS is shared and never changed: copy it first")

    append = extend = insert = __setitem__ = __iadd__ = __imul__ = _refuse


#: What a source without findings keeps: one object for them all (most sections of a large
#: document have none).  Results of :func:`capped` are read, never changed.
NO_DIAGNOSTICS: Final = _NoDiagnostics()


def more_of(diags: Iterable[Diagnostic]) -> int:
    """How many diagnostics were found beyond those of ``diags`` (see :class:`Capped`)."""
    return diags.more if isinstance(diags, Capped) else 0


def capped(diags: list[Diagnostic], more: int = 0, maximum: int = MAX_DIAGNOSTICS) -> Capped:
    """``diags`` sorted by position (stable), the ``maximum`` first by :func:`cap_key`
    kept (errors before warnings before hints); ``more``: how many were already left out
    before."""
    if not diags and not more:
        return NO_DIAGNOSTICS
    if len(diags) > maximum:
        diags.sort(key=cap_key)
        more += len(diags) - maximum
        del diags[maximum:]
    diags.sort(key=sort_key)
    return Capped(diags, more)


class NameMemo:
    """What the name rules found, kept for the analyses of one document (its history:
    ``names_memo``) or one pass, never shared between threads.

    ``violations``: the violations of each name text, per role (a role decides the kind
    and whether the name is declared): model and port names repeat (every use of a node
    type or port), and a dict keyed by the text alone is the cheapest lookup.  Instance
    names rarely repeat and their rule is quick: they are not kept (they would cost memory
    in proportion to the documents).  ``tags``: what the name rules find in a start tag
    (:data:`_TagNames`), by tag and zone; ``symbols``: the symbols of their names.  All
    bounded."""

    __slots__ = ("symbols", "tags", "violations")

    def __init__(self) -> None:
        self.violations: dict[Role, dict[str, tuple[Violation, ...]]] = {r: {} for r in Role}
        self.tags: dict[int, tuple[Token, _TagNames]] = {}
        self.symbols = SymbolPool()


_MAX_CACHED = 4096


def names_memo(doc: Document) -> NameMemo:
    """The name rules' memo of ``doc`` (kept for its history; see :class:`NameMemo`)."""
    memo: NameMemo | None = doc.history.memo.get("names")
    if memo is None:
        memo = NameMemo()
        doc.history.memo["names"] = memo
    return memo


def violations(
    text: str, kind: NameKind, role: Role, memo: NameMemo | None = None
) -> tuple[Violation, ...]:
    """The rules ``text`` breaks as a ``kind`` of name in ``role`` (kept in ``memo``), as
    the document alone tells: a reserved name of a declared port is reported by the
    semantic checks, which know the model entry and the BehaviorTree.CPP version
    (:func:`bt_lsp.rules.names.reserved_port_declaration`)."""
    if memo is None:
        return check_name(text, kind)
    cache = memo.violations[role]
    found = cache.get(text)
    if found is None:
        found = check_name(text, kind)
        if kind is not NameKind.INSTANCE:
            if len(cache) >= _MAX_CACHED:
                cache.clear()
            cache[text] = found
    return found


def name_violations(ref: NameRef) -> tuple[Violation, ...]:
    if ref.kind is None:
        return ()
    return violations(ref.text, ref.kind, ref.role)


def name_diagnostics(model: Model, memo: NameMemo | None = None) -> list[Diagnostic]:
    return ref_diagnostics(model.refs, memo)


def ref_diagnostics(refs: Iterable[NameRef], memo: NameMemo | None = None) -> list[Diagnostic]:
    """The name-rule diagnostics of ``refs`` (what they find kept in ``memo``, else for
    this call only)."""
    out: list[Diagnostic] = []
    if memo is None:
        memo = NameMemo()
    caches = memo.violations
    # Unpacked rather than read by field: this runs for every name of a document.
    for start, end, text, kind, role, _symbol, _element, _quote in refs:
        if kind is None:
            continue
        found = caches[role].get(text)
        if found is None:
            found = violations(text, kind, role, memo)
        for v in found:
            out.append(
                make(
                    start,
                    end,
                    v.code,
                    v.message,
                    NameData(text, kind, role),
                )
            )
    return out


def lexical_diagnostics(scan: Scan) -> list[Diagnostic]:
    out: list[Diagnostic] = []
    for start, tok in zip(scan.starts, scan.tokens, strict=True):
        if tok.problems:
            for p in tok.problems:
                out.append(make(start + p.start, start + p.end, p.code, p.message))
    return out


def sort_key(d: Diagnostic) -> tuple[int, int, str]:
    """The order of diagnostics: by position, then code."""
    return d.start, d.end, d.code


def cap_key(d: Diagnostic) -> tuple[int, int, int, str]:
    """Which diagnostics the cap keeps first: by severity (errors, then warnings, then
    information, then hints), then by position: a thousand hints never push an error
    out."""
    return d.severity, d.start, d.end, d.code


def _own(section: Section, memo: NameMemo) -> Capped:
    """The diagnostics of one section (in its coordinates), computed once; the first
    :data:`MAX_DIAGNOSTICS` are kept."""
    out: Capped | None = section.cache.get("diagnostics")
    if out is None:
        found = [make(p.start, p.end, p.code, p.message) for p in section.lexical]
        found.extend(make(p.start, p.end, p.code, p.message) for p in section.problems)
        more = _section_name_diagnostics(section, found, memo)
        out = section.cache["diagnostics"] = capped(found, more)
    return out


# What the name rules find in one start tag where it sits: each finding's offsets from
# the tag's start, code, message, severity and data; and the symbols its names denote.
_TagNames = tuple[tuple[tuple[int, int, str, str, Severity, NameData], ...], tuple[Symbol, ...]]
# Kept by tag (a token shared by equal tags, kept with it so that its id stays its own)
# and zone, as ``id(tag) << 4 | zone`` (NameMemo.tags): a document of a hundred thousand
# ``<Frob/>`` checks one.
# Zones in which no token is a name (see bt_lsp.syntax.nametokens).
_NAMELESS: Final = frozenset({Zone.MODELS, Zone.INCLUDE, Zone.OTHER, Zone.OUTSIDE})


def _tag_names(el: Element, parent: Element | None, memo: NameMemo) -> _TagNames:
    """What the name rules find in ``el``'s start tag (see :data:`_TagNames`)."""
    refs: list[NameRef] = []
    name_refs(el, 0, parent, refs, memo.symbols)
    ts = el.token_start
    found: list[tuple[int, int, str, str, Severity, NameData]] = []
    symbols: dict[Symbol, None] = {}
    for start, end, text, kind, role, symbol, _element, _quote in refs:
        if symbol is not None:
            symbols[symbol] = None
        if kind is None:
            continue
        vs = violations(text, kind, role, memo)
        if vs:
            data = NameData(text, kind, role)
            found.extend(
                (start - ts, end - ts, v.code, v.message, defined(v.code).severity, data)
                for v in vs
            )
    return tuple(found), tuple(symbols)


def _section_name_diagnostics(section: Section, out: list[Diagnostic], memo: NameMemo) -> int:
    """Add the name-rule diagnostics of ``section`` to ``out`` and note the section's
    symbols (:meth:`Section.symbols`) on the way.  Each distinct start tag is checked once
    (equal tags are one token); once ``out`` holds twice :data:`MAX_DIAGNOSTICS`, only the
    first by severity, then position, are kept and later findings past them are counted,
    not made: the count returned.

    The section's rows are told apart by tag and zone in C, from its columns, and only
    those whose tag has findings are read one by one (a document may be a million
    ``<A/>``); but in a section whose elements are kept (made once) or with port
    declarations, whose names depend on their entry (:func:`_element_name_diagnostics`)."""
    els = section.elements
    if els.kept:  # its elements are made once: read as they are
        return _element_name_diagnostics(section, out, memo)
    rows = els.rows
    cols = els.columns
    lo, n = rows.start, len(rows)
    zones = cols.zones[lo : lo + n]
    if _PORT_DECL in zones:
        return _element_name_diagnostics(section, out, memo)
    tags = cols.tags
    # As NameMemo.tags's, as machine integers (a list of them would cost 40 bytes a row).
    keys = array("q", map(or_, map(_SHIFTED, map(id, islice(tags, lo, lo + n))), zones))
    symbols: dict[Symbol, None] = {}
    # What the tags with findings find, by key.
    bad: dict[int, tuple[tuple[int, int, str, str, Severity, NameData], ...]] = {}
    hits: list[tuple[int, tuple[tuple[int, int, str, str, Severity, NameData], ...]]] = []
    root = section.root
    if root is not None and root.zone not in _NAMELESS:  # the head's: read first
        found = _tag_names(root, None, memo)
        symbols.update(dict.fromkeys(found[1]))
        if found[0]:
            hits.append((root.token_start, found[0]))
    shared = memo.tags
    nameless = _NAMELESS_ZONES
    # Each key once, in the order of its first row (with one of its rows).
    for key, i in dict(zip(keys, range(n), strict=True)).items():
        if key & 15 in nameless:
            continue
        tag = tags[lo + i]
        hit = shared.get(key)
        if hit is not None and hit[0] is tag:
            found = hit[1]
        else:
            found = _tag_names(els[i], None, memo)
            if len(shared) >= _MAX_CACHED:
                shared.clear()
            shared[key] = (tag, found)
        symbols.update(dict.fromkeys(found[1]))
        if found[0]:
            bad[key] = found[0]
    placer = _Placer(out)
    if bad or hits:
        starts = cols.starts
        at = els.origin
        picked = compress(range(lo, lo + n), map(bad.__contains__, keys))
        for ts, findings in chain(hits, ((starts[k] + at, bad[keys[k - lo]]) for k in picked)):
            placer.place(ts, findings)
    if "symbols" not in section.cache:  # what Section.symbols() would make from its names
        section.cache["symbols"] = tuple(symbols)
    return placer.more


class _Placer:
    """Places a tag's findings (:data:`_TagNames`) at its start into ``out``, keeping the
    first :data:`MAX_DIAGNOSTICS` by :func:`cap_key`: once ``out`` holds twice as many, the
    rest are cut, and later findings past the last kept are counted (``more``), not
    made."""

    __slots__ = ("limit", "more", "out")

    def __init__(self, out: list[Diagnostic]) -> None:
        self.out = out
        self.more = 0
        self.limit: tuple[int, int, int, str] | None = None

    def place(
        self, ts: int, findings: tuple[tuple[int, int, str, str, Severity, NameData], ...]
    ) -> None:
        out = self.out
        for rs, re_, code, message, severity, data in findings:
            start, end = ts + rs, ts + re_
            limit = self.limit
            if limit is not None and (severity, start, end, code) >= limit:
                self.more += 1  # past the first MAX_DIAGNOSTICS found: never kept
                continue
            out.append(Diagnostic(start, end, code, message, severity, data))
            if len(out) >= 2 * MAX_DIAGNOSTICS:
                out.sort(key=cap_key)  # stable: the first found first among equals
                self.more += len(out) - MAX_DIAGNOSTICS
                del out[MAX_DIAGNOSTICS:]
                self.limit = cap_key(out[-1])


_PORT_DECL: Final = int(Zone.PORT_DECL)
_NAMELESS_ZONES: Final = frozenset(map(int, _NAMELESS))
_SHIFTED: Final = (4).__rlshift__  # x -> x << 4


def _element_name_diagnostics(section: Section, out: list[Diagnostic], memo: NameMemo) -> int:
    """:func:`_section_name_diagnostics` element by element."""
    seen: dict[int, _TagNames] = {}  # this section's tags (alive while it runs)
    shared = memo.tags
    symbols: dict[Symbol, None] = {}
    placer = _Placer(out)
    els = section.elements
    root = section.root
    nameless = _NAMELESS
    port_decl = Zone.PORT_DECL
    for el in chain((root,), els) if root is not None else els:
        zone = el.zone
        if zone in nameless:
            continue
        tag = el.tag
        key = id(tag) << 4 | zone
        found = seen.get(key)
        if found is None:
            if zone == port_decl:  # its symbols depend on the entry it is in: not kept
                p = el.parent
                found = _tag_names(el, els[p - 1] if p > 0 else None, memo)
            else:
                hit = shared.get(key)
                if hit is not None and hit[0] is tag:
                    found = hit[1]
                else:
                    found = _tag_names(el, None, memo)
                    if len(shared) >= _MAX_CACHED:
                        shared.clear()
                    shared[key] = (tag, found)
                seen[key] = found
            for symbol in found[1]:
                symbols[symbol] = None
        if found[0]:
            placer.place(el.token_start, found[0])
    if "symbols" not in section.cache:  # what Section.symbols() would make from its names
        section.cache["symbols"] = tuple(symbols)
    return placer.more


def compute(doc: Document) -> Capped:
    model = doc.model
    memo = names_memo(doc)
    more = 0
    if model.head is None:
        out = lexical_diagnostics(doc.scan)
        out.extend(make(p.start, p.end, p.code, p.message) for p in model.problems)
        out.extend(name_diagnostics(model, memo))
    else:
        # Each section's own diagnostics are kept on it; they are only moved here, from
        # the sections that have some.  Which those are is remembered for the document:
        # an edit leaves all but a few sections as they were.
        head = _own(model.head, memo)
        out = list(head)
        more = head.more
        sections = model.sections
        seen, with_diagnostics = doc.history.memo.get("own-sections", ([], set()))
        p, q = common_ends(seen, sections)
        with_diagnostics = with_diagnostics.difference(seen[p : len(seen) - q])
        with_diagnostics.update(sec for sec in sections[p : len(sections) - q] if _own(sec, memo))
        doc.history.memo["own-sections"] = (sections, with_diagnostics)
        if with_diagnostics:
            origins = model.origins
            for k in compress(count(), map(with_diagnostics.__contains__, sections)):
                o = origins[k]
                own = _own(sections[k], memo)
                more += own.more
                out.extend(
                    Diagnostic(d.start + o, d.end + o, d.code, d.message, d.severity, d.data)
                    for d in own
                )
        if model.tail is not None:
            tail = _own(model.tail, memo)
            out.extend(tail)
            more += tail.more
    return capped(out, more)


def with_severities(
    diags: Iterable[Diagnostic], overrides: Mapping[str, Severity | None]
) -> list[Diagnostic]:
    """Apply per-code severity settings; a code set to ``None`` ("off") is dropped."""
    if not overrides:
        return list(diags)
    out: list[Diagnostic] = []
    for d in diags:
        if d.code in overrides:
            sev = overrides[d.code]
            if sev is None:
                continue
            d = replace(d, severity=sev)
        out.append(d)
    return out


def limited(
    diags: list[Diagnostic], maximum: int = MAX_DIAGNOSTICS, more: int = 0
) -> list[Diagnostic]:
    """At most ``maximum`` diagnostics (the most severe, the first by position among
    equals: :func:`cap_key`), in the order of ``diags``, plus one that says how many were
    left out (``more`` of them before ``diags`` was made): hostile or binary input must
    not flood the client, and hints must not push an error out."""
    left_out = len(diags) + more - maximum
    if left_out <= 0:
        return diags
    if len(diags) > maximum:
        chosen = set(map(id, sorted(diags, key=cap_key)[:maximum]))
        kept = [d for d in diags if id(d) in chosen]
    else:
        kept = list(diags)
    kept.append(
        make(
            0,
            0,
            TOO_MANY_PROBLEMS.code,
            f"{left_out} more problems are not shown (only {maximum} are reported:"
            " errors first, then warnings, information and hints)",
        )
    )
    return kept


def own_diagnostics(doc: Document) -> Capped:
    """The diagnostics of ``doc`` alone (lexical, XML structure, names), kept on it until
    its next edit: the first :data:`MAX_DIAGNOSTICS` by :func:`cap_key`, with how many
    more there are."""
    found = doc.own_diagnostics
    if not isinstance(found, Capped):
        found = doc.own_diagnostics = compute(doc)
    return found


def size_limited(doc: Document, max_bytes: int) -> list[Diagnostic]:
    """What a document larger than ``max_bytes`` (UTF-8) gets: its own diagnostics (XML and
    names, which stay cheap) and ``document-too-large`` saying the rest does not run.
    Capped like every other path, and found with the cyclic collector paused: hostile
    input has the most problems."""
    own = own_diagnostics(doc)
    out = list(limited(own, more=own.more))
    out.append(
        make(
            0,
            0,
            DOCUMENT_TOO_LARGE.code,
            f"Document is {doc.utf8_size} bytes, above btLsp.maxDocumentBytes "
            f"({max_bytes}): only XML and name checks run",
        )
    )
    return out
