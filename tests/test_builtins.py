"""Tests for bt_lsp.rules.builtins: the built-in node table and literal conversions."""

from __future__ import annotations

import dataclasses
import re
from collections import Counter
from pathlib import Path

import pytest
from hypothesis import given
from hypothesis import strategies as st

from bt_lsp.rules.builtins import (
    BUILTINS,
    V3_RENAMES,
    NodeModel,
    PortModel,
    is_builtin,
)
from bt_lsp.rules.conversions import (
    blackboard_key,
    convert_literal,
    convert_queue,
    is_blackboard_reference,
    is_converted_as_reference,
)

_SPEC = Path(__file__).parent / "data" / "spec" / "bt-xml.md"

# Registration order of BehaviorTreeFactory's constructor in BehaviorTree.CPP 4.10.
_EXPECTED_IDS = {
    "Action": [
        "AlwaysSuccess",
        "AlwaysFailure",
        "Script",
        "SetBlackboard",
        "Sleep",
        "UnsetBlackboard",
        "WasEntryUpdated",
    ],
    "Condition": ["ScriptCondition"],
    "Control": [
        "Sequence",
        "Fallback",
        "SequenceWithMemory",
        "AsyncSequence",
        "AsyncFallback",
        "ReactiveSequence",
        "ReactiveFallback",
        "Parallel",
        "ParallelAll",
        "IfThenElse",
        "WhileDoElse",
        "TryCatch",
        "Switch2",
        "Switch3",
        "Switch4",
        "Switch5",
        "Switch6",
    ],
    "Decorator": [
        "Inverter",
        "ForceSuccess",
        "ForceFailure",
        "KeepRunningUntilFailure",
        "Repeat",
        "RetryUntilSuccessful",
        "Timeout",
        "Delay",
        "RunOnce",
        "Precondition",
        "SkipUnlessUpdated",
        "WaitValueUpdate",
        "LoopInt",
        "LoopDouble",
        "LoopBool",
        "LoopString",
    ],
    "SubTree": ["SubTree"],
}


def test_there_are_42_builtins() -> None:
    assert len(BUILTINS) == 42
    assert Counter(m.category for m in BUILTINS.values()) == {
        "Action": 7,
        "Condition": 1,
        "Control": 17,
        "Decorator": 16,
        "SubTree": 1,
    }
    for category, ids in _EXPECTED_IDS.items():
        for id_ in ids:
            assert BUILTINS[id_].category == category


def test_keys_match_ids_and_models_are_frozen() -> None:
    for id_, model in BUILTINS.items():
        assert model.id == id_
        with pytest.raises(dataclasses.FrozenInstanceError):
            model.id = "x"  # type: ignore[misc]
    with pytest.raises(TypeError):
        BUILTINS["X"] = BUILTINS["Sequence"]  # type: ignore[index]


def test_is_builtin() -> None:
    assert is_builtin("Sequence")
    assert is_builtin("SubTree")
    assert not is_builtin("sequence")
    assert not is_builtin("SequenceStar")
    assert not is_builtin("RetryUntilSuccesful")
    assert not is_builtin("BlackboardCheckInt")
    assert not is_builtin("")


def test_v3_renames() -> None:
    assert V3_RENAMES == {
        "SequenceStar": "SequenceWithMemory",
        "SubTreePlus": "SubTree",
        "RetryUntilSuccesful": "RetryUntilSuccessful",
    }
    for old, new in V3_RENAMES.items():
        assert not is_builtin(old)
        assert is_builtin(new)


def test_child_rules() -> None:
    def rule(id_: str) -> tuple[int, int | None]:
        return BUILTINS[id_].min_children, BUILTINS[id_].max_children

    for model in BUILTINS.values():
        if model.category in ("Action", "Condition", "SubTree"):
            assert rule(model.id) == (0, 0)
        elif model.category == "Decorator":
            assert rule(model.id) == (1, 1)
    for id_ in _EXPECTED_IDS["Control"][:9]:
        assert rule(id_) == (1, None)
    assert rule("IfThenElse") == (2, 3)
    assert rule("WhileDoElse") == (2, 3)
    assert rule("TryCatch") == (2, None)
    for n in range(2, 7):
        assert rule(f"Switch{n}") == (n + 1, n + 1)
    switch3 = BUILTINS["Switch3"]
    assert [switch3.accepts_children(k) for k in range(6)] == [False] * 4 + [True, False]
    assert BUILTINS["Sequence"].accepts_children(1000)
    assert not BUILTINS["Sequence"].accepts_children(0)


def test_async_flags() -> None:
    assert {m.id for m in BUILTINS.values() if m.is_async} == {"AsyncSequence", "AsyncFallback"}


def test_descriptions_are_one_line() -> None:
    for model in BUILTINS.values():
        assert model.description and "\n" not in model.description
        assert model.description[0].isupper()
        for port in model.ports:
            assert port.description and "\n" not in port.description


def test_port_names_are_unique_and_allowed() -> None:
    allowed = re.compile(r"[A-Za-z][A-Za-z0-9_-]*\Z")
    for model in BUILTINS.values():
        names = model.port_names
        assert len(names) == len(set(names))
        for name in names:
            if model.id == "SubTree":
                assert name == "_autoremap"  # built as a PortInfo, not via CreatePort
            else:
                assert allowed.match(name), name


def test_defaults_convert_to_their_own_type() -> None:
    for model in BUILTINS.values():
        for port in model.ports:
            if port.default is not None:
                assert convert_literal(port.default, port.type) is None, (model.id, port)


def test_port_lookup() -> None:
    sleep = BUILTINS["Sleep"]
    assert sleep.port("msec") == PortModel(
        "msec", "input", "unsigned int", None, sleep.ports[0].description
    )
    assert sleep.port("msec") is not None and sleep.port("msec").required  # type: ignore[union-attr]
    assert sleep.port("nope") is None
    assert not BUILTINS["RunOnce"].ports[0].required


def test_selected_ports() -> None:
    def ports(id_: str) -> list[tuple[str, str, str, str | None]]:
        return [(p.name, p.direction, p.type, p.default) for p in BUILTINS[id_].ports]

    assert ports("Parallel") == [
        ("success_count", "input", "int", "-1"),
        ("failure_count", "input", "int", "1"),
    ]
    assert ports("SetBlackboard") == [
        ("value", "input", "any", None),
        ("output_key", "inout", "any", None),
    ]
    assert ports("Precondition") == [
        ("if", "input", "std::string", None),
        ("else", "input", "NodeStatus", "FAILURE"),
    ]
    assert ports("LoopDouble") == [
        ("queue", "inout", "any", None),
        ("if_empty", "input", "NodeStatus", "SUCCESS"),
        ("value", "output", "double", None),
    ]
    assert ports("Switch3") == [
        ("variable", "input", "std::string", None),
        ("case_1", "input", "std::string", None),
        ("case_2", "input", "std::string", None),
        ("case_3", "input", "std::string", None),
    ]
    assert ports("SubTree") == [("_autoremap", "input", "bool", "false")]
    assert ports("TryCatch") == [("catch_on_halt", "input", "bool", "false")]
    for id_ in ("Sequence", "Inverter", "AlwaysSuccess", "IfThenElse", "ReactiveSequence"):
        assert ports(id_) == []


# ---------------------------------------------------------------------------------------
# Cross-check with the table in tests/data/spec/bt-xml.md section (d)

_PORT = re.compile(
    r"\b(inout|in|out) `(\w+)` ([\w:]+(?:[ /][\w:]+)*?)"
    r"(?: \((req)[^)]*\)| =([^\s;|]+?)(?=[;.|]?(?:\s|$))|(?=;|$))"
)
_DIRECTIONS = {"in": "input", "out": "output", "inout": "inout"}


def _spec_rows() -> list[tuple[list[str], str]]:
    text = _SPEC.read_text(encoding="utf-8")
    section = text[text.index("## (d)") : text.index("## (e)")]
    rows: list[tuple[list[str], str]] = []
    for line in section.splitlines():
        if not line.startswith("| ") or line.startswith(("| ID |", "|---")):
            continue
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        first, rest = cells[0], " | ".join(cells[1:])
        if "…" in first:
            low, high = (int(x) for x in re.findall(r"Switch(\d)", first))
            ids = [f"Switch{n}" for n in range(low, high + 1)]
        else:
            ids = [x.strip() for x in re.split(r"[,/]", first)]
        rows.append((ids, rest))
    return rows


def test_spec_table_lists_exactly_the_builtins() -> None:
    ids = [id_ for row_ids, _ in _spec_rows() for id_ in row_ids]
    assert len(ids) == 42
    assert set(ids) == set(BUILTINS)


def test_spec_table_ports_match() -> None:
    checked = 0
    for ids, description in _spec_rows():
        found = _PORT.findall(description)
        if not found and ids != ["SubTree"]:
            assert all(not BUILTINS[i].ports for i in ids), ids
        for direction, name, type_, req, default in found:
            for index, id_ in enumerate(ids):
                port = BUILTINS[id_].port(name)
                assert port is not None, (id_, name)
                assert port.direction == _DIRECTIONS[direction], (id_, name)
                expected_type = type_.split("/")[index] if "/" in type_ else type_
                assert port.type == expected_type, (id_, name)
                assert port.default == (default or None), (id_, name)
                if req:
                    assert port.required
                checked += 1
        if ids[0].startswith("Switch"):
            for id_ in ids:
                n = int(id_.removeprefix("Switch"))
                assert BUILTINS[id_].port_names == (
                    "variable",
                    *(f"case_{i}" for i in range(1, n + 1)),
                )
                assert BUILTINS[id_].min_children == BUILTINS[id_].max_children == n + 1
    assert checked >= 25
    # SubTree's row is prose: "model has one port, `_autoremap` bool =false".
    assert BUILTINS["SubTree"].ports == (
        PortModel("_autoremap", "input", "bool", "false", BUILTINS["SubTree"].ports[0].description),
    )


# ---------------------------------------------------------------------------------------
# convert_literal

_OK: list[tuple[str, str]] = [
    ("0", "int"),
    ("-2147483648", "int"),
    ("2147483647", "int"),
    ("007", "int"),
    ("12abc", "int"),  # std::from_chars stops at the first non-digit: accepted as 12
    ("1.5", "int"),
    ("0x10", "int"),
    (
        "-" + "0" * 5000 + "1",
        "int",
    ),  # read as 0: std::from_chars has no "0x" prefix and stops at 'x'
    ("4294967295", "unsigned int"),
    ("0", "unsigned int"),
    ("-0", "unsigned int"),
    ("5000", "unsigned"),
    ("-9223372036854775808", "long"),
    ("18446744073709551615", "uint64_t"),
    ("255", "uint8_t"),
    ("-128", "int8_t"),
    ("3.14", "double"),
    ("-1e3", "double"),
    ("  2.5", "double"),  # strtod skips leading white space
    ("\t2.5", "double"),
    (".5", "double"),
    ("5.", "double"),
    ("+7", "double"),
    ("1e308", "double"),
    ("0x1p3", "double"),
    ("inf", "double"),
    ("-Infinity", "double"),
    ("NaN", "double"),
    ("2.5 m", "double"),  # trailing text is ignored by stod
    ("1e38", "float"),
    ("0", "double"),
    ("0.0e-999", "double"),
    ("true", "bool"),
    ("false", "bool"),
    ("True", "bool"),
    ("False", "bool"),
    ("TRUE", "bool"),
    ("FALSE", "bool"),
    ("1", "bool"),
    ("0", "bool"),
    ("SUCCESS", "NodeStatus"),
    ("FAILURE", "NodeStatus"),
    ("RUNNING", "NodeStatus"),
    ("IDLE", "NodeStatus"),
    ("SKIPPED", "BT::NodeStatus"),
    ("anything at all", "std::string"),
    ("", "std::string"),
    ("whatever", "any"),
    ("whatever", "BT::Any"),
    ("whatever", "AnyTypeAllowed"),
    ("whatever", "geometry_msgs::msg::PoseStamped"),  # unknown type: not checked
    ("1;2;3", "std::vector<int>"),
    ("1;2;", "std::vector<int>"),
    ("", "std::vector<int>"),
    ("0.5;1", "std::vector<double>"),
    ("true;0", "std::vector<bool>"),
    ("a;b", "std::vector<std::string>"),
    # Not converted when version 4 creates the tree: exactly {key}.
    ("{goal}", "unsigned int"),
    ("{@root}", "bool"),
    ("{=}", "double"),
    ("{ goal }", "int"),
    ('json:{"x": 1}', "int"),
]

_BAD: list[tuple[str, str, str]] = [
    ("abc", "unsigned int", "'abc' is not an integer"),
    ("", "int", "'' is not an integer"),
    (" 5", "int", "' 5' is not an integer"),
    ("+5", "int", "'+5' is not an integer"),
    ("-", "int", "'-' is not an integer"),
    ("2147483648", "int", "2147483648 is out of range [-2147483648, 2147483647]"),
    ("-2147483649", "int", "-2147483649 is out of range [-2147483648, 2147483647]"),
    ("-1", "unsigned int", "-1 is out of range [0, 4294967295]"),
    ("4294967296", "unsigned int", "4294967296 is out of range [0, 4294967295]"),
    ("256", "uint8_t", "256 is out of range [0, 255]"),
    ("9223372036854775808", "long", "'9223372036854775808' is out of range for a 64-bit integer"),
    ("-1", "unsigned long", "'-1' is not an integer"),
    (
        "18446744073709551616",
        "uint64_t",
        "'18446744073709551616' is out of range for a 64-bit integer",
    ),
    ("abc", "double", "'abc' is not a number"),
    ("", "double", "'' is not a number"),
    ("e5", "double", "'e5' is not a number"),
    (".", "double", "'.' is not a number"),
    ("1e309", "double", "'1e309' is out of range for double"),
    ("1e-400", "double", "'1e-400' is out of range for double"),
    ("1e39", "float", "'1e39' is out of range for float"),
    ("yes", "bool", "'yes' is not a bool (use true/false, True/False, TRUE/FALSE, 1 or 0)"),
    ("tRue", "bool", "'tRue' is not a bool (use true/false, True/False, TRUE/FALSE, 1 or 0)"),
    (" true", "bool", "' true' is not a bool (use true/false, True/False, TRUE/FALSE, 1 or 0)"),
    ("2", "bool", "'2' is not a bool (use true/false, True/False, TRUE/FALSE, 1 or 0)"),
    (
        "success",
        "NodeStatus",
        "'success' is not a NodeStatus (use one of SUCCESS, FAILURE, RUNNING, IDLE, SKIPPED)",
    ),
    (
        "OK",
        "BT::NodeStatus",
        "'OK' is not a NodeStatus (use one of SUCCESS, FAILURE, RUNNING, IDLE, SKIPPED)",
    ),
    ("1;x;3", "std::vector<int>", "item 'x' is not an integer"),
    (";1", "std::vector<int>", "item '' is not an integer"),
    ("9" * 5000, "long", f"'{'9' * 5000}' is out of range for a 64-bit integer"),
    ("{}", "int", "'{}' is not an integer"),  # too short to be a blackboard reference
    ("{x", "int", "'{x' is not an integer"),
    # A reference to getInput, but converted as a literal at tree creation (4.8.2 throws
    # "can not be converted"): only an exact {key} is skipped there.
    ("  {goal}  ", "int", "'  {goal}  ' is not an integer"),
    ("{goal} ", "double", "'{goal} ' is not a number"),
    (
        "=",
        "NodeStatus",
        "'=' is not a NodeStatus (use one of SUCCESS, FAILURE, RUNNING, IDLE, SKIPPED)",
    ),
]


@pytest.mark.parametrize(("value", "type_"), _OK)
def test_convert_ok(value: str, type_: str) -> None:
    assert convert_literal(value, type_) is None


@pytest.mark.parametrize(("value", "type_", "message"), _BAD)
def test_convert_bad(value: str, type_: str, message: str) -> None:
    assert convert_literal(value, type_) == message


@pytest.mark.parametrize(
    ("value", "type_", "message"),
    [
        ("12abc", "int", "'12abc' has extra characters after the integer 12"),
        ("1.5", "unsigned int", "'1.5' has extra characters after the integer 1"),
        ("2.5 m", "double", "'2.5 m' has extra characters after the number 2.5"),
        ("12", "int", None),
        ("  2.5", "double", None),
    ],
)
def test_convert_strict(value: str, type_: str, message: str | None) -> None:
    assert convert_literal(value, type_, strict=True) == message


def test_builtin_port_examples() -> None:
    def check(id_: str, port: str, value: str) -> str | None:
        model_port = BUILTINS[id_].port(port)
        assert model_port is not None
        return convert_literal(value, model_port.type)

    assert check("Sleep", "msec", "abc") == "'abc' is not an integer"
    assert check("Sleep", "msec", "-5") == "-5 is out of range [0, 4294967295]"
    assert check("Sleep", "msec", "{delay}") is None
    assert check("Repeat", "num_cycles", "-1") is None
    assert check("RunOnce", "then_skip", "yes") is not None
    assert check("Precondition", "else", "SKIPPED") is None
    assert check("Precondition", "else", "skipped") is not None
    assert check("SetBlackboard", "value", "anything") is None
    assert check("Script", "code", "x := 1") is None


def test_is_blackboard_reference() -> None:
    assert is_blackboard_reference("{a}")
    assert is_blackboard_reference(" {a} ")
    assert is_blackboard_reference("{=}")
    assert is_blackboard_reference("=")
    assert not is_blackboard_reference("{}")
    assert not is_blackboard_reference("a{b}")
    assert not is_blackboard_reference("\t{a}")
    assert not is_blackboard_reference(" = ")  # getRemappedKey wants exactly "=" or "{=}"


def test_blackboard_key_keeps_the_spaces_inside_the_braces() -> None:
    """BehaviorTree.CPP 4.8.2: output_key=" a " then {a} is 'Missing parameter', while
    output_key=" a " then { a } reads the entry: the key is what is between the braces."""
    assert blackboard_key("goal", "{ a }") == " a "
    assert blackboard_key("goal", "  {a}  ") == "a"
    assert blackboard_key("goal", "{=}") == "goal"
    assert blackboard_key("goal", "=") == "goal"
    assert blackboard_key("goal", " {=} ") == "="
    assert blackboard_key("goal", "{}") is None
    assert blackboard_key("goal", "a") is None


def test_only_an_exact_key_is_left_out_of_the_conversion_at_creation() -> None:
    assert is_converted_as_reference("{a}") and is_converted_as_reference("{ a }")
    assert not is_converted_as_reference(" {a}")
    assert not is_converted_as_reference("=")
    assert not is_converted_as_reference("{}")


_BOOLS = "(use true/false, True/False, TRUE/FALSE, 1 or 0)"


@pytest.mark.parametrize(
    ("value", "item", "message"),
    [
        ("1;2;3", "int", None),
        ("1;2;", "int", None),  # no item after the last ';'
        ("", "int", None),  # an empty queue
        ("1.5;3x", "int", None),  # from_chars reads the leading integer
        ("1;0;true", "bool", None),
        (" 2; 3", "double", None),  # strtod skips leading spaces
        ("1;;2", "int", "item '' is not an integer"),
        (" 1", "int", "item ' 1' is not an integer"),
        ("yes", "bool", "item 'yes' is not a bool " + _BOOLS),
        ("1.5;x", "double", "item 'x' is not a number"),
        ("{}", "int", "item '{}' is not an integer"),
        ("json:[1,2]", "int", "item 'json:[1,2]' is not an integer"),
        ("a;{}", "std::string", None),
    ],
)
def test_convert_queue_converts_each_item(value: str, item: str, message: str | None) -> None:
    """What BehaviorTree.CPP 4.8.2 does with LoopInt/LoopDouble/LoopBool queue="..."."""
    assert convert_queue(value, item) == message


@given(st.text(), st.sampled_from(sorted({p.type for m in BUILTINS.values() for p in m.ports})))
def test_convert_never_raises(value: str, type_: str) -> None:
    result = convert_literal(value, type_)
    strict = convert_literal(value, type_, strict=True)
    assert result is None or isinstance(result, str)
    if result is not None:  # strict only ever adds errors
        assert strict == result


@given(st.integers(min_value=0, max_value=2**32 - 1))
def test_unsigned_int_range(number: int) -> None:
    assert convert_literal(str(number), "unsigned int") is None
    assert convert_literal(str(-number - 1), "unsigned int") is not None


def test_node_model_is_constructible() -> None:
    model = NodeModel("X", "Action", (), 0, 0, False, "An example.")
    assert model.accepts_children(0) and not model.accepts_children(1)
