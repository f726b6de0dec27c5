"""The tree renderer: what a picture holds, its layout's geometry, and the three outputs."""

from __future__ import annotations

import re
from itertools import pairwise
from typing import Any
from xml.sax.saxutils import quoteattr

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from lxml import etree

from bt_lsp.render import (
    build_picture,
    changed_node,
    find_tree,
    layout,
    main_tree,
    render,
    to_dot,
    to_mermaid,
    to_svg,
    tree_at,
    workspace_resolver,
)
from bt_lsp.render.layout import MARGIN, SIBLING_GAP
from bt_lsp.render.picture import MAX_NODES
from bt_lsp.rules.analysis import analyze
from bt_lsp.rules.codes import Severity
from bt_lsp.rules.context import Context
from bt_lsp.syntax.document import Document
from tests.layout_check import extents, problems

SVG_NS = "{http://www.w3.org/2000/svg}"

SAMPLE = """<root BTCPP_format="4" main_tree_to_execute="Main">
  <BehaviorTree ID="Main">
    <Sequence name="root seq">
      <CheckBattery/>
      <Fallback>
        <Condition ID="IsDoorOpen" door="{door}"/>
        <RetryUntilSuccessful num_attempts="3">
          <Action ID="OpenDoor" name="open &amp; &quot;push&quot;"/>
        </RetryUntilSuccessful>
      </Fallback>
      <SubTree ID="Walk" goal="{goal}"/>
      <Foo bar="1"/>
    </Sequence>
  </BehaviorTree>
  <BehaviorTree ID="Walk">
    <Sequence><Action ID="Move" to="{goal}"/><SubTree ID="Walk"/></Sequence>
  </BehaviorTree>
  <TreeNodesModel><Condition ID="CheckBattery"/></TreeNodesModel>
</root>
"""


def _attr(el: etree._Element, name: str) -> str:
    value = el.get(name)
    assert value is not None, name
    return value


def _found(el: etree._Element, path: str) -> etree._Element:
    found = el.find(path)
    assert found is not None, path
    return found


def _text(el: etree._Element) -> str:
    return "".join(str(t) for t in el.itertext())


def _picture(text: str = SAMPLE, **kw: Any):  # type: ignore[no-untyped-def]
    doc = Document(text)
    tree = main_tree(doc.model)
    assert tree is not None
    return doc, build_picture(
        doc.model, tree, ctx=Context.from_document(doc), diagnostics=analyze(doc), **kw
    )


# -- what is drawn ---------------------------------------------------------------------------


def test_nodes_kinds_names_and_spans() -> None:
    doc, pic = _picture()
    got = [(n.kind, n.type, n.name) for n in pic.nodes]
    assert got == [
        ("tree", "Main", None),
        ("control", "Sequence", "root seq"),
        ("condition", "CheckBattery", None),  # declared in the TreeNodesModel
        ("control", "Fallback", None),
        ("condition", "IsDoorOpen", None),
        ("decorator", "RetryUntilSuccessful", None),
        ("action", "OpenDoor", 'open & "push"'),
        ("subtree", "Walk", None),
        ("unknown", "Foo", None),  # neither built in nor declared: drawn neutrally
    ]
    seq = pic.nodes[1]
    assert doc.text[seq.start : seq.end].startswith("<Sequence name=")
    assert doc.text[seq.start : seq.end].endswith("</Sequence>")
    assert pic.nodes[7].subtree == "Walk" and not pic.nodes[7].expanded


def test_children_in_xml_order_and_parents() -> None:
    _, pic = _picture()
    assert pic.nodes[1].children == [2, 3, 7, 8]
    assert all(pic.nodes[c].parent == n.index for n in pic.nodes for c in n.children)


def test_problems_go_to_the_innermost_node() -> None:
    _doc, pic = _picture()
    by_type = {n.type: n for n in pic.nodes}
    assert by_type["Foo"].severity is not None
    assert any("Foo" in p for p in by_type["Foo"].problems)
    # The unknown-node hint of OpenDoor is OpenDoor's, not its decorator's or Sequence's.
    assert any("OpenDoor" in p for p in by_type["OpenDoor"].problems)
    assert not any("OpenDoor" in p for p in by_type["RetryUntilSuccessful"].problems)
    assert by_type["Sequence"].severity is None


def test_severity_is_the_worst() -> None:
    text = '<root BTCPP_format="4"><BehaviorTree ID="T"><Inverter><AlwaysSuccess/>'
    text += "<AlwaysFailure/></Inverter></BehaviorTree></root>"
    _doc, pic = _picture(text)
    inv = pic.nodes[1]
    assert inv.type == "Inverter" and inv.severity == Severity.ERROR


def test_expanded_subtree_inlines_and_stops_at_recursion() -> None:
    _, pic = _picture(expand_subtrees=True)
    walk = pic.nodes[7]
    assert walk.expanded
    inner = [pic.nodes[c] for c in walk.children]
    assert [n.type for n in inner] == ["Sequence"]
    calls = [pic.nodes[c] for c in inner[0].children]
    assert [(n.type, n.recursive, n.expanded) for n in calls] == [
        ("Move", False, False),
        ("Walk", True, False),
    ]
    # The recursion error of the inner call is on the drawn call.
    assert calls[1].severity == Severity.ERROR


def test_expansion_across_documents() -> None:
    main = Document(
        '<root BTCPP_format="4"><include path="b.xml"/><BehaviorTree ID="A">'
        '<SubTree ID="B"/></BehaviorTree></root>',
        "/ws/a.xml",
    )
    other = Document(
        '<root BTCPP_format="4"><BehaviorTree ID="B"><AlwaysSuccess/></BehaviorTree></root>',
        "/ws/b.xml",
    )
    ctx = Context.combine(main, [("/ws/b.xml", other, True)], path="/ws/a.xml")
    resolve = workspace_resolver(main.model, ctx, {"/ws/b.xml": other.model})
    tree = find_tree(main.model, "A")
    assert tree is not None
    pic = build_picture(main.model, tree, ctx=ctx, resolve=resolve, expand_subtrees=True)
    leaf = pic.nodes[-1]
    assert (leaf.type, leaf.source) == ("AlwaysSuccess", "/ws/b.xml")
    assert other.text[leaf.start : leaf.end] == "<AlwaysSuccess/>"


def test_expansion_is_bounded() -> None:
    # Each tree calls the next one twice: 2**20 nodes if inlined in full.
    trees = [
        f'<BehaviorTree ID="T{i}"><Sequence><SubTree ID="T{i + 1}"/><SubTree ID="T{i + 1}"/>'
        "</Sequence></BehaviorTree>"
        for i in range(20)
    ]
    text = f'<root BTCPP_format="4" main_tree_to_execute="T0">{"".join(trees)}</root>'
    _, pic = _picture(text, expand_subtrees=True)
    assert pic.truncated and len(pic.nodes) == MAX_NODES


def test_ports_on_request() -> None:
    _, plain = _picture()
    assert all(not n.ports for n in plain.nodes)
    _, pic = _picture(ports=True)
    door = next(n for n in pic.nodes if n.type == "IsDoorOpen")
    assert [(p.name, p.value, p.is_key) for p in door.ports] == [("door", "{door}", True)]
    retry = next(n for n in pic.nodes if n.type == "RetryUntilSuccessful")
    assert [(p.name, p.is_key) for p in retry.ports] == [("num_attempts", False)]


def test_unclosed_elements_end_at_the_text_end() -> None:
    text = '<root BTCPP_format="4"><BehaviorTree ID="T"><Sequence><AlwaysSuccess/>'
    doc = Document(text)
    tree = main_tree(doc.model)
    assert tree is not None
    pic = build_picture(doc.model, tree, diagnostics=analyze(doc), text_length=len(text))
    assert [(n.type, n.start, n.end) for n in pic.nodes] == [
        ("T", text.index("<BehaviorTree"), len(text)),
        ("Sequence", text.index("<Sequence"), len(text)),
        ("AlwaysSuccess", text.index("<AlwaysSuccess"), len(text)),
    ]
    assert pic.nodes[1].severity == Severity.ERROR  # the unclosed tag is its problem


def test_tree_at_and_main_tree() -> None:
    doc = Document(SAMPLE)
    walk_at = SAMPLE.index('<Action ID="Move"')
    t = tree_at(doc.model, walk_at)
    assert t is not None and t.value("ID") == "Walk"
    t = tree_at(doc.model, SAMPLE.index("<TreeNodesModel>"))
    assert t is not None and t.value("ID") == "Main"  # outside every tree: the main one


def test_changed_node_is_what_an_edit_made_or_changed() -> None:
    text = SAMPLE.replace("<CheckBattery/>", '<CheckBattery/>\n      <Sleep msec="5"/>')
    doc, pic = _picture(text, expand_subtrees=True)
    walk = next(n for n in pic.nodes if n.type == "Walk")  # the call, expanded below

    def changed(start: int, end: int) -> str | None:
        node = changed_node(pic, start, end)
        return node.type if node is not None else None

    sleep = text.index("<Sleep")
    assert changed(sleep, sleep + len('<Sleep msec="5"/>')) == "Sleep"  # typed whole
    assert changed(sleep - 7, sleep + len('<Sleep msec="5"/>') + 1) == "Sleep"  # with blanks
    fallback = text.index("<Fallback>")
    end = text.index("</Fallback>") + len("</Fallback>")
    assert changed(fallback, end) == "Fallback"  # a pasted subtree: its top node
    assert changed(end - 3, end) == "Fallback"  # its end tag edited
    door = text.index('door="{door}"') + 7
    assert changed(door, door + 1) == "IsDoorOpen"  # an attribute edited
    assert changed(door + 1, door) == "IsDoorOpen"  # the span either way round
    assert changed(sleep, sleep) == "Sleep"  # an empty span: a deletion inside it
    after = text.index("/>", sleep) + 2
    assert changed(after, after) == "Sleep"  # just after its end: the last character typed
    assert changed(after + 1, after + 2) == "Sequence"  # between children: their parent
    # An edit in the called tree changes its copy drawn under the SubTree call.
    move = text.index('<Action ID="Move"') + 3
    node = changed_node(pic, move, move)
    assert node is not None and node.type == "Move" and node.source is None
    assert walk.expanded and node.depth > walk.depth
    assert changed(text.index("<TreeNodesModel>"), text.index("<TreeNodesModel>") + 3) is None
    assert doc.text == text


# -- layout geometry -------------------------------------------------------------------------

TYPES = [
    "Sequence",
    "Fallback",
    "Parallel",
    "Inverter",
    "Repeat",
    "AlwaysSuccess",
    "ScriptCondition",
    "X",
    "AVeryLongCustomActionNameThatIsWide",
]


@st.composite
def random_trees(draw: st.DrawFn) -> str:
    """A random tree (any shape; box widths and heights varying with the node type, the
    instance name and the number of attributes) as BT XML."""
    n = draw(st.integers(1, 60))
    parents = [draw(st.integers(0, i)) for i in range(n)]  # node i+1's parent is <= i
    kids: list[list[int]] = [[] for _ in range(n + 1)]
    for i, p in enumerate(parents, 1):
        kids[p].append(i)
    names = draw(st.lists(st.sampled_from(TYPES), min_size=n + 1, max_size=n + 1))
    inst = draw(st.lists(st.text("ab <&\"'é😀", max_size=48), min_size=n + 1, max_size=n + 1))
    extra = draw(st.lists(st.integers(0, 3), min_size=n + 1, max_size=n + 1))
    out: list[str] = []
    stack: list[tuple[int, bool]] = [(0, False)]
    while stack:
        i, closing = stack.pop()
        tag = names[i]
        if closing:
            out.append(f"</{tag}>")
            continue
        attr = f" name={quoteattr(inst[i])}" if inst[i] else ""
        attr += "".join(f' p{j}="{{key_{j}}}"' for j in range(extra[i]))
        if not kids[i]:
            out.append(f"<{tag}{attr}/>")
            continue
        out.append(f"<{tag}{attr}>")
        stack.append((i, True))
        stack.extend((k, False) for k in reversed(kids[i]))
    return f'<root BTCPP_format="4"><BehaviorTree ID="T">{"".join(out)}</BehaviorTree></root>'


@settings(max_examples=80, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(random_trees(), st.booleans())
def test_layout_is_tidy(text: str, ports: bool) -> None:
    """No overlap, sibling subtrees side by side in XML order, parents above and centred
    over their children, no connector through a box (tests/layout_check.py)."""
    _, pic = _picture(text, ports=ports)
    assert problems(pic) == []


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(random_trees(), st.booleans())
def test_layout_is_compact(text: str, ports: bool) -> None:
    """Each subtree sits exactly the gap to the right of its left sibling's subtree, and a
    node with children is no wider than the subtree below it needs."""
    _, pic = _picture(text, ports=ports)
    laid = layout(pic)
    ext = extents(pic, laid.boxes)
    for node in pic.nodes:
        kids = node.children
        for a, b in pairwise(kids):
            assert ext[b][0] - ext[a][1] == pytest.approx(SIBLING_GAP)
    assert laid.width == pytest.approx(ext[0][1] - ext[0][0] + 2 * MARGIN)


def test_layout_keeps_a_deep_subtree_out_of_its_neighbours_column() -> None:
    """A leaf beside a deep, wide subtree stays to its right at every row: the contour
    packing this replaced tucked the leaf's neighbour's children under it."""
    text = (
        '<root BTCPP_format="4"><BehaviorTree ID="T"><Sequence>'
        "<Inverter><Sequence><AVeryLongCustomActionNameThatIsWide/>"
        "<AVeryLongCustomActionNameThatIsWide/></Sequence></Inverter>"
        '<AlwaysSuccess p0="{a}" p1="{b}" p2="{c}"/>'
        "</Sequence></BehaviorTree></root>"
    )
    _, pic = _picture(text, ports=True)
    boxes = layout(pic).boxes
    leaf = next(n.index for n in pic.nodes if n.type == "AlwaysSuccess")
    wide = [n.index for n in pic.nodes if n.type == "AVeryLongCustomActionNameThatIsWide"]
    assert all(boxes[leaf].x >= boxes[w].x + boxes[w].w + SIBLING_GAP for w in wide)
    assert problems(pic) == []


def test_deep_tree_has_no_recursion_limit() -> None:
    depth = 1000
    body = "<Inverter>" * depth + "<AlwaysSuccess/>" + "</Inverter>" * depth
    text = f'<root BTCPP_format="4"><BehaviorTree ID="T">{body}</BehaviorTree></root>'
    _, pic = _picture(text)
    assert len(pic.nodes) == depth + 2
    laid = layout(pic)
    assert laid.boxes[-1].y > laid.boxes[-2].bottom
    assert etree.fromstring(to_svg(pic, laid).encode()) is not None


# -- outputs ---------------------------------------------------------------------------------


@settings(max_examples=30, deadline=None)
@given(random_trees())
def test_svg_parses_and_holds_every_node(text: str) -> None:
    _doc, pic = _picture(text, ports=True)
    svg = etree.fromstring(to_svg(pic).encode())
    assert svg.tag == f"{SVG_NS}svg"
    groups = {
        g.get("id"): g for g in svg.iter(f"{SVG_NS}g") if "node" in g.get("class", "").split()
    }
    assert set(groups) == {n.id for n in pic.nodes}
    for n in pic.nodes:
        g = groups[n.id]
        assert (int(_attr(g, "data-start")), int(_attr(g, "data-end"))) == (n.start, n.end)
        label = _text(_found(g, f"{SVG_NS}text"))
        assert label.startswith(n.type[:10])
    assert len(svg.findall(f".//{SVG_NS}path[@class='edge']")) == len(pic.nodes) - 1


def test_svg_is_standalone_and_themed() -> None:
    model = Document(SAMPLE).model
    tree = main_tree(model)
    assert tree is not None
    out, _ = render(model, tree, "svg")
    svg = etree.fromstring(out.encode())
    style = _found(svg, f"{SVG_NS}style").text or ""
    assert "prefers-color-scheme: dark" in style
    assert "--bt-action:var(--vscode-" in style
    assert "href" not in out and "url(" not in out and "<image" not in out and "<script" not in out
    texts = [_text(t) for t in svg.iter(f"{SVG_NS}text")]
    assert "Sequence" in texts and '"root seq"' in texts


def test_svg_opens_fitted() -> None:
    """The viewBox holds every box, and the root (a file opened on its own, not a picture
    inlined in a page) is capped at the window's size, so a viewer scales it to fit."""
    _, pic = _picture(ports=True)
    laid = layout(pic)
    svg = etree.fromstring(to_svg(pic, laid).encode())
    x, y, w, h = map(float, _attr(svg, "viewBox").split())
    assert (x, y) == (0, 0)
    assert (w, h) == (float(_attr(svg, "width")), float(_attr(svg, "height")))
    assert all(b.x + b.w <= w and b.bottom <= h for b in laid.boxes)
    style = _found(svg, f"{SVG_NS}style").text or ""
    assert ".bt-tree:root{max-width:100vw;max-height:100vh}" in style
    assert svg.get("preserveAspectRatio") in (None, "xMidYMid meet")  # scaled, not cropped


def test_svg_marks_keys_and_badges() -> None:
    _, pic = _picture(ports=True)
    svg = etree.fromstring(to_svg(pic).encode())
    keys = [t.text for t in svg.iter(f"{SVG_NS}tspan") if t.get("class") == "key"]
    assert keys == ["{door}", "{goal}"]
    badged = {g.get("data-type") for g in svg.iter(f"{SVG_NS}g") if "sev-" in g.get("class", "")}
    assert "Foo" in badged and "Sequence" not in badged


def test_svg_escapes_what_xml_cannot_hold() -> None:
    text = '<root BTCPP_format="4"><BehaviorTree ID="T"><AlwaysSuccess name="a&#7;b]]&gt;"/>'
    text += "</BehaviorTree></root>"
    _, pic = _picture(text)
    svg = etree.fromstring(to_svg(pic).encode())
    assert '"aU+0007b]]>"' in [_text(t) for t in svg.iter(f"{SVG_NS}text")]


_MERMAID_NODE = re.compile(r'  n\d+(>|\[|\{\{|\(|\(\[|\[\[|\[/)"[^"]*"(\]|\}\}|\)|\]\)|\]\]|/\])')


@settings(max_examples=30, deadline=None)
@given(random_trees())
def test_mermaid_syntax(text: str) -> None:
    _, pic = _picture(text, ports=True)
    lines = to_mermaid(pic).splitlines()
    assert lines[0] == "flowchart TD"
    nodes = [ln for ln in lines if _MERMAID_NODE.fullmatch(ln)]
    edges = [ln for ln in lines if re.fullmatch(r"  n\d+ -(->|\.->) n\d+", ln)]
    styles = [
        ln for ln in lines if re.fullmatch(r"  (classDef \w+ [\w#:,.\- ]+|class [n\d,]+ \w+)", ln)
    ]
    assert len(nodes) == len(pic.nodes) and len(edges) == len(pic.nodes) - 1
    assert len(nodes) + len(edges) + len(styles) == len(lines) - 1


def test_mermaid_escapes_labels() -> None:
    _, pic = _picture(ports=True)
    out = to_mermaid(pic)
    assert 'n6("OpenDoor<br>#quot;open #amp; #quot;push#quot;#quot;<br>' in out
    assert "n5{{" in out and "n2([" in out and "n7[[" in out and "n8[/" in out


@settings(max_examples=30, deadline=None)
@given(random_trees())
def test_dot_syntax(text: str) -> None:
    _, pic = _picture(text, ports=True)
    out = to_dot(pic)
    lines = out.splitlines()
    assert lines[0].startswith("digraph ") and lines[-1] == "}"
    strings = re.compile(r'"(?:[^"\\]|\\.)*"')
    for line in lines[1:-1]:
        bare = strings.sub('""', line)
        assert '"' not in bare.replace('""', "")  # every quote is inside a closed string
        assert re.fullmatch(r"  (node|edge|n\d+)( -> n\d+)?( \[.*\])?;", bare), line
    assert sum(" -> " in ln for ln in lines) == len(pic.nodes) - 1


def test_dot_escapes_labels() -> None:
    _, pic = _picture()
    assert 'n6 [label="OpenDoor\\n\\"open & \\"push\\"\\"' in to_dot(pic)
