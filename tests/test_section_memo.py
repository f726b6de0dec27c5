"""What the layers above keep of a section is kept in its slots (``Section.cache``): read
and written like a dict, by the keys listed in ``SectionMemo``; any other key is refused."""

from __future__ import annotations

import pytest

from bt_lsp.rules.analysis import analyze
from bt_lsp.syntax.document import Document
from bt_lsp.syntax.sections import Section, SectionMemo

_TEXT = (
    '<root BTCPP_format="4">\n'
    + "".join(
        f'<BehaviorTree ID="T{i}"><Sequence><Frob/></Sequence></BehaviorTree>\n' for i in range(3)
    )
    + "</root>\n"
)


def _section() -> Section:
    doc = Document(_TEXT)
    analyze(doc)
    return doc.model.sections[1]


def test_memo_reads_and_writes_like_a_dict() -> None:
    sec = _section()
    memo = sec.cache
    assert memo is sec and isinstance(memo, SectionMemo)
    assert "diagnostics" in memo and "semantics" in memo and "symbols" in memo
    assert "outline-json" not in memo and memo.get("outline-json") is None
    with pytest.raises(KeyError):
        memo["outline-json"]
    memo["outline-json"] = "kept"
    assert "outline-json" in memo and memo["outline-json"] == "kept"
    assert memo.get("outline-json", 1) == "kept"


def test_memo_refuses_an_unlisted_key_and_has_no_dict() -> None:
    sec = _section()
    with pytest.raises(KeyError):
        sec.cache["mine"] = 1
    with pytest.raises(KeyError):
        sec.cache.get("mine")
    assert not hasattr(sec, "__dict__")  # slots only: a dict per section cost 230+ bytes
