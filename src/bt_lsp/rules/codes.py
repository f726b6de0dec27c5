"""Every diagnostic code bt-lsp emits, with its default severity and README anchor.

This table is the single source for codes: the README's code table, the server's
``codeDescription`` links and the severity settings all read it. Codes are stable once
released.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import IntEnum

DOCS_URL = "https://github.com/bt-lsp/bt-lsp/blob/main/README.md"


class Severity(IntEnum):
    """Values match LSP's ``DiagnosticSeverity``."""

    ERROR = 1
    WARNING = 2
    INFORMATION = 3
    HINT = 4

    @property
    def label(self) -> str:
        return self.name.lower()

    @classmethod
    def parse(cls, word: str) -> Severity | None:
        """A severity word from the settings; ``None`` for ``'off'``."""
        word = word.strip().lower()
        if word == "info":
            word = "information"
        for member in cls:
            if member.label == word:
                return member
        if word == "off":
            return None
        raise ValueError(f"unknown severity {word!r}")


@dataclass(frozen=True, slots=True)
class Code:
    code: str
    severity: Severity
    summary: str
    family: str

    @property
    def url(self) -> str:
        return f"{DOCS_URL}#{self.code}"


_NAME = "names"
_XML = "xml"
_BT = "behaviortree"

CODES: dict[str, Code] = {
    c.code: c
    for c in (
        # Name rules (the contract's table).
        Code("model-name-empty", Severity.ERROR, "a model name is empty", _NAME),
        Code("model-name-reserved", Severity.ERROR, "a model name is `Root` or `root`", _NAME),
        Code(
            "model-name-forbidden-char",
            Severity.ERROR,
            "a model name contains a forbidden character",
            _NAME,
        ),
        Code("port-name-empty", Severity.ERROR, "a port name is empty", _NAME),
        Code(
            "port-name-leading-digit",
            Severity.ERROR,
            "a port name starts with an ASCII digit",
            _NAME,
        ),
        Code(
            "port-name-reserved",
            Severity.ERROR,
            "a port declared in `<TreeNodesModel>` uses a reserved attribute name",
            _NAME,
        ),
        Code(
            "port-name-forbidden-char",
            Severity.ERROR,
            "a port name contains a forbidden character",
            _NAME,
        ),
        Code(
            "instance-name-control-char",
            Severity.ERROR,
            "an instance name contains a control character",
            _NAME,
        ),
        # XML well-formedness.
        Code("xml-syntax", Severity.ERROR, "the document is not well-formed XML", _XML),
        Code(
            "xml-unescaped-char",
            Severity.WARNING,
            "a raw `&` or `<` in an attribute value (tinyxml2 accepts it, XML does not)",
            _XML,
        ),
        Code(
            "xml-doctype",
            Severity.WARNING,
            "a DOCTYPE; its entities and external DTDs are never expanded or fetched",
            _XML,
        ),
        # BehaviorTree.CPP semantics (bt_lsp.rules.semantics): one document plus its context.
        Code("root-element", Severity.ERROR, "the top element is not `<root>`", _BT),
        Code("missing-format", Severity.WARNING, "`<root>` has no `BTCPP_format`", _BT),
        Code(
            "missing-id",
            Severity.ERROR,
            "a `<BehaviorTree>`, explicit node, `<SubTree>` or model entry has no `ID`",
            _BT,
        ),
        Code("missing-port-name", Severity.ERROR, "a SubTree model port has no `name`", _BT),
        Code(
            "tree-child-count",
            Severity.ERROR,
            "a `<BehaviorTree>` does not have exactly one child element",
            _BT,
        ),
        Code("id-on-compact-node", Severity.ERROR, "`ID` on a node written in compact form", _BT),
        Code(
            "duplicate-model-section",
            Severity.ERROR,
            "a second `<TreeNodesModel>` section",
            _BT,
        ),
        Code("include-missing-path", Severity.ERROR, "an `<include>` without `path`", _BT),
        Code(
            "include-ros-pkg",
            Severity.WARNING,
            "an `<include ros_pkg>` whose package bt-lsp cannot resolve",
            _BT,
        ),
        Code(
            "no-main-tree",
            Severity.INFORMATION,
            "several trees and no `main_tree_to_execute`",
            _BT,
        ),
        Code("nesting-depth", Severity.ERROR, "a tree nested deeper than 256 levels", _BT),
        Code(
            "unknown-node",
            Severity.ERROR,
            "a node type that is neither built in nor declared (a hint unless a catalog "
            "of the custom nodes is configured)",
            _BT,
        ),
        Code("unknown-subtree", Severity.ERROR, "a `<SubTree ID>` that names no tree", _BT),
        Code(
            "unknown-main-tree",
            Severity.ERROR,
            "`main_tree_to_execute` names no tree",
            _BT,
        ),
        Code("duplicate-tree-id", Severity.WARNING, "two trees with the same `ID`", _BT),
        Code(
            "registered-name-as-tree-id",
            Severity.ERROR,
            "a tree ID that is the name of a registered node type",
            _BT,
        ),
        Code("subtree-recursion", Severity.ERROR, "trees that call each other in a cycle", _BT),
        Code(
            "duplicate-subtree-name",
            Severity.ERROR,
            "two `<SubTree>` calls with the same `name` in one tree",
            _BT,
        ),
        Code("child-count", Severity.ERROR, "a node with the wrong number of children", _BT),
        Code(
            "reactive-async-children",
            Severity.ERROR,
            "a `ReactiveSequence` with more than one `AsyncSequence` child",
            _BT,
        ),
        Code(
            "reactive-explicit-child",
            Severity.ERROR,
            "a `ReactiveSequence` child written in explicit form (`<Action ID=…>`)",
            _BT,
        ),
        Code(
            "parallel-threshold",
            Severity.ERROR,
            "a `Parallel` threshold larger than its number of children",
            _BT,
        ),
        Code(
            "undeclared-port", Severity.ERROR, "an attribute the node's model does not declare", _BT
        ),
        Code(
            "missing-required-port",
            Severity.ERROR,
            "a port without a default that is not given",
            _BT,
        ),
        Code(
            "invalid-port-value",
            Severity.ERROR,
            "a literal that does not convert to the port's type",
            _BT,
        ),
        Code(
            "blackboard-type-mismatch",
            Severity.ERROR,
            "one blackboard key used by ports of different types",
            _BT,
        ),
        Code("script-syntax", Severity.ERROR, "a script that does not parse", _BT),
        Code(
            "port-name-not-remappable",
            Severity.WARNING,
            "a port name that does not start with an ASCII letter, so XML cannot set it",
            _BT,
        ),
        Code(
            "unknown-attribute",
            Severity.WARNING,
            "an underscore attribute BehaviorTree.CPP silently ignores",
            _BT,
        ),
        Code(
            "document-too-large",
            Severity.INFORMATION,
            "analysis limited because the document is larger than the configured maximum",
            _XML,
        ),
        Code(
            "too-many-problems",
            Severity.INFORMATION,
            "more problems than a client can usefully show; only the first are reported",
            _XML,
        ),
        # Includes, resolved by the workspace layer.
        Code(
            "include-not-found",
            Severity.ERROR,
            "an included file does not exist or cannot be read",
            _BT,
        ),
        Code("include-cycle", Severity.ERROR, "files include each other in a cycle", _BT),
    )
}


def code_info(code: str) -> Code:
    return CODES[code]
