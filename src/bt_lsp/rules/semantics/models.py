"""``<TreeNodesModel>`` entries and their port declarations.

* ``missing-id`` (error): a ``<SubTree>`` entry without ``ID`` ("Missing attribute 'ID' in
  SubTree element within TreeNodesModel"); other entries are not read by
  BehaviorTree.CPP.  Range: the element name.
* ``missing-port-name`` (error): a port of a ``<SubTree>`` entry without ``name``
  ("Missing attribute [name] in port (SubTree model)").  Range: the element name.
* ``port-name-not-remappable`` (warning): a declared port name that passes the name rules
  but does not start with an ASCII letter (``_goal``, ``检查``, ``-x``): BehaviorTree.CPP
  accepts it in a ``<SubTree>`` model, but an attribute of that name is never passed as a
  remapping, and a C++ node cannot declare it at all.  Range: the name value.
* A declared port name the name rules reserve (``port-name-reserved``,
  ``port-name-reserved-groot2``, ``port-name-groot1``): what it is worth depends on the
  entry and on the project's BehaviorTree.CPP version, which the document's own name rules
  do not know (:func:`bt_lsp.rules.names.reserved_port_declaration`).  Range: the name
  value, as the name rules' own (so that their rename fixes apply).
"""

from __future__ import annotations

from typing import Final

from bt_lsp.rules.codes import BT, NAMES, Severity, define, defined
from bt_lsp.rules.context import Context
from bt_lsp.rules.names import (
    NameData,
    NameKind,
    Violation,
    check_name,
    is_allowed_port_name,
    reserved_port_declaration,
)
from bt_lsp.rules.semantics.base import State, quoted
from bt_lsp.syntax.elements import Element, NameRef, Role
from bt_lsp.syntax.model import Model

# The codes of these rules (see bt_lsp.rules.registry).
MISSING_PORT_NAME: Final = define(
    "missing-port-name",
    Severity.ERROR,
    "a SubTree model port has no `name`",
    BT,
    doc="""
        A port of a `<TreeNodesModel>` `<SubTree>` entry must have a `name`. BehaviorTree.CPP
        reads these entries when it loads the XML and refuses one without:
        `Missing attribute [name] in port (SubTree model)`.
        """,
    why="The file does not load.",
    bad="""
        <root BTCPP_format="4">
          <TreeNodesModel>
            <SubTree ID="Dock">
              <input_port type="double"/>
            </SubTree>
          </TreeNodesModel>
        </root>
        """,
    good="""
        <root BTCPP_format="4">
          <TreeNodesModel>
            <SubTree ID="Dock">
              <input_port name="speed" type="double"/>
            </SubTree>
          </TreeNodesModel>
        </root>
        """,
    since="BehaviorTree.CPP 4 (3.x does not read `<TreeNodesModel>`).",
)


def check_entry(st: State, el: Element) -> None:
    if el.name == "SubTree" and el.attr("ID") is None:
        st.add(
            el.name_start,
            el.name_end,
            "missing-id",
            "<SubTree> in <TreeNodesModel> has no ID attribute naming the tree it describes",
        )


def check_port_decl(st: State, el: Element) -> None:
    entry = st.model.elements[el.parent]
    a = el.attr("name")
    if a is None:
        if entry.name == "SubTree":
            st.add(
                el.name_start,
                el.name_end,
                "missing-port-name",
                f"<{el.name}> of a <SubTree> model has no name attribute",
            )
        return
    name = a.value
    if name is None or is_allowed_port_name(name) or check_name(name, NameKind.PORT):
        return
    s, e = el.span_of_value(a)
    reserved = reserved_port_declaration(name, entry.name, btcpp_of(st))
    if reserved is not None:
        # A name-rule code carries what its rename fixes read; the hint has no fix.
        named = defined(reserved.code).family == NAMES
        data = NameData(name, NameKind.PORT, Role.PORT_DECL) if named else None
        st.add(s, e, reserved.code, reserved.message, data=data)
        return
    if entry.name == "SubTree":
        why = (
            "a <SubTree> attribute of that name is never passed on as a remapping, so the port "
            "can only take its default or come from _autoremap"
        )
    else:
        why = "a C++ node cannot declare such a port (BehaviorTree.CPP's CreatePort rejects it)"
    st.add(
        s,
        e,
        "port-name-not-remappable",
        f"Port name {quoted(name)} does not start with an ASCII letter; {why}",
    )


def btcpp_of(st: State) -> str | None:
    """The BehaviorTree.CPP major version the document is checked against: ``"3"`` or
    ``"4"`` when its build or ``BTCPP_format`` says so, ``None`` when it is checked as 4
    for want of either."""
    return "3" if st.v3 else "4" if st.v4 else None


def reserved_declaration_at(model: Model, ref: NameRef, ctx: Context | None) -> Violation | None:
    """What :func:`check_port_decl` reports for the reserved name of the declared port
    ``ref`` (``None`` if nothing), for hover, which has no check's state: the version is
    read as :func:`bt_lsp.rules.semantics.document.check_root` reads it."""
    if ref.role is not Role.PORT_DECL or ref.element < 0:
        return None
    el = model.elements[ref.element]
    if el.parent < 0:
        return None
    root = model.root
    declared = root is not None and root.attr("BTCPP_format") is not None
    version = ctx.btcpp_version if ctx is not None else None
    btcpp = "3" if version == "3" else "4" if declared or version == "4" else None
    return reserved_port_declaration(ref.text, model.elements[el.parent].name, btcpp)
