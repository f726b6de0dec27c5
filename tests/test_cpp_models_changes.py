"""C++ files changed, deleted and created on disk while the server runs.

With watched files, a file deleted and then created again is a new file: it was left out
of the file lists for good (its path stayed "known", so its creation did not find the
files again).  Without watched files, C++ files on disk were never looked at again: they
are now revalidated by their stamps (and the folders searched by their modification
times), as the XML files are.
"""

from __future__ import annotations

import os
from pathlib import Path

from bt_lsp.project.cpp_models import CppModels
from bt_lsp.project.cpp_scan import Scanner
from bt_lsp.project.index import ProjectIndex

NODE = (
    "struct {cls} : BT::SyncActionNode "
    "{{ static BT::PortsList providedPorts() {{ return {{}}; }} }};\n"
)


def _source(*ids: str) -> str:
    classes = "".join(NODE.format(cls=f"C{i}") for i in range(len(ids)))
    regs = " ".join(f'f.registerNodeType<C{i}>("{n}");' for i, n in enumerate(ids))
    return classes + f"BT_REGISTER_NODES(f) {{ {regs} }}\n"


def _package(tmp_path: Path) -> tuple[Path, Path]:
    pkg = tmp_path / "pkg"
    (pkg / "src").mkdir(parents=True)
    (pkg / "package.xml").write_text("<package><name>pkg</name></package>")
    reg = pkg / "src" / "register_nodes.cpp"
    reg.write_text(_source("A"))
    return pkg / "trees" / "t.xml", reg


def _ids(models: CppModels, tree: Path) -> set[str]:
    return {n.id for n in models.catalog_for(tree).nodes}


def _touch_later(path: Path) -> None:
    """Move the modification time on: a file system's clock may be coarse."""
    st = path.stat()
    os.utime(path, ns=(st.st_atime_ns, st.st_mtime_ns + 2_000_000_000))


def test_a_watched_file_deleted_then_created_again_is_read(tmp_path: Path) -> None:
    tree, reg = _package(tmp_path)
    models = CppModels([tmp_path], scanner=Scanner(None))
    models.watched = True
    assert _ids(models, tree) == {"A"}
    reg.unlink()
    models.file_changed(reg)
    assert _ids(models, tree) == set()
    reg.write_text(_source("B", "C"))
    models.file_changed(reg)
    assert _ids(models, tree) == {"B", "C"}
    reg.write_text(_source("D"))  # and changed after that, as any file
    models.file_changed(reg)
    assert _ids(models, tree) == {"D"}


def test_without_watching_a_changed_file_is_read_again(tmp_path: Path) -> None:
    tree, reg = _package(tmp_path)
    models = CppModels([tmp_path], scanner=Scanner(None))
    assert _ids(models, tree) == {"A"}
    assert not models.revalidate()  # nothing changed: nothing forgotten
    reg.write_text(_source("A", "B"))
    _touch_later(reg)
    assert models.revalidate()
    assert _ids(models, tree) == {"A", "B"}
    assert not models.revalidate()


def test_without_watching_created_and_deleted_files_are_seen(tmp_path: Path) -> None:
    tree, reg = _package(tmp_path)
    models = CppModels([tmp_path], scanner=Scanner(None))
    assert _ids(models, tree) == {"A"}
    reg.unlink()
    assert models.revalidate()
    assert _ids(models, tree) == set()
    reg.write_text(_source("B", "C"))  # created again, with other nodes
    _touch_later(reg.parent)
    assert models.revalidate()
    assert _ids(models, tree) == {"B", "C"}
    deeper = reg.parent / "more" / "extra.cpp"  # in a new folder
    deeper.parent.mkdir()
    deeper.write_text(_source("E"))
    _touch_later(reg.parent)
    assert models.revalidate()
    assert _ids(models, tree) == {"B", "C", "E"}
    assert not models.revalidate()


def test_a_watched_workspace_does_not_stat_its_cpp(tmp_path: Path) -> None:
    tree, reg = _package(tmp_path)
    models = CppModels([tmp_path], scanner=Scanner(None))
    models.watched = True
    assert _ids(models, tree) == {"A"}
    reg.write_text(_source("B"))
    _touch_later(reg)
    assert not models.revalidate()  # the editor reports the change (file_changed)
    assert _ids(models, tree) == {"A"}


def test_the_project_index_revalidates_its_cpp(tmp_path: Path) -> None:
    tree, reg = _package(tmp_path)
    index = ProjectIndex([tmp_path])
    models = CppModels([tmp_path], index.packages, scanner=Scanner(None))
    index.cpp = models
    assert _ids(models, tree) == {"A"}
    generation = index.generation
    reg.write_text(_source("Z"))
    _touch_later(reg)
    assert index.revalidate()
    assert index.generation > generation
    assert _ids(models, tree) == {"Z"}
