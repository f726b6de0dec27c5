"""Blackboard keys: references, highlights and rename.  Fixtures mark expected spans with
``⟦…⟧`` and the cursor with ``‸`` (as in ``test_navigation``)."""

from __future__ import annotations

import pytest
from lxml import etree

from bt_lsp.ide.blackboard import KeyForm, blackboard_keys, key_at, key_uses, tree_keys
from bt_lsp.ide.places import Place
from bt_lsp.ide.references import highlights, references
from bt_lsp.ide.rename import RenamePlan, RenameRefused, prepare_rename, rename
from bt_lsp.syntax.document import Document
from bt_lsp.syntax.edits import apply_edits
from tests.marks import cursor
from tests.test_navigation import at

# Tree "Main" uses the key "target" in port values and in every kind of script, and the
# other key " target " ("{ target }": the spaces inside the braces are part of the key);
# tree "Other" uses a key "target" in its own blackboard.
KEYS = """\
<root BTCPP_format="4" main_tree_to_execute="Main">
  <BehaviorTree ID="Main">
    <Sequence name="target" _successIf="⟦target⟧ == 'target'">
      <Script code="⟦target⟧ := 'target: ' .. ⟦target⟧; done := true"/>
      <ScriptCondition code="⟦target⟧ != &quot;target&quot; &amp;&amp; !done"/>
      <Precondition if="⟦target⟧&gt;1" else="FAILURE">
        <MoveBase goal="{ target }" _onSuccess="⟦target⟧ += 1" _post="x:=⟦target⟧"/>
      </Precondition>
      <MoveBase goal="{⟦target⟧}" speed="1" note="Go to {target}" _while="target_2 || _target"/>
      <Fallback _failureIf="⟦target⟧" _onFailure="⟦target⟧=0" _onHalted="⟦target⟧-=1">
        <AlwaysSuccess/>
      </Fallback>
      <Script code="{script}"/>
    </Sequence>
  </BehaviorTree>
  <BehaviorTree ID="Other">
    <MoveBase goal="{target}" _skipIf="target == 0"/>
  </BehaviorTree>
</root>
"""


def marked_at(marked: str, needle: str, into: int = 1, nth: int = 0) -> str:
    """``marked`` with the cursor put ``into`` characters into the ``nth`` ``needle``."""
    pos = -1
    for _ in range(nth + 1):
        pos = marked.index(needle, pos + 1)
    return marked[: pos + into] + "‸" + marked[pos + into :]


def edit_spans(plan: RenamePlan | None, new: str) -> list[tuple[int, int]]:
    assert plan is not None
    assert all(e.new_text == new for e in plan.edits)
    return [(e.start, e.end) for e in plan.edits]


def place_spans(places: list[Place]) -> list[tuple[int, int]]:
    return sorted((p.start, p.end) for p in places)


def refused(doc: Document, off: int, new: str, reason: str) -> str:
    with pytest.raises(RenameRefused, match=reason) as info:
        rename(doc, off, new)
    return info.value.message


# --- finding keys -------------------------------------------------------------------------


def test_a_key_is_a_whole_port_value_or_a_script_identifier() -> None:
    text, _, spans = cursor(KEYS)
    doc = Document(text)
    main = next(i for i, el in enumerate(doc.model.elements) if el.value("ID") == "Main")
    uses = [k for k in key_uses(doc, main) if k.key == "target"]
    assert [(k.start, k.end) for k in uses] == spans
    assert all(text[k.start : k.end] == "target" for k in uses)
    # "Go to {target}" is a literal text, as BehaviorTree.CPP reads it.
    assert sorted(k.key for k in blackboard_keys(doc, main)) == [" target ", "script", "target"]
    assert {k.key for k in key_uses(doc, main)} == {
        " target ",
        "done",
        "script",
        "target",
        "target_2",
        "_target",
        "x",
    }


def test_same_key_as_the_port() -> None:
    doc, off, spans = at(
        '<root><BehaviorTree ID="T"><Nav goal="{⟦‸=⟧}" speed="⟦=⟧" to=" = "/></BehaviorTree></root>'
    )
    found = key_at(doc, off)
    assert found is not None and found.key == "goal" and found.form == KeyForm.SAME
    keys = key_uses(doc, 1)
    assert [(k.key, k.form, (k.start, k.end)) for k in keys] == [
        ("goal", KeyForm.SAME, spans[0]),
        ("speed", KeyForm.BARE_SAME, spans[1]),
    ]


def test_the_uses_of_one_key_are_those_of_all_keys_filtered() -> None:
    text, _, _ = cursor(KEYS)
    doc = Document(text)
    main = next(i for i, el in enumerate(doc.model.elements) if el.value("ID") == "Main")
    every = key_uses(doc, main)
    for key in {k.key for k in every} | {"nothing", "goal"}:
        assert tree_keys(doc, main, key).uses == [k for k in every if k.key == key]


def test_a_key_in_a_script_of_many_statements() -> None:
    """Under the cursor and in its tree, a key of a script of 50,000 statements is found
    by its word, as among every identifier of the script."""
    code = "".join(f"a{i}:=1; " for i in range(50_000))
    tree = f'<Script code="{code}"/><Sub in="{{a7}}"/>'
    text = f'<root><BehaviorTree ID="T">{tree}</BehaviorTree></root>'
    doc = Document(text)
    start = text.index("a7:=")
    for off in (start, start + 1, start + 2):  # its start, inside it, its end
        found = key_at(doc, off)
        assert found is not None and (found.key, found.start, found.end) == ("a7", start, start + 2)
    found = key_at(doc, text.index("a70:=") + 3)
    assert found is not None and found.key == "a70"
    assert key_at(doc, text.index(":=1; a8") + 1) is None  # between two keys: none
    uses = tree_keys(doc, 1, "a7").uses
    assert [(k.form, text[k.start : k.end]) for k in uses] == [
        (KeyForm.SCRIPT, "a7"),
        (KeyForm.BRACES, "a7"),
    ]
    assert sorted(p.start for p in references(doc, start, {})) == [k.start for k in uses]


# --- prepare ------------------------------------------------------------------------------


def test_spaces_inside_the_braces_are_part_of_the_key() -> None:
    """``{ target }`` is the entry " target " to BehaviorTree.CPP (getRemappedKey trims
    only the spaces outside the braces): its own key, renamed on its own."""
    text, off, _ = cursor(marked_at(KEYS, "{ target", 3))
    doc = Document(text)
    target = prepare_rename(doc, off)
    assert target is not None and target.placeholder == " target "
    start = text.index("{ target }") + 1
    assert (target.start, target.end) == (start, start + 8)
    plan = rename(doc, off, "pose")
    assert plan is not None and [(e.start, e.end) for e in plan.edits] == [(start, start + 8)]
    assert 'goal="{pose}"' in apply_edits(text, plan.edits)


@pytest.mark.parametrize(("needle", "into"), [('if="⟦target', 10), ("{⟦target⟧}", 8)])
def test_prepare_rename_of_a_key_gives_its_span_and_text(needle: str, into: int) -> None:
    text, off, _ = cursor(marked_at(KEYS, needle, into))
    target = prepare_rename(Document(text), off)
    assert target is not None and target.key is not None and target.ref is None
    assert text[target.start : target.end] == target.placeholder == "target"
    assert target.start <= off <= target.end


def test_prepare_rename_of_a_same_key_spans_the_equal_sign() -> None:
    doc, off, spans = at('<root><BehaviorTree ID="T"><Nav goal="{‸⟦=⟧}"/></BehaviorTree></root>')
    target = prepare_rename(doc, off)
    assert target is not None
    assert [(target.start, target.end)] == spans and target.placeholder == "goal"


def test_no_key_in_strings_literal_texts_or_models() -> None:
    for needle, into in [
        ("'target'", 2),  # a string of a script
        ("&quot;target", 8),  # a double-quoted string (4.0-4.9)
        ('{target}" _while', 3),  # a literal text with braces
        ("done := true", 10),  # the literal true
    ]:
        text, off, _ = cursor(marked_at(KEYS, needle, into))
        doc = Document(text)
        assert key_at(doc, off) is None, needle
        assert prepare_rename(doc, off) is None, needle
        assert references(doc, off) == [] and highlights(doc, off) == [], needle
    # A port default in a model is not a use in a tree.
    doc, off, _ = at(
        '<root><TreeNodesModel><Action ID="A"><input_port name="p" default="{k‸}"/>'
        "</Action></TreeNodesModel></root>"
    )
    assert key_at(doc, off) is None and prepare_rename(doc, off) is None
    # An identifier that starts like the key is another key.
    text, off, _ = cursor(marked_at(KEYS, "target_2", 6))
    found = key_at(Document(text), off)
    assert found is not None and found.key == "target_2"


def test_a_port_with_a_bad_name_gives_a_key_and_ignored_attributes_do_not() -> None:
    # "goal.x" and "1st" break the port naming rules (the name fixes rename them into
    # ports); "_note" is an attribute BehaviorTree.CPP ignores, "é" one it cannot read.
    doc, off, spans = at(
        '<root><BehaviorTree ID="T"><Nav goal.x="{⟦k‸⟧}" 1st="{⟦k⟧}" again.x="{⟦=⟧}" '
        '_note="{k}" é="{k}" ok="{⟦k⟧}"/></BehaviorTree></root>'
    )
    assert place_spans(references(doc, off)) == [spans[0], spans[1], spans[3]]
    found = key_at(doc, spans[2][0])
    assert found is not None and found.key == "again.x" and found.form == KeyForm.SAME


# --- rename in one tree -------------------------------------------------------------------


@pytest.mark.parametrize(
    ("needle", "into"),
    [
        ("{⟦target", 4),  # a port value
        ('code="⟦target', 9),  # Script code
        ('_onHalted="⟦target', 14),  # a postcondition
        ("x:=⟦target", 10),  # at the end of an identifier
    ],
)
def test_rename_changes_the_key_in_ports_and_scripts_of_its_tree_only(
    needle: str, into: int
) -> None:
    text, off, spans = cursor(marked_at(KEYS, needle, into))
    doc = Document(text)
    plan = rename(doc, off, "goal_pose")
    assert edit_spans(plan, "goal_pose") == spans
    assert plan is not None and not plan.other_edits
    new = apply_edits(text, plan.edits)
    etree.fromstring(new.encode())
    # Strings, literal texts, other identifiers and the other tree are untouched.
    assert "'target: '" in new and "&quot;target&quot;" in new and "== 'target'" in new
    assert 'note="Go to {target}"' in new and "target_2 || _target" in new
    assert '<MoveBase goal="{target}" _skipIf="target == 0"/>' in new
    assert 'name="target"' in new and 'goal="{ target }"' in new
    # The renamed document uses the new key exactly where the old one was.
    renamed = Document(new)
    main = next(i for i, el in enumerate(renamed.model.elements) if el.value("ID") == "Main")
    assert len([k for k in key_uses(renamed, main) if k.key == "goal_pose"]) == len(spans)
    assert not [k for k in key_uses(renamed, main) if k.key == "target"]


@pytest.mark.parametrize(
    ("needle", "into"), [("{⟦target", 4), ('_successIf="⟦target', 15), ("⟦target⟧=0", 2)]
)
def test_references_and_highlights_are_what_rename_changes(needle: str, into: int) -> None:
    text, off, spans = cursor(marked_at(KEYS, needle, into))
    doc = Document(text)
    assert edit_spans(rename(doc, off, "t2"), "t2") == spans
    assert place_spans(references(doc, off)) == spans
    assert place_spans(references(doc, off, include_declaration=False)) == spans
    assert [(h.start, h.end) for h in highlights(doc, off)] == spans


def test_edits_keep_entity_references_around_the_key() -> None:
    marked = (
        '<root><BehaviorTree ID="T">'
        "<Nav _skipIf=\"&apos;&lt;&amp;&apos; == ⟦k‸ey⟧ &amp;&amp; ⟦key⟧&lt;3\" a='{⟦key⟧}'"
        ' b="{&#32;key }" name="&#x1F680;"/>'
        "</BehaviorTree></root>"
    )
    doc, off, spans = at(marked)
    plan = rename(doc, off, "k2")
    assert edit_spans(plan, "k2") == spans
    assert plan is not None
    new = apply_edits(doc.text, plan.edits)
    el = etree.fromstring(new.encode())[0][0]
    assert el.get("_skipIf") == "'<&' == k2 && k2<3"
    assert el.get("a") == "{k2}" and el.get("b") == "{ key }"  # the key " key "


def test_rename_escapes_a_key_that_is_not_in_a_script() -> None:
    doc, off, _ = at('<root><BehaviorTree ID="T"><Nav a="{k‸}" b=\'{k}\'/></BehaviorTree></root>')
    plan = rename(doc, off, 'my "key" & <more>')
    assert plan is not None
    el = etree.fromstring(apply_edits(doc.text, plan.edits).encode())[0][0]
    assert el.get("a") == el.get("b") == '{my "key" & <more>}'


def test_rename_writes_out_a_same_key() -> None:
    doc, off, _ = at(
        '<root><BehaviorTree ID="T"><Nav goal="{=}" speed="="/>'
        '<Nav _skipIf="goal &gt; sp‸eed"/></BehaviorTree></root>'
    )
    plan = rename(doc, off, "velocity")
    assert plan is not None
    new = apply_edits(doc.text, plan.edits)
    assert '<Nav goal="{=}" speed="{velocity}"/>' in new
    assert '_skipIf="goal &gt; velocity"' in new


def test_rename_of_a_key_to_the_same_name_changes_nothing() -> None:
    text, off, _ = cursor(marked_at(KEYS, "{⟦target", 4))
    doc = Document(text)
    plan = rename(doc, off, "target")
    assert plan is not None and apply_edits(text, plan.edits) == text


# --- refused ------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("new", "reason"),
    [
        ("", "cannot be empty"),
        ("a{b", "cannot contain '{' or '}'"),
        ("ab}", "cannot contain '{' or '}'"),
        (" ab", "keeps the white space inside the braces"),
        ("ab\t", "keeps the white space inside the braces"),
        ("=", r"stands for the key named like its port"),
        ("@ab", "root blackboard"),
        ("a\x07b", "control characters"),
        ("a b", "must be an identifier"),
        ("1ab", "must be an identifier"),
        ("clé", "must be an identifier"),
        ("a-b", "must be an identifier"),
        ("true", "must be an identifier"),
        ("done", "already uses a key 'done'; the two keys would become one"),
        ("script", "already uses a key 'script'"),
    ],
)
def test_rename_of_a_key_refuses_a_bad_new_name(new: str, reason: str) -> None:
    text, off, _ = cursor(marked_at(KEYS, "{⟦target", 4))
    message = refused(Document(text), off, new, reason)
    assert message.startswith("Cannot rename to '")


def test_a_key_only_in_ports_may_have_any_name_but_braces() -> None:
    doc, off, _ = at('<root><BehaviorTree ID="T"><Nav a="{k‸}"/></BehaviorTree></root>')
    plan = rename(doc, off, "my key-1.0")
    assert plan is not None
    assert apply_edits(doc.text, plan.edits).count('"{my key-1.0}"') == 1


def test_a_key_written_with_references_is_refused() -> None:
    doc, off, _ = at(
        '<root><BehaviorTree ID="T"><Nav a="{go&#97;l}" b="{go‸al}"/></BehaviorTree></root>'
    )
    refused(doc, off, "target", "written with character or entity references in 'a'")
    off = doc.text.index("&#97;")
    with pytest.raises(RenameRefused, match="written with character or entity references"):
        prepare_rename(doc, off)
    # It is still the same key for references.
    assert len(references(doc, off)) == 2


def test_a_key_after_a_script_error_is_refused() -> None:
    doc, off, _ = at(
        '<root><BehaviorTree ID="T"><Nav a="{k‸ey}" _skipIf="ok := 1 %% key"/>'
        "</BehaviorTree></root>"
    )
    refused(doc, off, "k2", "syntax error before a 'key'")
    # A key before the error is found, and renamed.
    off = doc.text.index("ok :=") + 1
    plan = rename(doc, off, "fine")
    assert plan is not None
    assert '_skipIf="fine := 1 %% key"' in apply_edits(doc.text, plan.edits)


# --- @ keys, _autoremap and ports of subtrees ---------------------------------------------


ROOT = """\
<root BTCPP_format="4" main_tree_to_execute="Main">
  <BehaviorTree ID="Main">
    <Sequence>
      <Nav goal="{pose}" mode="{m}"/>
      <SubTree ID="Dock"/>
    </Sequence>
  </BehaviorTree>
  <BehaviorTree ID="Dock">
    <Nav goal="{@pose}" mode="{m}" _skipIf="@pose == 0"/>
  </BehaviorTree>
</root>
"""


def test_a_root_key_cannot_be_renamed() -> None:
    for needle in ("{@pose", "@pose =="):
        doc, off, _ = at(marked_at(ROOT, needle, 3))
        with pytest.raises(RenameRefused, match=r"'@pose' is a key of the root blackboard"):
            prepare_rename(doc, off)
        with pytest.raises(RenameRefused, match=r"'@pose' is a key of the root blackboard"):
            rename(doc, off, "p")
        assert len(references(doc, off)) == 2  # the uses in Dock


def test_a_key_of_the_main_tree_that_at_keys_reach_is_refused() -> None:
    doc, off, _ = at(marked_at(ROOT, "{pose", 2))
    refused(doc, off, "p", r"'@pose' in tree 'Dock' is this key .* when tree 'Main' runs as")
    # A key of the same name in a subtree that is not the main tree is its own.
    text = ROOT.replace('goal="{@pose}"', 'goal="{pose}" at="{@pose}"')
    doc, off, _ = at(marked_at(text, '{pose}" at', 2))
    plan = rename(doc, off, "p")
    assert plan is not None and len(plan.edits) == 1
    # A new name that '@' reaches in the main tree would merge two keys.
    doc, off, _ = at(marked_at(ROOT, "{m}", 2))
    refused(doc, off, "pose", r"already uses a key 'pose'")
    text = ROOT.replace('<Nav goal="{pose}" mode="{m}"/>', '<Nav mode="{m}"/>')
    doc, off, _ = at(marked_at(text, "{m}", 2))
    refused(doc, off, "pose", r"'@pose' in tree 'Dock' is that key .* would become one")


AUTO = """\
<root BTCPP_format="4" main_tree_to_execute="Main">
  <BehaviorTree ID="Main">
    <Sequence>
      <Nav goal="{goal}" a="{only_main}" p="{_private}"/>
      <SubTree ID="Dock" _autoremap="true" pose="{goal}"/>
    </Sequence>
  </BehaviorTree>
  <BehaviorTree ID="Dock">
    <Sequence>
      <Nav goal="{goal}" b="{only_dock}" p="{_private}"/>
      <SubTree ID="Leaf" _autoremap="1"/>
    </Sequence>
  </BehaviorTree>
  <BehaviorTree ID="Leaf">
    <Nav goal="{pose}" c="{deep}"/>
  </BehaviorTree>
  <BehaviorTree ID="Top">
    <SubTree ID="Leaf" _autoremap="true" deep="{top_key}"/>
    <Nav d="{deep}"/>
  </BehaviorTree>
</root>
"""


@pytest.mark.parametrize(
    ("needle", "into", "new", "outcome"),
    [
        # Main and Dock share "goal" through _autoremap (pose="{goal}" remaps another port).
        ('{goal}" a', 2, "target", r"tree 'Dock' shares it with tree 'Main' through"),
        ('{goal}" b', 2, "target", r"tree 'Main' shares it with tree 'Dock' through"),
        # Leaf's "deep" is Main's (through Dock), and a port of Leaf that Top remaps: the
        # rename changes it and Top's remapping.
        ("{deep", 2, "target", 2),
        # ... and "only_main" would merge it with another key of Main's blackboard.
        ("{deep", 2, "only_main", r"tree 'Main' already uses a key 'only_main', shared with"),
        ("{only_dock", 2, "only_main", r"tree 'Main' already uses a key 'only_main'"),
        ("{only_main", 2, "renamed", 1),
        # Private keys are never autoremapped.
        ('{_private}"/>\n      <Sub', 2, "_mine", 1),
        ('{_private}"/>\n      <Sub', 2, "only_dock", r"tree 'Dock' already uses"),
    ],
)
def test_autoremap_shares_keys_between_trees(
    needle: str, into: int, new: str, outcome: str | int
) -> None:
    doc, off, _ = at(marked_at(AUTO, needle, into))
    if isinstance(outcome, str):
        refused(doc, off, new, outcome)
        return
    key = key_at(doc, off)
    plan = rename(doc, off, new)
    assert key is not None and plan is not None and len(plan.edits) == outcome
    assert all(doc.text[e.start : e.end] == key.key for e in plan.edits)


def test_an_explicit_remapping_is_not_shared_through_autoremap() -> None:
    # Top remaps Leaf's "deep" to "top_key", so Top's own "deep" is not Leaf's.
    doc, off, _ = at(marked_at(AUTO, '{deep}"/>\n  </BehaviorTree>\n</root>', 2))
    plan = rename(doc, off, "d2")
    assert plan is not None
    assert '<Nav d="{d2}"/>' in apply_edits(doc.text, plan.edits)


DOCK = """\
<root BTCPP_format="4">
  <BehaviorTree ID="Dock">
    <Sequence _while="⟦pose⟧ != 0">
      <Nav goal="{⟦pose⟧}" speed="{speed}"/>
    </Sequence>
  </BehaviorTree>
  <TreeNodesModel>
    <SubTree ID="Dock"><input_port name="⟦pose⟧"/><input_port name="speed"/></SubTree>
  </TreeNodesModel>
</root>
"""

CALLER = """\
<root BTCPP_format="4">
  <BehaviorTree ID="Main">
    <Sequence>
      <SubTree ID="Dock" ⟦pose⟧="{target}"/>
      <SubTree ID="Dock" ⟦pose⟧="{=}" name="again"/>
      <Nav pose="{pose}"/>
    </Sequence>
  </BehaviorTree>
</root>
"""


@pytest.mark.parametrize(
    ("where", "needle", "into"),
    [
        ("dock", "{⟦pose", 4),  # the key inside the subtree
        ("dock", '_while="⟦pose', 12),  # the key in a script of the subtree
        ("dock", 'name="⟦pose', 9),  # the port declaration
        ("caller", '⟦pose⟧="{target', 2),  # the port on a call
    ],
)
def test_a_key_that_is_a_port_of_its_tree_is_renamed_with_the_port(
    where: str, needle: str, into: int
) -> None:
    dock_marked = marked_at(DOCK, needle, into) if where == "dock" else DOCK
    caller_marked = marked_at(CALLER, needle, into) if where == "caller" else CALLER
    dock_text, dock_off, dock_spans = cursor(dock_marked)
    caller_text, caller_off, caller_spans = cursor(caller_marked)
    dock, caller = Document(dock_text), Document(caller_text)
    if where == "dock":
        doc, off, spans, other, other_path, other_spans = (
            dock,
            dock_off,
            dock_spans,
            caller,
            "/ws/main.xml",
            caller_spans,
        )
    else:
        doc, off, spans, other, other_path, other_spans = (
            caller,
            caller_off,
            caller_spans,
            dock,
            "/ws/dock.xml",
            dock_spans,
        )
    others = {other_path: other}
    found = references(doc, off, others)
    assert place_spans([p for p in found if p.path is None]) == spans
    assert place_spans([p for p in found if p.path == other_path]) == other_spans
    plan = rename(doc, off, "dock_pose", others)
    assert plan is not None
    own = apply_edits(doc.text, plan.edits)
    elsewhere = apply_edits(other.text, plan.other_edits[other_path])
    new_dock, new_caller = (own, elsewhere) if where == "dock" else (elsewhere, own)
    assert new_dock == DOCK.replace("⟦pose⟧", "dock_pose").replace("⟦", "").replace("⟧", "")
    # The call that wrote "{=}" keeps the caller's key "pose"; Main's own key is untouched.
    assert new_caller == (
        CALLER.replace('⟦pose⟧="{target}"', 'dock_pose="{target}"')
        .replace('⟦pose⟧="{=}"', 'dock_pose="{pose}"')
        .replace("⟦", "")
        .replace("⟧", "")
    )
    for text in (new_dock, new_caller):
        etree.fromstring(text.encode())


def test_a_key_that_is_a_port_follows_the_port_rules() -> None:
    text, off, _ = cursor(marked_at(DOCK, "{⟦pose", 4))
    doc = Document(text)
    refused(doc, off, "_pose", "must start with an ASCII letter")
    refused(doc, off, "speed", "already has a port with that name")
    # Renaming the port to a key the subtree already uses would merge the two.
    text = DOCK.replace("{speed}", "{mine}")
    text, off, _ = cursor(marked_at(text, 'name="⟦pose', 9))
    refused(Document(text), off, "mine", "tree 'Dock' already uses a key 'mine'")


def test_renaming_a_port_writes_out_same_keys() -> None:
    doc, off, _ = at(
        '<root><BehaviorTree ID="T"><Nav goal="{=}"/><Nav goal="=" x="{goal}"/></BehaviorTree>'
        '<TreeNodesModel><Action ID="Nav"><input_port name="go‸al"/></Action></TreeNodesModel>'
        "</root>"
    )
    plan = rename(doc, off, "target")
    assert plan is not None
    new = apply_edits(doc.text, plan.edits)
    assert '<Nav target="{goal}"/><Nav target="{goal}" x="{goal}"/>' in new
    assert '<input_port name="target"/>' in new
