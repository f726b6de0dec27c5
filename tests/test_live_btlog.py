"""``.btlog`` files (BT::FileLogger2) and ``bt-lsp replay``: a hand-made log for the exact
output, and a log that BehaviorTree.CPP 4.8.2 itself wrote (behaviortreepy)."""

from __future__ import annotations

import gc
import json
import struct
from pathlib import Path

import pytest

from bt_lsp.cli.main import main

XML = (
    b'<root BTCPP_format="4"><BehaviorTree ID="Main" _fullpath="">'
    b'<Sequence name="seq" _uid="1"><SubTree ID="Sub" _fullpath="sub1" _uid="2"/></Sequence>'
    b'</BehaviorTree><BehaviorTree ID="Sub" _fullpath="sub1">'
    b'<AlwaysFailure name="nope" _uid="3"/></BehaviorTree></root>'
)
START = 1_700_000_000_000_000


def record(us: int, uid: int, status: int) -> bytes:
    return us.to_bytes(6, "little") + uid.to_bytes(2, "little") + bytes([status])


def btlog(xml: bytes = XML, records: bytes = b"") -> bytes:
    head = b"BTCPP4-FileLogger2" + b"\x01" + struct.pack("<i", len(xml)) + xml
    return head + struct.pack("<q", START) + records


RECORDS = record(10, 1, 1) + record(12, 2, 1) + record(15, 3, 3) + record(20, 2, 3)


def test_replay_text(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "run.btlog"
    path.write_bytes(btlog(records=RECORDS))
    assert main(["replay", str(path)]) == 0
    out = capsys.readouterr().out.splitlines()
    assert out == [
        f"{path}: tree Main, 3 nodes, started 2023-11-14T22:13:20.000Z",
        "    0.000010s  #1    seq (Sequence)  IDLE -> RUNNING",
        "    0.000012s  #2    sub1 (SubTree)  IDLE -> RUNNING",
        "    0.000015s  #3    sub1/nope (AlwaysFailure)  IDLE -> FAILURE",
        "    0.000020s  #2    sub1 (SubTree)  RUNNING -> FAILURE",
        "4 transitions",
    ]


def test_replay_json_and_node_filter(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "run.btlog"
    path.write_bytes(btlog(records=RECORDS))
    assert main(["replay", str(path), "--format", "json", "--node", "sub1"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["tree"] == "Main" and data["start_us"] == START
    assert [n["path"] for n in data["nodes"]] == ["seq", "sub1", "sub1/nope"]
    assert data["nodes"][1]["subtree"] == "Sub"
    assert data["transitions"] == [
        {"offset_us": 12, "time_us": START + 12, "uid": 2, "path": "sub1", "name": "sub1",
         "tag": "SubTree", "from": "IDLE", "to": "RUNNING"},
        {"offset_us": 20, "time_us": START + 20, "uid": 2, "path": "sub1", "name": "sub1",
         "tag": "SubTree", "from": "RUNNING", "to": "FAILURE"},
    ]  # fmt: skip
    assert data["partial_bytes"] == 0


def test_partial_last_record_is_left_out(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = tmp_path / "run.btlog"
    path.write_bytes(btlog(records=RECORDS[:-4]))
    assert main(["replay", str(path)]) == 0
    captured = capsys.readouterr()
    assert captured.out.splitlines()[-1] == "3 transitions"
    assert "the last 5 bytes are a partial record" in captured.err


@pytest.mark.parametrize(
    ("data", "why"),
    [
        (b"<root/>", "no BTCPP4-FileLogger2 magic"),
        (btlog()[:20], "ends inside its header"),
        (btlog()[:60], "ends inside the tree's XML"),
        (btlog()[:-3], "before its first timestamp"),
        (btlog(records=record(1, 9, 1)), "node 9, which the tree lacks"),
        (btlog(records=record(1, 1, 7)), "unknown node status 7"),
        (btlog(xml=b"<root/>"), "no <BehaviorTree>"),
        (b"BTCPP4-FileLogger2\x02" + btlog()[19:], "version 2"),
        (b"BTCPP4-FileLogger2\x01" + struct.pack("<i", -5), "XML size -5"),
    ],
)
def test_malformed_logs(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], data: bytes, why: str
) -> None:
    path = tmp_path / "bad.btlog"
    path.write_bytes(data)
    assert main(["replay", str(path)]) == 2
    assert why in capsys.readouterr().err


def test_missing_file_and_unknown_node(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["replay", str(tmp_path / "none.btlog")]) == 2
    assert "No such file" in capsys.readouterr().err
    path = tmp_path / "run.btlog"
    path.write_bytes(btlog(records=RECORDS))
    assert main(["replay", str(path), "--node", "elsewhere"]) == 2
    assert "no node 'elsewhere'" in capsys.readouterr().err


def test_a_log_written_by_behaviortree_cpp(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bt = pytest.importorskip("behaviortreepy")
    factory = bt.BehaviorTreeFactory()
    factory.register_behavior_tree_from_text(
        """<root BTCPP_format="4" main_tree_to_execute="Main">
          <BehaviorTree ID="Main">
            <Sequence name="seq">
              <SubTree ID="Sub" name="sub1"/>
              <Inverter><AlwaysSuccess name="ok"/></Inverter>
            </Sequence>
          </BehaviorTree>
          <BehaviorTree ID="Sub"><Sleep msec="20"/></BehaviorTree>
        </root>"""
    )
    tree = factory.create_tree("Main")
    path = tmp_path / "run.btlog"
    logger = bt.FileLogger(tree, str(path))
    status = tree.tick_while_running(5)
    assert str(status).endswith("FAILURE")
    del logger  # the destructor joins the writer thread and closes the file
    gc.collect()

    assert main(["replay", str(path)]) == 0
    text = capsys.readouterr().out
    assert "#3    sub1/Sleep  IDLE -> RUNNING" in text
    assert "sub1/Sleep  RUNNING -> SUCCESS" in text
    assert "ok (AlwaysSuccess)  IDLE -> SUCCESS" in text
    assert "seq (Sequence)  RUNNING -> FAILURE" in text

    assert main(["replay", str(path), "--format", "json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert {n["path"] for n in data["nodes"]} == {"seq", "sub1", "sub1/Sleep", "Inverter", "ok"}
    last: dict[int, str] = {}
    for t in data["transitions"]:
        assert t["from"] == last.get(t["uid"], "IDLE")  # each step starts where the last ended
        last[t["uid"]] = t["to"]
    times = [t["offset_us"] for t in data["transitions"]]
    assert times == sorted(times) and times[-1] - times[0] >= 15_000  # the Sleep
    assert data["partial_bytes"] == 0
