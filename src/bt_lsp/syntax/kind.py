"""Whether an XML text is a BehaviorTree.CPP document, from its own content.

One decision for the whole tool: the command line's folder walk, the workspace's files
and the editor's open documents all ask :func:`looks_like_bt`, so a file is BT XML (and
diagnosed) everywhere or nowhere.  Only the head of the text is looked at
(:data:`HEAD_CHARS`), so that the answer is cheap for a large file and the same whether
the text was read whole or sniffed from the first bytes of a file.

A text is BT XML when its head holds

* a ``<BehaviorTree>`` or ``<TreeNodesModel>`` element, or a ``BTCPP_format`` attribute
  (anywhere: a file whose top element is a misspelt ``<roo>`` or ``<Root>`` but which
  holds trees still tries to be BT, and its ``root-element`` error is useful), or
* a top element ``<root>`` with an ``<include>`` or a ``main_tree_to_execute`` attribute
  (a file that only includes others).

Other XML (``package.xml``, launch files, URDF, an IDE's project files, a server's
``server.xml``, a generic ``<root>`` of another tool) is not, and neither is a fragment
with no tree (a template's ``<Sequence>`` that a program pastes into a tree).  Files
included from a BT file are BT XML too, but that is a fact of the workspace, not of the
text (see the project layer).
"""

from __future__ import annotations

import re
from typing import Final

__all__ = [
    "HEAD_CHARS",
    "bt_evidence_end",
    "looks_like_bt",
    "not_xml",
    "top_element",
    "top_element_span",
]

# How many characters of a text the decision looks at; a file is sniffed from its first
# 4 * HEAD_CHARS bytes (at most 4 bytes a character in every encoding XML uses).
HEAD_CHARS: Final = 64 * 1024

# Before the top element: an XML declaration, processing instructions, comments, a
# DOCTYPE (with or without an internal subset), white space.
_TOP: Final = re.compile(
    r"(?:\s+|<\?.*?\?>|<!--.*?-->|<!DOCTYPE[^>\[]*(?:\[.*?\])?\s*>)*<([^\s/>!?]+)",
    re.DOTALL,
)
_MARKER: Final = re.compile(r"<(?:BehaviorTree|TreeNodesModel)[\s/>]|\bBTCPP_format\s*=")
_ROOT_ONLY: Final = re.compile(r"<include[\s/>]|\bmain_tree_to_execute\s*=")


def top_element_span(text: str, end: int | None = None) -> tuple[str, int] | None:
    """The name of the first element of ``text[:end]`` and where the name ends."""
    start = 1 if text.startswith("\ufeff") else 0
    m = _TOP.match(text, start, len(text) if end is None else end)
    return (m.group(1), m.end()) if m is not None else None


def top_element(text: str) -> str | None:
    """The name of the first element of an XML text (``None`` if there is none in it)."""
    found = top_element_span(text)
    return found[0] if found is not None else None


def bt_evidence_end(text: str) -> int:
    """Where the evidence that ``text`` is BT XML ends (the text before it decides), or
    -1 when it is not BT XML (see the module)."""
    head = min(len(text), HEAD_CHARS)
    m = _MARKER.search(text, 0, head)
    if m is not None:
        return m.end()
    top = top_element_span(text, head)
    if top is None or top[0] != "root":
        return -1
    m = _ROOT_ONLY.search(text, top[1], head)
    return m.end() if m is not None else -1


def looks_like_bt(text: str) -> bool:
    """Whether a text is BehaviorTree.CPP XML (see the module)."""
    return bt_evidence_end(text) >= 0


def not_xml(text: str) -> bool:
    """Whether a text is not XML at all: empty or blank, with no element, or whose top
    element's start tag never closes in the head (``<not valid xml!!!``).

    Such a file belongs to no tool, and every reader fails on it (BehaviorTree.CPP's
    ``loadFromText`` throws "Error parsing the XML"), so a folder walk checks it rather
    than skipping it silently.  The editor does not use this: a file the user has just
    created is empty, and it is not an error yet."""
    head = text[:HEAD_CHARS]
    if not head.strip() or head.strip() == "\ufeff":
        return True
    top = top_element_span(head)
    if top is None:
        return True
    return ">" not in head[top[1] :]
