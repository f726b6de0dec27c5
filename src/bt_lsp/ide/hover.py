"""Hover text: why a name breaks a rule and what to write instead, what a name is, or where
a blackboard key is written and read.

Written as Markdown or as plain text (for clients that ask for it: no ``**``, no backticks,
no tables), and narrow either way: lists rather than wide tables, which a hover cuts off.

Text that is not Markdown (a rule's statement, a character of a name) is made to read the
same in every client that renders Markdown (:func:`markdown_safe`).  A backslash escape
does not: Neovim 0.7 hides a backslash before punctuation or a space, even inside a code
span, while Neovim 0.11 shows escapes as typed; and an unescaped ``*`` or ``_`` starts
emphasis in Neovim 0.7's Markdown syntax.  So the Markdown-special characters go into
code spans (which every client shows as typed), and a backslash is named.  A name whose
backslash Neovim 0.7 would hide in a code span is shown in a code block instead, which
every client shows as typed (:meth:`_Writer.title_naming`).
"""

from __future__ import annotations

import os
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from types import MappingProxyType

from bt_lsp.ide.blackboard import KeyForm, KeyRef, key_at, tree_keys
from bt_lsp.ide.name_edits import elsewhere
from bt_lsp.ide.name_fixes import preferred_renaming
from bt_lsp.ide.ports import builtins_in, ports_of
from bt_lsp.rules.builtins import PortModel
from bt_lsp.rules.builtins_v3 import V3_BUILTINS
from bt_lsp.rules.codes import NAMES, defined
from bt_lsp.rules.context import Context, source_label
from bt_lsp.rules.diagnostics import name_violations
from bt_lsp.rules.names import RULES, BadChar, Violation
from bt_lsp.rules.semantics.models import reserved_declaration_at
from bt_lsp.syntax.document import Document
from bt_lsp.syntax.elements import DECLARING_ROLES, NameRef, Role

_CPP_SUFFIXES = (".cpp", ".hpp", ".h", ".cc", ".cxx", ".hh", ".hxx", ".ipp")


@dataclass(frozen=True, slots=True)
class HoverText:
    """The hover's text over ``[start, end)``; Markdown when ``markdown``, else plain."""

    text: str
    start: int
    end: int
    markdown: bool = True


_KIND_TITLE = MappingProxyType(
    {"model": "Model name", "port": "Port name", "instance": "Instance name"}
)


def _visible(text: str) -> str:
    return "".join(c if c.isprintable() or c == " " else f"U+{ord(c):04X}" for c in text)


_INLINE_CODE_RE = re.compile(r"`+ ?([^`]*?) ?`+")
# A backslash that Neovim 0.7's Markdown syntax hides even in a code span: before anything
# but a letter or a digit (the closing backtick included).
_HIDDEN_IN_CODE_RE = re.compile(r"\\(?![A-Za-z0-9])")
# A word of plain text, and the characters that Markdown (CommonMark, Neovim 0.7's syntax)
# may read as markup in it.
_WORD_RE = re.compile(r"[^\s(),;]+")
_MARKUP = frozenset("\\`*_<>&[]|#~!")


def _safe_word(match: re.Match[str]) -> str:
    word = match.group()
    if word == "\\":
        return "backslash"
    if not _MARKUP.intersection(word):
        return word
    return f"`` {word} ``" if "`" in word else f"`{word}`"


def markdown_safe(text: str) -> str:
    """Plain ``text`` written so that a Markdown hover shows it as it is, in VS Code and
    in Neovim 0.7 and 0.11 alike: every word with a Markdown-special character in a code
    span, a lone backslash as the word ``backslash``."""
    return _WORD_RE.sub(_safe_word, text)


def file_link(shown: str, path: str | None) -> str:
    """A Markdown link to ``path`` at the line ``shown`` ends with (``…:42``), which
    VS Code and other clients open at that line (``file:///…#L42``)."""
    if path is None or not os.path.isabs(path):
        return shown
    line = shown.rpartition(":")[2]
    anchor = f"#L{line}" if line.isdigit() else ""
    label = shown.replace("[", "\\[").replace("]", "\\]")
    return f"[{label}]({file_uri(path)}{anchor})"


_URI_SAFE = frozenset(b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789-._~/")


def file_uri(path: str) -> str:
    """The ``file://`` URI of an absolute path, percent-encoded as RFC 8089 writes it
    (written out here because the core imports no file-system or URL module)."""
    drive, rest = os.path.splitdrive(path)
    if drive:  # Windows: file:///C:/...
        rest, drive = rest.replace("\\", "/"), "/" + drive
    raw = rest.encode("utf-8", "surrogateescape")
    return "file://" + drive + "".join(chr(b) if b in _URI_SAFE else f"%{b:02X}" for b in raw)


class _Writer:
    """Markup for one hover: inline code and a title in Markdown, quotes in plain text."""

    def __init__(self, markdown: bool) -> None:
        self.markdown = markdown
        self.lines: list[str] = []

    def code(self, text: str) -> str:
        shown = _visible(text)
        if not self.markdown:
            return f"'{shown}'"
        if "`" in shown:
            return f"`` {shown} ``"
        return f"`{shown}`"

    def plain(self, text: str) -> str:
        """Text that is not Markdown (a rule, a character's description), as the client
        shows it as written (see :func:`markdown_safe`)."""
        return markdown_safe(text) if self.markdown else text

    def char(self, c: BadChar) -> str:
        """An offending character: ``'.' (period)``; a backslash, which no Markdown
        client shows alike escaped or not, by its code point in Markdown."""
        if self.markdown and c.char == "\\":
            return "U+005C (backslash)"
        return self.plain(c.shown)

    def prose(self, text: str) -> str:
        """A description written in Markdown (built-in nodes, rules), as the client reads
        it: inline code becomes quotes in plain text."""
        if self.markdown:
            return text
        return _INLINE_CODE_RE.sub(r"'\1'", text).replace("**", "")

    def link(self, shown: str, path: str | None) -> str:
        """``shown`` (``src/nodes.cpp:42``) as a link to that line of the file at ``path``
        in Markdown, as it is in plain text."""
        return file_link(shown, path) if self.markdown else shown

    def title(self, text: str) -> None:
        self.lines.append(f"**{text}**" if self.markdown else text)

    def title_naming(self, before: str, name: str, after: str) -> None:
        """The title ``before NAME after``, the name in inline code; or, when inline
        code would not show the name as it is in every client (a backslash that Neovim
        0.7 hides), ``before after:`` with the name below in a code block."""
        shown = _visible(name)
        if not self.markdown or _HIDDEN_IN_CODE_RE.search(shown) is None:
            self.title(f"{before} {self.code(name)} {after}")
            return
        self.title(f"{before} {after}:")
        # A line with a backslash never closes the fence (nor Neovim 0.7's ```+ match).
        self.lines.extend(["```text", shown, "```"])

    def para(self, text: str) -> None:
        if self.lines:
            self.lines.append("")
        self.lines.append(text)

    def items(self, items: Sequence[str]) -> None:
        """A list: each item on its own line, as narrow as its text."""
        self.lines.extend(f"- {i}" for i in items)

    def text(self) -> str:
        return "\n".join(self.lines)


def _what(w: _Writer, ref: NameRef) -> str:
    sym = ref.symbol
    if ref.role == Role.INSTANCE or sym is None:
        return "Instance name (the node's label; it defaults to the node type)"
    if sym.kind == "port":
        kind = "tree" if sym.owner_kind == "tree" else "node type"
        what = "Port declaration" if ref.role == Role.PORT_DECL else "Port"
        return f"{what} {w.code(sym.name)} of the {kind} {w.code(sym.owner)}"
    name = w.code(sym.name)
    return {
        Role.TREE_DEF: f"Behavior tree {name}",
        Role.SUBTREE_CALL: f"SubTree call of the tree {name}",
        Role.MAIN_TREE: f"Main tree {name}",
        Role.MODEL_DEF: f"TreeNodesModel entry for {name}",
    }.get(ref.role, f"Node type {name}")


def _port_item(w: _Writer, p: PortModel) -> str:
    default = "no default" if p.default is None else f"default {w.code(p.default)}"
    item = f"{w.code(p.name)}: {p.direction}, {w.code(p.type or 'any type')}, {default}"
    desc = w.prose(" ".join(p.description.split()))
    return f"{item}; {desc}" if desc else item


def _ports(w: _Writer, ports: Sequence[PortModel]) -> None:
    if not ports:
        w.para("No ports.")
        return
    w.para("Ports:")
    w.items([_port_item(w, p) for p in ports])


def _node_info(w: _Writer, ref: NameRef, ctx: Context | None) -> None:
    """What BehaviorTree.CPP knows of a node type or tree: category, ports, description."""
    sym = ref.symbol
    if sym is None or sym.kind == "port":
        return
    builtins = builtins_in(ctx)
    if sym.kind == "model" and sym.name in builtins:
        b = builtins[sym.name]
        of = "BehaviorTree.CPP 3.8" if builtins is V3_BUILTINS else "BehaviorTree.CPP"
        w.para(f"Built-in {b.category} of {of}: {w.prose(b.description)}")
        _ports(w, b.ports)
        return
    if ctx is None:
        return
    decl = ctx.models.get(sym.name) if sym.kind == "model" else ctx.subtree_models.get(sym.name)
    if decl is None:
        return
    where = "this document" if ctx.is_own(decl) else (decl.path or "another document")
    if decl.where:  # learned from C++: where, relative to the workspace folder
        w.para(f"{decl.category} registered in {w.link(decl.where, decl.path)}.")
    elif where.endswith(_CPP_SUFFIXES):
        w.para(f"{decl.category} registered in the C++ of {where}.")
    else:
        w.para(f"{decl.category} declared in the TreeNodesModel of {where}.")
    w.para(f"Model from {source_label(decl.source)}.")
    _ports(w, decl.ports)


def _port_info(w: _Writer, ref: NameRef, ctx: Context | None) -> None:
    sym = ref.symbol
    if sym is None or sym.kind != "port":
        return
    port: PortModel | None = None
    owner = sym.owner
    builtins = builtins_in(ctx)
    if sym.owner_kind == "model" and owner in builtins:
        port = builtins[owner].port(sym.name)
    elif ctx is not None:
        decl = ctx.models.get(owner) if sym.owner_kind == "model" else ctx.subtree_models.get(owner)
        port = decl.port(sym.name) if decl is not None else None
    if port is None:
        return
    default = "no default" if port.default is None else f"default {w.code(port.default)}"
    w.para(f"{port.direction} port, type {w.code(port.type or 'any')}, {default}.")
    if port.description:
        w.para(w.prose(port.description))


def _where_defined(
    w: _Writer, ref: NameRef, ctx: Context | None, others: Mapping[str, Document]
) -> None:
    """Where a name with no declaration in this document comes from: another workspace
    file, or (said as a fact, not as an error) from outside the workspace."""
    sym = ref.symbol
    if sym is None or ref.role == Role.INSTANCE or sym.kind == "port":
        return
    if sym.kind == "model" and sym.name in builtins_in(ctx):
        return
    if sym.kind == "tree":
        found = ctx.workspace_trees.get(sym.name) if ctx is not None else None
        if not found and ctx is not None:
            found = ctx.trees.get(sym.name)
        if found:
            w.para(f"Defined in {found[0].path or 'another document'}.")
            return
        away = elsewhere(sym, [d.model for d in others.values()])
        if away is not None:
            w.para(
                "No file of the workspace defines this tree: it comes from elsewhere, "
                "such as an installed package."
            )
        return
    decl = ctx.models.get(sym.name) if ctx is not None else None
    if decl is None:
        w.para(
            "Registered in code: no TreeNodesModel entry in the workspace declares this node type."
        )


def _violations(doc: Document, ref: NameRef, ctx: Context | None) -> tuple[Violation, ...]:
    """The name rules ``ref`` breaks, as its diagnostics say: a declared port's reserved
    name as the project's BehaviorTree.CPP version makes it (a name-rule code only)."""
    found = name_violations(ref)
    if found:
        return found
    reserved = reserved_declaration_at(doc.model, ref, ctx)
    if reserved is None or defined(reserved.code).family != NAMES:
        return ()
    return (reserved,)


def _bad_name(
    w: _Writer,
    doc: Document,
    ref: NameRef,
    violations: tuple[Violation, ...],
    others: Mapping[str, Document],
    ctx: Context | None = None,
) -> None:
    assert ref.kind is not None
    title = _KIND_TITLE[str(ref.kind)]
    w.title_naming(title, ref.text, "breaks the BehaviorTree.CPP naming rules")
    w.lines.append("")
    w.items([f"{w.code(v.code)}: {w.plain(RULES.get(v.code, v.rule))}" for v in violations])
    chars = [c for v in violations for c in v.chars]
    if chars:
        w.para("Characters:")
        items = []
        for c in chars:
            line, col = doc.lines.position(_raw_offset(doc, ref, c.offset), "utf-32")
            items.append(
                f"column {c.column} (line {line + 1}, col {col + 1}): {w.char(c)}, "
                f"{w.plain(c.category)}: {w.plain(c.reason)}"
            )
        w.items(items)
    registered = ctx.models if ctx is not None else None
    fix = preferred_renaming(doc, ref, others, registered)
    if fix is None:
        away = elsewhere(ref.symbol, [doc.model, *(d.model for d in others.values())], registered)
        if away is not None and away.refuse:
            w.para(f"No quick fix renames it: {away.why}.")
        return
    if fix.caution is not None:
        w.para(f"A quick fix can rename it to {w.code(fix.new)} ({fix.where}), but {fix.caution}.")
    else:
        w.para(f"Suggested replacement: {w.code(fix.new)} (the quick fix renames {fix.where})")
    if fix.kept is not None:
        w.para(f"The quick fix leaves the {fix.kept} as it is: {fix.why}")


def _key_hover(w: _Writer, doc: Document, key: KeyRef, ctx: Context | None) -> None:
    """A blackboard key: the nodes of its tree that write it, read it, or use it in a
    script, with the types of their ports."""
    model = doc.model
    tree_id = model.elements[key.tree].value("ID") or ""
    w.title(f"Blackboard key {w.code(key.key)} of the tree {w.code(tree_id)}")
    written: list[str] = []
    read: list[str] = []
    scripts: list[str] = []
    types: list[str] = []
    for u in tree_keys(doc, key.tree, key.key).uses:
        el = model.elements[u.element]
        line = doc.lines.position(u.start, "utf-32")[0] + 1
        node = el.node_id or el.name
        if u.form == KeyForm.SCRIPT:
            scripts.append(f"{w.code(node)} {w.code(u.attr)} (line {line})")
            continue
        ports = ports_of(el, ctx)
        port = next((p for p in ports or () if p.name == u.attr), None)
        where = f"{w.code(node)} port {w.code(u.attr)} (line {line})"
        if port is None:
            # An unknown model: which way the value flows is not known here.
            read.append(f"{where}, direction unknown")
            continue
        where += f", {w.code(port.type or 'any type')}"
        if port.type and port.type not in types:
            types.append(port.type)
        if port.direction in ("output", "inout"):
            written.append(where)
        if port.direction in ("input", "inout"):
            read.append(where)
    for label, found in (("Written by", written), ("Read by", read), ("In scripts", scripts)):
        if found:
            w.para(f"{label}:")
            w.items(found)
    if types:
        w.para(f"Port types: {', '.join(w.code(t) for t in types)}")


def hover_at(
    doc: Document,
    offset: int,
    ctx: Context | None = None,
    others: Mapping[str, Document] | None = None,
    *,
    markdown: bool = True,
) -> HoverText | None:
    """The hover at ``offset``; ``others`` are the other workspace documents (the quick
    fix's count of places includes theirs), ``markdown`` chooses Markdown or plain text."""
    others = others or {}
    w = _Writer(markdown)
    model = doc.model
    ref = model.ref_at(offset)
    if ref is None:
        key = key_at(doc, offset)
        if key is None or key.tree < 0:
            return None
        _key_hover(w, doc, key, ctx)
        return HoverText(w.text(), key.start, key.end, markdown)
    violations = _violations(doc, ref, ctx)
    if violations:
        _bad_name(w, doc, ref, violations, others, ctx)
    else:
        w.title(_what(w, ref))
        decl = (
            model.declarations_of(ref.symbol)
            if ref.symbol is not None
            else [ref] * (ref.role in DECLARING_ROLES)
        )
        if decl:
            line = doc.lines.position(decl[0].start, "utf-32")[0] + 1
            w.para(f"Declared at line {line} ({decl[0].role}).")
        else:
            _where_defined(w, ref, ctx, others)
        _node_info(w, ref, ctx)
        _port_info(w, ref, ctx)
    return HoverText(w.text(), ref.start, ref.end, markdown)


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


def root_hover(
    doc: Document,
    offset: int,
    version: str | None,
    source: str,
    markdown: bool = True,
    unclear: bool = False,
) -> HoverText | None:
    """On the ``root`` of ``<root>``: the BehaviorTree.CPP version the document is checked
    against and where that was read (``source``), so that a wrong guess is visible;
    ``unclear``: the project's build names both versions (``source`` says where)."""
    root = doc.model.root
    if root is None or root.name != "root" or not root.name_start <= offset <= root.name_end:
        return None
    if version is None and unclear:
        lines = [
            "**BehaviorTree.CPP version: unclear**",
            "",
            f"The build names both versions: {source}.",
            "",
            "Checked as BehaviorTree.CPP 4, with what depends on the version a warning at "
            "most. Set `btcpp` in `bt-lsp.toml` to say which version the project builds "
            "against.",
        ]
    elif version is None:
        lines = [
            "**BehaviorTree.CPP version: not detected**",
            "",
            "Checked as BehaviorTree.CPP 4. Set `btcpp` in `bt-lsp.toml` (or the package's "
            "`package.xml` dependency) to say which version the project builds against.",
        ]
    else:
        lines = [f"**BehaviorTree.CPP {version}**", "", f"From {source}."]
    text = "\n".join(lines)
    if not markdown:
        text = text.replace("**", "").replace("`", "")
    return HoverText(text, root.name_start, root.name_end, markdown)
