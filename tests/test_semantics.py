"""BehaviorTree.CPP's semantic rules, one marked fixture per case.

Each case is an XML text with ``⟦…⟧`` around every expected diagnostic and the list of
expected (code, severity) pairs in the order of the marks; the check must report exactly
these, nothing more (of the codes these cases were written against, :mod:`tests.pinned`,
and of the codes a case expects).  The rows of bt-xml.md §f that can be checked
statically are all here (named after the row), plus every code of
:mod:`bt_lsp.rules.semantics`.
"""

from __future__ import annotations

from collections.abc import Collection
from pathlib import Path

import pytest

from bt_lsp.rules import semantics
from bt_lsp.rules.analysis import analyze
from bt_lsp.rules.codes import Severity
from bt_lsp.rules.context import Context
from bt_lsp.rules.registry import CODES
from bt_lsp.syntax.document import Document
from tests.marks import unmark
from tests.pinned import pinned

E, W, INFO, H = Severity.ERROR, Severity.WARNING, Severity.INFORMATION, Severity.HINT

Expected = list[tuple[str, Severity]]


def R(children: str, root: str = 'BTCPP_format="4"') -> str:
    """A document with these children of <root>."""
    return f"<root {root}>\n{children}\n</root>\n" if root else f"<root>\n{children}\n</root>\n"


def T(body: str, root: str = 'BTCPP_format="4"') -> str:
    """A document with one tree ``Main`` whose body is ``body``."""
    return R(f'<BehaviorTree ID="Main">\n{body}\n</BehaviorTree>', root)


MODELS = """<TreeNodesModel>
  <Action ID="Say"><input_port name="text" type="std::string"/></Action>
  <Action ID="Count"><input_port name="n" type="int"/><input_port name="opt" default="1"/>
    <output_port name="out" type="double"/></Action>
  <Decorator ID="Guard"/>
  <Control ID="Switcher"/>
  <SubTree ID="Dock"><input_port name="target"/><input_port name="speed" default="0.3"/>
    <output_port name="result" default=""/></SubTree>
</TreeNodesModel>"""
DOCK = '<BehaviorTree ID="Dock"><AlwaysSuccess/></BehaviorTree>'


def TM(body: str) -> str:
    """A tree ``Main`` with ``body``, the tree ``Dock`` and the models above."""
    return R(f'<BehaviorTree ID="Main">\n{body}\n</BehaviorTree>\n{DOCK}\n{MODELS}').replace(
        "<root ", '<root main_tree_to_execute="Main" ', 1
    )


CASES: list[tuple[str, str, Expected]] = [
    # --- §f Document level -----------------------------------------------------------------
    ("clean", T("<Sequence><AlwaysSuccess/></Sequence>"), []),
    (
        "top element not <root>",
        '<⟦BehaviorTree⟧ ID="Main"><AlwaysSuccess/></BehaviorTree>',
        [("root-element", E)],
    ),
    ("empty document", "⟦⟧", [("root-element", E)]),
    (
        "no BTCPP_format",
        T("<AlwaysSuccess/>", root="").replace("<root>", "<⟦root⟧>"),
        [("missing-format", H)],  # the version is not known: a hint
    ),
    (
        "two <TreeNodesModel>",
        R(
            '<BehaviorTree ID="Main"><AlwaysSuccess/></BehaviorTree>\n'
            "<TreeNodesModel/>\n<⟦TreeNodesModel⟧/>"
        ),
        [("duplicate-model-section", E)],
    ),
    (
        "<Action> under <root> without ID while a TreeNodesModel exists",
        R(
            '<BehaviorTree ID="Main"><AlwaysSuccess/></BehaviorTree>\n<⟦Action⟧/>\n'
            "<TreeNodesModel/>"
        ),
        [("missing-id", E)],
    ),
    (
        "<Action> under <root> without ID, no TreeNodesModel: ignored",
        R('<BehaviorTree ID="Main"><AlwaysSuccess/></BehaviorTree>\n<Action/>'),
        [],
    ),
    # --- §f Includes ------------------------------------------------------------------------
    (
        "<include> without path",
        R('<⟦include⟧/>\n<BehaviorTree ID="Main"><AlwaysSuccess/></BehaviorTree>'),
        [("include-missing-path", E)],
    ),
    (
        "ros_pkg without a mapping",
        R(
            '<include ros_pkg="⟦my_pkg⟧" path="trees/a.xml"/>\n'
            '<BehaviorTree ID="Main"><AlwaysSuccess/></BehaviorTree>'
        ),
        [("include-ros-pkg", W)],
    ),
    (
        "ros_pkg with an absolute path is ignored",
        R(
            '<include ros_pkg="my_pkg" path="/opt/a.xml"/>\n'
            '<BehaviorTree ID="Main"><AlwaysSuccess/></BehaviorTree>'
        ),
        [],
    ),
    # --- §f Trees and IDs -------------------------------------------------------------------
    (
        "<BehaviorTree> without ID while root has >1 child",
        R("<⟦BehaviorTree⟧><AlwaysSuccess/></BehaviorTree>\n<TreeNodesModel/>"),
        [("missing-id", E)],
    ),
    (
        "<BehaviorTree> without ID as the only child",
        R("<BehaviorTree><AlwaysSuccess/></BehaviorTree>"),
        [],
    ),
    (
        "BehaviorTree ID = registered type",
        R('<BehaviorTree ID="⟦Sequence⟧"><AlwaysSuccess/></BehaviorTree>'),
        [("registered-name-as-tree-id", E)],
    ),
    (
        "BehaviorTree ID = a declared custom node",
        R(
            '<BehaviorTree ID="⟦Say⟧"><AlwaysSuccess/></BehaviorTree>\n'
            '<TreeNodesModel><Action ID="Say"/></TreeNodesModel>'
        ),
        [("registered-name-as-tree-id", H)],
    ),
    (
        "BehaviorTree with 2 children",
        R('<⟦BehaviorTree⟧ ID="Main"><AlwaysSuccess/><AlwaysFailure/></BehaviorTree>'),
        [("tree-child-count", E)],
    ),
    (
        "BehaviorTree with no child",
        R('<⟦BehaviorTree⟧ ID="Main"></BehaviorTree>'),
        [("tree-child-count", E)],
    ),
    (
        "duplicate BehaviorTree ID",
        R(
            '<BehaviorTree ID="A"><AlwaysSuccess/></BehaviorTree>\n'
            '<BehaviorTree ID="⟦A⟧"><AlwaysSuccess/></BehaviorTree>',
            'BTCPP_format="4" main_tree_to_execute="A"',
        ),
        [("duplicate-tree-id", W)],
    ),
    (
        "main_tree_to_execute names an unknown tree",
        R(
            '<BehaviorTree ID="Main"><AlwaysSuccess/></BehaviorTree>',
            'BTCPP_format="4" main_tree_to_execute="⟦Other⟧"',
        ),
        [("unknown-main-tree", E)],
    ),
    (
        "SubTree names an unknown tree",
        T('<SubTree ID="⟦Nowhere⟧"/>'),
        [("unknown-subtree", E)],
    ),
    (
        # Whether a catalog declaring the name is in the workspace or not: the same error.
        "SubTree names no tree but a declared custom node",
        R(
            '<BehaviorTree ID="Main"><SubTree ID="⟦Say⟧"/></BehaviorTree>\n'
            '<TreeNodesModel><Action ID="Say"/></TreeNodesModel>'
        ),
        [("unknown-subtree", E)],
    ),
    (
        "SubTree names no tree but a built-in",
        # VerifyXML refuses the registered name at load, before it looks for the tree.
        T('<SubTree ID="⟦Sequence⟧"/>'),
        [("registered-name-as-tree-id", E)],
    ),
    (
        "SubTree names a tree that is also a declared custom node",
        R(
            '<BehaviorTree ID="Main"><SubTree ID="⟦Say⟧"/></BehaviorTree>\n'
            '<BehaviorTree ID="⟦Say⟧"><AlwaysSuccess/></BehaviorTree>\n'
            '<TreeNodesModel><Action ID="Say"/></TreeNodesModel>',
            'BTCPP_format="4" main_tree_to_execute="Main"',
        ),
        [("registered-name-as-tree-id", H), ("registered-name-as-tree-id", H)],
    ),
    (
        "SubTree ID breaking a name rule and naming no tree: one problem",
        T('<SubTree ID="No where"/>'),
        [],
    ),
    ("root with nothing in it", '<⟦root⟧ BTCPP_format="4"></root>', [("no-tree", W)]),
    ("root with only an include", R('<include path="other.xml"/>'), []),
    (
        "several trees, no main_tree_to_execute",
        '<⟦root⟧ BTCPP_format="4">\n'
        '<BehaviorTree ID="A"><SubTree ID="B"/></BehaviorTree>\n'
        '<BehaviorTree ID="B"><AlwaysSuccess/></BehaviorTree>\n</root>',
        [("no-main-tree", INFO)],
    ),
    (
        "SubTree recursion A -> B -> A",
        R(
            '<BehaviorTree ID="A"><SubTree ID="B"/></BehaviorTree>\n'
            '<BehaviorTree ID="B"><SubTree ID="⟦A⟧"/></BehaviorTree>',
            'BTCPP_format="4" main_tree_to_execute="A"',
        ),
        [("subtree-recursion", E)],
    ),
    (
        "SubTree recursion: a tree calling itself",
        T('<Sequence><AlwaysSuccess/><SubTree ID="⟦Main⟧"/></Sequence>'),
        [("subtree-recursion", E)],
    ),
    (
        "SubTree recursion through three trees, walked from the main tree",
        R(
            '<BehaviorTree ID="C"><SubTree ID="⟦A⟧"/></BehaviorTree>\n'
            '<BehaviorTree ID="A"><SubTree ID="B"/></BehaviorTree>\n'
            '<BehaviorTree ID="B"><SubTree ID="C"/></BehaviorTree>',
            'BTCPP_format="4" main_tree_to_execute="A"',
        ),
        [("subtree-recursion", E)],
    ),
    (
        "two SubTrees with the same name under different parents",
        R(
            '<BehaviorTree ID="Main"><Sequence>'
            '<Fallback><SubTree ID="Sub" name="s"/></Fallback>'
            '<Sequence><SubTree ID="Sub" name="⟦s⟧"/></Sequence>'
            "</Sequence></BehaviorTree>\n"
            '<BehaviorTree ID="Sub"><AlwaysSuccess/></BehaviorTree>',
            'BTCPP_format="4" main_tree_to_execute="Main"',
        ),
        # Only BehaviorTree.CPP releases from 2026 on reject it: a warning.
        [("duplicate-subtree-name", W)],
    ),
    (
        "two SubTrees with the same name in different trees are fine",
        R(
            '<BehaviorTree ID="Main"><Sequence><SubTree ID="Sub" name="s"/>'
            '<SubTree ID="Other" name="t"/></Sequence></BehaviorTree>\n'
            '<BehaviorTree ID="Other"><SubTree ID="Sub" name="s"/></BehaviorTree>\n'
            '<BehaviorTree ID="Sub"><AlwaysSuccess/></BehaviorTree>',
            'BTCPP_format="4" main_tree_to_execute="Main"',
        ),
        [],
    ),
    # --- §f Nodes ---------------------------------------------------------------------------
    ("<Action> without ID", T("<⟦Action⟧/>"), [("missing-id", E)]),
    ("<Decorator> without ID", T("<⟦Decorator⟧><AlwaysSuccess/></Decorator>"), [("missing-id", E)]),
    ("<SubTree> without ID", T("<⟦SubTree⟧/>"), [("missing-id", E)]),
    ("unknown compact node, no catalog: a hint", T("<⟦MoveBase⟧/>"), [("unknown-node", H)]),
    ("unknown explicit node, no catalog", T('<Action ID="⟦MoveBase⟧"/>'), [("unknown-node", H)]),
    ("declared custom node", TM('<Say text="hi"/>'), []),
    ("explicit form of a declared node", TM('<Action ID="Say" text="hi"/>'), []),
    (
        "category tag contradicting the type is no error",
        T('<Condition ID="Sequence"><AlwaysSuccess/></Condition>'),
        [],
    ),
    (
        "v3 name SequenceStar",
        T("<⟦SequenceStar⟧><AlwaysSuccess/></SequenceStar>"),
        [("unknown-node", E)],
    ),
    (
        "v3 name in a document without BTCPP_format: a warning",
        R(
            '<BehaviorTree ID="Main"><⟦SequenceStar⟧><AlwaysSuccess/></SequenceStar>'
            "</BehaviorTree>",
            root="",
        ).replace("<root>", "<⟦root⟧>"),
        [("missing-format", H), ("unknown-node", W)],
    ),
    (
        "typo RetryUntilSuccesful",
        T('<⟦RetryUntilSuccesful⟧ num_attempts="2"><AlwaysSuccess/></RetryUntilSuccesful>'),
        [("unknown-node", E)],
    ),
    (
        "v3 built-in BlackboardCheckInt",
        T('<⟦BlackboardCheckInt⟧ value_A="1" value_B="2"><AlwaysSuccess/></BlackboardCheckInt>'),
        [("unknown-node", H)],
    ),
    (
        "wrong case of a built-in",
        T("<⟦inverter⟧><AlwaysSuccess/></inverter>"),
        [("unknown-node", E)],
    ),
    (
        "a tree used as a node type",
        R(
            '<BehaviorTree ID="Main"><⟦Sub⟧/></BehaviorTree>\n'
            '<BehaviorTree ID="Sub"><AlwaysSuccess/></BehaviorTree>',
            'BTCPP_format="4" main_tree_to_execute="Main"',
        ),
        [("unknown-node", E)],
    ),
    ("compact name breaking the name rules is left to them", T("<Move.Base/>"), []),
    ("decorator with 0 children", T("<⟦Inverter⟧/>"), [("child-count", E)]),
    (
        "decorator with 2 children",
        T("<⟦ForceSuccess⟧><AlwaysSuccess/><AlwaysSuccess/></ForceSuccess>"),
        [("child-count", E)],
    ),
    ("control with 0 children", T("<⟦Sequence⟧/>"), [("child-count", E)]),
    ("explicit control with 0 children", T('<⟦Control⟧ ID="Fallback"/>'), [("child-count", E)]),
    ("TryCatch with 1 child", T("<⟦TryCatch⟧><AlwaysSuccess/></TryCatch>"), [("child-count", E)]),
    ("TryCatch with 2 children", T("<TryCatch><AlwaysSuccess/><AlwaysSuccess/></TryCatch>"), []),
    (
        "action with a child",
        T("<⟦AlwaysSuccess⟧><AlwaysFailure/></AlwaysSuccess>"),
        [("child-count", E)],
    ),
    (
        "condition with a child",
        T('<⟦ScriptCondition⟧ code="true"><AlwaysFailure/></ScriptCondition>'),
        [("child-count", E)],
    ),
    (
        "<SubTree> with a child",
        R(
            '<BehaviorTree ID="Main"><⟦SubTree⟧ ID="Sub"><AlwaysSuccess/></SubTree>'
            "</BehaviorTree>\n"
            '<BehaviorTree ID="Sub"><AlwaysSuccess/></BehaviorTree>',
            'BTCPP_format="4" main_tree_to_execute="Main"',
        ),
        [("child-count", E)],
    ),
    (
        "ID on a compact node",
        T('<AlwaysSuccess ⟦ID⟧="AlwaysSuccess"/>'),
        [("id-on-compact-node", E)],
    ),
    (
        "IfThenElse with 1 child",
        T("<⟦IfThenElse⟧><AlwaysSuccess/></IfThenElse>"),
        [("child-count", E)],
    ),
    (
        "IfThenElse with 3 children",
        T("<IfThenElse><AlwaysSuccess/><AlwaysSuccess/><AlwaysSuccess/></IfThenElse>"),
        [],
    ),
    (
        "WhileDoElse with 4 children",
        T(
            "<⟦WhileDoElse⟧><AlwaysSuccess/><AlwaysSuccess/>"
            "<AlwaysSuccess/><AlwaysSuccess/></WhileDoElse>"
        ),
        [("child-count", E)],
    ),
    (
        "Switch2 with 2 children",
        T(
            '<⟦Switch2⟧ variable="{v}" case_1="a" case_2="b"><AlwaysSuccess/>'
            "<AlwaysSuccess/></Switch2>"
        ),
        [("child-count", E)],
    ),
    (
        "Switch2 with 3 children",
        T(
            '<Switch2 variable="{v}" case_1="a" case_2="b"><AlwaysSuccess/>'
            "<AlwaysSuccess/><AlwaysSuccess/></Switch2>"
        ),
        [],
    ),
    ("declared decorator with 0 children", TM("<⟦Guard⟧/>"), [("child-count", E)]),
    ("declared control with 0 children", TM('<⟦Control⟧ ID="Switcher"/>'), [("child-count", E)]),
    (
        "ReactiveSequence with 2 AsyncSequence children",
        T(
            "<⟦ReactiveSequence⟧><AsyncSequence><AlwaysSuccess/></AsyncSequence>"
            "<AsyncSequence><AlwaysSuccess/></AsyncSequence></ReactiveSequence>"
        ),
        [("reactive-async-children", E)],
    ),
    (
        "ReactiveSequence with 1 AsyncSequence child",
        T(
            "<ReactiveSequence><AsyncSequence><AlwaysSuccess/></AsyncSequence>"
            "<AsyncFallback><AlwaysSuccess/></AsyncFallback></ReactiveSequence>"
        ),
        [],
    ),
    (
        "ReactiveSequence with an explicit-form child",
        T('<ReactiveSequence><AlwaysSuccess/><⟦Action⟧ ID="AlwaysSuccess"/></ReactiveSequence>'),
        [("reactive-explicit-child", E)],
    ),
    (
        "ReactiveFallback takes explicit-form children",
        T('<ReactiveFallback><Action ID="AlwaysSuccess"/></ReactiveFallback>'),
        [],
    ),
    (
        "Parallel thresholds larger than the child count",
        T(
            '<Parallel success_count="⟦3⟧" failure_count="⟦4⟧"><AlwaysSuccess/><AlwaysSuccess/>'
            "</Parallel>"
        ),
        [("parallel-threshold", E), ("parallel-threshold", E)],
    ),
    (
        "Parallel thresholds counted from the end",
        T('<Parallel success_count="-1" failure_count="-5"><AlwaysSuccess/></Parallel>'),
        [],
    ),
    (
        "Parallel thresholds from the blackboard",
        T(
            '<Parallel success_count="{s}" failure_count="2"><AlwaysSuccess/><AlwaysSuccess/>'
            "</Parallel>"
        ),
        [],
    ),
    (
        "ParallelAll max_failures larger than the child count",
        # 4.8.2: "Number of children is less than threshold. Can never fail." at tick.
        T('<ParallelAll max_failures="⟦3⟧"><AlwaysSuccess/><AlwaysSuccess/></ParallelAll>'),
        [("parallel-threshold", E)],
    ),
    (
        "ParallelAll max_failures up to the child count, from the end or the blackboard",
        T(
            '<Sequence><ParallelAll max_failures="2"><AlwaysSuccess/><AlwaysSuccess/>'
            '</ParallelAll><ParallelAll max_failures="-9"><AlwaysSuccess/></ParallelAll>'
            '<ParallelAll max_failures="{m}"><AlwaysSuccess/></ParallelAll></Sequence>'
        ),
        [],
    ),
    # --- §f Ports and attributes ------------------------------------------------------------
    (
        "undeclared port of a built-in",
        T('<Sleep msec="10" ⟦timeout⟧="1"/>'),
        [("undeclared-port", E)],
    ),
    (
        "Groot 1's shared blackboard port in a file not checked as version 4",
        '<⟦root⟧ main_tree_to_execute="Main"><BehaviorTree ID="Main">'
        '<SubTree ID="Sub" ⟦__shared_blackboard⟧="true"/></BehaviorTree>'
        '<BehaviorTree ID="Sub"><AlwaysSuccess/></BehaviorTree><TreeNodesModel>'
        '<SubTree ID="Sub"><input_port name="⟦__shared_blackboard⟧" default="true"/>'
        "</SubTree></TreeNodesModel></root>",
        [("missing-format", H), ("unknown-attribute", W), ("port-name-groot1", H)],
    ),
    ("hyphenated undeclared port", T('<Sleep msec="10" ⟦foo-bar⟧="1"/>'), [("undeclared-port", E)]),
    (
        "undeclared port of a declared node",
        TM('<Say text="a" ⟦volume⟧="3"/>'),
        # An author's model is advisory: BehaviorTree.CPP reads the C++ registration.
        [("undeclared-port", H)],
    ),
    (
        "unknown node: ports not checked",
        T('<MoveBase ⟦goal⟧="{g}"/>').replace("⟦goal⟧", "goal").replace("<MoveBase", "<⟦MoveBase⟧"),
        [("unknown-node", H)],
    ),
    ("literal not convertible", T('<Sleep msec="⟦abc⟧"/>'), [("invalid-port-value", E)]),
    (
        "negative literal for an unsigned port",
        T('<Timeout msec="⟦-5⟧"><AlwaysSuccess/></Timeout>'),
        [("invalid-port-value", E)],
    ),
    ("blackboard value never converted", T('<Sleep msec="{delay}"/>'), []),
    (
        "a key with spaces around the braces is converted as a literal at creation",
        # 4.8.2: 'The port with name "msec" and value " {delay} " can not be converted';
        # only exactly {key} (or {=}) is left to the blackboard when the tree is created.
        T('<Sequence><Sleep msec="⟦ {delay} ⟧"/><Sleep msec="⟦=⟧"/><Sleep msec="{=}"/></Sequence>'),
        [("invalid-port-value", E), ("invalid-port-value", E)],
    ),
    (
        "a key with spaces around the braces for a port of any text",
        T(
            '<Sequence><UnsetBlackboard key=" {k} "/>'
            '<SetBlackboard value="=" output_key="v"/></Sequence>'
        ),
        [],
    ),
    ("empty braces are a literal", T('<Sleep msec="⟦{}⟧"/>'), [("invalid-port-value", E)]),
    (
        "literal queue of a Loop node, item by item",
        # 4.8.2: 'value "1;x;3" can not be converted to std::shared_ptr<std::deque<int>>'.
        T(
            '<Sequence><LoopInt queue="⟦1;x;3⟧"><AlwaysSuccess/></LoopInt>'
            '<LoopDouble queue="⟦{}⟧"><AlwaysSuccess/></LoopDouble>'
            '<LoopBool queue="⟦1;;0⟧"><AlwaysSuccess/></LoopBool></Sequence>'
        ),
        [("invalid-port-value", E)] * 3,
    ),
    (
        "literal queues that convert, a queue from the blackboard, any text",
        T(
            '<Sequence><LoopInt queue="1;2;3"><AlwaysSuccess/></LoopInt>'
            '<LoopBool queue="1;0;true;"><AlwaysSuccess/></LoopBool>'
            '<LoopDouble queue=""><AlwaysSuccess/></LoopDouble>'
            '<LoopInt queue="{q}"><AlwaysSuccess/></LoopInt>'
            '<LoopString queue="{};a b"><AlwaysSuccess/></LoopString></Sequence>'
        ),
        [],
    ),
    (
        "a queue key with spaces around the braces, a bare =",
        # Before 4.10 (4.8.2) the typed queue port converts " {q} " as a literal and fails;
        # 4.10's constructor reads it as the key q.  "=" fails in both.
        T(
            '<Sequence><LoopInt queue="⟦ {q} ⟧"><AlwaysSuccess/></LoopInt>'
            '<LoopBool queue="⟦=⟧"><AlwaysSuccess/></LoopBool></Sequence>'
        ),
        [("invalid-port-value", W), ("invalid-port-value", E)],
    ),
    (
        "empty entry of the nodes that watch an entry",
        # 4.8.2 and 4.10: "Missing port 'entry' in ..." from the node's constructor.
        T(
            '<Sequence><WasEntryUpdated entry="⟦⟧"/>'
            '<SkipUnlessUpdated entry="⟦⟧"><AlwaysSuccess/></SkipUnlessUpdated>'
            '<WaitValueUpdate entry="⟦⟧"><AlwaysSuccess/></WaitValueUpdate>'
            '<WaitValueUpdate entry="x"><AlwaysSuccess/></WaitValueUpdate></Sequence>'
        ),
        [("invalid-port-value", E)] * 3,
    ),
    (
        "bool literal",
        T('<RunOnce then_skip="⟦yes⟧"><AlwaysSuccess/></RunOnce>'),
        [("invalid-port-value", E)],
    ),
    (
        "an enum port is converted when the node reads it: a key with spaces is a key",
        # 4.8.2: if_empty=" {a} " reads the entry a at tick; else="xyz" fails at tick
        # ("Missing parameter [else]"), not when the tree is created.
        T(
            '<Sequence><LoopInt queue="1" if_empty=" {a} "><AlwaysSuccess/></LoopInt>'
            '<Precondition if="a" else="⟦xyz⟧"><AlwaysSuccess/></Precondition></Sequence>'
        ),
        [("invalid-port-value", E)],
    ),
    (
        "NodeStatus literal",
        T('<Precondition if="a" else="⟦OK⟧"><AlwaysSuccess/></Precondition>'),
        [("invalid-port-value", E)],
    ),
    ("declared typed port", TM('<Count n="⟦many⟧"/>'), [("invalid-port-value", W)]),
    ("declared untyped port takes anything", TM('<Count n="{x}" opt="anything"/>'), []),
    (
        "same blackboard key with two types",
        T(
            '<Sequence><Sleep msec="{t}"/><Repeat num_cycles="⟦{t}⟧"><AlwaysSuccess/></Repeat>'
            "</Sequence>"
        ),
        [("blackboard-type-mismatch", E)],
    ),
    (
        "spaces inside the braces make another key",
        # { t } is the entry " t " (getRemappedKey trims only outside the braces): 4.8.2
        # creates this tree.
        T(
            '<Sequence><Sleep msec="{t}"/><Repeat num_cycles="{ t }"><AlwaysSuccess/></Repeat>'
            "</Sequence>"
        ),
        [],
    ),
    (
        "spaces outside the braces name the same key",
        # 4.8.2: "the port [t] was initially created with type [unsigned int] and, later
        # type [std::string] was used somewhere else".
        T('<Sequence><Sleep msec="{t}"/><UnsetBlackboard key="⟦ {t} ⟧"/></Sequence>'),
        [("blackboard-type-mismatch", E)],
    ),
    (
        "a std::string entry takes any port",
        T(
            '<Sequence><UnsetBlackboard key="{t}"/><Repeat num_cycles="{t}"><AlwaysSuccess/>'
            "</Repeat></Sequence>"
        ),
        [],
    ),
    (
        "blackboard keys of different trees do not meet",
        R(
            '<BehaviorTree ID="Main"><Sequence><Sleep msec="{t}"/><SubTree ID="Sub"/></Sequence>'
            "</BehaviorTree>\n"
            '<BehaviorTree ID="Sub"><Repeat num_cycles="{t}"><AlwaysSuccess/></Repeat>'
            "</BehaviorTree>",
            'BTCPP_format="4" main_tree_to_execute="Main"',
        ),
        [],
    ),
    (
        "pre/post-condition script syntax",
        T('<AlwaysSuccess _skipIf="a == ⟦==⟧ b"/>'),
        [("script-syntax", E)],
    ),
    ("Script code syntax", T('<Script code="x := ⟦)⟧"/>'), [("script-syntax", E)]),
    (
        "an empty Script does nothing, a blank one does not parse",
        # 4.8.2: code="" creates and ticks (SUCCESS); code=" " throws "Empty Script".
        T('<Sequence><Script code=""/><Script code="⟦ ⟧"/></Sequence>'),
        [("script-syntax", E)],
    ),
    (
        "empty code of ScriptCondition and Precondition",
        # 4.8.2: created, then bad_function_call at the first tick.
        T(
            '<Sequence><ScriptCondition code="⟦⟧"/>'
            '<Precondition if="⟦⟧" else="FAILURE"><AlwaysSuccess/></Precondition></Sequence>'
        ),
        [("script-syntax", E), ("script-syntax", E)],
    ),
    ("ScriptCondition code syntax", T('<ScriptCondition code="⟦;⟧a"/>'), [("script-syntax", E)]),
    (
        "Precondition if syntax",
        T('<Precondition if="a &amp;&amp; ⟦%⟧"><AlwaysSuccess/></Precondition>'),
        [("script-syntax", E)],
    ),
    ("empty script", T('<AlwaysSuccess _post="⟦⟧"/>'), [("script-syntax", E)]),
    ("script ending too early", T('<AlwaysSuccess _post="x :⟦=⟧  "/>'), [("script-syntax", E)]),
    (
        "script in 4.0-4.9 syntax",
        T('<Script code="msg := ⟦&quot;⟧hi&quot;"/>'),
        [("script-syntax", W)],
    ),
    ("script from the blackboard is not parsed", T('<Script code="{the_code}"/>'), []),
    (
        "valid scripts",
        T(
            '<Sequence><Script code="a := 1; b := a + 2"/>'
            '<AlwaysSuccess _skipIf="a &gt; 1 &amp;&amp; b != 3"'
            " _onSuccess=\"c := 'x'\"/>"
            "</Sequence>"
        ),
        [],
    ),
    ("required built-in port missing", T("<⟦Sleep⟧/>"), [("missing-required-port", E)]),
    (
        # SwitchN reads its cases with getInput and goes on: a case without a value never
        # matches, which is very likely a mistake but not a failure.
        "unset cases of Switch3",
        T(
            '<⟦Switch3⟧ variable="{v}" case_1="a"><AlwaysSuccess/>'
            "<AlwaysSuccess/><AlwaysSuccess/><AlwaysSuccess/>"
            "</Switch3>"
        ),
        [("missing-required-port", W)],
    ),
    ("output ports are not required", T('<LoopInt queue="1;2;3"><AlwaysSuccess/></LoopInt>'), []),
    ("required declared port missing", TM("<⟦Say⟧/>"), [("missing-port-without-default", H)]),
    (
        "attribute neither port nor reserved",
        T('<AlwaysSuccess ⟦_skipif⟧="x"/>'),
        [("unknown-attribute", W)],
    ),
    ("_description is allowed", T('<AlwaysSuccess _description="says yes"/>'), []),
    (
        "unknown underscore attribute without suggestion",
        T('<AlwaysSuccess ⟦_color⟧="red"/>'),
        [("unknown-attribute", H)],
    ),
    (
        "attribute with a non-ASCII first letter",
        T('<AlwaysSuccess ⟦检查⟧="x"/>'),
        [("port-name-not-remappable", W)],
    ),
    (
        "attribute starting with '-'",
        T('<AlwaysSuccess ⟦-x⟧="1"/>'),
        [("port-name-not-remappable", W)],
    ),
    ("attribute breaking the name rules is left to them", T('<AlwaysSuccess a.b="1"/>'), []),
    # --- §f SubTree ports and the TreeNodesModel --------------------------------------------
    (
        "model <SubTree> without ID",
        R(
            '<BehaviorTree ID="Main"><AlwaysSuccess/></BehaviorTree>\n'
            "<TreeNodesModel><⟦SubTree⟧/></TreeNodesModel>"
        ),
        [("missing-id", E)],
    ),
    (
        "model port without name",
        R(
            '<BehaviorTree ID="Main"><AlwaysSuccess/></BehaviorTree>\n'
            '<TreeNodesModel><SubTree ID="Main"><⟦input_port⟧/></SubTree></TreeNodesModel>'
        ),
        [("missing-port-name", E)],
    ),
    (
        "model port name that can never be remapped",
        R(
            '<BehaviorTree ID="Main"><AlwaysSuccess/></BehaviorTree>\n'
            '<TreeNodesModel><SubTree ID="Main"><input_port name="⟦_goal⟧" default="1"/>'
            '</SubTree><Action ID="A"><input_port name="⟦检查⟧"/></Action></TreeNodesModel>'
        ),
        [("port-name-not-remappable", W), ("port-name-not-remappable", W)],
    ),
    (
        "SubTree call remapping every mandatory port",
        TM('<SubTree ID="Dock" target="{t}" result="{=}"/>'),
        [],
    ),
    (
        "model port neither remapped nor defaulted",
        TM('<⟦SubTree⟧ ID="Dock" target="{t}"/>'),
        [("missing-required-port", E)],
    ),
    ("_autoremap satisfies the mandatory ports", TM('<SubTree ID="Dock" _autoremap="true"/>'), []),
    (
        "_autoremap not a bool",
        TM('<SubTree ID="Dock" target="{t}" result="{r}" _autoremap="⟦yes⟧"/>'),
        [("invalid-port-value", E)],
    ),
    (
        "_autoremap from the blackboard",
        TM('<SubTree ID="Dock" target="{t}" result="{r}" _autoremap="⟦{x}⟧"/>'),
        [("invalid-port-value", E)],
    ),
    (
        "SubTree attribute with no matching model port",
        TM('<SubTree ID="Dock" target="{t}" result="{r}" ⟦tagret⟧="{t}"/>'),
        [("undeclared-port", W)],
    ),
    (
        "SubTree without a model accepts any remapping",
        R(
            '<BehaviorTree ID="Main"><SubTree ID="Sub" anything="{x}" more="1"/></BehaviorTree>\n'
            '<BehaviorTree ID="Sub"><AlwaysSuccess/></BehaviorTree>',
            'BTCPP_format="4" main_tree_to_execute="Main"',
        ),
        [],
    ),
    (
        "v3 __shared_blackboard",
        R(
            '<BehaviorTree ID="Main"><SubTree ID="Sub" ⟦__shared_blackboard⟧="true"/>'
            "</BehaviorTree>\n"
            '<BehaviorTree ID="Sub"><AlwaysSuccess/></BehaviorTree>',
            'BTCPP_format="4" main_tree_to_execute="Main"',
        ),
        [("unknown-attribute", W)],
    ),
    (
        "v3 Parallel thresholds in a document without BTCPP_format: warnings",
        R(
            '<BehaviorTree ID="Main"><Parallel ⟦success_threshold⟧="1" ⟦failure_threshold⟧="1">'
            "<AlwaysSuccess/></Parallel></BehaviorTree>",
            root="",
        ).replace("<root>", "<⟦root⟧>"),
        [("missing-format", H), ("undeclared-port", W), ("undeclared-port", W)],
    ),
]


def semantic(
    doc: Document, ctx: Context | None = None, also: Collection[str] = ()
) -> list[tuple[int, int, str, Severity]]:
    """What the semantic rules report on ``doc``: the pinned codes and ``also``."""
    found = semantics.check(doc, ctx if ctx is not None else Context.from_document(doc))
    return sorted((d.start, d.end, d.code, d.severity) for d in pinned(found, also))


Found = list[tuple[int, int, str, Severity]]


def expect(marked: str, expected: Expected) -> tuple[Document, Found]:
    text, spans = unmark(marked)
    assert len(spans) == len(expected), "one expectation per mark"
    return Document(text), sorted(
        (s, e, code, sev) for (s, e), (code, sev) in zip(spans, expected, strict=True)
    )


@pytest.mark.parametrize(("marked", "expected"), [c[1:] for c in CASES], ids=[c[0] for c in CASES])
def test_case(marked: str, expected: Expected) -> None:
    doc, want = expect(marked, expected)
    assert semantic(doc, also=[code for code, _ in expected]) == want


def test_every_semantic_code_has_a_case() -> None:
    seen = {code for _, _, exp in CASES for code, _ in exp}
    ours = {c for c, info in CODES.items() if info.family == "behaviortree"}
    # Codes the workspace layer reports (include resolution) are not ours; nesting-depth
    # has its own test below.
    ours -= {"include-not-found", "include-cycle", "nesting-depth"}
    # A code whose fixture holds its near miss (CONTRIBUTING.md, "Add a rule") is tested
    # there alone.
    ours -= {c for c in ours if _fixture_with_near_miss(c)}
    assert ours - seen == set()


def _fixture_with_near_miss(code: str) -> bool:
    path = Path(__file__).parent / "fixtures" / f"{code}.xml"
    return path.is_file() and "<!-- near miss -->" in path.read_text(encoding="utf-8")


def test_diagnostics_are_sorted_and_analyze_merges() -> None:
    doc = Document(T('<Sequence><Sleep msec="x" bad="1"/><Inverter/></Sequence>'))
    found = semantics.check(doc, Context.from_document(doc))
    assert found == sorted(found, key=lambda d: (d.start, d.end, d.code))
    merged = analyze(doc)
    assert merged == sorted(merged, key=lambda d: (d.start, d.end, d.code))
    assert {d.code for d in found} <= {d.code for d in merged}


# --- context-dependent cases ----------------------------------------------------------------


def test_unknown_node_is_an_error_with_a_catalog() -> None:
    doc, want = expect(T("<⟦MoveBase⟧/>"), [("unknown-node", E)])
    catalog = Document(R('<TreeNodesModel><Action ID="Other"/></TreeNodesModel>'))
    ctx = Context.combine(doc, [], model_files=[("/w/models.xml", catalog)])
    assert ctx.workspace_has_custom_models
    assert semantic(doc, ctx) == want
    # ... and known when the catalog declares it.
    catalog = Document(R('<TreeNodesModel><Action ID="MoveBase"/></TreeNodesModel>'))
    ctx = Context.combine(doc, [], model_files=[("/w/models.xml", catalog)])
    assert semantic(doc, ctx) == []


def test_models_of_other_workspace_files_count() -> None:
    doc = Document(T('<MoveBase goal="{g}"/>'))
    other = Document(  # a tree file with its <TreeNodesModel>: advisory
        R(
            '<BehaviorTree ID="Other"><AlwaysSuccess/></BehaviorTree>'
            '<TreeNodesModel><Action ID="MoveBase"><input_port name="goal"/>'
            "</Action></TreeNodesModel>"
        )
    )
    ctx = Context.combine(doc, [("/w/other.xml", other, False)])
    assert not ctx.workspace_has_custom_models
    assert semantic(doc, ctx) == []
    doc2, want = expect(
        T('<MoveBase ⟦gaol⟧="{g}"/>').replace("<MoveBase", "<⟦MoveBase⟧"),
        [("missing-port-without-default", H), ("undeclared-port", H)],
    )
    assert semantic(doc2, Context.combine(doc2, [("/w/other.xml", other, False)])) == want


def test_ros_pkg_mapped_in_the_settings() -> None:
    doc = Document(
        R(
            '<include ros_pkg="my_pkg" path="a.xml"/>\n'
            '<BehaviorTree ID="Main"><AlwaysSuccess/></BehaviorTree>'
        )
    )
    ctx = Context.from_document(doc, ros_pkg_paths={"my_pkg": "/opt/ros/share/my_pkg"})
    assert semantic(doc, ctx) == []


def test_no_main_tree_not_reported_for_an_included_document() -> None:
    doc = Document(
        R(
            '<BehaviorTree ID="A"><AlwaysSuccess/></BehaviorTree>\n'
            '<BehaviorTree ID="B"><AlwaysSuccess/></BehaviorTree>'
        )
    )
    assert [c for _, _, c, _ in semantic(doc)] == ["no-main-tree"]
    ctx = Context.combine(doc, [], path="/w/lib.xml", included_by=["/w/main.xml"])
    assert semantic(doc, ctx) == []


LIB = R(
    '<BehaviorTree ID="Lib"><SubTree ID="Main"/></BehaviorTree>\n'
    '<BehaviorTree ID="Shared"><AlwaysSuccess/></BehaviorTree>'
)


def test_included_trees_are_visible_and_cycles_cross_files() -> None:
    doc, want = expect(
        R(
            '<include path="lib.xml"/>\n'
            '<BehaviorTree ID="Main"><Sequence><SubTree ID="⟦Lib⟧"/><SubTree ID="Shared"/>'
            "</Sequence></BehaviorTree>"
        ),
        [("subtree-recursion", E)],
    )
    lib = Document(LIB)
    ctx = Context.combine(doc, [("/w/lib.xml", lib, True)], path="/w/main.xml")
    assert set(ctx.trees) == {"Main", "Lib", "Shared"}
    # Main -> Lib -> Main: the closing call Lib -> Main is in lib.xml, so the call of
    # this document on the cycle is reported.
    assert semantic(doc, ctx) == want


def test_duplicate_tree_id_across_files() -> None:
    doc, want = expect(
        R(
            '<include path="lib.xml"/>\n'
            '<BehaviorTree ID="Main"><SubTree ID="Shared"/></BehaviorTree>\n'
            '<BehaviorTree ID="⟦Shared⟧"><AlwaysFailure/></BehaviorTree>',
            'BTCPP_format="4" main_tree_to_execute="Main"',
        ),
        [("duplicate-tree-id", W)],
    )
    lib = Document(R('<BehaviorTree ID="Shared"><AlwaysSuccess/></BehaviorTree>'))
    ctx = Context.combine(doc, [("/w/lib.xml", lib, True)], path="/w/main.xml")
    assert [d.path for d in ctx.trees["Shared"]] == ["/w/lib.xml", "/w/main.xml"]
    assert semantic(doc, ctx) == want
    message = semantics.check(doc, ctx)[0].message
    assert "lib.xml" in message


def test_trees_of_files_not_included_are_hints() -> None:
    doc, want = expect(
        R(
            '<BehaviorTree ID="Main"><SubTree ID="⟦Elsewhere⟧"/></BehaviorTree>',
            'BTCPP_format="4" main_tree_to_execute="Main"',
        ),
        [("unknown-subtree", H)],
    )
    other = Document(R('<BehaviorTree ID="Elsewhere"><AlwaysSuccess/></BehaviorTree>'))
    ctx = Context.combine(doc, [("/w/other.xml", other, False)], path="/w/main.xml")
    assert "Elsewhere" not in ctx.trees and "Elsewhere" in ctx.workspace_trees
    assert semantic(doc, ctx) == want
    doc2, want2 = expect(
        R(
            '<BehaviorTree ID="Main"><AlwaysSuccess/></BehaviorTree>',
            'BTCPP_format="4" main_tree_to_execute="⟦Elsewhere⟧"',
        ),
        [("unknown-main-tree", H)],
    )
    assert semantic(doc2, Context.combine(doc2, [("/w/other.xml", other, False)])) == want2


def test_subtree_models_from_included_documents() -> None:
    doc, want = expect(
        R(
            '<include path="lib.xml"/>\n'
            '<BehaviorTree ID="Main"><⟦SubTree⟧ ID="Shared"/></BehaviorTree>'
        ),
        [("missing-required-port", E)],
    )
    lib = Document(
        R(
            '<BehaviorTree ID="Shared"><AlwaysSuccess/></BehaviorTree>\n'
            '<TreeNodesModel><SubTree ID="Shared"><input_port name="goal"/></SubTree>'
            "</TreeNodesModel>"
        )
    )
    assert semantic(doc, Context.combine(doc, [("/w/lib.xml", lib, True)])) == want


def test_nesting_depth() -> None:
    depth = 300
    body = "<Inverter>" * depth + "<AlwaysSuccess/>" + "</Inverter>" * depth
    doc = Document(T(body))
    found = semantic(doc)
    assert [c for _, _, c, _ in found] == ["nesting-depth"]
    start, end, _, sev = found[0]
    assert sev == W  # only releases from February 2026 on reject it
    # <BehaviorTree> is level 0; the first element below level 256 is the 257th Inverter.
    assert doc.text.count("<Inverter>", 0, start) == 256
    assert doc.text[start:end] == "Inverter"
    shallow = "<Inverter>" * 255 + "<AlwaysSuccess/>" + "</Inverter>" * 255
    assert semantic(Document(T(shallow))) == []


def test_v3_document_gets_warnings_not_errors() -> None:
    """A BehaviorTree.CPP 3 file (no BTCPP_format) that v4 would reject on its built-ins."""
    doc = Document(
        R(
            '<BehaviorTree ID="Main"><ReactiveSequence><Action ID="AlwaysSuccess"/>'
            '<Parallel success_threshold="1"><AlwaysSuccess/></Parallel>'
            "<SequenceStar><AlwaysSuccess/></SequenceStar>"
            '<SubTree ID="Main2" __shared_blackboard="true"/>'
            "</ReactiveSequence></BehaviorTree>\n"
            '<BehaviorTree ID="Main2"><AlwaysSuccess/></BehaviorTree>',
            root='main_tree_to_execute="Main"',
        )
    )
    found = semantic(doc)
    assert found and all(sev != E for _, _, _, sev in found)


@pytest.mark.parametrize(
    ("body", "says"),
    [
        # BehaviorTree.CPP 4.8.2's own words, and when it says them.
        (
            "<Sleep/>",
            "creates the tree, and the node throws at its first tick: 'Missing parameter [msec]'",
        ),
        ('<Script code=""/><Script/>', "fails when it creates the node: 'Missing port [code]'"),
        (
            "<LoopInt><AlwaysSuccess/></LoopInt>",
            "fails when it creates the node: '[queue] not found'",
        ),
    ],
)
def test_a_missing_builtin_port_says_when_and_how_the_library_fails(body: str, says: str) -> None:
    doc = Document(T(f"<Sequence>{body}</Sequence>"))
    messages = [
        d.message for d in semantics.check(doc, Context()) if d.code == "missing-required-port"
    ]
    assert len(messages) == 1 and messages[0].endswith(says), messages


def test_an_enum_literal_is_converted_when_the_node_reads_it() -> None:
    doc = Document(T('<Precondition if="a" else="xyz"><AlwaysSuccess/></Precondition>'))
    (d,) = pinned(semantics.check(doc, Context()))
    assert d.code == "invalid-port-value" and "only when the node reads it" in d.message


def test_controls_that_count_children_at_tick_say_so() -> None:
    """4.8.2 loads <IfThenElse> with one child and throws at its first tick."""
    doc = Document(T("<IfThenElse><AlwaysSuccess/></IfThenElse>"))
    (d,) = pinned(semantics.check(doc, Context()))
    assert d.code == "child-count" and d.message.endswith(
        "throws at its first tick: 'IfThenElseNode must have either 2 or 3 children'"
    )
