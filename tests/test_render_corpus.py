"""The layout's geometry on every tree of real BT XML (tests/layout_check.py): no box
overlaps another, sibling subtrees never interleave, parents are above and centred over
their children, and no connector passes through a box.

Every tree of the full corpus copy in ``data/corpus_real`` is drawn four ways (with and
without ports, with and without its SubTree calls expanded), always; Nav2's navigator
trees are also drawn as ``bt-lsp render`` draws them (their folder as the workspace).  Where
the shared data sits beside the clone (``../shared``: the corpus and the Nav2 project),
every tree there is checked too, in a test of its own that says so when it is absent.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from bt_lsp.project.fileio import read_text
from bt_lsp.project.index import ProjectIndex, normalize
from bt_lsp.project.pictures import draw
from bt_lsp.project.settings import Settings
from bt_lsp.render import build_picture, document_trees, to_svg
from bt_lsp.rules.context import Context
from bt_lsp.syntax.document import Document
from tests.layout_check import problems

HERE = Path(__file__).parent
CORPUS = HERE / "data" / "corpus_real"
NAV2 = CORPUS / "ros-navigation__navigation2"
SHARED = HERE.parent.parent / "shared"
SHARED_SETS = (SHARED / "corpus", SHARED / "projects" / "ros-navigation__navigation2")


def _check_file(path: Path) -> tuple[int, list[str]]:
    """How many pictures of ``path``'s trees were checked, and what is wrong with them."""
    doc = Document(read_text(str(path)).text, str(path))
    ctx = Context.from_document(doc)
    found: list[str] = []
    count = 0
    for tree in document_trees(doc.model):
        for ports in (False, True):
            for expand in (False, True):
                pic = build_picture(doc.model, tree, ctx=ctx, ports=ports, expand_subtrees=expand)
                count += 1
                where = f"{path.name} {pic.tree_id!r} ports={ports} expand={expand}"
                found.extend(f"{where}: {p}" for p in problems(pic))
    return count, found


def _check_all(files: list[Path]) -> int:
    count = 0
    found: list[str] = []
    for path in files:
        n, bad = _check_file(path)
        count += n
        found.extend(bad)
    assert found == [], "\n".join(found[:20])
    return count


def test_every_corpus_tree_is_laid_out_tidily() -> None:
    files = sorted(CORPUS.rglob("*.xml"))
    assert len(files) >= 180  # the full copy, not a sample
    assert _check_all(files) >= 4 * 300


def test_nav2_trees_as_bt_lsp_render_draws_them() -> None:
    """Through the CLI's path: the folder as the workspace, calls expanded across files."""
    files = sorted(NAV2.glob("nav2_bt_navigator__behavior_trees__*.xml"))
    assert len(files) >= 10
    workspace = ProjectIndex([str(NAV2)], Settings())
    sizes = []
    for path in files:
        doc = Document(read_text(str(path)).text, str(path))
        for tree in document_trees(doc.model):
            text, pic = draw(
                workspace, normalize(str(path)), doc, tree, "svg", ports=True, expand_subtrees=True
            )
            assert text == to_svg(pic)
            assert problems(pic) == [], path.name
            sizes.append(len(pic.nodes))
    assert max(sizes) >= 40  # the real, large ones are among them


def _shared_files() -> list[Path]:
    return sorted(p for d in SHARED_SETS if d.is_dir() for p in d.rglob("*.xml"))


@pytest.mark.skipif(not SHARED.is_dir(), reason=f"no shared data at {SHARED}")
def test_every_shared_tree_is_laid_out_tidily() -> None:
    files = _shared_files()
    assert files, f"{SHARED} holds no corpus"
    assert _check_all(files) > 0
