"""What the rest of the workspace provides to the semantic checks of one document.

A :class:`Context` is frozen, plain data and knows nothing of the protocol: the node
models declared anywhere (``<TreeNodesModel>`` sections of this document, of its includes,
of other workspace files and of model files named in the settings), the trees visible to
the document (its own and those of its include closure, sharing one ID namespace as in
BehaviorTree.CPP), the trees elsewhere in the workspace, and a few settings.

:meth:`Context.from_document` builds one from a document alone; :meth:`Context.combine`
adds other documents, which the workspace layer reads and resolves (include resolution is
not done here).  What one document declares (:mod:`bt_lsp.rules.decls`) is extracted
once per model and cached (:mod:`bt_lsp.rules.facts`), so combining is proportional to the number of
declarations, not to the size of the documents.
"""

from __future__ import annotations

from collections.abc import Collection, Iterable, Mapping
from dataclasses import dataclass, field
from itertools import chain
from operator import itemgetter
from types import MappingProxyType
from typing import TYPE_CHECKING, Final, cast

from bt_lsp.rules.builtins_v3 import builtins_for
from bt_lsp.rules.decls import (
    AUTHORITATIVE,
    DocumentFacts,
    ModelDecl,
    ModelSource,
    TreeDecl,
    source_label,
)
from bt_lsp.rules.facts import facts_of
from bt_lsp.syntax.model import Model

if TYPE_CHECKING:
    from bt_lsp.syntax.document import Document

__all__ = [
    "AUTHORITATIVE",
    "Context",
    "DocumentFacts",
    "ModelDecl",
    "ModelSource",
    "TreeDecl",
    "facts_of",
    "is_generated_catalog",
    "source_label",
]

_EMPTY: Final[Mapping[str, object]] = MappingProxyType({})


@dataclass(frozen=True, slots=True)
class Context:
    """The workspace as one document sees it.

    * ``models``: custom node models by ID (built-in IDs left out: a registered built-in
      wins over any declaration); the first declaration wins, this document's first.
    * ``subtree_models``: the ``<TreeNodesModel><SubTree ID>`` entries (a tree's ports).
    * ``trees``: the trees visible by ID, this document's and its include closure's, in
      BehaviorTree.CPP's load order (included documents first, this document last, so the
      last entry is the one BehaviorTree.CPP keeps); several entries mean a duplicate ID.
    * ``workspace_trees``: trees of other workspace documents that are not included.
    * ``workspace_has_custom_models``: whether a catalog of the custom nodes is known; when
      not, nodes missing from the models are probably registered in C++ only.
    * ``ros_pkg_paths``: ROS package name -> share directory (settings).
    * ``included_by``: paths of workspace documents that include this one.
    * ``included``: paths of the documents of this one's include closure, and
      ``workspace_files`` the number of the other workspace documents (what a message
      about a missing tree says was searched).
    * ``path``: this document's path; declarations with this path are its own.
    * ``btcpp_version``: the BehaviorTree.CPP major version the document is built for,
      ``"3"`` or ``"4"``, as the project layer detected or configured it (``None`` when
      unknown: the document's own ``BTCPP_format`` is all there is), and
      ``btcpp_unclear`` whether it is unknown because the project's build names both
      versions (then no finding that depends on the version is more than a warning).
    * ``registered``: when every package that can register nodes for this document was
      read (its C++ catalog is complete), the custom node IDs the application registers;
      ``None`` when that is not known, and ``incomplete`` then says why, for messages.
    """

    path: str | None = None
    models: Mapping[str, ModelDecl] = field(
        default_factory=lambda: cast("Mapping[str, ModelDecl]", _EMPTY)
    )
    subtree_models: Mapping[str, ModelDecl] = field(
        default_factory=lambda: cast("Mapping[str, ModelDecl]", _EMPTY)
    )
    trees: Mapping[str, tuple[TreeDecl, ...]] = field(
        default_factory=lambda: cast("Mapping[str, tuple[TreeDecl, ...]]", _EMPTY)
    )
    workspace_trees: Mapping[str, tuple[TreeDecl, ...]] = field(
        default_factory=lambda: cast("Mapping[str, tuple[TreeDecl, ...]]", _EMPTY)
    )
    workspace_has_custom_models: bool = False
    ros_pkg_paths: Mapping[str, str] = field(
        default_factory=lambda: cast("Mapping[str, str]", _EMPTY)
    )
    included_by: tuple[str, ...] = ()
    btcpp_version: str | None = None
    btcpp_unclear: bool = False
    included: tuple[str, ...] = ()  # the paths of this document's include closure
    workspace_files: int = 0  # how many other workspace documents were looked at
    registered: frozenset[str] | None = None
    incomplete: str = ""
    # What the context was combined from besides its own document's declarations (the
    # other documents' declarations, by identity, and the settings): equal sources mean
    # that only this document's own declarations can differ (see semantics/sections.py).
    sources: tuple[object, ...] = field(default=(), compare=False, repr=False)

    def is_own(self, decl: TreeDecl | ModelDecl) -> bool:
        """Whether ``decl`` is declared in this context's document."""
        return decl.path == self.path

    @classmethod
    def from_document(
        cls,
        doc: Document,
        path: str | None = None,
        *,
        ros_pkg_paths: Mapping[str, str] | None = None,
        workspace_has_custom_models: bool = False,
    ) -> Context:
        """The context of a document that sees nothing but itself."""
        return cls.combine(
            doc,
            (),
            path=path,
            ros_pkg_paths=ros_pkg_paths,
            workspace_has_custom_models=workspace_has_custom_models,
        )

    @classmethod
    def combine(
        cls,
        own: Document,
        others: Iterable[tuple[str, Document, bool]],
        *,
        path: str | None = None,
        ros_pkg_paths: Mapping[str, str] | None = None,
        model_files: Iterable[tuple[str, Document]] = (),
        ros_models: Iterable[tuple[str, Document]] = (),
        included_by: Iterable[str] = (),
        workspace_has_custom_models: bool | None = None,
        btcpp_version: str | None = None,
        foreign: Collection[str] = (),
        btcpp_unclear: bool = False,
    ) -> Context:
        """The context of ``own`` among ``others``: ``(path, document, included)`` triples.

        ``included`` is true for documents of ``own``'s include closure (their trees join
        its namespace; give them in BehaviorTree.CPP's depth-first load order) and false
        for any other workspace document (only its models count; its trees go to
        ``workspace_trees``).  A document whose path is ``own``'s is skipped.
        ``model_files`` are the node catalogs named in the settings (``models``,
        ``modelFiles``, ``--models``): authoritative, but for a Groot2 ``.btproj``, which
        is a palette.  ``ros_models`` are the catalogs shipped by the ROS packages ``own``
        depends on: authoritative for their nodes.  The models of a document whose path
        is in ``foreign`` (another package's, that ``own``'s package does not depend on)
        do not count: an author's model of a node describes that package's node, which
        may differ from a node of the same ID elsewhere; its trees still do.

        A model from an authoritative source wins over any advisory one (a
        ``<TreeNodesModel>`` of a tree file); among equals the first wins, this
        document's first.  ``workspace_has_custom_models`` (whether the catalog is
        complete: a node it lacks is not registered) defaults to whether a catalog is
        named: ``<TreeNodesModel>`` sections inside tree files are usually partial (editors
        write the nodes they show), and a ROS package's catalog holds only its own nodes.
        """
        own_path = path if path is not None else own.path
        own_facts = facts_of(own, own_path)
        # Gathered in the order of precedence, then grouped by ID in C (see _first_by_id).
        authoritative: list[tuple[ModelDecl, ...]] = []
        advisory: list[tuple[ModelDecl, ...]] = [own_facts.models]
        subtree_models: list[tuple[ModelDecl, ...]] = [own_facts.subtree_models]
        trees: list[tuple[TreeDecl, ...]] = []
        workspace_trees: list[tuple[TreeDecl, ...]] = []
        sources: list[object] = [own_path]
        included: list[str] = []
        workspace_files = 0
        for other_path, other, in_closure in others:
            if other_path == own_path:
                continue
            if in_closure:
                included.append(other_path or "")
            else:
                workspace_files += 1
            f = facts_of(other, other_path)
            if not in_closure and other_path in foreign:
                sources.append((f, in_closure, "foreign"))
                workspace_trees.append(f.trees)
                continue
            sources.append((f, in_closure))
            if other_path is not None and other_path.endswith(".btproj"):
                advisory.append(_tagged(f, "palette", other))
            elif f.models and is_generated_catalog(other):
                authoritative.append(_tagged(f, "generated", other))
            else:
                advisory.append(f.models)
            subtree_models.append(f.subtree_models)
            (trees if in_closure else workspace_trees).append(f.trees)
        trees.append(own_facts.trees)
        catalog = False
        for model_path, model_doc in model_files:
            f = facts_of(model_doc, model_path)
            sources.append(f)
            if model_path.endswith(".btproj"):
                advisory.append(_tagged(f, "palette", model_doc))
            else:
                authoritative.append(_tagged(f, "catalog", model_doc))
                catalog = True
            subtree_models.append(f.subtree_models)
        for model_path, model_doc in ros_models:
            f = facts_of(model_doc, model_path)
            sources.append(("ros", f))
            authoritative.append(_tagged(f, "ros", model_doc))
        has_custom = catalog if workspace_has_custom_models is None else workspace_has_custom_models
        return cls(
            path=own_path,
            models=MappingProxyType(
                _first_by_id([*authoritative, *advisory], builtins_for(btcpp_version))
            ),
            subtree_models=MappingProxyType(_first_by_id(subtree_models)),
            trees=MappingProxyType(_all_by_id(trees)),
            workspace_trees=MappingProxyType(_all_by_id(workspace_trees)),
            workspace_has_custom_models=has_custom,
            ros_pkg_paths=MappingProxyType(dict(ros_pkg_paths or {})),
            included_by=tuple(included_by),
            btcpp_version=btcpp_version,
            btcpp_unclear=btcpp_unclear,
            included=tuple(included),
            workspace_files=workspace_files,
            sources=(*sources, workspace_has_custom_models, btcpp_version, btcpp_unclear),
        )


def _tagged(facts: DocumentFacts, source: ModelSource, doc: Document) -> tuple[ModelDecl, ...]:
    """``facts.models`` (``doc``'s) with ``source`` as their source, kept for the document
    (its history) while its facts are the same object: a catalog is read again only when
    it changes."""
    hit: tuple[DocumentFacts, str, tuple[ModelDecl, ...]] | None = doc.history.memo.get("tagged")
    if hit is not None and hit[0] is facts and hit[1] == source:
        return hit[2]
    tagged = tuple([m._replace(source=source) for m in facts.models])
    doc.history.memo["tagged"] = (facts, source, tagged)
    return tagged


def is_generated_catalog(doc: Document) -> bool:
    """Whether ``doc`` reads as a node catalog that BehaviorTree.CPP exported
    (``writeTreeNodesModelXML``, ``bt-lsp models``): a ``<root>`` with ``BTCPP_format``
    whose only child is one ``<TreeNodesModel>``, and no comment (tinyxml2's printer
    writes none; a hand-kept model file usually explains itself in one).  Anything else
    with a ``<TreeNodesModel>`` is what an author or an editor wrote."""
    model = doc.model
    hit: tuple[Model, bool] | None = doc.history.memo.get("generated")  # per model
    if hit is not None and hit[0] is model:
        return hit[1]
    root = model.root
    found = (
        root is not None
        and root.name == "root"
        and root.attr("BTCPP_format") is not None
        and list(model.root_child_names()) == ["TreeNodesModel"]
        and "<!--" not in doc.text
    )
    doc.history.memo["generated"] = (model, found)
    return found


_ID = itemgetter(0)  # a declaration's ID


def _first_by_id(
    groups: Iterable[tuple[ModelDecl, ...]], left_out: Collection[str] = ()
) -> dict[str, ModelDecl]:
    """The first declaration of each ID (but those in ``left_out``), in the order of their
    first declarations.  Grouped in C when no ID repeats, as usual: an edit combines every
    declaration of the document again."""
    decls = list(chain.from_iterable(groups))
    ids = list(map(_ID, decls))
    if len(set(ids)) == len(ids):
        out = dict(zip(ids, decls, strict=True))
        for key in out.keys() & left_out:
            del out[key]
        return out
    out = {}
    for d in decls:
        if d.id not in left_out:
            out.setdefault(d.id, d)
    return out


def _all_by_id(groups: Iterable[tuple[TreeDecl, ...]]) -> dict[str, tuple[TreeDecl, ...]]:
    """Every declaration of each ID in order, in the order of their first declarations
    (grouped in C when no ID repeats)."""
    decls = list(chain.from_iterable(groups))
    ids = list(map(_ID, decls))
    if len(set(ids)) == len(ids):
        return dict(zip(ids, zip(decls), strict=True))  # zip of one makes 1-tuples
    lists: dict[str, list[TreeDecl]] = {}
    for d in decls:
        lists.setdefault(d.id, []).append(d)
    return {k: tuple(v) for k, v in lists.items()}
