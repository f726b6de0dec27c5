"""The name rules where names are born: registered IDs and port names in C++.

What BehaviorTree.CPP 4.10 does with each (``shared/spec/bt-xml.md`` M7 and P4):

* ``cpp-port-name`` (error): a port name literal of ``InputPort``/``OutputPort``/
  ``BidirectionalPort`` for which ``IsAllowedPortName`` is false (empty, not starting with
  an ASCII letter, a forbidden character such as the period of ``goal.pose``, a reserved
  attribute).  ``CreatePort`` throws when ``providedPorts()`` runs, which
  ``registerNodeType`` does: the program stops at registration.
* ``cpp-model-name`` (warning): a registered ID that breaks the model name rules
  (``"Dock Robot"``).  BehaviorTree.CPP registers any ID without a check, but a tree can
  name such a node only in the explicit form (``<Action ID="Dock Robot"/>``): as an element
  name it is rejected at load time by ``validateModelName`` (or is not even XML).

Range: the string literal.  Pure: the file's facts and text come from the caller.
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import Final

from bt_lsp.cpp.facts import FileFacts, Op, PortFacts, Span
from bt_lsp.rules.codes import NAMES, Severity, define
from bt_lsp.rules.diagnostics import Diagnostic, make
from bt_lsp.rules.names import NameKind, check_name, is_allowed_port_name
from bt_lsp.syntax.text import LineIndex

CPP_MODEL_NAME: Final = define(
    "cpp-model-name",
    Severity.WARNING,
    "a node ID registered in C++ breaks the model name rules (usable only as `<Action ID=…>`)",
    NAMES,
    doc="""
        Reported on the project's C++ (`registerNodeType<T>("Dock Robot")` and the like), not
        on a tree. BehaviorTree.CPP registers any ID without a check, but an ID that breaks the
        model name rules (a space, a period, `Root`) cannot be written as an element name: XML
        does not allow it, or BehaviorTree.CPP rejects it when it loads the tree. A tree can
        use it only in explicit form, `<Action ID="Dock Robot"/>`. The message names the rule
        broken. No example: it needs C++ code.
        """,
    why="""
        Every tree using the node must use the explicit form, which Groot2 and the name rules
        reject too; rename the ID (`DockRobot`).
        """,
    since=(
        "BehaviorTree.CPP 4.8.4 and later reject such a name in a tree; registration accepts "
        "it in every version."
    ),
)
CPP_PORT_NAME: Final = define(
    "cpp-port-name",
    Severity.ERROR,
    "a C++ port name BehaviorTree.CPP rejects when the node is registered",
    NAMES,
    doc="""
        Reported on the project's C++: a port name in `InputPort`, `OutputPort` or
        `BidirectionalPort` that BehaviorTree.CPP's `IsAllowedPortName` rejects (empty, not
        starting with an ASCII letter, a forbidden character such as the period of
        `goal.pose`, or a reserved attribute such as `name` or `ID`). `CreatePort` throws when
        `providedPorts()` runs, which `registerNodeType` does: `The name of a port must not be
        `name` or `ID` and must start with an alphabetic character. Underscore is reserved.`
        No example: it needs C++ code.
        """,
    why="""
        The program stops when it registers the node, before any tree is loaded.
        """,
    since="BehaviorTree.CPP 4 (the message quoted is that of 4.10).",
)

_CREATE_PORT_ERROR = (
    "The name of a port must not be `name` or `ID` and must start with an alphabetic "
    "character. Underscore is reserved."
)


def _ports(ops: tuple[Op, ...]) -> Iterator[PortFacts]:
    for op in ops:
        if op.port is not None:
            yield op.port
        yield from _ports(op.ops)


def _why_port(name: str) -> str:
    found = check_name(name, NameKind.PORT, declaration=True)
    if found:
        return found[0].message
    if not name[:1].isascii() or not name[:1].isalpha():
        return f"Port name '{name}' does not start with an ASCII letter"
    return f"Port name '{name}' is a reserved attribute"


def cpp_name_diagnostics(facts: FileFacts, text: str) -> list[Diagnostic]:
    """The name-rule diagnostics of one C++ file (``text`` is its content)."""
    lines = LineIndex(text)
    n = lines.line_count

    def offsets(span: Span) -> tuple[int, int]:
        def at(line: int, col: int) -> int:
            return (lines.line_start(line) if line < n else len(text)) + col

        return at(span[0], span[1]), at(span[2], span[3])

    out: list[Diagnostic] = []
    for reg in facts.registrations:
        if reg.id is None:
            continue
        found = check_name(reg.id, NameKind.MODEL)
        if found:
            s, e = offsets(reg.id_span)
            out.append(
                make(
                    s,
                    e,
                    "cpp-model-name",
                    f"{found[0].message}. BehaviorTree.CPP 4.10 registers the ID without a "
                    f'check, but a tree can use it only as <Action ID="{reg.id}"/>: as an '
                    "element name it is rejected when the XML is loaded",
                )
            )
    ports = [p for fn in facts.fns for p in _ports(fn.ops)]
    ports += [p for reg in facts.registrations for p in _ports(reg.ops or ())]
    seen: set[Span] = set()
    for p in ports:
        if p.name is None or is_allowed_port_name(p.name) or p.name_span in seen:
            continue
        seen.add(p.name_span)
        s, e = offsets(p.name_span)
        out.append(
            make(
                s,
                e,
                "cpp-port-name",
                f"{_why_port(p.name)}. BehaviorTree.CPP 4.10 throws when the node is "
                f'registered (CreatePort: "{_CREATE_PORT_ERROR}")',
            )
        )
    out.sort(key=lambda d: (d.start, d.end))
    return out
