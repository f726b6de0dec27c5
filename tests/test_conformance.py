"""BehaviorTree.CPP's own unit tests as an oracle: ``compare.py --models`` must pass.

``data/btcpp-gtests`` holds every XML that BehaviorTree.CPP 4.10's gtests feed to the
library, the nodes each test registers (``models.xml``, given to ``bt-lsp check --models``
as the authoritative catalog) and what the test expects.  Every load or creation failure
must be an error with the cause's code, and no valid case may get an error or a warning,
except the cases listed in ``known.json`` with their reason (differences made on purpose,
and failures that only the C++ can tell).  A listed case that starts to agree fails the
run too, so that the list stays exact.

Unlike the whole-output tests (:mod:`tests.pinned`), it sees every code, new ones too: an
error or a warning on a case BehaviorTree.CPP loads is a false alarm whatever the rule,
and a new code cannot make a caught failure a miss.  Its failure names the new codes.

The cases are checked in this process, as ``bt-lsp check`` checks them (one process per
case took minutes); one case still runs through the command to show that both agree.
"""

from __future__ import annotations

import contextlib
import importlib.util
import io
import json
import os
import subprocess
import sys
from pathlib import Path
from types import ModuleType

from tests.oracle.btlsp import check_folder
from tests.pinned import LATER

HERE = Path(__file__).parent
SUITE = HERE / "data" / "btcpp-gtests"
SRC = HERE.parent / "src"


def _compare() -> ModuleType:
    """compare.py (a script, not a package module)."""
    spec = importlib.util.spec_from_file_location("btcpp_compare", SUITE / "compare.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_compare_with_models_passes_but_for_the_known_limits() -> None:
    """Every case, checked in this process as ``bt-lsp check`` checks it."""
    out = io.StringIO()
    argv = ["compare.py", "(in process)", "--models", "--known", str(SUITE / "known.json")]
    with contextlib.redirect_stdout(out):
        status = _compare().main(argv, runner=check_folder)
    assert status == 0, out.getvalue() + _new_codes(out.getvalue())
    summary = out.getvalue().strip().splitlines()[-1]
    known = json.loads((SUITE / "known.json").read_text(encoding="utf-8"))
    assert summary.endswith(f"known: {len(known)})"), summary


def _new_codes(report: str) -> str:
    """What the report says of codes defined after the whole-output tests."""
    new = sorted(c for c in LATER if f" {c} " in report)
    if not new:
        return ""
    return (
        f"\n{', '.join(new)}: defined since tests/pinned.py was written. An error or a "
        "warning of them on a case that BehaviorTree.CPP loads (FALSE-ALARM) is a false "
        "alarm of the new rule: narrow it, make it a hint, or list the case in known.json "
        "with the reason."
    )


def test_the_command_reports_what_the_in_process_check_does(tmp_path: Path) -> None:
    """One case end to end through ``bt-lsp check``: the in-process runs stand for it."""
    folder = SUITE / "gtest_factory__NotRegisteredNode"
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(filter(None, [str(SRC), env.get("PYTHONPATH")]))
    compare = _compare()
    empty = tmp_path / "empty_models.xml"
    empty.write_text(compare.EMPTY_CATALOG, encoding="utf-8")
    catalog = compare.catalog_of(str(folder), str(empty))
    argv = [sys.executable, "-m", "bt_lsp", "check", str(folder), *compare.case_files(str(folder))]
    argv += ["--format", "json"]
    proc = subprocess.run(
        [*argv, "--no-progress", "--models", catalog],
        capture_output=True,
        text=True,
        env=env,
        timeout=120,
        check=False,
    )
    assert proc.returncode == 1, proc.stderr
    by_command = json.loads(proc.stdout)
    assert by_command == check_folder(str(folder), catalog)
    assert {(d["severity"], d["code"]) for d in by_command} == {("error", "unknown-node")}


def test_every_known_limit_says_why() -> None:
    known = json.loads((SUITE / "known.json").read_text(encoding="utf-8"))
    cases = {c["case"] for c in json.loads((SUITE / "expected.json").read_text("utf-8"))}
    assert set(known) <= cases
    for reason in known.values():
        assert reason.split(":")[0] in ("needs C++", "intended")
