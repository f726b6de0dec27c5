"""Small walks over a tree-sitter C++ syntax tree (up to an ancestor, into a declarator,
to the call a name is the function of), shared by the readers of :mod:`bt_lsp.cpp.extract`."""

from __future__ import annotations

import tree_sitter

from bt_lsp.cpp.names import split_top, squash

Node = tree_sitter.Node


def up(n: Node | None, steps: int) -> Node | None:
    """``n``'s parent ``steps`` times at most, stopping at a preprocessor definition."""
    for _ in range(steps):
        if n is None or n.type in ("preproc_def", "preproc_function_def"):
            return n
        n = n.parent
    return n


def up_to(n: Node | None, types: tuple[str, ...], steps: int) -> Node | None:
    for _ in range(steps):
        if n is None or n.type in types:
            return n
        n = n.parent
    return n if n is not None and n.type in types else None


def enclosing_call(ident: Node) -> Node | None:
    """The call whose function ``ident`` names (through templates, fields, scopes)."""
    n = ident
    for _ in range(4):
        p = n.parent
        if p is None:
            return None
        if p.type == "call_expression":
            return p if p.child_by_field_name("function") == n else None
        if p.type not in (
            "template_method",
            "template_function",
            "field_expression",
            "qualified_identifier",
        ):
            return None
        n = p
    return None


def template_args(fn: Node | None) -> list[str]:
    """The template arguments of a called function, as written (squashed)."""
    if fn is None:
        return []
    stack = [fn]
    while stack:
        n = stack.pop()
        if n.type == "template_argument_list":
            src = n.text or b""
            inner = src.decode("utf-8", "replace")[1:-1]
            return [squash(a) for a in split_top(inner)]
        stack.extend(reversed(n.named_children))
    return []


def declared_name(d: Node) -> Node | None:
    """The identifier a declarator declares (through pointers, arrays, references)."""
    n: Node | None = d
    while n is not None and n.type not in ("identifier", "field_identifier"):
        inner = n.child_by_field_name("declarator")
        if inner is None:
            named = [c for c in n.named_children if c.type in ("identifier", "field_identifier")]
            return named[0] if named else None
        n = inner
    return n
