"""Link the facts of many C++ files into a node catalog.

Each registration becomes a :class:`CppNode`: its ID, the class, the kind (from the base
class, through project base classes in any file), and its ports, read from the class's
``providedPorts`` (or an inherited one, ``using Base::providedPorts``, ``providedBasicPorts``
of a base, ``Base::providedPorts()`` plus ``insert``), with port names from constants
scoped to their class.  What cannot be known statically is said by a flag on the node
and a note, never guessed: such a node is advisory, one without flags authoritative.
A class that is never registered is not in the catalog.
"""

from __future__ import annotations

import re
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Final, NamedTuple

from bt_lsp.cpp.facts import (
    ClassFacts,
    FileFacts,
    Helper,
    MacroTemplate,
    Op,
    PortFacts,
    PortsFn,
    Registration,
    Span,
)
from bt_lsp.cpp.literals import to_str
from bt_lsp.cpp.names import last_name, split_top, strip_args
from bt_lsp.cpp.types import Bases, TypeNames

__all__ = [
    "FLAG_DEFAULT_EXPRESSION",
    "FLAG_DUPLICATE_ID",
    "FLAG_KIND_UNKNOWN",
    "FLAG_NOT_BUILT",
    "FLAG_PORTS_INCOMPLETE",
    "Catalog",
    "CppNode",
    "CppPort",
    "Unresolved",
    "link",
]

FLAG_KIND_UNKNOWN: Final = "kind-unknown"
FLAG_PORTS_INCOMPLETE: Final = "ports-incomplete"
FLAG_DEFAULT_EXPRESSION: Final = "default-expression"
FLAG_DUPLICATE_ID: Final = "duplicate-id"
# Registered in a source file that the project's build does not compile (its CMake lists
# the sources of every target, and not this one): not one of the project's nodes.
FLAG_NOT_BUILT: Final = "not-built"
# The flags that make a node advisory: every one (a default written as an expression is
# text bt-lsp cannot show as BehaviorTree.CPP would).
_ADVISORY: Final = frozenset(
    {
        FLAG_KIND_UNKNOWN,
        FLAG_PORTS_INCOMPLETE,
        FLAG_DUPLICATE_ID,
        FLAG_DEFAULT_EXPRESSION,
        FLAG_NOT_BUILT,
    }
)
# Files compiled on their own (a class defined in one is seen by no other file).
_SOURCE_SUFFIXES: Final = (".cpp", ".cc", ".cxx", ".c++")

# BehaviorTree.CPP's base classes (4.x and 3.x names) and the kind each gives.
LIBRARY_KINDS: Final[dict[str, str]] = {
    "ActionNodeBase": "Action",
    "SyncActionNode": "Action",
    "SimpleActionNode": "Action",
    "StatefulActionNode": "Action",
    "CoroActionNode": "Action",
    "ThreadedAction": "Action",
    "AsyncActionNode": "Action",
    "ConditionNode": "Condition",
    "SimpleConditionNode": "Condition",
    "ControlNode": "Control",
    "DecoratorNode": "Decorator",
    "SimpleDecoratorNode": "Decorator",
}
_MAX_DEPTH: Final = 16
_SIMPLE_KINDS: Final = {
    "registerSimpleAction": "Action",
    "registerSimpleCondition": "Condition",
    "registerSimpleDecorator": "Decorator",
}


@dataclass(frozen=True, slots=True)
class CppPort:
    """A port as the C++ declares it; ``span`` is its name argument's.

    ``resolved`` is ``type`` with the project's aliases followed and its classes
    qualified, as far as the C++ read says (:mod:`bt_lsp.cpp.types`); ``classes`` the
    class definitions read that it names.
    """

    name: str
    direction: str
    type: str
    default: str | None
    description: str
    path: str
    span: Span
    default_is_expr: bool = False
    resolved: str | None = None
    classes: frozenset[str] = frozenset()


@dataclass(frozen=True, slots=True)
class CppNode:
    """A registered node type.

    ``kind`` is ``None`` when the base class could not be followed to BehaviorTree.CPP's.
    ``flags`` say what the reading could not know (``notes`` say why, for people);
    ``authoritative`` is true when there is no advisory flag.
    """

    id: str
    kind: str | None
    cls: str | None
    ports: tuple[CppPort, ...]
    flags: tuple[str, ...]
    notes: tuple[str, ...]
    form: str
    path: str
    id_span: Span
    class_path: str | None = None
    class_span: Span | None = None

    @property
    def authoritative(self) -> bool:
        return not any(f in _ADVISORY for f in self.flags)

    def port(self, name: str) -> CppPort | None:
        for p in self.ports:
            if p.name == name:
                return p
        return None


class Unresolved(NamedTuple):
    """A registration whose ID is not a literal or a known constant."""

    path: str
    span: Span
    form: str
    text: str


@dataclass(frozen=True, slots=True)
class Catalog:
    nodes: tuple[CppNode, ...] = ()
    unresolved: tuple[Unresolved, ...] = ()
    by_id: dict[str, CppNode] = field(default_factory=dict)
    missing: frozenset[str] = frozenset()


class _Class(NamedTuple):
    path: str
    facts: ClassFacts


class _Lib(NamedTuple):
    kind: str


_Resolved = tuple[_Class | _Lib | None, dict[str, str]]


class _Ports:
    """A port list being built: first key wins, reasons for what is missing."""

    def __init__(self) -> None:
        self.ports: dict[str, CppPort] = {}
        self.missing: list[str] = []

    def add(self, p: CppPort) -> None:
        self.ports.setdefault(p.name, p)

    def merge(self, other: _Ports) -> None:
        for p in other.ports.values():
            self.add(p)
        self.missing.extend(other.missing)


class LinkMemo:
    """What the last link made of each registration, to link again only what a change
    touches: a node is made again when its registration changed or when a changed file
    defines (or defined) a name its making looked up (a class, a ``providedPorts``
    function, a constant, a macro); any other is kept as it was."""

    def __init__(self) -> None:
        self.facts: dict[str, FileFacts] = {}
        self.not_built: Mapping[str, str] = {}
        # (path, index of the registration) -> (registration, ID, node, names, missing)
        self.nodes: dict[tuple[str, int], _Made] = {}
        self.made = 0  # nodes made (not kept) by the last link, for tests and benchmarks


class _Made(NamedTuple):
    reg: Registration
    id: str
    node: CppNode
    names: frozenset[str]
    missing: frozenset[str]


def _defined(f: FileFacts) -> set[str]:
    """The names a file defines, as :class:`_Linker` notes its lookups."""
    out = {"c:" + c.name for c in f.classes}
    out.update(f"f:{last_name(fn.owner)}::{fn.name}" for fn in f.fns)
    out.update("k:" + k for k in f.constants)
    out.update("m:" + m.name for m in f.macros)
    out.update("h:" + h.name for h in f.helpers)
    out.update("t:" + last_name(a.name) for a in f.aliases)
    return out


def link(
    files: Iterable[tuple[str, FileFacts]],
    library: Iterable[tuple[str, FileFacts]] = (),
    memo: LinkMemo | None = None,
    not_built: Mapping[str, str] | None = None,
) -> Catalog:
    """The catalog of the nodes registered in ``files``.

    ``library`` files (known bases of libraries that are not in the sources) resolve
    classes after the project's own and never register anything.  With a ``memo`` of
    the last link, the nodes no change touches are kept (and the memo is updated).
    ``not_built`` are the files the build does not compile, each with why: their
    registrations come after the others' and are flagged :data:`FLAG_NOT_BUILT`, and
    their classes and port lists are used only when no compiled file has one.
    """
    return _Linker(list(files), list(library), memo, not_built or {}).run()


class _Linker:
    def __init__(
        self,
        files: list[tuple[str, FileFacts]],
        library: list[tuple[str, FileFacts]],
        memo: LinkMemo | None = None,
        not_built: Mapping[str, str] | None = None,
    ) -> None:
        self.not_built: Mapping[str, str] = not_built or {}
        # The compiled files' registrations first: an ID is theirs before an unbuilt copy's.
        self.files = sorted(files, key=lambda pf: pf[0] in self.not_built)
        self.memo = memo
        if memo is not None and memo.not_built != self.not_built:
            memo.nodes = {}  # what is built changed: every node is made again
        # The names the node being made looked up, and those it found missing.
        self._names: set[str] = set()
        self._missing: set[str] = set()
        self._stale: set[str] = set()  # names that changed files define or defined
        if memo is not None:
            now = dict(files)
            for path in now.keys() | memo.facts.keys():
                old, new = memo.facts.get(path), now.get(path)
                if old is not new:
                    for f in (old, new):
                        if f is not None:
                            self._stale.update(_defined(f))
        self.classes: dict[str, list[_Class]] = {}
        self.fns: dict[tuple[str, str], list[tuple[str, PortsFn]]] = {}
        self.file_constants: dict[str, dict[str, str]] = {}
        self.constants: dict[str, str] = {}
        self.macros: dict[str, MacroTemplate] = {}
        self.helpers: dict[str, list[Helper]] = {}
        self._called: set[str] = set()  # helpers whose calls were read
        self._library = {path for path, _ in library}
        # Class and constant names looked up and not found: the project layer reads the
        # files that may define them (lazily: most files declare no node) and links again.
        self.missing: set[str] = set()
        self._resolved: dict[
            tuple[str, int, str], tuple[_Class | _Lib | None, dict[str, str], frozenset[str]]
        ] = {}
        for path, f in [*files, *library]:
            for c in f.classes:
                self.classes.setdefault(c.name, []).append(_Class(path, c))
            for fn in f.fns:
                key = (last_name(fn.owner), fn.name)
                self.fns.setdefault(key, []).append((path, fn))
            self.file_constants[path] = f.constants
            for k, v in f.constants.items():
                self.constants.setdefault(k, v)
            for m in f.macros:
                self.macros.setdefault(m.name, m)
            for h in f.helpers:
                self.helpers.setdefault(h.name, []).append(h)
        # The project's own type names (not the library bases', whose members are not read).
        self.types = TypeNames(files, self._type_bases)

    # --- registrations -----------------------------------------------------------------

    def run(self) -> Catalog:
        nodes: list[CppNode] = []
        unresolved: list[Unresolved] = []
        by_id: dict[str, CppNode] = {}
        made: dict[tuple[str, int], _Made] = {}
        if self.memo is not None:
            self.memo.made = 0
        for path, f in self.files:
            for i, reg in enumerate(self._registrations(f)):
                id_ = reg.id if reg.id is not None else self._constant(reg.id_ref or "", None, path)
                if id_ is None:
                    unresolved.append(Unresolved(path, reg.id_span, reg.form, reg.id_ref or ""))
                    continue
                node = self._kept_or_made(path, i, reg, id_, made)
                first = by_id.get(id_)
                if first is not None and _same(first, node):
                    pass  # the same class registered again (a plugin and a test, copies)
                elif first is not None:
                    note = f"ID {id_!r} is also registered at {_where(first.path, first.id_span)}"
                    node = _with_flag(node, FLAG_DUPLICATE_ID, note)
                    unbuilt = " (a file that is not built)" if path in self.not_built else ""
                    by_id[id_] = _with_flag(
                        first,
                        FLAG_DUPLICATE_ID,
                        f"ID {id_!r} is also registered at {_where(path, reg.id_span)}{unbuilt}",
                    )
                    nodes[nodes.index(first)] = by_id[id_]
                else:
                    by_id[id_] = node
                nodes.append(node)
        # A helper that takes the ID from its callers, with no call read: it registers
        # from code not read (or a call not recognised), under IDs not known.
        for path, f in self.files:
            for h in f.helpers:
                if h.id_param >= 0 and h.name not in self._called:
                    unresolved.append(Unresolved(path, h.span, h.form, f"{h.name}(…)"))
        if self.memo is not None:
            self.memo.facts = dict(self.files)
            self.memo.nodes = made
            self.memo.not_built = dict(self.not_built)
        return Catalog(tuple(nodes), tuple(unresolved), by_id, frozenset(self.missing))

    def _kept_or_made(
        self, path: str, i: int, reg: Registration, id_: str, made: dict[tuple[str, int], _Made]
    ) -> CppNode:
        """The node of a registration: the last link's when nothing it rests on changed."""
        if self.memo is None:
            return self._node(path, reg, id_)
        last = self.memo.nodes.get((path, i))
        if last is not None and last.id == id_ and last.reg == reg and not last.names & self._stale:
            self.missing.update(last.missing)
            made[path, i] = last
            return last.node
        self._names, self._missing = set(), set()
        node = self._node(path, reg, id_)
        made[path, i] = _Made(reg, id_, node, frozenset(self._names), frozenset(self._missing))
        self.memo.made += 1
        return node

    def _note(self, name: str) -> None:
        self._names.add(name)

    def _miss(self, name: str) -> None:
        self.missing.add(name)
        self._missing.add(name)

    def _registrations(self, f: FileFacts) -> list[Registration]:
        regs = list(f.registrations)
        for call in f.macro_calls:
            m = self.macros.get(call.name)  # a change of it changes the registration
            if m is None or len(call.args) != len(m.params) or m.cls_param >= len(call.args):
                continue
            if m.form not in ("registerNodeType", "registerBuilder", *self.helpers):
                continue  # the function or class it calls registers nothing
            self._called.add(m.form)
            cls = call.args[m.cls_param]
            if m.cls_text:
                args = dict(zip(m.params, call.args, strict=False))
                cls = "::".join(args.get(part, part) for part in m.cls_text.split("::"))
            if m.id_param >= 0:
                arg = call.args[m.id_param]
                span = call.arg_spans[m.id_param]
                if m.stringify:
                    id_, ref = arg, None
                elif arg.startswith('"'):
                    id_, ref = arg[1:-1], None
                else:
                    id_, ref = None, arg
            else:
                id_, ref, span = m.id_literal, None, call.span
            regs.append(Registration(m.name, id_, ref, span, cls, None, None, call.span))
        for hc in f.helper_calls:
            for h in self.helpers.get(hc.name, ()):
                if h.cls_tparam >= len(hc.targs) or h.id_param >= len(hc.args):
                    continue  # another overload
                self._called.add(h.name)
                hcls = hc.targs[h.cls_tparam] if h.cls_tparam >= 0 else h.cls
                if h.id_param >= 0:
                    id_, ref = hc.values[h.id_param], None
                    if id_ is None:
                        ref = hc.args[h.id_param]
                    span = hc.arg_spans[h.id_param]
                else:
                    id_, ref, span = h.id_literal, None, hc.span
                kind = None if hcls is not None else _SIMPLE_KINDS.get(h.form)
                regs.append(Registration(h.name, id_, ref, span, hcls, kind, h.ops, hc.span))
        return regs

    def _node(self, path: str, reg: Registration, id_: str) -> CppNode:
        flags: list[str] = []
        notes: list[str] = []
        kind = reg.kind
        cls_name: str | None = None
        class_path: str | None = None
        class_span: Span | None = None
        ports = _Ports()
        if reg.cls is None:
            self._eval(reg.ops or (), None, {}, path, ports, None, 0)
        else:
            target, subst = self._resolve(reg.cls, None, path)
            if isinstance(target, _Class):
                cls_name = target.facts.qualname
                class_path, class_span = target.path, target.facts.span
                kind, why = self._kind(target, 0, subst)
                if kind is None:
                    flags.append(FLAG_KIND_UNKNOWN)
                    notes.append(why)
                if reg.ops is not None:
                    self._eval(reg.ops, target, subst, path, ports, None, 0)
                else:
                    ports.merge(self._ports_of(target, subst, 0))
            elif isinstance(target, _Lib):
                kind = target.kind
                cls_name = reg.cls
            else:
                cls_name = reg.cls
                flags += [FLAG_KIND_UNKNOWN, FLAG_PORTS_INCOMPLETE]
                notes.append(f"class {reg.cls} is not in the sources read")
        if ports.missing and FLAG_PORTS_INCOMPLETE not in flags:
            flags.append(FLAG_PORTS_INCOMPLETE)
            notes.extend(dict.fromkeys(ports.missing))
        if any(p.default_is_expr for p in ports.ports.values()):
            flags.append(FLAG_DEFAULT_EXPRESSION)
            notes.append(
                "a default is an expression: its value is known only when the program runs"
            )
        if path in self.not_built:
            flags.append(FLAG_NOT_BUILT)
            notes.append(self.not_built[path])
        return CppNode(
            id_,
            kind,
            cls_name,
            tuple(ports.ports.values()),
            tuple(flags),
            tuple(notes),
            reg.form,
            path,
            reg.id_span,
            class_path,
            class_span,
        )

    # --- classes -----------------------------------------------------------------------

    def _resolve(self, ref: str, ctx: _Class | None, path: str, depth: int = 0) -> _Resolved:
        """The class ``ref`` names (as written, maybe with template arguments)."""
        key = (ref, id(ctx.facts) if ctx is not None else 0, path)
        hit = self._resolved.get(key)
        if hit is None:
            outer = self._names
            self._names = set()
            found = self._resolve_uncached(ref, ctx, path, depth)
            hit = self._resolved[key] = (found[0], found[1], frozenset(self._names))
            self._names = outer
        self._names.update(hit[2])  # what resolving it looked up, for the memo
        return hit[0], dict(hit[1])

    def _resolve_uncached(self, ref: str, ctx: _Class | None, path: str, depth: int) -> _Resolved:
        ref = ref.strip().removeprefix("typename ").removeprefix("class ").strip()
        base = strip_args(ref)
        if ctx is not None and depth < _MAX_DEPTH:
            first = base.split("::", 1)[0]
            alias = ctx.facts.aliases.get(first)
            if alias is not None and alias != ref:
                return self._resolve(alias, None, path, depth + 1)
        last = last_name(base)
        self._note("c:" + last)
        cands = self.classes.get(last, [])
        if last in LIBRARY_KINDS:  # BehaviorTree.CPP's own bases end every lineage
            return _Lib(LIBRARY_KINDS[last]), {}
        if not cands:
            self._miss(last)
            return None, {}
        chosen = self._choose(cands, base, ctx, path)
        args = _args_of_last(ref)
        params = chosen.facts.template_params
        subst = dict(zip(params, args, strict=False)) if args else {}
        return chosen, subst

    def _choose(self, cands: list[_Class], base: str, ctx: _Class | None, path: str) -> _Class:
        if len(cands) == 1:
            return cands[0]
        if "::" in base:
            exact = [c for c in cands if ("::" + c.facts.qualname).endswith("::" + base)]
            if exact:
                cands = exact
        if ctx is not None:
            ns = ctx.facts.qualname.rsplit("::", 1)[0] if "::" in ctx.facts.qualname else ""
            same = [c for c in cands if c.facts.qualname.rsplit("::", 1)[0] == ns]
            if same:
                cands = same
        same_file = [c for c in cands if c.path == path]
        if same_file:
            return same_file[0]
        # A class defined in another source file is not seen from this one (but through
        # a header); one the build compiles before one it does not.
        seen = [c for c in cands if not c.path.endswith(_SOURCE_SUFFIXES)] or cands
        built = [c for c in seen if c.path not in self.not_built] or seen
        return built[0]

    def _lineage(
        self, cls: _Class, depth: int, outer: dict[str, str] | None = None
    ) -> tuple[_Class | _Lib | None, dict[str, str], str]:
        """The base through which ``cls`` descends from a BehaviorTree.CPP node class.

        ``outer`` gives ``cls``'s template arguments: a base that is a template parameter
        (``template <class B> class Logged : public B``) is the argument given.
        """
        unknown: list[str] = []
        for b in cls.facts.bases:
            ref = _substitute(b, outer) if outer else b
            target, subst = self._resolve(ref, cls, cls.path)
            if isinstance(target, _Lib):
                return target, subst, ""
            if isinstance(target, _Class) and target.facts is not cls.facts and depth < _MAX_DEPTH:
                k, _ = self._kind(target, depth + 1, _compose(subst, outer or {}))
                if k is not None:
                    return target, subst, ""
                unknown.append(b)
            elif target is None:
                unknown.append(b)
        if not cls.facts.bases:
            return None, {}, f"class {cls.facts.qualname} has no base class"
        bases = ", ".join(unknown) or cls.facts.bases[0]
        return None, {}, f"base class {bases} of {cls.facts.qualname} is not in the sources read"

    def _kind(
        self, cls: _Class, depth: int, subst: dict[str, str] | None = None
    ) -> tuple[str | None, str]:
        if depth > _MAX_DEPTH:
            return None, "base classes nest too deep"
        target, s2, why = self._lineage(cls, depth, subst)
        if isinstance(target, _Lib):
            return target.kind, ""
        if isinstance(target, _Class):
            return self._kind(target, depth + 1, _compose(s2, subst or {}))
        return None, why

    def _fn(self, cls: _Class, name: str) -> tuple[str, PortsFn] | None:
        found = self._fns(cls, name)
        return found[0] if found else None

    def _fns(self, cls: _Class, name: str) -> list[tuple[str, PortsFn]]:
        """Every definition of ``cls::name`` read (one, but for copies and ``#if`` branches)."""
        self._note(f"f:{cls.facts.name}::{name}")
        found = self.fns.get((cls.facts.name, name), [])
        q = cls.facts.qualname
        out = [
            (path, fn)
            for path, fn in found
            if (fn.owner == q or q.endswith("::" + fn.owner) or fn.owner.endswith("::" + q))
            and (path == cls.path or not self._defines_other(path, cls))
        ]
        if cls.path.endswith(_SOURCE_SUFFIXES) and any(path == cls.path for path, _ in out):
            # A class defined in a source file: its functions are defined there (no other
            # file sees the class).
            out = [(path, fn) for path, fn in out if path == cls.path]
        # A definition in a file the build compiles wins over one in a file it does not.
        built = [(path, fn) for path, fn in out if path not in self.not_built]
        return built or out

    def _defines_other(self, path: str, cls: _Class) -> bool:
        """Whether the source file ``path`` defines another class of ``cls``'s name (whose
        own functions its definitions there are: no other file sees that class).  Two
        headers that define one class differently stay two definitions of it: which one
        a registering file includes is not read."""
        return path.endswith(_SOURCE_SUFFIXES) and any(
            c.path == path and c.facts is not cls.facts and c.facts.qualname == cls.facts.qualname
            for c in self.classes.get(cls.facts.name, ())
        )

    def _other_definition(self, cls: _Class, name: str, first: tuple[str, PortsFn]) -> str | None:
        """Where another definition of ``cls::name`` that reads differently is, if any."""
        shape = _shape(first[1].ops)
        for path, fn in self._fns(cls, name):
            if fn is not first[1] and _shape(fn.ops) != shape:
                return _where(path, fn.span)
        return None

    def _ports_of(self, cls: _Class, subst: dict[str, str], depth: int) -> _Ports:
        """What ``cls::providedPorts()`` returns."""
        out = _Ports()
        if depth > _MAX_DEPTH:
            out.missing.append("base classes nest too deep")
            return out
        own = self._fn(cls, "providedPorts")
        if own is not None:
            self._eval(own[1].ops, cls, subst, own[0], out, None, depth)
            other = self._other_definition(cls, "providedPorts", own)
            if other is not None:
                out.missing.append(
                    f"{cls.facts.qualname}::providedPorts() is defined differently in "
                    f"{_where(own[0], own[1].span)} and {other}: which one is built is not known"
                )
            return out
        if "providedPorts" in cls.facts.declared:
            # Declared in the class, defined out of line in a file that was not read: its
            # ports are unknown, never "none" (nor the base's, which it hides).
            out.missing.append(
                f"{cls.facts.qualname}::providedPorts() is declared at "
                f"{_where(cls.path, cls.facts.span)} but its definition is not in the C++ read"
            )
            return out
        if cls.facts.using_ports:
            using = _substitute(cls.facts.using_ports, subst)
            target, s2 = self._resolve(using, cls, cls.path)
            self._ports_from(target, _compose(s2, subst), out, cls.facts.using_ports, depth)
            return out
        target, s2, why = self._lineage(cls, depth, subst)
        if target is None:
            out.missing.append(why)
            return out
        self._ports_from(target, _compose(s2, subst), out, "", depth)
        return out

    def _ports_from(
        self, target: _Class | _Lib | None, subst: dict[str, str], out: _Ports, ref: str, depth: int
    ) -> None:
        if isinstance(target, _Class):
            out.merge(self._ports_of(target, subst, depth + 1))
        elif target is None:
            out.missing.append(f"{ref}::providedPorts() is not in the sources read")

    def _basic(
        self, cls: _Class | None, ref: str, depth: int, outer: dict[str, str]
    ) -> tuple[_Class, tuple[str, PortsFn], dict[str, str]] | None:
        """The ``providedBasicPorts`` that a call in ``cls`` (whose template arguments
        ``outer`` gives) reaches, with the substitution of its class."""
        start: _Class | None = cls
        subst = dict(outer)
        if ref and cls is not None:
            t, s2 = self._resolve(_substitute(ref, outer), cls, cls.path)
            subst = _compose(s2, outer)
            start = t if isinstance(t, _Class) else None
        cur = start
        for _ in range(_MAX_DEPTH):
            if cur is None:
                return None
            fn = self._fn(cur, "providedBasicPorts")
            if fn is not None:
                return cur, fn, subst
            if "providedBasicPorts" in cur.facts.declared:
                return None  # defined out of line in a file that was not read
            target, s2, _ = self._lineage(cur, depth, subst)
            if not isinstance(target, _Class):
                return None
            subst = _compose(s2, subst)
            cur = target
        return None

    # --- port lists --------------------------------------------------------------------

    def _eval(
        self,
        ops: Sequence[Op],
        cls: _Class | None,
        subst: dict[str, str],
        path: str,
        out: _Ports,
        arg: _Ports | None,
        depth: int,
    ) -> None:
        for op in ops:
            if op.kind == "port" and op.port is not None:
                p = self._port(op.port, cls, subst, path)
                if p is None:
                    out.missing.append(f"port name {op.port.name_ref} is not a known constant")
                else:
                    out.add(p)
            elif op.kind == "ref":
                if cls is None:
                    out.missing.append(f"{op.ref}::providedPorts() is not in the sources read")
                elif not op.ref:
                    target, s2, why = self._lineage(cls, depth, subst)
                    if target is None:
                        out.missing.append(why)
                    self._ports_from(target, _compose(s2, subst), out, cls.facts.qualname, depth)
                else:
                    target, s2 = self._resolve(_substitute(op.ref, subst), cls, path)
                    if isinstance(target, _Class) and target.facts is cls.facts:
                        target, s2, _ = self._lineage(cls, depth, subst)
                    self._ports_from(target, _compose(s2, subst), out, op.ref, depth)
            elif op.kind == "basic":
                inner = _Ports()
                self._eval(op.ops, cls, subst, path, inner, arg, depth)
                found = self._basic(cls, op.ref, depth, subst) if depth < _MAX_DEPTH else None
                if found is None:
                    out.merge(inner)
                    owner = op.ref or (cls.facts.qualname if cls else "")
                    out.missing.append(
                        f"providedBasicPorts() of a base of {owner} is not in the sources read"
                    )
                else:
                    bcls, (bpath, fn), s2 = found
                    self._eval(fn.ops, bcls, s2, bpath, out, inner, depth + 1)
                    if not _uses_param(fn.ops):
                        # A body that was not read (a library base whose basic ports
                        # depend on its release): the node's own ports are still among
                        # what it returns, as in every providedBasicPorts.
                        out.merge(inner)
            elif op.kind == "param":
                if arg is not None:
                    out.merge(arg)
            else:
                out.missing.append(f"cannot read {op.ref!r} statically")

    def _port(
        self, p: PortFacts, cls: _Class | None, subst: dict[str, str], path: str
    ) -> CppPort | None:
        name = p.name if p.name is not None else self._constant(p.name_ref or "", cls, path)
        if name is None:
            return None
        type_ = _substitute(p.type, subst) if p.type is not None else "AnyTypeAllowed"
        default = p.default
        if default is not None and p.default_literal:
            default = to_str(default, type_)  # as BehaviorTree.CPP shows it
        # Names are looked up from the class the port list belongs to; a template argument
        # put in comes from another scope, and a simple node's from the registering call:
        # then only names the project defines once are found.
        scope = cls.facts.qualname if cls is not None and type_ == p.type else None
        found = self.types.resolve(type_, scope)
        for n in found.names:
            self._note("c:" + n)
            self._note("t:" + n)
        for n in found.missing:
            self._miss(n)
        return CppPort(
            name,
            p.direction,
            type_,
            default,
            p.description,
            path,
            p.name_span,
            p.default_is_expr,
            found.text,
            found.classes,
        )

    def _type_bases(self, qualname: str) -> Bases:
        """The bases of the project class ``qualname``, for :class:`TypeNames`."""
        last = last_name(qualname)
        names = {last}
        cands = [
            c
            for c in self.classes.get(last, [])
            if c.facts.qualname == qualname and c.path not in self._library
        ]
        if not cands:
            return Bases(names=frozenset(names))
        cls = cands[0]
        out: list[str] = []
        # Two definitions of one class (copies, `#if` branches) with other bases: unknown.
        complete = all(c.facts.bases == cls.facts.bases for c in cands)
        bt = False
        for b in cls.facts.bases:
            names.add(last_name(strip_args(b)))
            target, _ = self._resolve(b, cls, cls.path)
            if isinstance(target, _Lib):
                bt = True
            elif (
                isinstance(target, _Class)
                and target.path not in self._library
                and target.facts is not cls.facts
            ):
                out.append(target.facts.qualname)
            else:
                complete = False
        return Bases(tuple(out), complete, bt, frozenset(names))

    def _constant(self, ref: str, cls: _Class | None, path: str) -> str | None:
        """The value of the string constant ``ref`` as seen from ``cls`` in ``path``."""
        if not ref or not re.fullmatch(r"[A-Za-z_][\w:]*", ref):
            return None
        if "::" in ref:
            scope, name = ref.rsplit("::", 1)
            target, _ = self._resolve(scope, cls, path)
            if isinstance(target, _Class) and name in target.facts.constants:
                return target.facts.constants[name]
            self._note("k:" + name)
            return self.constants.get(name)
        seen = 0
        cur: _Class | None = cls
        while cur is not None and seen < _MAX_DEPTH:
            if ref in cur.facts.constants:
                return cur.facts.constants[ref]
            nxt: _Class | None = None
            for b in cur.facts.bases:
                t, _ = self._resolve(b, cur, cur.path)
                if isinstance(t, _Class) and t.facts is not cur.facts:
                    nxt = t
                    break
            cur = nxt
            seen += 1
        self._note("k:" + ref)
        own = self.file_constants.get(path, {})
        if ref in own:
            return own[ref]
        if ref not in self.constants:
            self._miss(ref)
        return self.constants.get(ref)


def _same(a: CppNode, b: CppNode) -> bool:
    """Whether two registrations of one ID make the same node (class, kind and ports)."""

    def ports(n: CppNode) -> list[tuple[str, str, str, str | None]]:
        return [(p.name, p.direction, p.type, p.default) for p in n.ports]

    def flags(n: CppNode) -> list[str]:
        return [f for f in n.flags if f != FLAG_NOT_BUILT]

    # Two simple registrations (no class) with the same port list: one manifest.
    return (
        (a.cls is not None or a.form == b.form)
        and a.cls == b.cls
        and a.kind == b.kind
        and flags(a) == flags(b)
        and ports(a) == ports(b)
    )


def _uses_param(ops: Sequence[Op]) -> bool:
    return any(op.kind == "param" or _uses_param(op.ops) for op in ops)


_NOWHERE: Final[Span] = (0, 0, 0, 0)


def _shape(ops: Sequence[Op]) -> tuple[object, ...]:
    """A port list's steps without their positions (two copies of one body compare equal)."""
    return tuple(
        (
            op.kind,
            None if op.port is None else op.port._replace(name_span=_NOWHERE, span=_NOWHERE),
            op.ref,
            _shape(op.ops),
        )
        for op in ops
    )


def _args_of_last(ref: str) -> list[str]:
    """The template arguments of the last component of ``ref``: ``a::B<int, X>`` -> [int, X]."""
    ref = ref.strip()
    if not ref.endswith(">"):
        return []
    depth = 0
    for i in range(len(ref) - 1, -1, -1):
        ch = ref[i]
        if ch == ">":
            depth += 1
        elif ch == "<":
            depth -= 1
            if depth == 0:
                return [a.strip() for a in split_top(ref[i + 1 : -1])]
    return []


def _substitute(text: str, subst: dict[str, str]) -> str:
    if not subst:
        return text
    pattern = re.compile(r"\b(" + "|".join(map(re.escape, subst)) + r")\b")
    return pattern.sub(lambda m: subst[m.group(1)], text)


def _compose(inner: dict[str, str], outer: dict[str, str]) -> dict[str, str]:
    """Substitution ``inner`` (a base's parameters) with ``outer`` applied to its values.

    An empty ``inner`` is the same class (or a base without parameters): ``outer`` stays.
    """
    if not inner:
        return dict(outer)
    return {k: _substitute(v, outer) for k, v in inner.items()} if outer else dict(inner)


def _where(path: str, span: Span) -> str:
    return f"{path}:{span[0] + 1}"


def _with_flag(node: CppNode, flag: str, note: str) -> CppNode:
    if flag in node.flags:
        return node
    return CppNode(
        node.id,
        node.kind,
        node.cls,
        node.ports,
        (*node.flags, flag),
        (*node.notes, note),
        node.form,
        node.path,
        node.id_span,
        node.class_path,
        node.class_span,
    )
