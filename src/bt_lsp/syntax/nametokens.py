"""The name tokens of an element: which of its tokens is a model, port or instance name
or a reference, and the symbol it denotes, by where the element sits (the contract's
positions).  Everywhere else (comments, CDATA, ``<include path>``, attributes of
``<root>`` and ``<BehaviorTree>``, reserved attributes of nodes) nothing is a name.

Symbols repeat (every use of a node type or port), so they are shared, in bounded tables.
"""

from __future__ import annotations

from typing import TypeVar, cast

from bt_lsp.syntax.elements import (
    EXPLICIT_TAGS,
    Element,
    NameRef,
    NameSymbol,
    Role,
    Symbol,
    Zone,
    model_symbol,
    port_symbol,
    tree_symbol,
)
from bt_lsp.syntax.scanner import ScanPools, scan_token
from bt_lsp.syntax.tokens import Attr
from bt_lsp.syntax.vocabulary import RESERVED_PORT_NAMES, NameKind

# Members read in the hot loops below, as module globals: in Python 3.11 reading a member
# from an enum class costs about 0.2 µs (EnumType has a __getattr__ hook), a global a
# tenth of that, and a first analysis reads them hundreds of thousands of times.
_KIND_INSTANCE = NameKind.INSTANCE
_KIND_MODEL = NameKind.MODEL
_KIND_PORT = NameKind.PORT
_ROLE_INSTANCE = Role.INSTANCE
_ROLE_MAIN_TREE = Role.MAIN_TREE
_ROLE_MODEL_DEF = Role.MODEL_DEF
_ROLE_NODE_ID = Role.NODE_ID
_ROLE_NODE_TYPE = Role.NODE_TYPE
_ROLE_PORT_DECL = Role.PORT_DECL
_ROLE_PORT_USE = Role.PORT_USE
_ROLE_SUBTREE_CALL = Role.SUBTREE_CALL
_ROLE_TREE_DEF = Role.TREE_DEF
_ZONE_MODEL_ENTRY = Zone.MODEL_ENTRY
_ZONE_NODE = Zone.NODE
_ZONE_PORT_DECL = Zone.PORT_DECL
_ZONE_ROOT = Zone.ROOT
_ZONE_TREE = Zone.TREE


def _owner(el: Element) -> NameSymbol:
    """The symbol whose ports an element's attributes (or port declarations) are."""
    if el.name == "SubTree":
        return tree_symbol(el.value("ID") or "")
    if el.zone == _ZONE_NODE and el.name not in EXPLICIT_TAGS:
        return model_symbol(el.name)
    return model_symbol(el.value("ID") or "")


# A named tuple from all its fields, without the (slower) Python-level constructor.
_new = tuple.__new__

_S = TypeVar("_S", bound=Symbol)


class SymbolPool:
    """Equal symbols made once, for one pass over names (its caller's, never shared
    between threads): the symbols made so far, the port symbols of each owner by port
    name, and each node type's symbol with its ports' (every element looks them up).
    Bounded."""

    __slots__ = ("models", "ports", "symbols")

    def __init__(self) -> None:
        self.symbols: dict[Symbol, Symbol] = {}
        self.ports: dict[NameSymbol, dict[str, Symbol]] = {}
        self.models: dict[str, tuple[NameSymbol, dict[str, Symbol]]] = {}

    def shared(self, symbol: _S) -> _S:
        symbols = self.symbols
        shared = symbols.get(symbol)
        if shared is None:
            if len(symbols) >= 65536:
                symbols.clear()
            shared = symbols[symbol] = symbol
        return cast(_S, shared)  # equal symbols are of one class

    def port_symbols(self, owner: NameSymbol) -> dict[str, Symbol]:
        ports = self.ports.get(owner)
        if ports is None:
            if len(self.ports) >= 4096:
                self.ports.clear()
            ports = self.ports[owner] = {}
        return ports

    def model_symbols(self, name: str) -> tuple[NameSymbol, dict[str, Symbol]]:
        found = self.models.get(name)
        if found is None:
            if len(self.models) >= 4096:
                self.models.clear()
            owner = model_symbol(name)
            found = self.models[name] = (self.shared(owner), self.port_symbols(owner))
        return found


def _value_ref(
    out: list[NameRef],
    el: Element,
    idx: int,
    a: Attr,
    kind: NameKind | None,
    role: Role,
    symbol: Symbol | None,
    pool: SymbolPool,
) -> None:
    if a.value is not None:
        out.append(
            _new(
                NameRef,
                (
                    el.token_start + a.value_start,
                    el.token_start + a.value_end,
                    a.value,
                    kind,
                    role,
                    pool.shared(symbol) if symbol is not None else None,
                    idx,
                    a.quote,
                ),
            )
        )


def name_refs(
    el: Element,
    idx: int,
    parent: Element | None,
    out: list[NameRef],
    pool: SymbolPool | None = None,
) -> None:
    """Append the name tokens of one element to ``out``, by where the element sits (the
    contract's positions); their symbols shared through ``pool`` (a pass over many
    elements passes one)."""
    if pool is None:
        pool = SymbolPool()
    zone = el.zone
    ts = el.token_start
    if zone == _ZONE_NODE:
        name = el.name
        if name in EXPLICIT_TAGS or name == "SubTree":
            a = el.attr("ID")
            if a is not None:
                role, sym = (
                    (_ROLE_SUBTREE_CALL, tree_symbol(a.value or ""))
                    if name == "SubTree"
                    else (_ROLE_NODE_ID, model_symbol(a.value or ""))
                )
                _value_ref(out, el, idx, a, _KIND_MODEL, role, sym, pool)
            owner = _owner(el)
            ports = pool.port_symbols(owner)
        else:
            type_symbol, ports = pool.model_symbols(name)
            owner = type_symbol
            out.append(
                _new(
                    NameRef,
                    (
                        ts + 1,
                        ts + 1 + len(name),
                        name,
                        _KIND_MODEL,
                        _ROLE_NODE_TYPE,
                        type_symbol,
                        idx,
                        "",
                    ),
                )
            )
        # Unpacked rather than read by field: this runs for every attribute of every node.
        for an, ns, ne, value, vs, ve, quote in el.attrs:
            if an == "name":
                if value is not None:
                    out.append(
                        _new(
                            NameRef,
                            (
                                ts + vs,
                                ts + ve,
                                value,
                                _KIND_INSTANCE,
                                _ROLE_INSTANCE,
                                None,
                                idx,
                                quote,
                            ),
                        )
                    )
            elif an not in RESERVED_PORT_NAMES:
                psym = ports.get(an)
                if psym is None:
                    psym = ports[an] = pool.shared(port_symbol(owner, an))
                out.append(
                    _new(
                        NameRef,
                        (ts + ns, ts + ne, an, _KIND_PORT, _ROLE_PORT_USE, psym, idx, ""),
                    )
                )
    elif zone == _ZONE_ROOT:
        a = el.attr("main_tree_to_execute")
        if a is not None:
            _value_ref(out, el, idx, a, None, _ROLE_MAIN_TREE, tree_symbol(a.value or ""), pool)
    elif zone == _ZONE_TREE:
        a = el.attr("ID")
        if a is not None:
            _value_ref(
                out, el, idx, a, _KIND_MODEL, _ROLE_TREE_DEF, tree_symbol(a.value or ""), pool
            )
    elif zone == _ZONE_MODEL_ENTRY:
        a = el.attr("ID")
        if a is not None:
            entry = NameSymbol("tree" if el.name == "SubTree" else "model", a.value or "")
            _value_ref(out, el, idx, a, _KIND_MODEL, _ROLE_MODEL_DEF, entry, pool)
    elif zone == _ZONE_PORT_DECL and parent is not None:
        a = el.attr("name")
        if a is not None:
            _value_ref(
                out,
                el,
                idx,
                a,
                _KIND_PORT,
                _ROLE_PORT_DECL,
                port_symbol(_owner(parent), a.value or ""),
                pool,
            )


def start_tag_refs(text: str, at: int, zone: Zone, parent: Element | None) -> list[NameRef]:
    """The name tokens of the start tag at offset ``at``, exactly as a model of ``text``
    makes them, for a caller that knows the element's zone and parent without a model
    (:mod:`bt_lsp.rules.early_names`).  Element indexes in the result are 0."""
    out: list[NameRef] = []
    name_refs(start_tag_element(text, at, zone), 0, parent, out)
    return out


def start_tag_element(text: str, at: int, zone: Zone) -> Element:
    """The element whose start tag is at offset ``at``, alone (no parent or children)."""
    tok = scan_token(text, at, ScanPools())
    return Element(
        tok.name, zone, at, 0, -1, 0, tok.attrs, tok.self_closing, tok.closed, length=tok.length
    )
