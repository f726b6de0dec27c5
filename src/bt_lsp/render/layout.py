"""A tidy top-down layout of a picture (Reingold–Tilford, with boxes of any width).

Each subtree is laid out once, bottom-up, as its left and right contours (the extremes of
its boxes at each depth below its root, relative to the root's centre); a subtree is put
to the right of its left siblings as close as their contours allow, and a parent is
centred above its first and last children.  Both passes walk the pre-order list of nodes
(children after their parent), so no Python recursion happens whatever the depth; the
contour merge costs the depth of the shallower side, so the whole layout is at most
nodes × height.

Rows are as tall as their tallest box, so boxes of different heights never meet.
"""

from __future__ import annotations

from dataclasses import dataclass

from bt_lsp.render.picture import Node, Picture

CHAR_W = 7.2  # the advance of a 12px monospace character
LINE_H = 16.0
PAD_X = 10.0
PAD_Y = 6.0
MIN_W = 64.0
SIBLING_GAP = 16.0
LEVEL_GAP = 36.0
MARGIN = 16.0
MAX_LABEL = 40  # characters of a label drawn (the full text is in the node's title)


def clip(text: str, limit: int = MAX_LABEL) -> str:
    return text if len(text) <= limit else text[: limit - 1] + "…"


def node_lines(node: Node) -> list[str]:
    """The text lines of a node's box: its type, its instance name, then its ports."""
    lines = [clip(node.type or "(no ID)") + (" ↻" if node.recursive else "")]
    if node.name and node.name != node.type:
        lines.append(clip(f'"{node.name}"'))
    lines.extend(clip(f"{p.name}: {p.value}") for p in node.ports)
    return lines


@dataclass(frozen=True, slots=True)
class Box:
    x: float  # left
    y: float  # top
    w: float
    h: float

    @property
    def cx(self) -> float:
        return self.x + self.w / 2

    @property
    def bottom(self) -> float:
        return self.y + self.h


@dataclass(frozen=True, slots=True)
class Layout:
    boxes: list[Box]  # by node index
    lines: list[list[str]]  # each node's text lines (node_lines)
    width: float
    height: float


# Room the outline takes from the text: the side bars of a SubTree, the points of a
# decorator's hexagon.
_SHAPE_EXTRA = {"subtree": 12.0, "decorator": 16.0}


def measure(node: Node, lines: list[str]) -> tuple[float, float]:
    w = max(MIN_W, max(len(s) for s in lines) * CHAR_W + 2 * PAD_X)
    if node.severity is not None:
        w += 18  # the badge
    w += _SHAPE_EXTRA.get(node.kind, 0.0)
    return w, len(lines) * LINE_H + 2 * PAD_Y


def layout(picture: Picture) -> Layout:
    nodes = picture.nodes
    n = len(nodes)
    lines = [node_lines(nd) for nd in nodes]
    sizes = [measure(nd, ls) for nd, ls in zip(nodes, lines, strict=True)]
    rel = [0.0] * n  # x of a node's centre relative to its parent's centre
    left: list[list[float] | None] = [None] * n  # contours, index = depth below the node
    right: list[list[float] | None] = [None] * n
    for i in range(n - 1, -1, -1):  # children (later in pre-order) before parents
        half = sizes[i][0] / 2
        kids = nodes[i].children
        if not kids:
            left[i], right[i] = [-half], [half]
            continue
        first = kids[0]
        acc_l = left[first]
        acc_r = right[first]
        assert acc_l is not None and acc_r is not None
        offsets = [0.0]
        for k in kids[1:]:
            cl, cr = left[k], right[k]
            assert cl is not None and cr is not None
            m = min(len(acc_r), len(cl))
            shift = max(acc_r[d] - cl[d] for d in range(m)) + SIBLING_GAP
            offsets.append(shift)
            if len(cl) > len(acc_l):
                acc_l = acc_l + [c + shift for c in cl[len(acc_l) :]]
            acc_r = [c + shift for c in cr] + acc_r[len(cr) :]
            left[k] = right[k] = None
        left[first] = right[first] = None
        mid = (offsets[0] + offsets[-1]) / 2
        for k, off in zip(kids, offsets, strict=True):
            rel[k] = off - mid
        left[i] = [-half, *(c - mid for c in acc_l)]
        right[i] = [half, *(c - mid for c in acc_r)]

    # Row heights and tops.
    depth_h: list[float] = []
    for nd, (_, h) in zip(nodes, sizes, strict=True):
        while len(depth_h) <= nd.depth:
            depth_h.append(0.0)
        depth_h[nd.depth] = max(depth_h[nd.depth], h)
    tops = [MARGIN]
    for h in depth_h[:-1]:
        tops.append(tops[-1] + h + LEVEL_GAP)

    cx = [0.0] * n
    for i in range(1, n):  # parents (earlier in pre-order) before children
        cx[i] = cx[nodes[i].parent] + rel[i]
    root_l, root_r = left[0], right[0]
    assert root_l is not None and root_r is not None
    shift = MARGIN - min(root_l)
    boxes = [
        Box(cx[i] + shift - sizes[i][0] / 2, tops[nodes[i].depth], sizes[i][0], sizes[i][1])
        for i in range(n)
    ]
    width = max(root_r) - min(root_l) + 2 * MARGIN
    height = tops[-1] + depth_h[-1] + MARGIN
    return Layout(boxes, lines, width, height)
