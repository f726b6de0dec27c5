"""Hover text: why a name breaks a rule and what to write instead, or what a name is."""

from __future__ import annotations

from dataclasses import dataclass

from bt_lsp.diagnostics import name_violations
from bt_lsp.document import Document
from bt_lsp.fixes import occurrences, taken_names
from bt_lsp.model import DECLARING_ROLES, NameRef, Role
from bt_lsp.names import RULES
from bt_lsp.sanitize import sanitize


@dataclass(frozen=True, slots=True)
class HoverText:
    markdown: str
    start: int
    end: int


_KIND_TITLE = {"model": "Model name", "port": "Port name", "instance": "Instance name"}


def _code(text: str) -> str:
    """``text`` as inline Markdown code, whatever backticks it holds."""
    shown = "".join(c if c.isprintable() or c == " " else f"U+{ord(c):04X}" for c in text)
    if "`" in shown:
        return f"`` {shown} ``"
    return f"`{shown}`"


def _what(ref: NameRef) -> str:
    sym = ref.symbol
    if ref.role == Role.INSTANCE:
        return "instance name (the node's label; defaults to its type)"
    if sym is None:
        return str(ref.role)
    if sym[0] == "tree":
        return f"{ref.role} of the behavior tree {_code(sym[1])}"
    if sym[0] == "model":
        return f"{ref.role} of the node type {_code(sym[1])}"
    owner = f"tree {_code(sym[2])}" if sym[1] == "tree" else f"node type {_code(sym[2])}"
    return f"{ref.role} {_code(sym[3])} of the {owner}"


def hover_at(doc: Document, offset: int) -> HoverText | None:
    model = doc.model
    ref = model.ref_at(offset)
    if ref is None:
        return None
    lines: list[str] = []
    violations = name_violations(ref)
    if violations:
        assert ref.kind is not None
        title = _KIND_TITLE[str(ref.kind)]
        lines.append(f"**{title} {_code(ref.text)} breaks the BehaviorTree.CPP naming rules**")
        lines.append("")
        for v in violations:
            lines.append(f"- `{v.code}`: {RULES.get(v.code, v.rule)}")
        chars = [c for v in violations for c in v.chars]
        if chars:
            lines.append("")
            lines.append("| column | character | category | why |")
            lines.append("|---|---|---|---|")
            for c in chars:
                lines.append(f"| {c.column} | {c.shown} | {c.category} | {c.reason} |")
        new = sanitize(ref.text, ref.kind, taken_names(model, ref.symbol))
        places = len(occurrences(model, ref))
        lines.append("")
        where = "1 place" if places == 1 else f"{places} places"
        lines.append(f"Suggested replacement: {_code(new)} (the quick fix renames {where})")
    else:
        lines.append(f"**{_what(ref)}**")
        decl = [r for r in occurrences(model, ref) if r.role in DECLARING_ROLES]
        if decl:
            line = doc.lines.position(decl[0].start, "utf-32")[0] + 1
            lines.append("")
            lines.append(f"Declared at line {line} ({decl[0].role}).")
        elif ref.symbol is not None and ref.role != Role.INSTANCE:
            lines.append("")
            lines.append("Not declared in this document.")
    return HoverText("\n".join(lines), ref.start, ref.end)
