"""Fixes for name diagnostics: sanitized, unique replacements that rename every reference.

Pure: these functions return edits; the front ends decide whether to apply them.
"""

from __future__ import annotations

from collections.abc import Collection, Iterable, Iterator, Mapping
from dataclasses import dataclass, field

from bt_lsp.diagnostics import Diagnostic
from bt_lsp.edits import TextEdit
from bt_lsp.model import Model, NameRef, Symbol
from bt_lsp.sanitize import candidates, sanitize


@dataclass(frozen=True, slots=True)
class Fix:
    """A fix: edits to the document, and to other workspace files by path."""

    title: str
    edits: tuple[TextEdit, ...]
    preferred: bool
    diagnostic: Diagnostic
    other_edits: Mapping[str, tuple[TextEdit, ...]] = field(default_factory=dict)

    @property
    def places(self) -> int:
        return len(self.edits) + sum(len(e) for e in self.other_edits.values())


def escape_value(text: str, quote: str) -> str:
    """``text`` written inside an attribute value delimited by ``quote``."""
    text = text.replace("&", "&amp;").replace("<", "&lt;")
    if quote == '"':
        text = text.replace('"', "&quot;")
    elif quote == "'":
        text = text.replace("'", "&apos;")
    return text


def _written(ref: NameRef, new_name: str) -> str:
    return escape_value(new_name, ref.quote) if ref.quote else new_name


def occurrences(model: Model, ref: NameRef) -> list[NameRef]:
    """Every name token that a rename of ``ref`` must change, ``ref`` included."""
    if ref.symbol is None:
        return [ref]
    return model.refs_to(ref.symbol)


def rename_edits(refs: Iterable[NameRef], new_name: str) -> list[TextEdit]:
    return sorted({TextEdit(r.start, r.end, _written(r, new_name)) for r in refs})


def _namespace(symbol: Symbol) -> tuple[str, ...]:
    """Names in one namespace must stay distinct: trees and models share one (a tree ID may
    not be a node type), a port's namespace is its owner's ports."""
    return ("port", *symbol[1:-1]) if symbol[0] == "port" else ("ids",)


def _names_in(model: Model, ns: tuple[str, ...]) -> set[str]:
    return {sym[-1] for sym in model.by_symbol if _namespace(sym) == ns}


def taken_names(model: Model, symbol: Symbol | None, others: Iterable[Model] = ()) -> set[str]:
    """Names a new name for ``symbol`` must avoid: the others in its namespace, in this
    document and in the other workspace documents."""
    if symbol is None:
        return set()
    ns = _namespace(symbol)
    taken: set[str] = set()
    for m in (model, *others):
        taken |= _names_in(m, ns)
    if not any(symbol in m.by_symbol for m in others):
        taken.discard(symbol[-1])
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


def shown(name: str) -> str:
    """A name with its control characters written visibly (``U+0007``)."""
    return "".join(c if c.isprintable() or c == " " else f"U+{ord(c):04X}" for c in name)


def _title(old: str, new: str, places: int) -> str:
    where = "1 place" if places == 1 else f"{places} places"
    if not new:
        return f"Clear '{shown(old)}' ({where})"
    return f"Rename '{shown(old)}' to '{shown(new)}' ({where})"


def fixes_for(
    model: Model, diag: Diagnostic, others: Mapping[str, Model] | None = None
) -> list[Fix]:
    """Quick fixes for one name diagnostic: the preferred rename first, then alternatives.
    ``others`` are the other workspace documents' models, by path: references there are
    renamed too."""
    if not diag.is_name_rule:
        return []
    ref = model.ref_at(diag.start)
    if ref is None or ref.start != diag.start or ref.end != diag.end or ref.kind is None:
        return []
    others = others or {}
    occ = occurrences(model, ref)
    names = candidates(ref.text, ref.kind, taken_names(model, ref.symbol, others.values()))
    fixes: list[Fix] = []
    for i, new in enumerate(names):
        if new == ref.text:
            continue
        edits = tuple(rename_edits(occ, new))
        elsewhere = other_file_edits(ref.symbol, new, others)
        places = len(edits) + sum(len(e) for e in elsewhere.values())
        title = _title(ref.text, new, places)
        if elsewhere:
            n = len(elsewhere)
            title = title[:-1] + f", {n} other file{'s' if n > 1 else ''})"
        fixes.append(Fix(title, edits, i == 0, diag, elsewhere))
    return fixes


class _Without(Collection[str]):
    """A set minus one name, without copying the set."""

    def __init__(self, names: set[str], left_out: str) -> None:
        self._names, self._left_out = names, left_out

    def __contains__(self, name: object) -> bool:
        return name != self._left_out and name in self._names

    def __iter__(self) -> Iterator[str]:
        return (n for n in self._names if n != self._left_out)

    def __len__(self) -> int:
        return len(self._names) - (self._left_out in self._names)


def fix_all(model: Model, diags: Iterable[Diagnostic]) -> list[TextEdit]:
    """Every preferred name fix at once, consistently: one new name per symbol, all
    distinct from each other and from the names that stay."""
    chosen: dict[Symbol | tuple[int, int], str] = {}
    edits: dict[tuple[int, int], TextEdit] = {}
    taken_by_ns: dict[tuple[str, ...], set[str]] = {}
    for sym in model.by_symbol:
        taken_by_ns.setdefault(_namespace(sym), set()).add(sym[-1])
    for diag in diags:
        if not diag.is_name_rule:
            continue
        ref = model.ref_at(diag.start)
        if ref is None or ref.start != diag.start or ref.end != diag.end or ref.kind is None:
            continue
        key: Symbol | tuple[int, int] = (
            ref.symbol if ref.symbol is not None else (ref.start, ref.end)
        )
        if key in chosen:
            continue
        if ref.symbol is not None:
            ns = _namespace(ref.symbol)
            taken_by_ns.setdefault(ns, set())
            taken: Collection[str] = _Without(taken_by_ns[ns], ref.symbol[-1])
        else:
            taken = ()
        new = sanitize(ref.text, ref.kind, taken)
        chosen[key] = new
        if ref.symbol is not None:
            taken_by_ns[_namespace(ref.symbol)].add(new)
        for e in rename_edits(occurrences(model, ref), new):
            edits[(e.start, e.end)] = e
    return sorted(edits.values())
