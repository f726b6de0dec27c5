"""Hover text: why a name breaks a rule and what to write instead, or what a name is."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from bt_lsp.ide.name_edits import occurrences
from bt_lsp.ide.name_fixes import preferred_renaming
from bt_lsp.rules.builtins import BUILTINS, PortModel
from bt_lsp.rules.context import Context
from bt_lsp.rules.diagnostics import name_violations
from bt_lsp.rules.names import RULES
from bt_lsp.syntax.document import Document
from bt_lsp.syntax.elements import DECLARING_ROLES, NameRef, Role

_CPP_SUFFIXES = (".cpp", ".hpp", ".h", ".cc", ".cxx", ".hh", ".hxx", ".ipp")


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
    if ref.role == Role.INSTANCE or sym is None:
        return "Instance name (the node's label; it defaults to the node type)"
    if sym[0] == "port":
        owner = f"tree {_code(sym[2])}" if sym[1] == "tree" else f"node type {_code(sym[2])}"
        what = "Port declaration" if ref.role == Role.PORT_DECL else "Port"
        return f"{what} {_code(sym[3])} of the {owner}"
    name = _code(sym[1])
    return {
        Role.TREE_DEF: f"Behavior tree {name}",
        Role.SUBTREE_CALL: f"SubTree call of the tree {name}",
        Role.MAIN_TREE: f"Main tree {name}",
        Role.MODEL_DEF: f"TreeNodesModel entry for {name}",
    }.get(ref.role, f"Node type {name}")


def _cell(text: str) -> str:
    return text.replace("|", "\\|")


def _ports_table(ports: Sequence[PortModel]) -> list[str]:
    if not ports:
        return ["No ports."]
    rows = ["| port | direction | type | default | description |", "|---|---|---|---|---|"]
    for p in ports:
        default = "required" if p.default is None else _code(p.default)
        desc = " ".join(p.description.split()).replace("|", "\\|")
        rows.append(f"| {_code(p.name)} | {p.direction} | {_code(p.type)} | {default} | {desc} |")
    return rows


def _node_info(ref: NameRef, ctx: Context | None) -> list[str]:
    """What BehaviorTree.CPP knows of a node type or tree: category, ports, description."""
    sym = ref.symbol
    if sym is None or sym[0] not in ("model", "tree"):
        return []
    if sym[0] == "model" and sym[1] in BUILTINS:
        b = BUILTINS[sym[1]]
        return [
            "",
            f"Built-in {b.category} of BehaviorTree.CPP: {b.description}",
            "",
            *_ports_table(b.ports),
        ]
    if ctx is None:
        return []
    decl = ctx.models.get(sym[1]) if sym[0] == "model" else ctx.subtree_models.get(sym[1])
    if decl is None:
        return []
    where = "this document" if ctx.is_own(decl) else (decl.path or "another document")
    return [
        "",
        f"{decl.category} registered in the C++ of {where}."
        if where.endswith(_CPP_SUFFIXES)  # learned from C++ (the server says where)
        else f"{decl.category} declared in the TreeNodesModel of {where}.",
        "",
        *_ports_table(decl.ports),
    ]


def _port_info(ref: NameRef, ctx: Context | None) -> list[str]:
    sym = ref.symbol
    if sym is None or sym[0] != "port":
        return []
    port: PortModel | None = None
    if sym[1] == "model" and sym[2] in BUILTINS:
        port = BUILTINS[sym[2]].port(sym[3])
    elif ctx is not None:
        decl = ctx.models.get(sym[2]) if sym[1] == "model" else ctx.subtree_models.get(sym[2])
        port = decl.port(sym[3]) if decl is not None else None
    if port is None:
        return []
    default = "required" if port.default is None else f"default {_code(port.default)}"
    lines = ["", f"{port.direction} port, type {_code(port.type)}, {default}."]
    if port.description:
        lines += ["", port.description]
    return lines


def hover_at(doc: Document, offset: int, ctx: Context | None = None) -> HoverText | None:
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
            lines.append("| column | at | character | category | why |")
            lines.append("|---|---|---|---|---|")
            for c in chars:
                line, col = doc.lines.position(_raw_offset(doc, ref, c.offset), "utf-32")
                lines.append(
                    f"| {c.column} | line {line + 1}, col {col + 1} | {_cell(c.shown)} "
                    f"| {c.category} "
                    f"| {c.reason} |"
                )
        fix = preferred_renaming(doc, ref)
        if fix is not None:
            places = fix.plan.places
            where = "1 place" if places == 1 else f"{places} places"
            lines.append("")
            lines.append(f"Suggested replacement: {_code(fix.new)} (the quick fix renames {where})")
            if fix.kept is not None:
                lines.append("")
                lines.append(f"The quick fix leaves the {fix.kept} as it is: {fix.why}")
    else:
        lines.append(f"**{_what(ref)}**")
        decl = [r for r in occurrences(model, ref) if r.role in DECLARING_ROLES]
        if decl:
            line = doc.lines.position(decl[0].start, "utf-32")[0] + 1
            lines.append("")
            lines.append(f"Declared at line {line} ({decl[0].role}).")
        elif (
            ref.symbol is not None
            and ref.role != Role.INSTANCE
            and not (ref.symbol[0] == "model" and ref.symbol[1] in BUILTINS)
        ):
            lines.append("")
            lines.append("Not declared in this document.")
        lines.extend(_node_info(ref, ctx))
        lines.extend(_port_info(ref, ctx))
    return HoverText("\n".join(lines), ref.start, ref.end)


def _raw_offset(doc: Document, ref: NameRef, index: int) -> int:
    """Document offset of the ``index``-th character of a name's decoded text; inside an
    attribute value, entity and character references count as the one character they
    stand for."""
    raw = doc.text[ref.start : ref.end]
    if raw == ref.text:
        return ref.start + index
    pos = 0
    for _ in range(index):
        if pos < len(raw) and raw[pos] == "&":
            semi = raw.find(";", pos)
            pos = semi + 1 if semi != -1 else pos + 1
        else:
            pos += 1
    return ref.start + min(pos, len(raw))
