"""The blackboard-key graph across trees: which trees own a key, which share it through
``<SubTree _autoremap="true">`` calls, and which ports of a tree are keys inside it.
References, highlights and rename of keys read it; it reads the documents it is given
and nothing else."""

from __future__ import annotations

import os
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import TypeGuard

from bt_lsp.ide.blackboard import (
    KeyRef,
    TreeKeys,
    enclosing_tree,
    mentions,
    subtree_range,
    tree_keys,
)
from bt_lsp.ide.name_edits import shown
from bt_lsp.rules.names import is_allowed_port_name
from bt_lsp.syntax.document import Document
from bt_lsp.syntax.elements import NameRef, PortSymbol, Role, Symbol, Zone, tree_symbol


@dataclass(frozen=True, slots=True)
class Tree:
    """A ``<BehaviorTree>``, by element index, of the document asked about (``path=None``)
    or of another workspace document."""

    path: str | None
    doc: Document
    index: int

    @property
    def id(self) -> str | None:
        return self.doc.model.elements[self.index].value("ID")

    def shown(self) -> str:
        tid = self.id
        name = f"tree '{shown(tid)}'" if tid is not None else "a tree without ID"
        return name if self.path is None else f"{name} (in {os.path.basename(self.path)})"


@dataclass(frozen=True, slots=True)
class _Call:
    """A ``<SubTree ID>`` call: the tree it is in, the tree it calls, whether it sets
    ``_autoremap``, and the ports it remaps explicitly."""

    caller: Tree
    callee: str
    autoremap: bool
    remapped: frozenset[str]


_TRUE_WORDS = frozenset({"1", "true", "True", "TRUE"})


def _call_at(path: str | None, doc: Document, idx: int) -> _Call | None:
    model = doc.model
    el = model.elements[idx]
    callee = el.value("ID")
    if el.zone != Zone.NODE or el.name != "SubTree" or callee is None:
        return None
    tree = enclosing_tree(model, idx)
    if tree < 0:
        return None
    remapped = frozenset(a.name for a in el.attrs if is_allowed_port_name(a.name))
    return _Call(Tree(path, doc, tree), callee, el.value("_autoremap") in _TRUE_WORDS, remapped)


class KeyGraph:
    """The document and the other workspace documents, as seen by the features on keys."""

    def __init__(self, doc: Document, others: Mapping[str, Document]) -> None:
        self.doc = doc
        self.others = others
        self.docs: list[tuple[str | None, Document]] = [(None, doc), *others.items()]
        self._keys: dict[tuple[Tree, str], TreeKeys] = {}

    def keys(self, t: Tree, key: str) -> TreeKeys:
        """The uses of ``key`` in ``t`` (and the unread script texts that may hold it):
        only that key's, as a request is about one key and a tree may use 200,000."""
        found = self._keys.get((t, key))
        if found is None:
            found = self._keys[t, key] = tree_keys(t.doc, t.index, key)
        return found

    def refs(self, sym: Symbol) -> list[tuple[str | None, Document, NameRef]]:
        return [(path, d, r) for path, d in self.docs for r in d.model.refs_to(sym)]

    def trees(self, tid: str) -> list[Tree]:
        """The trees with ID ``tid``."""
        return [
            Tree(path, d, r.element)
            for path, d, r in self.refs(tree_symbol(tid))
            if r.role == Role.TREE_DEF
        ]

    def calls_to(self, tid: str) -> list[_Call]:
        out: list[_Call] = []
        for path, d, r in self.refs(tree_symbol(tid)):
            if r.role == Role.SUBTREE_CALL:
                c = _call_at(path, d, r.element)
                if c is not None:
                    out.append(c)
        return out

    def calls_from(self, t: Tree) -> list[_Call]:
        els = t.doc.model.elements
        out: list[_Call] = []
        for i in subtree_range(t.doc.model, t.index):
            if els[i].name == "SubTree":
                c = _call_at(t.path, t.doc, i)
                if c is not None:
                    out.append(c)
        return out

    def shared(self, start: Tree, key: str) -> list[Tree]:
        """``start`` and the trees whose blackboards reach its ``key`` by name through
        ``<SubTree _autoremap="true">`` calls, either way and transitively.  A call that
        remaps the port of that name explicitly does not share it; private keys
        (``_key``) and root keys (``@key``) are never autoremapped."""
        found = [start]
        if key.startswith(("_", "@")):
            return found
        seen = {start}
        i = 0
        while i < len(found):
            t = found[i]
            i += 1
            linked: list[Tree] = []
            for c in self.calls_from(t):
                if c.autoremap and key not in c.remapped:
                    linked.extend(self.trees(c.callee))
            tid = t.id
            if tid is not None:
                linked.extend(
                    c.caller for c in self.calls_to(tid) if c.autoremap and key not in c.remapped
                )
            for o in linked:
                if o not in seen:
                    seen.add(o)
                    found.append(o)
        return found

    def may_be_root(self, t: Tree) -> bool:
        """Whether ``t`` may run as the main tree, whose blackboard is the root one: it is a
        ``main_tree_to_execute``, or no ``<SubTree>`` calls it."""
        tid = t.id
        if tid is None:
            return True
        roles = {r.role for _, _, r in self.refs(tree_symbol(tid))}
        return Role.MAIN_TREE in roles or Role.SUBTREE_CALL not in roles

    def root_users(self, key: str) -> list[Tree]:
        """The trees that use ``@key``, the key ``key`` of the root blackboard."""
        name = "@" + key
        out: list[Tree] = []
        for path, d in self.docs:
            if name not in d.text:
                continue
            for i, el in enumerate(d.model.elements):
                if el.zone == Zone.TREE:
                    t = Tree(path, d, i)
                    if mentions(self.keys(t, name), name):
                        out.append(t)
        return out

    def has_port(self, t: Tree, name: str) -> bool:
        tid = t.id
        return tid is not None and bool(self.refs(PortSymbol("port", "tree", tid, name)))


@dataclass(slots=True)
class KeyTargets:
    """What renaming a key changes: its uses in the trees that own it and, when the key is
    a port of its tree (declared in a ``<SubTree>`` model or remapped by a ``<SubTree>``
    call), that port's names."""

    key: str
    homes: list[Tree]
    uses: list[tuple[Tree, KeyRef]]
    port: PortSymbol | None = None
    port_refs: list[tuple[str | None, Document, NameRef]] = field(default_factory=list)

    def places(self) -> list[tuple[str | None, int, int, bool]]:
        """``(path, start, end, declaration)`` of every occurrence."""
        out = [(t.path, u.start, u.end, False) for t, u in self.uses]
        out.extend((path, r.start, r.end, r.declaration) for path, _, r in self.port_refs)
        return out


def port_targets(graph: KeyGraph, sym: PortSymbol, home: Tree | None = None) -> KeyTargets:
    """A port of a tree (``owner_kind == "tree"``): in the tree, the key of its name."""
    key = sym.name
    homes = graph.trees(sym.owner)
    if home is not None and home not in homes:
        homes.insert(0, home)
    uses = [(t, u) for t in homes for u in graph.keys(t, key).uses]
    return KeyTargets(key, homes, uses, sym, graph.refs(sym))


def key_targets(graph: KeyGraph, home: Tree, key: str) -> KeyTargets:
    tid = home.id
    if tid is not None and not key.startswith("@"):
        sym = PortSymbol("port", "tree", tid, key)
        if graph.refs(sym):
            return port_targets(graph, sym, home)
    return KeyTargets(key, [home], [(home, u) for u in graph.keys(home, key).uses])


def is_tree_port(sym: Symbol | None) -> TypeGuard[PortSymbol]:
    return sym is not None and sym.kind == "port" and sym.owner_kind == "tree"
