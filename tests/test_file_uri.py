"""The hover's links into C++ files: the same URI as the standard library writes, made
without a file-system module (the core's import contract)."""

from __future__ import annotations

from pathlib import PurePosixPath

from hypothesis import given
from hypothesis import strategies as st

from bt_lsp.ide.hover import file_link, file_uri


@given(
    st.lists(
        st.text(min_size=1).filter(
            lambda s: "/" not in s and "\0" not in s and s not in (".", "..")
        ),
        min_size=1,
    )
)
def test_file_uri_is_the_standard_librarys(parts: list[str]) -> None:
    path = "/" + "/".join(parts)
    assert file_uri(path) == PurePosixPath(path).as_uri()


def test_file_link_points_at_the_line() -> None:
    assert file_link("src/a b.cpp:42", "/ws/src/a b.cpp") == (
        "[src/a b.cpp:42](file:///ws/src/a%20b.cpp#L42)"
    )
    assert file_link("src/a.cpp:42", None) == "src/a.cpp:42"
