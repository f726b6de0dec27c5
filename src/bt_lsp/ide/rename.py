"""The one rename core: what a rename at a position changes, the checks that refuse a
rename (with the reason) rather than do it partly or change the meaning, and the edits.
Both the rename request and the name fixes (:mod:`bt_lsp.ide.name_fixes`) go through
:class:`Renamer`."""

from __future__ import annotations

import re
from collections.abc import Collection, Iterable, Mapping
from dataclasses import dataclass, field
from typing import NoReturn

from bt_lsp.ide.blackboard import KeyForm, KeyRef, key_at, mentions, port_value_key, unread_mentions
from bt_lsp.ide.keygraph import KeyGraph, KeyTargets, Tree, is_tree_port, key_targets, port_targets
from bt_lsp.ide.name_edits import (
    Elsewhere,
    elsewhere,
    other_file_edits,
    rename_edits,
    shown,
    taken_names,
)
from bt_lsp.rules.builtins import NodeModel
from bt_lsp.rules.builtins_v3 import builtins_for
from bt_lsp.rules.context import ModelDecl
from bt_lsp.rules.names import NameKind, check_name, is_allowed_port_name
from bt_lsp.syntax.document import Document
from bt_lsp.syntax.edits import TextEdit, escape_value
from bt_lsp.syntax.elements import NameRef, PortSymbol, Role, Symbol
from bt_lsp.syntax.model import Model
from bt_lsp.syntax.xmlnames import XML_NAME_RE


class RenameRefused(Exception):
    """A rename that cannot be done; the message says why.  ``new_name`` tells a refusal of
    the new name (another name may do: it breaks a rule, is taken, or would merge two
    keys) from a refusal of the rename itself (the name or key cannot be renamed)."""

    def __init__(self, message: str, *, new_name: bool = False) -> None:
        super().__init__(message)
        self.message = message
        self.new_name = new_name


@dataclass(frozen=True, slots=True)
class RenameTarget:
    """What a rename at a position changes: the span of the name and its current text;
    ``ref`` is the name token, or ``key`` the blackboard key use."""

    start: int
    end: int
    placeholder: str
    ref: NameRef | None = None
    key: KeyRef | None = None


@dataclass(frozen=True, slots=True)
class RenamePlan:
    """Edits to the document, and to the other documents by path.

    ``written_out`` holds ``(path, start, end)`` (``path=None`` for the document) of the
    edits that only write out the key a port attribute already has (its ``{=}`` or ``=``,
    see :func:`rename`): when renames are combined, another rename's edit of the same span
    wins, since it renames that key."""

    edits: tuple[TextEdit, ...]
    other_edits: Mapping[str, tuple[TextEdit, ...]] = field(default_factory=dict)
    written_out: frozenset[tuple[str | None, int, int]] = frozenset()

    @property
    def places(self) -> int:
        return len(self.edits) + sum(len(e) for e in self.other_edits.values())


def _refuse_key_use(k: KeyRef) -> None:
    if k.key.startswith("@"):
        raise RenameRefused(
            f"'{shown(k.key)}' is a key of the root blackboard (the '@' prefix), which every "
            "tree of the running program shares; it cannot be renamed from one tree"
        )
    if k.entities:
        raise RenameRefused(
            f"The key '{shown(k.key)}' is written with character or entity references in "
            f"'{k.attr}'; write it out plainly to rename it"
        )


def prepare_rename(doc: Document, offset: int, version: str | None = None) -> RenameTarget | None:
    """The name a rename at ``offset`` would change, ``None`` when there is none there.

    Raises :class:`RenameRefused` for names that cannot be renamed from XML (the built-in
    nodes of the project's BehaviorTree.CPP ``version`` and their ports) and for
    blackboard keys that cannot be renamed (see :func:`rename`)."""
    builtins = builtins_for(version)
    ref = doc.model.ref_at(offset)
    if ref is None:
        key = key_at(doc, offset)
        if key is None or key.tree < 0:
            return None
        _refuse_key_use(key)
        return RenameTarget(key.start, key.end, key.key, key=key)
    sym = ref.symbol
    if sym is not None and sym.kind == "model" and sym.name in builtins:
        raise RenameRefused(
            f"'{shown(sym.name)}' is a built-in node type of BehaviorTree.CPP; it cannot be renamed"
        )
    if (
        sym is not None
        and sym.kind == "port"
        and sym.owner_kind == "model"
        and sym.owner in builtins
        and builtins[sym.owner].port(sym.name) is not None
    ):
        raise RenameRefused(
            f"'{shown(sym.name)}' is a port of the built-in node '{sym.owner}'; "
            "BehaviorTree.CPP declares it, so it cannot be renamed"
        )
    return RenameTarget(ref.start, ref.end, ref.text, ref)


def _kind_of(ref: NameRef) -> NameKind:
    if ref.kind is not None:
        return ref.kind
    return NameKind.MODEL  # main_tree_to_execute, end tags


def _refuse_new_name(new_name: str, why: str) -> NoReturn:
    raise RenameRefused(f"Cannot rename to '{shown(new_name)}': {why}", new_name=True)


def _check_new_name(
    ref: NameRef,
    new_name: str,
    model: Model,
    others: Mapping[str, Document],
    taken: Collection[str] | None = None,
    builtins: Mapping[str, NodeModel] | None = None,
) -> None:
    """Refuse a new name that breaks a rule of the name, or that another name of its
    namespace has (``taken``: those names, when the caller knows them already)."""
    kind = _kind_of(ref)
    sym = ref.symbol
    violations = check_name(new_name, kind, declaration=kind is NameKind.PORT)
    if violations:
        _refuse_new_name(new_name, violations[0].message)
    if kind is NameKind.INSTANCE or sym is None:
        return
    all_refs = [r for m in (model, *(d.model for d in others.values())) for r in m.refs_to(sym)]
    if kind is NameKind.PORT:
        if not is_allowed_port_name(new_name):
            _refuse_new_name(
                new_name,
                "a port name must start with an ASCII letter, or BehaviorTree.CPP does not "
                "read the attribute as a port",
            )
        if any(r.role == Role.PORT_USE for r in all_refs) and not XML_NAME_RE.fullmatch(new_name):
            _refuse_new_name(
                new_name,
                "the port is written as an attribute name, and this is not a valid XML name",
            )
    elif not XML_NAME_RE.fullmatch(new_name) and any(
        r.role in (Role.NODE_TYPE, Role.NODE_TYPE_END) for r in all_refs
    ):
        _refuse_new_name(
            new_name,
            "the node type is written as an element name, and this is not a valid XML name",
        )
    if new_name == sym.name:
        return
    if sym.kind != "port" and new_name in (builtins_for(None) if builtins is None else builtins):
        _refuse_new_name(
            new_name,
            "it is a built-in node type of BehaviorTree.CPP, and trees and node types share "
            "one namespace",
        )
    if taken is None:
        taken = taken_names(model, sym, (d.model for d in others.values()))
    if new_name in taken:
        if sym.kind == "port":
            owner = (
                f"tree '{sym.owner}'" if sym.owner_kind == "tree" else f"node type '{sym.owner}'"
            )
            _refuse_new_name(new_name, f"the {owner} already has a port with that name")
        _refuse_new_name(
            new_name,
            "a tree or node type with that name already exists (trees and node types share "
            "one namespace)",
        )


_SCRIPT_IDENTIFIER_RE = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")


def _check_key_name(new_name: str, in_script: bool) -> None:
    """Refuse a new name that cannot be a blackboard key where the key is written."""
    if not new_name:
        _refuse_new_name(new_name, "a blackboard key cannot be empty")
    if "{" in new_name or "}" in new_name:
        _refuse_new_name(
            new_name,
            "a blackboard key cannot contain '{' or '}', which delimit it in a port value",
        )
    if new_name != new_name.strip(" \t\r\n"):
        _refuse_new_name(
            new_name,
            "BehaviorTree.CPP keeps the white space inside the braces as part of the key "
            "('{ key }' is another entry than 'key')",
        )
    if new_name == "=":
        _refuse_new_name(new_name, "'{=}' stands for the key named like its port")
    if new_name.startswith("@"):
        _refuse_new_name(
            new_name,
            "a key starting with '@' is a key of the root blackboard; a rename cannot move "
            "a key there",
        )
    if any(c < " " or c == "\x7f" for c in new_name):
        _refuse_new_name(new_name, "a blackboard key cannot contain control characters")
    if in_script and (
        _SCRIPT_IDENTIFIER_RE.fullmatch(new_name) is None or new_name in ("true", "false")
    ):
        _refuse_new_name(
            new_name,
            "the key is used in a script, where it must be an identifier: an ASCII letter or "
            "'_', then ASCII letters, digits or '_' (and not 'true' or 'false')",
        )


def _check_key_movable(graph: KeyGraph, targets: KeyTargets, new_name: str) -> None:
    """Refuse a key rename that would not change every use of the key in the blackboards of
    the running program (whatever the new name)."""
    key = targets.key
    homes = targets.homes
    for t, u in targets.uses:
        if u.entities:
            raise RenameRefused(
                f"Cannot rename '{shown(key)}': it is written with character or entity "
                f"references in '{u.attr}' in {t.shown()}; write it out plainly first"
            )
    for t in homes:
        if unread_mentions(graph.keys(t, key), key):
            raise RenameRefused(
                f"Cannot rename '{shown(key)}': a script in {t.shown()} has a syntax error "
                f"before a '{shown(key)}' that may be this key; fix the script first"
            )
    if new_name == key:
        return
    for t in homes:
        group = graph.shared(t, key)
        for o in group:
            if o not in homes and mentions(graph.keys(o, key), key):
                raise RenameRefused(
                    f"Cannot rename '{shown(key)}': {o.shown()} shares it with {t.shown()} "
                    'through <SubTree _autoremap="true">, and renaming it in one tree '
                    "would disconnect them"
                )
        root = next((o for o in group if graph.may_be_root(o)), None)
        users = graph.root_users(key) if root is not None else []
        if root is not None and users:
            raise RenameRefused(
                f"Cannot rename '{shown(key)}': '@{shown(key)}' in {users[0].shown()} is this "
                f"key (of the root blackboard) when {root.shown()} runs as the main tree"
            )


def _check_no_merge(graph: KeyGraph, targets: KeyTargets, new_name: str) -> None:
    """Refuse a new name that is already a key of the trees owning the key (or of a tree
    sharing it): the two keys would become one."""
    if new_name == targets.key:
        return
    for t in targets.homes:
        group = graph.shared(t, new_name)
        for o in group:
            if mentions(graph.keys(o, new_name), new_name) or graph.has_port(o, new_name):
                how = "" if o == t else f", shared with {t.shown()} through _autoremap"
                _refuse_new_name(
                    new_name,
                    f"{o.shown()} already uses a key '{shown(new_name)}'{how}; the two keys "
                    "would become one",
                )
        root = next((o for o in group if graph.may_be_root(o)), None)
        users = graph.root_users(new_name) if root is not None else []
        if root is not None and users:
            _refuse_new_name(
                new_name,
                f"'@{shown(new_name)}' in {users[0].shown()} is that key (of the root "
                f"blackboard) when {root.shown()} runs as the main tree; the two keys would "
                "become one",
            )


def _key_edit(u: KeyRef, new_name: str) -> TextEdit:
    if u.form == KeyForm.SCRIPT:
        return TextEdit(u.start, u.end, new_name)
    text = escape_value(new_name, u.quote)
    return TextEdit(u.start, u.end, "{" + text + "}" if u.form == KeyForm.BARE_SAME else text)


def _spelled_out(d: Document, r: NameRef) -> TextEdit | None:
    """For a port attribute about to be renamed whose value is ``{=}`` or ``=`` (the key
    named like the port): that key written out, so that it stays the same key."""
    if r.role != Role.PORT_USE:
        return None
    a = d.model.elements[r.element].attr(r.text)
    k = port_value_key(d, r.element, a) if a is not None else None
    if k is None or k.form not in (KeyForm.SAME, KeyForm.BARE_SAME):
        return None
    return _key_edit(k, k.key)


class _Edits:
    """Edits by path (``None``: the document), one per span.  A written-out key gives way
    to any other edit of its span."""

    def __init__(self) -> None:
        self.by_path: dict[str | None, dict[tuple[int, int], TextEdit]] = {}
        self.written_out: set[tuple[str | None, int, int]] = set()

    def add(self, path: str | None, e: TextEdit, written_out: bool = False) -> None:
        spans = self.by_path.setdefault(path, {})
        span = (e.start, e.end)
        if written_out:
            if span in spans and (path, e.start, e.end) not in self.written_out:
                return
            self.written_out.add((path, e.start, e.end))
        else:
            self.written_out.discard((path, e.start, e.end))
        spans[span] = e

    def plan(self) -> RenamePlan:
        own = self.by_path.get(None, {})
        return RenamePlan(
            tuple(sorted(own.values())),
            {
                path: tuple(sorted(e.values()))
                for path, e in self.by_path.items()
                if path is not None and e
            },
            frozenset(self.written_out),
        )


def combined(plans: Iterable[RenamePlan]) -> RenamePlan:
    """Several renames (of different names) as one: one edit per span, where an edit that
    only writes out a key gives way to another rename's edit of the same span."""
    edits = _Edits()
    for p in plans:
        out = p.written_out
        for e in p.edits:
            edits.add(None, e, (None, e.start, e.end) in out)
        for path, file_edits in p.other_edits.items():
            for e in file_edits:
                edits.add(path, e, (path, e.start, e.end) in out)
    return edits.plan()


def _port_edits(graph: KeyGraph, sym: PortSymbol, new_name: str) -> _Edits:
    """Renaming a port: its names, and the ``{=}`` values of renamed attributes spelled out."""
    edits = _Edits()
    for path, d, r in graph.refs(sym):
        fix = _spelled_out(d, r)
        if fix is not None:
            edits.add(path, fix, written_out=True)
        for e in rename_edits([r], new_name):
            edits.add(path, e)
    return edits


def _rename_keys(
    graph: KeyGraph, targets: KeyTargets, new_name: str, port_checked: bool = False
) -> RenamePlan:
    if targets.uses or not targets.port:
        _check_key_name(new_name, any(u.form == KeyForm.SCRIPT for _, u in targets.uses))
    if targets.port_refs and not port_checked:
        _check_new_name(targets.port_refs[0][2], new_name, graph.doc.model, graph.others)
    _check_key_movable(graph, targets, new_name)
    _check_no_merge(graph, targets, new_name)
    edits = _port_edits(graph, targets.port, new_name) if targets.port is not None else _Edits()
    for t, u in targets.uses:
        edits.add(t.path, _key_edit(u, new_name))
    return edits.plan()


class Renamer:
    """Renames of the names of one document, by the rules of :func:`rename`, with the other
    workspace documents (by path).  One renamer serves many renames of the same documents
    (the name fixes use it so): what it reads of their trees is read once."""

    def __init__(
        self,
        doc: Document,
        others: Mapping[str, Document] | None = None,
        registered: Mapping[str, ModelDecl] | None = None,
        version: str | None = None,
    ) -> None:
        self._graph = KeyGraph(doc, others or {})
        self._registered = registered  # the context's models: where node types come from
        self._builtins = builtins_for(version)
        self._elsewhere: dict[Symbol, Elsewhere | None] = {}

    def elsewhere(self, sym: Symbol | None) -> Elsewhere | None:
        """Whether the target of ``sym`` is outside the workspace (see
        :func:`~bt_lsp.ide.name_edits.elsewhere`): a rename refuses a tree defined
        elsewhere, and a name fix is not offered as safe for a node type registered
        elsewhere."""
        if sym is None:
            return None
        if sym not in self._elsewhere:
            graph = self._graph
            self._elsewhere[sym] = elsewhere(
                sym, [graph.doc.model, *(d.model for d in graph.others.values())], self._registered
            )
        return self._elsewhere[sym]

    def plan(
        self,
        ref: NameRef,
        new_name: str,
        *,
        keys: bool = True,
        taken: Collection[str] | None = None,
    ) -> RenamePlan:
        """The edits renaming the name token ``ref`` of the document (and every reference to
        its symbol) to ``new_name``, as :func:`rename` makes them; raises
        :class:`RenameRefused` like it.

        ``keys=False`` leaves the blackboard keys of a tree's port as they are: only the
        port's own names change (a ``{=}`` of a renamed attribute is still written out), and
        only the new name is checked, also against the keys of the tree.  ``taken`` are the
        names the new one must avoid in its namespace, when the caller knows them already
        (by default they are collected from the documents)."""
        graph = self._graph
        away = self.elsewhere(ref.symbol)
        if away is not None and away.refuse:
            raise RenameRefused(f"Cannot rename {away.what}: {away.why}")
        _check_new_name(ref, new_name, graph.doc.model, graph.others, taken, self._builtins)
        sym = ref.symbol
        if sym is None:
            return RenamePlan(tuple(rename_edits([ref], new_name)))
        if is_tree_port(sym):
            targets = port_targets(graph, sym)
            if keys:
                return _rename_keys(graph, targets, new_name, port_checked=True)
            _check_no_merge(graph, targets, new_name)
            return _port_edits(graph, sym, new_name).plan()
        if sym.kind == "port":
            return _port_edits(graph, sym, new_name).plan()
        return RenamePlan(
            tuple(rename_edits(graph.doc.model.refs_to(sym), new_name)),
            other_file_edits(sym, new_name, {p: d.model for p, d in graph.others.items()}),
        )

    def key_plan(self, key: KeyRef, new_name: str) -> RenamePlan:
        """The edits renaming the blackboard key used at ``key`` (a use in the document)
        in its tree, and the port it is, as :func:`rename` makes them."""
        graph = self._graph
        home = Tree(None, graph.doc, key.tree)
        return _rename_keys(graph, key_targets(graph, home, key.key), new_name)


def rename(
    doc: Document,
    offset: int,
    new_name: str,
    others: Mapping[str, Document] | None = None,
    registered: Mapping[str, ModelDecl] | None = None,
    version: str | None = None,
) -> RenamePlan | None:
    """Rename the name under ``offset`` and every reference to it in the workspace.

    ``None`` when there is no name there; raises :class:`RenameRefused` when the name cannot
    be renamed or ``new_name`` breaks a rule (the message gives the rule's reason).  A port
    attribute renamed while its value is ``{=}`` or ``=`` (the key named like the port)
    gets that key written out, so that the node keeps its key.  ``version`` is the
    project's BehaviorTree.CPP major version: its built-in nodes keep their names, and a
    node of the project named like another version's built-in is the project's own.

    A blackboard key (under the cursor in ``{key}``, at the ``=`` of ``{=}`` or as a script
    identifier) is renamed in the tree that uses it, because BehaviorTree.CPP gives each
    tree instance a blackboard of its own: every use in the port values and scripts of
    that tree's nodes, nothing in other trees (the ``port="{key}"`` of a ``<SubTree>``
    call belongs to the calling tree).  When the key is also a port of its tree (declared
    in a ``<SubTree>`` model entry or remapped by ``<SubTree>`` calls: inside a subtree the
    port's name is its key), the port is renamed with it across the workspace; renaming
    such a port likewise renames the key inside the tree.

    Refused with the reason, rather than done partly or with a changed meaning:

    * a key starting with ``@``: a key of the root blackboard, which every tree of the
      running program shares, so no rename inside one tree can follow it;
    * a key that some tree reaches as ``@key``, in a tree that may run as the main tree
      (its document's ``main_tree_to_execute``, or called by no ``<SubTree>``): the main
      tree's blackboard is the root one;
    * a key shared through ``_autoremap``: a ``<SubTree _autoremap="true">`` call that does
      not remap a port of that name gives caller and subtree one entry for every key not
      starting with ``_`` (transitively, either way), so renaming the key where another
      tree of that chain uses it would disconnect the two;
    * a new name that would merge two keys: one already used in the tree or in a tree
      sharing it through ``_autoremap``, a port of the tree, or a key that ``@name``
      reaches while the tree may be the main one;
    * a key written with character or entity references (``{go&#97;l}``), and a key that
      appears after a syntax error in a script of the tree (which cannot be read further);
    * a new name that is empty, contains ``{`` or ``}`` or control characters, has white
      space around it, is ``=``, starts with ``@`` or, for a key used in a script, is not an
      identifier (``[A-Za-z_][A-Za-z0-9_]*``, not ``true`` or ``false``); for a key that
      is a port too, the port name rules apply as well.

    A refusal of the new name itself (a rule it breaks, a name already taken in its
    namespace, two keys it would merge) carries :attr:`RenameRefused.new_name`: another
    name may do.
    """
    target = prepare_rename(doc, offset, version)
    if target is None:
        return None
    renamer = Renamer(doc, others, registered, version)
    if target.key is not None:
        return renamer.key_plan(target.key, new_name)
    ref = target.ref
    if ref is None:  # pragma: no cover - a target is a name or a key
        return None
    return renamer.plan(ref, new_name)
