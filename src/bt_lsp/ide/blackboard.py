"""Blackboard keys: where each tree of a document uses a key.

BehaviorTree.CPP gives every tree instance a blackboard of its own, so a key belongs to a
tree.  A tree uses a key

* as a port value that is a blackboard reference: ``goal="{key}"`` (spaces around the
  braces are trimmed, those inside are part of the key: ``{ key }`` is the key
  ``" key "``, another entry than ``key``), ``goal="{=}"`` or ``goal="="`` (the key named
  like the port), exactly when BehaviorTree.CPP's ``getRemappedKey`` reads the whole value
  as one (``"Hello {name}"`` is a literal text, not a key);
* as an identifier in a script: the pre- and post-condition attributes (``_skipIf`` …
  ``_post``) of any node, ``code`` of ``<Script>`` and ``<ScriptCondition>`` and ``if`` of
  ``<Precondition>`` (unless the value is itself a blackboard reference).  Identifiers
  are found with the script tokenizer of :mod:`bt_lsp.rules.script`: never inside a string, and
  ``true``/``false`` are literals.  Enum names are identifiers too (they are registered
  in C++), so an identifier spelled like a key is taken for that key.

Port values count in attributes whose names break the port naming rules (``goal.x="{g}"``):
those are errors that the name fixes correct, and the key is the tree's once they do.
Reserved attributes, the underscore attributes BehaviorTree.CPP ignores (``_x``) and valid
names it cannot read as ports (starting with a non-ASCII letter) are never ports.

Every use has the span of the key as written in the file: values are decoded (entity
references replaced) before they are read, and spans are mapped back through the
references, so ``&amp;&amp;`` before a key does not shift it.  A key whose own characters
are written with references (``{go&#97;l}``) is flagged ``entities``.
"""

from __future__ import annotations

import re
from bisect import bisect_right
from collections.abc import Sequence
from dataclasses import dataclass, field
from enum import StrEnum
from functools import lru_cache

from bt_lsp.rules.builtins import BUILTINS
from bt_lsp.rules.conversions import is_blackboard_reference
from bt_lsp.rules.names import NameKind, check_name, is_allowed_port_name
from bt_lsp.rules.script import CONDITION_ATTRS, SCRIPT_PORTS, identifier_spans, identifiers
from bt_lsp.syntax.document import Document
from bt_lsp.syntax.elements import Element, Zone
from bt_lsp.syntax.model import Model
from bt_lsp.syntax.tokens import Attr
from bt_lsp.syntax.values import raw_offsets

__all__ = [
    "KeyForm",
    "KeyRef",
    "TreeKeys",
    "blackboard_keys",
    "enclosing_tree",
    "key_at",
    "key_names",
    "key_uses",
    "mentions",
    "port_value_key",
    "subtree_range",
    "tree_keys",
    "unread_mentions",
]


class KeyForm(StrEnum):
    """How a key is written."""

    BRACES = "braces"  # goal="{key}"
    SAME = "same"  # goal="{=}": the key named like the port; the span is the '='
    BARE_SAME = "bare"  # goal="=": likewise, without braces
    SCRIPT = "script"  # an identifier of a script


@dataclass(frozen=True, slots=True)
class KeyRef:
    """A use of a blackboard key: ``start``/``end`` span the key as written (between the
    braces, spaces inside them included; the ``=`` of ``{=}``), ``element`` is the element
    index of its node and ``tree`` of its ``<BehaviorTree>``.  ``attr`` is the attribute
    it is written in, ``quote`` that attribute's quote, ``entities`` whether the key's own
    characters are written with entity or character references."""

    key: str
    start: int
    end: int
    element: int
    tree: int
    form: KeyForm = KeyForm.BRACES
    attr: str = ""
    quote: str = '"'
    entities: bool = False


@dataclass(frozen=True, slots=True)
class TreeKeys:
    """The key uses of one tree, and the script texts it could not read: ``unread`` holds,
    for each script with a lexical error, the decoded text after the error (BehaviorTree.CPP
    rejects the script there, and which of its words are keys is unknown)."""

    uses: list[KeyRef] = field(default_factory=list)
    unread: list[str] = field(default_factory=list)

    def of(self, key: str) -> list[KeyRef]:
        return [k for k in self.uses if k.key == key]


def enclosing_tree(model: Model, index: int) -> int:
    """Index of the ``<BehaviorTree>`` holding element ``index`` (itself included), or -1."""
    els = model.elements
    while index >= 0:
        if els[index].zone == Zone.TREE:
            return index
        index = els[index].parent
    return -1


def subtree_range(model: Model, index: int) -> range:
    """Indexes of element ``index`` and its descendants (elements are in document order)."""
    els = model.elements
    depth = els[index].depth
    stop = index + 1
    while stop < len(els) and els[stop].depth > depth:
        stop += 1
    return range(index, stop)


class _Value:
    """An attribute value: decoded, and how its code points map to the raw text."""

    __slots__ = ("base", "decoded", "offs")

    def __init__(self, doc: Document, el: Element, a: Attr) -> None:
        vs, ve = el.span_of_value(a)
        raw = doc.text[vs:ve]
        self.base = vs
        self.decoded = a.value if a.value is not None else raw
        self.offs = raw_offsets(raw) if "&" in raw else None

    def span(self, start: int, end: int) -> tuple[int, int, bool]:
        """The absolute raw span of ``decoded[start:end]``, and whether references are
        written in it."""
        if self.offs is None:
            return self.base + start, self.base + end, False
        last = len(self.offs) - 1
        rs, re_ = self.offs[min(start, last)], self.offs[min(end, last)]
        return self.base + rs, self.base + re_, (re_ - rs) != (end - start)


def _is_script_port(el: Element, a: Attr) -> bool:
    """``code`` of ``Script``/``ScriptCondition``, ``if`` of ``Precondition``."""
    node_id = el.node_id
    return node_id is not None and node_id in BUILTINS and (node_id, a.name) in SCRIPT_PORTS


def _port_key(
    doc: Document, el: Element, a: Attr, idx: int, tree: int, value: str
) -> KeyRef | None:
    """The key of a port value that is a blackboard reference, as ``getRemappedKey``
    reads it: ``=`` and ``{=}`` name the port's own key; else the key is all that is
    between the braces, spaces included (only those outside the braces are trimmed)."""
    v = _Value(doc, el, a)
    if value == "=":
        s, e, _ = v.span(0, 1)
        return KeyRef(a.name, s, e, idx, tree, KeyForm.BARE_SAME, a.name, a.quote)
    if value == "{=}":
        s, e, _ = v.span(1, 2)
        return KeyRef(a.name, s, e, idx, tree, KeyForm.SAME, a.name, a.quote)
    lead = len(value) - len(value.lstrip(" "))
    key = value.strip(" ")[1:-1]
    if not key:
        return None
    s, e, ent = v.span(lead + 1, lead + 1 + len(key))
    return KeyRef(key, s, e, idx, tree, KeyForm.BRACES, a.name, a.quote, ent)


_SCRIPT = KeyForm.SCRIPT  # (an enum member read from the class costs a lookup per key)


_ASCII_WORD = frozenset("ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789_")


def _word_at(code: str, at: int) -> str:
    """The word of an ASCII script that ends or starts at or holds ``at`` (the one before
    it when two touch it): the only identifier there can be the key under ``at``."""
    start = at
    while start > 0 and code[start - 1] in _ASCII_WORD:
        start -= 1
    if start > 0 and code[start - 1] == "@":
        start -= 1
    end = at
    if start == at and code[at : at + 1] == "@":
        end += 1
    while end < len(code) and code[end] in _ASCII_WORD:
        end += 1
    return code[start:end]


def _script_keys(
    doc: Document,
    el: Element,
    a: Attr,
    idx: int,
    tree: int,
    out: TreeKeys,
    at: int = -1,
    only: str | None = None,
) -> None:
    """The keys of a script attribute; with ``at``, only those whose span holds it; with
    ``only``, only that key (found without a span per identifier of the script)."""
    v = _Value(doc, el, a)
    code = v.decoded
    if at >= 0 and v.offs is None and only is None and code.isascii():
        local = at - v.base
        word = _word_at(code, local) if 0 <= local <= len(code) else ""
        if not word:
            return  # no key of this script is under ``at``
        only = word
    spans: Sequence[tuple[int, int]]
    spans, stop = identifiers(code) if only is None else identifier_spans(code, only)
    uses = out.uses
    name, quote = a.name, a.quote
    if v.offs is None:  # no references: decoded offsets are the text's, from the value's
        base = v.base
        if at >= 0:
            spans = [(ds, de) for ds, de in spans if ds <= at - base <= de]
        for ds, de in spans:
            uses.append(KeyRef(code[ds:de], base + ds, base + de, idx, tree, _SCRIPT, name, quote))
    else:
        for ds, de in spans:
            s, e, ent = v.span(ds, de)
            if at < 0 or s <= at <= e:
                uses.append(KeyRef(code[ds:de], s, e, idx, tree, _SCRIPT, name, quote, ent))
    if stop < len(code):
        out.unread.append(code[stop:])


def _is_port(name: str) -> bool:
    """Whether a node attribute gives a port: an allowed port name, or a port name that
    breaks the naming rules (an error to fix, after which its value is the port's)."""
    if is_allowed_port_name(name):
        return True
    return not name.startswith("_") and bool(check_name(name, NameKind.PORT))


def _element_keys(
    doc: Document, idx: int, tree: int, out: TreeKeys, at: int = -1, only: str | None = None
) -> None:
    """The key uses of node ``idx``; with ``at``, of its scripts only those holding it;
    with ``only``, those of that key (and the unread script texts that may hold it)."""
    el = doc.model.elements[idx]
    if el.zone != Zone.NODE:
        return
    for a in el.attrs:
        value = a.value
        if value is None or (only is not None and only not in value and only != a.name):
            continue  # (``{=}`` is the key named like its port)
        _element_attr_keys(doc, el, a, idx, tree, out, at, only)


def _element_attr_keys(
    doc: Document,
    el: Element,
    a: Attr,
    idx: int,
    tree: int,
    out: TreeKeys,
    at: int = -1,
    only: str | None = None,
) -> None:
    """The key uses of one attribute (with a value) of node ``idx``: see :func:`_element_keys`."""
    value = a.value
    if value is None:
        return
    if a.name in CONDITION_ATTRS:
        _script_keys(doc, el, a, idx, tree, out, at, only)
    elif not _is_port(a.name):
        return  # ID, name, _autoremap, and attributes BehaviorTree.CPP ignores
    elif is_blackboard_reference(value):
        k = _port_key(doc, el, a, idx, tree, value)
        if k is not None and (only is None or k.key == only):
            out.uses.append(k)
    elif _is_script_port(el, a):
        _script_keys(doc, el, a, idx, tree, out, at, only)


def port_value_key(doc: Document, idx: int, a: Attr) -> KeyRef | None:
    """The key a port attribute of node ``idx`` is given (``{key}``, ``{=}``, ``=``), or
    ``None`` when its value is not a blackboard reference."""
    el = doc.model.elements[idx]
    value = a.value
    if el.zone != Zone.NODE or value is None or not is_blackboard_reference(value):
        return None
    return _port_key(doc, el, a, idx, enclosing_tree(doc.model, idx), value)


def tree_keys(doc: Document, tree: int, key: str | None = None) -> TreeKeys:
    """Every key use in the nodes of one tree (by element index), in document order; with
    ``key``, the uses of that key only, and only the unread script texts that hold it as
    a word (what a request about one key needs: a script of 200,000 statements has
    200,000 uses)."""
    model = doc.model
    out = TreeKeys()
    if not 0 <= tree < len(model.elements) or model.elements[tree].zone != Zone.TREE:
        return out
    for i in subtree_range(model, tree):
        _element_keys(doc, i, tree, out, only=key)
    return out


def key_names(doc: Document, tree: int, skip_at: int = -1) -> dict[str, KeyForm]:
    """The keys one tree uses, each with the form of its first use, leaving out a use whose
    span holds ``skip_at`` (the key being typed): what a completion lists.  The names of
    a script are read from its text alone and remembered for it, without a use per
    identifier (a script of 200,000 statements has 200,000 uses, and a completion is
    asked at every keystroke)."""
    model = doc.model
    out: dict[str, KeyForm] = {}
    if not 0 <= tree < len(model.elements) or model.elements[tree].zone != Zone.TREE:
        return out
    for i in subtree_range(model, tree):
        el = model.elements[i]
        if el.zone != Zone.NODE:
            continue
        for a in el.attrs:
            value = a.value
            if value is None:
                continue
            if a.name in CONDITION_ATTRS:
                script = True
            elif not _is_port(a.name):
                continue
            elif is_blackboard_reference(value):
                script = False
            elif _is_script_port(el, a):
                script = True
            else:
                continue
            vs, ve = el.span_of_value(a)
            if script and not vs <= skip_at <= ve:
                for name in _script_names(value):  # (names are the decoded text's)
                    out.setdefault(name, _SCRIPT)
                continue
            found = TreeKeys()
            _element_attr_keys(doc, el, a, i, tree, found)
            for k in found.uses:
                if not k.start <= skip_at <= k.end:
                    out.setdefault(k.key, k.form)
    return out


@lru_cache(maxsize=64)
def _script_names(code: str) -> tuple[str, ...]:
    """The distinct identifiers of a script, in order of first use."""
    spans, _ = identifiers(code)
    return tuple(dict.fromkeys([code[s:e] for s, e in spans]))


def key_uses(doc: Document, tree: int) -> list[KeyRef]:
    """Every key use in the nodes of one tree (by element index): port values and scripts."""
    return tree_keys(doc, tree).uses


def blackboard_keys(doc: Document, tree: int) -> list[KeyRef]:
    """Every key written ``{key}`` in the port values of the nodes of one tree."""
    return [k for k in key_uses(doc, tree) if k.form == KeyForm.BRACES]


def key_at(doc: Document, offset: int) -> KeyRef | None:
    """The key use under ``offset`` (its end counts), in a port value or a script."""
    model = doc.model
    els = model.elements
    # Start tags do not overlap: the one holding ``offset`` is the last to start before it.
    i = bisect_right(els, offset, key=_token_start) - 1
    if i < 0:
        return None
    el = els[i]
    if el.zone != Zone.NODE or el.token_start + doc.scan.tokens[el.token_index].length < offset:
        return None
    out = TreeKeys()
    _element_keys(doc, i, enclosing_tree(model, i), out, offset)
    for k in out.uses:
        if k.start <= offset <= k.end:
            return k
    return None


def _token_start(el: Element) -> int:
    return el.token_start


_WORD_CHARS = "A-Za-z0-9_"


def unread_mentions(keys: TreeKeys, key: str) -> bool:
    """Whether ``key`` is written as a word in a script text the tree could not read."""
    if not keys.unread:
        return False
    word = re.compile(rf"(?<![{_WORD_CHARS}@]){re.escape(key)}(?![{_WORD_CHARS}])")
    return any(word.search(text) for text in keys.unread)


def mentions(keys: TreeKeys, key: str) -> bool:
    """Whether a tree uses ``key``, or may use it in a script it could not read."""
    return any(k.key == key for k in keys.uses) or unread_mentions(keys, key)
