"""Which source files a package's CMake builds: only a plain reading leaves any out."""

from __future__ import annotations

from pathlib import Path

import pytest

from bt_lsp.project.cpp_cmake import CMakeReader

SOURCES = ("src/app.cpp", "src/old_copy.cpp", "src/plugins/a.cpp", "include/pkg/a.hpp")


def _not_built(
    tmp_path: Path, cmake: str | None, texts: dict[str, bytes] | None = None
) -> set[str]:
    for rel in SOURCES:
        p = tmp_path / rel
        p.parent.mkdir(parents=True, exist_ok=True)
        p.write_text("")
    if cmake is not None:
        (tmp_path / "CMakeLists.txt").write_text(cmake)
    found = CMakeReader().not_built([tmp_path / rel for rel in SOURCES], texts)
    return {Path(p).relative_to(tmp_path).as_posix() for p in found}


HEAD = "cmake_minimum_required(VERSION 3.8)\nproject(pkg)\n"


def test_sources_no_target_names_are_not_built(tmp_path: Path) -> None:
    cmake = HEAD + (
        "set(SRCS src/app.cpp) # src/old_copy.cpp\n"
        "list(APPEND LIBS src/plugins/a.cpp)\n"
        "add_executable(app ${SRCS})\n"
        'add_library(plugins SHARED "${CMAKE_CURRENT_SOURCE_DIR}/${LIBS}")\n'
        "target_link_libraries(app ${catkin_LIBRARIES})\n"
    )
    # Headers are included, never "not built".
    assert _not_built(tmp_path, cmake) == {"src/old_copy.cpp"}


def test_glob_patterns_and_folders_that_are_read(tmp_path: Path) -> None:
    glob = HEAD + (
        "set(DIR src/plugins)\n"
        'file(GLOB_RECURSE FILES CONFIGURE_DEPENDS "${DIR}/*.cpp")\n'
        "foreach(F ${FILES})\n  get_filename_component(N ${F} NAME_WE)\n"
        "  add_library(${N} SHARED ${F})\nendforeach()\n"
        "add_executable(app src/app.cpp)\n"
    )
    assert _not_built(tmp_path / "1", glob) == {"src/old_copy.cpp"}
    wide = HEAD + 'file(GLOB FILES "src/*.cpp")\nadd_executable(app ${FILES})\n'
    assert _not_built(tmp_path / "2", wide) == {"src/plugins/a.cpp"}
    folder = HEAD + "ament_auto_add_library(x SHARED DIRECTORY src)\n"
    assert _not_built(tmp_path / "3", folder) == set()


@pytest.mark.parametrize(
    "cmake",
    [
        None,  # no CMake at all
        "add_executable(app src/app.cpp)\n",  # no project(): a part of a larger one
        HEAD + "add_executable(app src/app.cpp ${EXTRA_SOURCES})\n",
        HEAD + 'file(GLOB FILES "${SOMEWHERE}/*.cpp")\nadd_executable(app src/app.cpp)\n',
        HEAD + "include(cmake/sources.cmake)\nadd_executable(app src/app.cpp)\n",
        HEAD + "add_executable(app src/app.cpp)\nmy_add_plugins(${PLUGIN_SOURCES})\n",
        HEAD + "add_executable(app $<$<CONFIG:Debug>:src/old_copy.cpp> src/app.cpp)\n",
        HEAD + "add_subdirectory(missing)\nadd_executable(app src/app.cpp)\n",
        HEAD + "add_executable(app src/app.cpp\n",  # not closed
    ],
)
def test_cmake_not_understood_builds_every_file(tmp_path: Path, cmake: str | None) -> None:
    assert _not_built(tmp_path, cmake) == set()


def test_a_subdirectory_and_its_own_targets(tmp_path: Path) -> None:
    (tmp_path / "src").mkdir()
    (tmp_path / "src" / "CMakeLists.txt").write_text(
        "add_library(plugins SHARED plugins/a.cpp)\nadd_executable(app app.cpp)\n"
    )
    assert _not_built(tmp_path, HEAD + "add_subdirectory(src)\n") == {"src/old_copy.cpp"}


def test_a_source_file_another_includes_is_built(tmp_path: Path) -> None:
    cmake = HEAD + "add_executable(app src/app.cpp)\nadd_library(p src/plugins/a.cpp)\n"
    texts = {"app.cpp": b'#include "old_copy.cpp"\n'}
    assert _not_built(tmp_path, cmake, texts) == set()


def test_another_build_system_next_to_the_cmake(tmp_path: Path) -> None:
    (tmp_path / "platformio.ini").write_text("")
    assert _not_built(tmp_path, HEAD + "add_executable(app src/app.cpp)\n") == set()


def test_a_changed_cmake_is_read_again(tmp_path: Path) -> None:
    for rel in SOURCES:
        (tmp_path / rel).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / rel).write_text("")
    lists = tmp_path / "CMakeLists.txt"
    lists.write_text(HEAD + "add_executable(app src/app.cpp src/plugins/a.cpp)\n")
    reader = CMakeReader()
    files = [tmp_path / rel for rel in SOURCES]
    assert set(reader.not_built(files)) == {str(tmp_path / "src/old_copy.cpp")}
    lists.write_text(HEAD + "add_executable(app src/app.cpp src/plugins/a.cpp src/old_copy.cpp)\n")
    assert reader.not_built(files) == {}
