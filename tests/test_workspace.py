"""The workspace layer: includes, cycles, missing files, the workspace's BT files."""

from __future__ import annotations

from pathlib import Path

from bt_lsp.project.index import ProjectIndex, normalize
from bt_lsp.project.settings import Settings
from bt_lsp.syntax.document import Document
from tests.annotated import check


def tree(body: str = "", includes: tuple[str, ...] = ()) -> str:
    inc = "".join(f'<include path="{p}"/>' for p in includes)
    return f'<root BTCPP_format="4">{inc}{body}</root>\n'


def write(path: Path, text: str) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text, encoding="utf-8")
    return normalize(path)


def diags(ws: ProjectIndex, path: Path) -> list[tuple[str, str]]:
    doc = ws.document(path)
    assert doc is not None
    return [(d.code, doc.text[d.start : d.end]) for d in ws.includes.diagnostics(path, doc)]


def test_include_resolved_relative_to_the_including_file(tmp_path: Path) -> None:
    a = write(tmp_path / "a.xml", tree(includes=("trees/b.xml",)))
    b = write(tmp_path / "trees" / "b.xml", tree(includes=("c.xml",)))
    c = write(tmp_path / "trees" / "c.xml", tree())
    ws = ProjectIndex([tmp_path])
    assert ws.includes.closure(a) == [b, c]
    assert diags(ws, a) == []


_CYCLE = "BehaviorTree.CPP fails with a misleading 'file not found' or crashes"


def test_missing_include_is_flagged_at_its_path() -> None:
    check("""<!-- file: a.xml -->
<root BTCPP_format="4"><include path="nope.xml"/></root>
<!--                                  ^^^^^^^^ error include-not-found: Included file 'nope.xml' not found ({root}/nope.xml: {not-found}) -->
""")  # noqa: E501


def test_self_include_by_bare_name_is_a_cycle() -> None:
    check("""<!-- file: a.xml -->
<root BTCPP_format="4"><include path="a.xml"/></root>
<!--                                  ^^^^^ error include-cycle: 'a.xml' includes this file itself; BehaviorTree.CPP recurses until it crashes -->
""")  # noqa: E501


def test_every_file_of_a_cycle_is_flagged_at_its_include() -> None:
    check(f"""<!-- file: a.xml -->
<root BTCPP_format="4"><include path="trees/b.xml"/></root>
<!--                                  ^^^^^^^^^^^ error include-cycle: Include cycle: a.xml → trees/b.xml → trees/c.xml → a.xml; {_CYCLE} -->
<!-- file: trees/b.xml -->
<root BTCPP_format="4"><include path="c.xml"/></root>
<!--                                  ^^^^^ error include-cycle: Include cycle: b.xml → c.xml → ../a.xml → b.xml; {_CYCLE} -->
<!-- file: trees/c.xml -->
<root BTCPP_format="4"><include path="../a.xml"/></root>
<!--                                  ^^^^^^^^ error include-cycle: Include cycle: c.xml → ../a.xml → b.xml → c.xml; {_CYCLE} -->
""")  # noqa: E501


def test_open_document_overrides_disk_and_dependents(tmp_path: Path) -> None:
    a = write(tmp_path / "a.xml", tree(includes=("b.xml",)))
    b = write(tmp_path / "b.xml", tree())
    ws = ProjectIndex([tmp_path])
    ws.open(a, Document(tree(includes=("missing.xml",)), str(a)))
    assert diags(ws, a) == [("include-not-found", "missing.xml")]
    ws.open(a, Document(tree(includes=("b.xml",)), str(a)))
    ws.open(b, Document(tree(), str(b)))
    assert ws.includes.dependents(b) == [a]


def test_file_changed_invalidates_cache(tmp_path: Path) -> None:
    a = write(tmp_path / "a.xml", tree(includes=("b.xml",)))
    ws = ProjectIndex([tmp_path])
    assert diags(ws, a) == [("include-not-found", "b.xml")]
    write(tmp_path / "b.xml", tree())
    ws.file_changed(tmp_path / "b.xml")
    assert diags(ws, a) == []


def test_ros_pkg_resolved_through_settings(tmp_path: Path) -> None:
    a = write(tmp_path / "a.xml", '<root><include ros_pkg="pkg" path="t/b.xml"/></root>')
    write(tmp_path / "share" / "pkg" / "t" / "b.xml", tree())
    ws = ProjectIndex([tmp_path], Settings(ros_packages={"pkg": str(tmp_path / "share" / "pkg")}))
    assert len(ws.includes.closure(a)) == 1
    ws2 = ProjectIndex([tmp_path])
    assert ws2.includes.closure(a) == []  # unmapped: the include-ros-pkg rule reports it


def test_workspace_files_skip_build_and_hidden_dirs_and_non_bt(tmp_path: Path) -> None:
    a = write(tmp_path / "src" / "a.xml", tree())
    write(tmp_path / "build" / "x.xml", tree())
    write(tmp_path / ".git" / "y.xml", tree())
    write(tmp_path / "package.xml", "<package><name>x</name></package>")
    ws = ProjectIndex([tmp_path])
    assert [p for p, _ in ws.bt_documents()] == [a]


def test_include_closure_is_bounded_and_iterative(tmp_path: Path) -> None:
    n = 300
    for i in range(n):
        write(tmp_path / f"f{i}.xml", tree(includes=(f"f{i + 1}.xml",)))
    write(tmp_path / f"f{n}.xml", tree())
    ws = ProjectIndex([tmp_path])
    assert len(ws.includes.closure(normalize(tmp_path / "f0.xml"))) == n


def test_revalidate_finds_files_created_and_deleted_in_the_workspace(tmp_path: Path) -> None:
    """Without file-change notifications, a file created or deleted in a walked folder
    (its modification time changes) is found on the next revalidation; a temporary file
    that is no BT file changes nothing."""
    import os

    a = write(tmp_path / "a.xml", tree())
    ws = ProjectIndex([tmp_path])
    assert ws.files.paths() == [a]
    assert not ws.revalidate()

    sub = tmp_path / "sub"
    sub.mkdir()
    generation = ws.generation
    assert not ws.revalidate()  # walked again, no BT file more: nothing changed
    assert ws.files.paths() == [a] and ws.generation == generation
    b = write(sub / "b.xml", tree())
    assert ws.revalidate() and ws.files.paths() == [a, b] and ws.generation > generation

    swap = sub / ".b.xml.swp"  # an editor's temporary file: the same BT files
    swap.write_text("x", encoding="utf-8")
    generation = ws.generation
    assert not ws.revalidate() and ws.generation == generation

    ws.document(b)  # read, then deleted
    os.remove(b)
    assert ws.revalidate() and ws.files.paths() == [a] and ws.document(b) is None
