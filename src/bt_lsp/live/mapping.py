"""Where each node of a running tree comes from in the text: its uid -> its element.

The executor's tree (:class:`~bt_lsp.live.tree.LiveTree`, read from FULLTREE or a .btlog)
is matched against the documents it was loaded from: its main tree against the
``<BehaviorTree>`` of that ID (the document's own, else one its includes or the
workspace declare, found by a :data:`~bt_lsp.render.Resolver`), each SubTree instance
against the tree it calls, and the children of each node against its element's
children in order.  BehaviorTree.CPP writes each node with its registration ID and
instance name, so those are what is compared.

The text may have changed since the executor started.  Children are aligned with a diff
(difflib on ``(type, name)``, after the common ends), so one inserted, removed or renamed
node leaves its siblings mapped; what differs is reported as :class:`Mismatch` values.
Pure: it reads models and returns code-point offsets (:class:`~bt_lsp.ide.places.Place`);
the caller reads the files and converts positions.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from difflib import SequenceMatcher
from typing import Final, Literal

from bt_lsp.ide.places import Place
from bt_lsp.live.tree import LiveNode, LiveTree, parse_tree_xml
from bt_lsp.render import Resolver, TreeSource, main_tree, tree_id_of, workspace_resolver
from bt_lsp.syntax.elements import Element, Zone
from bt_lsp.syntax.model import Model

MismatchKind = Literal["renamed", "changed", "missing", "added", "tree"]

# Above this many comparisons, the middle of two lists of children (after their common
# ends) is aligned greedily, not by difflib (quadratic on a hostile or huge tree).
MAX_DIFF_CELLS: Final = 250_000
# How far a greedy alignment looks ahead for a counterpart of a running node.
LOOKAHEAD: Final = 32

# (registration ID, the tree a SubTree calls, instance name); the name is None for a
# SubTree without one (BehaviorTree.CPP names its instance "ID::uid").
_Key = tuple[str, str | None, str | None]


@dataclass(frozen=True, slots=True)
class Mismatch:
    """A difference between the running tree and the text.

    ``renamed``: same type, another instance name in the text; ``changed``: another type
    (or a SubTree calling another tree) at that place; ``missing``: a running node the
    text no longer has (``place`` is None); ``added``: an element of the text that is not
    running (``node`` is None); ``tree``: the running tree's ID is nowhere in the text,
    and the document's main tree was used instead."""

    kind: MismatchKind
    message: str
    node: LiveNode | None = None
    place: Place | None = None

    @property
    def uid(self) -> int | None:
        return self.node.uid if self.node is not None else None


@dataclass(frozen=True, slots=True)
class TreeMap:
    """The running tree mapped onto the text: where each uid's element is (its start
    tag's name), where the ``<BehaviorTree>`` of the main tree is, and the differences."""

    tree_id: str
    places: Mapping[int, Place]
    mismatches: tuple[Mismatch, ...]
    tree: Place | None = None
    missing: frozenset[int] = field(default=frozenset())

    def place(self, uid: int) -> Place | None:
        return self.places.get(uid)


@dataclass(frozen=True, slots=True)
class _Src:
    """An element and the model it is read from (``source`` as in TreeSource)."""

    model: Model
    element: Element
    source: str | None

    @property
    def place(self) -> Place:
        el = self.element
        return Place(self.source, el.name_start, el.name_end)

    def children(self) -> list[_Src]:
        els = self.model.elements
        out = []
        for i in self.element.children:
            el = els[i]
            if el.zone == Zone.NODE:
                out.append(_Src(self.model, el, self.source))
        return out


def _live_key(node: LiveNode, prefix: str) -> _Key:
    if node.subtree is not None:
        # The instance path is the enclosing instance's path, '/', and its name.
        name: str | None = node.path[len(prefix) + 1 :] if prefix else node.path
        if name == f"{node.subtree}::{node.uid}":
            name = None
        return ("SubTree", node.subtree, name)
    return (node.tag, None, node.name)


def _src_key(el: Element) -> _Key:
    if el.name == "SubTree":
        return ("SubTree", el.value("ID") or "", el.value("name"))
    node_id = el.node_id or ""
    return (node_id, None, el.value("name") or node_id)


def _label(key: _Key) -> str:
    kind, called, name = key
    text = kind if name is None or name == kind else f'{kind} "{name}"'
    return f"{text} -> {called}" if called is not None else text


def _running(node: LiveNode) -> str:
    return f"#{node.uid} {node.label} ({node.path})"


def align(
    a: Sequence[_Key], b: Sequence[_Key], similar: Callable[[int, int], bool]
) -> Iterator[tuple[int | None, int | None]]:
    """Pairs ``(i, j)`` of ``a[i]`` and ``b[j]`` in order, ``(i, None)`` for an item of
    ``a`` without a counterpart, ``(None, j)`` for one of ``b``.  Equal keys pair by
    difflib; where they differ, an item pairs with the next ``similar`` one."""
    n, m = len(a), len(b)
    lo = 0
    while lo < n and lo < m and a[lo] == b[lo]:
        yield lo, lo
        lo += 1
    hi_a, hi_b = n, m
    while hi_a > lo and hi_b > lo and a[hi_a - 1] == b[hi_b - 1]:
        hi_a -= 1
        hi_b -= 1
    if (hi_a - lo) * (hi_b - lo) <= MAX_DIFF_CELLS:
        matcher = SequenceMatcher(None, a[lo:hi_a], b[lo:hi_b], autojunk=False)
        ops = matcher.get_opcodes()
    else:
        ops = [("replace", 0, hi_a - lo, 0, hi_b - lo)]
    for op, i1, i2, j1, j2 in ops:
        i1, i2, j1, j2 = i1 + lo, i2 + lo, j1 + lo, j2 + lo
        if op == "equal":
            yield from zip(range(i1, i2), range(j1, j2), strict=True)
            continue
        j = j1
        for i in range(i1, i2):
            found = next((k for k in range(j, min(j2, j + LOOKAHEAD)) if similar(i, k)), None)
            if found is None:
                yield i, None
                continue
            for k in range(j, found):
                yield None, k
            yield i, found
            j = found + 1
        for k in range(j, j2):
            yield None, k
    for k in range(n - hi_a):
        yield hi_a + k, hi_b + k


def _overlap(a: Sequence[_Key], b: Sequence[_Key]) -> float:
    """How much two lists of children have in common, by type (0 to 1)."""
    if not a or not b:
        return 0.0
    common = Counter(k[:2] for k in a) & Counter(k[:2] for k in b)
    return 2 * sum(common.values()) / (len(a) + len(b))


class _Mapper:
    """``follow``: a SubTree instance's children are mapped onto the tree it calls (else
    they are left to a later :meth:`run` on that tree: :func:`map_each_tree`)."""

    def __init__(self, resolve: Resolver, follow: bool = True) -> None:
        self.resolve = resolve
        self.follow = follow
        self.places: dict[int, Place] = {}
        self.mismatches: list[Mismatch] = []
        self.missing: set[int] = set()
        self._added: set[Place] = set()
        # (running nodes, their enclosing instance's path, their counterparts' candidates)
        self.work: list[tuple[Sequence[LiveNode], str, list[_Src]]] = []

    def run(self, roots: Sequence[LiveNode], candidates: list[_Src], prefix: str = "") -> None:
        self.work.append((roots, prefix, candidates))
        while self.work:
            nodes, prefix, srcs = self.work.pop()
            self._children(nodes, prefix, srcs)

    def _children(self, nodes: Sequence[LiveNode], prefix: str, srcs: list[_Src]) -> None:
        keys = [_live_key(n, prefix) for n in nodes]
        skeys = [_src_key(s.element) for s in srcs]

        def similar(i: int, j: int) -> bool:
            a, b = keys[i], skeys[j]
            if a[:2] == b[:2] or (a[2] is not None and a[2] == b[2]):
                return True
            node, src = nodes[i], srcs[j]
            if node.subtree is not None or not node.children:
                return False
            kids = srcs[j].children() if src.element.name != "SubTree" else []
            own = [_live_key(c, prefix) for c in node.children]
            return _overlap(own, [_src_key(k.element) for k in kids]) >= 0.5

        start = len(self.work)
        for i, j in align(keys, skeys, similar):
            if i is None:
                assert j is not None
                self._add(srcs[j])
            elif j is None:
                self._lose(nodes[i], f"{_running(nodes[i])} is not in the text")
            else:
                self._pair(nodes[i], keys[i], prefix, srcs[j], skeys[j])
        # The first child's descendants next: what is found comes in document order.
        self.work[start:] = self.work[start:][::-1]

    def _pair(self, node: LiveNode, key: _Key, prefix: str, src: _Src, skey: _Key) -> None:
        place = src.place
        self.places[node.uid] = place
        if key[:2] != skey[:2]:
            self.mismatches.append(
                Mismatch(
                    "changed",
                    f"{_running(node)} runs where the text has {_label(skey)}",
                    node,
                    place,
                )
            )
        elif key[2] != skey[2]:
            self.mismatches.append(
                Mismatch(
                    "renamed",
                    f"{_running(node)} is {_label(skey)} in the text",
                    node,
                    place,
                )
            )
        if node.subtree is None:
            kids = src.children() if src.element.name != "SubTree" else []
            self.work.append((node.children, prefix, kids))
            return
        if not self.follow:
            return
        # A SubTree instance: its tree as the executor loaded it, else the one the text
        # now calls there.
        called = [node.subtree]
        if src.element.name == "SubTree" and skey[1] and skey[1] != node.subtree:
            called.append(skey[1])
        target = next((t for t in map(self.resolve, called) if t is not None), None)
        if target is None:
            why = f"tree {node.subtree!r} is not in the text"
            for child in node.children:
                self._lose(child, f"{_running(child)} is not in the text: {why}")
            return
        self.work.append((node.children, node.path, _tree_nodes(target)))

    def _lose(self, top: LiveNode, message: str) -> None:
        """``top`` and everything below it: missing in the text."""
        self.mismatches.append(Mismatch("missing", message, top))
        self.missing.add(top.uid)
        stack = list(reversed(top.children))
        while stack:
            node = stack.pop()
            self.missing.add(node.uid)
            self.mismatches.append(
                Mismatch("missing", f"{_running(node)} is not in the text", node)
            )
            stack.extend(reversed(node.children))

    def _add(self, src: _Src) -> None:
        place = src.place
        if place in self._added:  # a tree instantiated twice: said once
            return
        self._added.add(place)
        message = f"{_label(_src_key(src.element))} of the text is not in the running tree"
        self.mismatches.append(Mismatch("added", message, None, place))


def _tree_nodes(target: TreeSource) -> list[_Src]:
    return _Src(target.model, target.element, target.source).children()


def map_tree(live: LiveTree, model: Model, resolve: Resolver | None = None) -> TreeMap:
    """Map ``live`` onto the document of ``model``: its tree of the running main tree's
    ID (through ``resolve``: its own trees first, then those its context sees; default
    its own only), else its main tree.  Every uid gets a place or a ``missing`` mismatch."""
    resolve = resolve or workspace_resolver(model)
    mapper = _Mapper(resolve)
    target = resolve(live.tree_id)
    if target is None:
        main = main_tree(model)
        if main is None:
            mapper._lose(live.root, f"{_running(live.root)} is not in the text: it has no tree")
            return _result(live, mapper, None)
        target = TreeSource(model, main)
        mapper.mismatches.append(
            Mismatch(
                "tree",
                f"the executor runs tree {live.tree_id!r}, which the text does not declare; "
                f"mapped onto {tree_id_of(main)!r}",
                None,
                Place(None, main.name_start, main.name_end),
            )
        )
    tree = _Src(target.model, target.element, target.source)
    mapper.run((live.root,), tree.children())
    return _result(live, mapper, tree.place)


def map_each_tree(live: LiveTree, model: Model) -> TreeMap:
    """Each ``<BehaviorTree>`` of one document mapped onto every running instance of its ID
    (the main tree, each SubTree node calling it), for a file seen alone (a debugger's
    breakpoints): a tree the file does not declare is left to its own file, and neither
    its nodes nor what differs there are reported."""
    instances: dict[str, list[tuple[Sequence[LiveNode], str]]] = {
        live.tree_id: [((live.root,), "")]
    }
    for node in live.nodes.values():
        if node.subtree is not None and node.children:
            instances.setdefault(node.subtree, []).append((node.children, node.path))
    mapper = _Mapper(lambda _: None, follow=False)
    for el in model.elements:
        if el.zone != Zone.TREE or el.name != "BehaviorTree":
            continue
        tree = _Src(model, el, None)
        for nodes, prefix in instances.get(el.value("ID") or "", ()):
            mapper.run(nodes, tree.children(), prefix)
    return _result(live, mapper, None)


def _result(live: LiveTree, mapper: _Mapper, tree: Place | None) -> TreeMap:
    return TreeMap(
        live.tree_id,
        mapper.places,
        tuple(mapper.mismatches),
        tree,
        frozenset(mapper.missing),
    )


def map_tree_xml(xml: str | bytes, model: Model, resolve: Resolver | None = None) -> TreeMap:
    """:func:`map_tree` of the executor's XML (FULLTREE's answer); a ProtocolError for
    XML that is malformed, too large, or not a tree with a uid on every node."""
    return map_tree(parse_tree_xml(xml), model, resolve)
