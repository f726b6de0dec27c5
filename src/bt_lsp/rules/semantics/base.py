"""What the rule families share: the state of one check and how a node's model is found."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from functools import lru_cache
from types import MappingProxyType
from typing import TYPE_CHECKING, Final, Literal

from bt_lsp.rules.builtins import BUILTINS, Category, NodeModel, PortModel
from bt_lsp.rules.builtins_v3 import V3_BUILTINS, V3_OPTIONAL_PORTS
from bt_lsp.rules.codes import BT, FixData, Severity, define, defined
from bt_lsp.rules.context import Context
from bt_lsp.rules.diagnostics import MAX_DIAGNOSTICS, Diagnostic, cap_key
from bt_lsp.syntax.elements import EXPLICIT_TAGS, Element
from bt_lsp.syntax.model import Model
from bt_lsp.syntax.tokens import Token

if TYPE_CHECKING:
    from bt_lsp.syntax.document import Document

# The codes of these rules (see bt_lsp.rules.registry).
MISSING_ID: Final = define(
    "missing-id",
    Severity.ERROR,
    "a `<BehaviorTree>`, explicit node, `<SubTree>` or model entry has no `ID`",
    BT,
    doc="""
        BehaviorTree.CPP needs an `ID` on a `<SubTree>` call (the tree to call), on a node
        in explicit form (`<Action ID="Dock"/>`), on a `<TreeNodesModel>` `<SubTree>` entry,
        and on a `<BehaviorTree>` when `<root>` has more than one child element. It refuses
        the file when it loads it: `The tag <SubTree> must have the attribute [ID]`,
        `Missing attribute 'ID' in SubTree element within TreeNodesModel`. (An empty
        `ID=""` is `model-name-empty`.)
        """,
    why="The file does not load.",
    bad="""
        <root BTCPP_format="4" main_tree_to_execute="Main">
          <BehaviorTree ID="Main">
            <SubTree/>
          </BehaviorTree>
          <BehaviorTree ID="Dock">
            <AlwaysSuccess/>
          </BehaviorTree>
        </root>
        """,
    good="""
        <root BTCPP_format="4" main_tree_to_execute="Main">
          <BehaviorTree ID="Main">
            <SubTree ID="Dock"/>
          </BehaviorTree>
          <BehaviorTree ID="Dock">
            <AlwaysSuccess/>
          </BehaviorTree>
        </root>
        """,
    since="Every version.",
)


Origin = Literal["builtin", "custom", "subtree"]

#: Rules about what BehaviorTree.CPP 4 defines (built-in ports, load-time checks it added)
#: whose errors are warnings in a document without ``BTCPP_format``, which may be written
#: for version 3.
VERSION_4_RULES: Final[frozenset[str]] = frozenset(
    {
        "undeclared-port",
        "missing-required-port",
        "invalid-port-value",
        "reactive-explicit-child",
        "reactive-async-children",
        "parallel-threshold",
        "blackboard-type-mismatch",
        "port-name-reserved",
    }
)


@dataclass(frozen=True, slots=True)
class Resolved:
    """The model of a node type as the checks need it.

    ``origin`` says where it comes from: a built-in of BehaviorTree.CPP (exact), a custom
    ``<TreeNodesModel>`` entry, or the ``<SubTree>`` model of a tree.  A custom entry is
    exact when its source is authoritative (a catalog of what BehaviorTree.CPP registers,
    ``decl``'s source), else it is what an author declared while BehaviorTree.CPP itself
    reads the C++ registration.
    """

    id: str
    origin: Origin
    category: Category
    ports: Mapping[str, PortModel]
    min_children: int
    max_children: int | None
    required: tuple[str, ...] = ()  # ports that must be given (see ports.py)
    authoritative: bool = False  # a custom model from an authoritative source
    where: str = ""  # where a model learned from C++ is registered (ModelDecl.where)

    @property
    def exact(self) -> bool:
        """Whether BehaviorTree.CPP is known to use exactly this model."""
        return self.origin != "custom" or self.authoritative


#: Of those, what BehaviorTree.CPP 3.8 fails on as well: its XMLParser throws at tree
#: creation for an attribute that is not in the node's manifest ("Possible typo? ...") and
#: for a blackboard entry declared with two port types, and its built-ins throw when they
#: read a port that is missing ("Missing parameter [delay_msec] in DelayNode").
V3_CREATION_RULES: Final[frozenset[str]] = frozenset(
    {"undeclared-port", "missing-required-port", "blackboard-type-mismatch"}
)


def resolve_builtin(type_id: str) -> Resolved | None:
    m = BUILTINS.get(type_id)
    if m is None:
        return None
    return Resolved(
        m.id,
        "builtin",
        m.category,
        {p.name: p for p in m.ports},
        m.min_children,
        m.max_children,
        tuple(p.name for p in m.ports if p.default is None and p.direction != "output"),
    )


_BUILTIN_RESOLVED: Final[Mapping[str, Resolved]] = MappingProxyType(
    {k: r for k in BUILTINS if (r := resolve_builtin(k)) is not None}
)


def _resolve_v3(m: NodeModel) -> Resolved:
    required = tuple(
        p.name
        for p in m.ports
        if p.default is None and p.direction != "output" and (m.id, p.name) not in V3_OPTIONAL_PORTS
    )
    ports = {p.name: p for p in m.ports}
    return Resolved(m.id, "builtin", m.category, ports, m.min_children, m.max_children, required)


#: The built-ins of a BehaviorTree.CPP 3.8 factory (see :mod:`bt_lsp.rules.builtins_v3`).
_BUILTIN_RESOLVED_V3: Final[Mapping[str, Resolved]] = MappingProxyType(
    {k: _resolve_v3(m) for k, m in V3_BUILTINS.items()}
)


# When ``State.out`` holds this many diagnostics, it is cut to the first MAX_DIAGNOSTICS.
_SHRINK_AT: Final = 2 * MAX_DIAGNOSTICS


def is_compact(el: Element) -> bool:
    return el.name not in EXPLICIT_TAGS and el.name != "SubTree"


# What a rule gave State.add: start, end, code, message, severity, data.
Finding = tuple[int, int, str, str, Severity | None, FixData | None]
# A node tag, its number of children and what the node checks found there (offsets from
# the tag's start), or ``False`` when that depends on more than the tag.
TagFindings = tuple[Token, int, tuple[Finding, ...] | Literal[False]]


@dataclass(slots=True)
class State:
    """One run of the checks over one document."""

    doc: Document
    ctx: Context
    model: Model
    text: str
    out: list[Diagnostic] = field(default_factory=list)
    v4: bool = False  # <root> declares BTCPP_format
    v3: bool = False  # the project builds against BehaviorTree.CPP 3 (ctx.btcpp_version)
    _types: dict[str, Resolved | None] = field(default_factory=dict)
    _subtrees: dict[str, Resolved | None] = field(default_factory=dict)
    # Models resolved from declarations, shared by the runs over the sections of one check:
    # by ("model" | "subtree", ID), with the declaration they were made from (still looked
    # up in each run, so that the run records what it read).
    made: dict[tuple[str, str], tuple[object, Resolved]] = field(default_factory=dict)
    # A run over one section of the document (see sections.py) has the section's model and
    # text, in coordinates that start at document offset ``origin``.
    origin: int = 0
    uses_lines: bool = False  # whether a message names a line (see line_of)
    # How many diagnostics were found and not kept in ``out``: only the first
    # MAX_DIAGNOSTICS by severity, then position (cap_key) are ever published, so no more
    # are kept (see add).
    more: int = 0
    # Once ``out`` holds MAX_DIAGNOSTICS: the cap_key of its last diagnostic by that
    # order, which a later one must be below to be kept (an equal one sorts after it).
    limit: tuple[int, int, int, str] | None = None
    # What a rule found for a name, by its own key, so that a document repeating the name
    # a hundred thousand times costs one finding (the run over one section records
    # what it read, so each run has its own).
    memo: dict[object, object] = field(default_factory=dict)
    # While a node's checks run to be remembered for its start tag (see
    # semantics.check_elements): what they add, as given to add, and whether they read
    # only the tag and the number of children (``pure``; a rule that reads anything else
    # clears it).
    record: list[Finding] | None = None
    pure: bool = True
    # The findings of node tags (see semantics.check_elements), by the tag's id, for this
    # run and, ``shared_tags``, for every run of one check (those that looked nothing up
    # in the context: ``lookups`` counts the lookups of a run's context, when it counts).
    tags: dict[int, TagFindings] = field(default_factory=dict)
    shared_tags: dict[int, TagFindings] | None = None
    lookups: list[int] | None = None

    def line_of(self, offset: int) -> int:
        """The 0-based document line of ``offset`` (in this run's coordinates).  Messages
        that name a line depend on where their section is: the section's results are kept
        only as long as it starts on the same line."""
        self.uses_lines = True
        self.pure = False
        return self.doc.lines.line_of(self.origin + offset)

    def add(
        self,
        start: int,
        end: int,
        code: str,
        message: str,
        severity: Severity | None = None,
        data: FixData | None = None,
    ) -> None:
        if self.record is not None:
            self.record.append((start, end, code, message, severity, data))
        sev = defined(code).severity if severity is None else severity
        downgraded = (
            sev == Severity.ERROR
            and not self.v4
            and code in VERSION_4_RULES
            and not (self.v3 and code in V3_CREATION_RULES)
        )
        if downgraded:
            sev = Severity.WARNING
        limit = self.limit
        if limit is not None and (sev, start, end, code) >= limit:
            self.more += 1  # after the first MAX_DIAGNOSTICS kept: never kept
            return
        if downgraded:
            if self.v3:
                message += " (a check BehaviorTree.CPP 4 makes; this project builds against 3)"
            elif self.ctx.btcpp_unclear:
                message += (
                    " (a check BehaviorTree.CPP 4 makes; the project's build names both "
                    "BehaviorTree.CPP 3 and 4, so its version is unclear)"
                )
            else:
                message += (
                    " (checked against BehaviorTree.CPP 4; this document has no BTCPP_format)"
                )
        out = self.out
        out.append(Diagnostic(start, end, code, message, sev, data))
        if len(out) == MAX_DIAGNOSTICS and limit is None:
            self.limit = max(map(cap_key, out))  # one at or after it is the cap's + 1st
        elif len(out) >= _SHRINK_AT:  # keep the first by cap_key (a stable sort)
            out.sort(key=cap_key)
            self.more += len(out) - MAX_DIAGNOSTICS
            del out[MAX_DIAGNOSTICS:]
            self.limit = cap_key(out[-1])

    def resolve(self, type_id: str) -> Resolved | None:
        """The model of node type ``type_id``: built-in first (of the project's
        BehaviorTree.CPP version), then a custom declaration."""
        r = (_BUILTIN_RESOLVED_V3 if self.v3 else _BUILTIN_RESOLVED).get(type_id)
        if r is not None:
            return r
        if type_id in self._types:
            return self._types[type_id]
        decl = self.ctx.models.get(type_id)
        res: Resolved | None = None
        made = self.made.get(("model", type_id))
        if made is not None and made[0] is decl:
            res = made[1]
        elif decl is not None:
            lo, hi = decl.child_range
            required = tuple(
                p.name for p in decl.ports if p.default is None and p.direction != "output"
            )
            res = Resolved(
                decl.id,
                "custom",
                decl.category,
                {p.name: p for p in decl.ports},
                lo,
                hi,
                required,
                decl.authoritative,
                decl.where,
            )
            self.made["model", type_id] = (decl, res)
        self._types[type_id] = res
        return res

    def resolve_subtree(self, tree_id: str) -> Resolved | None:
        """The ``<TreeNodesModel><SubTree>`` model of tree ``tree_id``, if declared."""
        if tree_id in self._subtrees:
            return self._subtrees[tree_id]
        decl = self.ctx.subtree_models.get(tree_id)
        res = None
        made = self.made.get(("subtree", tree_id))
        if made is not None and made[0] is decl:
            res = made[1]
        elif decl is not None:
            # BehaviorTree.CPP treats an empty default of a SubTree model port as none.
            required = tuple(p.name for p in decl.ports if not p.default)
            ports = {p.name: p for p in decl.ports}
            res = Resolved(decl.id, "subtree", "SubTree", ports, 0, 0, required)
            self.made["subtree", tree_id] = (decl, res)
        self._subtrees[tree_id] = res
        return res

    def node_type(self, el: Element) -> str | None:
        """The registration ID a node element asks for (``None`` when it has none)."""
        if is_compact(el):
            return el.name
        return el.value("ID")


def quoted(text: str, limit: int = 60) -> str:
    """``text`` in single quotes for a message, control characters shown, long text cut."""
    shown = "".join(c if c.isprintable() else f"\\u{ord(c):04x}" for c in text)
    if len(shown) > limit:
        shown = shown[: limit - 1] + "…"
    return f"'{shown}'"


@lru_cache(maxsize=65536)  # the same names are compared again in every document
def edit_distance(a: str, b: str, limit: int) -> int:
    """Levenshtein distance of ``a`` and ``b``; any value above ``limit`` is ``limit + 1``.

    Only the cells within ``limit`` of the diagonal are computed (the others are above the
    limit anyway), so a check against hundreds of names stays cheap."""
    la, lb = len(a), len(b)
    if abs(la - lb) > limit:
        return limit + 1
    if a == b:
        return 0
    big = limit + 1
    prev = [j if j <= limit else big for j in range(lb + 1)]
    for i in range(1, la + 1):
        ca = a[i - 1]
        lo = i - limit if i > limit else 1
        hi = i + limit if i + limit < lb else lb
        cur = [big] * (lb + 1)
        best = cur[0] = i if i <= limit else big
        for j in range(lo, hi + 1):
            v = prev[j - 1] + (ca != b[j - 1])
            x = prev[j] + 1
            if x < v:
                v = x
            x = cur[j - 1] + 1
            if x < v:
                v = x
            if v > big:
                v = big
            cur[j] = v
            if v < best:
                best = v
        if best > limit:
            return big
        prev = cur
    return prev[lb] if prev[lb] < big else big


@dataclass(slots=True)
class BlackboardUse:
    """The first port that used a blackboard key in a tree: its type and where."""

    type: str  # canonical type name
    shown: str  # as written
    exact: bool  # from a built-in model
    port: str
    node: str
    # Whether the type names only what cannot be an alias (see port_types.is_closed), or
    # comes from a catalog BehaviorTree.CPP exported (demangled: aliases resolved).
    closed: bool = True


@dataclass(slots=True)
class TreeScope:
    """What the checks remember while inside one ``<BehaviorTree>``."""

    element: Element | None
    subtree_names: dict[str, Element] = field(default_factory=dict)
    depth_flagged: list[bool] = field(default_factory=lambda: [False])
    keys: dict[str, BlackboardUse] = field(default_factory=dict)
