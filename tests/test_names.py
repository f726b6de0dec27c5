"""The name rules: the seed examples, BehaviorTree.CPP's gtest_name_validation cases, and more."""

from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st

from bt_lsp.rules.names import (
    BTCPP_RESERVED_ATTRIBUTES,
    FORBIDDEN,
    POSTCONDITIONS,
    PRECONDITIONS,
    RESERVED_MODEL_NAMES,
    RESERVED_PORT_NAMES,
    RULES,
    BadChar,
    NameKind,
    Violation,
    check_name,
    is_allowed_port_name,
    reserved_port_declaration,
)
from bt_lsp.rules.registry import CODES

MODEL = NameKind.MODEL
PORT = NameKind.PORT
INSTANCE = NameKind.INSTANCE


def codes(name: str, kind: NameKind, *, declaration: bool = False) -> list[str]:
    return [v.code for v in check_name(name, kind, declaration=declaration)]


def only(name: str, kind: NameKind, *, declaration: bool = False) -> Violation:
    found = check_name(name, kind, declaration=declaration)
    assert len(found) == 1, found
    return found[0]


# --- constants ----------------------------------------------------------------------------


def test_constants() -> None:
    assert frozenset(" \t\n\r<>&\"'/\\:*?|.") == FORBIDDEN
    assert len(FORBIDDEN) == 16
    assert set(PRECONDITIONS) == {"_failureIf", "_successIf", "_skipIf", "_while"}
    assert set(POSTCONDITIONS) == {"_onHalted", "_onFailure", "_onSuccess", "_post"}
    btcpp = "ID name _autoremap _failureIf _successIf _skipIf _while _onSuccess _onFailure"
    btcpp += " _onHalted _post"
    assert set(btcpp.split()) == BTCPP_RESERVED_ATTRIBUTES
    assert len(BTCPP_RESERVED_ATTRIBUTES) == 11
    assert set(btcpp.split()) | {"_description", "__shared_blackboard"} == RESERVED_PORT_NAMES
    assert len(RESERVED_PORT_NAMES) == 13
    assert {"Root", "root"} == RESERVED_MODEL_NAMES


def test_codes_exist_and_rules_cover_them() -> None:
    name_codes = {c for c, info in CODES.items() if info.family == "names"}
    assert set(RULES) == name_codes
    assert all(rule.endswith(".") for rule in RULES.values())


# --- the seed examples (name-validation-rules.md) -----------------------------------------

SEED_VALID = ["MyAction", "my_action", "My-Action", "检查门状态", "ドアを開ける", "Tür_öffnen"]


@pytest.mark.parametrize("name", SEED_VALID)
@pytest.mark.parametrize("kind", [MODEL, PORT])
def test_seed_valid_model_and_port_names(name: str, kind: NameKind) -> None:
    assert check_name(name, kind, declaration=True) == ()


@pytest.mark.parametrize(
    ("name", "kind", "code", "chars"),
    [
        ("My Action", MODEL, "model-name-forbidden-char", " "),
        ("My Action", PORT, "port-name-forbidden-char", " "),
        ("request.name", MODEL, "model-name-forbidden-char", "."),
        ("request.name", PORT, "port-name-forbidden-char", "."),
        ("My<Node>", MODEL, "model-name-forbidden-char", "<>"),
        ("My<Node>", PORT, "port-name-forbidden-char", "<>"),
        ("path/to/node", MODEL, "model-name-forbidden-char", "//"),
        ("path/to/node", PORT, "port-name-forbidden-char", "//"),
        ("Root", MODEL, "model-name-reserved", ""),
    ],
)
def test_seed_invalid_model_and_port_names(
    name: str, kind: NameKind, code: str, chars: str
) -> None:
    violation = only(name, kind, declaration=True)
    assert violation.code == code
    assert "".join(c.char for c in violation.chars) == chars


@pytest.mark.parametrize("name", ["My Action", "node.name", "Success 1", "检查门状态"])
def test_seed_valid_instance_names(name: str) -> None:
    assert check_name(name, INSTANCE) == ()


@pytest.mark.parametrize(
    ("name", "char", "shown"),
    [
        ("name_with_null\0", "\0", "U+0000 (control character)"),
        ("name_with_bell\x07", "\x07", "U+0007 (control character)"),
    ],
)
def test_seed_invalid_instance_names(name: str, char: str, shown: str) -> None:
    violation = only(name, INSTANCE)
    assert violation.code == "instance-name-control-char"
    assert [(c.char, c.offset, c.shown) for c in violation.chars] == [(char, 14, shown)]
    assert f"{shown} at column 15" in violation.message


# --- gtest_name_validation.cpp: unit tests ------------------------------------------------

GTEST_VALID = [
    "ValidName",
    "my_action",
    "My-Action",
    "action123",
    "CamelCaseNode",
    "snake_case_node",
    "kebab-case-node",
]
GTEST_UNICODE = ["检查门状态", "ドアを開ける", "Tür_öffnen", "проверка", "действие"]


@pytest.mark.parametrize("name", GTEST_VALID + GTEST_UNICODE)
@pytest.mark.parametrize("kind", [MODEL, PORT])
def test_gtest_forbidden_char_detection_valid(name: str, kind: NameKind) -> None:
    assert check_name(name, kind, declaration=True) == ()


GTEST_FORBIDDEN = [
    ("My Action", " "),
    ("with\ttab", "\t"),
    ("with\nnewline", "\n"),
    ("with\rcarriage", "\r"),
    ("My<Node>", "<"),
    ("Node>End", ">"),
    ("A&B", "&"),
    ('say"hello"', '"'),
    ("it's", "'"),
    ("path/to/node", "/"),
    ("path\\to\\node", "\\"),
    ("C:drive", ":"),
    ("wild*card", "*"),
    ("what?", "?"),
    ("pipe|char", "|"),
    ("request.name", "."),
    ("file.ext", "."),
    ("test\0name", "\0"),  # BT.CPP misses NUL (its return value doubles as "none")
    ("test\x07bell", "\x07"),
    ("test\x7fdel", "\x7f"),
]


@pytest.mark.parametrize(("name", "char"), GTEST_FORBIDDEN)
@pytest.mark.parametrize(
    ("kind", "code"), [(MODEL, "model-name-forbidden-char"), (PORT, "port-name-forbidden-char")]
)
def test_gtest_forbidden_char_detection(name: str, char: str, kind: NameKind, code: str) -> None:
    violation = only(name, kind, declaration=True)
    assert violation.code == code
    assert violation.chars[0].char == char
    assert violation.chars[0].offset == name.index(char)


@pytest.mark.parametrize(
    ("name", "char"), [("test\0name", "\0"), ("test\x07bell", "\x07"), ("test\x7fdel", "\x7f")]
)
def test_gtest_control_chars_in_instance_names(name: str, char: str) -> None:
    violation = only(name, INSTANCE)
    assert violation.code == "instance-name-control-char"
    assert [c.char for c in violation.chars] == [char]


@pytest.mark.parametrize("name", ["input", "output_value", "myPort123", "Port_With_Underscore"])
def test_gtest_is_allowed_port_name_valid(name: str) -> None:
    assert is_allowed_port_name(name)
    assert check_name(name, PORT, declaration=True) == ()


GTEST_NOT_ALLOWED_PORTS = [
    "",
    "1port",
    "123",
    "_private",
    "name",
    "ID",
    "_failureIf",
    "_successIf",
    "_skipIf",
    "_while",
    "_onSuccess",
    "_onFailure",
    "_onHalted",
    "_post",
    "_autoremap",
    "port name",
    "port.name",
    "port<T>",
]


@pytest.mark.parametrize("name", GTEST_NOT_ALLOWED_PORTS)
def test_gtest_is_allowed_port_name_invalid(name: str) -> None:
    assert not is_allowed_port_name(name)


@pytest.mark.parametrize(
    ("name", "allowed"),
    [
        ("_description", False),
        ("__shared_blackboard", False),
        ("foo-bar", True),
        ("Name", True),
        ("id", True),
        ("_SkipIf", False),
        ("检查", False),
        ("Äpfel", False),
        ("-x", False),
        ("a检查", True),
        ("a\x07", False),
        ("a\0", False),
        ("x", True),
    ],
)
def test_is_allowed_port_name_more(name: str, allowed: bool) -> None:
    assert is_allowed_port_name(name) is allowed


# --- gtest_name_validation.cpp: XML tests, mapped to our kinds -----------------------------

GTEST_XML = [
    # (test, kind, declaration, name, expected codes)
    ("ValidBehaviorTreeID", MODEL, False, "MainTree", []),
    ("ValidBehaviorTreeID_WithUnderscore", MODEL, False, "My_Main_Tree", []),
    ("InvalidBehaviorTreeID_Root", MODEL, False, "Root", ["model-name-reserved"]),
    ("InvalidBehaviorTreeID_root_lowercase", MODEL, False, "root", ["model-name-reserved"]),
    ("InvalidBehaviorTreeID_WithSpace", MODEL, False, "Main Tree", ["model-name-forbidden-char"]),
    ("InvalidBehaviorTreeID_WithPeriod", MODEL, False, "Main.Tree", ["model-name-forbidden-char"]),
    ("ValidInstanceName", INSTANCE, False, "my_success_node", []),
    ("ValidInstanceName_WithSpace", INSTANCE, False, "my success node", []),
    ("ValidInstanceName_WithPeriod", INSTANCE, False, "node.name", []),
    ("ValidSubTreeID", MODEL, False, "SubTree1", []),
    ("InvalidSubTreeID_WithSpace", MODEL, False, "Sub Tree", ["model-name-forbidden-char"]),
    ("UnicodeTreeID_Chinese", MODEL, False, "检查门", []),
    ("UnicodeInstanceName_Japanese", INSTANCE, False, "成功ノード", []),
    ("UnicodeTreeID_German", MODEL, False, "Türöffner", []),
    ("ValidSubTreePortName", PORT, True, "input_value", []),
    ("InvalidSubTreePortName_WithSpace", PORT, True, "input value", ["port-name-forbidden-char"]),
    ("InvalidSubTreePortName_Reserved", PORT, True, "ID", ["port-name-reserved"]),
    ("InvalidSubTreePortName_StartsWithDigit", PORT, True, "1port", ["port-name-leading-digit"]),
]


@pytest.mark.parametrize(
    ("kind", "declaration", "name", "expected"),
    [case[1:] for case in GTEST_XML],
    ids=[case[0] for case in GTEST_XML],
)
def test_gtest_xml_cases(kind: NameKind, declaration: bool, name: str, expected: list[str]) -> None:
    assert codes(name, kind, declaration=declaration) == expected


# --- model names --------------------------------------------------------------------------


def test_model_empty() -> None:
    violation = only("", MODEL)
    assert violation.code == "model-name-empty"
    assert violation.chars == ()
    assert "empty" in violation.message
    assert violation.rule == RULES["model-name-empty"]


@pytest.mark.parametrize("name", ["Root", "root"])
def test_model_reserved(name: str) -> None:
    violation = only(name, MODEL)
    assert violation.code == "model-name-reserved"
    assert f"'{name}'" in violation.message
    assert "reserved" in violation.message


@pytest.mark.parametrize("name", ["ROOT", "rOOT", "Root1", "MyRoot", "root_tree", "Roots"])
def test_model_reserved_is_exact(name: str) -> None:
    assert codes(name, MODEL) == []


@pytest.mark.parametrize("name", ["9Tree", "123", "_x", "-x", "_", "-", "__init__", "0-1_2"])
def test_model_may_start_with_digit_underscore_hyphen(name: str) -> None:
    assert codes(name, MODEL) == []


@pytest.mark.parametrize(
    "name",
    [
        "Ümlauts",
        "中文",
        "日本語",
        "한국어",
        "a😀b",
        "😀",
        "x\u00a0y",
        "é",
        "\u0300x",
        "\u2028",
        "a\x85b",
    ],
)
def test_non_ascii_allowed_anywhere(name: str) -> None:
    assert codes(name, MODEL) == []
    assert codes(name, PORT, declaration=True) == []
    assert codes(name, INSTANCE) == []


@pytest.mark.parametrize(
    "name", ["!#$%()+,;=@[]^{}~`", "a(b)", "x#1", "a=b", "a,b", "a;b", "{bb}", "a+b"]
)
def test_other_printable_ascii_allowed(name: str) -> None:
    assert codes(name, MODEL) == []
    assert codes(name, PORT, declaration=True) == []


# --- each forbidden character -------------------------------------------------------------

FORBIDDEN_TABLE = [
    (" ", "whitespace", "breaks XML element/attribute names", "' ' (space)"),
    ("\t", "whitespace", "breaks XML element/attribute names", "U+0009 (tab)"),
    ("\n", "whitespace", "breaks XML element/attribute names", "U+000A (line feed)"),
    ("\r", "whitespace", "breaks XML element/attribute names", "U+000D (carriage return)"),
    ("<", "XML special", "reserved in XML", "'<' (less-than sign)"),
    (">", "XML special", "reserved in XML", "'>' (greater-than sign)"),
    ("&", "XML special", "reserved in XML", "'&' (ampersand)"),
    ('"', "XML special", "reserved in XML", "'\"' (double quote)"),
    ("'", "XML special", "reserved in XML", '"\'" (apostrophe)'),
    ("/", "path separator", "filesystem conflicts", "'/' (slash)"),
    ("\\", "path separator", "filesystem conflicts", "'\\\\' (backslash)"),
    (":", "path separator", "filesystem conflicts", "':' (colon)"),
    ("*", "wildcard", "shell/glob conflicts", "'*' (asterisk)"),
    ("?", "wildcard", "shell/glob conflicts", "'?' (question mark)"),
    ("|", "wildcard", "shell/glob conflicts", "'|' (vertical bar)"),
    (".", "period", "ambiguous in port names (e.g. request.name)", "'.' (period)"),
]


def test_forbidden_table_is_complete() -> None:
    assert {row[0] for row in FORBIDDEN_TABLE} == FORBIDDEN


@pytest.mark.parametrize(("char", "category", "reason", "shown"), FORBIDDEN_TABLE)
@pytest.mark.parametrize(
    ("kind", "code", "subject"),
    [(MODEL, "model-name-forbidden-char", "Model"), (PORT, "port-name-forbidden-char", "Port")],
)
def test_each_forbidden_char(
    char: str, category: str, reason: str, shown: str, kind: NameKind, code: str, subject: str
) -> None:
    name = f"ab{char}cd"
    violation = only(name, kind, declaration=True)
    assert violation.code == code
    assert violation.chars == (BadChar(2, char, category, reason),)
    assert violation.chars[0].shown == shown
    assert violation.chars[0].column == 3
    assert violation.message.startswith(f"{subject} name '")
    assert f"contains a forbidden character: {shown} at column 3; " in violation.message
    assert "\n" not in violation.message and "\r" not in violation.message
    assert violation.rule == RULES[code]


@pytest.mark.parametrize("code_point", [*range(0x20), 0x7F])
def test_each_control_char(code_point: int) -> None:
    char = chr(code_point)
    name = f"x{char}y"
    for kind in (MODEL, PORT):
        violation = only(name, kind, declaration=True)
        bad = violation.chars[0]
        assert bad.offset == 1
        assert f"{bad.shown} at column 2" in violation.message
        if char in "\t\n\r":
            assert bad.category == "whitespace"
        else:
            assert bad.category == "control character"
            assert bad.reason == "non-printable"
            assert bad.shown == f"U+{code_point:04X} (control character)"
    instance = check_name(name, INSTANCE)
    if char in "\t\n\r":
        assert instance == ()
    else:
        assert [v.code for v in instance] == ["instance-name-control-char"]
        assert instance[0].chars == (BadChar(1, char, "control character", "non-printable"),)
        assert f"U+{code_point:04X} (control character) at column 2" in instance[0].message


@pytest.mark.parametrize(
    ("char", "shown"),
    [
        ("\0", "U+0000 (control character)"),
        ("\x07", "U+0007 (control character)"),
        ("\x1b", "U+001B (control character)"),
        ("\x7f", "U+007F (control character)"),
        ("\t", "U+0009 (tab)"),
        ("\n", "U+000A (line feed)"),
        ("\r", "U+000D (carriage return)"),
    ],
)
def test_control_chars_shown(char: str, shown: str) -> None:
    assert only(f"a{char}", MODEL).chars[0].shown == shown


# --- messages -----------------------------------------------------------------------------


def test_message_example() -> None:
    assert only("Main Tree", MODEL).message == (
        "Model name 'Main Tree' contains a forbidden character: ' ' (space) at column 5; "
        "whitespace breaks XML element/attribute names"
    )


def test_message_lists_every_char_with_columns() -> None:
    violation = only("a b.c d\x07", MODEL)
    assert [(c.char, c.offset) for c in violation.chars] == [
        (" ", 1),
        (".", 3),
        (" ", 5),
        ("\x07", 7),
    ]
    message = violation.message
    assert "contains 4 forbidden characters" in message
    assert "' ' (space) at columns 2 and 6" in message
    assert "'.' (period) at column 4" in message
    assert "U+0007 (control character) at column 8" in message
    assert "whitespace breaks XML element/attribute names" in message
    assert "period" in message and "non-printable" in message
    assert "\x07" not in message
    assert "'a b.c d\\x07'" in message


def test_message_columns_count_code_points() -> None:
    violation = only("😀检 x", MODEL)
    assert violation.chars[0].offset == 2
    assert "at column 3" in violation.message


def test_message_is_one_line_for_line_breaks() -> None:
    violation = only("a\nb\rc\u2028", PORT)
    assert "\n" not in violation.message
    assert "\r" not in violation.message
    assert "\u2028" not in violation.message
    assert "'a\\nb\\rc\\u2028'" in violation.message


def test_message_long_names_are_cut() -> None:
    name = "x" * 500 + " " * 30
    violation = only(name, MODEL)
    assert len(violation.message) < 400
    assert "at columns 501, 502" in violation.message
    assert "22 more" in violation.message
    assert len(violation.chars) == 30


def test_instance_message() -> None:
    violation = only("bad\x07\x00name", INSTANCE)
    assert violation.message.startswith("Instance name 'bad\\x07\\x00name' contains 2 control")
    assert "U+0007 (control character) at column 4" in violation.message
    assert "U+0000 (control character) at column 5" in violation.message


def test_port_messages() -> None:
    digit = only("1port", PORT)
    assert digit.code == "port-name-leading-digit"
    assert "'1port'" in digit.message and "digit" in digit.message
    assert digit.chars == ()
    reserved = only("_skipIf", PORT, declaration=True)
    assert reserved.code == "port-name-reserved"
    assert "'_skipIf'" in reserved.message and "reserved" in reserved.message
    assert "_skipIf" in reserved.rule and "__shared_blackboard" not in reserved.rule
    groot2 = only("__shared_blackboard", PORT, declaration=True)
    assert groot2.code == "port-name-reserved-groot2"
    assert "_skipIf" in groot2.rule and "__shared_blackboard" in groot2.rule


# --- ports --------------------------------------------------------------------------------


def test_port_empty() -> None:
    assert codes("", PORT) == ["port-name-empty"]
    assert codes("", PORT, declaration=True) == ["port-name-empty"]


@pytest.mark.parametrize("name", sorted(RESERVED_PORT_NAMES))
def test_reserved_ports_only_flagged_in_declarations(name: str) -> None:
    assert codes(name, PORT) == []
    # BehaviorTree.CPP's own reserved attributes, or the two only the name rules reserve.
    code = (
        "port-name-reserved" if name in BTCPP_RESERVED_ATTRIBUTES else "port-name-reserved-groot2"
    )
    assert codes(name, PORT, declaration=True) == [code]


# A declared port's reserved name, by entry and BehaviorTree.CPP version ("3", "4", or None:
# checked as 4 with neither a build nor BTCPP_format saying so).
_GROOT1, _GROOT2, _BTCPP = "port-name-groot1", "port-name-reserved-groot2", "port-name-reserved"


@pytest.mark.parametrize(
    ("name", "entry", "btcpp", "code"),
    [
        # BehaviorTree.CPP 4.8.4+ validates <SubTree> model ports: its 11 names throw.
        ("_autoremap", "SubTree", "4", _BTCPP),
        ("ID", "SubTree", "4", _BTCPP),
        ("_while", "SubTree", None, _BTCPP),
        # ... and accepts the two only the name rules (Groot2) reserve.
        ("__shared_blackboard", "SubTree", "4", _GROOT2),
        ("_description", "SubTree", "4", _GROOT2),
        ("_description", "SubTree", None, _GROOT2),
        # Groot 1's v3 palette: right for BehaviorTree.CPP 3, which reads no models.
        ("__shared_blackboard", "SubTree", "3", _GROOT1),
        ("__shared_blackboard", "SubTree", None, _GROOT1),
        ("_autoremap", "SubTree", "3", _GROOT2),
        # Entries BehaviorTree.CPP never reads.
        ("name", "Action", "4", _GROOT2),
        ("_onSuccess", "Condition", None, _GROOT2),
        ("__shared_blackboard", "Decorator", "4", _GROOT2),
        ("ID", "Control", "3", _GROOT2),
    ],
)
def test_reserved_port_declarations(name: str, entry: str, btcpp: str | None, code: str) -> None:
    found = reserved_port_declaration(name, entry, btcpp)
    assert found is not None and found.code == code
    assert f"'{name}'" in found.message and "\n" not in found.message
    assert found.rule.endswith(".")
    if code == _BTCPP:
        assert "4.8.4" in found.message and "throw" in found.message
    elif code == _GROOT2:
        assert "Groot2" in found.message
        assert ("BehaviorTree.CPP 3" if btcpp == "3" else "BehaviorTree.CPP") in found.message
    else:
        assert "Groot 1" in found.message and "_autoremap" in found.message


@pytest.mark.parametrize("name", ["goal", "Name", "_goal", "autoremap", ""])
def test_unreserved_port_declarations(name: str) -> None:
    for entry in ("SubTree", "Action"):
        for btcpp in ("3", "4", None):
            assert reserved_port_declaration(name, entry, btcpp) is None


@pytest.mark.parametrize("name", ["Name", "id", "_SkipIf", "_skipif", "name_", "IDs", "_desc"])
def test_reserved_ports_case_sensitive(name: str) -> None:
    assert codes(name, PORT, declaration=True) == []


@pytest.mark.parametrize("name", ["0", "9abc", "1_x", "2-y"])
def test_port_leading_ascii_digit(name: str) -> None:
    assert codes(name, PORT) == ["port-name-leading-digit"]


@pytest.mark.parametrize("name", ["١٢٣", "²x", "０port", "_1", "-1", "_x", "-x", "检查"])
def test_port_leading_non_ascii_digit_or_underscore_is_not_flagged(name: str) -> None:
    assert codes(name, PORT, declaration=True) == []


@pytest.mark.parametrize(
    ("name", "declaration", "expected"),
    [
        ("1a.b", False, ["port-name-leading-digit", "port-name-forbidden-char"]),
        ("1a b.c", True, ["port-name-leading-digit", "port-name-forbidden-char"]),
        ("9", True, ["port-name-leading-digit"]),
        ("1 ", True, ["port-name-leading-digit", "port-name-forbidden-char"]),
    ],
)
def test_multiple_port_violations(name: str, declaration: bool, expected: list[str]) -> None:
    assert codes(name, PORT, declaration=declaration) == expected


def test_model_violations_are_exclusive() -> None:
    assert codes("a.b c", MODEL) == ["model-name-forbidden-char"]
    assert len(only("a.b c", MODEL).chars) == 2


# --- instances ----------------------------------------------------------------------------


@pytest.mark.parametrize(
    "name", ["", "a\tb", "a\nb", "a\r\nb", "a:b/c", "<&>", "'\"", "*?|", "Root", " lead"]
)
def test_instance_allowed(name: str) -> None:
    assert codes(name, INSTANCE) == []


def test_instance_all_chars_in_one_violation() -> None:
    violation = only("\x01a\x02\x7f", INSTANCE)
    assert [c.offset for c in violation.chars] == [0, 2, 3]


# --- properties ---------------------------------------------------------------------------


def reference_forbidden(name: str) -> list[int]:
    """Offsets of forbidden characters, following BT.CPP's findForbiddenChar (NUL included)."""
    return [i for i, c in enumerate(name) if ord(c) < 32 or ord(c) == 127 or c in FORBIDDEN]


names = st.text(st.characters(exclude_categories=()), max_size=30) | st.text(
    st.sampled_from("aZ09_-. \t\n\r<>&\"'/\\:*?|\x00\x07\x7f检😀"), max_size=12
)


@given(names)
def test_model_matches_reference(name: str) -> None:
    found = check_name(name, MODEL)
    if not name:
        assert [v.code for v in found] == ["model-name-empty"]
    elif name in ("Root", "root"):
        assert [v.code for v in found] == ["model-name-reserved"]
    elif reference_forbidden(name):
        assert [v.code for v in found] == ["model-name-forbidden-char"]
        assert [c.offset for c in found[0].chars] == reference_forbidden(name)
        assert all(name[c.offset] == c.char for c in found[0].chars)
    else:
        assert found == ()


@given(names, st.booleans())
def test_port_matches_reference(name: str, declaration: bool) -> None:
    expected = []
    if not name:
        expected = ["port-name-empty"]
    else:
        if name[0] in "0123456789":
            expected.append("port-name-leading-digit")
        if declaration and name in BTCPP_RESERVED_ATTRIBUTES:
            expected.append("port-name-reserved")
        elif declaration and name in RESERVED_PORT_NAMES:
            expected.append("port-name-reserved-groot2")
        if reference_forbidden(name):
            expected.append("port-name-forbidden-char")
    assert codes(name, PORT, declaration=declaration) == expected
    if is_allowed_port_name(name):
        assert check_name(name, PORT, declaration=True) == ()


@given(names)
def test_instance_matches_reference(name: str) -> None:
    bad = [i for i, c in enumerate(name) if (ord(c) < 32 and c not in "\t\n\r") or ord(c) == 127]
    found = check_name(name, INSTANCE)
    assert [c.offset for v in found for c in v.chars] == bad


@given(names, st.sampled_from(list(NameKind)), st.booleans())
def test_messages_are_one_line(name: str, kind: NameKind, declaration: bool) -> None:
    for violation in check_name(name, kind, declaration=declaration):
        assert violation.code in CODES
        assert violation.rule == RULES[violation.code]
        assert len(violation.message.splitlines()) == 1
        assert not any("\ud800" <= c <= "\udfff" for c in violation.message)
        violation.message.encode("utf-8")
        for bad in violation.chars:
            assert f"{bad.shown} at column" in violation.message
