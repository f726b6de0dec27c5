"""Renaming a name token: where its symbol occurs, the edits that write a new name there,
and the names a new one must avoid.

Pure, and blind to blackboard keys: :mod:`bt_lsp.ide.rename` builds renames (keys
included) on top of these, and :mod:`bt_lsp.ide.name_fixes` uses those renames.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping
from typing import NamedTuple

from bt_lsp.rules.context import ModelDecl
from bt_lsp.syntax.edits import TextEdit, escape_value
from bt_lsp.syntax.elements import NameRef, NameSymbol, Role, Symbol
from bt_lsp.syntax.model import Model

__all__ = [
    "Elsewhere",
    "elsewhere",
    "namespace",
    "occurrences",
    "other_file_edits",
    "rename_edits",
    "shown",
    "taken_names",
]


def shown(name: str) -> str:
    """A name with its control characters written visibly (``U+0007``)."""
    return "".join(c if c.isprintable() or c == " " else f"U+{ord(c):04X}" for c in name)


def _written(ref: NameRef, new_name: str) -> str:
    return escape_value(new_name, ref.quote) if ref.quote else new_name


def occurrences(model: Model, ref: NameRef) -> list[NameRef]:
    """Every name token of ``model`` with the symbol of ``ref``, ``ref`` included."""
    if ref.symbol is None:
        return [ref]
    return model.refs_to(ref.symbol)


def rename_edits(refs: Iterable[NameRef], new_name: str) -> list[TextEdit]:
    """The edits writing ``new_name`` over the name tokens ``refs``."""
    return sorted({TextEdit(r.start, r.end, _written(r, new_name)) for r in refs})


def namespace(symbol: Symbol) -> tuple[str, ...]:
    """Names in one namespace must stay distinct: trees and models share one (a tree ID may
    not be a node type), a port's namespace is its owner's ports."""
    return ("port", symbol.owner_kind, symbol.owner) if symbol.kind == "port" else ("ids",)


def _names_in(model: Model, ns: tuple[str, ...]) -> set[str]:
    return {sym.name for sym in model.by_symbol if namespace(sym) == ns}


def taken_names(model: Model, symbol: Symbol | None, others: Iterable[Model] = ()) -> set[str]:
    """Names a new name for ``symbol`` must avoid: the others in its namespace, in this
    document and in the other workspace documents."""
    if symbol is None:
        return set()
    ns = namespace(symbol)
    others = list(others)
    taken: set[str] = set()
    for m in (model, *others):
        taken |= _names_in(m, ns)
    if not any(symbol in m.by_symbol for m in others):
        taken.discard(symbol.name)
    return taken


def other_file_edits(
    symbol: Symbol | None, new_name: str, others: Mapping[str, Model]
) -> dict[str, tuple[TextEdit, ...]]:
    """The edits renaming ``symbol`` in other workspace documents (by path)."""
    if symbol is None:
        return {}
    out: dict[str, tuple[TextEdit, ...]] = {}
    for path, m in others.items():
        refs = m.refs_to(symbol)
        if refs:
            out[path] = tuple(rename_edits(refs, new_name))
    return out


class Elsewhere(NamedTuple):
    """A name whose target is not in the workspace: renaming the name here would leave the
    target with the old one.  ``refuse``: no rename may touch it (a tree's ID stays where
    the tree is defined, so a call renamed alone calls nothing); otherwise a rename is
    possible but not safe on its own (a node type's registration in C++ must follow).
    ``why`` says it, in a sentence that completes "... : why"; ``where`` is where the
    target is (``"registered in C++ in nodes.cpp"``), and ``first`` what a name
    diagnostic adds to its message: where the name must change first."""

    what: str
    why: str
    refuse: bool
    where: str = "outside the workspace"
    first: str = ""


def _file(path: str) -> str:
    """A file's name, for titles (the full path is in the message and the hover)."""
    return path.replace("\\", "/").rsplit("/", 1)[-1] or path


def _registered_where(decl: ModelDecl | None) -> tuple[str, str] | None:
    """Where a node type that bt-lsp does not rename is registered: (for a title, for a
    message), from its model's source; ``None`` when no model says."""
    if decl is None or decl.path is None:
        return None
    if decl.source == "cpp":
        return f"registered in C++ in {_file(decl.path)}", f"registered in C++ in {decl.path}"
    return (
        f"declared in {_file(decl.path)}, outside the workspace",
        f"declared in the node catalog {decl.path}, outside the workspace",
    )


def elsewhere(
    symbol: Symbol | None,
    models: Iterable[Model],
    registered: Mapping[str, ModelDecl] | None = None,
    defined: Callable[[NameSymbol], bool] | None = None,
) -> Elsewhere | None:
    """Whether ``symbol``'s target is outside the documents of ``models`` (the workspace):

    * a tree (``<SubTree ID>``, ``main_tree_to_execute``, a port of a ``<SubTree>`` call)
      whose ``<BehaviorTree ID>`` none of them defines: it comes from elsewhere (an
      installed package, a file outside the folder), where its ID stays;
    * a node type (or a port of one) that no ``<TreeNodesModel>`` entry declares: it is
      registered in code bt-lsp cannot see, which keeps the old name;
    * a node type that the project's C++ registers (``registered``, the context's models,
      say so): bt-lsp does not rewrite C++, so even a ``<TreeNodesModel>`` entry of the
      workspace renamed with it would leave the registration with the old name.

    ``None`` when the target is here, or when there is none: an instance name, and an
    empty name (nothing is registered or defined under it, so no reference works).
    ``defined`` says whether a tree or node type is defined in the workspace, when the
    caller knows it more cheaply than from the models' name tokens."""
    if symbol is None or not symbol.name:
        return None
    if symbol.kind == "port":
        owner = symbol.owner_symbol
        subject = f"the port '{shown(symbol.name)}' of "
    else:
        owner = symbol
        subject = ""
    if defined is None:
        found_in = list(models)

        def defined(owner: NameSymbol) -> bool:
            role = Role.TREE_DEF if owner.kind == "tree" else Role.MODEL_DEF
            return any(r.role == role for m in found_in for r in m.refs_to(owner))

    if owner.kind == "tree":
        if defined(owner):
            return None
        tree = shown(owner.name)
        return Elsewhere(
            f"{subject}the tree '{tree}'",
            f"the tree '{tree}' is not defined in the workspace (it comes from "
            "elsewhere, such as an installed package, and keeps its ID there); rename it "
            "where it is defined first, then this reference",
            refuse=True,
            first=(
                "the tree is not defined in this workspace: rename it where it is defined "
                "first; this call keeps its ID until then"
                if not subject
                else f"the tree '{tree}' is not defined in this workspace: rename the port "
                "where the tree is defined first; this call keeps it until then"
            ),
        )
    if owner.kind == "model":
        node = shown(owner.name)
        decl = registered.get(owner.name) if registered is not None else None
        in_cpp = decl is not None and decl.source == "cpp" and decl.path is not None
        if not in_cpp and defined(owner):
            return None
        found = _registered_where(decl)
        short, full = (
            found
            if found is not None
            else (
                "registered outside the workspace",
                "registered in C++ that bt-lsp cannot see (no <TreeNodesModel> of the workspace "
                "declares it)",
            )
        )
        subject_first = f"the node type '{node}'" if subject else "the node type"
        return Elsewhere(
            f"{subject}the node type '{node}'",
            f"the node type '{node}' is {full}"
            + (", which bt-lsp does not rename" if found is not None else "")
            + "; its registration must be renamed too",
            refuse=False,
            where=short,
            first=(
                f"{subject_first} is {full}: rename {'the port' if subject else 'it'} there "
                "first; fix-all leaves this name until then"
            ),
        )
    return None
