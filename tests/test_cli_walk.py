"""``bt-lsp check`` over a real source tree: only BT XML is checked when a folder is
walked; package.xml, launch files, URDF/xacro and pluginlib XML are skipped (``--verbose``
counts them), as are ``exclude`` globs and colcon's build, install and log folders; a file
named on the command line is checked as given."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from bt_lsp.project.config import anchor, excluded
from bt_lsp.project.sniff import is_bt_file, top_element
from tests.pinned import main  # bt-lsp as the tests know it (tests/pinned.py)

PKG = Path(__file__).parent / "data" / "ros_pkg" / "my_robot_bt"


@pytest.fixture
def pkg(tmp_path: Path) -> Path:
    dest = tmp_path / "my_robot_bt"
    shutil.copytree(PKG, dest)
    return dest


def run(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    code = main(["check", "--no-progress", *argv])
    out, err = capsys.readouterr()
    return code, out, err


def test_package_checks_its_trees_alone(pkg: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code, out, err = run(capsys, "--format", "json", "--verbose", str(pkg))
    assert code == 0, out + err
    assert out.strip() == "[]"
    lines = err.splitlines()
    # package.xml, two launch files, the xacro as .xml, the plugin description (robot.urdf
    # is not *.xml: never looked at).
    assert "bt-lsp: skipped 5 files: not BehaviorTree.CPP XML" in lines
    assert "bt-lsp: skipped 1 file: excluded" in lines
    assert "bt-lsp: skipped 2 folders: build, install, log and VCS folders" in lines
    assert any(
        line.startswith("bt-lsp: BehaviorTree.CPP 4: 2 files (") and "package.xml" in line
        for line in lines
    )


def test_text_summary_counts_the_trees(pkg: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code, out, err = run(capsys, str(pkg))
    assert code == 0
    assert out == ""
    assert "2 files" in err.splitlines()[-1]


def test_a_named_file_is_checked_as_given(pkg: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = run(capsys, str(pkg / "package.xml"))
    assert code == 1
    assert " error root-element " in out
    code, out, _ = run(capsys, str(pkg / "generated" / "broken.xml"))
    assert code == 1 and "xml-syntax" in out


def test_without_the_exclude_the_generated_tree_is_checked(
    pkg: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    (pkg / "bt-lsp.toml").unlink()
    code, out, _ = run(capsys, str(pkg))
    assert code == 1
    assert {line.split(":")[0] for line in out.splitlines()} == {
        str(pkg / "generated" / "broken.xml")
    }


def test_only_skipped_files(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    (tmp_path / "package.xml").write_text("<package><name>x</name></package>")
    code, _, err = run(capsys, str(tmp_path))
    assert code == 0
    assert "no BehaviorTree.CPP XML files to check" in err


def test_sniffing() -> None:
    assert top_element('<?xml version="1.0"?>\n<!-- <root> -->\n<launch>') == "launch"
    assert top_element("\ufeff<root/>") == "root"
    assert top_element('<!DOCTYPE root [<!ENTITY a "b">]>\n<root>') == "root"
    assert top_element("<?xml version='1.0'?><!-- unterminated") is None
    assert top_element("") is None
    assert is_bt_file(PKG / "behavior_trees" / "main.xml")
    assert not is_bt_file(PKG / "plugins.xml")
    assert is_bt_file(PKG / "missing.xml")  # unreadable: checked, so that the error shows


def test_broken_bt_files_are_still_checked(tmp_path: Path) -> None:
    """A file that tries to be BT (trees under a misspelt top element, a truncated tree)
    is checked, and so is a file that is not XML at all (empty, blank, text, a first tag
    that never closes: every reader fails on it); other XML and a generic <root> of
    another tool are not."""
    p = tmp_path / "t.xml"
    for text in (
        "<Root><BehaviorTree ID='M'/></Root>",
        "<roo BTCPP_format='4'>",
        "",
        " \n\t",
        "\ufeff",
        "not xml",
        "<root",
        "<not valid xml!!!",
        "<?xml version='1.0'?><!-- unterminated",
    ):
        p.write_text(text)
        assert is_bt_file(p), repr(text)
    for text in ("<Root/>", "<root><item/></root>", "<root><Tree", "<server/>", "<a b='>'"):
        p.write_text(text)
        assert not is_bt_file(p), text


def test_a_file_that_is_not_xml_is_an_error_in_a_walk(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """BehaviorTree.CPP's own tests (MalformedXML_CompletelyEmpty, _InvalidRoot): loading
    an empty file or ``<not valid xml!!!`` throws; a walk over the folder says so."""
    (tmp_path / "empty.xml").write_text("")
    (tmp_path / "broken.xml").write_text("<not valid xml!!!")
    code, out, _ = run(capsys, str(tmp_path))
    assert code == 1
    assert f"{tmp_path / 'empty.xml'}:1:1: error root-element " in out
    assert "BehaviorTree.CPP fails to load it" in out
    assert f"{tmp_path / 'broken.xml'}:1:2: error xml-syntax " in out


def test_utf16_files_are_sniffed(tmp_path: Path) -> None:
    p = tmp_path / "t.xml"
    p.write_bytes("\ufeff<root BTCPP_format='4'/>".encode("utf-16-le"))
    assert is_bt_file(p)
    p.write_bytes("<robot/>".encode("utf-16-be"))
    assert not is_bt_file(p)


OTHER_TOOLS = {
    # An MPLAB X project, an Open Liberty server, a DDS profile, a PlanSys2 fragment.
    "nbproject/configurations.xml": (
        "<configurationDescriptor version='65'><root/></configurationDescriptor>"
    ),
    "server.xml": "<?xml version='1.0'?>\n<server description='x'><featureManager/></server>",
    "fastdds.xml": "<profiles><participant profile_name='p'/></profiles>",
    "fragment.xml": "<Sequence name='ACTION_ID'><WaitAtStartReq/></Sequence>",
    "generic.xml": "<root><item>1</item></root>",
}


def test_other_tools_xml_is_skipped(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    for name, text in OTHER_TOOLS.items():
        (tmp_path / name).parent.mkdir(exist_ok=True)
        (tmp_path / name).write_text(text)
    (tmp_path / "main.xml").write_text(
        '<root BTCPP_format="4"><BehaviorTree ID="M"><AlwaysSuccess/></BehaviorTree></root>'
    )
    (tmp_path / "typo.xml").write_text(
        '<roo><BehaviorTree ID="T"><AlwaysSuccess/></BehaviorTree></roo>'
    )
    code, out, err = run(capsys, "--verbose", str(tmp_path))
    assert code == 1
    assert {line.split(":")[0] for line in out.splitlines()} == {str(tmp_path / "typo.xml")}
    assert " error root-element " in out
    assert "bt-lsp: skipped 5 files: not BehaviorTree.CPP XML" in err.splitlines()


def test_an_included_file_is_checked(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A file that a BT file includes is loaded as BT XML, whatever it looks like."""
    (tmp_path / "main.xml").write_text(
        '<root BTCPP_format="4" main_tree_to_execute="M"><include path="part.xml"/>'
        '<BehaviorTree ID="M"><AlwaysSuccess/></BehaviorTree></root>'
    )
    (tmp_path / "part.xml").write_text("<Root/>")
    (tmp_path / "lone.xml").write_text("<Root/>")
    code, out, err = run(capsys, "--verbose", str(tmp_path))
    assert code == 1
    assert {line.split(":")[0] for line in out.splitlines()} == {str(tmp_path / "part.xml")}
    assert "bt-lsp: skipped 1 file: not BehaviorTree.CPP XML" in err.splitlines()


def test_exclude_globs(tmp_path: Path) -> None:
    base = tmp_path.as_posix()
    globs = (anchor(tmp_path, "generated"), anchor(tmp_path, "test/**/*.xml"))
    assert excluded(Path(f"{base}/generated"), globs)
    assert excluded(Path(f"{base}/a/b/generated"), globs)
    assert not excluded(Path(f"{base}/generated_not"), globs)
    assert excluded(Path(f"{base}/test/x.xml"), globs)
    assert excluded(Path(f"{base}/test/a/b/x.xml"), globs)
    assert not excluded(Path(f"{base}/other/test/x.xml"), globs)
    assert not excluded(Path(f"{base}/test/x.xmlx"), globs)
