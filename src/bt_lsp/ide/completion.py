"""Completion for BT XML, tolerant of half-typed text.

Pure: :func:`complete` reads the scanner's token under the cursor and the document model,
and returns plain items with the span they replace (code-point offsets).  Contexts:

* a start tag's name after ``<``: the elements allowed there (in a tree, the built-in and
  declared node types, with their required ports, and a ``<SubTree>`` call of each tree);
* an empty line or the space between tags (Ctrl+Space with no ``<`` typed): the same
  elements, the ``<`` included, where one fits (not in a leaf, a full decorator or a tree
  that has its child);
* an end tag's name after ``</``: the element it closes;
* an attribute name in a start tag: the ports of the node and the reserved attributes;
* an attribute value: tree IDs in ``<SubTree ID>`` and ``main_tree_to_execute``, node types
  in ``<Action|Condition|Control|Decorator ID>``, ``true``/``false`` and statuses for bool
  and ``NodeStatus`` ports, and after ``{`` the blackboard keys used in the tree (in port
  values and scripts).
"""

from __future__ import annotations

import re
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from enum import StrEnum

from bt_lsp.ide.blackboard import KeyForm, enclosing_tree, key_uses
from bt_lsp.ide.ports import ports_of
from bt_lsp.rules.builtins import BUILTINS, PortModel
from bt_lsp.rules.context import Context, source_label
from bt_lsp.rules.names import POSTCONDITIONS, PRECONDITIONS
from bt_lsp.syntax.document import Document
from bt_lsp.syntax.elements import EXPLICIT_TAGS, Element, Zone
from bt_lsp.syntax.model import Model
from bt_lsp.syntax.scanner import Attr, Kind, Token

__all__ = ["Completions", "Item", "ItemKind", "complete", "ports_markdown"]

# Models learned from C++ (bt_lsp.project.cpp_models) are declared in a C++ file.
_CPP = (".cpp", ".hpp", ".h", ".cc", ".cxx", ".hh", ".hxx", ".ipp")


class ItemKind(StrEnum):
    ELEMENT = "element"  # a structural element (BehaviorTree, include, input_port, ...)
    NODE = "node"  # a node type
    SUBTREE = "subtree"  # a <SubTree ID="..."> call
    ATTRIBUTE = "attribute"  # a reserved or structural attribute
    PORT = "port"
    TREE = "tree"  # a tree ID
    MODEL = "model"  # a node type ID in a value
    KEY = "key"  # a blackboard key
    VALUE = "value"  # a literal value


@dataclass(frozen=True, slots=True)
class Item:
    """One proposal.  ``insert`` is plain text; ``snippet`` (LSP snippet syntax) is used
    instead when the client supports snippets.  Both replace the span of the
    :class:`Completions` they belong to."""

    label: str
    kind: ItemKind
    detail: str = ""
    documentation: str = ""
    insert: str = ""
    snippet: str | None = None
    filter: str | None = None
    sort: str = ""


@dataclass(frozen=True, slots=True)
class Completions:
    """Items for the cursor, all replacing ``text[start:end]`` (``start <= cursor <= end``);
    ``context`` names the situation (``tag``, ``end-tag``, ``attribute``, ``value``,
    ``key``)."""

    start: int
    end: int
    context: str
    items: list[Item] = field(default_factory=list)


# --- text helpers --------------------------------------------------------------------------


def _snip(text: str) -> str:
    """``text`` as literal snippet text."""
    return text.replace("\\", "\\\\").replace("$", "\\$").replace("}", "\\}")


def _code(text: str) -> str:
    return f"`` {text} ``" if "`" in text else f"`{text}`"


def ports_markdown(ports: Sequence[PortModel]) -> str:
    """The ports as a Markdown list, one a line (a table is cut off in a narrow popup):
    name, direction, type, default, description."""
    if not ports:
        return "No ports."
    rows = ["Ports:", ""]
    for p in ports:
        default = "no default" if p.default is None else f"default {_code(p.default)}"
        ptype = f", {_code(p.type)}" if p.type else ""
        desc = " ".join(p.description.split())
        rows.append(
            f"- {_code(p.name)}: {p.direction}{ptype}, {default}" + (f"; {desc}" if desc else "")
        )
    return "\n".join(rows)


def _port_doc(p: PortModel) -> str:
    default = "no default" if p.default is None else f"default {_code(p.default)}"
    ptype = f", type {_code(p.type)}" if p.type else ""
    out = f"{p.direction} port{ptype}, {default}."
    return f"{out}\n\n{p.description}" if p.description else out


def _attr_insert(name: str, ports: Sequence[PortModel], n: int = 1) -> tuple[str, str]:
    """``name="…"`` for a port: (plain, snippet).  A port with a default gets it (in the
    snippet as the placeholder's text, to accept or overwrite); an output or inout port
    without one gets the key named like it, ``{name}``; any other an empty value (in the
    snippet a tab stop)."""
    port = next((p for p in ports if p.name == name), None)
    if port is not None and port.default is not None:
        value = _attr_text(port.default)
        return f'{name}="{value}"', f'{_snip(name)}="${{{n}:{_snip(value)}}}"'
    if port is not None and port.direction != "input":
        return f'{name}="{{{name}}}"', f'{_snip(name)}="{{${{{n}:{_snip(name)}}}}}"'
    return f'{name}=""', f'{_snip(name)}="${{{n}}}"'


def _with_ports(
    name: str, ports: Sequence[PortModel], leaf: bool, attrs: tuple[str, str] = ("", "")
) -> tuple[str, str]:
    """A start tag's text after ``<``: the name, ``attrs`` (plain, snippet), the ports
    without a default, the tag's end: (plain, snippet).

    Ports with a default are left out (BehaviorTree.CPP uses the default).  The snippet
    writes each port without a default as a tab stop to fill in (an output as the key
    named like it); the plain text, which has no tab stops, writes only the outputs'
    keys, since an empty value is never right (the missing ports are then reported)."""
    plain = [name, attrs[0]] if attrs[0] else [name]
    snip = [_snip(name), attrs[1]] if attrs[1] else [_snip(name)]
    n = 1
    for p in ports:
        if p.default is None:
            a, s = _attr_insert(p.name, ports, n)
            if p.direction != "input":
                plain.append(a)
            snip.append(s)
            n += 1
    if leaf:
        return " ".join(plain) + "/>", " ".join(snip) + "/>"
    return (
        " ".join(plain) + f"></{name}>",
        " ".join(snip) + f">\n\t$0\n</{_snip(name)}>",
    )


# --- where the cursor is -------------------------------------------------------------------


def _element_at(model: Model, token_start: int) -> tuple[int, Element] | None:
    for i, el in enumerate(model.elements):
        if el.token_start == token_start:
            return i, el
        if el.token_start > token_start:
            break
    return None


def _innermost(model: Model, offset: int) -> int:
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


def complete(doc: Document, offset: int, ctx: Context | None = None) -> Completions | None:
    """Completions at ``offset``, or ``None`` where there is nothing to propose."""
    if ctx is None:
        ctx = Context.from_document(doc)
    offset = min(max(offset, 0), len(doc.text))
    if offset == 0:
        return None
    scan = doc.scan
    ti = scan.index_at(offset - 1)
    tstart, tok = scan.starts[ti], scan.tokens[ti]
    rel = offset - tstart
    model = doc.model
    if tok.kind == Kind.STRAY and tok.length == 1 and rel == 1:
        parent = _innermost(model, offset)
        return _tag(doc, ctx, offset, offset, parent, bare=True)
    if tok.kind == Kind.END and 2 <= rel <= tok.name_end:
        return _end_tag(doc, tstart, tok, offset)
    if tok.kind == Kind.TEXT or (
        tok.kind in (Kind.START, Kind.END, Kind.COMMENT) and tok.closed and rel >= tok.length
    ):
        return _between_tags(doc, ctx, offset, tstart if tok.kind == Kind.TEXT else offset)
    if tok.kind != Kind.START:
        return None
    hit = _element_at(model, tstart)
    if hit is None:
        return None
    idx, el = hit
    if rel <= tok.name_end:
        bare = not tok.attrs and not tok.closed
        return _tag(doc, ctx, tstart + 1, tstart + tok.name_end, el.parent, bare=bare)
    if tok.closed and rel >= tok.length:
        return None
    text = doc.text
    for a in tok.attrs:
        if a.value is not None and a.value_start <= rel <= a.value_end:
            return _value(doc, ctx, idx, el, a, offset)
        if a.name_start < rel <= a.name_end:
            return _attributes(
                ctx, el, tstart + a.name_start, tstart + a.name_end, a.value is not None, a.name
            )
    if text[offset - 1] in " \t\r\n":
        return _attributes(
            ctx, el, offset, offset, False, None, before_name=_name_follows(text, offset)
        )
    return None


def _name_follows(text: str, offset: int) -> bool:
    return offset < len(text) and text[offset] not in " \t\r\n/>"


# --- tag names -----------------------------------------------------------------------------


def _tag(
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
        items.extend(_node_items(ctx, bare, _tree_id(model, tree)))
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
    b = BUILTINS.get(node_id)
    if b is not None:
        most = b.max_children
    elif node_id in ctx.models:
        most = ctx.models[node_id].child_range[1]
    else:
        return True  # an unknown node type: it may take children
    return most is None or children < most


def _between_tags(doc: Document, ctx: Context, offset: int, text_start: int) -> Completions | None:
    """Completions with no ``<`` typed: on an empty line or between tags, the elements
    that fit there, each written with its ``<``, replacing the name typed so far."""
    text = doc.text
    start = offset
    while start > text_start and _is_name_char(text[start - 1]):
        start -= 1
    if text[text_start:start].strip(" \t\r\n"):
        return None  # after text content (BT elements have none), not between tags
    if start == offset and not _at_line_end(text, offset) and text[offset - 1] != ">":
        return None  # in the indentation before a tag: the place of no new element
    model = doc.model
    parent = _innermost(model, offset)
    if parent < 0:
        return None
    zone = model.elements[parent].zone
    if zone not in (Zone.ROOT, Zone.TREE, Zone.NODE, Zone.MODELS, Zone.MODEL_ENTRY):
        return None
    if not _fits(doc, ctx, parent):
        return Completions(start, offset, "text", [])
    found = _tag(doc, ctx, start, offset, parent, bare=True)
    items = [
        Item(
            it.label,
            it.kind,
            it.detail,
            it.documentation,
            insert="<" + it.insert,
            snippet="<" + it.snippet if it.snippet is not None else None,
            filter=it.filter or it.label,
            sort=it.sort,
        )
        for it in found.items
    ]
    return Completions(start, offset, "text", items)


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


def _tree_id(model: Model, tree: int) -> str | None:
    return model.elements[tree].value("ID") if tree >= 0 else None


def _node_items(ctx: Context, bare: bool, current_tree: str | None) -> Iterable[Item]:
    for mid, decl in sorted(ctx.models.items()):
        leaf = decl.category in ("Action", "Condition")
        plain, snip = _with_ports(mid, decl.ports, leaf)
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
    for nid, b in sorted(BUILTINS.items()):
        if b.category == "SubTree":
            continue  # offered below, with an ID
        leaf = b.max_children == 0
        plain, snip = _with_ports(nid, b.ports, leaf)
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
    for tid in _tree_ids(ctx):
        if tid == current_tree:
            continue  # a tree calling itself recurses forever
        model = ctx.subtree_models.get(tid)
        ports = model.ports if model is not None else ()
        written = _attr_text(tid)
        attrs = (f'ID="{written}"', f'ID="{_snip(written)}"')
        plain, snip = _with_ports("SubTree", ports, leaf=True, attrs=attrs)
        yield Item(
            f"SubTree {tid}",
            ItemKind.SUBTREE,
            detail="SubTree call",
            documentation=f"Runs the tree {_code(tid)}.\n\n" + ports_markdown(ports)
            if ports
            else f"Runs the tree {_code(tid)}.",
            insert=plain,
            snippet=snip,
            filter=f"SubTree {tid}",
            sort=f"3{tid}",
        )


def _attr_text(value: str) -> str:
    return value.replace("&", "&amp;").replace("<", "&lt;").replace('"', "&quot;")


def _tree_ids(ctx: Context) -> list[str]:
    ids = set(ctx.trees) | set(ctx.workspace_trees) | set(ctx.subtree_models)
    return sorted(i for i in ids if i)


# --- end tags ------------------------------------------------------------------------------


def _end_tag(doc: Document, tstart: int, tok: Token, offset: int) -> Completions | None:
    model = doc.model
    name: str | None = None
    for el in model.elements:
        if el.end_name_start == tstart + 2:
            name = el.name
            break
    if name is None:
        inner = _innermost(model, tstart)
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


# --- attribute names -----------------------------------------------------------------------

_NODE_RESERVED: tuple[tuple[str, str], ...] = (
    ("name", "Instance name: the node's label (defaults to its type)."),
    *((p, "Precondition: a script checked before the node is ticked.") for p in PRECONDITIONS),
    *((p, "Postcondition: a script run after the node completes.") for p in POSTCONDITIONS),
    ("_description", "A description of the node (ignored by BehaviorTree.CPP)."),
)
_STRUCTURAL_ATTRS: dict[Zone, tuple[tuple[str, str, str], ...]] = {
    Zone.ROOT: (
        ("BTCPP_format", "4", "The format version; BehaviorTree.CPP 4.x expects 4."),
        ("main_tree_to_execute", "", "The tree to run when several are loaded."),
    ),
    Zone.TREE: (
        ("ID", "", "The tree's ID, used by <SubTree ID> and main_tree_to_execute."),
        ("_description", "", "A description of the tree."),
    ),
    Zone.INCLUDE: (
        ("path", "", "The file to include, relative to this one (or to ros_pkg)."),
        ("ros_pkg", "", "A ROS package whose share directory the path is relative to."),
    ),
    Zone.MODEL_ENTRY: (("ID", "", "The node type (or tree) this entry describes."),),
    Zone.PORT_DECL: (
        ("name", "", "The port's name."),
        ("type", "", "The port's C++ type, e.g. std::string."),
        ("default", "", "The value used when the port is not set."),
        ("description", "", "What the port is for."),
    ),
}


def _attributes(
    ctx: Context,
    el: Element,
    start: int,
    end: int,
    has_value: bool,
    editing: str | None,
    *,
    before_name: bool = False,
) -> Completions:
    present = {a.name for a in el.attrs if a.name != editing}
    tail = " " if before_name else ""
    items: list[Item] = []

    def add(
        name: str, kind: ItemKind, detail: str, doc: str, value: tuple[str, str], sort: str
    ) -> None:
        if name in present:
            return
        if has_value:
            items.append(Item(name, kind, detail, doc, insert=name, sort=sort))
        else:
            items.append(
                Item(
                    name,
                    kind,
                    detail,
                    doc,
                    insert=value[0] + tail,
                    snippet=value[1] + _snip(tail),
                    sort=sort,
                )
            )

    if el.zone == Zone.NODE:
        ports = ports_of(el, ctx) or ()
        for p in ports:
            req = "0" if p.default is None else "1"
            add(
                p.name,
                ItemKind.PORT,
                f"{p.direction} port" + (f": {p.type}" if p.type else ""),
                _port_doc(p),
                _attr_insert(p.name, ports),
                f"{req}{p.name}",
            )
        if (el.name in EXPLICIT_TAGS or el.name == "SubTree") and el.attr("ID") is None:
            add(
                "ID",
                ItemKind.ATTRIBUTE,
                "node type",
                "The node type.",
                _attr_insert("ID", ()),
                "2ID",
            )
        if el.name == "SubTree":
            add(
                "_autoremap",
                ItemKind.ATTRIBUTE,
                "reserved attribute",
                "When true, every port of the subtree is remapped to the parent's blackboard "
                "entry of the same name.",
                ('_autoremap="true"', '_autoremap="${1|true,false|}"'),
                "3_autoremap",
            )
        for name, doc in _NODE_RESERVED:
            add(
                name,
                ItemKind.ATTRIBUTE,
                "reserved attribute",
                doc,
                _attr_insert(name, ()),
                f"4{name}",
            )
    else:
        for name, default, doc in _STRUCTURAL_ATTRS.get(el.zone, ()):
            value = (
                (f'{name}="{default}"', f'{name}="${{1:{default}}}"')
                if default
                else _attr_insert(name, ())
            )
            add(name, ItemKind.ATTRIBUTE, "attribute", doc, value, f"0{name}")
    return Completions(start, end, "attribute", items)


# --- attribute values ----------------------------------------------------------------------

_STATUSES = ("SUCCESS", "FAILURE", "RUNNING", "SKIPPED")


def _value(
    doc: Document, ctx: Context, idx: int, el: Element, a: Attr, offset: int
) -> Completions | None:
    text = doc.text
    vs, ve = el.span_of_value(a)
    model = doc.model
    if el.zone == Zone.NODE and a.name not in ("ID", "name"):
        lb = text.rfind("{", vs, offset)
        if lb != -1 and "}" not in text[lb:offset]:
            return _keys(doc, ctx, idx, lb + 1, offset, ve)
    if "\n" in text[vs:ve] or "\r" in text[vs:ve]:
        vs, ve = vs, offset  # a range must stay on one line
    items: list[Item] = []
    if (el.zone == Zone.NODE and el.name == "SubTree" and a.name == "ID") or (
        el.zone == Zone.ROOT and a.name == "main_tree_to_execute"
    ):
        current = _tree_id(model, enclosing_tree(model, idx)) if el.zone == Zone.NODE else None
        for tid in _tree_ids(ctx):
            if tid == current:
                continue
            decls = ctx.trees.get(tid) or ctx.workspace_trees.get(tid) or ()
            where = (
                "this document"
                if decls and ctx.is_own(decls[-1])
                else (decls[-1].path or "")
                if decls
                else "TreeNodesModel"
            )
            items.append(
                Item(tid, ItemKind.TREE, f"BehaviorTree ({where})", insert=_attr_text(tid))
            )
        return Completions(vs, ve, "value", items)
    if el.zone == Zone.NODE and el.name in EXPLICIT_TAGS and a.name == "ID":
        for nid, b in sorted(BUILTINS.items()):
            if b.category == el.name:
                items.append(
                    Item(nid, ItemKind.MODEL, f"{b.category} (built-in)", b.description, nid)
                )
        for mid, decl in sorted(ctx.models.items()):
            if decl.category == el.name:
                items.append(
                    Item(
                        mid,
                        ItemKind.MODEL,
                        f"{decl.category} (TreeNodesModel)",
                        ports_markdown(decl.ports),
                        _attr_text(mid),
                    )
                )
        return Completions(vs, ve, "value", items)
    if el.zone == Zone.NODE:
        ptype: str | None = None
        if a.name == "_autoremap":
            ptype = "bool"
        else:
            port = next((p for p in ports_of(el, ctx) or () if p.name == a.name), None)
            ptype = port.type if port is not None else None
        if ptype == "bool":
            values: Sequence[str] = ("true", "false")
        elif ptype == "NodeStatus":
            values = _STATUSES
        else:
            return None
        items = [Item(v, ItemKind.VALUE, ptype, insert=v) for v in values]
        return Completions(vs, ve, "value", items)
    return None


def _keys(
    doc: Document, ctx: Context, idx: int, start: int, offset: int, value_end: int
) -> Completions:
    text = doc.text
    model = doc.model
    end = offset
    while end < value_end and text[end] not in "{}\"' \t\r\n":
        end += 1
    closed = end < value_end and text[end] == "}"
    tree = enclosing_tree(model, idx)
    seen: dict[str, str] = {}
    if tree >= 0:
        for k in key_uses(doc, tree):
            if not (k.start <= offset <= k.end):
                where = "a script of " if k.form == KeyForm.SCRIPT else ""
                seen.setdefault(k.key, f"used in {where}this tree")
        tid = _tree_id(model, tree)
        decl = ctx.subtree_models.get(tid) if tid else None
        for p in decl.ports if decl is not None else ():
            seen.setdefault(p.name, f"{p.direction} port of this tree")
    items = [
        Item(k, ItemKind.KEY, why, insert=k if closed else k + "}", filter=k, sort=k)
        for k, why in sorted(seen.items())
    ]
    return Completions(start, end, "key", items)
