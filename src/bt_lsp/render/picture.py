"""What a picture of a behavior tree shows, read from the document model.

A :class:`Picture` is a flat list of :class:`Node` values in pre-order (a parent before
its children, children in XML order), each with the source span of its element, its kind
as BehaviorTree.CPP registers it, its ports and the worst severity of the diagnostics
inside it.  It is built with an explicit stack (a 256-deep tree is no deeper for Python
than a flat one), and a ``<SubTree>`` can be expanded in place: the called tree's nodes
become its children, never twice along one path (a recursive call stays collapsed) and
never beyond :data:`MAX_NODES` in all (a tree calling a tree twice per level grows
exponentially when inlined).
"""

from __future__ import annotations

from bisect import bisect_right
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Literal

from bt_lsp.rules.builtins import BUILTINS
from bt_lsp.rules.codes import Severity
from bt_lsp.rules.context import Context
from bt_lsp.rules.conversions import is_blackboard_reference
from bt_lsp.rules.diagnostics import Diagnostic
from bt_lsp.syntax.elements import EXPLICIT_TAGS, Element, Zone
from bt_lsp.syntax.model import Model

Kind = Literal["tree", "control", "decorator", "action", "condition", "subtree", "unknown"]

MAX_NODES = 20_000

_CATEGORY_KIND: Mapping[str, Kind] = {
    "Action": "action",
    "Condition": "condition",
    "Control": "control",
    "Decorator": "decorator",
    "SubTree": "subtree",
}
# Attributes that name the node rather than pass a value (shown as its title, not ports).
_NOT_PORTS = frozenset({"ID", "name"})


@dataclass(frozen=True, slots=True)
class Port:
    name: str
    value: str
    is_key: bool  # the value is a blackboard reference ({key} or =)


@dataclass(slots=True)
class Node:
    """One node of the picture.

    ``start``/``end`` are the code-point span of its element (the ``<BehaviorTree>``
    element for the root) in the document ``source`` (``None``: the rendered document;
    otherwise the path of the document an expanded SubTree came from).
    """

    index: int
    parent: int
    kind: Kind
    type: str
    name: str | None
    start: int
    end: int
    source: str | None = None
    ports: tuple[Port, ...] = ()
    children: list[int] = field(default_factory=list)
    severity: Severity | None = None  # the worst diagnostic inside the node's own element
    problems: tuple[str, ...] = ()  # their messages, worst first
    subtree: str | None = None  # the tree a SubTree calls
    expanded: bool = False  # its tree is drawn below it
    recursive: bool = False  # it calls a tree already on its path (never expanded)
    depth: int = 0

    @property
    def id(self) -> str:
        return f"n{self.index}"


@dataclass(frozen=True, slots=True)
class Picture:
    tree_id: str
    nodes: list[Node]
    truncated: bool = False  # expansion stopped at MAX_NODES

    @property
    def root(self) -> Node:
        return self.nodes[0]


@dataclass(frozen=True, slots=True)
class TreeSource:
    """A ``<BehaviorTree>`` and the model it belongs to (``source`` as in :class:`Node`)."""

    model: Model
    element: Element
    source: str | None = None


# What finds a called tree: an ID -> its source, or None when it is nowhere to be seen.
Resolver = Callable[[str], TreeSource | None]


def tree_id_of(el: Element) -> str:
    return el.value("ID") or ""


def document_trees(model: Model) -> list[Element]:
    """The document's ``<BehaviorTree>`` elements in order."""
    return model.trees()


def main_tree(model: Model) -> Element | None:
    """The tree BehaviorTree.CPP runs: ``main_tree_to_execute`` if it names one of the
    document's trees, else the first tree."""
    trees = document_trees(model)
    root = model.root
    main = root.value("main_tree_to_execute") if root is not None else None
    for t in trees:
        if main is not None and tree_id_of(t) == main:
            return t
    return trees[0] if trees else None


def tree_at(model: Model, offset: int) -> Element | None:
    """The tree whose element holds ``offset``, else the main tree."""
    for t in document_trees(model):
        end = t.end if t.end >= 0 else 1 << 62
        if t.token_start <= offset <= end:
            return t
    return main_tree(model)


def find_tree(model: Model, tree_id: str) -> Element | None:
    for t in document_trees(model):
        if tree_id_of(t) == tree_id:
            return t
    return None


def workspace_resolver(
    model: Model, ctx: Context | None = None, others: Mapping[str, Model] | None = None
) -> Resolver:
    """A resolver over the document's own trees, then the trees its context sees (its
    include closure, where the last declaration wins as in BehaviorTree.CPP, then the other
    workspace files), looked up in ``others`` (path -> model)."""
    others = others or {}
    cache: dict[str, TreeSource | None] = {}
    # Each model's trees by ID, made on first use: a picture that expands a chain of
    # thousands of SubTree calls looks each one up, and a walk over the trees per call
    # made that quadratic.
    indexes: dict[int, dict[str, Element]] = {}

    def tree_in(m: Model, tree_id: str) -> Element | None:
        index = indexes.get(id(m))
        if index is None:
            index = indexes[id(m)] = {}
            for t in document_trees(m):
                index.setdefault(tree_id_of(t), t)  # the first, as find_tree
        return index.get(tree_id)

    def resolve(tree_id: str) -> TreeSource | None:
        if tree_id in cache:
            return cache[tree_id]
        found: TreeSource | None = None
        own = tree_in(model, tree_id)
        if own is not None:
            found = TreeSource(model, own)
        elif ctx is not None:
            decls = ctx.trees.get(tree_id) or ctx.workspace_trees.get(tree_id) or ()
            for decl in reversed(decls):
                other = others.get(decl.path) if decl.path is not None else None
                el = tree_in(other, tree_id) if other is not None else None
                if other is not None and el is not None:
                    found = TreeSource(other, el, decl.path)
                    break
        cache[tree_id] = found
        return found

    return resolve


def kind_of(el: Element, ctx: Context | None) -> tuple[Kind, str]:
    """The node's kind and type, as BehaviorTree.CPP's factory would register them."""
    tag = el.name
    if tag == "SubTree":
        return "subtree", el.value("ID") or ""
    if tag in EXPLICIT_TAGS:
        return _CATEGORY_KIND[tag], el.value("ID") or ""
    builtin = BUILTINS.get(tag)
    if builtin is not None:
        return _CATEGORY_KIND[builtin.category], tag
    if ctx is not None:
        decl = ctx.models.get(tag)
        if decl is not None:
            return _CATEGORY_KIND[decl.category], tag
    return "unknown", tag


def _ports(el: Element) -> tuple[Port, ...]:
    return tuple(
        Port(a.name, a.value or "", is_blackboard_reference(a.value or ""))
        for a in el.attrs
        if a.name not in _NOT_PORTS
    )


def _element_end(el: Element) -> int:
    return el.end if el.end >= 0 else 1 << 62


class _Problems:
    """The diagnostics of one document, each given to the innermost rendered element
    whose span holds its start."""

    def __init__(self, diagnostics: Iterable[Diagnostic]) -> None:
        self.diags = sorted(diagnostics, key=lambda d: d.start)
        self.by_element: dict[int, list[Diagnostic]] = {}

    def assign(self, elements: Sequence[tuple[int, int, int]]) -> None:
        """``elements``: (start, end, parent's position in the list or -1), sorted by
        start, properly nested (an element's span holds its descendants')."""
        starts = [e[0] for e in elements]
        for d in self.diags:
            i = bisect_right(starts, d.start) - 1
            while i >= 0 and not (elements[i][0] <= d.start < elements[i][1]):
                i = elements[i][2]
            if i >= 0:
                self.by_element.setdefault(elements[i][0], []).append(d)

    def of(self, start: int) -> list[Diagnostic]:
        return self.by_element.get(start, [])


def build_picture(
    model: Model,
    tree: Element,
    *,
    ctx: Context | None = None,
    diagnostics: Iterable[Diagnostic] = (),
    expand_subtrees: bool = False,
    resolve: Resolver | None = None,
    ports: bool = False,
    text_length: int | None = None,
) -> Picture:
    """The picture of ``tree`` (a ``<BehaviorTree>`` element of ``model``).

    ``diagnostics`` are the rendered document's (other documents' nodes get none);
    ``resolve`` finds the trees SubTree calls name (default: the document's own).
    ``text_length``, the document's length, ends the spans of elements never closed
    (otherwise they reach an arbitrary far offset).
    """
    resolve = resolve or workspace_resolver(model, ctx)
    tid = tree_id_of(tree)
    root = Node(0, -1, "tree", tid, None, tree.token_start, _element_end(tree))
    nodes = [root]
    own_spans: list[tuple[int, int, int, int]] = [(tree.token_start, _element_end(tree), -1, 0)]
    truncated = False
    # The trees on the path from the root to the element popped next: an expanded call
    # adds its tree, and an entry pushed under the called tree's children takes it out
    # again once they are done (a set per path made a chain of n calls cost n^2).
    path = {tid}
    # (model, element index, parent node, source); element index -1: leave tree ``src``
    stack: list[tuple[Model, int, int, str | None]] = []

    def push_children(m: Model, el: Element, parent: int, src: str | None) -> None:
        for ci in reversed(el.children):
            stack.append((m, ci, parent, src))

    push_children(model, tree, 0, None)
    while stack:
        m, ei, parent, src = stack.pop()
        if ei < 0:
            assert src is not None
            path.discard(src)
            continue
        el = m.elements[ei]
        if el.zone != Zone.NODE:
            continue
        if len(nodes) >= MAX_NODES:
            truncated = True
            break
        kind, type_ = kind_of(el, ctx)
        node = Node(
            len(nodes),
            parent,
            kind,
            type_,
            el.value("name"),
            el.token_start,
            _element_end(el),
            src,
            _ports(el) if ports else (),
            depth=nodes[parent].depth + 1,
        )
        nodes.append(node)
        nodes[parent].children.append(node.index)
        if src is None:
            own_spans.append((node.start, node.end, -1, node.index))
        if kind == "subtree":
            node.subtree = type_
            if type_ in path:
                node.recursive = True
            elif expand_subtrees:
                target = resolve(type_)
                if target is not None:
                    node.expanded = True
                    tsrc = target.source if target.model is not model else None
                    stack.append((m, -1, -1, type_))
                    path.add(type_)
                    push_children(target.model, target.element, node.index, tsrc)
            continue
        push_children(m, el, node.index, src)

    _give_problems(nodes, own_spans, diagnostics)
    if text_length is not None:
        for node in nodes:
            if node.source is None and node.end > text_length:
                node.end = text_length
    return Picture(tid, nodes, truncated)


def _give_problems(
    nodes: list[Node], spans: list[tuple[int, int, int, int]], diagnostics: Iterable[Diagnostic]
) -> None:
    """Each diagnostic to the innermost own element holding it (an expanded tree of the
    same document may show one element several times: each copy gets it)."""
    unique = sorted({(s, e) for s, e, _, _ in spans})
    # Parent links by nesting: a stack over the spans sorted by start.
    elements: list[tuple[int, int, int]] = []
    open_: list[int] = []
    for s, e in unique:
        while open_ and not (elements[open_[-1]][0] <= s < elements[open_[-1]][1]):
            open_.pop()
        elements.append((s, e, open_[-1] if open_ else -1))
        open_.append(len(elements) - 1)
    problems = _Problems(diagnostics)
    problems.assign(elements)
    for s, _, _, idx in spans:
        found = problems.of(s)
        if found:
            found = sorted(found, key=lambda d: (d.severity, d.start))
            node = nodes[idx]
            node.severity = found[0].severity
            node.problems = tuple(f"{d.code}: {d.message}" for d in found)


def changed_node(picture: Picture, start: int, end: int) -> Node | None:
    """The node an edit of ``[start, end)`` (code points of the rendered document, the text
    as it is now) made or changed, for a viewer to keep it in view: the first node whose
    element lies inside the span (an element typed or pasted), else the innermost one
    whose element holds ``start`` (an attribute edited, a child deleted; an empty span
    also at the element's end, where a deletion or the last keystroke was); ``None`` when
    the edit is outside the tree.  Only nodes of the rendered document count; of the
    copies an expansion drew of one element, the first (or the deepest, for ``start``)."""
    start, end = min(start, end), max(start, end)
    holding: Node | None = None
    for node in picture.nodes:
        if node.source is not None:
            continue
        if node.index > 0 and start <= node.start and node.end <= end:
            return node
        holds = node.start <= start < node.end or start == end == node.end
        if holds and (holding is None or node.depth > holding.depth):
            holding = node
    return holding
