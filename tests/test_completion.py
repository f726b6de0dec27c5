"""Completion core: contexts detected from half-typed text, the items offered, and the span
they replace.  ``‸`` marks the cursor and ``⟦…⟧`` the span the items replace."""

from __future__ import annotations

import pytest

from bt_lsp.ide.completion import Completions, Item, ItemKind, complete
from bt_lsp.ide.completion_attrs import MAX_KEY_ITEMS
from bt_lsp.rules.builtins import BUILTINS
from bt_lsp.rules.context import Context
from bt_lsp.syntax.document import Document
from tests.marks import CURSOR, cursor

DOC = """\
<root BTCPP_format="4">
  <BehaviorTree ID="Main">
    <Sequence>
      <MoveBase goal="{{target}}" result="{{res}}"/>
      {here}
    </Sequence>
  </BehaviorTree>
  <BehaviorTree ID="Dock">
    <Sleep msec="{{delay}}"/>
  </BehaviorTree>
  <TreeNodesModel>
    <Action ID="MoveBase">
      <input_port name="goal" type="Pose" description="Where to go"/>
      <output_port name="result" type="int"/>
      <input_port name="speed" type="double" default="0.5"/>
      <input_port name="careful" type="bool" default="false"/>
    </Action>
    <Control ID="Retry3"/>
    <SubTree ID="Dock">
      <input_port name="pose"/><output_port name="done" default="{{ok}}"/>
    </SubTree>
  </TreeNodesModel>
</root>
"""


def run(marked: str, ctx: Context | None = None) -> tuple[Completions, str, list[tuple[int, int]]]:
    text, offset, spans = cursor(marked)
    assert offset >= 0, "no cursor"
    doc = Document(text)
    found = complete(doc, offset, ctx)
    assert found is not None, "no completion"
    assert found.start <= offset <= found.end
    if spans:
        assert [(found.start, found.end)] == spans
    return found, text, spans


def here(snippet: str) -> str:
    return DOC.format(here=snippet)


def item(found: Completions, label: str) -> Item:
    for it in found.items:
        if it.label == label:
            return it
    raise AssertionError(f"no item {label!r} in {[i.label for i in found.items]}")


def labels(found: Completions) -> list[str]:
    return [i.label for i in found.items]


# --- tag names ----------------------------------------------------------------------------


def test_after_lt_in_a_tree_offers_node_types_with_required_ports() -> None:
    found, _, _ = run(here("<⟦⟧‸"))
    assert found.context == "tag"
    move = item(found, "MoveBase")
    assert move.kind == ItemKind.NODE and move.detail == "Action (TreeNodesModel)"
    # The ports without a default only, as tab stops: goal (input) and result (output, as
    # the key named like it); speed and careful have defaults, which BehaviorTree.CPP uses.
    assert move.snippet == 'MoveBase goal="${1}" result="{${2:result}}"/>'
    # Plain text has no tab stops: no empty value (never right), only the output's key.
    assert move.insert == 'MoveBase result="{result}"/>'
    assert "\n- `goal`: input, `Pose`, no default; Where to go\n" in move.documentation
    seq = item(found, "Sequence")
    assert seq.snippet == "Sequence>\n\t$0\n</Sequence>"
    assert seq.detail == "Control (built-in)" and BUILTINS["Sequence"].description in (
        seq.documentation
    )
    assert item(found, "Retry3").snippet == "Retry3>\n\t$0\n</Retry3>"
    assert item(found, "Sleep").snippet == 'Sleep msec="${1}"/>'
    assert set(BUILTINS) - {"SubTree"} <= set(labels(found))
    assert labels(found).count("SubTree") == 1


def test_subtree_calls_of_each_other_tree_with_their_ports() -> None:
    found, _, _ = run(here("<‸"))
    dock = item(found, "SubTree Dock")
    assert dock.kind == ItemKind.SUBTREE
    assert dock.snippet == 'SubTree ID="Dock" pose="${1}"/>'  # done has a default
    assert dock.insert == 'SubTree ID="Dock"/>'
    assert "SubTree Main" not in labels(found)  # a tree calling itself never ends


def test_a_half_typed_name_is_replaced_whole() -> None:
    found, _, _ = run(here("<⟦Mo‸⟧"))
    assert item(found, "MoveBase").snippet is not None
    # Editing the name of a complete tag replaces only the name.
    found, _, _ = run(here('<⟦Mo‸ve⟧ goal="1"/>'))
    move = item(found, "MoveBase")
    assert move.insert == "MoveBase" and move.snippet is None
    assert "SubTree Dock" not in labels(found)


def test_tag_names_by_place() -> None:
    found, _, _ = run("<root>\n  <‸\n</root>")
    assert labels(found) == ["BehaviorTree", "TreeNodesModel", "include"]
    assert item(found, "include").snippet == 'include path="$1"/>'
    found, _, _ = run("<root><TreeNodesModel>\n<‸\n</TreeNodesModel></root>")
    assert labels(found) == ["Action", "Condition", "Control", "Decorator", "SubTree"]
    found, _, _ = run('<root><TreeNodesModel><Action ID="X"><‸</Action></TreeNodesModel></root>')
    assert labels(found) == ["input_port", "output_port", "inout_port"]
    found, _, _ = run("<‸")
    assert labels(found) == ["root"]
    assert item(found, "root").snippet == 'root BTCPP_format="4">\n\t$0\n</root>'


def test_end_tag_names_the_element_it_closes() -> None:
    found, _, _ = run(here("<Fallback><AlwaysSuccess/></⟦⟧‸"))
    assert found.context == "end-tag"
    assert [(i.label, i.insert) for i in found.items] == [("Fallback", "Fallback>")]
    found, _, _ = run(here("<Fallback><AlwaysSuccess/></⟦Fa‸⟧>"))
    assert [(i.label, i.insert) for i in found.items] == [("Fallback", "Fallback")]


# --- attribute names ----------------------------------------------------------------------


def test_ports_of_the_node_then_reserved_attributes() -> None:
    found, _, _ = run(here('<MoveBase goal="1" ⟦⟧‸/>'))
    assert found.context == "attribute"
    got = labels(found)
    assert "goal" not in got  # already there
    assert {"result", "speed", "careful"} <= set(got)
    assert {"name", "_skipIf", "_while", "_onSuccess", "_post", "_description"} <= set(got)
    assert "_autoremap" not in got and "ID" not in got
    assert item(found, "result").snippet == 'result="{${1:result}}"'
    # A port with a default gets it, to accept or overwrite; one without, a tab stop.
    assert item(found, "speed").snippet == 'speed="${1:0.5}"'
    assert item(found, "speed").insert == 'speed="0.5"'
    assert item(found, "careful").snippet == 'careful="${1:false}"'
    assert item(found, "speed").detail == "input port: double"
    assert "default `0.5`" in item(found, "speed").documentation
    # Required ports sort first.
    assert item(found, "result").sort < item(found, "speed").sort < item(found, "name").sort


def test_a_half_typed_attribute_name_is_replaced() -> None:
    found, _, _ = run(here("<MoveBase ⟦sp‸⟧"))
    assert item(found, "speed").insert == 'speed="0.5"'
    # Renaming an attribute that has a value inserts the name only.
    found, _, _ = run(here('<MoveBase ⟦sp‸eed⟧="1"/>'))
    assert item(found, "speed").insert == "speed" and item(found, "speed").snippet is None


def test_attribute_inserted_before_another_gets_a_space() -> None:
    found, _, _ = run(here('<MoveBase ‸goal="1"/>'))
    assert item(found, "speed").insert == 'speed="0.5" '


def test_subtree_and_explicit_nodes() -> None:
    found, _, _ = run(here('<SubTree ID="Dock" ‸/>'))
    got = labels(found)
    assert {"pose", "done", "_autoremap", "name"} <= set(got) and "ID" not in got
    assert item(found, "_autoremap").snippet == '_autoremap="${1|true,false|}"'
    found, _, _ = run(here("<SubTree ‸/>"))
    assert "ID" in labels(found)
    found, _, _ = run(here('<Action ID="MoveBase" ‸/>'))
    assert "goal" in labels(found) and "ID" not in labels(found)


def test_structural_attributes() -> None:
    found, _, _ = run('<root ‸><BehaviorTree ID="A"/></root>')
    assert labels(found) == ["BTCPP_format", "main_tree_to_execute"]
    assert item(found, "BTCPP_format").snippet == 'BTCPP_format="${1:4}"'
    found, _, _ = run('<root><include ‸/><BehaviorTree ID="A"/></root>')
    assert labels(found) == ["path", "ros_pkg"]
    found, _, _ = run('<root><TreeNodesModel><Action ID="A"><input_port ‸/></Action></root>')
    assert labels(found) == ["name", "type", "default", "description"]


def test_unknown_node_offers_reserved_attributes_only() -> None:
    found, _, _ = run(here("<Mystery ‸/>"))
    assert "name" in labels(found) and all(i.kind == ItemKind.ATTRIBUTE for i in found.items)


# --- values -------------------------------------------------------------------------------


def test_subtree_id_offers_the_other_trees() -> None:
    found, _, _ = run(here('<SubTree ID="⟦D‸o⟧"/>'))
    assert found.context == "value"
    assert labels(found) == ["Dock"]
    assert item(found, "Dock").kind == ItemKind.TREE


def test_main_tree_to_execute_offers_every_tree() -> None:
    found, _, _ = run(
        here("").replace('<root BTCPP_format="4">', '<root main_tree_to_execute="⟦‸⟧">')
    )
    assert labels(found) == ["Dock", "Main"]


def test_trees_of_other_documents_are_offered() -> None:
    text = here('<SubTree ID="‸"/>')
    other = Document('<root><BehaviorTree ID="Elsewhere"><X/></BehaviorTree></root>')
    at = text.index(CURSOR)
    doc = Document(text.replace(CURSOR, ""))
    ctx = Context.combine(doc, [("/ws/other.xml", other, False)], path="/ws/this.xml")
    found = complete(doc, at, ctx)
    assert found is not None and labels(found) == ["Dock", "Elsewhere"]
    assert item(found, "Elsewhere").detail == "BehaviorTree (/ws/other.xml)"


def test_explicit_id_offers_node_types_of_that_category() -> None:
    found, _, _ = run(here('<Control ID="⟦‸⟧"><X/></Control>'))
    got = labels(found)
    assert "Retry3" in got and "Sequence" in got and "MoveBase" not in got and "Sleep" not in got


def test_bool_ports_and_autoremap_offer_true_and_false() -> None:
    found, _, _ = run(here('<MoveBase goal="1" careful="⟦t‸⟧"/>'))
    assert labels(found) == ["true", "false"]
    found, _, _ = run(here('<SubTree ID="Dock" _autoremap="‸"/>'))
    assert labels(found) == ["true", "false"]
    found, _, _ = run(here('<LoopInt queue="{q}" if_empty="‸" value="{v}"><X/></LoopInt>'))
    assert labels(found) == ["SUCCESS", "FAILURE", "RUNNING", "SKIPPED"]


def test_no_values_for_plain_ports() -> None:
    text = here('<MoveBase goal="‸"/>')
    at = text.index(CURSOR)
    assert complete(Document(text.replace(CURSOR, "")), at) is None


# --- blackboard keys ----------------------------------------------------------------------


def test_keys_used_in_the_tree_after_a_brace() -> None:
    found, _, _ = run(here('<MoveBase goal="{⟦t‸⟧'))
    assert found.context == "key"
    assert labels(found) == ["res", "target"]  # not "delay": that is another tree's
    assert item(found, "target").insert == "target}"
    found, _, _ = run(here('<MoveBase goal="{⟦‸⟧}"/>'))
    assert item(found, "target").insert == "target"
    found, _, _ = run(here('<MoveBase goal="x {⟦ta‸rg⟧} y"/>'))
    assert item(found, "target").insert == "target"


def test_keys_include_those_of_scripts_and_same_name_ports() -> None:
    found, _, _ = run(
        here(
            "<Script code=\"counter := counter + 1; msg := '{quoted}'\"/>"
            '<MoveBase goal="{=}"/><MoveBase goal="{⟦‸⟧}"/>'
        )
    )
    assert labels(found) == ["counter", "goal", "msg", "res", "target"]  # not "quoted"
    assert item(found, "counter").detail == "used in a script of this tree"
    assert item(found, "goal").detail == "used in this tree"


def test_keys_include_the_ports_of_the_tree() -> None:
    text = DOC.format(here="").replace(
        '<Sleep msec="{delay}"/>', '<Sleep msec="{delay}"/><Sleep msec="{‸'
    )
    found, _, _ = run(text)
    assert labels(found) == ["delay", "done", "pose"]
    assert item(found, "pose").detail == "input port of this tree"


def test_keys_of_a_huge_script_are_capped_those_typed_first() -> None:
    script = "".join(f"k{i}:=1; " for i in range(MAX_KEY_ITEMS + 500)) + "zeta:=2"
    found, _, _ = run(here(f'<Script code="{script}"/><MoveBase goal="{{⟦k15‸⟧"/>'))
    assert found.incomplete  # the client asks again as the key is typed
    assert len(found.items) == MAX_KEY_ITEMS
    got = labels(found)
    assert got == sorted(got)
    # Every key that starts as typed is listed (k15, k150..k159, k1500..k1499+500).
    typed = {f"k{i}" for i in range(MAX_KEY_ITEMS + 500) if f"k{i}".startswith("k15")}
    assert typed <= set(got)
    assert item(found, "k15").detail == "used in a script of this tree"
    assert "zeta" not in got  # past the cap, and not as typed
    few, _, _ = run(here('<Script code="a:=1; b:=2"/><MoveBase goal="{⟦‸⟧"/>'))
    assert not few.incomplete


def test_no_keys_in_names_and_ids() -> None:
    text = here('<MoveBase name="{‸"/>')
    at = text.index(CURSOR)
    assert complete(Document(text.replace(CURSOR, "")), at) is None


# --- nothing ------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "text",
    [
        "‸",
        "<root>text ‸</root>",
        "<root><BehaviorTree ID='T'><AlwaysSuccess/>‸</BehaviorTree></root>",
        "<root><BehaviorTree ID='T'><Inverter><X/>‸</Inverter></BehaviorTree></root>",
        "<root><!-- <‸ --></root>",
        '<root BTCPP_format="4"‸>',
        "<root/>‸",
    ],
)
def test_nothing_outside_a_context(text: str) -> None:
    at = text.index(CURSOR)
    found = complete(Document(text.replace(CURSOR, "")), at)
    assert found is None or found.items == []  # (a full tree or decorator: nothing fits)


# --- no '<' typed: an empty line, between tags -----------------------------------------------


def test_an_empty_line_in_a_control_node_offers_node_types_with_their_lt() -> None:
    found, _, _ = run(here("⟦⟧‸"))
    assert found.context == "text"
    move = item(found, "MoveBase")
    assert move.snippet == '<MoveBase goal="${1}" result="{${2:result}}"/>'
    assert move.insert == '<MoveBase result="{result}"/>'
    assert move.filter == "MoveBase"  # what the client matches the typed word against
    assert item(found, "Sequence").snippet == "<Sequence>\n\t$0\n</Sequence>"
    assert item(found, "SubTree Dock").insert == '<SubTree ID="Dock"/>'
    assert set(BUILTINS) - {"SubTree"} <= set(labels(found))


def test_a_word_typed_between_tags_is_replaced() -> None:
    found, _, _ = run(here("⟦Mo‸⟧"))
    assert item(found, "MoveBase").insert.startswith("<MoveBase ")
    text = DOC.format(here="").replace("<Sequence>\n", "<Sequence>⟦⟧‸")
    found, _, _ = run(text)  # right after a start tag's '>'
    assert "Fallback" in labels(found)


@pytest.mark.parametrize("column", [0, 2, 6])
def test_the_indentation_before_a_tag_offers_what_fits_before_it(column: int) -> None:
    # Anywhere in the indentation of `      <MoveBase …/>` (a child of a Sequence): the
    # edit runs from the cursor to the tag, never over it.
    line = "      <MoveBase goal"
    text = here("").replace(line, line[:column] + "‸⟦" + line[column:6] + "⟧" + line[6:])
    found, plain, _ = run(text)
    assert found.context == "text"
    assert plain[found.end] == "<"  # the existing tag is not in the edit
    move = item(found, "MoveBase")
    assert move.insert == " " * (6 - column) + '<MoveBase result="{result}"/>'
    assert move.snippet == " " * (6 - column) + '<MoveBase goal="${1}" result="{${2:result}}"/>'
    assert found.trail == "\n      "  # the tag goes on to a line of its own, as indented
    assert "Fallback" in labels(found)
    # Applied: the new node before the old one, each on its own line.
    new = plain[: found.start] + move.insert + found.trail + plain[found.end :]
    assert '      <MoveBase result="{result}"/>\n      <MoveBase goal=' in new


def test_the_indentation_before_a_closing_tag_offers_a_last_child() -> None:
    found, _, _ = run(here("").replace("    </Sequence>", "‸⟦    ⟧</Sequence>"))
    assert item(found, "Sleep").insert == "    <Sleep/>"
    assert found.trail == "\n    "


def test_the_indentation_before_a_tag_where_nothing_fits() -> None:
    # The tree has its one child: no second one goes before it.
    found, _, _ = run("<root><BehaviorTree ID='T'>\n  ‸⟦⟧<Sequence/>\n</BehaviorTree></root>")
    assert found.items == []
    # Text before the cursor on the line: not the indentation.
    text = here("").replace("      <MoveBase goal", "    x ‸<MoveBase goal")
    at = text.index(CURSOR)
    after_text = complete(Document(text.replace(CURSOR, "")), at)
    assert after_text is None or after_text.items == []


def test_the_indentation_before_a_tag_keeps_the_line_ends() -> None:
    for newline in ("\r\n", "\r"):
        text = here("").replace("\n", newline)
        at = text.index("      <MoveBase goal") + 2
        found = complete(Document(text), at)
        assert found is not None and found.trail == newline + "      "


def test_between_tags_elsewhere_offers_what_fits_there() -> None:
    found, _, _ = run("<root>⟦⟧‸</root>")
    assert labels(found) == ["BehaviorTree", "TreeNodesModel", "include"]
    assert item(found, "include").snippet == '<include path="$1"/>'
    found, _, _ = run("<root><TreeNodesModel>\n  ⟦⟧‸\n</TreeNodesModel></root>")
    assert labels(found) == ["Action", "Condition", "Control", "Decorator", "SubTree"]
    # An empty tree takes one child; a control node any number.
    found, _, _ = run("<root><BehaviorTree ID='T'>⟦⟧‸</BehaviorTree></root>")
    assert "Sequence" in labels(found)
    found, _, _ = run(
        "<root><BehaviorTree ID='T'><Sequence><X/>⟦⟧‸</Sequence></BehaviorTree></root>"
    )
    assert "Sequence" in labels(found)


def test_every_prefix_and_offset_is_safe() -> None:
    text = here('<SubTree ID="Dock" pose="{target}"/>')
    for cut in range(0, len(text), 5):
        doc = Document(text[:cut])
        for off in range(0, cut + 1, 3):
            found = complete(doc, off)
            if found is not None:
                assert found.start <= off <= found.end
