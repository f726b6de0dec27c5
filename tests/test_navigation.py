"""Navigation core: definition, references, highlights, rename, symbols, folding, linked
editing.  Fixtures mark expected spans with ``⟦…⟧`` and the cursor with ``‸``."""

from __future__ import annotations

import contextlib
from pathlib import Path

import pytest
from lxml import etree

from bt_lsp.ide.blackboard import key_at
from bt_lsp.ide.catalog import BUILTIN_CATALOG, builtin_catalog
from bt_lsp.ide.definition import definition
from bt_lsp.ide.folding import Fold, folding_ranges, linked_editing_ranges
from bt_lsp.ide.places import Place
from bt_lsp.ide.references import MAX_HIGHLIGHTS, highlights, references
from bt_lsp.ide.rename import RenameRefused, prepare_rename, rename
from bt_lsp.ide.symbols import DocSymbol, SymbolKind, document_symbols, workspace_symbols
from bt_lsp.project.index import ProjectIndex, links, normalize
from bt_lsp.rules.analysis import analyze
from bt_lsp.rules.builtins import BUILTINS
from bt_lsp.rules.diagnostics import own_diagnostics
from bt_lsp.syntax.document import Document
from bt_lsp.syntax.edits import apply_edits
from bt_lsp.syntax.elements import model_symbol, port_symbol
from tests.marks import cursor


def spans_of(places: list[Place], path: str | None = None) -> list[tuple[int, int]]:
    return sorted((p.start, p.end) for p in places if p.path == path)


DOC = """\
<root BTCPP_format="4" main_tree_to_execute="{main}">
  <BehaviorTree ID="{main_def}">
    <Sequence name="seq">
      <{move} goal="{{target}}" speed="1"/>
      <Action ID="{move2}" goal="{{other}}"/>
      <SubTree ID="{dock}" pose="{{target}}"/>
      <{move3}></{move3_end}>
    </Sequence>
  </BehaviorTree>
  <BehaviorTree ID="{dock_def}">
    <MoveBase goal="{{target}}"/>
  </BehaviorTree>
  <TreeNodesModel>
    <Action ID="{move_def}">
      <input_port name="{goal_def}" type="Pose">Where to go</input_port>
      <input_port name="speed" default="0.5"/>
    </Action>
    <SubTree ID="{dock_model}"><input_port name="{pose_def}"/></SubTree>
  </TreeNodesModel>
</root>
"""
NAMES = {
    "main": "Main",
    "main_def": "Main",
    "move": "MoveBase",
    "move2": "MoveBase",
    "dock": "Dock",
    "move3": "MoveBase",
    "move3_end": "MoveBase",
    "dock_def": "Dock",
    "move_def": "MoveBase",
    "goal_def": "goal",
    "dock_model": "Dock",
    "pose_def": "pose",
}


def doc_with(**marks: str) -> str:
    """DOC with some names replaced by marked text (``⟦Dock⟧``, ``Do‸ck``)."""
    return DOC.format(**{**NAMES, **marks})


def at(marked: str) -> tuple[Document, int, list[tuple[int, int]]]:
    text, offset, spans = cursor(marked)
    return Document(text), offset, spans


# --- definition ---------------------------------------------------------------------------


def test_subtree_call_leads_to_its_tree() -> None:
    doc, off, spans = at(doc_with(dock="Do‸ck", dock_def="⟦Dock⟧"))
    assert spans_of(definition(doc, off)) == spans


def test_main_tree_to_execute_leads_to_its_tree() -> None:
    doc, off, spans = at(doc_with(main="‸Main", main_def="⟦Main⟧"))
    assert spans_of(definition(doc, off)) == spans


def test_compact_node_and_explicit_id_lead_to_the_model_entry() -> None:
    for mark in ("move", "move2", "move3_end"):
        doc, off, spans = at(doc_with(**{mark: "Move‸Base", "move_def": "⟦MoveBase⟧"}))
        assert spans_of(definition(doc, off)) == spans, mark


def test_port_attribute_leads_to_its_declaration() -> None:
    text = doc_with(goal_def="⟦goal⟧").replace(
        '<MoveBase goal="{target}"/>', '<MoveBase go‸al=""/>'
    )
    doc, off, spans = at(text)
    assert spans_of(definition(doc, off)) == spans
    text = doc_with(pose_def="⟦pose⟧").replace('pose="{target}"', 'po‸se="{target}"')
    doc, off, spans = at(text)
    assert spans_of(definition(doc, off)) == spans


def test_a_declaration_leads_to_itself() -> None:
    doc, off, spans = at(doc_with(dock_def="⟦Do‸ck⟧"))
    assert spans_of(definition(doc, off)) == spans


def test_builtin_node_and_port_lead_to_the_builtin_catalog() -> None:
    doc, off, _ = at(doc_with().replace("<Sequence name", "<Seq‸uence name"))
    (place,) = definition(doc, off)
    assert place.path == BUILTIN_CATALOG
    catalog = builtin_catalog().text
    assert catalog[place.start : place.end] == "Sequence"
    assert BUILTINS["Sequence"].description.split()[0] in catalog[place.start - 300 : place.start]
    doc, off, _ = at('<root><BehaviorTree ID="T"><Sleep ms‸ec="1"/></BehaviorTree></root>')
    (place,) = definition(doc, off)
    assert place.path == BUILTIN_CATALOG and catalog[place.start : place.end] == "msec"


def test_nothing_to_define_outside_names() -> None:
    doc, off, _ = at(doc_with().replace("<root BTCPP", "<ro‸ot BTCPP"))
    assert definition(doc, off) == []
    doc, off, _ = at(doc_with().replace('speed="1"', 'speed="‸1"'))
    assert definition(doc, off) == []


def test_builtin_catalog_is_a_clean_tree_nodes_model() -> None:
    cat = builtin_catalog()
    etree.fromstring(cat.text.encode())
    assert analyze(Document(cat.text)) == []
    for node in BUILTINS.values():
        if node.category == "SubTree":
            continue
        s, e = cat.spans[model_symbol(node.id)]
        assert cat.text[s:e] == node.id
        for p in node.ports:
            s, e = cat.spans[port_symbol(model_symbol(node.id), p.name)]
            assert cat.text[s:e] == p.name


def _write(path: Path, text: str) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text, encoding="utf-8")
    return normalize(path)


def test_definition_across_files_prefers_the_include_closure(tmp_path: Path) -> None:
    main = _write(
        tmp_path / "main.xml",
        '<root BTCPP_format="4"><include path="sub/dock.xml"/>'
        '<BehaviorTree ID="Main"><SubTree ID="Dock"/></BehaviorTree></root>',
    )
    dock = _write(
        tmp_path / "sub" / "dock.xml",
        '<root BTCPP_format="4"><BehaviorTree ID="Dock"><Nav/></BehaviorTree>'
        '<TreeNodesModel><Action ID="Nav"/></TreeNodesModel></root>',
    )
    # An unrelated file that also declares a tree "Dock" (sorted before sub/dock.xml).
    _write(
        tmp_path / "a_other.xml",
        '<root BTCPP_format="4"><BehaviorTree ID="Dock"><Nav/></BehaviorTree></root>',
    )
    ws = ProjectIndex([tmp_path])
    doc = ws.document(main)
    assert doc is not None
    others = {str(p): d for p, d in ws.bt_documents() if p != main}
    ctx = ws.context_for(main, doc)
    includes = links(ws.includes.of(main, doc))
    off = doc.text.index('"Dock"') + 2
    (place,) = definition(doc, off, others, ctx=ctx, includes=includes)
    assert place.path == str(dock)
    assert others[str(dock)].text[place.start : place.end] == "Dock"
    # Without a context, the first declaration found in the workspace is as good as any.
    assert definition(doc, off, others)
    # The include path leads to the file.
    off = doc.text.index("sub/dock.xml") + 3
    assert definition(doc, off, others, ctx=ctx, includes=includes) == [Place(str(dock), 0, 0)]
    # A node declared in another file's TreeNodesModel.
    dock_doc = others[str(dock)]
    off = dock_doc.text.index("<Nav/>") + 2
    found = definition(dock_doc, off, {str(main): doc}, ctx=ws.context_for(dock, dock_doc))
    assert [dock_doc.text[p.start : p.end] for p in found] == ["Nav"]
    assert found[0].path is None


# --- references and highlights ------------------------------------------------------------


def test_references_of_a_model_in_this_and_other_documents() -> None:
    doc, off, spans = at(
        doc_with(
            move="⟦Move‸Base⟧", move2="⟦MoveBase⟧", move3="⟦MoveBase⟧", move_def="⟦MoveBase⟧"
        ).replace('<MoveBase goal="{target}"/>', '<⟦MoveBase⟧ goal="{target}"/>')
    )
    other = Document('<root><BehaviorTree ID="X"><MoveBase/></BehaviorTree></root>')
    found = references(doc, off, {"/ws/other.xml": other})
    assert spans_of(found) == spans  # the end tag is left out
    start = other.text.index("MoveBase")
    assert spans_of(found, "/ws/other.xml") == [(start, start + 8)]


def test_references_without_declaration() -> None:
    doc, off, spans = at(doc_with(dock="⟦Do‸ck⟧"))
    assert spans_of(references(doc, off, include_declaration=False)) == spans


def test_references_of_a_blackboard_key_stay_in_its_tree() -> None:
    text = doc_with().replace('goal="{target}" speed', 'goal="{⟦tar‸get⟧}" speed')
    # (spaces outside the braces are trimmed: " {target} " is the key "target")
    text = text.replace('pose="{target}"', 'pose=" {⟦target⟧} "')
    doc, off, spans = at(text)
    assert spans_of(references(doc, off)) == spans
    key = key_at(doc, off)
    assert key is not None and key.key == "target"


def test_highlights_mark_declarations_as_writes() -> None:
    doc, off, spans = at(doc_with(dock="⟦Do‸ck⟧", dock_def="⟦Dock⟧", dock_model="⟦Dock⟧"))
    found = highlights(doc, off)
    assert [(h.start, h.end) for h in found] == spans
    assert [h.write for h in found] == [False, True, True]


@pytest.mark.parametrize("where", [0.0, 0.5, 1.0])
def test_highlights_are_those_nearest_the_cursor(where: float) -> None:
    """A name used more than MAX_HIGHLIGHTS times gets that many highlights, the nearest
    to the cursor in document order (the cursor's own among them)."""
    n = MAX_HIGHLIGHTS * 3
    text = (
        '<root BTCPP_format="4"><BehaviorTree ID="T"><Sequence>'
        + '<Frob a="1"/>' * n
        + '</Sequence></BehaviorTree><BehaviorTree ID="U"><Frob/></BehaviorTree></root>'
    )
    doc = Document(text)
    uses = [i + 1 for i in range(len(text)) if text.startswith("<Frob", i)]
    at = uses[min(int(where * len(uses)), len(uses) - 1)] + 2
    found = highlights(doc, at)
    assert len(found) == MAX_HIGHLIGHTS
    starts = [h.start for h in found]
    assert starts == sorted(starts)
    k = uses.index(starts[0])
    assert starts == uses[k : k + MAX_HIGHLIGHTS]  # a run of neighbours, none skipped
    assert any(h.start <= at <= h.end for h in found)
    # Centred on the cursor's use, shifted where the document begins or ends.
    c = next(i for i, u in enumerate(uses) if u <= at <= u + 4)
    assert k == max(0, min(c - MAX_HIGHLIGHTS // 2, len(uses) - MAX_HIGHLIGHTS))


def test_highlights_of_a_compact_node_include_end_tags() -> None:
    doc, off, spans = at(
        doc_with(
            move="⟦MoveBase⟧",
            move3="⟦MoveBase⟧",
            move3_end="⟦Move‸Base⟧",
            move2="⟦MoveBase⟧",
            move_def="⟦MoveBase⟧",
        ).replace('<MoveBase goal="{target}"/>', '<⟦MoveBase⟧ goal="{target}"/>')
    )
    assert [(h.start, h.end) for h in highlights(doc, off)] == spans


def test_highlights_of_other_tags_pair_start_and_end() -> None:
    doc, off, spans = at('<root><⟦Behavior‸Tree⟧ ID="A"><X/></⟦BehaviorTree⟧></root>')
    found = highlights(doc, off)
    assert [(h.start, h.end) for h in found] == spans and all(h.text for h in found)


def test_highlights_of_an_instance_name_and_of_nothing() -> None:
    doc, off, spans = at(doc_with().replace('name="seq"', 'name="⟦s‸eq⟧"'))
    assert [(h.start, h.end) for h in highlights(doc, off)] == spans
    doc, off, _ = at(doc_with().replace("  <TreeNodesModel>", "‸  <TreeNodesModel>"))
    assert highlights(doc, off) == []


# --- rename -------------------------------------------------------------------------------


def test_prepare_rename_gives_the_name_span_and_text() -> None:
    doc, off, spans = at(doc_with(dock="⟦Do‸ck⟧"))
    target = prepare_rename(doc, off)
    assert target is not None
    assert (target.start, target.end) == spans[0] and target.placeholder == "Dock"


def test_prepare_rename_nowhere_is_none() -> None:
    doc, off, _ = at(doc_with().replace("<root BTCPP", "<root ‸BTCPP"))
    assert prepare_rename(doc, off) is None
    assert rename(doc, off, "X") is None


@pytest.mark.parametrize(
    ("text", "reason"),
    [
        (
            doc_with().replace("<Sequence name", "<Seq‸uence name"),
            "'Sequence' is a built-in node type",
        ),
        (
            '<root><BehaviorTree ID="T"><Sleep ms‸ec="1"/></BehaviorTree></root>',
            "'msec' is a port of the built-in node 'Sleep'",
        ),
    ],
)
def test_builtins_cannot_be_renamed(text: str, reason: str) -> None:
    doc, off, _ = at(text)
    with pytest.raises(RenameRefused, match=reason):
        prepare_rename(doc, off)
    with pytest.raises(RenameRefused, match=reason):
        rename(doc, off, "Other")


def test_rename_tree_reaches_calls_main_tree_model_entry_and_other_files() -> None:
    doc, off, _ = at(doc_with(dock="Do‸ck"))
    other = Document('<root><BehaviorTree ID="X"><SubTree ID="Dock"/></BehaviorTree></root>')
    plan = rename(doc, off, "Docking", {"/ws/x.xml": other})
    assert plan is not None and plan.places == 4
    new = apply_edits(doc.text, plan.edits)
    assert new.count('"Docking"') == 3 and '"Dock"' not in new
    assert apply_edits(other.text, plan.other_edits["/ws/x.xml"]).count('"Docking"') == 1
    etree.fromstring(new.encode())


def test_rename_model_reaches_element_names_end_tags_ids_and_entry() -> None:
    doc, off, _ = at(doc_with(move2="Move‸Base"))
    plan = rename(doc, off, "Drive")
    assert plan is not None
    new = apply_edits(doc.text, plan.edits)
    assert "MoveBase" not in new and new.count("Drive") == 6
    etree.fromstring(new.encode())
    assert not [d for d in own_diagnostics(Document(new)) if d.is_name_rule]


def test_rename_port_reaches_uses_of_that_model_only() -> None:
    text = doc_with(goal_def="go‸al").replace(
        "  </BehaviorTree>\n  <TreeNodesModel>",
        '  </BehaviorTree>\n  <BehaviorTree ID="T"><Other goal="1"/></BehaviorTree>\n'
        "  <TreeNodesModel>",
    )
    doc, off, _ = at(text)
    plan = rename(doc, off, "target")
    assert plan is not None
    new = apply_edits(doc.text, plan.edits)
    assert new.count(' target="') == 3  # MoveBase: compact, explicit, in Dock
    assert '<input_port name="target" type="Pose">' in new
    assert '<Other goal="1"/>' in new


def test_rename_instance_name_changes_only_it() -> None:
    doc, off, _ = at(doc_with().replace('name="seq"', 'name="s‸eq"'))
    plan = rename(doc, off, "main loop: phase 1.2")
    assert plan is not None and plan.places == 1
    assert 'name="main loop: phase 1.2"' in apply_edits(doc.text, plan.edits)


def test_rename_escapes_values() -> None:
    doc, off, _ = at('<root><BehaviorTree ID="T"><X name="a‸"/></BehaviorTree></root>')
    plan = rename(doc, off, 'say "hi" & <go>')
    assert plan is not None
    new = apply_edits(doc.text, plan.edits)
    assert 'name="say &quot;hi&quot; &amp; &lt;go>"' in new
    etree.fromstring(new.encode())


@pytest.mark.parametrize(
    ("cursor", "new", "reason"),
    [
        ({"dock": "Do‸ck"}, "Dock.2", r"forbidden character: '\.' \(period\)"),
        ({"dock": "Do‸ck"}, "Root", "reserved"),
        ({"dock": "Do‸ck"}, "", "empty"),
        ({"dock": "Do‸ck"}, "Main", "already exists"),
        ({"dock": "Do‸ck"}, "Sequence", "built-in node type"),
        ({"move": "Move‸Base"}, "1Move", "not a valid XML name"),
        ({"goal_def": "go‸al"}, "_goal", "must start with an ASCII letter"),
        ({"goal_def": "go‸al"}, "1goal", "cannot start with a digit"),
        ({"goal_def": "go‸al"}, "_skipIf", "reserved attribute name"),
        ({"goal_def": "go‸al"}, "speed", "already has a port"),
        ({"goal_def": "go‸al"}, "a,b", "not a valid XML name"),
    ],
)
def test_rename_refuses_a_name_that_breaks_a_rule(
    cursor: dict[str, str], new: str, reason: str
) -> None:
    doc, off, _ = at(doc_with(**cursor))
    with pytest.raises(RenameRefused, match=reason) as info:
        rename(doc, off, new)
    assert info.value.message.startswith(f"Cannot rename to '{new}'")


def test_rename_to_the_same_name_is_allowed() -> None:
    doc, off, _ = at(doc_with(dock="Do‸ck"))
    plan = rename(doc, off, "Dock")
    assert plan is not None and apply_edits(doc.text, plan.edits) == doc.text


def test_instance_rename_refuses_control_characters() -> None:
    doc, off, _ = at(doc_with().replace('name="seq"', 'name="s‸eq"'))
    with pytest.raises(RenameRefused, match="control character"):
        rename(doc, off, "a\x07b")


# --- symbols ------------------------------------------------------------------------------


def outline(symbols: list[DocSymbol], text: str) -> list[object]:
    out: list[object] = []
    for s in symbols:
        assert s.start <= s.sel_start <= s.sel_end <= s.end
        for c in s.children:
            assert s.start <= c.start and c.end <= s.end
        entry: tuple[object, ...] = (s.kind.value, s.name, s.detail, text[s.sel_start : s.sel_end])
        out.append((*entry, outline(s.children, text)) if s.children else entry)
    return out


def test_document_symbols_are_a_hierarchy() -> None:
    doc = Document(doc_with())
    assert outline(document_symbols(doc), doc.text) == [
        (
            "tree",
            "Main",
            "BehaviorTree",
            "Main",
            [
                (
                    "node",
                    "seq",
                    "Control Sequence",
                    "Sequence",
                    [
                        ("node", "MoveBase", "Action", "MoveBase"),
                        ("node", "MoveBase", "Action MoveBase", "MoveBase"),
                        ("subtree call", "Dock", "SubTree Dock", "Dock"),
                        ("node", "MoveBase", "Action", "MoveBase"),
                    ],
                )
            ],
        ),
        ("tree", "Dock", "BehaviorTree", "Dock", [("node", "MoveBase", "Action", "MoveBase")]),
        (
            "TreeNodesModel",
            "TreeNodesModel",
            "",
            "TreeNodesModel",
            [
                (
                    "model",
                    "MoveBase",
                    "Action",
                    "MoveBase",
                    [
                        ("port", "goal", "input port: Pose", "goal"),
                        ("port", "speed", "input port", "speed"),
                    ],
                ),
                ("model", "Dock", "SubTree", "Dock", [("port", "pose", "input port", "pose")]),
            ],
        ),
    ]


def test_document_symbols_of_broken_text_have_names_and_nest() -> None:
    text = (
        '<root><include path="a.xml"/><BehaviorTree><Sequence><Foo x="1">\n'
        '<SubTree/><Action/><BehaviorTree ID=""><TreeNodesModel><input_port/>'
    )
    doc = Document(text)
    symbols = document_symbols(doc)
    assert outline(symbols, text)  # ranges nest (checked by outline)
    names = []
    stack = list(symbols)
    while stack:
        s = stack.pop()
        names.append(s.name)
        stack.extend(s.children)
    assert all(names) and "a.xml" in names and "(no ID)" in names


def test_workspace_symbols_match_a_subsequence() -> None:
    a = Document(doc_with())
    b = Document('<root><BehaviorTree ID="Navigate"/></root>')
    found = workspace_symbols([("a", a), ("b", b)], "nav")
    assert [(s.name, s.kind, s.path) for s in found] == [("Navigate", SymbolKind.TREE, "b")]
    found = workspace_symbols([("a", a), ("b", b)], "mb")
    assert [(s.name, s.detail) for s in found] == [("MoveBase", "Action")]
    everything = workspace_symbols([("a", a), ("b", b)])
    assert [s.name for s in everything] == ["Main", "Dock", "MoveBase", "Dock", "Navigate"]
    assert len(workspace_symbols([("a", a), ("b", b)], limit=2)) == 2
    s = everything[0]
    assert a.text[s.start : s.end] == "Main"


# --- folding and linked editing -----------------------------------------------------------


def test_folding_keeps_end_tags_visible_and_folds_comments() -> None:
    text = (
        "<root>\n"  # 0
        '  <BehaviorTree ID="A">\n'  # 1
        "    <Sequence><X/></Sequence>\n"  # 2: one line, no fold
        "    <!-- a\n"  # 3
        "      comment -->\n"  # 4
        "    <Y a='1'\n"  # 5
        "       b='2'/>\n"  # 6
        "    <Z>\n"  # 7
        "    </Z><W>\n"  # 8
        "    </W>\n"  # 9
        "  </BehaviorTree></root>\n"  # 10
    )
    assert folding_ranges(Document(text)) == [
        Fold(0, 10),  # </root> shares its line with </BehaviorTree>: it stays folded
        Fold(1, 9),
        Fold(3, 4, comment=True),
        Fold(5, 6),  # a start tag over two lines; <Z> and <W> keep their end tag visible
    ]


def test_linked_editing_pairs_start_and_end_tag_names() -> None:
    doc, off, spans = at("<root><⟦Sequ‸ence⟧><X/></⟦Sequence⟧></root>")
    assert linked_editing_ranges(doc, off) == spans
    doc, off, spans = at("<root><⟦Sequence⟧><X/></⟦Seq‸uence⟧></root>")
    assert linked_editing_ranges(doc, off) == spans
    doc, off, _ = at("<root><Sequence><X‸/></Sequence></root>")
    assert linked_editing_ranges(doc, off) is None  # self-closing
    doc, off, _ = at("<root><Sequence ‸name='x'><X/></Sequence></root>")
    assert linked_editing_ranges(doc, off) is None


# --- robustness ---------------------------------------------------------------------------


def test_every_offset_of_every_prefix_is_safe() -> None:
    text = doc_with()
    for cut in range(0, len(text), 7):
        doc = Document(text[:cut])
        for off in range(0, cut + 1, 5):
            definition(doc, off)
            references(doc, off)
            highlights(doc, off)
            linked_editing_ranges(doc, off)
            with contextlib.suppress(RenameRefused):
                prepare_rename(doc, off)
        document_symbols(doc)
        folding_ranges(doc)
