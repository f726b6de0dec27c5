"""The core run by two threads at once, as the language server runs it: the event loop
edits documents, takes snapshots and answers hover, definition and references on the open
documents, while the worker thread analyses the snapshots (holding the document's
history lock, as ``DiagnosticsCache.compute`` does) and reads their sections' names.
Nothing may raise, and every result must equal a single-threaded run on the same text.

Bounded in time: ``BT_LSP_RACE_SECONDS`` (10 by default; 60 or more on demand).
"""

from __future__ import annotations

import os
import sys
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass

from bt_lsp.ide.definition import definition
from bt_lsp.ide.hover import hover_at
from bt_lsp.ide.references import references
from bt_lsp.rules.analysis import analyze
from bt_lsp.rules.context import Context
from bt_lsp.syntax.document import Document

SECONDS = float(os.environ.get("BT_LSP_RACE_SECONDS", "10"))

# Two documents hold more trees than a cache of recently asked sections would (64): the
# names of one document kept while the other thread makes those of the other.
_TREES = 40


def _text(tag: str) -> str:
    trees = "".join(
        f"""  <BehaviorTree ID="Tree{i}">
    <Sequence name="seq{i}">
      <{tag} goal="{{goal{i}}}" speed="0.{i % 10}"/>
      <SubTree ID="Tree{(i + 1) % _TREES}" goal="{{goal{i}}}"/>
      <Script code="count{i} := count{i} + 1"/>
      <Frob{i % 7} frob="x"/>
    </Sequence>
  </BehaviorTree>
"""
        for i in range(_TREES)
    )
    models = "".join(
        f'    <Action ID="Frob{k}"><input_port name="frob"/></Action>\n' for k in range(7)
    )
    return f"""<root BTCPP_format="4" main_tree_to_execute="Tree0">
{trees}  <TreeNodesModel>
    <Action ID="{tag}"><input_port name="goal"/><input_port name="speed"/></Action>
{models}  </TreeNodesModel>
</root>
"""


@dataclass(frozen=True)
class _Expected:
    """What a single-threaded run finds in one text."""

    diagnostics: tuple[object, ...]
    refs: tuple[tuple[object, ...], ...]
    answers: tuple[object, ...]


def _diagnostics(doc: Document) -> tuple[object, ...]:
    return tuple((d.start, d.end, d.code, d.message) for d in analyze(doc))


def _section_refs(doc: Document) -> tuple[tuple[object, ...], ...]:
    return tuple(tuple(sec.refs) for sec in doc.model.sections)


def _offsets(text: str) -> list[int]:
    """Where the requests are asked: node types, ports, tree IDs, keys, instance names."""
    out: list[int] = []
    for needle in ("<Frob3", 'goal="{goal4', 'ID="Tree7"', "<GoTo", 'name="seq9', "count2 :="):
        at = 0
        while (at := text.find(needle, at)) != -1:
            out.append(at + min(3, len(needle) - 1))
            at += len(needle)
            if len(out) % 4 == 0:
                break
    return out


def _answers(doc: Document, offsets: list[int]) -> tuple[object, ...]:
    ctx = Context.from_document(doc)
    out: list[object] = []
    for at in offsets:
        out.append(hover_at(doc, at, ctx))
        out.append(tuple(definition(doc, at, ctx=ctx)))
        out.append(tuple(references(doc, at)))
    return tuple(out)


def _expected(text: str, offsets: list[int]) -> _Expected:
    doc = Document(text, "race.xml")
    return _Expected(_diagnostics(doc), _section_refs(doc), _answers(doc, offsets))


def test_two_threads_share_documents_without_errors_or_different_results() -> None:
    text = _text("GoTo")
    edit_at = text.index("<GoTo", len(text) // 2) + len("<GoTo")
    texts = [text, text[:edit_at] + " " + text[edit_at:]]  # a space typed after a tag name
    offsets = _offsets(texts[0])  # before the edit: the same offsets in both texts
    assert len(offsets) >= 12
    expected = [_expected(t, offsets) for t in texts]
    docs = [Document(texts[0], f"race{k}.xml") for k in range(2)]
    states = [0, 0]  # which text each document holds
    snapshots: list[tuple[Document, int]] = []
    lock = threading.Lock()  # guards the list of snapshots (as the server's queue)
    errors: list[BaseException] = []
    mismatches: list[str] = []
    deadline = time.monotonic() + SECONDS
    counts = {"loop": 0, "worker": 0}
    last: list[tuple[Document, int]] = []  # the worker's last snapshot

    def guarded(work: Callable[[], None], name: str) -> Callable[[], None]:
        def run() -> None:
            try:
                while time.monotonic() < deadline and not errors:
                    work()
                    counts[name] += 1
            except BaseException as e:  # every failure, reported by the test
                errors.append(e)

        return run

    def loop() -> None:
        """The event loop: edit, snapshot for the worker, answer requests."""
        for k, doc in enumerate(docs):
            if states[k] == 0:
                doc.edit(edit_at, edit_at, " ")
            else:
                doc.edit(edit_at, edit_at + 1, "")
            states[k] = 1 - states[k]
            assert doc.text == texts[states[k]]
            with lock:
                snapshots.append((doc.snapshot(), states[k]))
                del snapshots[:-4]
            want = expected[states[k]]
            for _ in range(3):
                if _section_refs(doc) != want.refs:
                    mismatches.append(f"loop: section names of text {states[k]}")
            if _answers(doc, offsets) != want.answers:
                mismatches.append(f"loop: answers on text {states[k]}")

    def worker() -> None:
        """The worker thread: analyse a snapshot, read its sections' names."""
        with lock:
            job = snapshots.pop(0) if snapshots else None
        if job is None:  # nothing new: read the last one's names again
            if not last:
                time.sleep(0.001)
                return
            snap, state = last[0]
            if _section_refs(snap) != expected[state].refs:
                mismatches.append(f"worker: section names of text {state}")
            return
        last[:] = [job]
        snap, state = job
        want = expected[state]
        for _ in range(3):  # the names of every section, made and dropped again
            if _section_refs(snap) != want.refs:
                mismatches.append(f"worker: section names of text {state}")
        with snap.history.lock:
            found = _diagnostics(snap)
        if found != want.diagnostics:
            mismatches.append(f"worker: diagnostics of text {state}")
        if _section_refs(snap) != want.refs:
            mismatches.append(f"worker: section names of text {state}")

    threads = [
        threading.Thread(target=guarded(loop, "loop")),
        threading.Thread(target=guarded(worker, "worker")),
    ]
    interval = sys.getswitchinterval()
    sys.setswitchinterval(1e-5)  # the threads take turns often: races show sooner
    try:
        for t in threads:
            t.start()
        for t in threads:
            t.join()
    finally:
        sys.setswitchinterval(interval)
    assert not errors, f"{type(errors[0]).__name__}: {errors[0]!r}"
    assert not mismatches, mismatches[:5]
    assert counts["loop"] > 0 and counts["worker"] > 0, counts
