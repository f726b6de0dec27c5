"""Quick fixes for the semantic diagnostics (and for ``xml-unescaped-char``).

Pure: they return edits.  Each fix leaves the document well-formed.  Whether a fix is
safe is defined with its code (``fixes=`` of :func:`bt_lsp.rules.codes.define`); the first
safe fix of a diagnostic is its preferred one.  A rule that defines its code with a
``fixer=`` makes its fixes beside itself (:data:`bt_lsp.rules.codes.Fixer`); the codes
below have theirs here.

* ``missing-format``: add ``BTCPP_format="4"`` to ``<root>`` (safe where the project is
  known to build against version 4).
* ``unknown-node``: rename to the suggested type (safe for BehaviorTree.CPP 3 names in a
  version 4 project, built-ins in another case, and the one nearest name when every
  registration is known), call a tree with ``<SubTree ID=…/>``, and declare the node in
  ``<TreeNodesModel>`` as an entry with every port attribute its uses in this document
  give, creating the section before ``</root>`` when there is none (never applied in bulk:
  a fix-all must not invent models).
* ``unknown-attribute``: rename to the reserved attribute it most likely means.
* ``id-on-compact-node``: remove the attribute.
* ``xml-unescaped-char``: write the raw ``&`` or ``<`` as ``&amp;`` or ``&lt;``.
* ``missing-required-port`` / ``missing-port-without-default``: add the missing ports
  after the node's last attribute: a ``<SubTree>`` port as the key of its name
  (``goal="{goal}"``), any other (a port without a default) as ``""`` to fill in.
* ``unknown-subtree``: rename the call to the one tree whose ID is a typo away, or write
  the missing tree before ``</root>``: a ``<BehaviorTree>`` whose one node is
  ``<AlwaysFailure/>`` and a TODO comment, so that it loads and fails until written (a
  placeholder that succeeds would let the caller go on as if it had run).
"""

from __future__ import annotations

from bisect import bisect_right
from collections.abc import Callable, Mapping
from types import MappingProxyType
from typing import TYPE_CHECKING

from bt_lsp.ide.fix import Fix
from bt_lsp.rules.codes import Applicability, Code, all_defined
from bt_lsp.rules.context import Context
from bt_lsp.rules.diagnostics import XML_UNESCAPED_CHAR, Diagnostic
from bt_lsp.rules.names import is_allowed_port_name
from bt_lsp.rules.semantics.base import edit_distance
from bt_lsp.rules.semantics.document import MISSING_FORMAT
from bt_lsp.rules.semantics.nodes import ID_ON_COMPACT_NODE, UNKNOWN_NODE, UnknownNodeData
from bt_lsp.rules.semantics.ports import (
    MISSING_PORT_WITHOUT_DEFAULT,
    MISSING_REQUIRED_PORT,
    UNKNOWN_ATTRIBUTE,
    AttributeSuggestion,
    MissingPorts,
)
from bt_lsp.rules.semantics.trees import UNKNOWN_SUBTREE
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
    if fixer is not None:
        return fixer(doc, ctx, diag)
    code = all_defined().get(diag.code)
    if code is None or code.fixer is None:
        return []
    out: list[Fix] = []
    for f in code.fixer(doc, ctx, diag):
        kind = code.applicability(f.key)
        # The first safe fix is the preferred one (fix-all and check --fix make it).
        preferred = kind is Applicability.SAFE and not any(x.preferred for x in out)
        title = code.fix_title(f.key, **f.values)
        out.append(Fix(title, f.edits, preferred, diag, applicability=kind))
    return out


def _fix(
    code: Code,
    key: str,
    edits: tuple[TextEdit, ...],
    diag: Diagnostic,
    preferred: bool = True,
    **values: object,
) -> Fix:
    """The fix ``key`` of ``code``, titled and classed as the code defines it; preferred
    (unless told not to) when it is safe."""
    kind = code.applicability(key)
    preferred = preferred and kind is Applicability.SAFE
    return Fix(code.fix_title(key, **values), edits, preferred, diag, applicability=kind)


def _escape(doc: Document, ctx: Context, diag: Diagnostic) -> list[Fix]:
    ch = doc.text[diag.start : diag.end]
    new = _ESCAPES.get(ch)
    if new is None:
        return []
    edit = TextEdit(diag.start, diag.end, new)
    return [_fix(XML_UNESCAPED_CHAR, "escape", (edit,), diag, char=ch, escaped=new)]


def _add_format(doc: Document, ctx: Context, diag: Diagnostic) -> list[Fix]:
    root = doc.model.root
    if root is None or root.attr("BTCPP_format") is not None:
        return []
    edit = TextEdit(root.name_end, root.name_end, ' BTCPP_format="4"')
    key = "add" if ctx.btcpp_version == "4" else "add-unknown-version"
    return [_fix(MISSING_FORMAT, key, (edit,), diag)]


def _suggested_attribute(doc: Document, ctx: Context, diag: Diagnostic) -> list[Fix]:
    data = diag.data
    if not isinstance(data, AttributeSuggestion) or _element_at(doc, doc.model, diag.start) is None:
        return []
    old = doc.text[diag.start : diag.end]
    edit = TextEdit(diag.start, diag.end, data.suggestion)
    key = "rename" if data.preferred else "guess"
    return [_fix(UNKNOWN_ATTRIBUTE, key, (edit,), diag, suggestion=data.suggestion, old=old)]


def _remove_id_fix(doc: Document, ctx: Context, diag: Diagnostic) -> list[Fix]:
    el = _element_at(doc, doc.model, diag.start)
    return _remove_id(doc.text, el, diag) if el is not None else []


def _unknown_node_fixes(doc: Document, ctx: Context, diag: Diagnostic) -> list[Fix]:
    el = _element_at(doc, doc.model, diag.start)
    return _unknown_node(doc, ctx, doc.model, el, diag) if el is not None else []


def _missing_ports(doc: Document, ctx: Context, diag: Diagnostic) -> list[Fix]:
    data = diag.data
    el = _element_at(doc, doc.model, diag.start)
    if not isinstance(data, MissingPorts) or el is None or not data.ports:
        return []
    given: list[str] = []
    for name in data.ports:
        if el.attr(name) is not None:
            return []  # typed since the diagnostic was made
        # A <SubTree> port as the key of its name, as _autoremap would pass it; any other
        # port is one without a default: its value is for the author to write.
        value = "{" + name + "}" if el.name == "SubTree" else ""
        given.append(f'{name}="{escape_value(value, chr(34))}"')
    at = _tag_end(el)
    edit = TextEdit(at, at, "".join(" " + g for g in given))
    code = (
        MISSING_REQUIRED_PORT
        if diag.code == MISSING_REQUIRED_PORT.code
        else (MISSING_PORT_WITHOUT_DEFAULT)
    )
    return [_fix(code, "add", (edit,), diag, ports=", ".join(given))]


def _tag_end(el: Element) -> int:
    """Where an attribute is added to ``el``'s start tag: after its last attribute."""
    end = el.name_end
    for a in el.attrs:
        if a.value is None:
            end = max(end, el.span_of_name(a)[1])
        else:
            end = max(end, el.token_start + a.value_end + (1 if a.quote else 0))
    return end


def _unknown_subtree(doc: Document, ctx: Context, diag: Diagnostic) -> list[Fix]:
    el = _element_at(doc, doc.model, diag.start)
    a = el.attr("ID") if el is not None and el.name == "SubTree" else None
    if el is None or a is None or not a.value or a.value in ctx.workspace_trees:
        return []  # defined in a file this one does not include: nothing to write
    tree_id = a.value
    fixes: list[Fix] = []
    near = _near_tree(ctx, tree_id)
    if near is not None:
        s, e = el.span_of_value(a)
        edit = TextEdit(s, e, escape_value(near, a.quote) if a.quote else near)
        fixes.append(_fix(UNKNOWN_SUBTREE, "rename", (edit,), diag, old=tree_id, new=near))
    new_tree = _new_tree(doc.text, doc.model, tree_id)
    if new_tree is not None:
        fixes.append(_fix(UNKNOWN_SUBTREE, "create", (new_tree,), diag, tree=tree_id))
    return fixes


def _near_tree(ctx: Context, tree_id: str) -> str | None:
    """The one tree whose ID is nearest ``tree_id``, a typo away (edit distance 1, or 2 from
    four characters on: a swap of two letters, ``Dokc``, is two edits)."""
    limit = 1 if len(tree_id) < 4 else 2
    best: list[tuple[int, str]] = []
    for known in dict.fromkeys((*ctx.trees, *ctx.workspace_trees)):
        if known == tree_id:
            continue
        d = edit_distance(tree_id, known, limit)
        if d <= limit:
            best.append((d, known))
    best.sort()
    if not best or (len(best) > 1 and best[1][0] == best[0][0]):
        return None
    return best[0][1]


def _new_tree(text: str, model: Model, tree_id: str) -> TextEdit | None:
    """A tree ``tree_id`` that loads and fails, as the last child of ``<root>``."""
    root = model.root
    if root is None or root.name != "root" or root.end_name_start < 0:
        return None
    nl = "\r\n" if "\r\n" in text else "\n"
    unit = _unit(text, model)
    lines = [
        f'<BehaviorTree ID="{escape_value(tree_id, chr(34))}">',
        f"{unit}<!-- TODO: write this tree; until then it fails when it runs -->",
        f"{unit}<AlwaysFailure/>",
        "</BehaviorTree>",
    ]
    return _insert_before_end_tag(text, root, lines, unit, nl)


# The fixes of each code that has some (their titles are defined with the code).
_FIXERS: Mapping[str, Callable[[Document, Context, Diagnostic], list[Fix]]] = MappingProxyType(
    {
        XML_UNESCAPED_CHAR.code: _escape,
        MISSING_FORMAT.code: _add_format,
        ID_ON_COMPACT_NODE.code: _remove_id_fix,
        UNKNOWN_ATTRIBUTE.code: _suggested_attribute,
        UNKNOWN_NODE.code: _unknown_node_fixes,
        MISSING_REQUIRED_PORT.code: _missing_ports,
        MISSING_PORT_WITHOUT_DEFAULT.code: _missing_ports,
        UNKNOWN_SUBTREE.code: _unknown_subtree,
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
    return [_fix(ID_ON_COMPACT_NODE, "remove", (TextEdit(start, end, ""),), diag, element=el.name)]


def _unknown_node(
    doc: Document, ctx: Context, model: Model, el: Element, diag: Diagnostic
) -> list[Fix]:
    data = diag.data
    if not isinstance(data, UnknownNodeData):
        return []
    type_id, explicit, new = data.type, data.explicit, data.rename
    fixes: list[Fix] = []
    if new is not None:
        edits = tuple(_rename_edits(el, explicit, new))
        fixes.append(_fix(UNKNOWN_NODE, data.fix, edits, diag, type=type_id, new=new))
    if (
        not explicit
        and (type_id in ctx.trees or type_id in ctx.workspace_trees)
        and el.self_closing
        and el.attr("ID") is None
    ):
        call = f'SubTree ID="{escape_value(type_id, chr(34))}"'
        edit = TextEdit(el.name_start, el.name_end, call)
        fixes.append(_fix(UNKNOWN_NODE, "subtree", (edit,), diag, type=type_id))
    declare = _declare(doc.text, model, el, type_id, explicit)
    if declare is not None:
        fixes.append(_fix(UNKNOWN_NODE, "declare", (declare,), diag, type=type_id))
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
