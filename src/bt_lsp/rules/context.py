"""What the rest of the workspace provides to the semantic checks of one document.

A :class:`Context` is frozen, plain data and knows nothing of the protocol: the node
models declared anywhere (``<TreeNodesModel>`` sections of this document, of its includes,
of other workspace files and of model files named in the settings), the trees visible to
the document (its own and those of its include closure, sharing one ID namespace as in
BehaviorTree.CPP), the trees elsewhere in the workspace, and a few settings.

:meth:`Context.from_document` builds one from a document alone; :meth:`Context.combine`
adds other documents, which the workspace layer reads and resolves (include resolution is
not done here).  What one document declares is extracted once per model and cached, so
combining is proportional to the number of declarations, not to the size of the documents.
"""

from __future__ import annotations

import weakref
from collections.abc import Callable, Collection, Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from functools import partial
from itertools import chain, compress, count, repeat
from operator import is_not, itemgetter, ne, or_
from types import MappingProxyType
from typing import TYPE_CHECKING, Any, Final, Literal, NamedTuple, TypeVar, cast

from bt_lsp.rules.builtins import Category, Direction, PortModel
from bt_lsp.rules.builtins_v3 import builtins_for
from bt_lsp.syntax.elements import Element, Zone
from bt_lsp.syntax.model import Model
from bt_lsp.syntax.sections import Section

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

#: Where a node model comes from.  Authoritative sources say what BehaviorTree.CPP
#: registers: ``catalog`` (a file named in ``models``/``modelFiles``/``--models``),
#: ``generated`` (a workspace file that is nothing but a ``<TreeNodesModel>``, as
#: ``writeTreeNodesModelXML`` writes it: see :func:`is_generated_catalog`), ``ros`` (the
#: shipped model of a ROS package the document depends on) and ``cpp`` (the project's C++
#: registrations).  Advisory ones say what an author or an editor wrote: ``tree`` (a
#: ``<TreeNodesModel>`` inside a tree file), ``palette`` (a Groot2 ``.btproj``) and
#: ``cpp-partial`` (a C++ registration whose kind, ports or defaults could not all be read).
ModelSource = Literal["tree", "palette", "generated", "catalog", "ros", "cpp", "cpp-partial"]
AUTHORITATIVE: Final[frozenset[str]] = frozenset({"generated", "catalog", "ros", "cpp"})
_SOURCE_LABELS: Final[Mapping[str, str]] = MappingProxyType(
    {
        "tree": "the <TreeNodesModel> of a tree file (advisory: BehaviorTree.CPP reads the C++)",
        "palette": "a Groot2 palette (advisory: BehaviorTree.CPP reads the C++)",
        "generated": "a catalog exported by BehaviorTree.CPP (authoritative)",
        "catalog": "a node catalog named in the settings (authoritative)",
        "ros": "the node catalog a ROS package ships (authoritative)",
        "cpp": "the project's C++ registration (authoritative)",
        "cpp-partial": "the project's C++ registration (advisory: a static reading could not "
        "know all of it)",
    }
)


def source_label(source: str) -> str:
    """What a model source is, for hovers and completion."""
    return _SOURCE_LABELS.get(source, source)


_EMPTY: Final[Mapping[str, object]] = MappingProxyType({})

_ENTRY_CATEGORIES: Final[frozenset[str]] = frozenset(
    {"Action", "Condition", "Control", "Decorator", "SubTree"}
)
_DIRECTIONS: Final[Mapping[str, Direction]] = MappingProxyType(
    {"input_port": "input", "output_port": "output", "inout_port": "inout"}
)
# Attributes of a model entry that are not ports in the pre-3.x attribute form
# (``<Action ID="Say" message=""/>``).
_ENTRY_NON_PORT_ATTRS: Final[frozenset[str]] = frozenset({"ID", "name", "description"})


class ModelDecl(NamedTuple):
    """A node model (or the port list of a tree) declared in a ``<TreeNodesModel>``.

    ``category`` is the entry's tag.  ``ports`` are :class:`~bt_lsp.rules.builtins.PortModel`
    values; a port's ``default`` is the ``default`` attribute as written, ``None`` when
    absent.  ``path`` is the declaring document (``None`` for an unsaved one) and
    ``start``/``end`` the code-point span of the entry's ``ID`` value (its tag name when it
    has no ``ID``).  ``source`` says where the model comes from and so whether it is
    authoritative (what BehaviorTree.CPP registers) or advisory (what someone wrote).
    ``where`` says where a model learned from C++ is registered, for people
    (``src/nodes.cpp:42``, relative to the workspace folder); empty for the others.
    """

    id: str
    category: Category
    ports: tuple[PortModel, ...]
    path: str | None
    start: int
    end: int
    source: ModelSource = "tree"
    where: str = ""

    @property
    def authoritative(self) -> bool:
        """Whether BehaviorTree.CPP is known to register exactly this model."""
        return self.source in AUTHORITATIVE

    def port(self, name: str) -> PortModel | None:
        for p in self.ports:
            if p.name == name:
                return p
        return None

    @property
    def child_range(self) -> tuple[int, int | None]:
        """How many children a node of this category takes: (minimum, maximum or None)."""
        if self.category == "Decorator":
            return 1, 1
        if self.category == "Control":
            return 1, None
        return 0, 0


class TreeDecl(NamedTuple):
    """A ``<BehaviorTree ID>``: where it is and which trees it calls.

    ``start``/``end`` span the ``ID`` value.  ``calls`` are the IDs of its ``<SubTree>``
    elements in document order (empty IDs left out) and ``call_offsets`` the spans of those
    ``ID`` values relative to ``start``, index for index (:attr:`call_spans` places them),
    so that moving a tree moves two numbers.

    Declarations are named tuples (immutable, and cheap to make: a document's are made
    again for the part of it that an edit moved).
    """

    id: str
    path: str | None
    start: int
    end: int
    calls: tuple[str, ...] = ()
    call_offsets: tuple[tuple[int, int], ...] = ()

    @property
    def call_spans(self) -> tuple[tuple[int, int], ...]:
        """The spans of the called IDs, in the document's coordinates."""
        o = self.start
        return tuple([(s + o, e + o) for s, e in self.call_offsets])


@dataclass(frozen=True, slots=True)
class DocumentFacts:
    """What one document declares, in document order."""

    path: str | None
    trees: tuple[TreeDecl, ...]
    models: tuple[ModelDecl, ...]  # Action/Condition/Control/Decorator entries
    subtree_models: tuple[ModelDecl, ...]  # <SubTree> entries
    # For a model made of sections: where each section's declarations begin in the three
    # tuples above, so that the facts of the document's next version are made from these
    # by replacing what its changed sections declare and moving what follows.
    layout: _Layout | None = field(default=None, compare=False, repr=False)


@dataclass(frozen=True, slots=True)
class _Layout:
    """The sections and origins facts were made from, and for each section ``k`` the index
    of its first tree, model and SubTree model (``at[k]``; ``at[len(sections)]`` is the
    count)."""

    sections: Sequence[Section]
    origins: Sequence[int]
    trees_at: list[int]
    models_at: list[int]
    subtree_models_at: list[int]


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
      unknown: the document's own ``BTCPP_format`` is all there is).
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
    ) -> Context:
        """The context of ``own`` among ``others``: ``(path, document, included)`` triples.

        ``included`` is true for documents of ``own``'s include closure (their trees join
        its namespace; give them in BehaviorTree.CPP's depth-first load order) and false
        for any other workspace document (only its models count; its trees go to
        ``workspace_trees``).  A document whose path is ``own``'s is skipped.
        ``model_files`` are the node catalogs named in the settings (``models``,
        ``modelFiles``, ``--models``): authoritative, but for a Groot2 ``.btproj``, which
        is a palette.  ``ros_models`` are the catalogs shipped by the ROS packages ``own``
        depends on: authoritative for their nodes.

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
            sources.append((f, in_closure))
            if other_path is not None and other_path.endswith(".btproj"):
                advisory.append(_tagged(f, "palette"))
            elif f.models and is_generated_catalog(other):
                authoritative.append(_tagged(f, "generated"))
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
                advisory.append(_tagged(f, "palette"))
            else:
                authoritative.append(_tagged(f, "catalog"))
                catalog = True
            subtree_models.append(f.subtree_models)
        for model_path, model_doc in ros_models:
            f = facts_of(model_doc, model_path)
            sources.append(("ros", f))
            authoritative.append(_tagged(f, "ros"))
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
            included=tuple(included),
            workspace_files=workspace_files,
            sources=(*sources, workspace_has_custom_models, btcpp_version),
        )


# The models of a document with another source, kept per facts object (a catalog is read
# again only when it changes); bounded, oldest first out.
_TAGGED: dict[tuple[int, str], tuple[DocumentFacts, tuple[ModelDecl, ...]]] = {}
_TAGGED_MAX: Final = 256


def _tagged(facts: DocumentFacts, source: ModelSource) -> tuple[ModelDecl, ...]:
    """``facts.models`` with ``source`` as their source."""
    key = (id(facts), source)
    hit = _TAGGED.get(key)
    if hit is not None and hit[0] is facts:
        return hit[1]
    tagged = tuple([m._replace(source=source) for m in facts.models])
    if len(_TAGGED) >= _TAGGED_MAX:
        del _TAGGED[next(iter(_TAGGED))]
    _TAGGED[key] = (facts, tagged)
    return tagged


_GENERATED: weakref.WeakKeyDictionary[Document, tuple[Model, bool]] = weakref.WeakKeyDictionary()


def is_generated_catalog(doc: Document) -> bool:
    """Whether ``doc`` reads as a node catalog that BehaviorTree.CPP exported
    (``writeTreeNodesModelXML``, ``bt-lsp models``): a ``<root>`` with ``BTCPP_format``
    whose only child is one ``<TreeNodesModel>``, and no comment (tinyxml2's printer
    writes none; a hand-kept model file usually explains itself in one).  Anything else
    with a ``<TreeNodesModel>`` is what an author or an editor wrote."""
    model = doc.model
    hit = _GENERATED.get(doc)
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
    _GENERATED[doc] = (model, found)
    return found


def _first_by_id(
    groups: Iterable[tuple[ModelDecl, ...]], left_out: Collection[str] = ()
) -> dict[str, ModelDecl]:
    """The first declaration of each ID (but those in ``left_out``), in the order of their
    first declarations.  Grouped in C when no ID repeats, as usual: an edit combines every
    declaration of the document again."""
    decls = list(chain.from_iterable(groups))
    ids = list(map(_FIELDS[0], decls))
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
    ids = list(map(_FIELDS[0], decls))
    if len(set(ids)) == len(ids):
        return dict(zip(ids, zip(decls), strict=True))  # zip of one makes 1-tuples
    lists: dict[str, list[TreeDecl]] = {}
    for d in decls:
        lists.setdefault(d.id, []).append(d)
    return {k: tuple(v) for k, v in lists.items()}


# --- extraction ---------------------------------------------------------------------------

# Model -> facts, keyed by document; a cached entry is valid while the document's model is
# the same object (a document builds a new model after every edit).
_CACHE: weakref.WeakKeyDictionary[Document, tuple[Model, str | None, DocumentFacts]] = (
    weakref.WeakKeyDictionary()
)


def facts_of(doc: Document, path: str | None = None) -> DocumentFacts:
    """What ``doc`` declares (cached per model and path)."""
    model = doc.model
    if path is None:
        path = doc.path
    hit = _CACHE.get(doc)
    if hit is not None and hit[0] is model and hit[1] == path:
        return hit[2]
    if model.head is None:
        facts = extract(model, path)
    else:
        facts = extract_sections(model, path, hit[2] if hit is not None else None)
    _CACHE[doc] = (model, path, facts)
    return facts


def extract_sections(
    model: Model, path: str | None, before: DocumentFacts | None = None
) -> DocumentFacts:
    """:func:`extract` for a model made of sections: each section's declarations are
    extracted once (they are kept on the section, in its coordinates) and placed here.

    With the facts ``before`` of an earlier version of the document, the sections both
    versions begin and end with keep their declarations: those before the edit as they
    are, those after it moved by the edit's length (in C: no Python code runs per tree),
    so that an edit costs what its own sections declare.
    """
    sections, origins = model.sections, model.origins
    if before is None or before.layout is None or before.path != path:
        return _extract_all(sections, origins, model.root, path)
    layout = before.layout
    old_sections, old_origins = layout.sections, layout.origins
    n_old, n_new = len(old_sections), len(sections)
    most = min(n_old, n_new)
    # The sections both begin with, where they were; then those both end with (moved).
    moved = map(or_, map(is_not, old_sections, sections), map(ne, old_origins, origins))
    p = next(compress(count(), moved), most)
    q = next(compress(count(), map(is_not, reversed(old_sections), reversed(sections))), most)
    q = min(q, most - p)
    if p == n_old == n_new:
        return before
    delta = origins[n_new - q] - old_origins[n_old - q] if q else 0
    mid = _extract_all(sections[p : n_new - q], origins[p : n_new - q], model.root, path)
    assert mid.layout is not None
    cut = _Cut(p, n_old - q, delta, path)
    trees, trees_at = cut.splice(
        before.trees, layout.trees_at, mid.trees, mid.layout.trees_at, _moved_trees
    )
    models, models_at = cut.splice(
        before.models, layout.models_at, mid.models, mid.layout.models_at, _moved_models
    )
    subs, subs_at = cut.splice(
        before.subtree_models,
        layout.subtree_models_at,
        mid.subtree_models,
        mid.layout.subtree_models_at,
        _moved_models,
    )
    return DocumentFacts(
        path, trees, models, subs, _Layout(sections, origins, trees_at, models_at, subs_at)
    )


D = TypeVar("D", bound="tuple[object, ...]")  # a TreeDecl or a ModelDecl


@dataclass(frozen=True, slots=True)
class _Cut:
    """An edit as the facts see it: old sections ``[first, stop)`` were replaced; those
    from ``stop`` on moved by ``delta`` characters."""

    first: int
    stop: int
    delta: int
    path: str | None

    def splice(
        self,
        old: tuple[D, ...],
        old_at: list[int],
        new: tuple[D, ...],
        new_at: list[int],
        move: _Mover,
    ) -> tuple[tuple[D, ...], list[int]]:
        """One kind of declaration: the old ones of the sections kept, the new ones of the
        sections in between, and where each section's begin."""
        first, stop = self.first, self.stop
        head_end: int = old_at[first]
        tail_start: int = old_at[stop]
        kept = old[tail_start:]
        tail: Iterable[D] = move(kept, self.delta, self.path) if self.delta else kept
        decls: tuple[D, ...] = tuple(chain(old[:head_end], new, tail))
        shift = head_end + len(new) - tail_start
        at = old_at[:first]
        at.extend(map(head_end.__add__, new_at))
        at.pop()  # the count of the new ones is where the tail begins
        at.extend(map(shift.__add__, old_at[stop:]) if shift else old_at[stop:])
        return decls, at


def _extract_all(
    sections: Sequence[Section], origins: Sequence[int], root: Element | None, path: str | None
) -> DocumentFacts:
    """The declarations of ``sections`` (at ``origins``), with their layout."""
    trees: list[TreeDecl] = []
    models: list[ModelDecl] = []
    subtree_models: list[ModelDecl] = []
    trees_at: list[int] = []
    models_at: list[int] = []
    subs_at: list[int] = []
    for section, o in zip(sections, origins, strict=True):
        trees_at.append(len(trees))
        models_at.append(len(models))
        subs_at.append(len(subtree_models))
        local: DocumentFacts | None = section.cache.get("facts")
        if local is None:
            local = section.cache["facts"] = extract(Model.of_section(section, root), None)
        if not local.models and not local.subtree_models and len(local.trees) == 1:
            t = local.trees[0]  # the usual section: one tree
            # Made without the named tuple's constructor, as every tree of a first analysis.
            trees.append(_new(TreeDecl, (t.id, path, t.start + o, t.end + o, t.calls, t[5])))
            continue
        if local.trees:
            trees.extend(_moved_trees(local.trees, o, path))
        if local.models:
            models.extend(_moved_models(local.models, o, path))
        if local.subtree_models:
            subtree_models.extend(_moved_models(local.subtree_models, o, path))
    trees_at.append(len(trees))
    models_at.append(len(models))
    subs_at.append(len(subtree_models))
    return DocumentFacts(
        path,
        tuple(trees),
        tuple(models),
        tuple(subtree_models),
        _Layout(sections, origins, trees_at, models_at, subs_at),
    )


_new = tuple.__new__
_FIELDS = tuple(itemgetter(i) for i in range(8))


class _Mover(NamedTuple):
    """Moves declarations of one kind: where their path and start are among their
    ``width`` fields (the end follows the start)."""

    make: Callable[[Iterable[object]], Any]
    width: int
    path_at: int
    start_at: int

    def __call__(self, decls: Sequence[D], by: int, path: str | None) -> Iterator[D]:
        """``decls`` moved by ``by`` characters, of ``path``, made by C code alone: a
        megabyte has thousands of trees."""
        columns: list[Iterator[Any]] = [map(f, decls) for f in _FIELDS[: self.width]]
        columns[self.path_at] = repeat(path)
        add = by.__add__
        s = self.start_at
        columns[s], columns[s + 1] = map(add, columns[s]), map(add, columns[s + 1])
        return map(self.make, zip(*columns, strict=False))


_moved_trees = _Mover(
    partial(_new, TreeDecl), len(TreeDecl._fields), *map(TreeDecl._fields.index, ("path", "start"))
)
_moved_models = _Mover(
    partial(_new, ModelDecl),
    len(ModelDecl._fields),
    *map(ModelDecl._fields.index, ("path", "start")),
)


def _id_span(el: Element) -> tuple[str | None, int, int]:
    a = el.attr("ID")
    if a is None or a.value is None:
        return None, el.name_start, el.name_end
    s, e = el.span_of_value(a)
    return a.value, s, e


def extract(model: Model, path: str | None) -> DocumentFacts:
    """One pass over the elements: trees with their calls, and the model entries."""
    trees: list[TreeDecl] = []
    models: list[ModelDecl] = []
    subtree_models: list[ModelDecl] = []
    tree: _OpenTree | None = None
    entry: _OpenEntry | None = None
    # Members bound once: reading one from its enum class is slow in Python 3.11.
    node, tree_zone, entry_zone, port_zone = Zone.NODE, Zone.TREE, Zone.MODEL_ENTRY, Zone.PORT_DECL
    for el in model.elements:
        zone = el.zone
        if zone == node:
            if tree is not None and el.name == "SubTree":
                a = el.attr("ID")
                if a is not None and a.value:
                    tree.calls.append(a.value)
                    tree.spans.append(el.span_of_value(a))
            continue
        if el.depth <= 1 or zone == entry_zone:
            if tree is not None:
                trees.append(tree.close(path))
                tree = None
            if entry is not None:
                decl = entry.close(path)
                (subtree_models if decl.category == "SubTree" else models).append(decl)
                entry = None
        if zone == tree_zone:
            tid, s, e = _id_span(el)
            if tid:
                tree = _OpenTree(tid, s, e)
        elif zone == entry_zone:
            if el.name in _ENTRY_CATEGORIES:
                mid, s, e = _id_span(el)
                if mid is not None:
                    entry = _OpenEntry(mid, cast("Category", el.name), s, e)
                    # The attribute form of very old models: every other attribute a port.
                    for a in el.attrs:
                        if a.name not in _ENTRY_NON_PORT_ATTRS and a.value is not None:
                            entry.ports.append(PortModel(a.name, "input", "", a.value, ""))
        elif zone == port_zone and entry is not None:
            pname = el.value("name")
            if pname is not None:
                entry.ports.append(
                    PortModel(
                        pname,
                        _DIRECTIONS[el.name],
                        el.value("type") or "",
                        el.value("default"),
                        el.value("description") or el.content or "",
                    )
                )
    if tree is not None:
        trees.append(tree.close(path))
    if entry is not None:
        decl = entry.close(path)
        (subtree_models if decl.category == "SubTree" else models).append(decl)
    return DocumentFacts(path, tuple(trees), tuple(models), tuple(subtree_models))


@dataclass(slots=True)
class _OpenTree:
    id: str
    start: int
    end: int
    calls: list[str] = field(default_factory=list)
    spans: list[tuple[int, int]] = field(default_factory=list)

    def close(self, path: str | None) -> TreeDecl:
        s = self.start
        spans = tuple([(a - s, b - s) for a, b in self.spans])
        return TreeDecl(self.id, path, s, self.end, tuple(self.calls), spans)


@dataclass(slots=True)
class _OpenEntry:
    id: str
    category: Category
    start: int
    end: int
    ports: list[PortModel] = field(default_factory=list)

    def close(self, path: str | None) -> ModelDecl:
        return ModelDecl(self.id, self.category, tuple(self.ports), path, self.start, self.end)
