"""The one table of every diagnostic code.

Each rule defines its codes beside itself (:func:`bt_lsp.rules.codes.define`); this module
imports every module that defines one, so :data:`CODES` is complete: the documentation's code
table and pages (``scripts/docs_gen.py``), the server's ``codeDescription`` links, SARIF rules and
the severity settings read it.  Ordered by family, then by name.
"""

from __future__ import annotations

from collections.abc import Mapping
from types import MappingProxyType
from typing import Final

from bt_lsp.rules import (  # noqa: F401  (they define codes)
    configuration,
    cpp_names,
    diagnostics,
    includes,
    names,
)
from bt_lsp.rules.codes import BT, NAMES, PROJECT, XML, Code, all_defined, freeze
from bt_lsp.rules.semantics import (  # noqa: F401  (they define codes)
    base,
    document,
    models,
    nodes,
    ports,
    scripts,
    trees,
)

freeze()  # every module that defines a code is imported: none is defined later

#: The families in the order the documentation lists them, with their headings.
FAMILIES: Final[Mapping[str, str]] = MappingProxyType(
    {NAMES: "Name rules", XML: "XML", BT: "BehaviorTree.CPP semantics", PROJECT: "Project"}
)

CODES: Final[Mapping[str, Code]] = MappingProxyType(
    {
        c.code: c
        for c in sorted(
            all_defined().values(), key=lambda c: (list(FAMILIES).index(c.family), c.code)
        )
    }
)

__all__ = ["CODES", "FAMILIES"]
