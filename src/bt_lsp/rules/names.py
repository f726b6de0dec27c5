"""The name rules for BT XML: model (node type) names, port names and instance names.

The rules are the seed rules (``name-validation-rules.md``), followed where BehaviorTree.CPP
is stricter (``root`` is reserved as well as ``Root``). Everything here is pure: no I/O and no
LSP types. :func:`check_name` runs on every name of a document, so the common valid case
costs one precompiled regex search and a few set look-ups.

Offsets and columns are counted in code points within the name (0-based ``offset``,
1-based column in messages); converting them to document positions is the caller's job.
"""

from __future__ import annotations

import re
from collections.abc import Collection, Iterator, Mapping
from dataclasses import dataclass
from types import MappingProxyType
from typing import Final

from bt_lsp.rules.codes import BT, NAMES, FixData, Severity, define, display_only, safe
from bt_lsp.syntax.elements import Role
from bt_lsp.syntax.vocabulary import (
    BTCPP_RESERVED_ATTRIBUTES,
    FORBIDDEN,
    POSTCONDITIONS,
    PRECONDITIONS,
    RESERVED_MODEL_NAMES,
    RESERVED_PORT_NAMES,
    NameKind,
)


@dataclass(frozen=True, slots=True)
class NameData(FixData):
    """What a name diagnostic tells its fixes: the name as written, its kind and role."""

    name: str
    kind: NameKind
    role: Role

    def as_json(self) -> dict[str, object]:
        return {"name": self.name, "kind": str(self.kind), "role": str(self.role)}


#: The quick fixes of every name code: a rename to a sanitized, unique name (``where``
#: counts the places and the other files it changes) or clearing an instance name that has
#: nothing left to keep, both safe: BehaviorTree.CPP refuses the name, and every reference
#: is renamed with it.  A name whose target bt-lsp cannot rename with it (a node type
#: registered in C++ or in an installed catalog) is offered in the editor only: applied
#: alone, the rename would break the reference.
NAME_FIX_TITLES: Final = MappingProxyType(
    {
        "rename": safe("Rename '{old}' to '{new}' ({where})"),
        "clear": safe("Clear '{old}' ({where})"),
        "rename-elsewhere": display_only(
            "Rename '{old}' to '{new}' ({where}); {caution}",
            "a node type registered in C++ or in an installed catalog, which bt-lsp cannot rename",
        ),
    }
)

# The versions the name rules apply to (the ``since`` of each code's page).
_NAME_RULES_SINCE: Final = (
    "BehaviorTree.CPP 4.8.4 and later (the release that added name validation). Earlier "
    "releases, 3.x included, load the name, but Groot2 and every newer release reject it, "
    "so bt-lsp reports it for every version."
)

# The codes of these rules (see bt_lsp.rules.registry).
MODEL_NAME_EMPTY: Final = define(
    "model-name-empty",
    Severity.ERROR,
    "a model name is empty",
    NAMES,
    fixes=NAME_FIX_TITLES,
    doc="""
        BehaviorTree.CPP checks every model name it reads from a tree (a node type written as an
        element, `<BehaviorTree ID>`, `<SubTree ID>`) when it loads the XML, and rejects an empty
        one: `Model/Node type name cannot be empty` (an empty `<SubTree ID="">` is reported as a
        missing `ID`). bt-lsp also checks the `ID` of explicit nodes and `<TreeNodesModel>` entries.
        """,
    why="""
        The file does not load: `registerBehaviorTreeFromFile` or `createTreeFromFile` throws, and
        the robot never starts the tree. A node or tree without a name cannot be registered,
        called or shown in Groot2.
        """,
    bad='<SubTree ID=""/>',
    good='<SubTree ID="Dock"/>',
    since=_NAME_RULES_SINCE,
)
MODEL_NAME_RESERVED: Final = define(
    "model-name-reserved",
    Severity.ERROR,
    "a model name is `Root` or `root`",
    NAMES,
    fixes=NAME_FIX_TITLES,
    doc="""
        `Root` and `root` are reserved: BehaviorTree.CPP rejects either as a node type, a tree ID
        or a SubTree ID when it loads the XML (`'Root' is a reserved name and cannot be used as a
        node type`). The match is exact, so `ROOT` or `RootTree` are fine.
        """,
    why="""
        The file does not load. `<root>` is the document's top element, so a node or tree called
        `Root` is easily confused with it, in the XML and in Groot2.
        """,
    bad="""
        <BehaviorTree ID="Root">
          <AlwaysSuccess/>
        </BehaviorTree>
        """,
    good="""
        <BehaviorTree ID="RootTree">
          <AlwaysSuccess/>
        </BehaviorTree>
        """,
    since=_NAME_RULES_SINCE,
)
MODEL_NAME_FORBIDDEN_CHAR: Final = define(
    "model-name-forbidden-char",
    Severity.ERROR,
    "a model name contains a forbidden character",
    NAMES,
    fixes=NAME_FIX_TITLES,
    doc="""
        A model name (node type, tree ID, SubTree ID) may hold any character except whitespace,
        `< > & " '`, `/ \\ :`, `* ? |`, `.` and the control characters (ASCII 0-31, 127); any
        non-ASCII letter is allowed. BehaviorTree.CPP rejects the name when it loads the XML:
        `Model name 'Main Tree' contains forbidden character ' '`.
        """,
    why="""
        The file does not load. A space or a period in a node type cannot even be written as an
        XML element name, and a tree ID with one cannot be used in compact form or saved by
        Groot2.
        """,
    bad="""
        <root BTCPP_format="4" main_tree_to_execute="Main Tree">
          <BehaviorTree ID="Main Tree">
            <AlwaysSuccess/>
          </BehaviorTree>
        </root>
        """,
    good="""
        <root BTCPP_format="4" main_tree_to_execute="Main_Tree">
          <BehaviorTree ID="Main_Tree">
            <AlwaysSuccess/>
          </BehaviorTree>
        </root>
        """,
    since=_NAME_RULES_SINCE,
)
PORT_NAME_EMPTY: Final = define(
    "port-name-empty",
    Severity.ERROR,
    "a port name is empty",
    NAMES,
    fixes=NAME_FIX_TITLES,
    doc="""
        A port declared in a `<TreeNodesModel>` `<SubTree>` entry (`<input_port name="…">`) must
        have a name: BehaviorTree.CPP rejects an empty one when it loads the XML (`Port name
        cannot be empty`).
        """,
    why="""
        The file does not load, and a port without a name can never be remapped.
        """,
    bad="""
        <root BTCPP_format="4">
          <TreeNodesModel>
            <SubTree ID="Dock">
              <input_port name=""/>
            </SubTree>
          </TreeNodesModel>
        </root>
        """,
    good="""
        <root BTCPP_format="4">
          <TreeNodesModel>
            <SubTree ID="Dock">
              <input_port name="target"/>
            </SubTree>
          </TreeNodesModel>
        </root>
        """,
    since=_NAME_RULES_SINCE,
)
PORT_NAME_LEADING_DIGIT: Final = define(
    "port-name-leading-digit",
    Severity.ERROR,
    "a port name starts with an ASCII digit",
    NAMES,
    fixes=NAME_FIX_TITLES,
    doc="""
        A port name cannot start with an ASCII digit. BehaviorTree.CPP rejects such a port in a
        `<TreeNodesModel>` `<SubTree>` entry when it loads the XML (`Port name '2x' cannot start
        with a digit`), and never treats a node attribute that starts with a digit as a port.
        """,
    why="""
        The file does not load; and an attribute such as `2nd_goal` is not even a well-formed XML
        attribute name, so the port can never be set from XML.
        """,
    bad='<SubTree ID="Dock" 2nd_goal="{goal}"/>',
    good='<SubTree ID="Dock" second_goal="{goal}"/>',
    since=_NAME_RULES_SINCE,
)
PORT_NAME_RESERVED: Final = define(
    "port-name-reserved",
    Severity.ERROR,
    "a port of a `<SubTree>` model is named after an attribute BehaviorTree.CPP reserves "
    "(`ID`, `name`, `_autoremap`, the pre/post conditions); 4.8.4 and later throw when "
    "they load the model",
    NAMES,
    fixes=NAME_FIX_TITLES,
    doc="""
        `ID`, `name`, `_autoremap` and the pre- and post-condition attributes (`_skipIf`,
        `_successIf`, `_failureIf`, `_while`, `_onSuccess`, `_onFailure`, `_onHalted`, `_post`)
        are reserved: BehaviorTree.CPP reads them itself on every node. It rejects a port declared
        with one of these names in a `<TreeNodesModel>` `<SubTree>` entry when it loads the XML
        (`Port name '_autoremap' is a reserved attribute name`).
        """,
    why="""
        The file does not load; and the port could never be set, since the attribute of that name
        means something else on every node.
        """,
    bad="""
        <root BTCPP_format="4">
          <TreeNodesModel>
            <SubTree ID="Dock">
              <input_port name="_autoremap"/>
            </SubTree>
          </TreeNodesModel>
        </root>
        """,
    good="""
        <root BTCPP_format="4">
          <TreeNodesModel>
            <SubTree ID="Dock">
              <input_port name="autoremap"/>
            </SubTree>
          </TreeNodesModel>
        </root>
        """,
    since=_NAME_RULES_SINCE,
)
PORT_NAME_RESERVED_GROOT2: Final = define(
    "port-name-reserved-groot2",
    Severity.WARNING,
    "a port declared in `<TreeNodesModel>` has a name the name rules (Groot2) reserve, "
    "where BehaviorTree.CPP accepts it (`__shared_blackboard`, `_description`, or an entry "
    "BehaviorTree.CPP does not read)",
    NAMES,
    fixes=NAME_FIX_TITLES,
    doc="""
        A `<TreeNodesModel>` port named `__shared_blackboard`, `_description` or after an
        attribute BehaviorTree.CPP reserves, where BehaviorTree.CPP itself accepts it: it reads
        only the `<SubTree>` entries of `<TreeNodesModel>` (3.x none), and 4.8.4 and later
        throw only for `ID`, `name`, `_autoremap` and the pre/post conditions there
        (`port-name-reserved`). The name rules (Groot2) reject every one of these names, and
        the message says what BehaviorTree.CPP does with the port: a `<SubTree>` attribute
        that does not start with a letter is never passed on as a remapping, so the port only
        takes its default.
        """,
    why="""
        Groot2 refuses the model, and the port can never be set from a `<SubTree>` call.
        """,
    bad="""
        <root BTCPP_format="4">
          <TreeNodesModel>
            <SubTree ID="Dock">
              <input_port name="_description"/>
            </SubTree>
          </TreeNodesModel>
        </root>
        """,
    good="""
        <root BTCPP_format="4">
          <TreeNodesModel>
            <SubTree ID="Dock">
              <input_port name="description"/>
            </SubTree>
          </TreeNodesModel>
        </root>
        """,
    since=_NAME_RULES_SINCE,
)
# Not a name-rule code: the name is right for Groot 1 and BehaviorTree.CPP 3, so no fix
# renames it (the name fixes and ``check --fix`` act on every code of the NAMES family).
PORT_NAME_GROOT1: Final = define(
    "port-name-groot1",
    Severity.HINT,
    "`__shared_blackboard` declared as a port of a `<SubTree>` model, Groot 1's way of "
    "writing BehaviorTree.CPP 3's shared blackboard, in a file not checked as version 4",
    BT,
    doc="""
        Groot 1 writes BehaviorTree.CPP 3's `__shared_blackboard="true"` attribute of a
        `<SubTree>` call as a port of its `<SubTree>` model. BehaviorTree.CPP 3 does not read
        `<TreeNodesModel>`, so in a file not known to be for version 4 (no `BTCPP_format="4"`
        and no build saying so) this is only a hint: the name is right for Groot 1. In a
        version 4 file it is `port-name-reserved-groot2`: BehaviorTree.CPP 4 ignores a
        `__shared_blackboard` attribute and shares the blackboard with `_autoremap="true"`.
        """,
    why="""
        When the project moves to version 4, the subtree silently stops sharing the parent's
        blackboard.
        """,
    bad="""
        <root>
          <TreeNodesModel>
            <SubTree ID="Dock">
              <input_port name="__shared_blackboard"/>
            </SubTree>
          </TreeNodesModel>
        </root>
        """,
    good="""
        <root BTCPP_format="4" main_tree_to_execute="Main">
          <BehaviorTree ID="Main">
            <SubTree ID="Dock" _autoremap="true"/>
          </BehaviorTree>
          <BehaviorTree ID="Dock">
            <AlwaysSuccess/>
          </BehaviorTree>
        </root>
        """,
    since="BehaviorTree.CPP 3 and Groot 1 (version 4 reads `_autoremap` instead).",
)

#: The name codes that depend on the project's BehaviorTree.CPP version and on the model
#: entry a port is declared in: reported by the semantic checks
#: (:func:`reserved_port_declaration`), never by a document's own name rules nor the early
#: name pass.
PROJECT_NAME_CODES: Final = frozenset({"port-name-reserved", "port-name-reserved-groot2"})
PORT_NAME_FORBIDDEN_CHAR: Final = define(
    "port-name-forbidden-char",
    Severity.ERROR,
    "a port name contains a forbidden character",
    NAMES,
    fixes=NAME_FIX_TITLES,
    doc="""
        A port name has the same forbidden characters as a model name (whitespace, `< > & " '`,
        `/ \\ :`, `* ? |`, `.`, control characters). BehaviorTree.CPP rejects such a port in a
        `<TreeNodesModel>` `<SubTree>` entry when it loads the XML, and never treats such a node
        attribute as a port: `door.id="…"` is silently ignored, not passed to the node.
        """,
    why="""
        A period reads like a member access (`request.name`) and cannot be remapped; the node
        never gets the value it was given, with no error at run time.
        """,
    bad='<OpenDoor door.id="{door}"/>',
    good='<OpenDoor door_id="{door}"/>',
    since=_NAME_RULES_SINCE,
)
INSTANCE_NAME_CONTROL_CHAR: Final = define(
    "instance-name-control-char",
    Severity.ERROR,
    "an instance name contains a control character",
    NAMES,
    fixes=NAME_FIX_TITLES,
    doc="""
        An instance name (`name="…"`) is an attribute value, so spaces, periods and any Unicode
        are fine; only control characters other than tab, line feed and carriage return (ASCII
        0-8, 11, 12, 14-31, 127) are rejected. BehaviorTree.CPP checks it when it creates the
        tree: `Instance name 'start\\x07' contains invalid control character (ASCII 7)`.
        """,
    why="""
        Tree creation fails. A control character is invisible in editors, logs and Groot2, and is
        not allowed in XML 1.0 at all, so other XML tools refuse the file.
        """,
    bad='<Sequence name="start&#7;">',
    good='<Sequence name="start">',
    since=_NAME_RULES_SINCE,
)


__all__ = [
    "BTCPP_RESERVED_ATTRIBUTES",
    "FORBIDDEN",
    "POSTCONDITIONS",
    "PRECONDITIONS",
    "PROJECT_NAME_CODES",
    "RESERVED_MODEL_NAMES",
    "RESERVED_PORT_NAMES",
    "RULES",
    "BadChar",
    "NameKind",
    "Violation",
    "check_name",
    "is_allowed_port_name",
    "may_hold_bad_instance_name",
    "reserved_port_declaration",
]


# The reserved port names in the seed's order, for messages and rule texts.
_RESERVED_PORT_ORDER: Final[tuple[str, ...]] = (
    "ID",
    "name",
    "_description",
    "_skipIf",
    "_successIf",
    "_failureIf",
    "_while",
    "_onSuccess",
    "_onFailure",
    "_onHalted",
    "_post",
    "_autoremap",
    "__shared_blackboard",
)

# --- character table -------------------------------------------------------------------

_WHITESPACE = "whitespace"
_XML_SPECIAL = "XML special"
_PATH = "path separator"
_WILDCARD = "wildcard"
_PERIOD = "period"
_CONTROL = "control character"

# category -> (the seed table's reason, a clause explaining it in a message)
_REASONS: Final[Mapping[str, tuple[str, str]]] = MappingProxyType(
    {
        _WHITESPACE: (
            "breaks XML element/attribute names",
            "whitespace breaks XML element/attribute names",
        ),
        _XML_SPECIAL: ("reserved in XML", "XML special characters are reserved in XML"),
        _PATH: ("filesystem conflicts", "path separators cause filesystem conflicts"),
        _WILDCARD: ("shell/glob conflicts", "wildcards cause shell/glob conflicts"),
        _PERIOD: (
            "ambiguous in port names (e.g. request.name)",
            "a period is ambiguous in names (e.g. request.name)",
        ),
        _CONTROL: ("non-printable", "control characters are non-printable"),
    }
)

# char -> (category, visible name)
_CHAR_INFO_TABLE: dict[str, tuple[str, str]] = {
    " ": (_WHITESPACE, "space"),
    "\t": (_WHITESPACE, "tab"),
    "\n": (_WHITESPACE, "line feed"),
    "\r": (_WHITESPACE, "carriage return"),
    "<": (_XML_SPECIAL, "less-than sign"),
    ">": (_XML_SPECIAL, "greater-than sign"),
    "&": (_XML_SPECIAL, "ampersand"),
    '"': (_XML_SPECIAL, "double quote"),
    "'": (_XML_SPECIAL, "apostrophe"),
    "/": (_PATH, "slash"),
    "\\": (_PATH, "backslash"),
    ":": (_PATH, "colon"),
    "*": (_WILDCARD, "asterisk"),
    "?": (_WILDCARD, "question mark"),
    "|": (_WILDCARD, "vertical bar"),
    ".": (_PERIOD, "period"),
}
for _code in (*range(0x20), 0x7F):
    _CHAR_INFO_TABLE.setdefault(chr(_code), (_CONTROL, "control character"))
del _code
_CHAR_INFO: Final[Mapping[str, tuple[str, str]]] = MappingProxyType(_CHAR_INFO_TABLE)
del _CHAR_INFO_TABLE

# Any character forbidden in a model or port name (ASCII 0-31, 127 and the 16).
_FORBIDDEN_RE: Final = re.compile(r"[\x00-\x1f\x7f \"&'./:<>?\\|*]")
# Control characters forbidden in an instance name (tab, LF and CR are allowed).
_INSTANCE_RE: Final = re.compile(r"[\x00-\x08\x0b\x0c\x0e-\x1f\x7f]")
# The same characters, each searched for in a whole text (quicker than the pattern).
_INSTANCE_FORBIDDEN: Final = "".join(map(chr, (*range(9), 11, 12, *range(14, 32), 127)))
# Characters escaped when a name is quoted in a one-line message.
_UNPRINTABLE_RE: Final = re.compile(r"[\x00-\x1f\x7f-\x9f\u2028\u2029\ud800-\udfff]")
_ASCII_DIGITS: Final = frozenset("0123456789")
_ASCII_LETTERS: Final = frozenset("ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz")

_MAX_SHOWN_NAME = 80  # code points of a name quoted in a message
_MAX_SHOWN_COLUMNS = 8  # columns listed per character in a message


@dataclass(frozen=True, slots=True)
class BadChar:
    """One offending character of a name."""

    offset: int
    """Code-point index within the name (0-based)."""
    char: str
    category: str
    """The seed table's category: ``whitespace``, ``XML special``, ``path separator``,
    ``wildcard``, ``period`` or ``control character``."""
    reason: str
    """The seed table's reason, e.g. ``breaks XML element/attribute names``."""

    @property
    def shown(self) -> str:
        """The character written visibly, e.g. ``'.' (period)`` or ``U+0009 (tab)``."""
        return _show_char(self.char)

    @property
    def column(self) -> int:
        """1-based column within the name."""
        return self.offset + 1


@dataclass(frozen=True, slots=True)
class Violation:
    """One broken rule of one name."""

    code: str
    """A diagnostic code (defined below, see :mod:`bt_lsp.rules.registry`)."""
    message: str
    """One line: what is wrong, which characters (shown visibly, with columns) and why."""
    chars: tuple[BadChar, ...]
    """Every offending character, for the ``*-forbidden-char``/``*-control-char`` codes."""
    rule: str
    """A short statement of the rule, for hover."""


# --- rule texts ---------------------------------------------------------------------------

_FORBIDDEN_LIST = (
    "whitespace, XML special characters (< > & \" '), path separators (/ \\ :), "
    "wildcards (* ? |), periods or control characters (ASCII 0-31, 127)"
)
_RULE_MODEL_EMPTY: Final = "A model (node type or tree ID) name cannot be empty."
_RULE_MODEL_RESERVED: Final = "'Root' and 'root' are reserved and cannot be used as a model name."
_RULE_MODEL_FORBIDDEN: Final = f"A model name cannot contain {_FORBIDDEN_LIST}."
_MODEL_EMPTY_MESSAGE: Final = "Model name is empty; a node type or tree ID needs a name"
_PORT_EMPTY_MESSAGE: Final = "Port name is empty; a port needs a name"
_RULE_PORT_EMPTY: Final = "A port name cannot be empty."
_RULE_PORT_LEADING_DIGIT: Final = "A port name cannot start with a digit (0-9)."
_RULE_PORT_RESERVED: Final = (
    "A port declared in <TreeNodesModel> cannot use a reserved attribute name: "
    + ", ".join(_RESERVED_PORT_ORDER)
    + " (the name rules, as Groot2 applies them to every model entry)."
)
_RULE_PORT_RESERVED_BTCPP: Final = (
    "A port of a <SubTree> model cannot be named after an attribute BehaviorTree.CPP "
    "reserves: "
    + ", ".join(n for n in _RESERVED_PORT_ORDER if n in BTCPP_RESERVED_ATTRIBUTES)
    + " (BehaviorTree.CPP 4.8.4 and later throw when they load such a model)."
)
_RULE_PORT_GROOT1: Final = (
    "Groot 1 declares __shared_blackboard, BehaviorTree.CPP 3's attribute of a <SubTree> "
    "call, as a port of <SubTree> models; BehaviorTree.CPP 3 does not read them, Groot2 "
    "reserves the name and BehaviorTree.CPP 4 shares a blackboard with _autoremap instead."
)
_RULE_PORT_FORBIDDEN: Final = f"A port name cannot contain {_FORBIDDEN_LIST}."
_RULE_INSTANCE_CONTROL: Final = (
    "An instance name cannot contain control characters other than tab, line feed and "
    "carriage return (ASCII 0-8, 11, 12, 14-31, 127)."
)

#: The rule each name code stands for, as stated in hover.
RULES: Final[Mapping[str, str]] = MappingProxyType(
    {
        "model-name-empty": _RULE_MODEL_EMPTY,
        "model-name-reserved": _RULE_MODEL_RESERVED,
        "model-name-forbidden-char": _RULE_MODEL_FORBIDDEN,
        "port-name-empty": _RULE_PORT_EMPTY,
        "port-name-leading-digit": _RULE_PORT_LEADING_DIGIT,
        "port-name-reserved": _RULE_PORT_RESERVED_BTCPP,
        "port-name-reserved-groot2": _RULE_PORT_RESERVED,
        "port-name-forbidden-char": _RULE_PORT_FORBIDDEN,
        "instance-name-control-char": _RULE_INSTANCE_CONTROL,
        # Where names are born (bt_lsp.rules.cpp_names).
        "cpp-model-name": (
            "A node ID registered in C++ follows the model name rules, or a tree can name it "
            "only in the explicit form <Action ID=...>."
        ),
        "cpp-port-name": (
            "A port name in C++ starts with an ASCII letter, has no forbidden character and is "
            "not a reserved attribute (BehaviorTree.CPP's IsAllowedPortName)."
        ),
    }
)


# --- checks -------------------------------------------------------------------------------


def check_name(name: str, kind: NameKind, *, declaration: bool = False) -> tuple[Violation, ...]:
    """Every rule ``name`` breaks as a ``kind`` of name; ``()`` when it is valid.

    ``declaration`` is true for a port declared in ``<TreeNodesModel>``: only there does a
    reserved attribute name (:data:`RESERVED_PORT_NAMES`) break a rule, ``port-name-reserved``
    for one BehaviorTree.CPP reserves, ``port-name-reserved-groot2`` for the two only the
    name rules reserve. What a document reports for such a declaration depends on the
    entry and the BehaviorTree.CPP version (:func:`reserved_port_declaration`). Port
    violations come in the order empty, leading digit, reserved, forbidden character.
    """
    if kind is NameKind.MODEL:
        if not name:
            return (Violation("model-name-empty", _MODEL_EMPTY_MESSAGE, (), _RULE_MODEL_EMPTY),)
        if name in RESERVED_MODEL_NAMES:
            message = (
                f"Model name {_quote(name)} is reserved; 'Root' and 'root' cannot be used "
                "as a node type or tree ID"
            )
            return (Violation("model-name-reserved", message, (), _RULE_MODEL_RESERVED),)
        if _FORBIDDEN_RE.search(name) is None:
            return ()
        return (
            _char_violation(
                "model-name-forbidden-char",
                "Model",
                "forbidden",
                name,
                _FORBIDDEN_RE,
                _RULE_MODEL_FORBIDDEN,
            ),
        )
    if kind is NameKind.PORT:
        if not name:
            return (Violation("port-name-empty", _PORT_EMPTY_MESSAGE, (), _RULE_PORT_EMPTY),)
        found: list[Violation] = []
        if name[0] in _ASCII_DIGITS:
            message = (
                f"Port name {_quote(name)} starts with the digit '{name[0]}'; "
                "a port name cannot start with a digit"
            )
            found.append(
                Violation("port-name-leading-digit", message, (), _RULE_PORT_LEADING_DIGIT)
            )
        if declaration and name in RESERVED_PORT_NAMES:
            message = (
                f"Port name {_quote(name)} is a reserved attribute name and cannot be "
                "declared as a port"
            )
            if name in BTCPP_RESERVED_ATTRIBUTES:
                found.append(
                    Violation("port-name-reserved", message, (), _RULE_PORT_RESERVED_BTCPP)
                )
            else:
                found.append(
                    Violation("port-name-reserved-groot2", message, (), _RULE_PORT_RESERVED)
                )
        if _FORBIDDEN_RE.search(name) is not None:
            found.append(
                _char_violation(
                    "port-name-forbidden-char",
                    "Port",
                    "forbidden",
                    name,
                    _FORBIDDEN_RE,
                    _RULE_PORT_FORBIDDEN,
                )
            )
        return tuple(found)
    if kind is NameKind.INSTANCE:
        if _INSTANCE_RE.search(name) is None:
            return ()
        return (
            _char_violation(
                "instance-name-control-char",
                "Instance",
                "control",
                name,
                _INSTANCE_RE,
                _RULE_INSTANCE_CONTROL,
            ),
        )
    raise ValueError(f"unknown name kind {kind!r}")  # pragma: no cover


# A name of a "\x00"-joined list that is empty or starts with a digit.
_EMPTY_OR_DIGIT_RE: Final = re.compile(r"(?:^|\x00)(?:[0-9]|\x00|$)")


def all_valid_port_uses(names: Collection[str]) -> bool:
    """Whether no name of ``names`` breaks a rule as a port where it is used (what
    :func:`check_name` with ``NameKind.PORT`` says of each), in a few C-level passes:
    a start tag may hold hundreds of thousands of attributes."""
    if not names:
        return True
    if _FORBIDDEN_RE.search("".join(names)) is not None:  # "\x00" among them
        return False
    return _EMPTY_OR_DIGIT_RE.search("\x00".join(names)) is None


def instance_rule_breaks(text: str) -> Iterator[int]:
    """The offsets of the characters of ``text`` that an instance name may not hold (the
    instance rule of :func:`check_name`), in order: a pass may join many names in one
    search (by a character the rule allows, such as a line feed)."""
    return (m.start() for m in _INSTANCE_RE.finditer(text))


def may_hold_bad_instance_name(text: str) -> bool:
    """Whether an instance name within ``text`` could break its rule: false when no
    character the rule forbids occurs in ``text``, written or as a character reference."""
    return "&#" in text or any(c in text for c in _INSTANCE_FORBIDDEN)


def is_allowed_port_name(name: str) -> bool:
    """BehaviorTree.CPP's ``IsAllowedPortName``: the rule for ports usable from XML.

    True iff ``name`` is non-empty, starts with an ASCII letter, has no forbidden
    character and is not one of BT.CPP's 11 reserved attributes.
    """
    return (
        bool(name)
        and name[0] in _ASCII_LETTERS
        and _FORBIDDEN_RE.search(name) is None
        and name not in BTCPP_RESERVED_ATTRIBUTES
    )


# What each attribute BehaviorTree.CPP reserves is, for the messages.
_RESERVED_MEANING: Final[Mapping[str, str]] = MappingProxyType(
    {
        "ID": "`ID` names the tree a <SubTree> calls",
        "name": "`name` is the instance name of every node",
        "_autoremap": "`_autoremap` is an attribute of the <SubTree> call itself, not a port",
        **{n: f"`{n}` is a precondition script of every node" for n in PRECONDITIONS},
        **{n: f"`{n}` is a postcondition script of every node" for n in POSTCONDITIONS},
    }
)
_BTCPP4_RESERVES = "it reserves only ID, name, _autoremap and the pre/post conditions"


def reserved_port_declaration(name: str, entry: str, btcpp: str | None) -> Violation | None:
    """What a document reports for a port declared as ``name`` in a ``<TreeNodesModel>``
    entry ``<entry>`` when the name is reserved (:data:`RESERVED_PORT_NAMES`), else ``None``.

    ``btcpp`` is the BehaviorTree.CPP major version the file is checked against: ``"3"``,
    ``"4"``, or ``None`` when it is checked as 4 without a build or ``BTCPP_format``
    saying so. BehaviorTree.CPP 3 reads no ``<TreeNodesModel>``; 4 reads only its
    ``<SubTree>`` entries, and since 4.8.4 throws for a port named after an attribute it
    reserves (``validatePortName``). So that is the one error (``port-name-reserved``);
    ``__shared_blackboard`` in a ``<SubTree>`` model of a file not known to be for
    version 4 is Groot 1's convention for version 3 (a hint, ``port-name-groot1``); every
    other reserved name only the name rules (Groot2) reject (``port-name-reserved-groot2``).
    """
    if name not in RESERVED_PORT_NAMES:
        return None
    q = _quote(name)
    subtree = entry == "SubTree"
    if subtree and name == "__shared_blackboard" and btcpp != "4":
        why = (
            "this project builds against BehaviorTree.CPP 3"
            if btcpp == "3"
            else "no BTCPP_format or build says this file is for BehaviorTree.CPP 4"
        )
        message = (
            f"Port {q} of a <SubTree> model is how Groot 1 writes BehaviorTree.CPP 3's "
            f"__shared_blackboard attribute of a <SubTree> call ({why}); BehaviorTree.CPP 3 "
            "does not read <TreeNodesModel>. Groot2's name rules reserve the name, and "
            "BehaviorTree.CPP 4 ignores that attribute: it shares a blackboard with "
            '_autoremap="true"'
        )
        return Violation("port-name-groot1", message, (), _RULE_PORT_GROOT1)
    if subtree and btcpp != "3" and name in BTCPP_RESERVED_ATTRIBUTES:
        message = (
            f"Port name {q} is reserved by BehaviorTree.CPP: {_RESERVED_MEANING[name]}. "
            "BehaviorTree.CPP 4.8.4 and later throw when they load this <SubTree> model "
            f'("Port name {q} is a reserved attribute name"); 4.0 to 4.8.3 accepted it'
        )
        return Violation("port-name-reserved", message, (), _RULE_PORT_RESERVED_BTCPP)
    start = f"Port name {q} is reserved by the name rules (Groot2 rejects it)"
    if btcpp == "3":
        message = (
            f"{start}; BehaviorTree.CPP 3, which this project builds against, does not "
            "read <TreeNodesModel>"
        )
        if subtree and name in BTCPP_RESERVED_ATTRIBUTES:
            message += ", and BehaviorTree.CPP 4.8.4 and later throw when they load it"
    elif not subtree:
        message = (
            f"{start}; BehaviorTree.CPP reads only the <SubTree> entries of "
            "<TreeNodesModel>, but no C++ node can declare a port of that name "
            "(BehaviorTree.CPP 4's CreatePort throws for it), so this entry describes a port "
            "its node cannot have"
        )
    elif name == "__shared_blackboard":
        message = (
            f"{start}; BehaviorTree.CPP 4 accepts it in a <SubTree> model "
            f"({_BTCPP4_RESERVES}) but ignores a __shared_blackboard attribute of a "
            "<SubTree> call, BehaviorTree.CPP 3's way of sharing the blackboard: version 4 "
            'shares it with _autoremap="true"'
        )
    else:
        message = (
            f"{start}; BehaviorTree.CPP 4 accepts it in a <SubTree> model "
            f"({_BTCPP4_RESERVES}) but never passes a <SubTree> attribute of that name on "
            "as a remapping (it does not start with a letter), so the port only takes its "
            "default"
        )
    return Violation("port-name-reserved-groot2", message, (), _RULE_PORT_RESERVED)


# --- helpers ------------------------------------------------------------------------------


def _bad_chars(name: str, pattern: re.Pattern[str]) -> tuple[BadChar, ...]:
    result: list[BadChar] = []
    for match in pattern.finditer(name):
        char = match.group()
        category = _CHAR_INFO[char][0]
        result.append(BadChar(match.start(), char, category, _REASONS[category][0]))
    return tuple(result)


def _char_violation(
    code: str, subject: str, adjective: str, name: str, pattern: re.Pattern[str], rule: str
) -> Violation:
    chars = _bad_chars(name, pattern)
    columns: dict[str, list[int]] = {}
    categories: dict[str, None] = {}
    for bad in chars:
        columns.setdefault(bad.char, []).append(bad.offset + 1)
        categories.setdefault(bad.category, None)
    listed = ", ".join(f"{_show_char(c)} at {_columns(cols)}" for c, cols in columns.items())
    why = ", ".join(_REASONS[category][1] for category in categories)
    if len(chars) == 1:
        counted = f"a {adjective} character"
    else:
        counted = f"{len(chars)} {adjective} characters"
    message = f"{subject} name {_quote(name)} contains {counted}: {listed}; {why}"
    return Violation(code, message, chars, rule)


def _columns(cols: list[int]) -> str:
    if len(cols) == 1:
        return f"column {cols[0]}"
    if len(cols) > _MAX_SHOWN_COLUMNS:
        shown = ", ".join(str(c) for c in cols[:_MAX_SHOWN_COLUMNS])
        return f"columns {shown} and {len(cols) - _MAX_SHOWN_COLUMNS} more"
    return "columns " + ", ".join(str(c) for c in cols[:-1]) + f" and {cols[-1]}"


def _show_char(char: str) -> str:
    info = _CHAR_INFO.get(char)
    label = info[1] if info is not None else "character"
    code = ord(char)
    if code < 0x20 or code == 0x7F:
        return f"U+{code:04X} ({label})"
    if char == "'":
        return f'"\'" ({label})'
    if char == "\\":
        return f"'\\\\' ({label})"
    return f"'{char}' ({label})"


def _escape(match: re.Match[str]) -> str:
    char = match.group()
    special = {"\t": "\\t", "\n": "\\n", "\r": "\\r"}.get(char)
    if special is not None:
        return special
    code = ord(char)
    return f"\\x{code:02x}" if code < 0x100 else f"\\u{code:04x}"


def _quote(name: str) -> str:
    """``name`` in single quotes, on one line, control characters escaped, long names cut."""
    shown = name if len(name) <= _MAX_SHOWN_NAME else name[: _MAX_SHOWN_NAME - 1] + "…"
    if _UNPRINTABLE_RE.search(shown) is not None:
        # Escaped, so a backslash of the name is doubled to keep it unambiguous.
        shown = _UNPRINTABLE_RE.sub(_escape, shown.replace("\\", "\\\\"))
    return f"'{shown}'"
