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
"""

from __future__ import annotations

from typing import Final

from bt_lsp.rules.codes import BT, Severity, define
from bt_lsp.rules.names import NameKind, check_name, is_allowed_port_name
from bt_lsp.rules.semantics.base import State, quoted
from bt_lsp.syntax.elements import Element

# The codes of these rules (see bt_lsp.rules.registry).
MISSING_PORT_NAME: Final = define(
    "missing-port-name", Severity.ERROR, "a SubTree model port has no `name`", BT
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
    if (
        name is None
        or is_allowed_port_name(name)
        or check_name(name, NameKind.PORT, declaration=True)
    ):
        return
    s, e = el.span_of_value(a)
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
