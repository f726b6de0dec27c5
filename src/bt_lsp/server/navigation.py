"""Navigation features: definition, references, highlights, rename, document and workspace
symbols, folding ranges and linked editing.  Each handler converts positions with the
document's own line index in the negotiated encoding and calls the features of :mod:`bt_lsp.ide`.
"""

from __future__ import annotations

import json
import os
import re
import tempfile
from bisect import bisect_right
from collections.abc import Callable, Generator, Iterator, Sequence
from itertools import repeat
from pathlib import Path
from typing import TYPE_CHECKING, Any

from lsprotocol import types
from pygls.exceptions import JsonRpcException
from pygls.uris import from_fs_path

from bt_lsp import __version__
from bt_lsp.ide.catalog import BUILTIN_CATALOG, BUILTIN_CATALOG_V3, builtin_catalog
from bt_lsp.ide.definition import definition as find_definition
from bt_lsp.ide.folding import folding_ranges, linked_editing_ranges
from bt_lsp.ide.places import Place
from bt_lsp.ide.references import highlights
from bt_lsp.ide.references import references as find_references
from bt_lsp.ide.rename import RenameRefused
from bt_lsp.ide.rename import prepare_rename as rename_target
from bt_lsp.ide.rename import rename as plan_rename
from bt_lsp.ide.symbols import (
    KEPT,
    DocSymbol,
    SymbolKind,
    categories_hold,
    iter_outline_parts,
    workspace_symbols,
)
from bt_lsp.project.index import links
from bt_lsp.rules.context import Context
from bt_lsp.server.convert import RawJson, to_range, to_ranges, to_text_edits, workspace_edit
from bt_lsp.server.lookup import (
    Source,
    at_position,
    context_of,
    includes_of,
    source_at,
    workspace_sources,
)
from bt_lsp.server.state import OpenDocument
from bt_lsp.syntax.document import Document
from bt_lsp.syntax.edits import TextEdit
from bt_lsp.syntax.sections import Section
from bt_lsp.syntax.text import Encoding, LineIndex

if TYPE_CHECKING:
    from bt_lsp.server.app import BtServer

_SYMBOL_KINDS = {
    SymbolKind.TREE: types.SymbolKind.Class,
    SymbolKind.NODE: types.SymbolKind.Function,
    SymbolKind.SUBTREE: types.SymbolKind.Module,
    SymbolKind.MODELS: types.SymbolKind.Namespace,
    SymbolKind.MODEL: types.SymbolKind.Interface,
    SymbolKind.PORT: types.SymbolKind.Property,
    SymbolKind.INCLUDE: types.SymbolKind.File,
}
_KIND_NUMBERS = {kind: str(int(number)) for kind, number in _SYMBOL_KINDS.items()}


class RequestFailed(JsonRpcException):
    """LSP's ``RequestFailed``: the request was valid but cannot be done (the message says
    why, and editors show it)."""

    CODE = types.LSPErrorCodes.RequestFailed.value


# --- the built-in catalog file ------------------------------------------------------------

_catalogs: dict[str, tuple[str, LineIndex]] = {}  # by place path


def _catalog_dirs() -> list[Path]:
    cache = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return [Path(cache) / "bt-lsp" / __version__]


def catalog_file(place: str = BUILTIN_CATALOG) -> tuple[str, LineIndex] | None:
    """The URI and line index of a built-in catalog (``place`` names it: 4.x's or
    3.8's), written once per process to the user's cache folder (or a private temporary
    folder) so that editors can open it."""
    hit = _catalogs.get(place)
    if hit is not None:
        return hit
    name = place.split(":", 1)[1]
    text = builtin_catalog("3" if place == BUILTIN_CATALOG_V3 else None).text
    for folder in _catalog_dirs():
        try:
            folder.mkdir(parents=True, exist_ok=True)
            path = folder / name
            if not path.is_file() or path.read_text(encoding="utf-8") != text:
                path.write_text(text, encoding="utf-8")
            break
        except OSError:
            continue
    else:
        try:
            path = Path(tempfile.mkdtemp(prefix="bt-lsp-")) / name
            path.write_text(text, encoding="utf-8")
        except OSError:
            return None
    uri = from_fs_path(str(path))
    if uri is None:
        return None
    _catalogs[place] = (uri, LineIndex(text))
    return _catalogs[place]


# --- conversions --------------------------------------------------------------------------


def _located(
    ls: BtServer, od: OpenDocument, places: Sequence[Place], sources: dict[str, Source]
) -> Iterator[tuple[str, tuple[int, int], tuple[int, int]]]:
    """Each of ``places`` as its document's URI and its start and end positions, in
    order; the positions of each document found together (:meth:`LineIndex.positions`:
    one at a time, each counts its line from its start, and a name used a million times
    on one 8 MB line took minutes); a place in a document no longer found is left out."""
    enc = ls.encoding
    offsets: dict[str | None, list[int]] = {}
    for p in places:
        offsets.setdefault(p.path, []).extend((p.start, p.end))
    files: dict[str | None, tuple[str, dict[int, tuple[int, int]]] | None] = {}
    for path, found in offsets.items():
        if path is None:
            uri, lines = od.uri, od.doc.lines
        elif path in (BUILTIN_CATALOG, BUILTIN_CATALOG_V3):
            catalog = catalog_file(path)
            if catalog is None:
                files[path] = None
                continue
            uri, lines = catalog
        else:
            src = source_at(ls, sources, path)
            if src is None:
                files[path] = None
                continue
            uri, lines = src.uri, src.doc.lines
        files[path] = (uri, lines.positions(found, enc))
    for p in places:
        file = files[p.path]
        if file is not None:
            yield file[0], file[1][p.start], file[1][p.end]


def _locations(
    ls: BtServer, od: OpenDocument, places: Sequence[Place], sources: dict[str, Source]
) -> list[types.Location]:
    P, R = types.Position, types.Range
    return [
        types.Location(uri=uri, range=R(P(*s), P(*e)))
        for uri, s, e in _located(ls, od, places, sources)
    ]


def _locations_json(
    ls: BtServer, od: OpenDocument, places: Sequence[Place], sources: dict[str, Source]
) -> RawJson:
    """:func:`_locations` written as JSON text: a name's references may be a million
    places, and a million lsprotocol objects, unstructured again, took seconds more."""
    uris: dict[str, str] = {}
    parts: list[str] = []
    for uri, (sl, sc), (el, ec) in _located(ls, od, places, sources):
        quoted = uris.get(uri)
        if quoted is None:
            quoted = uris[uri] = json.dumps(uri)
        parts.append(
            f'{{"uri":{quoted},"range":{{"start":{{"line":{sl},"character":{sc}}},'
            f'"end":{{"line":{el},"character":{ec}}}}}}}'
        )
    return RawJson(f"[{','.join(parts)}]")


def rename_edit(
    ls: BtServer,
    od: OpenDocument,
    edits: Sequence[TextEdit],
    other_edits: dict[str, tuple[TextEdit, ...]],
    sources: dict[str, Source],
    what: str = "the rename",
) -> types.WorkspaceEdit:
    """A WorkspaceEdit over several documents, each converted with its own line index
    (versioned for open documents when the client supports document changes); ``what``
    says in the other files' change annotations what renames them."""
    enc = ls.encoding
    per_uri: list[tuple[str, int | None, list[types.TextEdit]]] = [
        (od.uri, od.version, to_text_edits(od.doc.lines, edits, enc))
    ]
    for key, file_edits in other_edits.items():
        src = sources.get(key)
        if src is None:
            continue
        per_uri.append((src.uri, src.version, to_text_edits(src.doc.lines, file_edits, enc)))
    return workspace_edit(per_uri, ls.versioned_edits, ls.annotated_edits, what)


# The outline's nesting depth.  BehaviorTree.CPP allows trees 256 levels deep; a symbol
# deeper than this is listed after its ancestor at this depth, in document order (its
# range stays inside the ancestor's parent), so that no nesting of the answer, in the
# server or in the client, has to recurse hundreds of levels deep.
MAX_SYMBOL_DEPTH = 64


def _pre_order(top: Sequence[DocSymbol]) -> list[tuple[DocSymbol, int]]:
    """The symbols with their depth (from 1), in document order, without recursion."""
    order: list[tuple[DocSymbol, int]] = []
    add = order.append
    stack = [(s, 1) for s in reversed(top)]
    pop, push = stack.pop, stack.extend
    while stack:
        s, depth = pop()
        add((s, depth))
        if s.children:  # most symbols are leaves
            push(zip(reversed(s.children), repeat(min(depth + 1, MAX_SYMBOL_DEPTH))))
    return order


def _write(
    order: list[tuple[DocSymbol, int]], out: list[str], rng: Callable[[int, int], str]
) -> None:
    """Append the symbols of ``order`` to ``out`` as the JSON of LSP DocumentSymbols,
    separated by commas, without the enclosing brackets; ``rng`` writes a range."""
    first = [True] * (MAX_SYMBOL_DEPTH + 2)  # no symbol yet in the open list at a depth
    open_depth = 0
    add = out.append
    quoted: dict[str, str] = {}  # names and details repeat: each is quoted once
    for s, depth in order:
        while open_depth >= depth:  # close the symbols this one is not inside
            add("]}")
            open_depth -= 1
        if not first[depth]:
            add(", ")
        first[depth] = False
        name = quoted.get(s.name)
        if name is None:
            name = quoted[s.name] = json.dumps(s.name)
        detail = ""
        if s.detail:
            detail = quoted.get(s.detail) or quoted.setdefault(s.detail, json.dumps(s.detail))
            detail = f'"detail": {detail}, '
        add(
            f'{{"name": {name}, {detail}"kind": {_KIND_NUMBERS[s.kind]}, '
            f'"range": {rng(s.start, s.end)}, "selectionRange": {rng(s.sel_start, s.sel_end)}, '
            '"children": ['
        )
        first[depth + 1] = True
        open_depth = depth
    add("]}" * open_depth)


def _symbols_text(lines: LineIndex, top: Sequence[DocSymbol], enc: Encoding) -> str:
    """The symbols of ``top`` (document coordinates) as comma-separated JSON objects."""
    order = _pre_order(top)
    at = lines.positions(
        [o for s, _ in order for o in (s.start, s.end, s.sel_start, s.sel_end)], enc
    )
    out: list[str] = []

    def rng(start: int, end: int) -> str:
        (sl, sc), (el, ec) = at[start], at[end]
        return (
            f'{{"start": {{"line": {sl}, "character": {sc}}}, '
            f'"end": {{"line": {el}, "character": {ec}}}}}'
        )

    _write(order, out, rng)
    return "".join(out)


def document_symbols_json(lines: LineIndex, top: Sequence[DocSymbol], enc: Encoding) -> RawJson:
    """The outline as the JSON text of LSP DocumentSymbols, written in one pre-order walk
    without recursion: building lsprotocol objects and unstructuring them cost ten times
    the outline itself on a large document."""
    return RawJson(f"[{_symbols_text(lines, top, enc)}]")


class _Rendered:
    """A section's outline as the JSON text it was last written as, with the position
    (``line``, ``column``) its section started at then, the encoding, and the custom
    node types' categories it shows: only the text is kept, neither the symbols nor
    pieces to fill in (they took a large outline's server to 32 times its document).
    Where the section moved, its numbers are moved in the text (:meth:`at`).

    The text and its position are one tuple, replaced in one assignment: a section is
    shared by the open document and its snapshots, whose outlines may be written on two
    threads at once, and a text moved from one position must never be kept with another."""

    __slots__ = ("categories", "enc", "state")

    def __init__(
        self, text: str, line: int, column: int, enc: Encoding, categories: dict[str, str]
    ) -> None:
        self.state = (text, line, column)
        self.enc, self.categories = enc, categories

    @property
    def text(self) -> str:
        return self.state[0]

    def at(self, line: int, column: int) -> str:
        """The text for a section that now starts at (``line``, ``column``)."""
        text, line0, column0 = self.state
        dl, dc = line - line0, column - column0
        if not (dl or dc):
            return text
        if dc:  # the columns on the section's first line move too
            first = str(line0)

            def move(m: re.Match[str]) -> str:
                row, col = m[1], int(m[2])
                return _POSITION % (int(row) + dl, col + dc if row == first else col)

            text = _POSITIONS.sub(move, text)
        else:
            moved: dict[str, str] = {}  # a line's positions are written alike

            def move_line(m: re.Match[str]) -> str:
                row = m[1]
                found = moved.get(row)
                if found is None:
                    found = moved[row] = _LINE % (int(row) + dl)
                return found

            text = _LINES.sub(move_line, text)
        self.state = (text, line, column)
        return text


_POSITIONS = re.compile(r'"line": (\d+), "character": (\d+)')
_POSITION = '"line": %d, "character": %d'
_LINES = re.compile(r'"line": (\d+)')
_LINE = '"line": %d'


def _section_text(
    lines: LineIndex, origin: int, top: Sequence[DocSymbol], enc: Encoding, line0: int
) -> str:
    """The JSON of a section's symbols (offsets from ``origin``, which is on line
    ``line0``) in document coordinates."""
    order = _pre_order(top)
    pos: Callable[[int], str]
    if lines.plain_columns(enc):
        # A column is a distance: the section's line starts are enough (one C search per
        # position, no sorting of the positions).
        reach = max(max(s.end, s.sel_end) for s, _ in order) if order else 0
        _, starts = lines.starts_between(origin, origin + reach)
        local = [start - origin for start in starts]  # local[0] <= 0: the first line's
        col0 = -local[0] if local else 0

        def pos(offset: int) -> str:
            k = bisect_right(local, offset) - 1
            if k <= 0:  # on the first line
                return f'{{"line": {line0}, "character": {col0 + offset}}}'
            return f'{{"line": {line0 + k}, "character": {offset - local[k]}}}'

    else:
        at = lines.positions(
            [origin + o for s, _ in order for o in (s.start, s.end, s.sel_start, s.sel_end)],
            enc,
        )

        def pos(offset: int) -> str:
            line, col = at[origin + offset]
            return f'{{"line": {line}, "character": {col}}}'

    out: list[str] = []

    def rng(start: int, end: int) -> str:
        return f'{{"start": {pos(start)}, "end": {pos(end)}}}'

    _write(order, out, rng)
    return "".join(out)


def outline_json(doc: Document, ctx: Context, enc: Encoding) -> RawJson:
    """:func:`document_symbols_json` of the document's outline, made of its sections'
    pieces: a section's JSON is kept on it (with the categories it shows, see
    :func:`bt_lsp.ide.symbols.section_outline`) and only its numbers moved where it
    moved, so that the outline after an edit costs what the edit changed."""
    lines = doc.lines

    def kept(sec: Section) -> bool:
        found: _Rendered | None = sec.cache.get("outline-json")
        return found is not None and found.enc == enc and categories_hold(found.categories, ctx)

    texts: list[str] = []
    model = doc.model
    # Section by section: only one section's symbols at a time, not all of them.
    origins = lines.positions(model.origins if model.head is not None else (), enc)
    for part in iter_outline_parts(doc, ctx, kept):
        sec = part.section
        if sec is None:
            if part.outline.symbols:
                texts.extend((_symbols_text(lines, part.outline.symbols, enc), ", "))
            continue
        line, column = origins[part.origin]
        if part.outline is KEPT:
            text = sec.cache["outline-json"].at(line, column)
        else:
            symbols = part.outline.symbols
            text = _section_text(lines, part.origin, symbols, enc, line) if symbols else ""
            sec.cache["outline-json"] = _Rendered(text, line, column, enc, part.outline.categories)
        if text:
            texts.extend((text, ", "))
    if not texts:
        return RawJson("[]")
    texts[0], texts[-1] = "[" + texts[0], "]"  # one join, no copy of it
    return RawJson("".join(texts))


def folding_json(od: OpenDocument) -> RawJson:
    """The folding ranges as JSON text, kept for the document's version: a request sent
    with the open of a large document finds them made by the worker thread, and lsprotocol
    objects for 55,000 ranges cost a third of finding them."""
    kept = od.folding
    if kept is not None and kept[0] == od.version:
        return RawJson(kept[1])
    od.folding = (od.version, folding_text(od.doc))
    return RawJson(od.folding[1])


def folding_text(doc: Document) -> str:
    """The JSON text of the document's folding ranges."""
    text = ", ".join(
        f'{{"startLine": {f.start_line}, "endLine": {f.end_line}, '
        f'"kind": "{"comment" if f.comment else "region"}"}}'
        for f in folding_ranges(doc)
    )
    return f"[{text}]"


def _snapshot(od: OpenDocument) -> Document:
    """A copy of the open document for another thread: its model made first (after an
    edit, only the sections the edit touched), so that both do not make it."""
    _ = od.doc.model
    return od.doc.snapshot()


# --- features -----------------------------------------------------------------------------


def register(server: BtServer) -> None:
    @server.feature(types.TEXT_DOCUMENT_DEFINITION)
    def definition(ls: BtServer, params: types.DefinitionParams) -> list[types.Location] | None:
        req = at_position(ls, params)
        if req is None:
            return None
        od = req.od
        in_cpp = ls.cpp.definition(od, req.offset)
        if in_cpp is not None:  # a node or port learned from C++: its class, registration, call
            return in_cpp
        sources = workspace_sources(ls, od)
        places = find_definition(
            od.doc,
            req.offset,
            {k: s.doc for k, s in sources.items()},
            ctx=req.context(),
            includes=links(includes_of(ls, od)),
        )
        return _locations(ls, od, places, sources) or None

    @server.feature(types.TEXT_DOCUMENT_REFERENCES)
    def references(ls: BtServer, params: types.ReferenceParams) -> RawJson | None:
        req = at_position(ls, params)
        if req is None:
            return None
        od = req.od
        sources = workspace_sources(ls, od)
        places = find_references(
            od.doc,
            req.offset,
            {k: s.doc for k, s in sources.items()},
            include_declaration=params.context.include_declaration,
        )
        return _locations_json(ls, od, places, sources)

    @server.feature(types.TEXT_DOCUMENT_DOCUMENT_HIGHLIGHT)
    def highlight(
        ls: BtServer, params: types.DocumentHighlightParams
    ) -> list[types.DocumentHighlight] | None:
        req = at_position(ls, params)
        if req is None:
            return None
        found = highlights(req.doc, req.offset)
        ranges = to_ranges(req.doc.lines, ((h.start, h.end) for h in found), req.enc)
        return [
            types.DocumentHighlight(
                range=rng,
                kind=types.DocumentHighlightKind.Text
                if h.text
                else types.DocumentHighlightKind.Write
                if h.write
                else types.DocumentHighlightKind.Read,
            )
            for h, rng in zip(found, ranges, strict=True)
        ]

    @server.feature(types.TEXT_DOCUMENT_PREPARE_RENAME)
    def prepare_rename(
        ls: BtServer, params: types.PrepareRenameParams
    ) -> types.PrepareRenamePlaceholder | None:
        req = at_position(ls, params)
        if req is None:
            return None
        try:
            target = rename_target(req.doc, req.offset, req.context().btcpp_version)
        except RenameRefused as e:
            raise RequestFailed(e.message) from None
        if target is None:
            return None
        return types.PrepareRenamePlaceholder(
            range=req.range(target.start, target.end),
            placeholder=target.placeholder,
        )

    @server.feature(types.TEXT_DOCUMENT_RENAME)
    def rename(ls: BtServer, params: types.RenameParams) -> types.WorkspaceEdit | None:
        req = at_position(ls, params)
        if req is None:
            return None
        od = req.od
        sources = workspace_sources(ls, od)
        try:
            plan = plan_rename(
                od.doc,
                req.offset,
                params.new_name,
                {k: s.doc for k, s in sources.items()},
                version=req.context().btcpp_version,
            )
        except RenameRefused as e:
            raise RequestFailed(e.message) from None
        if plan is None:
            return None
        target = rename_target(od.doc, req.offset, req.context().btcpp_version)
        what = f"Rename '{target.placeholder}' to '{params.new_name}'" if target else "the rename"
        return rename_edit(ls, od, plan.edits, dict(plan.other_edits), sources, what)

    @server.feature(types.TEXT_DOCUMENT_DOCUMENT_SYMBOL)
    def document_symbol(
        ls: BtServer, params: types.DocumentSymbolParams
    ) -> Generator[Any, Any, RawJson | None]:
        od = ls.get(params.text_document.uri)
        if od is None or not od.is_bt:
            return None
        ctx = context_of(ls, od)
        if not ls.background.wants(od):
            return outline_json(od.doc, ctx, ls.encoding)
        # A large document's: beside the loop, which answers the other requests meanwhile,
        # from the document as the request found it (see Background.beside).
        outline: RawJson = yield ls.background.beside(outline_json, _snapshot(od), ctx, ls.encoding)
        return outline

    @server.feature(types.WORKSPACE_SYMBOL)
    def workspace_symbol(
        ls: BtServer, params: types.WorkspaceSymbolParams
    ) -> list[types.WorkspaceSymbol]:
        enc = ls.encoding
        sources = workspace_sources(ls)
        found = workspace_symbols(((k, s.doc) for k, s in sources.items()), params.query)
        out: list[types.WorkspaceSymbol] = []
        for s in found:
            src = sources[s.path]
            out.append(
                types.WorkspaceSymbol(
                    name=s.name,
                    kind=_SYMBOL_KINDS[s.kind],
                    location=types.Location(
                        uri=src.uri, range=to_range(src.doc.lines, s.start, s.end, enc)
                    ),
                    container_name=f"{s.detail} in {os.path.basename(s.path)}",
                )
            )
        return out

    @server.feature(types.TEXT_DOCUMENT_FOLDING_RANGE)
    def folding_range(
        ls: BtServer, params: types.FoldingRangeParams
    ) -> Generator[Any, Any, RawJson | None]:
        od = ls.get(params.text_document.uri)
        if od is None or not od.is_bt:
            return None
        kept = od.folding
        if (kept is not None and kept[0] == od.version) or not ls.background.wants(od):
            return folding_json(od)
        version = od.version
        text: str = yield ls.background.beside(folding_text, _snapshot(od))
        if od.version == version:  # (else an edit came meanwhile: not the current ones)
            od.folding = (version, text)
        return RawJson(text)

    @server.feature(types.TEXT_DOCUMENT_LINKED_EDITING_RANGE)
    def linked_editing_range(
        ls: BtServer, params: types.LinkedEditingRangeParams
    ) -> types.LinkedEditingRanges | None:
        req = at_position(ls, params)
        if req is None:
            return None
        spans = linked_editing_ranges(req.doc, req.offset)
        if spans is None:
            return None
        return types.LinkedEditingRanges(
            ranges=to_ranges(req.doc.lines, spans, req.enc),
            word_pattern=r"[^\s<>/=\"']+",
        )
