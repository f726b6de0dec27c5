"""Port types with the project's own type aliases followed and its classes qualified.

BehaviorTree.CPP compares the types of two ports that share a blackboard entry by
``typeid``: under ``namespace foo { using TaskPtr = std::shared_ptr<Task>; }``, the
ports ``InputPort<TaskPtr>`` and ``OutputPort<std::shared_ptr<Task>>`` written in ``foo``
have one type.  :class:`TypeNames` looks each name of a type up roughly as C++ does (from
the scope the port is written in outward, through the bases of a class) among the
aliases (``using X = Y;``, ``typedef Y X;``, ``using ns::Y;``) and the class definitions
of the C++ read, and writes the type again with every alias it found replaced by what it
names and every class it found fully qualified.

A name it cannot find stays as written: an alias from a header outside the project, a
member of a generated type (``Action::Result::_error_code_type``), a template parameter
(``ActionT::Goal``), a name a base class outside the project may declare.  Such a name
proves nothing; only the classes listed in :attr:`Resolution.classes` are known to be
class definitions (so not aliases of anything else).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from typing import Final, NamedTuple

from bt_lsp.cpp.facts import FileFacts
from bt_lsp.cpp.names import split_top

__all__ = ["Bases", "Resolution", "TypeNames"]

_MAX_DEPTH: Final = 16

# Words of a type that are never names of the project: keywords, built-in types, and the
# names bt-lsp's type comparison already knows (so a port typed ``NodeStatus`` does not
# make the catalog read every file that names it).
_PASS: Final = frozenset(
    {
        "const",
        "volatile",
        "struct",
        "class",
        "enum",
        "union",
        "unsigned",
        "signed",
        "short",
        "long",
        "int",
        "char",
        "bool",
        "float",
        "double",
        "void",
        "auto",
        "wchar_t",
        "char8_t",
        "char16_t",
        "char32_t",
        "int8_t",
        "uint8_t",
        "int16_t",
        "uint16_t",
        "int32_t",
        "uint32_t",
        "int64_t",
        "uint64_t",
        "size_t",
        "ssize_t",
        "ptrdiff_t",
        "string",
        "NodeStatus",
        "Any",
        "AnyTypeAllowed",
        "StringView",
        "true",
        "false",
        "nullptr",
        "decltype",
        "sizeof",
    }
)
# Namespaces that no project defines names in.
_FOREIGN: Final = frozenset({"std", "__gnu_cxx", "__cxx11"})
# The member types every BehaviorTree.CPP node inherits from ``TreeNode``.
_BT_MEMBERS: Final = frozenset(
    {
        "Ptr",
        "PreTickCallback",
        "PostTickCallback",
        "TickMonitorCallback",
        "StatusChangeSignal",
        "StatusChangeSubscriber",
        "StatusChangeCallback",
    }
)
_OPAQUE: Final = "__bt_lsp_arg"  # an alias template's parameter while its target is read


class Resolution(NamedTuple):
    """A type with the aliases found replaced and the classes found qualified.

    ``classes`` are the class definitions it names (qualified, without template
    arguments); ``names`` every name looked up (a change of a file that defines one may
    change the result); ``missing`` the names found nowhere that a file not read yet may
    define.
    """

    text: str
    classes: frozenset[str]
    names: frozenset[str]
    missing: frozenset[str]


class Bases(NamedTuple):
    """The bases of a class as far as the C++ read says.

    ``classes``: the qualified names of the bases read; ``complete``: every base is one
    read or one of BehaviorTree.CPP's node classes (else a name not found in the class
    may be a member of a base that was not read); ``bt``: it derives from a
    BehaviorTree.CPP node class (and so has ``TreeNode``'s member types); ``names``: the
    names looked up to find them.
    """

    classes: tuple[str, ...] = ()
    complete: bool = False
    bt: bool = False
    names: frozenset[str] = frozenset()


class _Comp(NamedTuple):
    name: str
    args: tuple[str, ...] | None  # template arguments as written, None without a list


@dataclass(slots=True)
class _State:
    """What one resolution found and looked up."""

    classes: set[str] = field(default_factory=set)
    names: set[str] = field(default_factory=set)
    missing: set[str] = field(default_factory=set)
    active: set[str] = field(default_factory=set)  # aliases being expanded (no cycles)


class TypeNames:
    """The type aliases and classes defined by the project's C++ read, by qualified name.

    ``bases`` gives the bases of a class (by qualified name) as the catalog resolves them.
    One per link; resolutions are kept (by type text and scope) for the link's life.
    """

    def __init__(
        self, files: Iterable[tuple[str, FileFacts]], bases: Callable[[str], Bases]
    ) -> None:
        self._bases_of = bases
        self.aliases: dict[str, set[tuple[str, tuple[str, ...]]]] = {}
        self.classes: dict[str, tuple[str, ...]] = {}  # qualified name -> template params
        self.scopes: set[str] = set()  # namespaces and classes that hold a name read
        # Names at namespace scope by their last part (the lookup from an unknown scope).
        self.by_last: dict[str, set[str]] = {}
        for _, f in files:
            for c in f.classes:
                if c.local:
                    continue
                self.classes.setdefault(c.qualname, c.template_params)
                self._add_scopes(c.qualname)
            for a in f.aliases:
                self.aliases.setdefault(a.name, set()).add((a.target, a.params))
                self._add_scopes(a.name)
        for q in (*self.classes, *self.aliases):
            parent = q.rsplit("::", 1)[0] if "::" in q else ""
            if parent not in self.classes:
                self.by_last.setdefault(q.rsplit("::", 1)[-1], set()).add(q)
        self._bases: dict[str, Bases] = {}
        self._done: dict[tuple[str, str | None], Resolution] = {}

    def _add_scopes(self, q: str) -> None:
        parts = q.split("::")
        for i in range(1, len(parts)):
            self.scopes.add("::".join(parts[:i]))

    def resolve(self, text: str, scope: str | None) -> Resolution:
        """``text`` (a type as written) as seen from ``scope`` (the qualified class or
        namespace it is written in; ``None`` when not known: then only a name that the C++
        read defines once at namespace scope is found)."""
        key = (text, scope)
        hit = self._done.get(key)
        if hit is None:
            st = _State()
            out = " ".join(self._rewrite(text, scope, st, 0).split())
            hit = Resolution(out, frozenset(st.classes), frozenset(st.names), frozenset(st.missing))
            self._done[key] = hit
        return hit

    # --- the text ---------------------------------------------------------------------

    def _rewrite(self, text: str, scope: str | None, st: _State, depth: int) -> str:
        out: list[str] = []
        i, n = 0, len(text)
        while i < n:
            ch = text[i]
            glob = text.startswith("::", i) and i + 2 < n and _word_start(text[i + 2])
            if _word_start(ch) or glob:
                comps, i = _chain(text, i + 2 if glob else i)
                out.append(self._name(comps, glob, scope, st, depth))
            else:
                out.append(ch)
                i += 1
        return "".join(out)

    def _name(
        self, comps: list[_Comp], glob: bool, scope: str | None, st: _State, depth: int
    ) -> str:
        """One (maybe qualified) name of a type, resolved as far as the C++ read allows."""
        comps = [
            _Comp(
                c.name,
                None
                if c.args is None
                else tuple(self._rewrite(a.strip(), scope, st, depth + 1) for a in c.args),
            )
            for c in comps
        ]
        first = comps[0].name
        if first == "typename":
            return ""
        if first in _PASS or first in _FOREIGN or first.startswith(_OPAQUE) or depth > _MAX_DEPTH:
            return ("::" if glob else "") + _written(comps)
        st.names.update(c.name for c in comps)
        found = self._first(first, glob, scope, st)
        if found is None:
            return ("::" if glob else "") + _written(comps)
        if found == "":
            if len(comps) == 1:
                st.missing.add(first)
            return ("::" if glob else "") + _written(comps)
        return self._walk(found, comps, st, depth)

    def _first(self, name: str, glob: bool, scope: str | None, st: _State) -> str | None:
        """The qualified name that ``name`` (the first part of a name) denotes; ``""``
        when it is found nowhere, ``None`` when it may be a name bt-lsp cannot see."""
        if scope is None and not glob:
            if name in self.scopes and name not in self.classes and name not in self.aliases:
                return name  # a top-level namespace
            found = self.by_last.get(name, set())
            if len(found) == 1:
                return next(iter(found))
            return "" if not found else None
        prefixes = [""] if glob else _prefixes(scope or "")
        for p in prefixes:
            q = f"{p}::{name}" if p else name
            if self._defines(q):
                return q
            if p in self.classes:
                if name in self.classes[p]:
                    return None  # a template parameter
                inherited = self._inherited(p, name, st)
                if inherited is not None:
                    return inherited or None
        return ""

    def _inherited(self, cls: str, name: str, st: _State) -> str | None:
        """``name`` as a member of a base of ``cls``: its qualified name; ``""`` when it
        may be a member of a base not read; ``None`` when no base has it."""
        seen: set[str] = set()
        todo = [cls]
        while todo:
            cur = todo.pop(0)
            if cur in seen or len(seen) > _MAX_DEPTH:
                continue
            seen.add(cur)
            b = self._bases.get(cur)
            if b is None:
                b = self._bases[cur] = self._bases_of(cur)
            st.names.update(b.names)
            if not b.complete or (b.bt and name in _BT_MEMBERS):
                return ""
            for base in b.classes:
                q = f"{base}::{name}"
                if self._defines(q):
                    return q
                todo.append(base)
        return None

    def _defines(self, q: str) -> bool:
        return q in self.aliases or q in self.classes or q in self.scopes

    def _walk(self, cur: str, comps: list[_Comp], st: _State, depth: int) -> str:
        """The rest of a name from its first part, found as ``cur``."""
        i = 0
        while True:
            comp = comps[i]
            rest = comps[i + 1 :]
            if cur in self.aliases:
                if cur in self.classes:
                    return _written(comps)  # an alias and a class of one name: unknown
                target = self._alias(cur, comp.args, st, depth)
                if target is None:
                    return _written(comps)
                if not rest:
                    return target
                if target not in self.classes or self.classes[target]:
                    return "::".join([target, _written(rest)])
                cur = target
            elif cur in self.classes:
                here = cur + _args(comp.args)
                if not rest:
                    st.classes.add(cur)
                    return here
                if self.classes[cur]:
                    return "::".join([here, _written(rest)])  # a member of a template
            elif not rest:
                return _written(comps)  # a namespace is not a type
            nxt = f"{cur}::{rest[0].name}"
            if not self._defines(nxt):
                found = self._inherited(cur, rest[0].name, st) if cur in self.classes else None
                if not found:
                    if cur not in self.classes and len(rest) == 1:
                        st.missing.add(rest[0].name)  # a namespace member not read yet
                    return "::".join([cur + _args(comp.args), _written(rest)])
                nxt = found
            cur = nxt
            i += 1

    def _alias(self, q: str, args: tuple[str, ...] | None, st: _State, depth: int) -> str | None:
        """What the alias ``q`` (with template ``args``, already resolved) names, resolved
        from the scope it is declared in; ``None`` when that is not one type."""
        defs = self.aliases[q]
        if len(defs) != 1 or q in st.active:
            return None
        target, params = next(iter(defs))
        if bool(params) != (args is not None) or (args is not None and len(args) != len(params)):
            return None
        scope = q.rsplit("::", 1)[0] if "::" in q else ""
        marks = {p: f"{_OPAQUE}{i}__" for i, p in enumerate(params)}
        if marks:
            target = _replace_words(target, marks)
        st.active.add(q)
        try:
            out = self._rewrite(target, scope, st, depth + 1)
        finally:
            st.active.discard(q)
        if args is not None:
            out = _replace_words(out, {m: a for m, a in zip(marks.values(), args, strict=True)})
        return " ".join(out.split())


# --- text helpers ---------------------------------------------------------------------------


def _word_start(ch: str) -> bool:
    return ch.isalpha() or ch == "_"


def _chain(text: str, i: int) -> tuple[list[_Comp], int]:
    """The name starting at ``i`` (``a::B<int>::C``) and the index after it."""
    n = len(text)
    comps: list[_Comp] = []
    while True:
        j = i
        while j < n and (text[j].isalnum() or text[j] == "_"):
            j += 1
        name = text[i:j]
        k = j
        while k < n and text[k] == " ":
            k += 1
        args: tuple[str, ...] | None = None
        if k < n and text[k] == "<" and name not in _PASS:
            end = _close(text, k)
            if end < 0:
                comps.append(_Comp(name, None))
                return comps, j
            args = tuple(split_top(text[k + 1 : end]))
            j = k = end + 1
            while k < n and text[k] == " ":
                k += 1
        comps.append(_Comp(name, args))
        if text.startswith("::", k) and k + 2 < n:
            m = k + 2
            while m < n and text[m] == " ":
                m += 1
            if m < n and _word_start(text[m]) and name not in _PASS:
                i = m
                continue
        return comps, j


def _close(text: str, start: int) -> int:
    """The index of the ``>`` that closes the ``<`` at ``start``, or -1."""
    depth = 0
    for i in range(start, len(text)):
        ch = text[i]
        if ch in "<([":
            depth += 1
        elif ch in ">)]":
            depth -= 1
            if depth == 0:
                return i if ch == ">" else -1
    return -1


def _args(args: tuple[str, ...] | None) -> str:
    return "" if args is None else "<" + ", ".join(args) + ">"


def _written(comps: list[_Comp]) -> str:
    return "::".join(c.name + _args(c.args) for c in comps)


def _prefixes(scope: str) -> list[str]:
    """``a::b`` -> ``["a::b", "a", ""]``: the scopes a name is looked up in, inner first."""
    parts = scope.split("::") if scope else []
    return ["::".join(parts[:i]) for i in range(len(parts), -1, -1)]


def _replace_words(text: str, table: dict[str, str]) -> str:
    out: list[str] = []
    i, n = 0, len(text)
    while i < n:
        if _word_start(text[i]):
            j = i
            while j < n and (text[j].isalnum() or text[j] == "_"):
                j += 1
            word = text[i:j]
            before = text[i - 2 : i] if i >= 2 else ""
            out.append(table.get(word, word) if before != "::" else word)
            i = j
        else:
            out.append(text[i])
            i += 1
    return "".join(out)
