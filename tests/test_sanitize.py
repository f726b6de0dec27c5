"""Replacement names: examples, uniqueness, alternatives, and properties over any text."""

from __future__ import annotations

import re

import pytest
from hypothesis import example, given
from hypothesis import strategies as st
from lxml import etree

from bt_lsp.ide.sanitize import candidates, is_xml_name, sanitize
from bt_lsp.rules.names import NameKind, check_name, is_allowed_port_name

MODEL = NameKind.MODEL
PORT = NameKind.PORT
INSTANCE = NameKind.INSTANCE

# XML 1.0 (5th edition) [4] NameStartChar, [4a] NameChar, [5] Name, written out again here so
# the test does not trust the module's own table.
_START = (
    ":A-Z_a-z\u00c0-\u00d6\u00d8-\u00f6\u00f8-\u02ff\u0370-\u037d\u037f-\u1fff\u200c\u200d"
    "\u2070-\u218f\u2c00-\u2fef\u3001-\ud7ff\uf900-\ufdcf\ufdf0-\ufffd\U00010000-\U000effff"
)
XML_NAME = re.compile(f"[{_START}][{_START}\\-.0-9\u00b7\u0300-\u036f\u203f\u2040]*")


def parses_as_element(name: str) -> bool:
    try:
        root = etree.fromstring(f"<{name}/>")
    except etree.XMLSyntaxError:
        return False
    return bool(root.tag == name)


def parses_as_attribute(name: str) -> bool:
    try:
        root = etree.fromstring(f'<a {name}="v"/>')
    except etree.XMLSyntaxError:
        return False
    return root.get(name) == "v"


# --- examples -----------------------------------------------------------------------------

MODEL_CASES = [
    ("Move to Pose (JTC)", "Move_to_Pose_JTC"),
    ("Move to Waypoint (JTC)", "Move_to_Waypoint_JTC"),
    ("Pick April Tag Labeled Object", "Pick_April_Tag_Labeled_Object"),
    ("Re-Zero Force-Torque Sensors", "Re-Zero_Force-Torque_Sensors"),
    ("Main Tree", "Main_Tree"),
    ("Main.Tree", "Main_Tree"),
    ("Sub Tree", "Sub_Tree"),
    ("request.name", "request_name"),
    ("My<Node>", "My_Node"),
    ("path/to/node", "path_to_node"),
    ("path\\to\\node", "path_to_node"),
    ("C:drive", "C_drive"),
    ("wild*card", "wild_card"),
    ("what?", "what"),
    ("it's", "it_s"),
    ('say"hello"', "say_hello"),
    ("A&B", "A_B"),
    ("pipe|char", "pipe_char"),
    ("a   b", "a_b"),
    ("a _b", "a_b"),
    ("a_ b", "a_b"),
    ("a - b", "a-b"),
    ("  padded  ", "padded"),
    ("x#1", "x_1"),
    ("a=b", "a_b"),
    ("{bb}", "bb"),
    ("Go! (fast), now; ok", "Go_fast_now_ok"),
    ("with\ttab", "with_tab"),
    ("with\r\nCRLF", "with_CRLF"),
    ("test\x07bell", "test_bell"),
    ("test\x00nul", "test_nul"),
    ("test\x7fdel", "test_del"),
    ("检查 门", "检查_门"),
    ("检查\u3000门", "检查_门"),
    ("a\u00a0b", "a_b"),
    ("Tür öffnen", "Tür_öffnen"),
    ("ドアを 開ける", "ドアを_開ける"),
    ("a😀 b", "a😀_b"),
    ("x\u00d7y", "x_y"),
    ("Root", "RootTree"),
    ("root", "root_tree"),
    (" Root ", "RootTree"),
    ("Root.", "RootTree"),
    ("", "Unnamed"),
    ("...", "Unnamed"),
    (" ", "Unnamed"),
    ("9 Tree", "_9_Tree"),
    ("9Tree", "_9Tree"),
    ("-x", "_-x"),
    ("1.5", "_1_5"),
    ("\u0300x", "_\u0300x"),
    # valid names are kept
    ("MyAction", "MyAction"),
    ("ROOT", "ROOT"),
    ("_x", "_x"),
    ("__", "__"),
    ("检查门状态", "检查门状态"),
    ("Tür_öffnen", "Tür_öffnen"),
    ("a😀", "a😀"),
]

PORT_CASES = [
    ("1port", "p_1port"),
    ("123", "p_123"),
    ("9", "p_9"),
    ("_goal", "goal"),
    ("_private", "private"),
    ("__shared_blackboard", "shared_blackboard"),
    ("_description", "description"),
    ("_skipIf", "skipIf"),
    ("_autoremap", "autoremap"),
    ("检查", "p_检查"),
    ("Äpfel", "p_Äpfel"),
    ("name", "name_"),
    ("ID", "ID_"),
    ("_ID", "ID_"),
    ("input value", "input_value"),
    ("port name", "port_name"),
    ("port.name", "port_name"),
    ("port<T>", "port_T"),
    ("1a.b", "p_1a_b"),
    ("-x", "x"),
    ("_1x", "p_1x"),
    ("", "port"),
    ("_", "port"),
    (" . ", "port"),
    ("{value}", "value"),
    ("target pose (map)", "target_pose_map"),
    # valid, allowed port names are kept
    ("input", "input"),
    ("output_value", "output_value"),
    ("myPort123", "myPort123"),
    ("foo-bar", "foo-bar"),
    ("a检查", "a检查"),
    ("Name", "Name"),
]

INSTANCE_CASES = [
    ("test\x07bell", "test bell"),
    ("name_with_bell\x07", "name_with_bell"),
    ("name_with_null\x00", "name_with_null"),
    ("\x07lead", "lead"),
    ("a \x07b", "a b"),
    ("a\x07 b", "a b"),
    ("a\x01\x02\x03b", "a b"),
    ("\x07", ""),
    ("\x7f\x7f", ""),
    ("a\ud800b", "a b"),
    ("a\uffffb", "a b"),
    # valid names are kept
    ("", ""),
    ("My Action", "My Action"),
    ("node.name", "node.name"),
    ("a\tb\nc\rd", "a\tb\nc\rd"),
    ("<&>'\"", "<&>'\""),
    ("成功ノード", "成功ノード"),
]


@pytest.mark.parametrize(("name", "expected"), MODEL_CASES)
def test_model_examples(name: str, expected: str) -> None:
    assert sanitize(name, MODEL) == expected
    assert_valid(expected, MODEL)


@pytest.mark.parametrize(("name", "expected"), PORT_CASES)
def test_port_examples(name: str, expected: str) -> None:
    assert sanitize(name, PORT) == expected
    assert_valid(expected, PORT)


@pytest.mark.parametrize(("name", "expected"), INSTANCE_CASES)
def test_instance_examples(name: str, expected: str) -> None:
    assert sanitize(name, INSTANCE) == expected
    assert_valid(expected, INSTANCE)


@pytest.mark.parametrize(
    ("text", "valid"),
    [
        ("a", True),
        ("_a", True),
        (":a", True),
        ("a.b-c", True),
        ("检查", True),
        ("😀", True),
        ("a\u00b7", True),
        ("", False),
        ("1a", False),
        ("-a", False),
        (".a", False),
        ("\u00b7a", False),
        ("a b", False),
        ("a(b)", False),
        ("a\u00d7", False),
        ("\u3000", False),
    ],
)
def test_is_xml_name(text: str, valid: bool) -> None:
    assert is_xml_name(text) is valid
    assert (XML_NAME.fullmatch(text) is not None) is valid


# --- uniqueness ---------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("name", "kind", "taken", "expected"),
    [
        ("Main Tree", MODEL, {"Main_Tree"}, "Main_Tree_2"),
        ("Main Tree", MODEL, {"Main_Tree", "Main_Tree_2"}, "Main_Tree_3"),
        ("Main Tree", MODEL, ["Main_Tree", "Main_Tree_2", "Main_Tree_3"], "Main_Tree_4"),
        ("Main Tree", MODEL, ("Main_Tree_2",), "Main_Tree"),
        ("Main Tree", MODEL, {"Main_Tree": 1}, "Main_Tree_2"),
        ("Root", MODEL, {"RootTree"}, "RootTree_2"),
        ("", MODEL, {"Unnamed"}, "Unnamed_2"),
        ("Foo", MODEL, {"Foo"}, "Foo_2"),
        ("_", MODEL, {"_"}, "__2"),
        ("name", PORT, {"name_"}, "name_2"),
        ("name", PORT, {"name_", "name_2"}, "name_3"),
        ("1port", PORT, {"p_1port"}, "p_1port_2"),
        ("", PORT, {"port"}, "port_2"),
        ("a\x07b", INSTANCE, {"a b"}, "a b_2"),
        ("\x07", INSTANCE, {""}, ""),
    ],
)
def test_uniqueness(name: str, kind: NameKind, taken: set[str], expected: str) -> None:
    assert sanitize(name, kind, taken) == expected
    assert candidates(name, kind, taken)[0] == expected


# --- alternatives -------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("name", "kind", "taken", "expected"),
    [
        (
            "Move to Pose (JTC)",
            MODEL,
            set(),
            ["Move_to_Pose_JTC", "MoveToPoseJTC", "Move-to-Pose-JTC"],
        ),
        (
            "Pick April Tag Labeled Object",
            MODEL,
            set(),
            [
                "Pick_April_Tag_Labeled_Object",
                "PickAprilTagLabeledObject",
                "Pick-April-Tag-Labeled-Object",
            ],
        ),
        (
            "Re-Zero Force-Torque Sensors",
            MODEL,
            set(),
            [
                "Re-Zero_Force-Torque_Sensors",
                "ReZeroForceTorqueSensors",
                "Re-Zero-Force-Torque-Sensors",
            ],
        ),
        ("检查 门", MODEL, set(), ["检查_门", "检查门", "检查-门"]),
        ("Root", MODEL, set(), ["RootTree"]),
        ("", MODEL, set(), ["Unnamed"]),
        ("...", MODEL, set(), ["Unnamed"]),
        ("9 Tree", MODEL, set(), ["_9_Tree", "_9Tree", "_9-Tree"]),
        ("Move to Pose", MODEL, {"MoveToPose"}, ["Move_to_Pose", "Move-to-Pose"]),
        (
            "Move to Pose",
            MODEL,
            {"Move_to_Pose"},
            ["Move_to_Pose_2", "MoveToPose", "Move-to-Pose"],
        ),
        ("input value", PORT, set(), ["input_value", "inputValue", "input-value"]),
        (
            "__shared_blackboard",
            PORT,
            set(),
            ["shared_blackboard", "sharedBlackboard", "shared-blackboard"],
        ),
        ("name", PORT, set(), ["name_"]),
        ("1 port", PORT, set(), ["p_1_port", "p_1Port", "p_1-port"]),
        ("test\x07bell", INSTANCE, set(), ["test bell", "testbell"]),
        ("bell\x07", INSTANCE, set(), ["bell"]),
        ("test\x07bell", INSTANCE, {"testbell"}, ["test bell"]),
    ],
)
def test_candidates(name: str, kind: NameKind, taken: set[str], expected: list[str]) -> None:
    assert candidates(name, kind, taken) == expected


# --- properties ---------------------------------------------------------------------------

any_text = st.text(st.characters(exclude_categories=()), max_size=40)
_PIECES = [
    *"aZz09_-.:;()# \t\n\r<>&\"'/\\*?|\x00\x07\x1f\x7f\u00a0\u00b7\u0300\u3000",
    *("检", "ß", "İ", "😀", "\ud800", "\ufffe", "Root", "root", "name", "ID", "__"),
]
tricky_text = st.lists(st.sampled_from(_PIECES), max_size=10).map("".join)
texts = any_text | tricky_text
kinds = st.sampled_from(list(NameKind))


def assert_valid(result: str, kind: NameKind) -> None:
    assert check_name(result, kind, declaration=True) == ()
    result.encode("utf-8")  # no lone surrogates
    if kind is INSTANCE:
        return
    assert XML_NAME.fullmatch(result), result
    assert is_xml_name(result)
    etree.Element(result)
    if kind is MODEL:
        assert parses_as_element(result), result
    else:
        assert is_allowed_port_name(result)
        assert parses_as_attribute(result), result


@given(texts, kinds)
@example("", MODEL)
@example("", PORT)
@example("Root", MODEL)
@example("\ud800", MODEL)
@example("\x07", INSTANCE)
def test_sanitized_names_pass_every_rule(name: str, kind: NameKind) -> None:
    result = sanitize(name, kind)
    assert_valid(result, kind)
    assert sanitize(result, kind) == result
    if kind is not INSTANCE:
        assert result


def is_already_valid(name: str, kind: NameKind) -> bool:
    if check_name(name, kind, declaration=True):
        return False
    if kind is INSTANCE:
        return not any(0xD800 <= ord(c) <= 0xDFFF or c in "\ufffe\uffff" for c in name)
    if XML_NAME.fullmatch(name) is None:
        return False
    return kind is MODEL or is_allowed_port_name(name)


@given(texts, kinds)
@example("MyAction", MODEL)
@example("input", PORT)
@example("My Action", INSTANCE)
def test_valid_names_are_kept(name: str, kind: NameKind) -> None:
    if is_already_valid(name, kind):
        assert sanitize(name, kind) == name


@given(texts, kinds, st.data())
def test_results_are_not_taken(name: str, kind: NameKind, data: st.DataObject) -> None:
    base = sanitize(name, kind)
    extra = data.draw(st.sets(texts, max_size=5))
    crowded = {base, f"{base}_2", f"{base.rstrip('_') or base}_2", f"{base}_3"}
    taken = extra | data.draw(st.sampled_from([set(), {base}, crowded]))
    as_list = sorted(taken)
    result = sanitize(name, kind, taken)
    assert result == sanitize(name, kind, as_list)
    assert_valid(result, kind)
    if not (kind is INSTANCE and result == ""):
        assert result not in taken

    found = candidates(name, kind, taken)
    assert found == candidates(name, kind, as_list)
    assert found[0] == result
    assert 1 <= len(found) <= 3
    assert len(set(found)) == len(found)
    for alternative in found[1:]:
        assert_valid(alternative, kind)
        assert alternative not in taken
