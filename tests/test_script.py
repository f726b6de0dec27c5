"""Tests for bt_lsp.rules.script: BehaviorTree.CPP script syntax check."""

from __future__ import annotations

import re
import time
from collections.abc import Iterator
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from bt_lsp.rules.script import (
    _EOF,
    _ERROR,
    _IDENT,
    _LEGACY_TOKENS,
    _PLAIN_SCRIPT,
    ScriptError,
    _Checker,
    check_script,
    identifier_spans,
    identifiers,
)

# Every distinct script found in the real corpus (tests/data/corpus_real): Script/ScriptCondition
# `code`, Precondition `if` and the eight pre/post-condition attributes, XML-decoded.
# All of them parse with BehaviorTree.CPP 4.10.
REAL_SCRIPTS: list[str] = [
    "first_attempt:=true",
    "first_attempt",
    "first_attempt:=false",
    "control_state=3",
    "control_state==1 || assist_kick || go_manual || assist_chase",
    "assist_chase",
    "assist_kick",
    "control_state==2",
    "!odom_calibrated",
    "odom_calibrated",
    "control_state==3 && (!go_manual)",
    "gc_is_under_penalty",
    "!gc_is_under_penalty",
    "gc_game_sub_state_type=='TIMEOUT'",
    "gc_game_sub_state_type=='NONE'",
    "gc_game_state=='INITIAL'",
    "gc_game_state=='READY'",
    "gc_game_state=='SET'",
    "gc_game_state=='PLAY'",
    "player_role == 'striker'",
    "player_role == 'goal_keeper'",
    "gc_game_state=='END'",
    "gc_game_sub_state_type=='FREE_KICK' && gc_game_state=='PLAY'",
    "gc_game_sub_state=='STOP'",
    "ball_location_known",
    "gc_game_sub_state=='GET_READY'",
    "gc_game_sub_state=='SET'",
    "decision!='find'",
    "wait_for_opponent_kickoff",
    "!wait_for_opponent_kickoff",
    "ball_out",
    "!ball_out",
    "decision=='find'",
    "decision == 'assist'",
    "decision == 'chase'",
    "decision == 'auto_visual_kick'",
    "decision =='adjust'",
    "decision == 'kick'",
    "decision == 'cross'",
    "name:='not given'",
    "text := 'My name is ' + name",
    "true",
    "msg := @msg",
    "msg := 'No blackboard parameter'",
    "n_times := @n_times",
    "n_times := 1",
    "prev_event_id := '';\nevent_id := '';\nis_emergency := false;\ncontingency_inactive := true",
    "is_emergency == true",
    "prev_event_id = event_id",
    "event_id = ''",
    "prev_event_id != event_id",
    "event_id == ''",
    "is_emergency = true",
    "contingency_inactive = false",
    "event_id == '' && is_emergency == false",
    "contingency_inactive == true",
    "is_emergency == false",
    "contingency_inactive = true",
    (
        "battery_status != POWER_SUPPLY_STATUS_CHARGING \n&& battery_status != "
        "POWER_SUPPLY_STATUS_FULL"
    ),
    (
        "current_battery_anim_id == CHARGING_BATTERY_ANIM_ID ||\ncurrent_battery_anim_id == "
        "BATTERY_CHARGED_ANIM_ID"
    ),
    (
        "(battery_percent_round == charging_anim_percent  \n&& current_battery_anim_id == "
        "CHARGING_BATTERY_ANIM_ID\n|| battery_percent_round == 1.0)"
    ),
    (
        "charging_anim_percent = battery_percent_round; \ncurrent_battery_anim_id = "
        "CHARGING_BATTERY_ANIM_ID"
    ),
    "battery_percent_round != 1.0 \n|| current_battery_anim_id == BATTERY_CHARGED_ANIM_ID",
    (
        "charging_anim_percent = battery_percent_round; \ncurrent_battery_anim_id = "
        "BATTERY_CHARGED_ANIM_ID"
    ),
    (
        "battery_status != POWER_SUPPLY_STATUS_DISCHARGING \n&& battery_status != "
        "POWER_SUPPLY_STATUS_NOT_CHARGING"
    ),
    (
        "battery_percent < CRITICAL_BATTERY_THRESHOLD_PERCENT \n|| battery_percent >= "
        "LOW_BATTERY_THRESHOLD_PERCENT"
    ),
    (
        "battery_percent >= CRITICAL_BATTERY_THRESHOLD_PERCENT \n|| current_battery_anim_id == "
        "CRITICAL_BATTERY_ANIM_ID"
    ),
    "current_battery_anim_id = CRITICAL_BATTERY_ANIM_ID",
    (
        "battery_percent < LOW_BATTERY_THRESHOLD_PERCENT  \n|| current_battery_anim_id == "
        "BATTERY_NOMINAL_ANIM_ID"
    ),
    "current_battery_anim_id = BATTERY_NOMINAL_ANIM_ID",
    "current_error_anim_id == ERROR_ANIM_ID",
    (
        "battery_status != POWER_SUPPLY_STATUS_CHARGING \n|| battery_health != "
        "POWER_SUPPLY_HEALTH_OVERHEAT"
    ),
    "current_error_anim_id = ERROR_ANIM_ID",
    "battery_status != POWER_SUPPLY_STATUS_UNKNOWN",
    "current_error_anim_id == NO_ERROR_ANIM_ID",
    (
        "battery_status == POWER_SUPPLY_STATUS_UNKNOWN \n|| (battery_status == "
        "POWER_SUPPLY_STATUS_CHARGING \n&& battery_health == POWER_SUPPLY_HEALTH_OVERHEAT)"
    ),
    "current_error_anim_id = NO_ERROR_ANIM_ID",
    "e_stop_state",
    "current_anim_id == MANUAL_ACTION_ANIM_ID",
    "current_anim_id = MANUAL_ACTION_ANIM_ID",
    "current_anim_id == AUTONOMOUS_ACTION_ANIM_ID",
    "current_anim_id = AUTONOMOUS_ACTION_ANIM_ID",
    "current_anim_id == READY_ANIM_ID",
    "current_anim_id = READY_ANIM_ID",
    "(!e_stop_state) || current_anim_id == E_STOP_ANIM_ID",
    "current_anim_id = E_STOP_ANIM_ID",
    "battery_health != POWER_SUPPLY_HEALTH_OVERHEAT",
    "bat_temp <= FATAL_BAT_TEMP",
    "bat_temp > FATAL_BAT_TEMP",
    "bat_temp <= CRITICAL_BAT_TEMP",
    "!aux_state",
    "fan_state",
    "battery_health != POWER_SUPPLY_HEALTH_DEAD",
    "battery_health != POWER_SUPPLY_HEALTH_OVERVOLTAGE",
    "cpu_temp <= CPU_FAN_ON_TEMP\n&& driver_temp <= DRIVER_FAN_ON_TEMP",
    (
        "cpu_temp > CPU_FAN_OFF_TEMP\n|| driver_temp > DRIVER_FAN_OFF_TEMP\n|| battery_health == "
        "POWER_SUPPLY_HEALTH_OVERHEAT\n|| (!fan_state)"
    ),
    "skip_scan",
    "skip_scan=false",
    "run_counter := 0",
    "run_counter += 1",
    "pose_count := 0",
    "pose_count += 1",
    "picked_at_wp1 := false; picked_at_wp2 := false; drained := false; placed_count := 0",
    "picked_at_wp2 := false",
    "picked_at_wp1",
    "drained := !(picked_at_wp1 || picked_at_wp2)",
    "!drained",
    "drained",
    "picked_box := false",
    "mask_count == 0",
    "placed_box_id := 'placed_box_' .. placed_count",
    "placed_count := placed_count + 1",
    "picked_box := true",
    "teleop_mode := 0",
    "teleop_mode != 7",
    "teleop_mode != 6",
    "teleop_mode == 5",
    "teleop_mode == 4",
    "teleop_mode == 3",
    "teleop_mode == 2",
    "teleop_mode == 1",
    "place_marker_count := 0",
    "place_marker_count += 1",
    "current_anim_id = ERROR_ANIM_ID",
    "battery_health == POWER_SUPPLY_HEALTH_OVERHEAT",
    "!e_stop_state",
    "e_stop_state || current_anim_id == READY_ANIM_ID",
    "battery_percent >= CRITICAL_BATTERY_THRESHOLD_PERCENT",
    "object_name:='object' ",
    "table_name:='table' ",
    "reference_frame:='world' ",
    "eef:='hand' ",
    "angle:=3.141592653589793/12 ",
    "arm_group_name:='panda_arm'",
    "hand_group_name:='hand'",
    "hand_frame:='panda_link8'",
    "control_state>=2",
    "control_state==3",
    "!ball_location_known",
    "ball_range>=1.5",
    "ball_range<1.0",
    "ball_location_known || tm_ball_pos_reliable",
    "decision == 'retreat'",
    "gc_is_sub_state_kickoff_side",
    "!(ball_location_known || tm_ball_pos_reliable)",
    "!gc_is_sub_state_kickoff_side",
    " run_tools:=false ",
    " tool_running:=false ",
    " tool_calls:='' ",
    " tool_call_results:='' ",
    " antenna_state_cur:='none' ",
    " antenna_state_req:='none' ",
    " pending_ui_input:='' ",
    " use_vad:=false ",
    " cancel_audio:=false ",
    " @next_tts:='' ",
    " @tts_buffer:='' ",
    " ai_text_to_speak:='' ",
    " text_to_speak:='' ",
    " ai_abort:=false ",
    " prompt:='' ",
    " @parallel_tool_mode:='wait_all' ",
    " @enable_reasoning:=false ",
    " system_prompt:= system_prompt + def_value_2 ",
    " tool_call_result:='' ",
    "@tts_buffer=='' && @next_tts==''",
    " antenna_state_req:='model_active' ",
    " use_vad:=true ",
    " antenna_state_req:='waiting_for_user_vad' ",
    " antenna_state_req:='waiting_for_user' ",
    "pending_ui_input !=''",
    " prompt=pending_ui_input; pending_ui_input='' ",
    " speech_to_text_delay:=0.5 ",
    "use_vad == true",
    " speech_to_text_delay:=-2.0 ",
    " antenna_state_req:='listening' ",
    " @tts_buffer+=ai_text_to_speak; ai_text_to_speak='' ",
    " run_tools:=true ",
    " pending_ui_input=temp_ui_input ",
    " ai_abort:=true; ",
    " @tts_buffer:=''; ai_text_to_speak:='' ",
    " cancel_audio:=true ",
    "antenna_state_req != antenna_state_cur",
    "antenna_state_req == 'waiting_for_user'",
    " antenna_state_cur:='waiting_for_user' ",
    "antenna_state_req == 'waiting_for_user_vad'",
    " antenna_state_cur:='waiting_for_user_vad' ",
    "antenna_state_req == 'model_active'",
    " antenna_state_cur:='model_active' ",
    "antenna_state_req == 'listening'",
    " antenna_state_cur:='listening' ",
    "cancel_audio == true",
    " @next_tts=@tts_buffer; @tts_buffer='' ",
    "@next_tts != ''",
    " @tts_buffer+=text_to_speak; text_to_speak='' ",
    ' tool_call_result:=\'{"result": "success"}\'',
    ' tool_call_result:=\'{"result": "failed"}\'',
    ' tool_call_result:=\'{"result": "failed_invalid_parameters"}\'',
    "rate>0.7 || rate<-0.7",
    "rate<0.2 && rate>=0.0",
    "rate=0.5",
    "rate<0.0 && rate>=-0.2",
    "rate=-0.5",
    " said:='' ",
    "said==''",
    " said:='<Nothing said>' ",
    ' tool_call_result:=\'{"result": "placeholder"}\'',
    " tool_call_result:=obj_json",
]

REAL_LEGACY_SCRIPTS: list[str] = [
    'viz_marker_name:="place_pose_"..viz_idx',
    (
        "battery_status != POWER_SUPPLY_STATUS_CHARGING \\\n&& battery_status != "
        "POWER_SUPPLY_STATUS_FULL"
    ),
    "battery_health != POWER_SUPPLY_HEALTH_OVERHEAT \\\n|| current_anim_id == ERROR_ANIM_ID",
    (
        "battery_percent_round == charging_anim_percent \\\n&& current_anim_id == "
        "CHARGING_BATTERY_ANIM_ID"
    ),
    "charging_anim_percent = battery_percent_round; \\\ncurrent_anim_id = CHARGING_BATTERY_ANIM_ID",
    (
        "battery_status != POWER_SUPPLY_STATUS_DISCHARGING \\\n&& battery_status != "
        "POWER_SUPPLY_STATUS_NOT_CHARGING"
    ),
    (
        "battery_percent < CRITICAL_BATTERY_THRESHOLD_PERCENT \\\n|| battery_percent >= "
        "LOW_BATTERY_THRESHOLD_PERCENT"
    ),
    "battery_status != POWER_SUPPLY_STATUS_UNKNOWN \\\n|| current_anim_id == ERROR_ANIM_ID",
    "cpu_temp <= CPU_FAN_ON_TEMP \\\n&& driver_temp <= DRIVER_FAN_ON_TEMP",
    (
        "cpu_temp > CPU_FAN_OFF_TEMP \\\n|| driver_temp > DRIVER_FAN_OFF_TEMP \\\n|| "
        "battery_health == POWER_SUPPLY_HEALTH_OVERHEAT \\\n|| (!fan_state)"
    ),
]

# Real scripts that BehaviorTree.CPP 4.0-4.9 (lexy grammar) accepted but 4.10 rejects:
# a double-quoted string (MoveIt Pro) and backslash line continuations (Panther).
# (REAL_LEGACY_SCRIPTS above.)

_SYNTHETIC_VALID = [
    "x:= 3; y:=5; x+y",
    "x+=1",
    "x -= 1",
    "x*=2; x/=2",
    "-x",
    "y & x",
    "y | x",
    "y ^ x",
    "~y",
    "A:='hello'; B:=' '; C:='world'; A+B+C",
    "A= '   right'; B= ' center '; C= 'left    '  ",
    " 'hello' = 'world' ",  # parses; fails only when run
    " 3.0 = 2.0 ",
    "x < y",
    "y == x ? 'T' : 'F'",
    "v1:= true; v2:= false",
    " v2 = !false ",
    "v1 && v2 || !v1",
    "(y == x) && (x == 3)",
    " y == x  &&  x == 3 ",
    "a < b < c",
    "a == b != c",
    "A:=THE_ANSWER; color1:=RED; color2:=BLUE; color3:=GREEN",
    " deviceA:=BATT; deviceB:=CONTROLLER; battery_level:=30 ",
    "find_enemy==0",
    "A:=5;\nB:=6",
    "A>-B && color != BLUE",
    "msg := 'value: ' .. 42",
    "a..b..c",
    "65..x",
    "x := 0x1F + 0XaB",
    "x := 1e3 + 1E-3 + 2.5e+2 + 3.14",
    "x := 007",
    "@root_key := @other + 1",
    "@",
    "_private := 1",
    "x := 'it''s'",  # two adjacent strings are two operands... see invalid list
    "c ? a : b ? d : e",
    "c ? (a ? b : d) : e",
    "x := c ? 1 : 2",
    "((((a))))",
    "--a",
    "!!a",
    "-!~a",
    "a+-b",
    "a = b = c",
    "a;",
    "a;;;b;;",
    "\t a \r\n ; \n b",
    "x := 'multi\nline ; string ? : )'",
    "x := ''",
    "x := 'ünïcödé ✓'",
    "true",
    "false",
    "1",
    "x:=1;y:=2;z:=x*y/2-1",
]
# "x := 'it''s'" is two string operands in a row: not valid. Keep the list honest.
_SYNTHETIC_VALID.remove("x := 'it''s'")


@pytest.mark.parametrize("code", REAL_SCRIPTS)
def test_real_scripts_parse(code: str) -> None:
    assert check_script(code) is None


@pytest.mark.parametrize("code", REAL_SCRIPTS)
def test_real_scripts_parse_in_legacy_mode(code: str) -> None:
    assert check_script(code, legacy=True) is None


@pytest.mark.parametrize("code", REAL_LEGACY_SCRIPTS)
def test_real_legacy_scripts(code: str) -> None:
    error = check_script(code)
    assert error is not None
    assert code[error.offset] in '"\\'
    assert check_script(code, legacy=True) is None


@pytest.mark.parametrize("code", _SYNTHETIC_VALID)
def test_valid(code: str) -> None:
    assert check_script(code) is None


# (script, offset, end, message)
_INVALID: list[tuple[str, int, int, str]] = [
    ("a == == b", 5, 7, "Expected operand at position 5 (got '==')"),
    ("x := ", 5, 5, "Expected operand at position 5 (got end of input)"),
    ("x :=", 4, 4, "Expected operand at position 4 (got end of input)"),
    ("", 0, 0, "Empty Script"),
    ("   \n ", 0, 5, "Empty Script"),
    (";", 0, 1, "Expected operand at position 0 (got ';')"),
    ("; a", 0, 1, "Expected operand at position 0 (got ';')"),
    ("a := ;", 5, 6, "Expected operand at position 5 (got ';')"),
    ("a * / b", 4, 5, "Expected operand at position 4 (got '/')"),
    ("+a", 0, 1, "Expected operand at position 0 (got '+')"),
    ("a + )", 4, 5, "Expected operand at position 4 (got ')')"),
    ("()", 1, 2, "Expected operand at position 1 (got ')')"),
    ("a ? : b", 4, 5, "Expected operand at position 4 (got ':')"),
    ("a b", 2, 3, "Expected ';' or end of script at position 2 (got 'b')"),
    ("x:=1 y:=2", 5, 6, "Expected ';' or end of script at position 5 (got 'y')"),
    ("a and b", 2, 5, "Expected ';' or end of script at position 2 (got 'and'); use '&&' instead"),
    ("a or b", 2, 4, "Expected ';' or end of script at position 2 (got 'or'); use '||' instead"),
    ("f(x)", 1, 2, "Expected ';' or end of script at position 1 (got '(')"),
    ("a !b", 2, 3, "Expected ';' or end of script at position 2 (got '!')"),
    ("1 2", 2, 3, "Expected ';' or end of script at position 2 (got '2')"),
    ("'a' 'b'", 4, 7, "Expected ';' or end of script at position 4 (got ''b'')"),
    ("a : b", 2, 3, "Expected ';' or end of script at position 2 (got ':')"),
    ("@@x", 1, 3, "Expected ';' or end of script at position 1 (got '@x')"),
    ("a)", 1, 2, "Unmatched ')' at position 1"),
    (
        "(a",
        2,
        2,
        "Expected ')' at position 2 (got end of input); '(' at position 0 is not closed",
    ),
    (
        "(a; b)",
        2,
        3,
        "Expected ')' at position 2 (got ';'); '(' at position 0 is not closed",
    ),
    (
        "x := (a b)",
        8,
        9,
        "Expected ')' at position 8 (got 'b'); '(' at position 5 is not closed",
    ),
    (
        "a ? (b : c)",
        7,
        8,
        "Expected ')' at position 7 (got ':'); '(' at position 4 is not closed",
    ),
    (
        "a ? b",
        5,
        5,
        "Expected ':' at position 5 (got end of input); '?' at position 2 has no ':'",
    ),
    (
        "(a ? b) : c",
        6,
        7,
        "Expected ':' at position 6 (got ')'); '?' at position 3 has no ':'",
    ),
    (
        "a ? b; c",
        5,
        6,
        "Expected ':' at position 5 (got ';'); '?' at position 2 has no ':'",
    ),
    (
        "a ? b c",
        6,
        7,
        "Expected ':' at position 6 (got 'c'); '?' at position 2 has no ':'",
    ),
    (  # ':=' is one token (an assignment inside the "then" branch), not ':' then '='
        "a ? b := c",
        10,
        10,
        "Expected ':' at position 10 (got end of input); '?' at position 2 has no ':'",
    ),
    # Lexical errors
    (
        'x := "abc"',
        5,
        6,
        "Invalid character '\"' at position 5; strings are written in single quotes",
    ),
    ("x := 'abc", 5, 9, "Unterminated string at position 5"),
    ("x := '", 5, 6, "Unterminated string at position 5"),
    ("3foo", 0, 4, "Invalid number '3foo' at position 0"),
    ("x := 65.", 5, 8, "Invalid number '65.' at position 5"),
    ("x := 65.x + 1", 5, 9, "Invalid number '65.x' at position 5"),
    ("x := 0x", 5, 7, "Invalid number '0x' at position 5"),
    ("x := 0xFG", 5, 9, "Invalid number '0xFG' at position 5"),
    ("x := 0x1.5", 5, 10, "Invalid number '0x1.5' at position 5"),
    ("x := 1e", 5, 7, "Invalid number '1e' at position 5"),
    ("x := 1e+", 5, 8, "Invalid number '1e+' at position 5"),
    ("x := 2.5e3y", 5, 11, "Invalid number '2.5e3y' at position 5"),
    ("x := 3_000", 5, 10, "Invalid number '3_000' at position 5"),
    ("x := 1.2.3", 8, 9, "Invalid character '.' at position 8; write a number as 0.5, not .5"),
    ("x := .5", 5, 6, "Invalid character '.' at position 5; write a number as 0.5, not .5"),
    ("a.b", 1, 2, "Invalid character '.' at position 1"),
    ("x % 2", 2, 3, "Invalid character '%' at position 2"),
    ("a, b", 1, 2, "Invalid character ',' at position 1"),
    (
        "a == b \\\n|| c",
        7,
        8,
        "Invalid character '\\' at position 7; "
        "a backslash line continuation is not needed, remove it",
    ),
    ("x := a[0]", 6, 7, "Invalid character '[' at position 6"),
    ("{key} == 1", 0, 1, "Invalid character '{' at position 0"),
    ("x := $y", 5, 6, "Invalid character '$' at position 5"),
    ("a\x07", 1, 2, "Invalid character U+0007 at position 1"),
    ("a\u00a0== b", 1, 2, "Invalid character U+00A0 at position 1"),
    # Positions are BehaviorTree.CPP's UTF-8 byte offsets; offsets are code points.
    ("x := 'é' ==", 11, 11, "Expected operand at position 12 (got end of input)"),
    ("é := 1", 0, 1, "Invalid character 'é' at position 0"),
    ("ab\u00e9 := 1", 2, 3, "Invalid character 'é' at position 2"),
    ("x := '✓✓' +", 11, 11, "Expected operand at position 15 (got end of input)"),
    # The first error wins, lexical or syntactic.
    ("a == ; 3foo", 5, 6, "Expected operand at position 5 (got ';')"),
    ("3foo == ;", 0, 4, "Invalid number '3foo' at position 0"),
]


@pytest.mark.parametrize(("code", "offset", "end", "message"), _INVALID)
def test_invalid(code: str, offset: int, end: int, message: str) -> None:
    assert check_script(code) == ScriptError(offset, end, message)


def test_long_token_is_shortened_in_message() -> None:
    error = check_script("a 'a very long string literal that goes on'")
    assert error is not None
    assert error.message.endswith("(got ''a very long string l...')")
    assert (error.offset, error.end) == (2, 43)


def test_line_breaks_in_shown_token_are_escaped() -> None:
    error = check_script("a 'x\ny'")
    assert error is not None
    assert error.message == "Expected ';' or end of script at position 2 (got ''x\\ny'')"


def test_legacy_mode() -> None:
    assert check_script('x := "abc"', legacy=True) is None
    assert check_script("größe := 1; x := größe", legacy=True) is None
    assert check_script("a \\\n&& b", legacy=True) is None
    assert check_script("a \\\r\n&& b", legacy=True) is None
    assert check_script("a \\ && b", legacy=True) is None  # LF normalized to a space
    error = check_script("a \\", legacy=True)
    assert error is not None and error.offset == 2
    error = check_script('x := "abc', legacy=True)
    assert error == ScriptError(5, 9, "Unterminated string at position 5")


def test_error_is_frozen() -> None:
    error = check_script("a ==")
    assert error is not None
    with pytest.raises(AttributeError):
        error.offset = 3  # type: ignore[misc]


def test_deep_nesting_is_fine() -> None:
    depth = 20_000
    assert check_script("(" * depth + "a" + ")" * depth) is None
    assert check_script("!" * depth + "a") is None
    assert check_script("a" + " = a" * depth) is None
    assert check_script("c ? " * depth + "a" + " : b" * depth) is None
    error = check_script("(" * depth + "a" + ")" * (depth - 1))
    assert error is not None and error.offset == error.end == 2 * depth


def test_linear_time() -> None:
    unit = "x := (a + 0x1F) * 2.5e3 .. 'str' ? y : z; "
    small, large = unit * 1_000, unit * 10_000
    started = time.perf_counter()
    assert check_script(small) is None
    small_time = time.perf_counter() - started
    started = time.perf_counter()
    assert check_script(large) is None
    large_time = time.perf_counter() - started
    assert large_time < max(2.0, small_time * 30)


_ALPHABET = st.sampled_from(
    [*"abxyz_@019eE.'\"()?:;=!<>+-*/&|^~%, \t\n\\{}é✓", "==", ":=", "&&", "..", "0x", "\x00"]
)


@settings(max_examples=400, deadline=None)
@given(st.text())
def test_never_raises_on_any_text(code: str) -> None:
    for legacy in (False, True):
        result = _Checker(code, legacy).run()  # bypass the defensive wrapper
        if result is not None:
            assert 0 <= result.offset <= result.end <= len(code)
            assert result.message


@settings(max_examples=600, deadline=None)
@given(st.lists(_ALPHABET, max_size=40).map("".join))
def test_never_raises_on_script_like_text(code: str) -> None:
    for legacy in (False, True):
        result = _Checker(code, legacy).run()
        if result is not None:
            assert 0 <= result.offset <= result.end <= len(code)
            assert "position" in result.message or result.message == "Empty Script"


def _until_end(tokens: Iterator[tuple[object, ...]]) -> list[tuple[object, ...]]:
    out = []
    for token in tokens:
        out.append(token)
        if token[0] in (_EOF, _ERROR):
            return out
    raise AssertionError("unreachable")  # pragma: no cover


_SCRIPT_TEXT = st.one_of(
    st.lists(_ALPHABET, max_size=40).map("".join),
    st.lists(
        st.sampled_from(_SYNTHETIC_VALID + REAL_SCRIPTS[:40] + [";", " ", "("]), max_size=6
    ).map(" ".join),
    st.text(max_size=30),
)


@settings(max_examples=1500, deadline=None)
@given(_SCRIPT_TEXT)
def test_regex_tokens_are_the_character_loops(code: str) -> None:
    """The fast tokenizer (one regular expression, the character loop for the rest) reads
    exactly the tokens the character loop alone reads, in both modes."""
    for legacy in (False, True):
        checker = _Checker(code, legacy)
        assert _until_end(checker.tokens()) == _until_end(checker.slow_tokens())


@settings(max_examples=1500, deadline=None)
@given(_SCRIPT_TEXT)
def test_plain_script_pattern_accepts_only_what_parses(code: str) -> None:
    """What the regular expression accepts without the checker parses, and
    check_script's answer is always the checker's."""
    if _PLAIN_SCRIPT.fullmatch(code):
        assert _Checker(code, False).run() is None
        assert _Checker(code, True).run() is None
    for legacy in (False, True):
        assert check_script(code, legacy=legacy) == _Checker(code, legacy).run()


def _identifiers_by_tokens(code: str) -> tuple[list[tuple[int, int]], int]:
    """identifiers() as the tokens read it, without the regular expressions' shortcut."""
    found: list[tuple[int, int]] = []
    for token in _Checker(code, True).tokens():
        if token[0] == _IDENT and code[token[1] : token[2]] not in ("true", "false"):
            found.append((token[1], token[2]))
        elif token[0] == _EOF:
            return found, len(code)
        elif token[0] == _ERROR:
            return found, token[1]
    raise AssertionError("unreachable")  # pragma: no cover


@settings(max_examples=1500, deadline=None)
@given(_SCRIPT_TEXT)
def test_identifiers_shortcut_is_the_tokens(code: str) -> None:
    """Where the whole script is fast-pattern tokens, identifiers() reads the names with
    one regular expression: the same spans the tokens give."""
    assert identifiers(code) == _identifiers_by_tokens(code)


def test_identifiers_of_a_large_script() -> None:
    code = "".join(f"k{i} := k{i} + 0x1F * 2.5e3 .. 'x y' .. \"q\"; " for i in range(5_000))
    assert _LEGACY_TOKENS.fullmatch(code)
    spans, stop = identifiers(code)
    assert stop == len(code)
    assert [code[s:e] for s, e in spans][:4] == ["k0", "k0", "k1", "k1"]
    assert len(spans) == 10_000 and (spans, stop) == _identifiers_by_tokens(code)


@settings(max_examples=1500, deadline=None)
@given(_SCRIPT_TEXT, st.sampled_from(["a", "b", "k1", "@a", "true", "x_y", "é", "1e5"]))
def test_identifier_spans_are_the_identifiers_of_one_word(code: str, extra: str) -> None:
    """identifier_spans(code, word) is identifiers() filtered by word, for the words of
    the script and others, whether the shortcut applies or the checker reads it."""
    spans, stop = identifiers(code)
    for word in {code[s:e] for s, e in spans} | {extra}:
        expected = tuple((s, e) for s, e in spans if code[s:e] == word)
        assert identifier_spans(code, word) == (expected, stop), word


def test_identifier_spans_of_a_large_script() -> None:
    code = "".join(f"k{i} := k{i}0 + 'k7' .. k7_ .. @k7; " for i in range(100_000))
    found, stop = identifier_spans(code, "k7")
    assert stop == len(code) and [code[s:e] for s, e in found] == ["k7"]
    assert found[0][0] == code.index("k7 :=")
    assert identifier_spans(code, "@k7")[0] == tuple(
        (s, e) for s, e in identifiers(code)[0] if code[s:e] == "@k7"
    )


def test_plain_script_pattern_takes_the_common_scripts() -> None:
    plain = [c for c in REAL_SCRIPTS if not any(ch in c for ch in "()?") and ": " not in c]
    assert len(plain) > 30
    for code in plain:
        assert _PLAIN_SCRIPT.fullmatch(code), code
    assert not _PLAIN_SCRIPT.fullmatch("a ? b : c")
    assert not _PLAIN_SCRIPT.fullmatch("(a)")
    assert not _PLAIN_SCRIPT.fullmatch("a and b")
    assert not _PLAIN_SCRIPT.fullmatch(";a")
    assert not _PLAIN_SCRIPT.fullmatch("")


def test_a_large_script_with_an_error_at_its_end() -> None:
    code = "".join(f"k{i} := k{i} + 1; " for i in range(20_000)) + "x := == 1"
    error = check_script(code)
    assert error is not None
    assert (error.offset, error.end) == (len(code) - 4, len(code) - 2)
    assert error.message == f"Expected operand at position {len(code) - 4} (got '==')"
    spans, stop = identifiers(code)
    assert len(spans) == 40_001 and stop == len(code)


@settings(max_examples=200, deadline=None)
@given(st.lists(st.sampled_from(_SYNTHETIC_VALID + REAL_SCRIPTS[:40]), min_size=1, max_size=6))
def test_valid_statements_joined_by_semicolons(parts: list[str]) -> None:
    assert check_script(";".join(parts)) is None
    assert check_script("; ".join(parts) + ";") is None


@settings(max_examples=200, deadline=None)
@given(st.sampled_from(REAL_SCRIPTS), st.sampled_from(["(", "?", "==", "'", ")"]))
def test_appending_a_dangling_token_is_an_error(code: str, suffix: str) -> None:
    error = check_script(code + " " + suffix)
    assert error is not None


# ---------------------------------------------------------------------------------------
# The corpus itself.

_CORPUS = Path(__file__).parent / "data" / "corpus_real"
_SCRIPT_ATTRIBUTES = frozenset(
    {
        "_skipIf",
        "_while",
        "_successIf",
        "_failureIf",
        "_onSuccess",
        "_onFailure",
        "_onHalted",
        "_post",
    }
)
_TAG = re.compile(r"<([A-Za-z_][\w.:-]*)((?:\s+[^\s=/>]+\s*=\s*(?:\"[^\"]*\"|'[^']*'))*)\s*/?>")
_ATTRIBUTE = re.compile(r"([^\s=/>]+)\s*=\s*(?:\"([^\"]*)\"|'([^']*)')")
_ENTITY = re.compile(r"&(#x[0-9a-fA-F]+|#[0-9]+|lt|gt|amp|apos|quot);")
_NAMED = {"lt": "<", "gt": ">", "amp": "&", "apos": "'", "quot": '"'}


def _decode(value: str) -> str:
    def one(match: re.Match[str]) -> str:
        name = match.group(1)
        if name.startswith("#x"):
            return chr(int(name[2:], 16))
        if name.startswith("#"):
            return chr(int(name[1:]))
        return _NAMED[name]

    return _ENTITY.sub(one, value)


def _corpus_scripts() -> list[str]:
    scripts: list[str] = []
    for path in sorted(_CORPUS.iterdir()):
        if not path.is_dir():
            continue
        for file in sorted(path.iterdir()):
            if file.suffix not in (".xml", ".btproj"):
                continue
            text = file.read_text(encoding="utf-8", errors="replace")
            for tag in _TAG.finditer(text):
                attributes = {
                    m.group(1): m.group(2) if m.group(2) is not None else m.group(3)
                    for m in _ATTRIBUTE.finditer(tag.group(2))
                }
                kind = tag.group(1)
                if kind in ("Action", "Condition", "Control", "Decorator"):
                    kind = attributes.get("ID", kind)
                for name, value in attributes.items():
                    if (
                        name in _SCRIPT_ATTRIBUTES
                        or (name == "code" and kind in ("Script", "ScriptCondition"))
                        or (name == "if" and kind == "Precondition")
                    ):
                        scripts.append(_decode(value))
    return scripts


def test_every_corpus_script_is_listed_and_parses() -> None:
    found = _corpus_scripts()
    assert len(found) > 300
    assert set(found) == set(REAL_SCRIPTS) | set(REAL_LEGACY_SCRIPTS)
    for code in found:
        assert check_script(code, legacy=True) is None, code


@pytest.mark.parametrize(
    ("code", "names", "stop"),
    [
        ("a := b + 1; c = true || false", ["a", "b", "c"], None),
        ("x := 'key' .. key", ["x", "key"], None),
        ('"key" == k', ["k"], None),  # a double-quoted string (4.0-4.9) stays a string
        ("clé = 1", ["clé"], None),  # a non-ASCII letter does not split an identifier
        ("@root_key > 3 ? e1 : 0x1F", ["@root_key", "e1"], None),
        ("a + %b", ["a"], 4),  # the tokens after a lexical error are unknown
        ("x := 'open", ["x"], 5),
    ],
)
def test_identifiers(code: str, names: list[str], stop: int | None) -> None:
    spans, end = identifiers(code)
    assert [code[s:e] for s, e in spans] == names
    assert end == (len(code) if stop is None else stop)
