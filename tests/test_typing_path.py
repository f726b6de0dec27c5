"""What the analysis of a one-character edit does not do again.

The server analyses a large document on a snapshot of it (``bt_lsp.server.background``)
and hands the snapshot's model back to the open document; the next edit's model is built
from that one, sharing every section but the edited one, so that the semantic pass checks
that section alone.  These tests pin down the work an edit of the only open document of a
workspace leaves out; ``tests/test_incremental.py`` checks that what it keeps gives what a
fresh analysis gives.
"""

from __future__ import annotations

import itertools
from pathlib import Path

import pytest

from bt_lsp.project import file_context
from bt_lsp.project.index import ProjectIndex
from bt_lsp.rules import shared_context
from bt_lsp.rules.semantics import sections as section_checks
from bt_lsp.syntax.document import Document
from bt_lsp.syntax.table import ElementTable

# Tree T0 is called by no other tree; each other Ti is called by T(i-1).  The models
# section has long elements, which its table keeps once made.
_PORTS = "".join(
    f'<input_port name="p{k}" type="std::string">a port described at length</input_port>'
    for k in range(4)
)
TEXT = (
    '<root BTCPP_format="4" main_tree_to_execute="T0">\n'
    + "".join(
        f'  <BehaviorTree ID="T{i}"><Sequence name="s{i}"><SubTree ID="T{i + 1}"/>'
        f'<Go p0="x"/></Sequence></BehaviorTree>\n'
        for i in range(8)
    )
    + '  <BehaviorTree ID="T8"><Go p0="y"/></BehaviorTree>\n'
    + f'  <TreeNodesModel><Action ID="Go">{_PORTS}</Action>'
    + "".join(f'<Action ID="Other{k}">{_PORTS}</Action>' for k in range(6))
    + "</TreeNodesModel>\n</root>\n"
)


def _workspace(tmp_path: Path) -> tuple[ProjectIndex, Path, Document]:
    path = tmp_path / "main.xml"
    path.write_text(TEXT, encoding="utf-8")
    (tmp_path / "other.xml").write_text(
        '<root BTCPP_format="4"><BehaviorTree ID="Far"><Go p0="z"/></BehaviorTree></root>\n',
        encoding="utf-8",
    )
    ws = ProjectIndex([tmp_path])
    doc = Document(TEXT, str(path))
    ws.open(path, doc)
    ws.diagnostics(path, doc)
    return ws, path, doc


def _type(doc: Document, after: str) -> None:
    """A letter typed at the end of the value that ``after`` ends in."""
    at = doc.text.index(after) + len(after) - 1
    doc.edit(at, at, "x")


def _analysed(ws: ProjectIndex, path: Path, doc: Document) -> list[object]:
    """As the server does: the diagnostics of a snapshot, whose model the document keeps."""
    snap = doc.snapshot()
    found: list[object] = list(ws.diagnostics(path, snap))
    doc.adopt(snap)
    return found


def test_the_open_document_keeps_the_model_of_its_analysed_snapshot(tmp_path: Path) -> None:
    """The analysis of the snapshot makes no model of the open document (a second one,
    which the open document kept instead of the snapshot's, made the next edit's model
    differ from the last one analysed in two sections and every section between)."""
    ws, path, doc = _workspace(tmp_path)
    _type(doc, 'name="s3"')
    snap = doc.snapshot()
    ws.diagnostics(path, snap)
    doc.adopt(snap)
    assert doc.model is snap.model


def test_edits_of_the_only_open_document_combine_the_workspace_once(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """What the other documents declare is combined again when one of them changes, not
    at each edit of the document whose own declarations it leaves out."""
    ws, path, doc = _workspace(tmp_path)
    made: list[object] = []
    real = shared_context.SharedDecls

    def counted(*args: object) -> object:
        made.append(args)
        return real(*args)  # type: ignore[arg-type]

    monkeypatch.setattr(file_context, "SharedDecls", counted)
    for k in range(4):
        _type(doc, f'name="s{k}"')
        _analysed(ws, path, doc)
    assert made == []
    other = tmp_path / "other.xml"
    other_doc = Document(other.read_text(encoding="utf-8"), str(other))
    ws.open(other, other_doc)
    _type(other_doc, 'ID="Far"')
    _analysed(ws, path, doc)
    assert len(made) == 1
    fresh = ProjectIndex([tmp_path])
    fresh.open(other, Document(other_doc.text, str(other)))
    again = Document(doc.text, str(path))
    fresh.open(path, again)
    assert _analysed(ws, path, doc) == list(fresh.diagnostics(path, again))


def test_typing_in_a_tree_no_other_calls_checks_that_tree_alone(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The ID of the tree typed in is new to the entries that the sections' results read
    (no other tree calls T0): the other sections are not looked at."""
    ws, path, doc = _workspace(tmp_path)
    looked = itertools.count()
    real = section_checks._unaffected

    def counted(*args: object) -> bool:
        next(looked)
        return real(*args)  # type: ignore[arg-type]

    monkeypatch.setattr(section_checks, "_unaffected", counted)
    _type(doc, 'name="s0"')
    got = _analysed(ws, path, doc)
    assert next(looked) == 0
    fresh = ProjectIndex([tmp_path])
    again = Document(doc.text, str(path))
    fresh.open(path, again)
    assert got == list(fresh.diagnostics(path, again))


def test_an_edit_before_a_section_that_keeps_its_elements_makes_only_its_top(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """The root's ``<TreeNodesModel>``, moved by an edit before it, is read without making
    every element of its section."""
    doc = Document(TEXT)
    (models,) = doc.model.root_children_named(("TreeNodesModel",))
    section = doc.model.sections[-1]
    assert section.elements.kept and len(section.elements) > 30
    _type(doc, 'name="s2"')
    kept = itertools.count()
    real = ElementTable._kept

    def counted(self: ElementTable) -> object:
        next(kept)
        return real(self)

    monkeypatch.setattr(ElementTable, "_kept", counted)
    (moved,) = doc.model.root_children_named(("TreeNodesModel",))
    assert next(kept) == 0
    assert moved.token_start == models.token_start + 1
    assert moved.attrs == models.attrs
    assert list(moved.children) == list(models.children)
