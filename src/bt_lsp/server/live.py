"""``workspace/executeCommand`` ``bt-lsp.mapRunningTree``: where each node of a running tree
is in the text, for an editor that shows a live tree's statuses on its elements.

Argument: one object ``{uri, tree}``: an open document and the running tree's XML, as the
executor answers Groot2's FULLTREE (``Groot2Client.read_tree().xml``), or a ``.btlog``
holds.  The tree is mapped onto the document, the trees its includes and the workspace
declare (``bt_lsp.live.mapping``).  The answer is ``{tree, treeLocation, nodes,
mismatches}``: ``nodes`` lists ``{uid, uri, range}`` (the range of the element's start
tag name, in the negotiated position encoding), ``mismatches`` each difference between
the running tree and the text (``kind``: renamed, changed, missing, added, tree;
``message``; the running node's ``uid``, ``tag``, ``name`` and ``path`` when there is
one; its ``uri`` and ``range`` in the text when it is there).  A tree that is not such
XML (malformed, too large, a node without a uid) is InvalidParams, with the reason.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any

from pygls.exceptions import JsonRpcInvalidParams

from bt_lsp.ide.places import Place
from bt_lsp.live.mapping import Mismatch, TreeMap, map_tree
from bt_lsp.live.protocol import ProtocolError
from bt_lsp.live.tree import LiveTree, parse_tree_xml
from bt_lsp.project.pictures import tree_resolver
from bt_lsp.render import workspace_resolver
from bt_lsp.rules.context import Context
from bt_lsp.server.app import BtServer
from bt_lsp.server.lookup import context_of, path_of
from bt_lsp.server.navigation import RequestFailed
from bt_lsp.server.render import Places, range_json
from bt_lsp.server.state import OpenDocument

COMMAND = "bt-lsp.mapRunningTree"


def _options(args: tuple[Any, ...]) -> tuple[str, str]:
    if len(args) != 1 or not isinstance(args[0], Mapping):
        raise JsonRpcInvalidParams(f"{COMMAND} takes one object: {{uri, tree}}")
    uri, tree = args[0].get("uri"), args[0].get("tree")
    if not isinstance(uri, str):
        raise JsonRpcInvalidParams(f"{COMMAND}: 'uri' must be a string")
    if not isinstance(tree, str):
        raise JsonRpcInvalidParams(f"{COMMAND}: 'tree' must be the running tree's XML")
    return uri, tree


def map_onto(ls: BtServer, od: OpenDocument, live: LiveTree) -> TreeMap:
    """``live`` mapped onto the open document ``od``, the trees its includes and the
    workspace declare (an untitled document sees only itself)."""
    doc = od.doc
    path = path_of(od)
    if path is not None:
        resolve = tree_resolver(ls.project, path, doc, context_of(ls, od))
    else:
        resolve = workspace_resolver(doc.model, Context.from_document(doc))
    return map_tree(live, doc.model, resolve)


Locate = Callable[[Place], dict[str, Any] | None]


def locator(ls: BtServer, od: OpenDocument) -> Locate:
    """Where a mapped place is: ``{uri, range}`` in the negotiated encoding, or None for
    a file that cannot be read."""
    places = Places(ls, od.uri, od.doc)
    enc = ls.encoding

    def location(place: Place) -> dict[str, Any] | None:
        found = places.get(place.path)
        if found is None:
            return None
        where, d = found
        return {"uri": where, "range": range_json(d, place.start, place.end, enc)}

    return location


def mismatch_json(m: Mismatch, location: Locate) -> dict[str, Any]:
    """One mismatch as the commands answer it."""
    item: dict[str, Any] = {"kind": m.kind, "message": m.message, "uid": m.uid}
    if m.node is not None:
        item.update(tag=m.node.tag, name=m.node.name, path=m.node.path)
    if m.place is not None:
        item.update(location(m.place) or {})
    return item


def map_running_tree(ls: BtServer, *args: Any) -> dict[str, Any]:
    uri, xml = _options(args)
    od = ls.get(uri)
    if od is None:
        raise RequestFailed(f"{uri} is not an open document")
    try:
        live = parse_tree_xml(xml)
    except ProtocolError as e:
        raise JsonRpcInvalidParams(f"{COMMAND}: {e}") from None
    tm = map_onto(ls, od, live)
    location = locator(ls, od)
    nodes = []
    for uid in sorted(tm.places):
        loc = location(tm.places[uid])
        if loc is not None:
            nodes.append({"uid": uid, **loc})
    return {
        "tree": tm.tree_id,
        "treeLocation": location(tm.tree) if tm.tree is not None else None,
        "nodes": nodes,
        "mismatches": [mismatch_json(m, location) for m in tm.mismatches],
    }


def register(server: BtServer) -> None:
    @server.command(COMMAND)
    def _map_running_tree(ls: BtServer, *args: Any) -> dict[str, Any]:
        return map_running_tree(ls, *args)
