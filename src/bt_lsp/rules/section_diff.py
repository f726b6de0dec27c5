"""Which sections of a model are new since an earlier model of the same document.

The builder keeps every section an edit cannot have changed as the same object, before
and after the changed ones, so the two lists of sections begin and end alike and differ in
one run between: comparing identities from both ends finds it (in C), where sets of
sections would cost a hash table as large as the document's sections, kept per document.
"""

from __future__ import annotations

from collections.abc import Sequence
from itertools import compress, count
from operator import is_not

from bt_lsp.syntax.sections import Section


def common_ends(old: Sequence[Section], new: Sequence[Section]) -> tuple[int, int]:
    """How many sections ``old`` and ``new`` begin with and, after those, end with (the
    same objects): ``new[p : len(new) - q]`` replaced ``old[p : len(old) - q]``."""
    most = min(len(old), len(new))
    p = next(compress(count(), map(is_not, old, new)), most)
    q = next(compress(count(), map(is_not, reversed(old), reversed(new))), most)
    return p, min(q, most - p)
