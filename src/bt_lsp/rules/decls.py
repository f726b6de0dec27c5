"""The declarations one document makes, as plain data: node models and trees.

Shared by the extraction (:mod:`bt_lsp.rules.facts`) and the workspace view that
combines them (:mod:`bt_lsp.rules.context`); here alone so that neither imports the other.
"""

from __future__ import annotations

from array import array
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Final, Literal, NamedTuple

from bt_lsp.rules.builtins import Category, PortModel
from bt_lsp.syntax.sections import Section

#: Where a node model comes from.  Authoritative sources say what BehaviorTree.CPP
#: registers: ``catalog`` (a file named in ``models``/``modelFiles``/``--models``),
#: ``generated`` (a workspace file that is nothing but a ``<TreeNodesModel>``, as
#: ``writeTreeNodesModelXML`` writes it: see :func:`is_generated_catalog`), ``ros`` (the
#: shipped model of a ROS package the document depends on) and ``cpp`` (the project's C++
#: registrations).  Advisory ones say what an author or an editor wrote: ``tree`` (a
#: ``<TreeNodesModel>`` inside a tree file), ``palette`` (a Groot2 ``.btproj``) and
#: ``cpp-partial`` (a C++ registration whose kind, ports or defaults could not all be read)
#: and ``ros-workspace`` (the shipped model of a workspace package whose C++ is read but
#: does not register this node where it was read).
ModelSource = Literal[
    "tree",
    "palette",
    "generated",
    "catalog",
    "ros",
    "ros-workspace",
    "cpp",
    "cpp-partial",
    "cpp-other-package",
]
AUTHORITATIVE: Final[frozenset[str]] = frozenset({"generated", "catalog", "ros", "cpp"})
#: Ends the ``where`` of a model learned from a C++ file that the build does not compile.
NOT_BUILT: Final = " (not built)"
_SOURCE_LABELS: Final[Mapping[str, str]] = MappingProxyType(
    {
        "tree": "the <TreeNodesModel> of a tree file (advisory: BehaviorTree.CPP reads the C++)",
        "palette": "a Groot2 palette (advisory: BehaviorTree.CPP reads the C++)",
        "generated": "a catalog exported by BehaviorTree.CPP (authoritative)",
        "catalog": "a node catalog named in the settings (authoritative)",
        "ros": "the node catalog a ROS package ships (authoritative)",
        "ros-workspace": "the node catalog a workspace ROS package ships (advisory: "
        "BehaviorTree.CPP registers the package's C++, and no registration of this node "
        "was found in it)",
        "cpp": "the project's C++ registration (authoritative)",
        "cpp-partial": "the project's C++ registration (advisory: a static reading could not "
        "know all of it)",
        "cpp-other-package": "the C++ of another workspace package, which this file's package "
        "does not depend on (advisory: BehaviorTree.CPP registers it only if the application "
        "loads that package's nodes, as Nav2 loads its plugin libraries by name)",
    }
)


def source_label(source: str) -> str:
    """What a model source is, for hovers and completion."""
    return _SOURCE_LABELS.get(source, source)


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

    @property
    def registers(self) -> bool:
        """Whether BehaviorTree.CPP is known to register the ID, if not exactly this model:
        an authoritative model, or a C++ registration whose ports (or which of two
        classes) a static reading could not know, in a file that the build compiles."""
        return self.authoritative or (
            self.source == "cpp-partial" and not self.where.endswith(NOT_BUILT)
        )

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
    layout: FactsLayout | None = field(default=None, compare=False, repr=False)


@dataclass(frozen=True, slots=True)
class FactsLayout:
    """The sections and origins facts were made from, and for each section ``k`` the index
    of its first tree, model and SubTree model (``at[k]``; ``at[len(sections)]`` is the
    count)."""

    sections: Sequence[Section]
    origins: Sequence[int]
    trees_at: array[int]  # machine integers: a document may have twenty thousand trees
    models_at: array[int]
    subtree_models_at: array[int]
