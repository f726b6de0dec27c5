"""BehaviorTree.CPP itself (the ``behaviortreepy`` bindings of 4.8.2) as an oracle.

The library runs in a worker process: a crash (a recursive SubTree overflows the C++
stack) or a hang must not take the test run with it.  One worker answers many cases, one
JSON line in and one out each; a case that takes longer than its time limit, or kills the
worker, gets the verdict ``timeout`` or ``crash`` and the next case gets a fresh worker.

A case is a set of XML files (the first is the one loaded; the others are written next to
it, for its ``<include>``) and the custom node IDs it registers as port-less simple
actions and conditions.  The verdict says where BehaviorTree.CPP failed:

* ``load``: the XML did not load (``registerBehaviorTreeFromFile/Text``: parsing,
  ``VerifyXML``, includes);
* ``create``: it loaded, but creating the main tree, or any tree by its ID, failed
  (unknown SubTree, ports, scripts);
* ``tick``: the trees were created, and one of the first ``ticks`` ticks of one threw;
* ``ok``: none of these (``status`` is the last tick's status, when ticked).
"""

from __future__ import annotations

import contextlib
import json
import os
import selectors
import subprocess
import sys
import tempfile
import time
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, field
from typing import Any, Final, Literal

Stage = Literal["ok", "load", "create", "tick", "crash", "timeout"]

TIME_LIMIT: Final = 5.0  # seconds for one case, start of the worker not counted


@dataclass(frozen=True, slots=True)
class Case:
    """XML files (``(name, text)``, the first is loaded), the custom nodes to register,
    and how many times to tick the created tree."""

    files: tuple[tuple[str, str], ...]
    actions: tuple[str, ...] = ()
    conditions: tuple[str, ...] = ()
    ticks: int = 1

    @property
    def main(self) -> str:
        return self.files[0][1]

    def as_json(self) -> dict[str, Any]:
        return {
            "files": [list(f) for f in self.files],
            "actions": list(self.actions),
            "conditions": list(self.conditions),
            "ticks": self.ticks,
        }


@dataclass(frozen=True, slots=True)
class Verdict:
    """What BehaviorTree.CPP did with a case (``message``: its exception's text)."""

    stage: Stage
    message: str = ""
    status: str | None = None
    tree: str | None = None  # the tree created by its ID that failed ("": the main tree)
    # Several trees, none named by main_tree_to_execute: createTreeFromText fails, and the
    # verdict is that of creating each tree by its ID.
    unspecified_main: bool = False

    @property
    def ok(self) -> bool:
        return self.stage == "ok"

    def __str__(self) -> str:
        if self.ok:
            return f"ok ({self.status})" if self.status else "ok"
        return f"throws at {self.stage}: {' '.join(self.message.split())}"


@dataclass(slots=True)
class Oracle:
    """A worker process that runs cases through BehaviorTree.CPP, restarted when it dies.

    :meth:`submit` sends a case and :meth:`result` waits for its verdict, so that the
    caller can work (run bt-lsp) while the library does.  Use as a context manager."""

    time_limit: float = TIME_LIMIT
    python: str = sys.executable
    _proc: subprocess.Popen[bytes] | None = field(default=None, init=False)
    _buffer: bytes = field(default=b"", init=False)
    _pending: bool = field(default=False, init=False)
    _sent: float = field(default=0.0, init=False)
    _stderr: Any = field(default=None, init=False)  # the worker's stderr, kept in a file
    _said: int = field(default=0, init=False)  # its size when the pending case was sent
    restarts: int = field(default=0, init=False)

    def __enter__(self) -> Oracle:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def close(self) -> None:
        if self._stderr is not None:
            self._stderr.close()
            self._stderr = None
        proc, self._proc = self._proc, None
        if proc is None:
            return
        with contextlib.suppress(OSError):
            assert proc.stdin is not None
            proc.stdin.close()
        try:
            proc.wait(timeout=2)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait()

    def _start(self) -> subprocess.Popen[bytes]:
        if self._stderr is None:
            self._stderr = tempfile.TemporaryFile()  # noqa: SIM115 - closed by close()
        if self._proc is None or self._proc.poll() is not None:
            if self._proc is not None:
                self.restarts += 1
            self._buffer = b""
            self._proc = subprocess.Popen(
                [self.python, os.path.abspath(__file__), "--worker"],
                stdin=subprocess.PIPE,
                stdout=subprocess.PIPE,
                stderr=self._stderr,
            )
        return self._proc

    def _kill(self) -> None:
        proc, self._proc = self._proc, None
        if proc is not None:
            proc.kill()
            proc.wait()
            self.restarts += 1

    def submit(self, case: Case) -> None:
        assert not self._pending, "one case at a time: call result() first"
        proc = self._start()
        assert proc.stdin is not None
        self._said = os.fstat(self._stderr.fileno()).st_size  # before the worker can write
        try:
            proc.stdin.write(json.dumps(case.as_json()).encode() + b"\n")
            proc.stdin.flush()
        except OSError:
            self._kill()
            proc = self._start()
            assert proc.stdin is not None
            proc.stdin.write(json.dumps(case.as_json()).encode() + b"\n")
            proc.stdin.flush()
        self._pending = True
        self._sent = time.monotonic()

    def result(self) -> Verdict:
        assert self._pending, "submit() a case first"
        self._pending = False
        proc = self._proc
        assert proc is not None and proc.stdout is not None
        fd = proc.stdout.fileno()
        deadline = self._sent + self.time_limit
        with selectors.DefaultSelector() as sel:
            sel.register(fd, selectors.EVENT_READ)
            while b"\n" not in self._buffer:
                left = deadline - time.monotonic()
                if left <= 0:
                    self._kill()
                    said = self._last_words()
                    return Verdict("timeout", f"no answer within {self.time_limit:g} s{said}")
                if not sel.select(left):
                    continue
                chunk = os.read(fd, 65536)
                if not chunk:
                    code = proc.wait()
                    self._proc = None
                    self.restarts += 1
                    said = self._last_words()
                    return Verdict("crash", f"the worker died (exit status {code}){said}")
                self._buffer += chunk
        line, _, self._buffer = self._buffer.partition(b"\n")
        data = json.loads(line)
        return Verdict(
            data["stage"],
            data.get("message", ""),
            data.get("status"),
            data.get("tree"),
            data.get("unspecified_main", False),
        )

    def _last_words(self) -> str:
        """What the worker wrote on stderr for the pending case (the C++ runtime's
        ``terminate called after throwing ...``), its last 1,000 bytes."""
        self._stderr.seek(max(self._said, os.fstat(self._stderr.fileno()).st_size - 1000))
        text = self._stderr.read().decode("utf-8", "replace").strip()
        self._stderr.seek(0, os.SEEK_END)
        return f": {text}" if text else ""

    def run(self, case: Case) -> Verdict:
        self.submit(case)
        return self.result()

    def run_many(self, cases: Sequence[Case]) -> Iterator[Verdict]:
        for case in cases:
            yield self.run(case)


# -- the worker ------------------------------------------------------------------------------


def _answer(case: dict[str, Any]) -> dict[str, Any]:  # pragma: no cover - in the worker
    """Load, create and tick one case with the library, in a fresh factory per stage."""
    import behaviortreepy as bt

    def factory() -> Any:
        f = bt.BehaviorTreeFactory()
        for name in case["actions"]:
            f.register_simple_action(name, lambda node: bt.NodeStatus.SUCCESS)
        for name in case["conditions"]:
            f.register_simple_condition(name, lambda node: bt.NodeStatus.SUCCESS)
        return f

    files = case["files"]
    text = files[0][1]
    here = os.getcwd()
    with tempfile.TemporaryDirectory(prefix="bt-oracle-") as tmp:
        for name, content in files:
            path = os.path.join(tmp, name)
            os.makedirs(os.path.dirname(path), exist_ok=True)
            with open(path, "w", encoding="utf-8") as fh:
                fh.write(content)
        # A document loaded from text finds its includes from the working folder.
        os.chdir(tmp)
        try:
            return _stages(factory, text, case["ticks"])
        finally:
            os.chdir(here)


def _stages(factory: Any, text: str, ticks: int) -> dict[str, Any]:  # pragma: no cover
    """Load in one factory; create the main tree in another; then create (and tick) every
    tree by its ID, as an application that calls ``createTree(ID)`` would.  Each factory
    is kept alive while its trees are."""
    try:
        factory().register_behavior_tree_from_text(text)
    except Exception as e:
        return {"stage": "load", "message": str(e)}
    f = factory()
    unspecified = False
    try:
        trees = [("", f.create_tree_from_text(text))]
    except Exception as e:
        if "[main_tree_to_execute] was not specified" not in str(e):
            return {"stage": "create", "message": str(e)}
        unspecified, trees = True, []
    every = factory()
    every.register_behavior_tree_from_text(text)
    for tree_id in every.registered_behavior_trees():
        try:
            trees.append((tree_id, every.create_tree(tree_id)))
        except Exception as e:
            return {"stage": "create", "message": str(e), "tree": tree_id}
    status = None
    for tree_id, tree in trees:
        try:
            for _ in range(ticks):
                status = str(tree.tick_once()).rpartition(".")[2]
                if status in ("SUCCESS", "FAILURE"):
                    break
        except Exception as e:
            return {"stage": "tick", "message": str(e), "tree": tree_id}
        finally:
            with contextlib.suppress(Exception):
                tree.halt_tree()
    answer: dict[str, Any] = {"stage": "ok", "status": status}
    if unspecified:
        answer["unspecified_main"] = True
    return answer


def _worker() -> None:  # pragma: no cover - in the worker
    """Answer cases from stdin; the library's own prints go to stderr, not the answers."""
    out = os.fdopen(os.dup(1), "w", encoding="utf-8")
    os.dup2(2, 1)
    for line in sys.stdin:
        if not line.strip():
            continue
        answer = _answer(json.loads(line))
        out.write(json.dumps(answer) + "\n")
        out.flush()


if __name__ == "__main__":  # pragma: no cover - the worker's entry
    if sys.argv[1:] == ["--worker"]:
        _worker()
