"""The tree an executor runs, read from the XML it sends (FULLTREE, or a .btlog header).

BehaviorTree.CPP writes it with ``WriteTreeToXML(tree, add_metadata=true, ...)``: one
``<BehaviorTree ID=... _fullpath=...>`` per instantiated tree (the main tree has an empty
``_fullpath``, each SubTree instance its path such as ``sub1/inner``), every node with a
``_uid``, and each ``<SubTree ... _fullpath=P>`` node standing for the ``<BehaviorTree
_fullpath=P>`` block.  The XML is untrusted: parsed without entities, DTDs or network,
size capped, and anything inconsistent (a duplicate uid, a SubTree cycle) is a
:class:`ProtocolError`.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, field
from typing import Final

from lxml import etree

from bt_lsp.live.protocol import MAX_UID, ProtocolError

MAX_XML_BYTES: Final = 64 * 1024 * 1024
MAX_DEPTH: Final = 300


@dataclass(frozen=True, slots=True, eq=False)
class LiveNode:
    """One node of the running tree.

    ``tag`` is the registration ID (``Sleep``), ``name`` the instance name (the tag when the
    XML gave none), ``path`` the subtree path and name (``sub1/Sleep``), ``subtree`` the
    tree ID a SubTree node calls."""

    uid: int
    tag: str
    name: str
    path: str
    subtree: str | None = None
    children: tuple[LiveNode, ...] = ()

    @property
    def label(self) -> str:
        text = self.tag if self.name == self.tag else f'{self.tag} "{self.name}"'
        if self.subtree is not None:
            text += f" -> {self.subtree}"
        return text


@dataclass(frozen=True, slots=True, eq=False)
class LiveTree:
    """The running tree: its root node, nodes by uid, and the blackboards' names."""

    root: LiveNode
    tree_id: str
    nodes: dict[int, LiveNode] = field(repr=False)
    blackboards: tuple[str, ...]
    xml: str = field(repr=False)

    def walk(self) -> Iterator[tuple[int, LiveNode]]:
        """Depth-first (depth, node) pairs, the root first."""
        stack = [(0, self.root)]
        while stack:
            depth, node = stack.pop()
            yield depth, node
            stack.extend((depth + 1, c) for c in reversed(node.children))

    def find(self, text: str) -> list[LiveNode]:
        """Nodes by uid (``7``), path (``sub1/Sleep``) or instance name."""
        if text.isdigit() and int(text) in self.nodes:
            return [self.nodes[int(text)]]
        by_path = [n for n in self.nodes.values() if n.path == text]
        return by_path or [n for n in self.nodes.values() if n.name == text]


def _parser() -> etree.XMLParser:
    # No entities, DTDs or network; libxml2's default limits (depth 256, no huge text).
    return etree.XMLParser(
        resolve_entities=False,
        no_network=True,
        load_dtd=False,
        dtd_validation=False,
        huge_tree=False,
        remove_comments=True,
        remove_pis=True,
    )


def parse_tree_xml(xml: str | bytes) -> LiveTree:
    """Read the executor's tree; raise ProtocolError for anything else."""
    data = xml.encode("utf-8") if isinstance(xml, str) else bytes(xml)
    if len(data) > MAX_XML_BYTES:
        raise ProtocolError(f"a tree of {len(data)} bytes is over the limit")
    try:
        root = etree.fromstring(data, _parser())
    except (etree.XMLSyntaxError, ValueError) as e:
        raise ProtocolError(f"the tree is not XML: {e}") from None
    if root is None or root.tag != "root":
        raise ProtocolError("the tree's XML has no <root>")
    blocks: dict[str, etree._Element] = {}
    order: list[tuple[str, str]] = []
    for el in root:
        if el.tag != "BehaviorTree":
            continue
        path = el.get("_fullpath", "")
        tree_id = el.get("ID", "")
        if path in blocks:
            raise ProtocolError(f"two trees with _fullpath {path!r}")
        blocks[path] = el
        order.append((path, tree_id))
    if not blocks:
        raise ProtocolError("the tree's XML has no <BehaviorTree>")
    main_path = "" if "" in blocks else order[0][0]
    nodes: dict[int, LiveNode] = {}
    used: set[str] = set()
    try:
        main = _tree_root(blocks, main_path, nodes, used, 0)
    except RecursionError:
        raise ProtocolError("the tree is nested too deep") from None
    text = data.decode("utf-8", errors="replace")
    names = tuple(tree_id if path == "" else path for path, tree_id in order)
    return LiveTree(main, dict(order)[main_path], nodes, names, text)


def _tree_root(
    blocks: dict[str, etree._Element],
    path: str,
    nodes: dict[int, LiveNode],
    used: set[str],
    depth: int,
) -> LiveNode:
    if path in used:
        raise ProtocolError(f"subtree {path!r} is called twice")
    used.add(path)
    children = [c for c in blocks[path] if isinstance(c.tag, str)]
    if len(children) != 1:
        raise ProtocolError(f"tree {path or 'main'!r} has {len(children)} root nodes, not 1")
    return _node(blocks, children[0], path, nodes, used, depth)


def _node(
    blocks: dict[str, etree._Element],
    el: etree._Element,
    prefix: str,
    nodes: dict[int, LiveNode],
    used: set[str],
    depth: int,
) -> LiveNode:
    if depth > MAX_DEPTH:
        raise ProtocolError("the tree is nested too deep")
    tag = str(el.tag)
    uid_text = el.get("_uid")
    if uid_text is None or not uid_text.isdigit() or int(uid_text) > MAX_UID:
        raise ProtocolError(f"<{tag}> has no valid _uid ({uid_text!r})"[:200])
    uid = int(uid_text)
    if uid in nodes:
        raise ProtocolError(f"two nodes have _uid {uid}")
    subpath = el.get("_fullpath")
    if subpath is not None and subpath in blocks:
        name = el.get("name") or subpath.rsplit("/", 1)[-1] or tag
        inner = _tree_root(blocks, subpath, nodes, used, depth + 1)
        node = LiveNode(uid, tag, name, subpath, el.get("ID"), (inner,))
    else:
        name = el.get("name") or tag
        kids = tuple(
            _node(blocks, c, prefix, nodes, used, depth + 1) for c in el if isinstance(c.tag, str)
        )
        node = LiveNode(uid, tag, name, f"{prefix}/{name}" if prefix else name, None, kids)
    if uid in nodes:  # a descendant had it
        raise ProtocolError(f"two nodes have _uid {uid}")
    nodes[uid] = node
    return node
