"""Completion in a start tag: attribute names (a node's ports, the reserved attributes,
the attributes of the structural elements) and values (tree IDs, node types, literals
of ``bool`` and ``NodeStatus`` ports, blackboard keys after ``{``)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from types import MappingProxyType

from bt_lsp.ide.blackboard import KeyForm, enclosing_tree, key_names
from bt_lsp.ide.completion_items import (
    Completions,
    Item,
    ItemKind,
    attr_insert,
    attr_text,
    port_doc,
    ports_markdown,
    snippet_literal,
    tree_id,
    tree_ids,
)
from bt_lsp.ide.ports import builtins_in, ports_of
from bt_lsp.rules.context import Context
from bt_lsp.rules.names import POSTCONDITIONS, PRECONDITIONS
from bt_lsp.syntax.document import Document
from bt_lsp.syntax.elements import EXPLICIT_TAGS, Element, Zone
from bt_lsp.syntax.tokens import Attr

_NODE_RESERVED: tuple[tuple[str, str], ...] = (
    ("name", "Instance name: the node's label (defaults to its type)."),
    *((p, "Precondition: a script checked before the node is ticked.") for p in PRECONDITIONS),
    *((p, "Postcondition: a script run after the node completes.") for p in POSTCONDITIONS),
    ("_description", "A description of the node (ignored by BehaviorTree.CPP)."),
)
_STRUCTURAL_ATTRS: Mapping[Zone, tuple[tuple[str, str, str], ...]] = MappingProxyType(
    {
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
)


def attribute_names(
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
                    snippet=value[1] + snippet_literal(tail),
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
                port_doc(p),
                attr_insert(p.name, ports),
                f"{req}{p.name}",
            )
        if (el.name in EXPLICIT_TAGS or el.name == "SubTree") and el.attr("ID") is None:
            add(
                "ID",
                ItemKind.ATTRIBUTE,
                "node type",
                "The node type.",
                attr_insert("ID", ()),
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
                attr_insert(name, ()),
                f"4{name}",
            )
    else:
        for name, default, doc in _STRUCTURAL_ATTRS.get(el.zone, ()):
            value = (
                (f'{name}="{default}"', f'{name}="${{1:{default}}}"')
                if default
                else attr_insert(name, ())
            )
            add(name, ItemKind.ATTRIBUTE, "attribute", doc, value, f"0{name}")
    return Completions(start, end, "attribute", items)


_STATUSES = ("SUCCESS", "FAILURE", "RUNNING", "SKIPPED")


def attribute_value(
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
        current = tree_id(model, enclosing_tree(model, idx)) if el.zone == Zone.NODE else None
        for tid in tree_ids(ctx):
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
            items.append(Item(tid, ItemKind.TREE, f"BehaviorTree ({where})", insert=attr_text(tid)))
        return Completions(vs, ve, "value", items)
    if el.zone == Zone.NODE and el.name in EXPLICIT_TAGS and a.name == "ID":
        for nid, b in sorted(builtins_in(ctx).items()):
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
                        attr_text(mid),
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
        for key, form in key_names(doc, tree, offset).items():
            seen[key] = f"used in {'a script of ' if form == KeyForm.SCRIPT else ''}this tree"
        tid = tree_id(model, tree)
        decl = ctx.subtree_models.get(tid) if tid else None
        for p in decl.ports if decl is not None else ():
            seen.setdefault(p.name, f"{p.direction} port of this tree")
    keys = sorted(seen)
    incomplete = len(keys) > MAX_KEY_ITEMS
    if incomplete:  # those that start as typed first; the client asks again as one types
        typed = text[start:offset].strip().casefold()
        keys.sort(key=lambda k: not k.casefold().startswith(typed))
        del keys[MAX_KEY_ITEMS:]
        keys.sort()
    items = [
        Item(k, ItemKind.KEY, seen[k], insert=k if closed else k + "}", filter=k, sort=k)
        for k in keys
    ]
    return Completions(start, end, "key", items, incomplete=incomplete)


# Keys listed at most by one completion (a tree may use 200,000): past them the list is
# marked incomplete, so that the client asks again as the key is typed.
MAX_KEY_ITEMS = 1000
