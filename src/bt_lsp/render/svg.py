"""A picture as a standalone SVG document.

No external assets: the style sheet is inline, every label is ``<text>``, and the colours
are CSS variables with light defaults and dark ones under ``prefers-color-scheme``; each
default first asks for the VS Code theme variable, so the same SVG follows the editor's
theme inside a webview.  Every node is a ``<g class="node …" id="nK">`` carrying its
source span (``data-start``/``data-end``, code points), so a viewer can map a click to the
text and the text back to a node.  The ``viewBox`` is the whole picture and ``width`` and
``height`` its natural size; opened on its own it is scaled down to fit the window, so it
never opens cut off.
"""

from __future__ import annotations

import re

from bt_lsp.render.layout import (
    LINE_H,
    PAD_X,
    PAD_Y,
    Box,
    Layout,
    bus_y,
    layout,
)
from bt_lsp.render.picture import Node, Picture

# Characters XML 1.0 cannot carry (most C0 controls, lone surrogates, U+FFFE/U+FFFF).
_NOT_XML = re.compile("[\x00-\x08\x0b\x0c\x0e-\x1f\ud800-\udfff\ufffe\uffff]")


def visible(text: str) -> str:
    """``text`` with characters XML cannot hold written as ``U+XXXX``."""
    return _NOT_XML.sub(lambda m: f"U+{ord(m.group()):04X}", text)


_SPECIAL = re.compile('[&<>"\x00-\x08\x0b\x0c\x0e-\x1f\ud800-\udfff\ufffe\uffff]')


def escape(text: str) -> str:
    if _SPECIAL.search(text) is None:
        return text
    return (
        visible(text)
        .replace("&", "&amp;")
        .replace("<", "&lt;")
        .replace(">", "&gt;")
        .replace('"', "&quot;")
    )


_LIGHT = {
    "bg": ("editor-background", "#ffffff"),
    "fg": ("editor-foreground", "#1f2328"),
    "edge": ("editorLineNumber-foreground", "#8c959f"),
    "box": ("editorWidget-background", "#f6f8fa"),
    "control": ("charts-blue", "#2f6fc4"),
    "decorator": ("charts-purple", "#8250df"),
    "action": ("charts-green", "#1a7f37"),
    "condition": ("charts-yellow", "#bf8700"),
    "subtree": ("charts-orange", "#bc4c00"),
    "tree": ("editor-foreground", "#1f2328"),
    "unknown": ("disabledForeground", "#8c959f"),
    "key": ("textLink-foreground", "#0969da"),
    "error": ("editorError-foreground", "#cf222e"),
    "warning": ("editorWarning-foreground", "#9a6700"),
    "info": ("editorInfo-foreground", "#0969da"),
    "hint": ("editorHint-foreground", "#6e7781"),
    "focus": ("focusBorder", "#0969da"),
}
_DARK = {
    "bg": "#0d1117",
    "fg": "#e6edf3",
    "edge": "#6e7681",
    "box": "#161b22",
    "control": "#58a6ff",
    "decorator": "#bc8cff",
    "action": "#3fb950",
    "condition": "#d29922",
    "subtree": "#f0883e",
    "tree": "#e6edf3",
    "unknown": "#8b949e",
    "key": "#58a6ff",
    "error": "#f85149",
    "warning": "#d29922",
    "info": "#58a6ff",
    "hint": "#8b949e",
    "focus": "#58a6ff",
}


def _vars(dark: bool) -> str:
    return "".join(
        f"--bt-{k}:var(--vscode-{v},{_DARK[k] if dark else d});" for k, (v, d) in _LIGHT.items()
    )


_KINDS = ("tree", "control", "decorator", "action", "condition", "subtree", "unknown")

# The font is monospace: the layout's width estimate (CHAR_W per character) relies on it.
STYLE = (
    f".bt-tree{{{_vars(False)}}}"
    f"@media (prefers-color-scheme: dark){{.bt-tree{{{_vars(True)}}}}}"
    # Opened on its own (a browser, an image viewer), the picture is scaled down to fit the
    # window; inside a page or an <img>, the page sizes it.
    ".bt-tree:root{max-width:100vw;max-height:100vh}"
    ".bt-tree{background:var(--bt-bg);font:12px ui-monospace,SFMono-Regular,Menlo,Consolas,"
    "'DejaVu Sans Mono',monospace}"
    ".bt-tree text{fill:var(--bt-fg);white-space:pre;pointer-events:none}"
    ".bt-tree .edge{fill:none;stroke:var(--bt-edge);stroke-width:1.5}"
    ".bt-tree .edge.inlined{stroke-dasharray:4 3}"
    ".bt-tree .shape{fill:var(--bt-box);stroke-width:2}"
    ".bt-tree .title{font-weight:bold}"
    ".bt-tree .port{opacity:.85}"
    ".bt-tree .key{fill:var(--bt-key);font-weight:bold}"
    ".bt-tree .badge circle{stroke:none}"
    ".bt-tree .badge text{fill:var(--bt-bg);font-weight:bold;text-anchor:middle}"
    ".bt-tree .selected .shape{stroke:var(--bt-focus);stroke-width:4}"
    + "".join(f".bt-tree .kind-{k} .shape{{stroke:var(--bt-{k})}}" for k in _KINDS)
    + ".bt-tree .kind-unknown .shape{stroke-dasharray:5 3}"
    ".bt-tree .kind-tree .shape{stroke-width:3}"
    + "".join(
        f".bt-tree .sev-{s} .badge circle{{fill:var(--bt-{s})}}"
        for s in ("error", "warning", "info", "hint")
    )
)

_SEVERITY_CLASS = {1: "error", 2: "warning", 3: "info", 4: "hint"}
_KIND_LABEL = {
    "tree": "BehaviorTree",
    "control": "Control",
    "decorator": "Decorator",
    "action": "Action",
    "condition": "Condition",
    "subtree": "SubTree",
    "unknown": "unknown kind",
}


def _f(v: float) -> str:
    return f"{v:.1f}"


def _shape(kind: str, b: Box, x: str, y: str, w: str, h: str) -> str:
    """The node's outline: how BehaviorTree.CPP users tell the kinds apart at a glance."""
    if kind == "condition":  # a stadium
        return f'<rect class="shape" x="{x}" y="{y}" width="{w}" height="{h}" rx="{b.h / 2:.1f}"/>'
    if kind == "decorator":  # a hexagon
        c = min(12.0, b.w / 4)
        r, m, bot = b.x + b.w, b.y + b.h / 2, b.y + b.h
        return (
            f'<polygon class="shape" points="{b.x + c:.1f},{y} {r - c:.1f},{y} {r:.1f},{m:.1f} '
            f'{r - c:.1f},{bot:.1f} {b.x + c:.1f},{bot:.1f} {x},{m:.1f}"/>'
        )
    if kind == "subtree":  # a box with side bars, like a flowchart's predefined process
        return (
            f'<rect class="shape" x="{x}" y="{y}" width="{w}" height="{h}"/>'
            f'<path class="shape" d="M{b.x + 6:.1f} {y}v{h}M{b.x + b.w - 6:.1f} {y}v{h}"/>'
        )
    if kind == "control":  # square corners
        return f'<rect class="shape" x="{x}" y="{y}" width="{w}" height="{h}"/>'
    return f'<rect class="shape" x="{x}" y="{y}" width="{w}" height="{h}" rx="6"/>'


def _title(node: Node) -> str:
    parts = [f"{_KIND_LABEL[node.kind]} {node.type}"]
    if node.name:
        parts.append(f'name="{node.name}"')
    if node.subtree is not None:
        parts.append(
            "calls itself (not expanded)"
            if node.recursive
            else ("expanded below" if node.expanded else f"calls tree {node.subtree}")
        )
    parts.extend(node.problems)
    return "\n".join(parts)


_TEXT_INDENT = {"subtree": 6.0, "decorator": 8.0}


def _text(node: Node, b: Box, lines: list[str]) -> str:
    x = f"{b.x + PAD_X + _TEXT_INDENT.get(node.kind, 0.0):.1f}"
    top = b.y + PAD_Y + 12
    out = [f'<text class="title" x="{x}" y="{top:.1f}">{escape(lines[0])}</text>']
    first_port = len(lines) - len(node.ports)
    for i in range(1, len(lines)):
        line = lines[i]
        y = f"{top + LINE_H * i:.1f}"
        if i < first_port:
            out.append(f'<text class="name" x="{x}" y="{y}">{escape(line)}</text>')
            continue
        p = node.ports[i - first_port]
        head = f"{p.name}: "
        if line.startswith(head):
            value = line[len(head) :]
        else:  # the name alone fills the line
            head, value = line, ""
        cls = ' class="key"' if p.is_key else ""
        out.append(
            f'<text class="port" x="{x}" y="{y}">{escape(head)}'
            f"<tspan{cls}>{escape(value)}</tspan></text>"
        )
    return "".join(out)


def _badge(node: Node, b: Box) -> str:
    if node.severity is None:
        return ""
    cx, cy = b.x + b.w - 12, b.y + 12
    count = str(len(node.problems)) if len(node.problems) < 10 else "+"
    return (
        f'<g class="badge"><circle cx="{cx:.1f}" cy="{cy:.1f}" r="7"/>'
        f'<text x="{cx:.1f}" y="{cy + 4:.1f}">{count}</text></g>'
    )


def _node(node: Node, b: Box, lines: list[str]) -> str:
    cls = f"node kind-{node.kind}"
    if node.severity is not None:
        cls += f" sev-{_SEVERITY_CLASS[int(node.severity)]}"
    extra = ""
    if node.subtree is not None:
        extra += f' data-subtree="{escape(node.subtree)}"'
    if node.source is not None:
        extra += f' data-source="{escape(node.source)}"'
    x, y, w, h = f"{b.x:.1f}", f"{b.y:.1f}", f"{b.w:.1f}", f"{b.h:.1f}"
    return (
        f'<g class="{cls}" id="n{node.index}" data-start="{node.start}" data-end="{node.end}" '
        f'data-kind="{node.kind}" data-type="{escape(node.type)}"{extra}>'
        f"<title>{escape(_title(node))}</title>"
        f"{_shape(node.kind, b, x, y, w, h)}{_text(node, b, lines)}{_badge(node, b)}</g>"
    )


def _edge(pb: Box, cb: Box, inlined: bool) -> str:
    """Down from the parent, along the gap above the child's row, down into the child: every
    segment stays in the parent's band and out of the rows' boxes (see layout)."""
    cls = "edge inlined" if inlined else "edge"
    return (
        f'<path class="{cls}" d="M{pb.cx:.1f} {pb.bottom:.1f}'
        f'V{bus_y(cb):.1f}H{cb.cx:.1f}V{cb.y:.1f}"/>'
    )


def to_svg(picture: Picture, laid: Layout | None = None) -> str:
    """The picture as an SVG document (a string, no XML declaration)."""
    laid = laid or layout(picture)
    boxes = laid.boxes
    nodes = picture.nodes
    edges = [_edge(boxes[n.parent], boxes[n.index], nodes[n.parent].expanded) for n in nodes[1:]]
    body = [_node(n, boxes[n.index], laid.lines[n.index]) for n in nodes]
    w, h = _f(laid.width), _f(laid.height)
    label = escape(f"Behavior tree {picture.tree_id}")
    note = ""
    if picture.truncated:
        note = (
            f'<text x="16" y="{_f(laid.height - 4)}">… more nodes not drawn (expansion stopped at '
            f"{len(nodes)} nodes)</text>"
        )
    return (
        f'<svg xmlns="http://www.w3.org/2000/svg" class="bt-tree" viewBox="0 0 {w} {h}" '
        f'width="{w}" height="{h}" role="img" aria-label="{label}" '
        f'data-tree="{escape(picture.tree_id)}">'
        f"<style>{STYLE}</style>"
        f'<rect class="background" width="100%" height="100%" fill="var(--bt-bg)"/>'
        f'<g class="edges">{"".join(edges)}</g><g class="nodes">{"".join(body)}</g>{note}</svg>'
    )
