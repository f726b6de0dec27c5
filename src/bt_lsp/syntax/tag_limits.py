"""What one start tag keeps of its attributes, so that hostile input costs memory in
proportion to what is shown, not to its size.

A tag keeps its first :data:`MAX_ATTRS` attributes (no BehaviorTree.CPP node has nearly
that many ports) and its first :data:`MAX_DUPLICATES` duplicate attributes, each reported
(tinyxml2 refuses the document at the first one).  The others are read, so that the tag
ends where it ends, but only counted: one problem says how many were left out from where.
"""

from __future__ import annotations

XML_SYNTAX = "xml-syntax"
TOO_MANY_ATTRIBUTES = "too-many-attributes"
MAX_ATTRS = 1000
MAX_DUPLICATES = 20
MAX_TAG_PROBLEMS = 100  # what one malformed tag reports at most


class TagLimits:
    """The attributes of one tag left out (see :data:`MAX_ATTRS`), and where the first
    of each kind is."""

    __slots__ = ("at", "dropped", "dropped_dups", "dup_at", "dups")

    def __init__(self) -> None:
        self.dups = self.dropped_dups = self.dropped = 0
        self.dup_at = self.at = (0, 0)

    def duplicate(self, ns: int, ne: int) -> bool:
        """Count a duplicate attribute; whether it is left out."""
        self.dups += 1
        if self.dups <= MAX_DUPLICATES:
            return False
        if not self.dropped_dups:
            self.dup_at = (ns, ne)
        self.dropped_dups += 1
        return True

    def beyond(self, ns: int, ne: int) -> None:
        """Count an attribute beyond :data:`MAX_ATTRS`."""
        if not self.dropped:
            self.at = (ns, ne)
        self.dropped += 1

    def keeps(self, duplicate: bool, kept: int, ns: int, ne: int) -> bool:
        """Whether the attribute at ``ns``-``ne`` is kept (``kept`` are, so far)."""
        if duplicate:
            return not self.duplicate(ns, ne)
        if kept >= MAX_ATTRS:
            self.beyond(ns, ne)
            return False
        return True

    def problems(self, name: str, kept: int) -> list[tuple[int, int, str, str]]:
        """What is left out, as (start, end, code, message) relative to the tag."""
        out: list[tuple[int, int, str, str]] = []
        if self.dropped_dups:
            out.append(
                (
                    *self.dup_at,
                    XML_SYNTAX,
                    f"{self.dropped_dups} more duplicate attributes in tag '<{name}' "
                    f"from here (only the first {MAX_DUPLICATES} are listed)",
                )
            )
        if self.dropped:
            out.append(
                (
                    *self.at,
                    TOO_MANY_ATTRIBUTES,
                    f"Tag '<{name}' has {kept + self.dropped} attributes: only the first "
                    f"{MAX_ATTRS} are read, the {self.dropped} from here are not checked",
                )
            )
        return out
