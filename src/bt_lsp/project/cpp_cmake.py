"""Which C++ source files a package's CMake builds, when its CMakeLists says so plainly.

A package that lists the sources of its targets (``add_executable(x src/a.cpp)``,
``set(SRCS ...)`` lists, ``file(GLOB ...)`` patterns that can be read) does not build a
source file that none of them names: an old copy (``mission (copy).cpp``), a program left
out of the build.  Its registrations are not the project's.

The reading is conservative: a source file is *not built* only when the CMakeLists of its
project (the nearest one above it with a ``project()`` call, and those it adds with
``add_subdirectory``) is understood entirely and names neither the file, nor a folder
holding it, nor a pattern matching it.  A variable that cannot be resolved where sources
are given, an ``include()`` of a project's own CMake file, a generator expression, a
command this module does not know given an unresolved variable, or no CMakeLists at all:
every file is built, as without this module.  Headers are included, not built: never
left out; nor is a source file that another file ``#include``\\ s.
"""

from __future__ import annotations

import fnmatch
import os
import re
import threading
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Final

# Compilation units (headers are never "not built": they are included).
SOURCE_SUFFIXES: Final = frozenset({".cpp", ".cc", ".cxx", ".c++"})

# Commands whose arguments after the first (the target) are source files.
_SOURCE_COMMANDS: Final = frozenset(
    {
        "add_executable",
        "add_library",
        "target_sources",
        "ament_auto_add_executable",
        "ament_auto_add_library",
        "cuda_add_executable",
        "cuda_add_library",
        "catkin_add_gtest",
        "catkin_add_gmock",
        "ament_add_gtest",
        "ament_add_gmock",
        "ament_add_gtest_executable",
        "ament_add_gmock_executable",
        "add_rostest_gtest",
        "pybind11_add_module",
        "qt5_add_executable",
        "qt_add_executable",
        "rosbuild_add_executable",
        "rosbuild_add_library",
    }
)
_SOURCE_KEYWORDS: Final = frozenset(
    {
        "STATIC",
        "SHARED",
        "MODULE",
        "OBJECT",
        "INTERFACE",
        "EXCLUDE_FROM_ALL",
        "WIN32",
        "MACOSX_BUNDLE",
        "PRIVATE",
        "PUBLIC",
        "NO_TARGET_LINK_LIBRARIES",
        "DIRECTORY",
        "SKIP_LINKING_MAIN_LIBRARIES",
        "SKIP_TEST",
    }
)
# Commands that never name source files; an unresolved variable in them is harmless.
_HARMLESS: Final = frozenset(
    {
        "cmake_minimum_required",
        "cmake_policy",
        "find_package",
        "find_library",
        "find_path",
        "find_program",
        "find_file",
        "find_dependency",
        "pkg_check_modules",
        "pkg_search_module",
        "include_directories",
        "link_directories",
        "link_libraries",
        "target_link_libraries",
        "target_include_directories",
        "target_compile_options",
        "target_compile_definitions",
        "target_compile_features",
        "target_link_options",
        "target_link_directories",
        "add_compile_options",
        "add_compile_definitions",
        "add_definitions",
        "add_link_options",
        "remove_definitions",
        "set_target_properties",
        "set_property",
        "set_source_files_properties",
        "set_directory_properties",
        "get_target_property",
        "get_property",
        "get_filename_component",
        "add_dependencies",
        "install",
        "message",
        "option",
        "enable_testing",
        "enable_language",
        "add_test",
        "if",
        "elseif",
        "else",
        "endif",
        "while",
        "endwhile",
        "endforeach",
        "endfunction",
        "endmacro",
        "function",
        "macro",
        "return",
        "break",
        "continue",
        "unset",
        "mark_as_advanced",
        "export",
        "string",
        "math",
        "execute_process",
        "configure_file",
        "cmake_parse_arguments",
        "separate_arguments",
        "add_custom_target",
        "add_custom_command",
        "catkin_package",
        "catkin_python_setup",
        "catkin_install_python",
        "catkin_destinations",
        "generate_messages",
        "add_message_files",
        "add_service_files",
        "add_action_files",
        "generate_dynamic_reconfigure_options",
        "ament_package",
        "ament_export_include_directories",
        "ament_export_libraries",
        "ament_export_dependencies",
        "ament_export_targets",
        "ament_target_dependencies",
        "ament_auto_find_build_dependencies",
        "ament_auto_package",
        "ament_lint_auto_find_test_dependencies",
        "ament_python_install_package",
        "ament_environment_hooks",
        "ament_index_register_resource",
        "rosidl_generate_interfaces",
        "rosidl_target_interfaces",
        "rosidl_get_typesupport_target",
        "rclcpp_components_register_nodes",
        "rclcpp_components_register_node",
        "pluginlib_export_plugin_description_file",
        "roslint_cpp",
        "add_rostest",
    }
)
# Commands whose arguments are folders to search for headers: naming a folder there does
# not build the sources in it.
_INCLUDE_DIRS: Final = frozenset(
    {
        "include_directories",
        "target_include_directories",
        "ament_export_include_directories",
        "catkin_package",
        "install",
        "message",
        "option",
        "if",
        "elseif",
        "while",
    }
)
# CMake's own modules, which define no sources.
_STANDARD_MODULES: Final = frozenset(
    {
        "GNUInstallDirs",
        "CMakePackageConfigHelpers",
        "CMakeParseArguments",
        "CTest",
        "CheckCXXCompilerFlag",
        "CheckCCompilerFlag",
        "CheckIncludeFile",
        "CheckIncludeFileCXX",
        "CheckCXXSourceCompiles",
        "CheckLanguage",
        "CheckSymbolExists",
        "CheckFunctionExists",
        "CheckLibraryExists",
        "ExternalProject",
        "FetchContent",
        "FeatureSummary",
        "FindPackageHandleStandardArgs",
        "FindPkgConfig",
        "GenerateExportHeader",
        "ProcessorCount",
        "CMakeDependentOption",
        "CPack",
    }
)
# Other build systems: the CMake may not be what builds the sources.
_OTHER_BUILDS: Final = ("platformio.ini", "meson.build", "BUILD", "BUILD.bazel", "SConstruct")
_MAX_VALUES: Final = 256
_MAX_DEPTH: Final = 8
_BUILD: Final = "\0build"  # the build folder: generated sources are never ours


class _Unknown(Exception):
    """The CMake says something this module does not follow: every file is built."""


@dataclass
class _Reading:
    """What one project's CMakeLists name: files and folders, patterns, folders read."""

    names: set[str] = field(default_factory=set)
    # ``file(GLOB)`` patterns (absolute, ``/``-separated), with whether ``*`` crosses
    # folders (``GLOB_RECURSE``).
    patterns: set[tuple[str, bool]] = field(default_factory=set)
    folders: set[str] = field(default_factory=set)  # the folders whose CMakeLists was read
    files: list[tuple[Path, tuple[int, int] | None]] = field(default_factory=list)

    def builds(self, path: str) -> bool:
        if path in self.names:
            return True
        parent = os.path.dirname(path)
        while True:
            if parent in self.names:
                return True
            up = os.path.dirname(parent)
            if up == parent:
                break
            parent = up
        posix = path.replace(os.sep, "/")
        depth = posix.count("/")
        return any(
            (deep or p.count("/") == depth) and fnmatch.fnmatchcase(posix, p)
            for p, deep in self.patterns
        )


_Vars = dict[str, list[str] | None]  # None: set to a value not known
_Args = list[tuple[str, bool]]  # (text, quoted)


def _commands(text: str) -> list[tuple[str, _Args]]:
    """The command invocations of a CMake file, comments left out."""
    out: list[tuple[str, _Args]] = []
    i, n = 0, len(text)
    while i < n:
        ch = text[i]
        if ch == "#":
            i = _skip_comment(text, i)
        elif ch.isalpha() or ch == "_":
            j = i
            while j < n and (text[j].isalnum() or text[j] == "_"):
                j += 1
            name = text[i:j].lower()
            while j < n and text[j] in " \t":
                j += 1
            if j >= n or text[j] != "(":
                i = j
                continue
            args, i = _arguments(text, j + 1)
            out.append((name, args))
        else:
            i += 1
    return out


_BRACKET = re.compile(r"\[(=*)\[")


def _skip_comment(text: str, i: int) -> int:
    m = _BRACKET.match(text, i + 1)
    if m:
        end = text.find("]" + m.group(1) + "]", m.end())
        if end < 0:
            raise _Unknown("an unterminated bracket comment")
        return end + len(m.group(1)) + 2
    end = text.find("\n", i)
    return len(text) if end < 0 else end + 1


def _arguments(text: str, i: int) -> tuple[_Args, int]:
    args: _Args = []
    depth = 0
    n = len(text)
    while i < n:
        ch = text[i]
        if ch.isspace():
            i += 1
        elif ch == "#":
            i = _skip_comment(text, i)
        elif ch == "(":
            depth += 1
            i += 1
        elif ch == ")":
            if depth == 0:
                return args, i + 1
            depth -= 1
            i += 1
        elif ch == '"':
            j = i + 1
            while j < n and text[j] != '"':
                j += 2 if text[j] == "\\" else 1
            if j >= n:
                raise _Unknown("an unterminated string")
            args.append((text[i + 1 : j], True))
            i = j + 1
        elif ch == "[" and _BRACKET.match(text, i):
            m = _BRACKET.match(text, i)
            assert m is not None
            end = text.find("]" + m.group(1) + "]", m.end())
            if end < 0:
                raise _Unknown("an unterminated bracket argument")
            args.append((text[m.end() : end], True))
            i = end + len(m.group(1)) + 2
        else:
            j = i
            while j < n and not text[j].isspace() and text[j] not in '()"#':
                j += 2 if text[j] == "\\" else 1
            args.append((text[i:j], False))
            i = j
    raise _Unknown("an unterminated command")


_VAR = re.compile(r"\$\{([^${}]*)\}")


def _expand(arg: str, env: _Vars) -> list[str] | None:
    """Every value ``arg`` may take (list elements apart); ``None`` if not known."""
    if "$ENV{" in arg or "$CACHE{" in arg or "$<" in arg:
        return None
    values = [arg]
    for _ in range(16):
        done: list[str] = []
        more = False
        for v in values:
            m = _VAR.search(v)
            if m is None:
                done.append(v)
                continue
            more = True
            got = env.get(m.group(1))
            if got is None:
                return None
            # A list inside a larger text: each element in turn (a superset of CMake's).
            for g in got or [""]:
                done.append(v[: m.start()] + g + v[m.end() :])
        values = list(dict.fromkeys(done))
        if len(values) > _MAX_VALUES:
            return None
        if not more:
            break
    else:
        return None
    out: list[str] = []
    for v in values:
        out.extend(x for x in re.split(r"(?<!\\);", v) if x)
    return out


def _union(before: list[str] | None, got: list[str] | None) -> list[str] | None:
    """A variable's values after one more assignment (``None``: not known)."""
    if before is None or got is None:
        return None
    return list(dict.fromkeys([*before, *got]))


def _plain(args: _Args, env: _Vars) -> list[str] | None:
    out: list[str] = []
    for a, _ in args:
        got = _expand(a, env)
        if got is None:
            return None
        out.extend(got)
    return out


class _Reader:
    def __init__(self, read: Callable[[Path], str | None]) -> None:
        self.read = read
        self.out = _Reading()

    def project(self, folder: Path, env: _Vars, depth: int = 0) -> None:
        if depth > _MAX_DEPTH:
            raise _Unknown("add_subdirectory nests too deep")
        lists = folder / "CMakeLists.txt"
        text = self.read(lists)
        self.out.files.append((lists, _stamp(lists)))
        if text is None:
            raise _Unknown(f"{lists} cannot be read")
        here = os.path.normpath(str(folder))
        self.out.folders.add(here)
        env = dict(env)  # a folder's scope: what it sets stays in it
        env["CMAKE_CURRENT_SOURCE_DIR"] = env["CMAKE_CURRENT_LIST_DIR"] = [here]
        env["CMAKE_CURRENT_BINARY_DIR"] = [_BUILD]
        for name, args in _commands(text):
            self.command(name, args, here, env, depth)

    def command(self, name: str, args: _Args, here: str, env: _Vars, depth: int) -> None:
        if name == "project":
            words = _plain(args[:1], env) or []
            if words:
                env["PROJECT_NAME"] = [words[0]]
                env[f"{words[0]}_SOURCE_DIR"] = [here]
            env["PROJECT_SOURCE_DIR"] = [here]
            env["PROJECT_BINARY_DIR"] = env["CMAKE_BINARY_DIR"] = [_BUILD]
            return
        if name == "set":
            self.set(args, env)
            return
        if name == "list":
            self.list(args, env)
            return
        if name == "file":
            self.file(args, here, env)
            return
        if name == "aux_source_directory" and len(args) == 2:
            folder = _expand(args[0][0], env)
            if folder is None:
                raise _Unknown(f"aux_source_directory({args[0][0]}) cannot be resolved")
            found = [self.path(f, here).replace(os.sep, "/") + "/*" for f in folder]
            env[args[1][0]] = found
            self.out.patterns.update((f, False) for f in found)
            return
        if name == "foreach" and args:
            self.foreach(args, env)
            return
        if name == "include":
            module = args[0][0] if args else ""
            if module not in _STANDARD_MODULES:
                raise _Unknown(f"include({module}) may define sources")
            return
        if name == "add_subdirectory":
            sub = _plain(args[:1], env)
            if not sub:
                raise _Unknown("add_subdirectory() cannot be resolved")
            self.project(Path(self.path(sub[0], here)), env, depth + 1)
            return
        if name in _SOURCE_COMMANDS:
            for a, _ in args[1:]:
                got = _expand(a, env)
                if got is None:
                    raise _Unknown(f"{name}() names sources by {a}, which cannot be resolved")
                self.name(got, here)
            return
        if name not in _HARMLESS:
            # A command of a package (a macro that builds sources, maybe): what it is
            # given must be known, and whatever it names may be built.
            got = _plain(args, env)
            if got is None:
                raise _Unknown(f"{name}() is given a value that cannot be resolved")
        elif name not in _INCLUDE_DIRS:
            got = [v for a, _ in args for v in (_expand(a, env) or ())]
        else:
            got = []
        self.name(got, here)
        # A command not followed may write a variable it is given by name.
        for a, quoted in args:
            if not quoted and a in env and name not in ("if", "elseif", "while", "message"):
                env[a] = None

    def set(self, args: _Args, env: _Vars) -> None:
        if not args:
            return
        var = args[0][0]
        rest = list(args[1:])
        for i, (a, quoted) in enumerate(rest):
            if not quoted and a in ("CACHE", "PARENT_SCOPE"):
                rest = rest[:i]
                break
        got = _plain(rest, env)
        if "$" in var:
            raise _Unknown(f"set({var}) names a variable by a variable")
        before = env.get(var, [])
        # Assignments in branches not followed: the union of every value given.
        env[var] = _union(before, got)

    def list(self, args: _Args, env: _Vars) -> None:
        if len(args) < 2:
            return
        op, var = args[0][0].upper(), args[1][0]
        if op in ("APPEND", "PREPEND", "INSERT"):
            items = args[3:] if op == "INSERT" else args[2:]
            got = _plain(items, env)
            before = env.get(var, [])  # an unset variable is an empty list
            env[var] = _union(before, got)
        elif op in ("REMOVE_ITEM", "REMOVE_AT", "REMOVE_DUPLICATES", "FILTER", "SORT", "REVERSE"):
            pass  # fewer values: what was there is still a superset
        else:
            env[var] = None
            env[args[-1][0]] = None

    def file(self, args: _Args, here: str, env: _Vars) -> None:
        if not args:
            return
        op = args[0][0].upper()
        if op not in ("GLOB", "GLOB_RECURSE"):
            for a, quoted in args[1:]:
                if not quoted:
                    env[a] = None  # READ, STRINGS, ... write a variable
            return
        if len(args) < 2:
            return
        var = args[1][0]
        patterns: list[str] = []
        rest = args[2:]
        i = 0
        while i < len(rest):
            a = rest[i][0]
            if a in ("LIST_DIRECTORIES", "RELATIVE"):
                i += 2
                continue
            if a in ("CONFIGURE_DEPENDS", "FOLLOW_SYMLINKS"):
                i += 1
                continue
            got = _expand(a, env)
            if got is None:
                raise _Unknown(f"file({op}) pattern {a} cannot be resolved")
            patterns.extend(self.path(g, here) for g in got)
            i += 1
        deep = op == "GLOB_RECURSE"
        self.out.patterns.update((p.replace(os.sep, "/"), deep) for p in patterns)
        env[var] = patterns

    def foreach(self, args: _Args, env: _Vars) -> None:
        var = args[0][0]
        rest = args[1:]
        words = [a for a, q in rest if not q]
        if words[:1] == ["RANGE"]:
            env[var] = None
            return
        values: list[str] = []
        mode = "items"
        for a, quoted in rest:
            if not quoted and a == "IN":
                continue
            if not quoted and a in ("LISTS", "ITEMS", "ZIP_LISTS"):
                mode = a
                continue
            if mode == "ZIP_LISTS":
                env[var] = None
                return
            got = env.get(a) if mode == "LISTS" else _expand(a, env)
            if got is None:
                env[var] = None
                return
            values.extend(got)
        env[var] = list(dict.fromkeys(values))

    def name(self, values: Iterable[str], here: str) -> None:
        for v in values:
            if not v or v in _SOURCE_KEYWORDS:
                continue
            p = self.path(v, here)
            if any(c in v for c in "*?["):
                # A pattern a file(GLOB) read is already there (a source command does not
                # expand one); one given to a command not known may be expanded by it.
                posix = p.replace(os.sep, "/")
                if not any(q == posix for q, _ in self.out.patterns):
                    self.out.patterns.add((posix, True))
            else:
                self.out.names.add(p)

    @staticmethod
    def path(value: str, here: str) -> str:
        return os.path.normpath(value if os.path.isabs(value) else os.path.join(here, value))


def _stamp(path: Path) -> tuple[int, int] | None:
    try:
        st = path.stat()
    except (OSError, ValueError):
        return None
    return (st.st_mtime_ns, st.st_size)


def _read_text(path: Path) -> str | None:
    try:
        return path.read_text(encoding="utf-8-sig", errors="replace")
    except (OSError, ValueError):
        return None


@dataclass(frozen=True)
class Project:
    """One CMake project's reading: ``reading`` ``None`` when not understood (``why``);
    ``files`` the CMakeLists read, with their modification times and sizes."""

    top: Path
    reading: _Reading | None
    why: str
    files: tuple[tuple[Path, tuple[int, int] | None], ...]


class CMakeReader:
    """Reads CMake projects, each again only when one of its CMakeLists changed."""

    def __init__(self, read: Callable[[Path], str | None] = _read_text) -> None:
        self._read = read
        self._lock = threading.Lock()
        self._projects: dict[Path, Project] = {}

    def project(self, top: Path) -> Project:
        with self._lock:
            hit = self._projects.get(top)
        if hit is not None and all(_stamp(p) == s for p, s in hit.files):
            return hit
        reader = _Reader(self._read)
        try:
            reader.project(top, {})
            found = Project(top, reader.out, "", tuple(reader.out.files))
        except _Unknown as e:
            found = Project(top, None, str(e), tuple(reader.out.files))
        with self._lock:
            self._projects[top] = found
        return found

    def not_built(
        self, files: Iterable[Path], texts: Mapping[str, bytes] | None = None
    ) -> dict[str, str]:
        """The source files among ``files`` that their project's CMake does not build,
        each with the reason (for a node's note)."""
        nearest: dict[Path, Path | None] = {}
        tops: dict[Path, Path | None] = {}
        projects: dict[Path, Project] = {}
        out: dict[str, str] = {}
        for f in files:
            if f.suffix.lower() not in SOURCE_SUFFIXES:
                continue
            lists = _nearest(f.parent, nearest)
            if lists is None:
                continue
            if lists not in tops:
                top = _top(lists, self._read)
                if top is not None and any((top / m).exists() for m in _OTHER_BUILDS):
                    top = None
                tops[lists] = top
            top = tops[lists]
            if top is None:
                continue
            if top not in projects:
                projects[top] = self.project(top)
            r = projects[top].reading
            if r is None or os.path.normpath(str(lists)) not in r.folders:
                continue
            if not r.builds(os.path.normpath(str(f))):
                out[str(f)] = (
                    f"not built: no target of {top / 'CMakeLists.txt'} lists {f.name} "
                    "among its sources"
                )
        if out and texts:
            included = _included_names(texts)
            out = {p: why for p, why in out.items() if Path(p).name not in included}
        return out


def _nearest(folder: Path, memo: dict[Path, Path | None]) -> Path | None:
    """The nearest folder at or above ``folder`` that has a CMakeLists.txt."""
    seen: list[Path] = []
    cur = folder
    found: Path | None = None
    while True:
        if cur in memo:
            found = memo[cur]
            break
        seen.append(cur)
        if (cur / "CMakeLists.txt").is_file():
            found = cur
            break
        if cur.parent == cur:
            break
        cur = cur.parent
    for s in seen:
        memo[s] = found
    return found


_PROJECT = re.compile(r"^\s*project\s*\(", re.IGNORECASE | re.MULTILINE)


def _top(lists: Path, read: Callable[[Path], str | None]) -> Path | None:
    """The top of the CMake project ``lists`` belongs to: itself or the nearest folder
    above with a ``project()`` call, through folders that all have a CMakeLists."""
    cur = lists
    for _ in range(_MAX_DEPTH):
        text = read(cur / "CMakeLists.txt")
        if text is None:
            return None
        if _PROJECT.search(text):
            return cur
        if cur.parent == cur or not (cur.parent / "CMakeLists.txt").is_file():
            return None
        cur = cur.parent
    return None


_INCLUDE = re.compile(rb"#\s*include\s*[\"<]([^\">\n]+)[\">]")


def _included_names(texts: Mapping[str, bytes]) -> set[str]:
    """The file names that ``#include`` lines of ``texts`` name (a source file included
    by another is compiled with it)."""
    out: set[str] = set()
    for data in texts.values():
        for m in _INCLUDE.finditer(data):
            name = m.group(1).decode("utf-8", "replace").rsplit("/", 1)[-1]
            if Path(name).suffix.lower() in SOURCE_SUFFIXES:
                out.add(name)
    return out
