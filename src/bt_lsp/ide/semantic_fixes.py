"""Quick fixes for the semantic diagnostics (and for ``xml-unescaped-char``).

Pure: they return edits.  Each fix leaves the document well-formed.

* ``missing-format``: add ``BTCPP_format="4"`` to ``<root>`` (preferred).
* ``unknown-node``: rename to the suggested type (BehaviorTree.CPP 3 names and
  case-insensitive matches of a built-in are preferred, typo guesses are not), call a tree
  with ``<SubTree ID=…/>``, and declare the node in ``<TreeNodesModel>`` as an entry with
  every port attribute its uses in this document give, creating the section before
  ``</root>`` when there is none (never preferred: a fix-all must not invent models).
* ``unknown-attribute``: rename to the reserved attribute it most likely means.
* ``id-on-compact-node``: remove the attribute (preferred).
* ``xml-unescaped-char``: write the raw ``&`` or ``<`` as ``&amp;`` or ``&lt;`` (preferred).
"""

from __future__ import annotations

from bisect import bisect_right
from collections.abc import Callable, Mapping
from types import MappingProxyType
from typing import TYPE_CHECKING

from bt_lsp.ide.fix import Fix
from bt_lsp.rules.context import Context
from bt_lsp.rules.diagnostics import XML_UNESCAPED_CHAR, Diagnostic
from bt_lsp.rules.names import is_allowed_port_name
from bt_lsp.rules.semantics.document import MISSING_FORMAT
from bt_lsp.rules.semantics.nodes import ID_ON_COMPACT_NODE, UNKNOWN_NODE, UnknownNodeData
from bt_lsp.rules.semantics.ports import UNKNOWN_ATTRIBUTE, AttributeSuggestion
from bt_lsp.syntax.edits import TextEdit, escape_value
from bt_lsp.syntax.elements import EXPLICIT_TAGS, Element, Zone
from bt_lsp.syntax.model import Model

if TYPE_CHECKING:
    from bt_lsp.syntax.document import Document

__all__ = ["fixes_for_rule"]

_ESCAPES = MappingProxyType({"&": "&amp;", "<": "&lt;"})


def fixes_for_rule(doc: Document, ctx: Context, diag: Diagnostic) -> list[Fix]:
    """The quick fixes of one diagnostic of a rule other than the name rules; the preferred
    one first."""
    fixer = _FIXERS.get(diag.code)
    return fixer(doc, ctx, diag) if fixer is not None else []


def _escape(doc: Document, ctx: Context, diag: Diagnostic) -> list[Fix]:
    ch = doc.text[diag.start : diag.end]
    new = _ESCAPES.get(ch)
    if new is None:
        return []
    title = XML_UNESCAPED_CHAR.fix_title("escape", char=ch, escaped=new)
    return [Fix(title, (TextEdit(diag.start, diag.end, new),), True, diag)]


def _add_format(doc: Document, ctx: Context, diag: Diagnostic) -> list[Fix]:
    root = doc.model.root
    if root is None or root.attr("BTCPP_format") is not None:
        return []
    edit = TextEdit(root.name_end, root.name_end, ' BTCPP_format="4"')
    return [Fix(MISSING_FORMAT.fix_title("add"), (edit,), True, diag)]


def _suggested_attribute(doc: Document, ctx: Context, diag: Diagnostic) -> list[Fix]:
    data = diag.data
    if not isinstance(data, AttributeSuggestion) or _element_at(doc, doc.model, diag.start) is None:
        return []
    old = doc.text[diag.start : diag.end]
    edit = TextEdit(diag.start, diag.end, data.suggestion)
    title = UNKNOWN_ATTRIBUTE.fix_title("rename", suggestion=data.suggestion, old=old)
    return [Fix(title, (edit,), data.preferred, diag)]


def _remove_id_fix(doc: Document, ctx: Context, diag: Diagnostic) -> list[Fix]:
    el = _element_at(doc, doc.model, diag.start)
    return _remove_id(doc.text, el, diag) if el is not None else []


def _unknown_node_fixes(doc: Document, ctx: Context, diag: Diagnostic) -> list[Fix]:
    el = _element_at(doc, doc.model, diag.start)
    return _unknown_node(doc, ctx, doc.model, el, diag) if el is not None else []


# The fixes of each code that has some (their titles are defined with the code).
_FIXERS: Mapping[str, Callable[[Document, Context, Diagnostic], list[Fix]]] = MappingProxyType(
    {
        XML_UNESCAPED_CHAR.code: _escape,
        MISSING_FORMAT.code: _add_format,
        ID_ON_COMPACT_NODE.code: _remove_id_fix,
        UNKNOWN_ATTRIBUTE.code: _suggested_attribute,
        UNKNOWN_NODE.code: _unknown_node_fixes,
    }
)


def _element_at(doc: Document, model: Model, offset: int) -> Element | None:
    """The element whose start tag contains ``offset``."""
    elements = model.elements
    starts = [e.token_start for e in elements]
    i = bisect_right(starts, offset) - 1
    if i < 0:
        return None
    el = elements[i]
    length = doc.scan.tokens[el.token_index].length
    return el if offset <= el.token_start + length else None


def _remove_id(text: str, el: Element, diag: Diagnostic) -> list[Fix]:
    a = el.attr("ID")
    if a is None:
        return []
    start, _ = el.span_of_name(a)
    while start > 0 and text[start - 1] in " \t\r\n":
        start -= 1
    if a.value is None:
        end = el.span_of_name(a)[1]
    else:
        end = el.token_start + a.value_end + (1 if a.quote else 0)
    title = ID_ON_COMPACT_NODE.fix_title("remove", element=el.name)
    return [Fix(title, (TextEdit(start, end, ""),), True, diag)]


def _unknown_node(
    doc: Document, ctx: Context, model: Model, el: Element, diag: Diagnostic
) -> list[Fix]:
    data = diag.data
    if not isinstance(data, UnknownNodeData):
        return []
    type_id, explicit, new = data.type, data.explicit, data.rename
    fixes: list[Fix] = []
    if new is not None:
        fixes.append(
            Fix(
                UNKNOWN_NODE.fix_title("rename", type=type_id, new=new),
                tuple(_rename_edits(el, explicit, new)),
                data.preferred,
                diag,
            )
        )
    if (
        not explicit
        and (type_id in ctx.trees or type_id in ctx.workspace_trees)
        and el.self_closing
        and el.attr("ID") is None
    ):
        call = f'SubTree ID="{escape_value(type_id, chr(34))}"'
        fixes.append(
            Fix(
                UNKNOWN_NODE.fix_title("subtree", type=type_id),
                (TextEdit(el.name_start, el.name_end, call),),
                False,
                diag,
            )
        )
    declare = _declare(doc.text, model, el, type_id, explicit)
    if declare is not None:
        title = UNKNOWN_NODE.fix_title("declare", type=type_id)
        fixes.append(Fix(title, (declare,), False, diag))
    return fixes


def _rename_edits(el: Element, explicit: bool, new: str) -> list[TextEdit]:
    if explicit:
        a = el.attr("ID")
        if a is None:
            return []
        s, e = el.span_of_value(a)
        return [TextEdit(s, e, escape_value(new, a.quote) if a.quote else new)]
    edits = [TextEdit(el.name_start, el.name_end, new)]
    if el.end_name_start >= 0:
        edits.append(TextEdit(el.end_name_start, el.end_name_end, new))
    return edits


def _line_indent(text: str, offset: int) -> str | None:
    """The text between the line start and ``offset`` when it is all blanks."""
    start = max(text.rfind("\n", 0, offset), text.rfind("\r", 0, offset)) + 1
    lead = text[start:offset]
    return lead if lead.strip(" \t") == "" else None


def _unit(text: str, model: Model) -> str:
    """One level of indentation as the document writes it (two spaces by default)."""
    root = model.root
    if root is not None and root.children:
        outer = _line_indent(text, root.token_start) or ""
        inner = _line_indent(text, model.elements[root.children[0]].token_start)
        if inner is not None and len(inner) > len(outer) and inner.startswith(outer):
            return inner[len(outer) :]
    return "  "


def _declare(text: str, model: Model, el: Element, type_id: str, explicit: bool) -> TextEdit | None:
    if explicit:
        category = el.name
    else:
        category = {0: "Action", 1: "Decorator"}.get(len(el.children), "Control")
    ports: dict[str, None] = {}
    for other in model.elements:
        if other.zone != Zone.NODE:
            continue
        if other.name in EXPLICIT_TAGS:
            if other.value("ID") != type_id:
                continue
        elif other.name != type_id:
            continue
        for a in other.attrs:
            if is_allowed_port_name(a.name):
                ports.setdefault(a.name, None)
    nl = "\r\n" if "\r\n" in text else "\n"
    unit = _unit(text, model)
    ident = escape_value(type_id, '"')
    if ports:
        entry = [f'<{category} ID="{ident}">']
        entry += [f'{unit}<input_port name="{escape_value(p, chr(34))}"/>' for p in ports]
        entry.append(f"</{category}>")
    else:
        entry = [f'<{category} ID="{ident}"/>']
    section = next((e for e in model.elements if e.zone == Zone.MODELS), None)
    if section is not None:
        if section.self_closing:
            ind = _line_indent(text, section.token_start) or ""
            body = nl.join(ind + unit + line for line in entry)
            new = f"<TreeNodesModel>{nl}{body}{nl}{ind}</TreeNodesModel>"
            return TextEdit(section.token_start, section.end, new)
        if section.end_name_start < 0:
            return None
        return _insert_before_end_tag(text, section, entry, unit, nl)
    root = model.root
    if root is None or root.name != "root" or root.end_name_start < 0:
        return None
    lines = ["<TreeNodesModel>", *(unit + line for line in entry), "</TreeNodesModel>"]
    return _insert_before_end_tag(text, root, lines, unit, nl)


def _insert_before_end_tag(
    text: str, parent: Element, lines: list[str], unit: str, nl: str
) -> TextEdit:
    """Insert ``lines`` as the last children of ``parent``, one level deeper."""
    pos = parent.end_name_start - 2  # the '<' of '</name'
    ind = _line_indent(text, pos)
    if ind is not None:
        body = (nl + ind + unit).join(lines)
        return TextEdit(pos, pos, f"{unit}{body}{nl}{ind}")
    outer = _line_indent(text, parent.token_start) or ""
    body = nl.join(outer + unit + line for line in lines)
    return TextEdit(pos, pos, f"{nl}{body}{nl}{outer}")
