"""bt-lsp's side of a comparison: ``bt-lsp check FOLDER --format json --models CATALOG``
run in this process (what the command does after reading its arguments)."""

from __future__ import annotations

import io
import json
import os
import tempfile
from collections.abc import Sequence
from typing import Any, Final

from bt_lsp.cli import check
from bt_lsp.rules.codes import NAMES, defined
from bt_lsp.rules.registry import CODES

# The codes of the name rules (bt-lsp's own, stricter than BehaviorTree.CPP 4.8.2).
NAME_CODES: Final = frozenset(c for c in CODES if defined(c).family == NAMES)


def check_folder(folder: str, models: str | None) -> list[dict[str, Any]] | str:
    """The JSON diagnostics of ``bt-lsp check folder [--models models]``, or why there are
    none (what the command printed on stderr)."""
    out, err = io.StringIO(), io.StringIO()
    options = check.Options(
        format="json",
        progress=False,
        models=(os.path.abspath(models),) if models else (),
    )
    # Each file is named too, as compare.py does: BehaviorTree.CPP is fed every one.
    fed = sorted(
        os.path.join(folder, f)
        for f in os.listdir(folder)
        if f.endswith(".xml") and f != "models.xml"
    )
    check.run([folder, *fed], options, out=out, err=err)
    text = out.getvalue()
    if not text.strip():
        return f"no JSON from bt-lsp: {err.getvalue().strip()[:200]}"
    found = json.loads(text)
    assert isinstance(found, list)
    return found


def catalog(actions: Sequence[str], conditions: Sequence[str]) -> str:
    """The catalog BehaviorTree.CPP's ``writeTreeNodesModelXML`` writes for a factory that
    registers these port-less custom nodes."""
    lines = ['<root BTCPP_format="4">', "  <TreeNodesModel>"]
    lines += [f'    <Action ID="{a}"/>' for a in actions]
    lines += [f'    <Condition ID="{c}"/>' for c in conditions]
    lines += ["  </TreeNodesModel>", "</root>", ""]
    return "\n".join(lines)


def check_files(
    files: Sequence[tuple[str, str]], actions: Sequence[str], conditions: Sequence[str]
) -> list[dict[str, Any]]:
    """bt-lsp's diagnostics of ``files`` (the first includes the others) checked as one
    workspace, with the custom nodes as the authoritative catalog; each with its file's
    name as ``file``."""
    with tempfile.TemporaryDirectory(prefix="bt-lsp-oracle-") as tmp:
        folder = os.path.join(tmp, "ws")
        for name, text in files:
            path = os.path.join(folder, name)
            os.makedirs(os.path.dirname(path), exist_ok=True)
            with open(path, "w", encoding="utf-8", newline="") as fh:
                fh.write(text)
        models = os.path.join(tmp, "models.xml")
        with open(models, "w", encoding="utf-8") as fh:
            fh.write(catalog(actions, conditions))
        found = check_folder(folder, models)
        assert not isinstance(found, str), found
        for d in found:
            d["file"] = os.path.relpath(d["path"], folder)
        return found
