"""The pinned code set of the whole-output tests (:mod:`tests.pinned`)."""

from __future__ import annotations

from bt_lsp.rules.codes import Severity
from bt_lsp.rules.diagnostics import Diagnostic
from bt_lsp.rules.registry import CODES
from tests.pinned import LATER, PINNED_CODES, later_off, pinned


def test_every_pinned_code_still_exists() -> None:
    gone = sorted(PINNED_CODES - set(CODES))
    assert gone == [], (
        f"{gone} no longer in the registry: take them out of tests/pinned.py and update the "
        "tests that expect them"
    )


def test_codes_defined_later_are_hidden_but_the_ones_a_test_is_about() -> None:
    assert set(CODES) - PINNED_CODES == LATER
    if not LATER:
        assert later_off() == []
    old = Diagnostic(0, 1, "child-count", "m", Severity.ERROR)
    outside = Diagnostic(0, 1, "file-error", "m", Severity.ERROR)  # not a registry code
    for code in LATER:
        new = Diagnostic(0, 1, code, "m", Severity.HINT)
        assert pinned([old, new, outside]) == [old, outside]
        assert pinned([old, new], also=[code]) == [old, new]
        cap = Diagnostic(0, 0, "too-many-problems", "m", Severity.HINT)
        assert pinned([old, new, cap]) == [old]  # the cap counted the new one
        assert pinned([old, cap]) == [old, cap]
        assert f"{code}=off" in later_off()[1].split(",")
        assert f"{code}=off" not in "".join(later_off(also=[code]))
