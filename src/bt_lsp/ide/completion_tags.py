"""Completion of element names: a start tag after ``<``, the elements that fit on an
empty line or between tags (written with their ``<``), an end tag after ``</``."""

from __future__ import annotations

import re
from collections.abc import Iterable

from bt_lsp.ide.blackboard import enclosing_tree
from bt_lsp.ide.completion_items import (
    Completions,
    Item,
    ItemKind,
    attr_text,
    md_code,
    ports_markdown,
    snippet_literal,
    tree_id,
    tree_ids,
    with_ports,
)
from bt_lsp.ide.ports import builtins_in
from bt_lsp.rules.context import Context, source_label
from bt_lsp.syntax.document import Document
from bt_lsp.syntax.elements import Zone
from bt_lsp.syntax.model import Model
from bt_lsp.syntax.tokens import Token

# Models learned from C++ (bt_lsp.project.cpp_models) are declared in a C++ file.
_CPP = (".cpp", ".hpp", ".h", ".cc", ".cxx", ".hh", ".hxx", ".ipp")


def innermost(model: Model, offset: int) -> int:
    """The innermost element whose content holds ``offset`` (-1: none)."""
    found = -1
    for i, el in enumerate(model.elements):
        if el.token_start >= offset:
            break
        if el.self_closing or not el.closed:
            continue  # no content
        if el.end == -1 or el.end_name_start - 2 >= offset:
            found = i
    return found


def tag_names(
    doc: Document, ctx: Context, start: int, end: int, parent: int, *, bare: bool
) -> Completions:
    model = doc.model
    pz = model.elements[parent].zone if parent >= 0 else None
    items: list[Item] = []
    if pz is None:
        if model.root is None:
            items.append(_structural("root", 'BTCPP_format="4"', leaf=False, bare=bare))
    elif pz == Zone.ROOT:
        items.append(
            _structural("BehaviorTree", 'ID="$1"', leaf=False, bare=bare, plain_attrs='ID=""')
        )
        items.append(_structural("TreeNodesModel", "", leaf=False, bare=bare))
        items.append(
            _structural("include", 'path="$1"', leaf=True, bare=bare, plain_attrs='path=""')
        )
    elif pz in (Zone.TREE, Zone.NODE):
        tree = enclosing_tree(model, parent)
        items.extend(_node_items(ctx, bare, tree_id(model, tree)))
    elif pz == Zone.MODELS:
        for cat in ("Action", "Condition", "Control", "Decorator", "SubTree"):
            items.append(_structural(cat, 'ID="$1"', leaf=False, bare=bare, plain_attrs='ID=""'))
    elif pz == Zone.MODEL_ENTRY:
        for tag in ("input_port", "output_port", "inout_port"):
            items.append(
                _structural(
                    tag, 'name="$1" type="$2"', leaf=True, bare=bare, plain_attrs='name="" type=""'
                )
            )
    return Completions(start, end, "tag", items)


def _is_name_char(c: str) -> bool:
    return c.isalnum() or c in "_-.:" or ord(c) > 127


def _at_line_end(text: str, offset: int) -> bool:
    """Whether only white space follows ``offset`` on its line."""
    m = _REST_OF_LINE_RE.match(text, offset)
    return m is not None and (m.end() == len(text) or text[m.end()] in "\r\n")


_REST_OF_LINE_RE = re.compile(r"[ \t]*")
_TAG_AHEAD_RE = re.compile(r"[ \t]*<")


def _fits(doc: Document, ctx: Context, parent: int) -> bool:
    """Whether another element fits in the element ``parent``: not in a leaf node, a
    decorator that has its child, or a tree that has its one child."""
    model = doc.model
    el = model.elements[parent]
    if el.zone not in (Zone.TREE, Zone.NODE):
        return True
    children = sum(
        1 for c in model.elements[parent + 1 :] if c.parent == parent and c.zone == Zone.NODE
    )
    if el.zone == Zone.TREE:
        return children == 0
    node_id = el.node_id
    if el.name == "SubTree" or node_id is None:
        return el.name != "SubTree"
    b = builtins_in(ctx).get(node_id)
    if b is not None:
        most = b.max_children
    elif node_id in ctx.models:
        most = ctx.models[node_id].child_range[1]
    else:
        return True  # an unknown node type: it may take children
    return most is None or children < most


def between_tags(doc: Document, ctx: Context, offset: int, text_start: int) -> Completions | None:
    """Completions with no ``<`` typed: on an empty line or between tags, the elements
    that fit there, each written with its ``<``, replacing the name typed so far."""
    text = doc.text
    start = offset
    while start > text_start and _is_name_char(text[start - 1]):
        start -= 1
    if text[text_start:start].strip(" \t\r\n"):
        return None  # after text content (BT elements have none), not between tags
    end, lead, trail = offset, "", ""
    if start == offset and not _at_line_end(text, offset) and text[offset - 1] != ">":
        # In the indentation before a tag: a new element goes before it, at the tag's
        # column, and the tag keeps its place (the edit ends where the tag starts).
        found_tag = _TAG_AHEAD_RE.match(text, offset)
        line_start = max(text.rfind("\n", 0, offset), text.rfind("\r", 0, offset)) + 1
        if found_tag is None or text[line_start:offset].strip(" \t"):
            return None
        end = found_tag.end() - 1
        # The document's own line end (CRLF, LF or a lone CR), that of the line above.
        newline = (
            "\r\n" if text.endswith("\r\n", 0, line_start) else text[line_start - 1 : line_start]
        )
        lead, trail = text[offset:end], (newline or "\n") + text[line_start:end]
    model = doc.model
    parent = innermost(model, offset)
    if parent < 0:
        return None
    zone = model.elements[parent].zone
    if zone not in (Zone.ROOT, Zone.TREE, Zone.NODE, Zone.MODELS, Zone.MODEL_ENTRY):
        return None
    if not _fits(doc, ctx, parent):
        return Completions(start, end, "text", [])
    found = tag_names(doc, ctx, start, offset, parent, bare=True)
    items = [
        Item(
            it.label,
            it.kind,
            it.detail,
            it.documentation,
            insert=lead + "<" + it.insert,
            snippet=lead + "<" + it.snippet if it.snippet is not None else None,
            filter=it.filter or it.label,
            sort=it.sort,
        )
        for it in found.items
    ]
    return Completions(start, end, "text", items, trail)


def _structural(
    name: str, attrs: str, *, leaf: bool, bare: bool, plain_attrs: str | None = None
) -> Item:
    if not bare:
        return Item(name, ItemKind.ELEMENT, insert=name)
    plain_attrs = attrs if plain_attrs is None else plain_attrs
    head = f"{name} {attrs}" if attrs else name
    phead = f"{name} {plain_attrs}" if plain_attrs else name
    if leaf:
        return Item(name, ItemKind.ELEMENT, insert=f"{phead}/>", snippet=f"{head}/>")
    return Item(
        name,
        ItemKind.ELEMENT,
        insert=f"{phead}></{name}>",
        snippet=f"{head}>\n\t$0\n</{name}>",
    )


def _node_items(ctx: Context, bare: bool, current_tree: str | None) -> Iterable[Item]:
    for mid, decl in sorted(ctx.models.items()):
        leaf = decl.category in ("Action", "Condition")
        plain, snip = with_ports(mid, decl.ports, leaf)
        where = "this document" if ctx.is_own(decl) else (decl.path or "another document")
        cpp = where.endswith(_CPP)
        origin = "C++" if cpp else ("node catalog" if decl.authoritative else "TreeNodesModel")
        yield Item(
            mid,
            ItemKind.NODE,
            detail=f"{decl.category} ({origin})",
            documentation=(
                f"{decl.category} registered in the C++ of {where}.\n\n"
                if cpp
                else f"{decl.category} declared in the TreeNodesModel of {where}.\n\n"
            )
            + f"Model from {source_label(decl.source)}.\n\n"
            + ports_markdown(decl.ports),
            insert=plain if bare else mid,
            snippet=snip if bare else None,
            sort=f"0{mid}",
        )
    for nid, b in sorted(builtins_in(ctx).items()):
        if b.category == "SubTree":
            continue  # offered below, with an ID
        leaf = b.max_children == 0
        plain, snip = with_ports(nid, b.ports, leaf)
        yield Item(
            nid,
            ItemKind.NODE,
            detail=f"{b.category} (built-in)",
            documentation=f"Built-in {b.category} of BehaviorTree.CPP: {b.description}\n\n"
            + ports_markdown(b.ports),
            insert=plain if bare else nid,
            snippet=snip if bare else None,
            sort=f"1{nid}",
        )
    yield Item(
        "SubTree",
        ItemKind.NODE,
        detail="SubTree call",
        documentation="Runs another tree of the project, by its ID.",
        insert='SubTree ID=""/>' if bare else "SubTree",
        snippet='SubTree ID="$1"/>' if bare else None,
        sort="2SubTree",
    )
    if not bare:
        return
    for tid in tree_ids(ctx):
        if tid == current_tree:
            continue  # a tree calling itself recurses forever
        model = ctx.subtree_models.get(tid)
        ports = model.ports if model is not None else ()
        written = attr_text(tid)
        attrs = (f'ID="{written}"', f'ID="{snippet_literal(written)}"')
        plain, snip = with_ports("SubTree", ports, leaf=True, attrs=attrs)
        yield Item(
            f"SubTree {tid}",
            ItemKind.SUBTREE,
            detail="SubTree call",
            documentation=f"Runs the tree {md_code(tid)}.\n\n" + ports_markdown(ports)
            if ports
            else f"Runs the tree {md_code(tid)}.",
            insert=plain,
            snippet=snip,
            filter=f"SubTree {tid}",
            sort=f"3{tid}",
        )


def end_tag_name(doc: Document, tstart: int, tok: Token, offset: int) -> Completions | None:
    model = doc.model
    name: str | None = None
    for el in model.elements:
        if el.end_name_start == tstart + 2:
            name = el.name
            break
    if name is None:
        inner = innermost(model, tstart)
        if inner >= 0:
            name = model.elements[inner].name
    if name is None:
        return None
    closed = tok.closed
    return Completions(
        tstart + 2,
        tstart + tok.name_end,
        "end-tag",
        [Item(name, ItemKind.ELEMENT, insert=name if closed else f"{name}>")],
    )
