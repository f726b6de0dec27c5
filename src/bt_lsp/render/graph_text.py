"""A picture as Mermaid (``flowchart TD``, for GitHub markdown) or Graphviz DOT.

Labels are always quoted and escaped for the format, so a node type, an instance name or
a port value can hold any character without breaking the graph: Mermaid gets entity codes
(``#quot;``, ``#35;`` …) inside a ``"…"`` label, DOT backslash escapes inside ``"…"``.
"""

from __future__ import annotations

from bt_lsp.render.layout import node_lines
from bt_lsp.render.picture import Node, Picture
from bt_lsp.render.svg import visible

# Mermaid shapes per kind: [rect] control, {{hexagon}} decorator, (rounded) action,
# ([stadium]) condition, [[subroutine]] SubTree, >flag] the tree itself, [/odd/] unknown.
_MERMAID_SHAPE = {
    "tree": (">", "]"),
    "control": ("[", "]"),
    "decorator": ("{{", "}}"),
    "action": ("(", ")"),
    "condition": ("([", "])"),
    "subtree": ("[[", "]]"),
    "unknown": ("[/", "/]"),
}
_MERMAID_STYLE = {
    "tree": "stroke:#1f2328,stroke-width:3px",
    "control": "stroke:#2f6fc4,stroke-width:2px",
    "decorator": "stroke:#8250df,stroke-width:2px",
    "action": "stroke:#1a7f37,stroke-width:2px",
    "condition": "stroke:#bf8700,stroke-width:2px",
    "subtree": "stroke:#bc4c00,stroke-width:2px",
    "unknown": "stroke:#8c959f,stroke-width:2px,stroke-dasharray:5 3",
}
_MERMAID_ESCAPES = {
    '"': "#quot;",
    "#": "#35;",
    "&": "#amp;",
    "<": "#lt;",
    ">": "#gt;",
    "`": "#96;",
    "\\": "#92;",
    "|": "#124;",
    ";": "#59;",
    "\n": " ",
    "\r": " ",
    "\t": " ",
}
_SEVERITY_WORD = {1: "error", 2: "warning", 3: "information", 4: "hint"}


def mermaid_escape(text: str) -> str:
    return "".join(_MERMAID_ESCAPES.get(c, c) for c in visible(text))


def _lines(node: Node) -> list[str]:
    lines = node_lines(node)
    if node.severity is not None:
        n = len(node.problems)
        lines.append(f"⚠ {n} {_SEVERITY_WORD[int(node.severity)]}{'s' if n > 1 else ''}")
    return lines


def to_mermaid(picture: Picture) -> str:
    out = ["flowchart TD"]
    for node in picture.nodes:
        o, c = _MERMAID_SHAPE[node.kind]
        label = "<br>".join(mermaid_escape(s) for s in _lines(node))
        out.append(f'  {node.id}{o}"{label}"{c}')
    for node in picture.nodes[1:]:
        arrow = "-.->" if picture.nodes[node.parent].expanded else "-->"
        out.append(f"  n{node.parent} {arrow} {node.id}")
    by_kind: dict[str, list[str]] = {}
    for node in picture.nodes:
        by_kind.setdefault(node.kind, []).append(node.id)
    for kind, ids in by_kind.items():
        out.append(f"  classDef {kind} {_MERMAID_STYLE[kind]}")
        out.append(f"  class {','.join(ids)} {kind}")
    flagged = [n.id for n in picture.nodes if n.severity is not None and n.severity <= 2]
    if flagged:
        out.append("  classDef problem fill:#ffebe9")
        out.append(f"  class {','.join(flagged)} problem")
    return "\n".join(out) + "\n"


_DOT_SHAPE = {
    "tree": 'shape=invhouse, style="filled,bold"',
    "control": 'shape=box, style="filled"',
    "decorator": 'shape=hexagon, style="filled"',
    "action": 'shape=box, style="rounded,filled"',
    "condition": 'shape=ellipse, style="filled"',
    "subtree": 'shape=component, style="filled"',
    "unknown": 'shape=box, style="dashed,filled"',
}
_DOT_COLOR = {
    "tree": "#1f2328",
    "control": "#2f6fc4",
    "decorator": "#8250df",
    "action": "#1a7f37",
    "condition": "#bf8700",
    "subtree": "#bc4c00",
    "unknown": "#8c959f",
}
_DOT_SEVERITY_COLOR = {1: "#cf222e", 2: "#9a6700", 3: "#0969da", 4: "#6e7781"}


def dot_quote(text: str) -> str:
    """A DOT string literal: backslashes and quotes escaped, line ends as ``\\n``."""
    body = visible(text).replace("\\", "\\\\").replace('"', '\\"')
    body = body.replace("\r\n", "\\n").replace("\r", "\\n").replace("\n", "\\n")
    return f'"{body}"'


def to_dot(picture: Picture) -> str:
    out = [
        f"digraph {dot_quote(picture.tree_id)} {{",
        '  node [fontname="monospace", fontsize=11, fillcolor="#ffffff"];',
        '  edge [color="#8c959f", arrowhead=none];',
    ]
    for node in picture.nodes:
        label = dot_quote("\n".join(_lines(node)))
        color = _DOT_COLOR[node.kind]
        extra = ""
        if node.severity is not None:
            sev = _DOT_SEVERITY_COLOR[int(node.severity)]
            extra = f', penwidth=3, color="{sev}", tooltip={dot_quote(chr(10).join(node.problems))}'
        else:
            extra = f', color="{color}"'
        out.append(f"  {node.id} [label={label}, {_DOT_SHAPE[node.kind]}{extra}];")
    for node in picture.nodes[1:]:
        style = " [style=dashed]" if picture.nodes[node.parent].expanded else ""
        out.append(f"  n{node.parent} -> {node.id}{style};")
    out.append("}")
    return "\n".join(out) + "\n"
