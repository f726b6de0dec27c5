"""The geometry a picture of a tree must have, checked on the SVG as drawn.

``problems(picture)`` lays the picture out, draws it, reads the boxes back from the layout
and the connectors from the SVG's ``<path class="edge">`` elements, and returns what is
wrong as readable lines (an empty list: nothing):

- every box lies on the canvas and no two boxes overlap;
- the subtrees of siblings occupy disjoint horizontal extents, in XML order;
- every parent is above its children (its box ends before their row begins) and centred
  over its first and last children;
- every connector starts on its parent's bottom edge, ends on its child's top edge, and
  none of its segments enters any box.

The SVG prints coordinates to 0.1, so comparisons allow :data:`EPS`.
"""

from __future__ import annotations

import re
from bisect import bisect_left
from itertools import pairwise

from lxml import etree

from bt_lsp.render import Picture, layout, to_svg
from bt_lsp.render.layout import Box

EPS = 0.11
SVG_NS = "{http://www.w3.org/2000/svg}"
_PATH = re.compile(r"([MVH])\s*(-?[\d.]+)(?:\s+(-?[\d.]+))?")

Point = tuple[float, float]
Segment = tuple[Point, Point]


def segments(d: str) -> list[Segment]:
    """The straight segments of an SVG path made of ``M x y``, ``V y`` and ``H x``."""
    out: list[Segment] = []
    cur: Point | None = None
    pos = 0
    for m in _PATH.finditer(d):
        assert d[pos : m.start()].strip() == "", f"unexpected path data in {d!r}"
        pos = m.end()
        op, a, b = m.group(1), float(m.group(2)), m.group(3)
        if op == "M":
            assert b is not None, d
            cur = (a, float(b))
            continue
        assert cur is not None and b is None, d
        nxt = (cur[0], a) if op == "V" else (a, cur[1])
        out.append((cur, nxt))
        cur = nxt
    assert d[pos:].strip() == "", f"unexpected path data in {d!r}"
    return out


def enters(seg: Segment, b: Box) -> bool:
    """Whether an axis-parallel segment passes through the inside of ``b`` (touching its
    outline is allowed)."""
    (x1, y1), (x2, y2) = seg
    return (
        min(x1, x2) < b.x + b.w - EPS
        and max(x1, x2) > b.x + EPS
        and min(y1, y2) < b.y + b.h - EPS
        and max(y1, y2) > b.y + EPS
    )


def _overlap(a: Box, b: Box) -> bool:
    return a.x < b.x + b.w and b.x < a.x + a.w and a.y < b.y + b.h and b.y < a.y + a.h


def extents(picture: Picture, boxes: list[Box]) -> list[tuple[float, float]]:
    """Each subtree's horizontal extent: the leftmost and rightmost x of its boxes."""
    n = len(picture.nodes)
    lo = [b.x for b in boxes]
    hi = [b.x + b.w for b in boxes]
    for i in range(n - 1, 0, -1):  # children after their parent in pre-order
        p = picture.nodes[i].parent
        lo[p] = min(lo[p], lo[i])
        hi[p] = max(hi[p], hi[i])
    return list(zip(lo, hi, strict=True))


def problems(picture: Picture) -> list[str]:
    laid = layout(picture)
    boxes = laid.boxes
    nodes = picture.nodes
    out: list[str] = []
    if len(boxes) != len(nodes):
        return [f"{len(boxes)} boxes for {len(nodes)} nodes"]

    for i, b in enumerate(boxes):
        if b.x < -EPS or b.y < -EPS or b.x + b.w > laid.width + EPS or b.bottom > laid.height + EPS:
            out.append(f"n{i} is off the canvas")
    by_x = sorted(range(len(boxes)), key=lambda i: boxes[i].x)
    for j, i in enumerate(by_x):  # sweep: only boxes starting before this one ends can meet
        a = boxes[i]
        for k in by_x[j + 1 :]:
            if boxes[k].x >= a.x + a.w:
                break
            if _overlap(a, boxes[k]):
                out.append(f"n{i} and n{k} overlap")

    ext = extents(picture, boxes)
    for node in nodes:
        kids = node.children
        for left, right in pairwise(kids):
            if ext[left][1] >= ext[right][0]:
                out.append(
                    f"the subtrees of siblings n{left} and n{right} interleave or are out of order"
                )
        box = boxes[node.index]
        for c in kids:
            if boxes[c].y <= box.bottom:
                out.append(f"n{node.index} is not above its child n{c}")
        if kids:
            mid = (boxes[kids[0]].cx + boxes[kids[-1]].cx) / 2
            if abs(box.cx - mid) > 1e-6:
                out.append(f"n{node.index} is not centred over its children")

    svg = etree.fromstring(to_svg(picture, laid).encode())
    paths = [p.get("d") or "" for p in svg.iter(f"{SVG_NS}path") if "edge" in p.get("class", "")]
    if len(paths) != len(nodes) - 1:
        return [*out, f"{len(paths)} connectors for {len(nodes) - 1} edges"]
    # Boxes by row top, each row sorted by x: a segment is checked against the rows its
    # height reaches and, in each, the boxes its x range reaches.
    rows: dict[float, list[int]] = {}
    for i, b in enumerate(boxes):
        rows.setdefault(b.y, []).append(i)
    row_tops = sorted(rows)
    row_xs = {y: sorted(rows[y], key=lambda i: boxes[i].x) for y in row_tops}
    row_bottom = {y: max(boxes[i].bottom for i in rows[y]) for y in row_tops}
    for child, d in zip(nodes[1:], paths, strict=True):
        segs = segments(d)
        pb, cb = boxes[child.parent], boxes[child.index]
        if not segs:
            out.append(f"the connector to n{child.index} is empty")
            continue
        (sx, sy), (ex, ey) = segs[0][0], segs[-1][1]
        if abs(sy - pb.bottom) > EPS or not pb.x - EPS <= sx <= pb.x + pb.w + EPS:
            out.append(f"the connector to n{child.index} does not start on n{child.parent}")
        if abs(ey - cb.y) > EPS or not cb.x - EPS <= ex <= cb.x + cb.w + EPS:
            out.append(f"the connector to n{child.index} does not end on n{child.index}")
        for seg in segs:
            (x1, y1), (x2, y2) = seg
            ylo, yhi = min(y1, y2), max(y1, y2)
            for top in row_tops[: bisect_left(row_tops, yhi)]:
                if row_bottom[top] <= ylo:
                    continue
                for i in row_xs[top]:
                    if boxes[i].x > max(x1, x2):
                        break
                    if enters(seg, boxes[i]):
                        out.append(f"the connector to n{child.index} crosses n{i}")
    return out
