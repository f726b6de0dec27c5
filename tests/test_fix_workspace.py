"""``bt-lsp check --fix`` renames across files all together or not at all.

A tree defined in one file and called in another is renamed in both or in neither: when
one file's fixes are refused (a lossy encoding, a link to outside the folder, a write that
fails), the other files of the same rename keep the old name too, and say why.  Two bad
names that sanitize to the same new name get one decision for the whole folder."""

from __future__ import annotations

import os
from collections.abc import Iterator
from pathlib import Path

import pytest

from bt_lsp.ide.name_fixes import edits_in
from bt_lsp.ide.name_fixes import fix_workspace as plan_workspace
from bt_lsp.project.fileio import FileError, write_text_atomic
from bt_lsp.rules.analysis import analyze
from bt_lsp.syntax.document import Document
from bt_lsp.syntax.edits import apply_edits
from tests.pinned import main  # bt-lsp as the tests know it (tests/pinned.py)

# Defines the tree the other file calls.
DEFINES = (
    '<root BTCPP_format="4">\n'
    '  <BehaviorTree ID="Dock Robot">\n'
    "    <AlwaysSuccess/>\n"
    "  </BehaviorTree>\n"
    "</root>\n"
)


def _calls(extra: str = "") -> str:
    return (
        '<root BTCPP_format="4" main_tree_to_execute="Main">\n'
        '  <BehaviorTree ID="Main">\n'
        "    <Sequence>\n"
        '      <SubTree ID="Dock Robot"/>\n'
        f"{extra}"
        "    </Sequence>\n"
        "  </BehaviorTree>\n"
        "</root>\n"
    )


@pytest.fixture
def work(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Iterator[Path]:
    monkeypatch.chdir(tmp_path)
    (tmp_path / "d").mkdir()
    yield tmp_path


def test_a_rename_across_files_is_made_in_all_of_them(work: Path) -> None:
    (work / "d" / "dock.xml").write_text(DEFINES, encoding="utf-8")
    (work / "d" / "main.xml").write_text(_calls(), encoding="utf-8")
    assert main(["check", "--fix", "d"]) == 0
    assert (work / "d" / "dock.xml").read_text(encoding="utf-8") == DEFINES.replace(
        "Dock Robot", "Dock_Robot"
    )
    assert (work / "d" / "main.xml").read_text(encoding="utf-8") == _calls().replace(
        "Dock Robot", "Dock_Robot"
    )


def test_a_file_that_cannot_be_fixed_keeps_the_rename_out_of_every_file(
    work: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # main.xml is in CP932 with a byte sequence that does not round-trip: it is never
    # rewritten, so the tree it calls must keep its ID in dock.xml as well.
    lossy = b'<?xml version="1.0" encoding="cp932"?>\n' + _calls(
        '      <AlwaysSuccess name="@@"/>\n'
    ).encode().replace(b"@@", b"\x87\x90")
    (work / "d" / "dock.xml").write_text(DEFINES, encoding="utf-8")
    (work / "d" / "main.xml").write_bytes(lossy)
    assert main(["check", "--fix", "d"]) == 1
    assert (work / "d" / "dock.xml").read_text(encoding="utf-8") == DEFINES
    assert (work / "d" / "main.xml").read_bytes() == lossy
    err = capsys.readouterr().err
    assert "bt-lsp: not fixing d/main.xml: CP932 does not round-trip its bytes\n" in err
    assert (
        "bt-lsp: d/dock.xml: left 'Dock Robot' as it is (not renamed to 'Dock_Robot' in any "
        "file): its rename changes d/main.xml too, which is not fixed: CP932 does not "
        "round-trip its bytes\n"
    ) in err
    assert "fixed" not in err.replace("not fixed", "").replace("not fixing", "")


def test_a_refused_rename_leaves_the_other_renames_of_a_file(
    work: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # dock.xml also has a tree of its own: that rename touches no refused file.
    own = DEFINES.replace(
        "</root>",
        '  <BehaviorTree ID="Own Tree">\n    <AlwaysSuccess/>\n  </BehaviorTree>\n</root>',
    )
    (work / "d" / "dock.xml").write_text(own, encoding="utf-8")
    (work / "elsewhere").mkdir()
    (work / "elsewhere" / "main.xml").write_text(_calls(), encoding="utf-8")
    (work / "d" / "main.xml").symlink_to(work / "elsewhere" / "main.xml")
    main(["check", "--fix", "d"])
    assert (work / "d" / "dock.xml").read_text(encoding="utf-8") == own.replace(
        "Own Tree", "Own_Tree"
    )
    assert (work / "elsewhere" / "main.xml").read_text(encoding="utf-8") == _calls()
    err = capsys.readouterr().err
    assert "its rename changes d/main.xml too, which is not fixed: it is a symbolic link" in err


def test_a_failed_write_puts_back_the_files_already_written(
    work: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    (work / "d" / "dock.xml").write_text(DEFINES, encoding="utf-8")
    (work / "d" / "main.xml").write_text(_calls(), encoding="utf-8")
    real = write_text_atomic
    wrote: list[str] = []

    def failing(path: str, text: str, encoding: str, bom: bool, **kw: object) -> None:
        if path.endswith("main.xml"):
            raise FileError(path, f"cannot write {path}: No space left on device")
        wrote.append(text)
        real(path, text, encoding, bom)

    monkeypatch.setattr("bt_lsp.cli.fix_workspace.write_text_atomic", failing)
    assert main(["check", "--fix", "d"]) == 2
    # dock.xml was written first, then put back when main.xml could not be written.
    assert wrote == [DEFINES.replace("Dock Robot", "Dock_Robot"), DEFINES]
    assert (work / "d" / "dock.xml").read_text(encoding="utf-8") == DEFINES
    assert (work / "d" / "main.xml").read_text(encoding="utf-8") == _calls()
    err = capsys.readouterr().err
    assert "bt-lsp: not fixing d/main.xml: cannot write d/main.xml: No space left on device" in err
    assert (
        "bt-lsp: not fixing d/dock.xml: its renames change d/main.xml too, which could not be "
        "written: cannot write d/main.xml: No space left on device"
    ) in err
    assert sorted(os.listdir(work / "d")) == ["dock.xml", "main.xml"]  # no temporary file


# Two bad tree IDs that sanitize to the same name, each defined in one file and called in
# the other, the calls in the opposite order of the definitions.
A = (
    '<root BTCPP_format="4" main_tree_to_execute="Dock.Robot">\n'
    '  <BehaviorTree ID="Dock.Robot">\n'
    '    <Sequence><SubTree ID="Dock Robot"/></Sequence>\n'
    "  </BehaviorTree>\n"
    "</root>\n"
)
B = (
    '<root BTCPP_format="4">\n'
    '  <BehaviorTree ID="Dock Robot">\n'
    "    <AlwaysSuccess/>\n"
    "  </BehaviorTree>\n"
    '  <BehaviorTree ID="Caller">\n'
    '    <SubTree ID="Dock.Robot"/>\n'
    "  </BehaviorTree>\n"
    "</root>\n"
)


def test_names_that_sanitize_alike_get_one_resolution_in_every_file(work: Path) -> None:
    (work / "d" / "a.xml").write_text(A, encoding="utf-8")
    (work / "d" / "b.xml").write_text(B, encoding="utf-8")
    main(["check", "--fix", "d"])
    a = (work / "d" / "a.xml").read_text(encoding="utf-8")
    b = (work / "d" / "b.xml").read_text(encoding="utf-8")
    new = {"Dock.Robot": "Dock_Robot", "Dock Robot": "Dock_Robot_2"}
    assert a == A.replace("Dock.Robot", new["Dock.Robot"]).replace("Dock Robot", new["Dock Robot"])
    assert b == B.replace("Dock.Robot", new["Dock.Robot"]).replace("Dock Robot", new["Dock Robot"])


def test_the_workspace_plan_decides_each_symbol_once() -> None:
    docs = {"/ws/a.xml": Document(A, "/ws/a.xml"), "/ws/b.xml": Document(B, "/ws/b.xml")}
    diags = {p: analyze(d) for p, d in docs.items()}
    for order in (list(docs), list(reversed(docs))):
        plan = plan_workspace({p: docs[p] for p in order}, diags)
        renamed = {r.renaming.old: r.renaming.new for r in plan.renames}
        assert sorted(renamed) == ["Dock Robot", "Dock.Robot"]
        assert len(set(renamed.values())) == 2
        for p, d in docs.items():
            fixed = apply_edits(d.text, edits_in(plan.renames, p))
            text = d.text
            for old, new in renamed.items():
                text = text.replace(f'"{old}"', f'"{new}"')
            assert fixed == text, order
        # Every rename touches both files: each is defined in one and called in the other.
        assert all(r.paths == frozenset(docs) for r in plan.renames)


def test_check_fix_leaves_no_temporary_file(work: Path) -> None:
    (work / "d" / "dock.xml").write_text(DEFINES, encoding="utf-8")
    (work / "d" / "main.xml").write_text(_calls(), encoding="utf-8")
    main(["check", "--fix", "d"])
    assert sorted(os.listdir(work / "d")) == ["dock.xml", "main.xml"]
