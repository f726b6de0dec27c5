"""The vocabulary of BT XML names, shared by the model (which reads a name as a model, port
or instance name) and the name rules: the kinds of names, the characters the rules forbid,
and BehaviorTree.CPP's reserved attributes."""

from __future__ import annotations

import enum
from typing import Final

__all__ = [
    "BTCPP_RESERVED_ATTRIBUTES",
    "CONTROL_CHARS",
    "FORBIDDEN",
    "POSTCONDITIONS",
    "PRECONDITIONS",
    "RESERVED_MODEL_NAMES",
    "RESERVED_PORT_NAMES",
    "NameKind",
]


class NameKind(enum.StrEnum):
    """Where a name is used; each kind has its own rules."""

    MODEL = "model"
    PORT = "port"
    INSTANCE = "instance"


#: The 16 ASCII characters forbidden in model and port names (besides ASCII 0-31 and 127).
FORBIDDEN: Final[frozenset[str]] = frozenset(" \t\n\r<>&\"'/\\:*?|.")

#: BehaviorTree.CPP's precondition attributes, in its ``PreCond`` order.
PRECONDITIONS: Final[tuple[str, ...]] = ("_failureIf", "_successIf", "_skipIf", "_while")
#: BehaviorTree.CPP's postcondition attributes, in its ``PostCond`` order.
POSTCONDITIONS: Final[tuple[str, ...]] = ("_onHalted", "_onFailure", "_onSuccess", "_post")

#: BehaviorTree.CPP's ``IsReservedAttribute``: exactly these 11 names (case-sensitive).
BTCPP_RESERVED_ATTRIBUTES: Final[frozenset[str]] = frozenset(
    ("ID", "name", "_autoremap", *PRECONDITIONS, *POSTCONDITIONS)
)

#: The seed's 13 reserved attribute names: BT.CPP's 11 plus ``_description`` and the v3
#: spelling ``__shared_blackboard``. A port declared in ``<TreeNodesModel>`` must not use one.
RESERVED_PORT_NAMES: Final[frozenset[str]] = BTCPP_RESERVED_ATTRIBUTES | {
    "_description",
    "__shared_blackboard",
}

#: Model names BehaviorTree.CPP rejects (exact match: ``ROOT`` is accepted).
RESERVED_MODEL_NAMES: Final[frozenset[str]] = frozenset({"Root", "root"})

#: ASCII control characters (0-31 and 127), forbidden in model and port names too.
CONTROL_CHARS: Final[frozenset[str]] = frozenset({chr(c) for c in range(32)} | {"\x7f"})
