"""The running tree as text: one node a line, with its status and uid."""

from __future__ import annotations

from collections.abc import Callable, Mapping

from bt_lsp.live.protocol import NodeState
from bt_lsp.live.tree import LiveNode, LiveTree


def state_text(state: NodeState | None) -> str:
    """``RUNNING``, ``IDLE (was SUCCESS)``, or ``?`` for a node the status left out."""
    return "?" if state is None else str(state)


def draw(
    tree: LiveTree,
    states: Mapping[int, NodeState] | None = None,
    where: Mapping[int, str] | None = None,
) -> list[str]:
    """The tree drawn with box characters; where each node comes from (``where``, by
    uid: ``file:line``) and its status aligned in columns when given."""
    rows: list[tuple[str, LiveNode]] = []

    def walk(node: LiveNode, prefix: str, last: bool, top: bool) -> None:
        branch = "" if top else ("└─ " if last else "├─ ")
        rows.append((f"{prefix}{branch}{node.label} #{node.uid}", node))
        inner = prefix if top else prefix + ("   " if last else "│  ")
        for i, child in enumerate(node.children):
            walk(child, inner, i == len(node.children) - 1, False)

    # Iterative depth is bounded by the tree parser (MAX_DEPTH), so recursion is safe here.
    walk(tree.root, "", True, True)
    columns: list[Callable[[int], str]] = []
    if where is not None:
        columns.append(lambda uid: where.get(uid, "?"))
    if states is not None:
        columns.append(lambda uid: state_text(states.get(uid)))
    texts = [text for text, _ in rows]
    for column in columns:
        width = max(map(len, texts)) + 2
        texts = [f"{t:<{width}}{column(n.uid)}" for t, (_, n) in zip(texts, rows, strict=True)]
    return texts
