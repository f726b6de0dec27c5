"""A publication reuses the JSON of the diagnostics an edit left unchanged: after typing
in one tree of a document with many diagnostics, only the diagnostics whose content
changed are converted again, and the text published is what a fresh conversion gives."""

from __future__ import annotations

import json

from lsprotocol import types
from pygls.protocol import default_converter

from bt_lsp.rules.analysis import analyze
from bt_lsp.server.convert import DiagnosticJson, to_diagnostic
from bt_lsp.syntax.document import Document

TREE = (
    '  <BehaviorTree ID="T{n}">\n'
    '    <Sequence name="s{n}">\n'
    '      <Move goalx="{{a}}" speed="1"/>\n'
    '      <Move goalx="{{b}}" speed="2"/>\n'
    "    </Sequence>\n"
    "  </BehaviorTree>\n"
)
MODELS = (
    "  <TreeNodesModel>\n"
    '    <Action ID="Move"><input_port name="goal"/><input_port name="speed"/></Action>\n'
    "  </TreeNodesModel>\n"
)


def document(trees: int) -> Document:
    body = "".join(TREE.format(n=n) for n in range(trees))
    return Document(f'<root BTCPP_format="4" main_tree_to_execute="T0">\n{body}{MODELS}</root>\n')


def fresh(doc: Document, enc: str = "utf-16") -> list[object]:
    """The diagnostics as lsprotocol gives them, unstructured (the reference)."""
    conv = default_converter()
    return [
        conv.unstructure(to_diagnostic(doc.lines, d, enc), types.Diagnostic)  # type: ignore[arg-type]
        for d in analyze(doc)
    ]


def test_an_edit_converts_only_the_diagnostics_it_changed() -> None:
    doc = document(30)
    published = DiagnosticJson()
    first = json.loads(published.array(doc.lines, analyze(doc), "utf-16"))
    assert first == fresh(doc)
    per_tree = 4  # two undeclared `goalx`, two missing `goal`
    assert len(first) == 30 * per_tree
    converted = published.converted
    assert 0 < converted < len(first)  # the same message twice is written once

    # Typing in a name of tree 12 moves every later diagnostic and changes none.
    at = doc.text.index('name="s12') + len('name="s12')
    doc.edit(at, at, "x")
    again = published.array(doc.lines, analyze(doc), "utf-16")
    assert json.loads(again) == fresh(doc)
    assert published.converted == converted

    # A new line moves every later diagnostic down a line: still nothing to convert.
    doc.edit(at, at, "\n")
    assert json.loads(published.array(doc.lines, analyze(doc), "utf-16")) == fresh(doc)
    assert published.converted == converted

    # Renaming one port changes the message of its diagnostic alone.
    at = doc.text.index("goalx", doc.text.index('ID="T7"'))
    doc.edit(at, at + len("goalx"), "goalz")
    assert json.loads(published.array(doc.lines, analyze(doc), "utf-16")) == fresh(doc)
    assert published.converted == converted + 1


def test_parts_of_diagnostics_no_longer_published_are_forgotten() -> None:
    doc = document(3)
    published = DiagnosticJson()
    published.array(doc.lines, analyze(doc), "utf-16")
    published.array(doc.lines, [], "utf-16")
    converted = published.converted
    assert json.loads(published.array(doc.lines, analyze(doc), "utf-16")) == fresh(doc)
    assert published.converted > converted  # written again: nothing was kept


def test_without_code_descriptions_nothing_described_is_reused() -> None:
    doc = document(2)
    published = DiagnosticJson()
    described = json.loads(published.array(doc.lines, analyze(doc), "utf-16"))
    assert all("codeDescription" in d for d in described)
    plain = json.loads(published.array(doc.lines, analyze(doc), "utf-16", described=False))
    assert plain and all("codeDescription" not in d for d in plain)


def test_a_pulled_report_reuses_the_unchanged_diagnostics_json() -> None:
    """textDocument/diagnostic writes its items with the document's DiagnosticJson, as a
    publication does: after an edit that changes no diagnostic's content, nothing is
    converted again, and the items are what a fresh conversion gives."""
    from bt_lsp.server.app import create_server
    from bt_lsp.server.state import OpenDocument

    ls = create_server()
    ls.code_descriptions = True
    od = OpenDocument("untitled:pulled.xml", document(30), 1, "xml")
    od.refresh_kind()
    ls.docs[od.uri] = od
    first = json.loads(ls.diagnostics.as_json(od))
    assert first == fresh(od.doc)
    converted = od.published.converted
    assert converted > 0
    at = od.doc.text.index('    <Sequence name="s12')
    od.doc.edit(at, at, "\n")  # every later diagnostic moves a line down
    od.version = 2
    ls.edits += 1
    again = json.loads(ls.diagnostics.as_json(od))
    assert again == fresh(od.doc) != first  # moved, and written anew where they moved to
    assert od.published.converted == converted
