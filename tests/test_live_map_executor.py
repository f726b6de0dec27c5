"""A real BehaviorTree.CPP 4.8.2 executor's tree mapped onto the files it loaded.

The executor (``tests/live/executor.py``) runs ``main.xml`` of ``data/live_map``, copied
to a temporary folder with the file it includes; its FULLTREE is mapped onto those texts,
then onto an edited ``main.xml``, through the API and through ``bt-lsp monitor --map``.
"""

from __future__ import annotations

import io
import shutil
import threading
from collections.abc import Iterator
from pathlib import Path

import pytest

pytest.importorskip("behaviortreepy")
pytest.importorskip("zmq")

from bt_lsp.cli.main import main
from bt_lsp.live.client import Groot2Client
from bt_lsp.live.mapping import map_tree
from bt_lsp.project.index import ProjectIndex, normalize
from bt_lsp.project.pictures import tree_resolver
from bt_lsp.syntax.document import Document
from tests.live.harness import Executor, free_port

DATA = Path(__file__).parent / "data" / "live_map"


@pytest.fixture
def folder(tmp_path: Path) -> Path:
    for name in ("main.xml", "inc.xml"):
        shutil.copy(DATA / name, tmp_path / name)
    return tmp_path


@pytest.fixture
def port(folder: Path) -> Iterator[int]:
    port = free_port()
    ex = Executor(port, tree=folder / "main.xml")
    yield port
    ex.kill()


def start_tag(text: str, name_start: int) -> str:
    """The start tag whose name begins at ``name_start``, up to its ``>``."""
    assert text[name_start - 1] == "<"
    return text[name_start - 1 : text.index(">", name_start)]


def line_of(text: str, needle: str) -> int:
    assert text.count(needle) == 1, needle
    return text[: text.index(needle)].count("\n") + 1


def test_every_uid_of_the_running_tree_maps_then_an_edit_is_reported(
    folder: Path, port: int
) -> None:
    with Groot2Client("127.0.0.1", port, timeout=3.0) as client:
        live = client.read_tree()
        statuses = client.status()
    assert set(statuses) == set(live.nodes) and len(live.nodes) == 22
    path = normalize(folder / "main.xml")
    workspace = ProjectIndex([folder])
    doc = workspace.document(path)
    assert doc is not None
    tm = map_tree(live, doc.model, tree_resolver(workspace, path, doc))
    assert tm.mismatches == () and set(tm.places) == set(live.nodes)
    # Each node's element has the node's registration ID (or is its <Action ID>) and name.
    texts = {None: doc.text, str(normalize(folder / "inc.xml")): (folder / "inc.xml").read_text()}
    for uid, place in tm.places.items():
        node = live.nodes[uid]
        text = texts[place.path]
        tag = text[place.start : place.end]
        written = start_tag(text, place.start)
        assert tag == node.tag or f'ID="{node.tag}"' in written, (uid, written)
        if node.name != node.tag and node.subtree is None:
            assert f'name="{node.name}"' in written

    # The text edited since the executor started: a node inserted before "ok", the
    # Script removed, "act" renamed.
    edited = (
        doc.text.replace(
            '<AlwaysSuccess name="ok"/>', '<Delay name="new"/><AlwaysSuccess name="ok"/>'
        )
        .replace('      <Script code="x := 1"/>\n', "")
        .replace('name="act"', 'name="acted"')
    )
    other = Document(edited, str(path))
    tm = map_tree(live, other.model, tree_resolver(workspace, path, other))
    script = live.find("Script")[0].uid
    act = live.find("act")[0].uid
    by_kind = {(m.kind, m.uid): m for m in tm.mismatches}
    assert set(by_kind) == {("missing", script), ("renamed", act), ("added", None)}
    assert by_kind["missing", script].place is None
    renamed = by_kind["renamed", act].place
    added = by_kind["added", None].place
    assert renamed is not None and added is not None
    assert start_tag(edited, renamed.start) == '<Action ID="AlwaysSuccess" name="acted"/'
    assert start_tag(edited, added.start) == '<Delay name="new"/'

    assert set(tm.places) == set(live.nodes) - {script}
    ok = live.find("ok")[0].uid
    assert tm.places[ok].start == edited.index('<AlwaysSuccess name="ok"') + 1


def test_monitor_map_prints_each_nodes_file_and_line(
    folder: Path, port: int, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(folder)
    main_text = (folder / "main.xml").read_text()
    inc_text = (folder / "inc.xml").read_text()
    assert main(["monitor", f"127.0.0.1:{port}", "--once", "--map", "main.xml"]) == 0
    out = capsys.readouterr().out
    lines = out.splitlines()
    script = next(x for x in lines if "Script #" in x)
    assert f"main.xml:{line_of(main_text, '<Script')}" in script
    naps = [x for x in lines if 'Sleep "nap"' in x]
    assert len(naps) == 2  # Inner runs twice, from inc.xml
    assert all(f"inc.xml:{line_of(inc_text, '<Sleep')}" in x for x in naps)
    # The status is still the last column.
    assert script.split("  ")[-1].strip() in {"IDLE", "RUNNING", "SUCCESS", "IDLE (was SUCCESS)"}
    assert "differs" not in out

    # Edited on disk while the executor runs: a folder as --map finds the file.
    edited = main_text.replace('name="ok"', 'name="fine"')
    (folder / "main.xml").write_text(edited)
    assert main(["monitor", f"127.0.0.1:{port}", "--once", "--map", str(folder)]) == 0
    out = capsys.readouterr().out
    at = line_of(edited, 'name="fine"')
    assert "the text differs from the running tree (1):" in out
    assert f'main.xml:{at}: #22 AlwaysSuccess "ok" (ok) is AlwaysSuccess "fine" in the text' in out


def test_monitor_map_while_watching_sees_an_edit_on_disk(folder: Path, port: int) -> None:
    from bt_lsp.cli import live

    main_text = (folder / "main.xml").read_text()
    edited = main_text.replace('name="ok"', 'name="fine"')
    timer = threading.Timer(0.5, lambda: (folder / "main.xml").write_text(edited))
    timer.start()
    out = io.StringIO()
    try:
        code = live.monitor(
            f"127.0.0.1:{port}", rate=20, plain=True, duration=3.0, map_path=str(folder), out=out
        )
    finally:
        timer.join()
    assert code == 0
    frames = [f for f in out.getvalue().split("\n\n") if f.strip()]
    assert "differs" not in frames[0] and "main.xml:" in frames[0]
    assert 'is AlwaysSuccess "fine" in the text' in frames[-1]


def test_monitor_map_of_a_missing_path_is_a_usage_error(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    code = main(["monitor", "127.0.0.1:1", "--once", "--map", str(tmp_path / "none.xml")])
    assert code == 2
    assert "no such file or folder" in capsys.readouterr().err
