"""A tidy top-down layout of a picture in which every subtree has a band of its own.

Each subtree is laid out once, bottom-up, as a band: the horizontal extent of all its boxes.
A node's children's bands are put side by side in XML order, :data:`SIBLING_GAP` apart, and
the node is centred above its first and last children; its band is the union of theirs and
its own box.  Sibling subtrees therefore never interleave (a deep subtree is never tucked
under a shallow neighbour, as a contour-packing layout does), which is what keeps the
connectors clear: a parent's connector runs down from its box, along the gap between its row
and its children's row, and down into each child, all inside the parent's band, where the
only boxes are the parent's and its children's.  Both passes walk the pre-order list of
nodes (children after their parent), so no Python recursion happens whatever the depth.

Rows are as tall as their tallest box, so boxes of different heights never meet, and the
connectors' horizontal run (:func:`bus_y`) lies in the gap below the whole row.
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


def bus_y(child: Box) -> float:
    """The height of the horizontal run of the connectors to ``child`` and its siblings:
    the middle of the gap above their row (every box of the row above ends over it)."""
    return child.y - LEVEL_GAP / 2


def layout(picture: Picture) -> Layout:
    nodes = picture.nodes
    n = len(nodes)
    lines = [node_lines(nd) for nd in nodes]
    sizes = [measure(nd, ls) for nd, ls in zip(nodes, lines, strict=True)]
    band = [0.0] * n  # the width of each subtree's band
    centre = [0.0] * n  # a node's centre, from the left of its band
    start = [0.0] * n  # the left of a node's band, from the left of its parent's band
    for i in range(n - 1, -1, -1):  # children (later in pre-order) before parents
        w = sizes[i][0]
        kids = nodes[i].children
        if not kids:
            band[i], centre[i] = w, w / 2
            continue
        x = 0.0
        for k in kids:
            start[k] = x
            x += band[k] + SIBLING_GAP
        first, last = kids[0], kids[-1]
        c = (start[first] + centre[first] + start[last] + centre[last]) / 2
        lo = min(0.0, c - w / 2)  # a box wider than its children's bands widens its own
        hi = max(x - SIBLING_GAP, c + w / 2)
        if lo < 0.0:
            for k in kids:
                start[k] -= lo
        band[i], centre[i] = hi - lo, c - lo

    # Row heights and tops.
    depth_h: list[float] = []
    for nd, (_, h) in zip(nodes, sizes, strict=True):
        while len(depth_h) <= nd.depth:
            depth_h.append(0.0)
        depth_h[nd.depth] = max(depth_h[nd.depth], h)
    tops = [MARGIN]
    for h in depth_h[:-1]:
        tops.append(tops[-1] + h + LEVEL_GAP)

    left = [0.0] * n  # the left of each band in the picture
    left[0] = MARGIN
    for i in range(1, n):  # parents (earlier in pre-order) before children
        left[i] = left[nodes[i].parent] + start[i]
    boxes = [
        Box(left[i] + centre[i] - sizes[i][0] / 2, tops[nodes[i].depth], sizes[i][0], sizes[i][1])
        for i in range(n)
    ]
    width = band[0] + 2 * MARGIN
    height = tops[-1] + depth_h[-1] + MARGIN
    return Layout(boxes, lines, width, height)
