"""The workspace combined once (:class:`SharedDecls`) gives each document the context that
``Context.combine`` gives it over all the others, and a folder's check does a bounded
amount of work per file (it used to look at every other file for each file)."""

from __future__ import annotations

import itertools
from pathlib import Path

import pytest

from bt_lsp.project import workspace_files
from bt_lsp.project.include_graph import IncludeGraph
from bt_lsp.project.index import ProjectIndex
from bt_lsp.rules import context as context_module
from bt_lsp.rules import shared_context
from bt_lsp.rules.context import Context
from bt_lsp.rules.shared_context import SharedDecls
from bt_lsp.syntax.document import Document
from tests.pinned import main  # bt-lsp as the tests know it (tests/pinned.py)


def _tree(tid: str, body: str = "<AlwaysSuccess/>") -> str:
    return f'  <BehaviorTree ID="{tid}">{body}</BehaviorTree>\n'


def _models(*ids: str, port: str = "x") -> str:
    rows = "".join(f'<Action ID="{i}"><input_port name="{port}"/></Action>' for i in ids)
    return f'  <TreeNodesModel>{rows}<SubTree ID="{ids[0]}T"/></TreeNodesModel>\n'


# Documents whose declarations overlap in every way the precedence rules tell apart: the
# same model in a tree file, a generated catalog and a palette; a tree defined twice; the
# first declaration of an ID in the document checked or in one it includes.
DOCS = {
    "/ws/a.xml": '<root BTCPP_format="4">\n'
    + _tree("A", '<SubTree ID="B"/>')
    + _tree("Shared")
    + _models("Go", "Stop")
    + "</root>\n",
    "/ws/b.xml": '<root BTCPP_format="4">\n'
    + _tree("B")
    + _tree("Shared")
    + _models("Stop", "Turn", port="y")
    + "</root>\n",
    "/ws/c.xml": '<root BTCPP_format="4">\n<include path="b.xml"/>\n'
    + _tree("C", '<SubTree ID="Shared"/>')
    + _models("Turn", "Go", port="z")
    + "</root>\n",
    "/ws/catalog.xml": '<root BTCPP_format="4">\n' + _models("Turn", "Lift") + "</root>\n",
    "/ws/d.btproj": '<root BTCPP_format="4">\n' + _models("Go", "Lift", port="p") + "</root>\n",
    "/ws/e.xml": '<root BTCPP_format="4">\n' + _tree("B") + _tree("E") + "</root>\n",
}


def _fields(ctx: Context) -> tuple[object, ...]:
    return (
        ctx.path,
        list(ctx.models.items()),
        list(ctx.subtree_models.items()),
        list(ctx.trees.items()),
        list(ctx.workspace_trees.items()),
        {k: ctx.workspace_trees.get(k) for k in ("A", "B", "C", "E", "Shared", "Nope")},
        ctx.workspace_has_custom_models,
        ctx.included_by,
        ctx.included,
        ctx.workspace_files,
        ctx.btcpp_version,
        ctx.btcpp_unclear,
    )


@pytest.mark.parametrize("own", sorted(DOCS))
@pytest.mark.parametrize("closure", [(), ("/ws/b.xml",), ("/ws/catalog.xml", "/ws/e.xml")])
@pytest.mark.parametrize("foreign", [(), ("/ws/catalog.xml", "/ws/b.xml")])
def test_the_shared_context_is_the_combined_one(
    own: str, closure: tuple[str, ...], foreign: tuple[str, ...]
) -> None:
    """Also with other packages' files, whose models do not count (their trees do)."""
    docs = {p: Document(t, p) for p, t in DOCS.items()}
    closure = tuple(p for p in closure if p != own)
    included = [(p, docs[p]) for p in closure]
    rest = [(p, d, False) for p, d in docs.items() if p != own and p not in closure]
    model_files = [("/models/m.xml", Document(DOCS["/ws/catalog.xml"], "/models/m.xml"))]
    expected = Context.combine(
        docs[own],
        [(p, d, True) for p, d in included] + rest,
        path=own,
        model_files=model_files,
        included_by=["/ws/x.xml"],
        btcpp_version="4",
        foreign=foreign,
        btcpp_unclear=bool(foreign),
    )
    shared = SharedDecls(list(docs.items()))
    got = shared.context(
        docs[own],
        included,
        path=own,
        model_files=model_files,
        included_by=["/ws/x.xml"],
        btcpp_version="4",
        foreign=foreign,
        btcpp_unclear=bool(foreign),
    )
    assert _fields(got) == _fields(expected)
    # An edit of the document changes its own declarations only: the rest is the same.
    again = SharedDecls(list(docs.items())).context(docs[own], included, path=own)
    assert again.sources[len(closure) + 1] == got.sources[len(closure) + 1]


def _folder(root: Path, n: int) -> None:
    """``n`` small files calling each other's trees, some including another."""
    root.mkdir()
    (root / "models.xml").write_text(
        '<root BTCPP_format="4"><TreeNodesModel><Action ID="Say">'
        '<input_port name="text"/></Action></TreeNodesModel></root>\n'
    )
    for i in range(n):
        include = f'<include path="t{i - 1}.xml"/>' if i % 4 == 1 else ""
        (root / f"t{i}.xml").write_text(
            f'<root BTCPP_format="4">{include}<BehaviorTree ID="T{i}"><Sequence>'
            f'<SubTree ID="T{(i * 7 + 3) % n}"/><Say text="hi"/></Sequence></BehaviorTree>'
            "</root>\n"
        )


def _work_per_file(tmp_path: Path, n: int, monkeypatch: pytest.MonkeyPatch) -> float:
    """The calls of the per-document work of combining contexts (reading a document's
    declarations, its includes), per file checked, over a check of ``n`` files."""
    calls = itertools.count()
    real_facts = context_module.facts_of
    real_includes = IncludeGraph.of

    def facts_of(*args: object, **kw: object) -> object:
        next(calls)
        return real_facts(*args, **kw)  # type: ignore[arg-type]

    def includes(self: IncludeGraph, *args: object, **kw: object) -> object:
        next(calls)
        return real_includes(self, *args, **kw)  # type: ignore[arg-type]

    monkeypatch.setattr(context_module, "facts_of", facts_of)
    monkeypatch.setattr(shared_context, "facts_of", facts_of)
    monkeypatch.setattr(IncludeGraph, "of", includes)
    folder = tmp_path / f"n{n}"
    _folder(folder, n)
    assert main(["check", "--no-cpp", "--no-progress", str(folder)]) == 0
    monkeypatch.undo()
    return next(calls) / n


def test_a_folder_check_does_bounded_work_per_file(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    small = _work_per_file(tmp_path, 30, monkeypatch)
    large = _work_per_file(tmp_path, 120, monkeypatch)
    # Linear: the same work per file whatever the number of files (it was 4x here).
    assert large <= small * 1.25, (small, large)


def test_a_folder_above_the_servers_cap_knows_every_tree(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """The server's workspace holds at most MAX_WORKSPACE_FILES files; check reads every
    file it checks, so a tree defined in any of them is known (it was an error beyond)."""
    monkeypatch.setattr(workspace_files, "MAX_WORKSPACE_FILES", 10)
    folder = tmp_path / "many"
    _folder(folder, 30)
    assert main(["check", "--no-cpp", "--no-progress", str(folder)]) == 0
    assert "error" not in capsys.readouterr().out
    assert len(ProjectIndex([folder]).files.paths()) == 10  # the server's cap is unchanged


def test_a_folder_check_parses_each_file_once(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """The file checked is the document the workspace read for the others' sake."""
    folder = tmp_path / "f"
    _folder(folder, 20)
    made = itertools.count()
    real = Document.__init__

    def init(self: Document, *args: object, **kw: object) -> None:
        next(made)
        real(self, *args, **kw)  # type: ignore[arg-type]

    monkeypatch.setattr(Document, "__init__", init)
    assert main(["check", "--no-cpp", "--no-progress", str(folder)]) == 0
    assert next(made) <= 21 + 1  # 21 files; the first one checked is read before the rest
