"""A tidy top-down layout of a picture (Reingold–Tilford, with boxes of any width).

Each subtree is laid out once, bottom-up, as its left and right contours (the extremes of
its boxes at each depth below its root, relative to the root's centre); a subtree is put
to the right of its left siblings as close as their contours allow, and a parent is
centred above its first and last children.  Both passes walk the pre-order list of nodes
(children after their parent), so no Python recursion happens whatever the depth.  A
contour is moved by an offset and merged by rewriting the shallower side's rows, so a
merge costs the depth of the shallower subtree and a chain of decorators costs one step
per node.

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


class _Contour:
    """One side of a subtree: x per row (deepest first) as ``values[j] + offset``."""

    __slots__ = ("offset", "values")

    def __init__(self, values: list[float], offset: float) -> None:
        self.values = values
        self.offset = offset


def _overlay(top: _Contour, under: _Contour) -> _Contour:
    """``top``'s rows where it has them, ``under``'s below: the deeper one's list is kept
    and the other's rows are written over its top rows, so the cost is the shallower's."""
    if len(top.values) >= len(under.values):
        return top
    base = len(under.values) - len(top.values)
    vals, d = under.values, top.offset - under.offset
    for j, v in enumerate(top.values):
        vals[base + j] = v + d
    return under


def layout(picture: Picture) -> Layout:
    nodes = picture.nodes
    n = len(nodes)
    lines = [node_lines(nd) for nd in nodes]
    sizes = [measure(nd, ls) for nd, ls in zip(nodes, lines, strict=True)]
    rel = [0.0] * n  # x of a node's centre relative to its parent's centre
    # Each subtree's contours as (values, offset): the deepest row first, the subtree's own
    # row last, each value plus the offset giving an x relative to the subtree root's centre.
    # Moving a contour changes its offset; merging two rewrites the rows of the shallower.
    left: list[_Contour | None] = [None] * n
    right: list[_Contour | None] = [None] * n
    for i in range(n - 1, -1, -1):  # children (later in pre-order) before parents
        half = sizes[i][0] / 2
        kids = nodes[i].children
        if not kids:
            left[i], right[i] = _Contour([-half], 0.0), _Contour([half], 0.0)
            continue
        acc_l, acc_r = left[kids[0]], right[kids[0]]
        assert acc_l is not None and acc_r is not None
        offsets = [0.0]
        for k in kids[1:]:
            cl, cr = left[k], right[k]
            assert cl is not None and cr is not None
            left[k] = right[k] = None
            a, c = acc_r.values, cl.values
            m = min(len(a), len(c))
            na, nc = len(a) - 1, len(c) - 1
            shift = (
                max([a[na - d] - c[nc - d] for d in range(m)]) + acc_r.offset - cl.offset
            ) + SIBLING_GAP
            offsets.append(shift)
            cl.offset += shift
            cr.offset += shift
            acc_l = _overlay(acc_l, cl)  # the left side: earlier siblings first
            acc_r = _overlay(cr, acc_r)  # the right side: this sibling first
        left[kids[0]] = right[kids[0]] = None
        mid = (offsets[0] + offsets[-1]) / 2
        for k, off in zip(kids, offsets, strict=True):
            rel[k] = off - mid
        acc_l.offset -= mid
        acc_r.offset -= mid
        acc_l.values.append(-half - acc_l.offset)
        acc_r.values.append(half - acc_r.offset)
        left[i], right[i] = acc_l, acc_r

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
    lo = min(root_l.values) + root_l.offset
    hi = max(root_r.values) + root_r.offset
    shift = MARGIN - lo
    boxes = [
        Box(cx[i] + shift - sizes[i][0] / 2, tops[nodes[i].depth], sizes[i][0], sizes[i][1])
        for i in range(n)
    ]
    width = hi - lo + 2 * MARGIN
    height = tops[-1] + depth_h[-1] + MARGIN
    return Layout(boxes, lines, width, height)
