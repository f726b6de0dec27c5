"""``workspace/executeCommand`` ``bt-lsp.renderTree``: the picture of the tree at a position.

Arguments: one object ``{uri, position?, tree?, format?, ports?, expandSubtrees?, edited?}``;
the tree is the one named by ``tree``, else the one holding ``position``, else the
document's main tree.  The answer is ``{tree, format, svg | text, trees, nodes, changed}``:
``trees`` lists the document's tree IDs, and each node has its SVG ``id``, its element's
``range`` (in the negotiated position encoding; with ``uri`` when it comes from another
document, an expanded SubTree of an included file), ``kind``, ``type``, ``name``, and for a
SubTree the ``target`` location of the tree it calls.  ``edited``, the range of the text
the client's edits since its last picture replaced (in the document as it is now), gives
``changed``: the ``id`` of the node those edits made or changed, for the client to keep it
in view (``null`` without ``edited`` or for an edit outside the tree).  ``null`` when the
document has no tree.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

from pygls.exceptions import JsonRpcInvalidParams
from pygls.uris import from_fs_path

from bt_lsp.project.pictures import draw
from bt_lsp.render import (
    FORMATS,
    Format,
    Picture,
    changed_node,
    document_trees,
    find_tree,
    render,
    tree_at,
    tree_id_of,
    workspace_resolver,
)
from bt_lsp.rules.context import Context
from bt_lsp.server.app import BtServer
from bt_lsp.server.convert import to_range
from bt_lsp.server.lookup import context_of, path_of
from bt_lsp.server.navigation import RequestFailed
from bt_lsp.syntax.document import Document
from bt_lsp.syntax.elements import Element
from bt_lsp.syntax.text import Encoding

COMMAND = "bt-lsp.renderTree"


def _options(args: tuple[Any, ...]) -> Mapping[str, Any]:
    if len(args) != 1 or not isinstance(args[0], Mapping):
        raise JsonRpcInvalidParams(f"{COMMAND} takes one object: {{uri, position, format?}}")
    opts = args[0]
    if not isinstance(opts.get("uri"), str):
        raise JsonRpcInvalidParams(f"{COMMAND}: 'uri' must be a string")
    fmt = opts.get("format", "svg")
    if fmt not in FORMATS:
        raise JsonRpcInvalidParams(f"{COMMAND}: 'format' must be one of {', '.join(FORMATS)}")
    tree = opts.get("tree")
    if tree is not None and not isinstance(tree, str):
        raise JsonRpcInvalidParams(f"{COMMAND}: 'tree' must be a string")
    return opts


def _position(raw: object, name: str = "position") -> tuple[int, int] | None:
    if raw is None:
        return None
    if not isinstance(raw, Mapping):
        raise JsonRpcInvalidParams(f"{COMMAND}: '{name}' must be {{line, character}}")
    line, character = raw.get("line"), raw.get("character")
    if not isinstance(line, int) or not isinstance(character, int) or line < 0 or character < 0:
        raise JsonRpcInvalidParams(f"{COMMAND}: '{name}' must be {{line, character}}")
    return line, character


def _edited(raw: object) -> tuple[tuple[int, int], tuple[int, int]] | None:
    if raw is None:
        return None
    if not isinstance(raw, Mapping):
        raise JsonRpcInvalidParams(f"{COMMAND}: 'edited' must be a range {{start, end}}")
    start, end = _position(raw.get("start"), "edited"), _position(raw.get("end"), "edited")
    if start is None or end is None:
        raise JsonRpcInvalidParams(f"{COMMAND}: 'edited' must be a range {{start, end}}")
    return start, end


def range_json(doc: Document, start: int, end: int, enc: Encoding) -> dict[str, Any]:
    """The LSP range of ``doc[start:end]`` as JSON (offsets past the text clamped)."""
    n = len(doc.text)
    r = to_range(doc.lines, min(start, n), min(end, n), enc)
    return {
        "start": {"line": r.start.line, "character": r.start.character},
        "end": {"line": r.end.line, "character": r.end.character},
    }


class Places:
    """Documents by the picture's ``source`` key (``None`` is the rendered one)."""

    def __init__(self, ls: BtServer, uri: str, doc: Document) -> None:
        self.ls = ls
        self.uri = uri
        self.doc = doc
        # The URI and document of each source asked for (None: none found).
        self._by_source: dict[str, tuple[str, Document] | None] = {}

    def get(self, source: str | None) -> tuple[str, Document] | None:
        if source is None:
            return self.uri, self.doc
        if source not in self._by_source:
            path = Path(source)
            found: tuple[str, Document] | None = None
            for od in self.ls.docs.values():  # an open document's text wins over the file
                if path_of(od) == path:
                    found = od.uri, od.doc
            if found is None:
                doc = self.ls.project.document(path)
                found = (from_fs_path(source) or source, doc) if doc is not None else None
            self._by_source[source] = found
        return self._by_source[source]


def _nodes(
    picture: Picture,
    places: Places,
    targets: Mapping[str, tuple[str | None, Element]],
    enc: Encoding,
) -> list[dict[str, Any]]:
    out: list[dict[str, Any]] = []
    for node in picture.nodes:
        place = places.get(node.source)
        item: dict[str, Any] = {
            "id": node.id,
            "kind": node.kind,
            "type": node.type,
            "name": node.name,
        }
        if place is not None:
            uri, doc = place
            item["range"] = range_json(doc, node.start, node.end, enc)
            if node.source is not None:
                item["uri"] = uri
        if node.severity is not None:
            item["severity"] = int(node.severity)
        if node.subtree is not None:
            item["subtree"] = node.subtree
            target = targets.get(node.subtree)
            tplace = places.get(target[0]) if target is not None else None
            if target is not None and tplace is not None:
                el = target[1]
                item["target"] = {
                    "uri": tplace[0],
                    "range": range_json(tplace[1], el.name_start, el.name_end, enc),
                }
        out.append(item)
    return out


def render_tree(ls: BtServer, *args: Any) -> dict[str, Any] | None:
    opts = _options(args)
    edited = _edited(opts.get("edited"))
    uri = opts["uri"]
    od = ls.get(uri)
    if od is None:
        raise RequestFailed(f"{uri} is not an open document")
    model = od.doc.model
    trees = document_trees(model)
    enc = ls.encoding
    tree: Element | None
    if opts.get("tree") is not None:
        tree = find_tree(model, opts["tree"])
        if tree is None:
            raise RequestFailed(f"no tree {opts['tree']!r} in {uri}")
    elif not trees:
        return None
    else:
        pos = _position(opts.get("position"))
        offset = od.doc.lines.offset(pos[0], pos[1], enc) if pos is not None else -1
        tree = tree_at(model, offset)
    assert tree is not None
    fmt: Format = opts.get("format", "svg")
    ports = bool(opts.get("ports", False))
    expand = bool(opts.get("expandSubtrees", False))
    diagnostics = ls.diagnostics.of(od) if od.is_bt else []
    path = path_of(od)
    if path is not None:
        text, picture = draw(
            ls.project,
            path,
            od.doc,
            tree,
            fmt,
            ports=ports,
            expand_subtrees=expand,
            diagnostics=diagnostics,
        )
        others = {str(p): d.model for p, d in ls.project.bt_documents()}
        resolve = workspace_resolver(model, context_of(ls, od), others)
    else:  # an untitled document sees only itself
        ctx = Context.from_document(od.doc)
        text, picture = render(
            model,
            tree,
            fmt,
            ctx=ctx,
            diagnostics=diagnostics,
            ports=ports,
            expand_subtrees=expand,
            text_length=len(od.doc.text),
        )
        resolve = workspace_resolver(model, ctx)
    # Where each called tree is, for a client to open it.
    targets: dict[str, tuple[str | None, Element]] = {}
    for node in picture.nodes:
        if node.subtree is not None and node.subtree not in targets:
            found = resolve(node.subtree)
            if found is not None:
                targets[node.subtree] = (found.source, found.element)
    changed: str | None = None
    if edited is not None:
        (sl, sc), (el, ec) = edited
        lines = od.doc.lines
        hit = changed_node(picture, lines.offset(sl, sc, enc), lines.offset(el, ec, enc))
        changed = hit.id if hit is not None else None
    places = Places(ls, uri, od.doc)
    return {
        "tree": picture.tree_id,
        "format": fmt,
        ("svg" if fmt == "svg" else "text"): text,
        "trees": [tree_id_of(t) for t in trees],
        "truncated": picture.truncated,
        "nodes": _nodes(picture, places, targets, enc),
        "changed": changed,
    }


def register(server: BtServer) -> None:
    @server.command(COMMAND)
    def _render_tree(ls: BtServer, *args: Any) -> dict[str, Any] | None:
        return render_tree(ls, *args)
