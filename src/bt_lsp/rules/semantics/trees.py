"""Trees and tree IDs: definitions, ``<SubTree>`` calls and the main tree.

* ``missing-id`` (error): a ``<BehaviorTree>`` without ``ID`` while ``<root>`` has more
  than one child element, or a ``<SubTree>`` without ``ID``.  Range: the element name.  (An
  empty ``ID=""`` is reported by the name rule ``model-name-empty``.)
* ``tree-child-count`` (error): a ``<BehaviorTree>`` without exactly one child element.
  Range: ``BehaviorTree``.
* ``registered-name-as-tree-id``: a ``<BehaviorTree ID>``, or a ``<SubTree ID>`` naming a
  tree that exists, that is the name of a built-in node or of a node in an authoritative
  catalog (error: BehaviorTree.CPP refuses it when it loads the file) or of a node only an
  advisory ``<TreeNodesModel>`` declares (a hint: refused if the C++ registers that node).
  A ``<SubTree ID>`` naming no tree is this error when a built-in or an authoritative model
  registers the name (VerifyXML refuses it at load), else ``unknown-subtree`` whatever an
  author's model declares.
  Range: the value.
* ``duplicate-tree-id`` (warning): a tree ID defined again, in this document or in a
  document of its include closure (BehaviorTree.CPP silently keeps the last one loaded).
  Range: the ID value of every definition in this document except the first one of it.
* ``unknown-subtree`` / ``unknown-main-tree``: a ``<SubTree ID>`` or
  ``main_tree_to_execute`` naming no visible tree: an error ("Can't find a tree with
  name"), or a hint when a workspace document that this one does not include defines it
  (applications often register every file).  The message says where bt-lsp looked: this
  document, its includes (named), the other BT files of the workspace (counted).  A
  ``<SubTree ID>`` that breaks a name rule and names no tree is left to the name rules:
  one problem, one diagnostic.  Range: the value.
* ``duplicate-subtree-name`` (warning): a second ``<SubTree>`` with the same ``name`` in one
  tree.  BehaviorTree.CPP 4 releases from January 2026 on (pull request 1053) reject it
  ("Duplicate SubTree path detected"); earlier releases and 3.8 create the tree, so it is
  a warning for version 4 and an unknown version, and not reported for version 3.
  Range: the second ``name`` value.
* ``subtree-recursion`` (error): trees calling each other in a cycle ("Recursive behavior
  tree cycle detected").  The cycle is found by a depth-first walk that starts at the main
  tree, then this document's trees in order; the call that closes a cycle is reported
  when it is in this document, else the last call of the cycle path that is.  Range: that
  ``<SubTree ID>`` value.
"""

from __future__ import annotations

import os
from itertools import compress
from operator import itemgetter
from typing import TYPE_CHECKING, Final

from bt_lsp.rules.builtins import BUILTINS
from bt_lsp.rules.codes import BT, Severity, define, unsafe
from bt_lsp.rules.context import TreeDecl
from bt_lsp.rules.names import NameKind, check_name
from bt_lsp.rules.semantics.base import State, TreeScope, quoted
from bt_lsp.syntax.elements import Element
from bt_lsp.syntax.tokens import Attr

if TYPE_CHECKING:
    pass

# The codes of these rules (see bt_lsp.rules.registry).
TREE_CHILD_COUNT: Final = define(
    "tree-child-count",
    Severity.ERROR,
    "a `<BehaviorTree>` does not have exactly one child element",
    BT,
    doc="""
        A `<BehaviorTree>` holds exactly one node, its root. BehaviorTree.CPP checks it when it
        loads the XML: `The tag <BehaviorTree> with ID 'Main' must have exactly 1 child`.
        """,
    why="The file does not load; wrap several nodes in a `<Sequence>` or another control node.",
    bad="""
        <BehaviorTree ID="Main">
          <AlwaysSuccess/>
          <AlwaysFailure/>
        </BehaviorTree>
        """,
    good="""
        <BehaviorTree ID="Main">
          <Sequence>
            <AlwaysSuccess/>
            <AlwaysFailure/>
          </Sequence>
        </BehaviorTree>
        """,
    since="Every version.",
)
UNKNOWN_SUBTREE: Final = define(
    "unknown-subtree",
    Severity.ERROR,
    "a `<SubTree ID>` that names no tree",
    BT,
    # bt-lsp never knows every tree an application registers (installed packages' files
    # among them), so a call renamed to a near tree may call the wrong one; a new tree
    # changes what the call runs.
    fixes={
        "rename": unsafe("Rename '{old}' to '{new}'"),
        "create": unsafe("Create the tree '{tree}' that fails until it is written"),
    },
    doc="""
        `<SubTree ID="X">` calls the tree `X`, which must be loaded by the time the tree is
        created: otherwise BehaviorTree.CPP throws `Can't find a tree with name: X`. bt-lsp looks
        in the document, the files it includes and the other BehaviorTree.CPP files of the
        workspace; a tree defined in a file that is not included is a hint (the application must
        register that file too).
        """,
    why="""
        The tree is not created; a renamed or misspelt tree ID breaks every call to it.
        """,
    bad="""
        <BehaviorTree ID="Main">
          <SubTree ID="Dokc"/>
        </BehaviorTree>
        <BehaviorTree ID="Dock">
          <AlwaysSuccess/>
        </BehaviorTree>
        """,
    good="""
        <BehaviorTree ID="Main">
          <SubTree ID="Dock"/>
        </BehaviorTree>
        <BehaviorTree ID="Dock">
          <AlwaysSuccess/>
        </BehaviorTree>
        """,
    since="Every version.",
)
UNKNOWN_MAIN_TREE: Final = define(
    "unknown-main-tree",
    Severity.ERROR,
    "`main_tree_to_execute` names no tree",
    BT,
    doc="""
        `main_tree_to_execute` on `<root>` names the tree `createTreeFromFile` creates; when no
        tree has that ID, creating it fails: `Can't find a tree with name: Mian`. bt-lsp looks
        in the document, the files it includes and the other tree files of the workspace; a
        tree found only in a file this one does not include makes it a hint (applications
        often register every file).
        """,
    why="The tree is never created; most often a typo or a tree renamed.",
    bad="""
        <root BTCPP_format="4" main_tree_to_execute="Mian">
          <BehaviorTree ID="Main">
            <AlwaysSuccess/>
          </BehaviorTree>
        </root>
        """,
    good="""
        <root BTCPP_format="4" main_tree_to_execute="Main">
          <BehaviorTree ID="Main">
            <AlwaysSuccess/>
          </BehaviorTree>
        </root>
        """,
    since="Every version.",
)
DUPLICATE_TREE_ID: Final = define(
    "duplicate-tree-id",
    Severity.WARNING,
    "two trees with the same `ID`",
    BT,
    doc="""
        Two trees with the same `ID`, in one document or across the files it includes.
        BehaviorTree.CPP reports nothing: all trees share one namespace, and the last
        definition loaded silently replaces the others.
        """,
    why="""
        A `<SubTree>` call runs a tree other than the one its author was reading.
        """,
    bad="""
        <BehaviorTree ID="Main">
          <AlwaysSuccess/>
        </BehaviorTree>
        <BehaviorTree ID="Main">
          <AlwaysFailure/>
        </BehaviorTree>
        """,
    good="""
        <BehaviorTree ID="Main">
          <AlwaysSuccess/>
        </BehaviorTree>
        <BehaviorTree ID="Fallback">
          <AlwaysFailure/>
        </BehaviorTree>
        """,
    since="Every version.",
)
REGISTERED_NAME_AS_TREE_ID: Final = define(
    "registered-name-as-tree-id",
    Severity.ERROR,
    "a tree ID that is the name of a registered node type",
    BT,
    doc="""
        A tree ID must not be the name of a registered node type (a built-in, a node of the
        catalog or of the C++). BehaviorTree.CPP refuses it when it loads the XML: `The
        attribute [ID] of tag <BehaviorTree> must not use the name of a registered Node`. A
        node only a tree file's `<TreeNodesModel>` declares makes it a hint: BehaviorTree.CPP
        refuses it only if the C++ registers that node.
        """,
    why="The file does not load.",
    bad="""
        <BehaviorTree ID="Sleep">
          <AlwaysSuccess/>
        </BehaviorTree>
        """,
    good="""
        <BehaviorTree ID="Nap">
          <AlwaysSuccess/>
        </BehaviorTree>
        """,
    since="Every version.",
)
SUBTREE_RECURSION: Final = define(
    "subtree-recursion",
    Severity.ERROR,
    "trees that call each other in a cycle",
    BT,
    doc="""
        Trees that call each other through `<SubTree>` in a cycle (`Main → Dock → Main`).
        BehaviorTree.CPP refuses it when it creates the tree: `Recursive behavior tree cycle
        detected: tree 'Main' references itself (directly or indirectly)`. The call that
        closes the cycle is reported.
        """,
    why="The tree is never created (it would be infinite).",
    bad="""
        <root BTCPP_format="4" main_tree_to_execute="Main">
          <BehaviorTree ID="Main">
            <SubTree ID="Dock"/>
          </BehaviorTree>
          <BehaviorTree ID="Dock">
            <SubTree ID="Main"/>
          </BehaviorTree>
        </root>
        """,
    good="""
        <root BTCPP_format="4" main_tree_to_execute="Main">
          <BehaviorTree ID="Main">
            <SubTree ID="Dock"/>
          </BehaviorTree>
          <BehaviorTree ID="Dock">
            <AlwaysSuccess/>
          </BehaviorTree>
        </root>
        """,
    since="Every version.",
)
DUPLICATE_SUBTREE_NAME: Final = define(
    "duplicate-subtree-name",
    Severity.WARNING,
    "two `<SubTree>` calls with the same `name` in one tree (rejected by BehaviorTree.CPP "
    "4 releases from January 2026 on)",
    BT,
    doc="""
        Two `<SubTree>` calls with the same `name` in one tree give two subtrees the same
        path. BehaviorTree.CPP 4 releases from January 2026 on (pull request 1053) refuse it
        when they create the tree: `Duplicate SubTree path detected: '…'. Multiple SubTree
        nodes with the same 'name' attribute under the same parent are not allowed`. Earlier
        releases, those of ROS 2 Humble and Jazzy among them, and 3.8 create the tree, so it
        is a warning naming the release; not reported for a version 3 project.
        """,
    why="""
        The tree stops loading with a newer release, and loggers and Groot2 cannot tell the
        two subtrees apart. Use unique names, or omit `name`.
        """,
    bad="""
        <root BTCPP_format="4" main_tree_to_execute="Main">
          <BehaviorTree ID="Main">
            <Sequence>
              <SubTree ID="Dock" name="dock"/>
              <SubTree ID="Dock" name="dock"/>
            </Sequence>
          </BehaviorTree>
          <BehaviorTree ID="Dock">
            <AlwaysSuccess/>
          </BehaviorTree>
        </root>
        """,
    good="""
        <root BTCPP_format="4" main_tree_to_execute="Main">
          <BehaviorTree ID="Main">
            <Sequence>
              <SubTree ID="Dock" name="dock"/>
              <SubTree ID="Dock" name="dock_again"/>
            </Sequence>
          </BehaviorTree>
          <BehaviorTree ID="Dock">
            <AlwaysSuccess/>
          </BehaviorTree>
        </root>
        """,
    since="BehaviorTree.CPP 4 releases from January 2026 on.",
)


def _where(st: State, decl: TreeDecl) -> str:
    if st.ctx.is_own(decl):
        return f"line {st.line_of(decl.start) + 1}"
    return os.path.basename(decl.path) if decl.path else "another document"


def _surely_registered(st: State, tree_id: str) -> bool:
    """Whether a built-in or an authoritative model (a catalog, the C++) registers
    ``tree_id`` (or a C++ registration whose port list is not all known)."""
    if tree_id in BUILTINS:
        return True
    decl = st.ctx.models.get(tree_id)
    return decl is not None and decl.registers


def _registered_name(st: State, tag: str, tree_id: str, start: int, end: int) -> bool:
    """Report a tree ID that is a node type's name; whether it was one."""
    if tree_id in BUILTINS:
        st.add(
            start,
            end,
            "registered-name-as-tree-id",
            f"{quoted(tree_id)} is a built-in node type; the ID of <{tag}> must not use the "
            "name of a registered node",
        )
        return True
    decl = st.ctx.models.get(tree_id)
    if decl is not None:
        where = "" if st.ctx.is_own(decl) or not decl.path else f" in {os.path.basename(decl.path)}"
        if decl.registers:
            what = (
                f"<{decl.category}> registered in {decl.where}"
                if decl.where and not decl.authoritative
                else f"<{decl.category}> in the node catalog{where}"
            )
            st.add(
                start,
                end,
                "registered-name-as-tree-id",
                f"{quoted(tree_id)} is a registered node type ({what}); BehaviorTree.CPP "
                f"refuses a <{tag}> ID that names a registered node",
            )
        elif decl.where:  # learned from C++ that the build does not compile
            st.add(
                start,
                end,
                "registered-name-as-tree-id",
                f"{quoted(tree_id)} is a node type registered in {decl.where}; "
                f"BehaviorTree.CPP refuses a <{tag}> ID that names a registered node, if the "
                "program that loads this file registers it",
                Severity.HINT,
            )
        else:
            st.add(
                start,
                end,
                "registered-name-as-tree-id",
                f"{quoted(tree_id)} is declared as a node type (<{decl.category}> in "
                f"<TreeNodesModel>{where}); BehaviorTree.CPP refuses a <{tag}> ID that names a "
                "registered node, if the C++ registers it (BehaviorTree.CPP reads the C++ "
                "registration, not this model)",
                Severity.HINT,
            )
        return True
    return False


def begin_tree(st: State, el: Element) -> None:
    a = el.attr("ID")
    if a is None:
        root = st.model.elements[el.parent] if el.parent >= 0 else None
        if root is not None and len(root.children) > 1:
            st.add(
                el.name_start,
                el.name_end,
                "missing-id",
                "<BehaviorTree> has no ID attribute; it is required when <root> has more "
                "than one child element",
            )
    elif a.value:
        s, e = el.span_of_value(a)
        _registered_name(st, "BehaviorTree", a.value, s, e)
    n = len(el.children)
    if n != 1:
        tid = el.value("ID") or ""
        what = "no child element" if n == 0 else f"{n} child elements"
        st.add(
            el.name_start,
            el.name_end,
            "tree-child-count",
            f"The <BehaviorTree> with ID {quoted(tid)} has {what}; it must have exactly 1 "
            "(wrap several nodes in a <Sequence> or another control node)",
        )


def check_duplicate_ids(st: State) -> None:
    """``duplicate-tree-id`` for this document's trees.  A document-wide rule: it compares
    the positions of the definitions, which every edit before them moves."""
    trees = st.ctx.trees
    # The IDs defined more than once, found in C: most documents have none.
    for tree_id in compress(trees.keys(), map((1).__lt__, map(len, trees.values()))):
        for d in trees[tree_id]:
            if st.ctx.is_own(d):
                _duplicate(st, tree_id, d.start, d.end)


def _duplicate(st: State, tree_id: str, start: int, end: int) -> None:
    decls = st.ctx.trees.get(tree_id, ())
    if len(decls) < 2:
        return
    others = [d for d in decls if not (st.ctx.is_own(d) and d.start == start)]
    earlier = [d for d in others if not st.ctx.is_own(d) or d.start < start]
    if not earlier:
        return
    shown = ", ".join(_where(st, d) for d in earlier[:3])
    if len(earlier) > 3:
        shown += f" and {len(earlier) - 3} more"
    st.add(
        start,
        end,
        "duplicate-tree-id",
        f"Tree ID {quoted(tree_id)} is also defined at {shown}; BehaviorTree.CPP silently "
        "keeps the last definition it loads",
    )


def check_call(st: State, el: Element, scope: TreeScope) -> None:
    """A ``<SubTree>`` element inside a tree."""
    a = el.attr("ID")
    if a is None:
        st.add(
            el.name_start,
            el.name_end,
            "missing-id",
            "<SubTree> has no ID attribute naming the tree to call",
        )
    elif a.value:
        s, e = el.span_of_value(a)
        if a.value in st.ctx.trees or a.value in st.ctx.workspace_trees:
            # A tree that exists: its ID must not be a registered node's name.
            if not _registered_name(st, "SubTree", a.value, s, e):
                _unknown_tree(st, a.value, s, e, "unknown-subtree", "<SubTree> calls")
        elif _surely_registered(st, a.value):
            # BehaviorTree.CPP's VerifyXML refuses the name at load, before it would look
            # for the tree: that is the error it reports.
            _registered_name(st, "SubTree", a.value, s, e)
        elif not check_name(a.value, NameKind.MODEL):
            # No such tree, whatever an author's model says of the name (an ID that breaks a
            # name rule is one problem: the name rules report it).
            _unknown_tree(st, a.value, s, e, "unknown-subtree", "<SubTree> calls")
    name = el.attr("name")
    if name is not None and name.value is not None:
        first = scope.subtree_names.get(name.value)
        if first is None:
            scope.subtree_names[name.value] = el
        else:
            _duplicate_name(st, el, name, first)


def _duplicate_name(st: State, el: Element, name: Attr, first: Element) -> None:
    """Only BehaviorTree.CPP releases from January 2026 on (pull request 1053) reject a
    duplicate SubTree path; earlier 4.x releases (ROS 2 Humble to Jazzy) and 3.8 create the
    tree, with two subtrees of one path (loggers and Groot2 confuse them).  bt-lsp knows
    the major version only, so version 4 and an unknown version get a warning; version 3
    never rejects it."""
    if st.v3 or name.value is None:
        return
    s, e = el.span_of_value(name)
    line = st.line_of(first.name_start) + 1
    st.add(
        s,
        e,
        "duplicate-subtree-name",
        f"Another <SubTree> in this tree (line {line}) has the name {quoted(name.value)}; "
        "BehaviorTree.CPP releases from January 2026 on (4.x after pull request 1053) "
        "reject the duplicate SubTree path, earlier ones create the tree with two "
        "subtrees of one path (use unique names or omit 'name')",
    )


def _unknown_tree(st: State, tree_id: str, start: int, end: int, code: str, what: str) -> None:
    if tree_id in st.ctx.trees:
        return
    elsewhere = st.ctx.workspace_trees.get(tree_id)
    if elsewhere:
        path = elsewhere[0].path
        st.add(
            start,
            end,
            code,
            f"{what} {quoted(tree_id)}, which is defined in "
            f"{os.path.basename(path) if path else 'another document'}; that document is "
            "not included, so the application must register it too",
            Severity.HINT,
        )
        return
    st.add(start, end, code, f"{what} {quoted(tree_id)}, but {searched(st)}")


def searched(st: State) -> str:
    """Where bt-lsp looked for a tree, for a message: the document, its includes, the
    workspace."""
    ctx = st.ctx
    n = len(ctx.included)
    if n:
        names = ", ".join(os.path.basename(p) for p in ctx.included[:3])
        more = f" and {n - 3} more" if n > 3 else ""
        files = f"the {n} file{'s' if n > 1 else ''} it includes ({names}{more})"
    else:
        files = "any file it includes (it includes none)"
    m = ctx.workspace_files
    others = (
        f"the {m} other BehaviorTree.CPP file{'s' if m > 1 else ''} of the workspace"
        if m
        else "the workspace (it holds no other BehaviorTree.CPP file)"
    )
    return f"no tree with that ID is defined in this document, in {files}, or in {others}"


def check_main_tree(st: State) -> None:
    root = st.model.root
    if root is None:
        return
    a = root.attr("main_tree_to_execute")
    if a is None or a.value is None:
        return
    s, e = root.span_of_value(a)
    _unknown_tree(st, a.value, s, e, "unknown-main-tree", "main_tree_to_execute names")


# A cycle found: the tree whose call is reported, the index of that call among its calls,
# and the cycle as shown.
_Cycle = tuple[str, int, str]
# What the walk reads: the main tree, this document's path, and the visible tree IDs with
# the calls and path of the definition kept for each.
_Graph = tuple[
    str | None, str | None, tuple[str, ...], tuple[tuple[str, ...], ...], tuple[str | None, ...]
]
_LAST = itemgetter(-1)
_PATH, _CALLS = itemgetter(1), itemgetter(4)


def check_recursion(st: State) -> None:
    """Find SubTree cycles among the visible trees; report the closing calls that are ours."""
    ctx = st.ctx
    if not ctx.trees:
        return
    root = st.model.root
    main = root.value("main_tree_to_execute") if root is not None else None
    # The definition BehaviorTree.CPP uses for each ID is the last one loaded.  Made in C:
    # an edit of a large document compares it with the last one instead of walking again.
    kept: list[TreeDecl] = list(map(_LAST, ctx.trees.values()))
    graph_key: _Graph = (
        main,
        ctx.path,
        tuple(ctx.trees),
        tuple(map(_CALLS, kept)),
        tuple(map(_PATH, kept)),
    )
    # The document's last walk, used again while its graph is the same: typing inside a
    # tree rarely changes which trees call which.
    last: tuple[_Graph, list[_Cycle]] | None = st.doc.history.memo.get("walks")
    if last is not None and last[0] == graph_key:
        cycles = last[1]
    else:
        cycles = _walk(dict(zip(graph_key[2], kept, strict=True)), main, ctx.path)
        st.doc.history.memo["walks"] = (graph_key, cycles)
    for tree_id, idx, shown in cycles:
        decl = ctx.trees[tree_id][-1]
        s, e = decl.call_offsets[idx]
        st.add(
            decl.start + s,
            decl.start + e,
            "subtree-recursion",
            f"This SubTree call closes a cycle ({shown}); BehaviorTree.CPP 4.10 refuses it "
            "when it creates the tree ('Recursive behavior tree cycle detected'), earlier "
            "versions recurse until the stack overflows (a crash)",
        )


def _walk(kept: dict[str, TreeDecl], main: str | None, own: str | None) -> list[_Cycle]:
    """The cycles of the calls between the trees ``kept`` (by ID), by a depth-first walk
    from the main tree, then from this document's trees, then from the others."""
    # A tree that calls none cannot be on a cycle.
    graph = {tid: decl for tid, decl in kept.items() if decl.calls}
    if not graph:
        return []
    order: list[str] = []
    if main:
        order.append(main)
    order.extend([tid for tid, decl in graph.items() if decl.path == own])
    order.extend(graph)
    state: dict[str, int] = {}  # 1 on the stack, 2 done
    found: list[_Cycle] = []
    flagged: set[tuple[str, int]] = set()
    for start_id in order:
        if start_id not in graph or start_id in state:
            continue
        # The walk's stack: tree IDs and, for each, how many of its calls were followed.
        ids: list[str] = [start_id]
        done: list[int] = [0]
        state[start_id] = 1
        while ids:
            decl = graph[ids[-1]]
            i = done[-1]
            if i >= len(decl.calls):
                state[ids.pop()] = 2
                done.pop()
                continue
            done[-1] = i + 1
            callee = decl.calls[i]
            if callee not in graph:
                continue
            cs = state.get(callee)
            if cs is None:
                state[callee] = 1
                ids.append(callee)
                done.append(0)
            elif cs == 1:
                cycle = _cycle(graph, ids, done, callee, own)
                if cycle is not None and cycle[:2] not in flagged:
                    flagged.add(cycle[:2])
                    found.append(cycle)
    return found


def _cycle(
    graph: dict[str, TreeDecl], ids: list[str], done: list[int], callee: str, own: str | None
) -> _Cycle | None:
    """The cycle that the call to ``callee`` closes, at the last of its calls that this
    document makes (``None`` when it makes none)."""
    # The cycle is the stack from `callee` to the top; each tree's last followed call
    # (index done - 1) leads to the next one, the top's closes the cycle.
    k = len(ids) - 1
    while k > 0 and ids[k] != callee:
        k -= 1
    path = [*ids[k:], callee]
    for j in range(len(ids) - 1, k - 1, -1):
        decl = graph[ids[j]]
        idx = done[j] - 1
        if decl.path == own and 0 <= idx < len(decl.call_offsets):
            shown = " → ".join(path) if len(path) <= 8 else " → ".join([*path[:4], "…", *path[-3:]])
            return ids[j], idx, shown
    return None
