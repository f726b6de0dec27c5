"""What one C++ file says about behavior-tree nodes: plain, immutable, JSON-able data.

A file's facts are made once per file content (and cached on disk by the project layer),
so they hold only what the file itself says: names are left as written and resolved
across files by :mod:`bt_lsp.cpp.catalog`.  Spans are ``(line, column, end line, end
column)``, 0-based, columns in code points.
"""

from __future__ import annotations

from typing import Any, NamedTuple

Span = tuple[int, int, int, int]


class PortFacts(NamedTuple):
    """One ``InputPort``/``OutputPort``/``BidirectionalPort`` call.

    ``name`` is the literal name, or ``None`` with ``name_ref`` the constant it names.
    ``default`` is the default as text (a string literal's value, other literals as
    written, an expression's source with ``default_is_expr``), ``None`` without one.
    """

    direction: str  # "input" | "output" | "inout"
    type: str | None  # the template argument as written; None when untyped
    name: str | None
    name_ref: str | None
    name_span: Span
    default: str | None
    default_is_expr: bool
    description: str
    span: Span
    # The default is a C++ number or bool literal as written (``0.7f``, ``10u``, ``-1``,
    # ``true``): BehaviorTree.CPP shows it converted (``toStr`` of the port's type).
    default_literal: bool = False


class Op(NamedTuple):
    """One step building a port list, applied in order; an existing key always wins.

    ``kind``: ``port`` (add ``port``), ``ref`` (add the ports of ``Class::providedPorts()``,
    ``ref`` naming the class; empty for the class's own base chain), ``basic`` (add what
    ``providedBasicPorts(ops)`` returns, looked up from ``ref`` or the class), ``param``
    (add the argument of a ``providedBasicPorts(PortsList addition)``) or ``unknown``
    (``ref`` is the source text that could not be read).
    """

    kind: str
    port: PortFacts | None = None
    ref: str = ""
    ops: tuple[Op, ...] = ()


class PortsFn(NamedTuple):
    """A ``providedPorts`` or ``providedBasicPorts`` definition (inline or out of line).

    ``owner`` is the class it belongs to, qualified as far as the file says
    (``ns::Foo``), template arguments stripped.
    """

    owner: str
    name: str
    param: str | None
    ops: tuple[Op, ...]
    span: Span


class ClassFacts(NamedTuple):
    name: str
    qualname: str
    span: Span
    bases: tuple[str, ...]
    template_params: tuple[str, ...]
    using_ports: str | None  # `using Base::providedPorts;`
    aliases: dict[str, str]  # `using Base = BT::RosActionNode<X>;`
    constants: dict[str, str]
    # `providedPorts`/`providedBasicPorts` declared in the body without a body of their own
    # (`static PortsList providedPorts();`): defined out of line, maybe in a file not read.
    declared: tuple[str, ...] = ()


class Registration(NamedTuple):
    """A place that registers a node type with the factory.

    ``form`` is the function (``registerNodeType``, ``registerBuilder``, ``CreateManifest``,
    ``registerSimpleAction`` ...); ``cls`` the registered type as written (``None`` for
    simple nodes, whose ``kind`` and ``ops`` are given at the call); ``id`` the literal ID
    or ``None`` with ``id_ref`` the constant or expression that names it.
    """

    form: str
    id: str | None
    id_ref: str | None
    id_span: Span
    cls: str | None
    kind: str | None
    ops: tuple[Op, ...] | None
    span: Span


class MacroTemplate(NamedTuple):
    """A function-like macro whose body registers a node.

    E.g. ``#define REG(T) f.registerBuilder<T>(#T, …)``.

    ``cls_param`` is the index of the parameter giving the class; the ID comes from the
    parameter ``id_param`` (stringified with ``#`` when ``stringify``) or is ``id_literal``.
    """

    name: str
    params: tuple[str, ...]
    form: str
    cls_param: int
    id_param: int
    stringify: bool
    id_literal: str | None
    # The class as the body writes it when it is more than the parameter
    # (``ns::class_name``, each parameter replaced by its argument); empty otherwise.
    cls_text: str = ""


class MacroCall(NamedTuple):
    """An invocation ``NAME(arg, …)`` that may be of a registering macro defined elsewhere."""

    name: str
    args: tuple[str, ...]
    arg_spans: tuple[Span, ...]
    span: Span


class Helper(NamedTuple):
    """A function of the project that registers a node for its callers.

    E.g. ``template <class T> void reg(Factory& f, const std::string& id)
    { f.registerNodeType<T>(id); }``.  The class is the template parameter at
    ``cls_tparam`` (or ``cls`` as written); the ID the function parameter at ``id_param``
    (or ``id_literal``).  ``ops`` are the port list the registration passes, if any.
    """

    name: str
    form: str
    cls_tparam: int
    cls: str | None
    id_param: int
    id_literal: str | None
    ops: tuple[Op, ...] | None
    span: Span


class HelperCall(NamedTuple):
    """A call ``name<targs>(args)`` that may be of a registering helper defined anywhere.

    ``args`` are the arguments as written and ``values`` their string values (``None`` for
    one that is not a string literal).
    """

    name: str
    targs: tuple[str, ...]
    args: tuple[str, ...]
    values: tuple[str | None, ...]
    arg_spans: tuple[Span, ...]
    span: Span


class FileFacts(NamedTuple):
    classes: tuple[ClassFacts, ...] = ()
    fns: tuple[PortsFn, ...] = ()
    registrations: tuple[Registration, ...] = ()
    macros: tuple[MacroTemplate, ...] = ()
    macro_calls: tuple[MacroCall, ...] = ()
    constants: dict[str, str] = {}  # noqa: RUF012 (never mutated)
    helpers: tuple[Helper, ...] = ()
    helper_calls: tuple[HelperCall, ...] = ()


# --- JSON ------------------------------------------------------------------------------


def to_json(facts: FileFacts) -> Any:
    """``facts`` as nested lists (named tuples are tuples; dicts stay dicts)."""
    return facts


def _span(v: Any) -> Span:
    a, b, c, d = v
    return (int(a), int(b), int(c), int(d))


def _port(v: Any) -> PortFacts:
    d, t, n, nr, ns, df, de, desc, sp, dl = v
    return PortFacts(
        str(d),
        None if t is None else str(t),
        None if n is None else str(n),
        None if nr is None else str(nr),
        _span(ns),
        None if df is None else str(df),
        bool(de),
        str(desc),
        _span(sp),
        bool(dl),
    )


def _op(v: Any) -> Op:
    kind, port, ref, ops = v
    return Op(str(kind), None if port is None else _port(port), str(ref), tuple(map(_op, ops)))


def _ops(v: Any) -> tuple[Op, ...]:
    return tuple(map(_op, v))


def _strs(v: Any) -> tuple[str, ...]:
    return tuple(map(str, v))


def _dict(v: Any) -> dict[str, str]:
    return {str(k): str(x) for k, x in dict(v).items()}


def from_json(v: Any) -> FileFacts:
    """The facts :func:`to_json` wrote; raises ``ValueError``/``TypeError`` on anything else."""
    classes, fns, regs, macros, calls, constants, helpers, helper_calls = v
    return FileFacts(
        tuple(
            ClassFacts(
                str(c[0]),
                str(c[1]),
                _span(c[2]),
                _strs(c[3]),
                _strs(c[4]),
                None if c[5] is None else str(c[5]),
                _dict(c[6]),
                _dict(c[7]),
                _strs(c[8]),
            )
            for c in classes
        ),
        tuple(
            PortsFn(
                str(f[0]), str(f[1]), None if f[2] is None else str(f[2]), _ops(f[3]), _span(f[4])
            )
            for f in fns
        ),
        tuple(
            Registration(
                str(r[0]),
                None if r[1] is None else str(r[1]),
                None if r[2] is None else str(r[2]),
                _span(r[3]),
                None if r[4] is None else str(r[4]),
                None if r[5] is None else str(r[5]),
                None if r[6] is None else _ops(r[6]),
                _span(r[7]),
            )
            for r in regs
        ),
        tuple(
            MacroTemplate(
                str(m[0]),
                _strs(m[1]),
                str(m[2]),
                int(m[3]),
                int(m[4]),
                bool(m[5]),
                None if m[6] is None else str(m[6]),
                str(m[7]),
            )
            for m in macros
        ),
        tuple(
            MacroCall(str(c[0]), _strs(c[1]), tuple(map(_span, c[2])), _span(c[3])) for c in calls
        ),
        _dict(constants),
        tuple(
            Helper(
                str(h[0]),
                str(h[1]),
                int(h[2]),
                None if h[3] is None else str(h[3]),
                int(h[4]),
                None if h[5] is None else str(h[5]),
                None if h[6] is None else _ops(h[6]),
                _span(h[7]),
            )
            for h in helpers
        ),
        tuple(
            HelperCall(
                str(c[0]),
                _strs(c[1]),
                _strs(c[2]),
                tuple(None if x is None else str(x) for x in c[3]),
                tuple(map(_span, c[4])),
                _span(c[5]),
            )
            for c in helper_calls
        ),
    )
