"""bt-lsp's side of a comparison: ``bt-lsp check FOLDER --format json --models CATALOG``
run in this process (what the command does after reading its arguments)."""

from __future__ import annotations

import io
import json
import os
import tempfile
from collections.abc import Sequence
from dataclasses import dataclass, field
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


@dataclass(slots=True)
class Workspace:
    """One folder that every case is written into in turn (the previous case's files
    removed first): creating and removing a temporary folder per case costs more than
    bt-lsp's check of it.  bt-lsp builds a fresh workspace index on each check, so
    nothing of one case is seen by the next.  Use as a context manager."""

    base: str | None = None  # where to make the folder (default: the system's)
    _tmp: tempfile.TemporaryDirectory[str] | None = field(default=None, init=False)
    _written: list[str] = field(default_factory=list, init=False)

    def __enter__(self) -> Workspace:
        return self

    def __exit__(self, *exc: object) -> None:
        if self._tmp is not None:
            self._tmp.cleanup()
            self._tmp = None

    def _root(self) -> str:
        if self._tmp is None:
            self._tmp = tempfile.TemporaryDirectory(prefix="bt-lsp-oracle-", dir=self.base)
        return self._tmp.name

    def check(
        self, files: Sequence[tuple[str, str]], actions: Sequence[str], conditions: Sequence[str]
    ) -> list[dict[str, Any]]:
        """bt-lsp's diagnostics of ``files`` (the first includes the others) checked as
        one workspace, with the custom nodes as the authoritative catalog; each with its
        file's name as ``file``."""
        root = self._root()
        folder = os.path.join(root, "ws")
        for path in self._written:
            os.unlink(path)
        self._written.clear()
        for name, text in files:
            path = os.path.join(folder, name)
            os.makedirs(os.path.dirname(path), exist_ok=True)
            with open(path, "w", encoding="utf-8", newline="") as fh:
                fh.write(text)
            self._written.append(path)
        models = os.path.join(root, "models.xml")
        with open(models, "w", encoding="utf-8") as fh:
            fh.write(catalog(actions, conditions))
        found = check_folder(folder, models)
        assert not isinstance(found, str), found
        for d in found:
            d["file"] = os.path.relpath(d["path"], folder)
        return found


def check_files(
    files: Sequence[tuple[str, str]], actions: Sequence[str], conditions: Sequence[str]
) -> list[dict[str, Any]]:
    """:meth:`Workspace.check` in a folder of its own."""
    with Workspace() as ws:
        return ws.check(files, actions, conditions)
