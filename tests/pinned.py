"""The codes that the whole-output tests were written against.

A whole-output test (a golden CLI output, a table of every code a document gets, a
fixture's "every finding is annotated") says what *all* the rules report on its text.  A
rule added later would change that output though the test is about something else: the
first one-line rule broke a dozen such tests.  So those tests see only the codes listed
here (and, for a fixture, the codes it annotates and the code it is named after):

* in-process, :func:`pinned` drops the diagnostics of the codes defined later;
* through the command line, :func:`main` (``bt_lsp.cli.main.main`` for the tests),
  :func:`later_off` and :func:`later_severities` turn them off as ``--severity CODE=off``
  does, so the summary line, JSON and SARIF are those of the pinned codes too.

A new code is tested by its own fixture and rule tests (CONTRIBUTING.md, "Add a rule");
the conformance test and the ecosystem check still see every code, since an error or a
warning on a file BehaviorTree.CPP loads is a false alarm whatever the rule.  To let the
whole-output tests see a new code, add it here and update the tests that then fail, in one
commit.  ``tests/test_pinned.py`` fails when a code listed here no longer exists.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from typing import Final, Protocol, TypeVar

from bt_lsp.rules.registry import CODES

#: The codes of the registry when the whole-output tests were written.
PINNED_CODES: Final = frozenset(
    {
        "blackboard-type-mismatch",
        "child-count",
        "config-error",
        "cpp-model-name",
        "cpp-port-name",
        "document-too-large",
        "duplicate-model-section",
        "duplicate-subtree-name",
        "duplicate-tree-id",
        "id-on-compact-node",
        "include-cycle",
        "include-missing-path",
        "include-not-found",
        "include-ros-pkg",
        "instance-name-control-char",
        "invalid-port-value",
        "missing-format",
        "missing-id",
        "missing-port-name",
        "missing-port-without-default",
        "missing-required-port",
        "model-name-empty",
        "model-name-forbidden-char",
        "model-name-reserved",
        "nesting-depth",
        "no-main-tree",
        "no-tree",
        "parallel-threshold",
        "port-name-empty",
        "port-name-forbidden-char",
        "port-name-groot1",
        "port-name-leading-digit",
        "port-name-not-remappable",
        "port-name-reserved",
        "port-name-reserved-groot2",
        "reactive-async-children",
        "reactive-explicit-child",
        "registered-name-as-tree-id",
        "root-element",
        "script-syntax",
        "subtree-recursion",
        "too-many-attributes",
        "too-many-problems",
        "tree-child-count",
        "undeclared-port",
        "unknown-attribute",
        "unknown-main-tree",
        "unknown-node",
        "unknown-subtree",
        "xml-doctype",
        "xml-extra-root",
        "xml-lenient",
        "xml-syntax",
        "xml-unescaped-char",
    }
)

#: The codes defined since: invisible to the whole-output tests.
LATER: Final = frozenset(CODES) - PINNED_CODES


class _Coded(Protocol):
    @property
    def code(self) -> str: ...


D = TypeVar("D", bound=_Coded)


def pinned(found: Iterable[D], also: Iterable[str] = ()) -> list[D]:
    """``found`` without the diagnostics of codes defined later (but those of ``also``,
    the codes a test is about).  Where some were dropped, so is ``too-many-problems``: the
    cap counted them (the pinned diagnostics it kept are still all there, errors first)."""
    hidden = LATER - set(also)
    found = list(found)
    kept = [d for d in found if d.code not in hidden]
    if len(kept) < len(found):
        kept = [d for d in kept if d.code != "too-many-problems" or "too-many-problems" in also]
    return kept


def later_off(also: Iterable[str] = ()) -> list[str]:
    """The ``bt-lsp check`` options that turn off the codes defined later (but ``also``)."""
    hidden = sorted(LATER - set(also))
    return ["--severity", ",".join(f"{c}=off" for c in hidden)] if hidden else []


def later_severities() -> dict[str, None]:
    """The ``severities`` of ``check.Options`` that turn off the codes defined later."""
    return dict.fromkeys(sorted(LATER))


def main(argv: Sequence[str]) -> int:
    """``bt-lsp`` as the whole-output tests know it: ``check`` without the codes defined
    later (every other command as it is)."""
    from bt_lsp.cli.main import main as cli  # the command line only where it is run

    if argv and argv[0] == "check":
        return cli([*argv, *later_off()])
    return cli(argv)
