"""What completion proposes and how its text is written: the items, and the helpers
that write names, ports and snippets (shared by the tag and the attribute completions)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from enum import StrEnum

from bt_lsp.rules.builtins import PortModel
from bt_lsp.rules.context import Context
from bt_lsp.syntax.model import Model


class ItemKind(StrEnum):
    ELEMENT = "element"  # a structural element (BehaviorTree, include, input_port, ...)
    NODE = "node"  # a node type
    SUBTREE = "subtree"  # a <SubTree ID="..."> call
    ATTRIBUTE = "attribute"  # a reserved or structural attribute
    PORT = "port"
    TREE = "tree"  # a tree ID
    MODEL = "model"  # a node type ID in a value
    KEY = "key"  # a blackboard key
    VALUE = "value"  # a literal value


@dataclass(frozen=True, slots=True)
class Item:
    """One proposal.  ``insert`` is plain text; ``snippet`` (LSP snippet syntax) is used
    instead when the client supports snippets.  Both replace the span of the
    :class:`Completions` they belong to."""

    label: str
    kind: ItemKind
    detail: str = ""
    documentation: str = ""
    insert: str = ""
    snippet: str | None = None
    filter: str | None = None
    sort: str = ""


@dataclass(frozen=True, slots=True)
class Completions:
    """Items for the cursor, all replacing ``text[start:end]`` (``start <= cursor <= end``);
    ``context`` names the situation (``tag``, ``end-tag``, ``attribute``, ``value``,
    ``key``)."""

    start: int
    end: int
    context: str
    items: list[Item] = field(default_factory=list)
    # Written after an item where the client inserts text as it is (no indentation added):
    # in the indentation before a tag, the line break and indentation that keep the tag on
    # a line of its own.
    trail: str = ""
    # Whether items were left out (see MAX_KEY_ITEMS): typing more may bring others.
    incomplete: bool = False


# --- text helpers --------------------------------------------------------------------------


def snippet_literal(text: str) -> str:
    """``text`` as literal snippet text."""
    return text.replace("\\", "\\\\").replace("$", "\\$").replace("}", "\\}")


def md_code(text: str) -> str:
    return f"`` {text} ``" if "`" in text else f"`{text}`"


def ports_markdown(ports: Sequence[PortModel]) -> str:
    """The ports as a Markdown list, one a line (a table is cut off in a narrow popup):
    name, direction, type, default, description."""
    if not ports:
        return "No ports."
    rows = ["Ports:", ""]
    for p in ports:
        default = "no default" if p.default is None else f"default {md_code(p.default)}"
        ptype = f", {md_code(p.type)}" if p.type else ""
        desc = " ".join(p.description.split())
        rows.append(
            f"- {md_code(p.name)}: {p.direction}{ptype}, {default}" + (f"; {desc}" if desc else "")
        )
    return "\n".join(rows)


def port_doc(p: PortModel) -> str:
    default = "no default" if p.default is None else f"default {md_code(p.default)}"
    ptype = f", type {md_code(p.type)}" if p.type else ""
    out = f"{p.direction} port{ptype}, {default}."
    return f"{out}\n\n{p.description}" if p.description else out


def attr_insert(name: str, ports: Sequence[PortModel], n: int = 1) -> tuple[str, str]:
    """``name="…"`` for a port: (plain, snippet).  A port with a default gets it (in the
    snippet as the placeholder's text, to accept or overwrite); an output or inout port
    without one gets the key named like it, ``{name}``; any other an empty value (in the
    snippet a tab stop)."""
    port = next((p for p in ports if p.name == name), None)
    if port is not None and port.default is not None:
        value = attr_text(port.default)
        return f'{name}="{value}"', f'{snippet_literal(name)}="${{{n}:{snippet_literal(value)}}}"'
    if port is not None and port.direction != "input":
        return (
            f'{name}="{{{name}}}"',
            f'{snippet_literal(name)}="{{${{{n}:{snippet_literal(name)}}}}}"',
        )
    return f'{name}=""', f'{snippet_literal(name)}="${{{n}}}"'


def with_ports(
    name: str, ports: Sequence[PortModel], leaf: bool, attrs: tuple[str, str] = ("", "")
) -> tuple[str, str]:
    """A start tag's text after ``<``: the name, ``attrs`` (plain, snippet), the ports
    without a default, the tag's end: (plain, snippet).

    Ports with a default are left out (BehaviorTree.CPP uses the default).  The snippet
    writes each port without a default as a tab stop to fill in (an output as the key
    named like it); the plain text, which has no tab stops, writes only the outputs'
    keys, since an empty value is never right (the missing ports are then reported)."""
    plain = [name, attrs[0]] if attrs[0] else [name]
    snip = [snippet_literal(name), attrs[1]] if attrs[1] else [snippet_literal(name)]
    n = 1
    for p in ports:
        if p.default is None:
            a, s = attr_insert(p.name, ports, n)
            if p.direction != "input":
                plain.append(a)
            snip.append(s)
            n += 1
    if leaf:
        return " ".join(plain) + "/>", " ".join(snip) + "/>"
    return (
        " ".join(plain) + f"></{name}>",
        " ".join(snip) + f">\n\t$0\n</{snippet_literal(name)}>",
    )


def attr_text(value: str) -> str:
    """``value`` written between double quotes of an attribute."""
    return value.replace("&", "&amp;").replace("<", "&lt;").replace('"', "&quot;")


def tree_ids(ctx: Context) -> list[str]:
    """The IDs of the trees a ``<SubTree>`` call may name, sorted."""
    ids = set(ctx.trees) | set(ctx.workspace_trees) | set(ctx.subtree_models)
    return sorted(i for i in ids if i)


def tree_id(model: Model, tree: int) -> str | None:
    """The ID of the ``<BehaviorTree>`` at element ``tree`` (``None``: none, or no tree)."""
    return model.elements[tree].value("ID") if tree >= 0 else None
