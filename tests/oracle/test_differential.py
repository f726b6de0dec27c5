"""bt-lsp against BehaviorTree.CPP itself (4.8.2, through ``behaviortreepy``).

For every generated document (:mod:`tests.oracle.strategies`): BehaviorTree.CPP throws at
load or creation (or a built-in throws at tick, or the library crashes) if and only if
bt-lsp reports an error, and one of bt-lsp's errors has a code that names the library's
cause (:data:`CAUSES` maps its messages to codes).  A disagreement that is a known
difference (``known.tsv``: the shape, what 4.8.2 does, what 4.10 does, what bt-lsp does
and why) is skipped by its shape.

A fixed seed and 2,000 documents by default; ``BT_LSP_ORACLE_EXAMPLES=N`` runs N.  A
failing document is shrunk and printed as XML, with both verdicts.
"""

from __future__ import annotations

import csv
import os
import re
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any, Final

import pytest
from hypothesis import HealthCheck, Phase, given, seed, settings

from tests.oracle.adapter import Case, Oracle, Verdict
from tests.oracle.btlsp import NAME_CODES, Workspace
from tests.oracle.strategies import Generated, documents

HERE = Path(__file__).parent
EXAMPLES: Final = int(os.environ.get("BT_LSP_ORACLE_EXAMPLES", "2000"))

# BehaviorTree.CPP's messages -> the bt-lsp codes that name the same cause.
CAUSES: Final[tuple[tuple[re.Pattern[str], frozenset[str]], ...]] = tuple(
    (re.compile(pattern, re.S), frozenset(codes.split()))
    for pattern, codes in (
        (r"Node not recognized|Unknown node type", "unknown-node reactive-explicit-child"),
        (r"The tag <BehaviorTree> must have the attribute \[ID\]", "missing-id"),
        (r"^\[\w+\] not found", "missing-required-port"),
        (r"invalid bool conversion", "invalid-port-value"),
        (r"was initially created with type", "blackboard-type-mismatch"),
        (r"The tag <BehaviorTree> with ID .* must have exactly 1 child", "tree-child-count"),
        (r"The node '.*' must (have|not have)", "child-count"),
        (r"Wrong number of children", "child-count"),  # SwitchN, at its first tick
        (r"The tag <SubTree> must have the attribute \[ID\]", "missing-id"),
        (r"Can't find a tree with name", "unknown-subtree unknown-main-tree"),
        (r"XML_ERROR_FILE_NOT_FOUND", "include-not-found"),
        (r"Error parsing the XML", "xml-syntax"),
        (r"is found in the XML .* but not in the providedPorts", "undeclared-port"),
        (r"can not be converted to", "invalid-port-value"),
        (r"Error in the script|Error in script|while parsing|bad_function_call", "script-syntax"),
        # A value that does not convert is "Missing parameter" to some built-ins.
        (
            r"Missing port|Missing parameter|missing port|missing input port",
            "missing-required-port invalid-port-value",
        ),
        (r"threshold", "parallel-threshold"),
        (r"the worker died|no answer within", "subtree-recursion"),
    )
)
# Failures at tick that depend on what the blackboard holds when the tree runs, which no
# static check can know: accepted without a bt-lsp error.
BLACKBOARD_AT_TICK: Final = re.compile(
    r"Variable not found|is not initialized|doesn't exist, yet|Any::cast failed"
    r"|Can't find the port referred by|Error assigning a value to entry"
    r"|Any failed string to number conversion"
)
# "Missing parameter [p]" at tick is the blackboard's doing when p is given a reference.
MISSING_AT_TICK: Final = re.compile(
    r"(?:Missing parameter|missing (?:input )?port) \[(?P<port>[^\]]+)\]"
)


@dataclass(frozen=True, slots=True)
class Known:
    """One row of known.tsv: a difference between bt-lsp and BehaviorTree.CPP 4.8.2."""

    shape: str
    stage: str  # the library's stage, or "ok" (it accepts; bt-lsp reports ``bt_lsp``)
    message: re.Pattern[str]  # matches the library's message
    document: re.Pattern[str]  # matches the document's text
    bt_lsp: str  # what bt-lsp reports: "none", "warning" (the cause's code, as a warning),
    # or (stage "ok") the code of the error it reports
    btcpp_4_8_2: str
    btcpp_4_10: str
    why: str


def known_shapes() -> list[Known]:
    with (HERE / "known.tsv").open(encoding="utf-8", newline="") as fh:
        rows = list(csv.DictReader(fh, delimiter="\t"))
    return [
        Known(
            r["shape"],
            r["stage"],
            re.compile(r["match"], re.S),
            re.compile(r["document"], re.S),
            r["bt_lsp"],
            r["btcpp_4_8_2"],
            r["btcpp_4_10"],
            r["why"],
        )
        for r in rows
    ]


KNOWN: Final = known_shapes()


def causes(message: str) -> frozenset[str]:
    """The codes that name the cause of the library's ``message``."""
    out: set[str] = set()
    for pattern, codes in CAUSES:
        if pattern.search(message):
            out |= codes
    return frozenset(out)


def _texts(g: Generated) -> str:
    return "\n".join(text for _, text in g.case.files)


def _at_tick(d: dict[str, Any]) -> bool:
    """Whether a bt-lsp error is one that BehaviorTree.CPP throws only when the node
    ticks: a Parallel/ParallelAll threshold, a built-in's missing port, SwitchN's
    children ("Wrong number of children"), a bad literal of an enum port, an empty
    ScriptCondition or Precondition code."""
    return (
        d["code"] in ("parallel-threshold", "missing-required-port")
        or (d["code"] == "child-count" and "cases + default" in d["message"])
        or (d["code"] == "invalid-port-value" and "only when the node reads it" in d["message"])
        or (d["code"] == "script-syntax" and "fails when it ticks" in d["message"])
    )


def disagreement(g: Generated, verdict: Verdict, diags: Sequence[dict[str, Any]]) -> str | None:
    """Why bt-lsp and the library disagree on ``g``, or ``None``."""
    errors = [d for d in diags if d["severity"] == "error"]
    if g.bad_names:  # bt-lsp's name rules are the reference for these names, not 4.8.2
        errors = [d for d in errors if d["code"] not in NAME_CODES]
    codes = {d["code"] for d in errors}
    if verdict.ok:
        return f"the library accepts it, bt-lsp reports {sorted(codes)}" if codes else None
    wanted = causes(verdict.message)
    if verdict.stage == "tick" and all(_at_tick(d) for d in errors):
        # The blackboard failed a tick first: bt-lsp's errors, if any, are of a later tick.
        if BLACKBOARD_AT_TICK.search(verdict.message):
            return None
        m = MISSING_AT_TICK.search(verdict.message)
        # (given a {key}, or "=": the key named like the port)
        if m is not None and re.search(rf'\b{re.escape(m["port"])}="(?:\s*\{{|=")', _texts(g)):
            return None
    if verdict.stage == "crash" and not codes and BLACKBOARD_AT_TICK.search(verdict.message):
        return None  # a script of _onHalted threw while halting: std::terminate
    if not wanted:
        return f"no code is mapped to the library's message (bt-lsp reports {sorted(codes)})"
    if codes & wanted:
        return None
    return f"the library throws ({'/'.join(sorted(wanted))}), bt-lsp reports {sorted(codes)}"


def known_shape(g: Generated, verdict: Verdict, diags: Sequence[dict[str, Any]]) -> Known | None:
    """The known difference that explains a disagreement on ``g``, if one does."""
    errors = {d["code"] for d in diags if d["severity"] == "error"}
    warnings = {d["code"] for d in diags if d["severity"] == "warning"}
    text = _texts(g)
    for k in KNOWN:
        if not k.document.search(text):
            continue
        if verdict.ok:
            if k.stage == "ok" and k.bt_lsp in errors:
                return k
            continue
        if k.stage not in (verdict.stage, "*") or not k.message.search(verdict.message):
            continue
        if k.bt_lsp == "none" or (k.bt_lsp == "warning" and warnings & causes(verdict.message)):
            return k
    return None


def describe(g: Generated, verdict: Verdict, diags: Sequence[dict[str, Any]]) -> str:
    lines = [f"--- {name}\n{text}" for name, text in g.case.files]
    lines.append(f"registered actions {list(g.case.actions)}, conditions {list(g.case.conditions)}")
    lines.append(f"BehaviorTree.CPP 4.8.2: {verdict}")
    lines += [f"bt-lsp: {d['severity']} {d['code']} {d['file']}: {d['message']}" for d in diags]
    return "\n".join(lines)


_ON_HALTED: Final = re.compile(r'\s_onHalted="[^"]*"')


def halting_crash(oracle: Oracle, case: Case, verdict: Verdict) -> Verdict:
    """What the library threw when the worker then crashed halting nodes: a script of
    ``_onHalted`` that throws while nodes are halted (after a tick threw, or destroyed
    when the creation of a tree failed) calls std::terminate.  The case without its
    ``_onHalted`` scripts says what was thrown first."""
    if verdict.stage != "crash" or not BLACKBOARD_AT_TICK.search(verdict.message):
        return verdict
    files = tuple((name, _ON_HALTED.sub("", text)) for name, text in case.files)
    if files == case.files:
        return verdict
    calm = oracle.run(replace(case, files=files))
    return calm if calm.stage in ("load", "create", "tick") else verdict


@pytest.fixture(scope="module")
def oracle() -> Iterator[Oracle]:
    with Oracle() as o:
        yield o


@pytest.fixture(scope="module")
def workspace() -> Iterator[Workspace]:
    # A memory-backed folder where there is one: the cases are written and removed there.
    with Workspace("/dev/shm" if os.access("/dev/shm", os.W_OK) else None) as ws:
        yield ws


def test_bt_lsp_agrees_with_behaviortree_cpp(oracle: Oracle, workspace: Workspace) -> None:
    @seed(20250704)
    @settings(
        max_examples=EXAMPLES,
        deadline=None,
        database=None,
        derandomize=False,
        phases=[Phase.generate, Phase.shrink],
        suppress_health_check=list(HealthCheck),
        print_blob=False,
    )
    @given(documents())
    def agree(g: Generated) -> None:
        oracle.submit(g.case)  # the library works while bt-lsp does
        diags = workspace.check(g.case.files, g.case.actions, g.case.conditions)
        verdict = halting_crash(oracle, g.case, oracle.result())
        why = disagreement(g, verdict, diags)
        if why is None or known_shape(g, verdict, diags) is not None:
            return
        raise AssertionError(f"{why}\n{describe(g, verdict, diags)}")

    agree()


def test_known_shapes_say_what_each_side_does() -> None:
    for k in KNOWN:
        assert k.stage in ("ok", "load", "create", "tick", "crash", "timeout", "*"), k.shape
        assert k.btcpp_4_8_2 and k.btcpp_4_10 and k.why, k.shape
        assert k.bt_lsp in ("none", "warning") or k.stage == "ok", k.shape
