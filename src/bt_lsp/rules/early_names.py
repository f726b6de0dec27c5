"""The name diagnostics of a well-formed document, found before its full analysis.

A first analysis of a megabyte of BT XML takes a few hundred milliseconds: the scanner
reads every token with exact positions, the model and the rules visit every element in
Python.  lxml's C parser reads the same bytes twenty times faster.  Whether an element
breaks a name rule needs neither positions nor a model, only its tag, its attributes and
where it sits, which lxml's parse gives in document order.  So this pass checks the names
of every element as lxml reads them (the checks are cached by text), and places only the
elements with a suspect name: their start tags are found by counting start tags, scanned by
the real scanner and named by the model's own code
(:func:`bt_lsp.syntax.nametokens.start_tag_refs`).
Every diagnostic found is therefore one the full analysis makes too, with the same range,
code and message; the server publishes them first and the complete set when it is ready.

The pass gives up (``None``) on what it does not follow exactly: text lxml rejects, cannot
take or warns about, a DOCTYPE, XML namespaces, a stretch of 256 Ki characters without a
``>`` (a start tag that long).  Such a document waits for the full analysis.
Parsing reads nothing but the text: no DTD, no entities, no network.
"""

from __future__ import annotations

import re
from bisect import bisect_left, bisect_right
from itertools import accumulate, islice
from typing import cast

from lxml import etree

from bt_lsp.rules.diagnostics import (
    MAX_DIAGNOSTICS,
    Diagnostic,
    NameMemo,
    ref_diagnostics,
    violations,
)
from bt_lsp.rules.names import (
    RESERVED_PORT_NAMES,
    NameKind,
    all_valid_port_uses,
    instance_rule_breaks,
    may_hold_bad_instance_name,
)
from bt_lsp.syntax.elements import EXPLICIT_TAGS, Element, Role, Zone, zone_in
from bt_lsp.syntax.nametokens import start_tag_element, start_tag_refs
from bt_lsp.syntax.tag_limits import MAX_ATTRS

__all__ = ["early_name_diagnostics"]

_MODEL, _PORT = NameKind.MODEL, NameKind.PORT
_NODE, _TREE, _ENTRY, _PORT_DECL = Zone.NODE, Zone.TREE, Zone.MODEL_ENTRY, Zone.PORT_DECL
# A tag that names its node type by its ID attribute rather than by itself.
_BY_ID = EXPLICIT_TAGS | {"SubTree"}


class _Reader:
    """An lxml parser target: follows each element's zone and notes those with a name
    that breaks a rule (a superset of what the model reports: the model decides).

    It runs once per element of the document, so the usual element (a node of a known
    type with known attributes) costs a few set lookups: the instance names are only
    collected, and checked together at the end (:meth:`bad_instances`)."""

    __slots__ = (
        "count",
        "good_keys",
        "good_models",
        "instances",
        "memo",
        "named",
        "names",
        "stack",
        "suspects",
    )

    def __init__(self, instances: bool) -> None:
        self.instances = instances  # whether instance names can break their rule here
        self.count = 0
        self.stack: list[tuple[int, Zone]] = []  # the open elements: index and zone
        self.suspects: list[tuple[int, Zone, int]] = []  # index, zone, parent's index
        # Texts seen to break no rule as a node type (or ID), or as an attribute of a
        # node (a valid port name, or a reserved attribute, which is not a port).
        self.good_models: set[str] = set(_BY_ID)
        self.good_keys: set[str] = set(RESERVED_PORT_NAMES)
        self.memo = NameMemo()  # what the name rules found, for this pass
        # The instance names of the nodes (with ``instances``) and the elements holding
        # them, index for index.
        self.names: list[str] = []
        self.named: list[int] = []

    def start(self, tag: str, attrib: dict[str, str]) -> None:
        index = self.count
        self.count = index + 1
        stack = self.stack
        if stack:
            parent, pz = stack[-1]
            zone = _NODE if pz is _NODE or pz is _TREE else zone_in(tag, pz)
        else:
            parent, zone = -1, Zone.ROOT
        stack.append((index, zone))
        if zone is _NODE:
            if not attrib:  # many nodes of a large document: a known type alone
                if tag not in self.good_models:
                    self._node_type(tag, index, parent)
                return
            good_models = self.good_models
            if tag not in good_models and self._node_type(tag, index, parent):
                return
            if not self.good_keys.issuperset(attrib) and self._node_keys(attrib, index, parent):
                return  # (most tags have known attributes only: no set is made)
            value = attrib.get("ID")
            if value is not None and value not in good_models:
                if violations(value, _MODEL, Role.NODE_ID, self.memo):
                    self.suspects.append((index, zone, parent))
                    return
                good_models.add(value)
            if self.instances:
                value = attrib.get("name")
                if value is not None:
                    self.names.append(value)
                    self.named.append(index)
            return
        if zone is _TREE or zone is _ENTRY:
            value = attrib.get("ID")
            role = Role.TREE_DEF if zone is _TREE else Role.MODEL_DEF
            suspect = value is not None and bool(violations(value, _MODEL, role, self.memo))
        elif zone is _PORT_DECL:
            value = attrib.get("name")
            suspect = value is not None and bool(
                violations(value, _PORT, Role.PORT_DECL, self.memo)
            )
        else:
            suspect = False
        if suspect:
            self.suspects.append((index, zone, parent))

    def _node_type(self, tag: str, index: int, parent: int) -> bool:
        """Whether node type ``tag`` (new to the pass) breaks a rule: the node is noted
        as a suspect if so, the type as good if not."""
        if violations(tag, _MODEL, Role.NODE_TYPE, self.memo):
            self.suspects.append((index, _NODE, parent))
            return True
        self.good_models.add(tag)
        return False

    def _node_keys(self, attrib: dict[str, str], index: int, parent: int) -> bool:
        """Whether an attribute name of a node, among those new to the pass, breaks the
        port rule (the model keeps a tag's first MAX_ATTRS attributes; the rest are only
        counted): as :meth:`_node_type`."""
        keys = attrib.keys() if len(attrib) <= MAX_ATTRS else islice(attrib, MAX_ATTRS)
        new_keys = set(keys) - self.good_keys
        if new_keys:
            if not all_valid_port_uses(new_keys):
                self.suspects.append((index, _NODE, parent))
                return True
            self.good_keys |= new_keys
        return False

    def end(self, tag: str) -> None:
        self.stack.pop()

    def close(self) -> None:
        return None

    def bad_instances(self) -> list[int]:
        """The nodes whose instance name breaks its rule, found in one search of all the
        names, joined by line feeds (which the rule allows)."""
        names = self.names
        found = list(instance_rule_breaks("\n".join(names)))
        if not found:
            return []
        ends = list(accumulate(len(n) + 1 for n in names))  # where each name's "\n" ends
        named = self.named
        return list(dict.fromkeys(named[bisect_right(ends, at)] for at in found))


# In well-formed XML without a DOCTYPE, every '<' starts a tag, a comment, a CDATA section
# or a processing instruction, except within the last three.
_START_TAG = re.compile(r"<[^/!?]")
_SKIPPED = re.compile(r"<!--.*?-->|<!\[CDATA\[.*?\]\]>|<\?.*?\?>", re.S)
_MATCH_START = re.Match.start


def _start_tags(text: str) -> list[int]:
    """The offsets of the start tags of a well-formed ``text``, in document order: those
    of the pattern but the ones inside a comment, CDATA section or processing
    instruction, cut out of the list in slices (a list of thousands, few cuts)."""
    starts = list(map(_MATCH_START, _START_TAG.finditer(text)))
    kept: list[int] = []
    at = 0  # the first start not yet kept or dropped
    for m in _SKIPPED.finditer(text):
        begin, end = m.span()
        inside = bisect_left(starts, begin, at)
        kept += starts[at:inside]
        at = bisect_left(starts, end, inside)
    if not at:
        return starts
    kept += starts[at:]
    return kept


_PIECE = 1 << 16
# lxml reads a tag (a comment, ...) in one call once it has all of it, holding the
# interpreter meanwhile: 0.8 s for one start tag of 700,000 attributes, when the pass
# runs beside the event loop.  It gives up on a text with no ">" in this many characters.
_MAX_RUN = 1 << 18


def early_name_diagnostics(text: str) -> list[Diagnostic] | None:
    """The name-rule diagnostics of ``text``, or ``None`` when the pass cannot vouch for
    them (see the module docstring)."""
    if "<!DOCTYPE" in text or "xmlns" in text:
        return None
    reader = _Reader(may_hold_bad_instance_name(text))
    parser = etree.XMLParser(
        # lxml calls only the methods a target has: none for text or comments.
        target=cast("etree.ParserTarget", reader),
        encoding="utf-8",
        resolve_entities=False,
        no_network=True,
        load_dtd=False,
        huge_tree=True,
    )
    try:
        # Fed in pieces: a copy of the whole text would be memory the allocator keeps.
        since_end = 0  # characters since the last ">"
        for i in range(0, len(text), _PIECE):
            piece = text[i : i + _PIECE]
            last = piece.rfind(">")
            if last < 0:
                since_end += len(piece)
            elif since_end + piece.find(">") > _MAX_RUN:
                return None
            else:
                since_end = len(piece) - last - 1
            if since_end > _MAX_RUN:
                return None
            parser.feed(piece.encode("utf-8"))
        parser.close()
    except (etree.XMLSyntaxError, UnicodeEncodeError, ValueError):  # lone surrogates too
        return None
    if len(parser.feed_error_log):  # e.g. an undeclared namespace prefix, which lxml drops
        return None
    suspects = reader.suspects
    bad_instances = reader.bad_instances()
    if bad_instances:
        suspects.extend((index, _NODE, -1) for index in bad_instances)
        suspects.sort()
    if len(suspects) >= MAX_DIAGNOSTICS:
        return None  # the complete set may leave some out (``limited``)
    if not suspects:
        return []
    offsets = _start_tags(text)
    if len(offsets) != reader.count:  # not a text this pass follows
        return None
    out: list[Diagnostic] = []
    for index, zone, parent_index in suspects:
        parent: Element | None = None
        if zone == _PORT_DECL:
            parent = start_tag_element(text, offsets[parent_index], _ENTRY)
        out.extend(ref_diagnostics(start_tag_refs(text, offsets[index], zone, parent), reader.memo))
    out.sort(key=lambda d: (d.start, d.end, d.code))
    return out
