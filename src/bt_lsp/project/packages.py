"""ROS package manifests (``package.xml``), CMake files and C++ includes, read for what
bt-lsp needs: a package's name, what it depends on, and which BehaviorTree.CPP it builds
against.

Manifests are parsed with lxml without entities, DTDs or network access, and bounded in
size; a manifest that cannot be read or parsed counts as a package without dependencies.

Which BehaviorTree.CPP a package builds against is read from what its build really uses
first: its ``CMakeLists.txt`` (``find_package``) and the ``#include`` lines of its C++
(``<behaviortree_cpp_v3/…>`` or ``<behaviortree_cpp/…>``), which beat a ``package.xml``
dependency left over from a migration; the ``package.xml`` decides when the build says
nothing.  When the build names both versions, the version is unclear: no guess is made
(:attr:`Detected.conflict`).
"""

from __future__ import annotations

import os
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Final

from lxml import etree

from bt_lsp.project.fileio import FileError, read_head

__all__ = [
    "BTCPP_PACKAGES",
    "NOT_DETECTED",
    "Detected",
    "Manifest",
    "Packages",
    "cmake_btcpp",
    "cmake_versions",
    "cpp_includes",
    "read_manifest",
]

# The BehaviorTree.CPP package names and the major version each one is.
BTCPP_PACKAGES: Final[dict[str, str]] = {
    "behaviortree_cpp_v3": "3",
    "behaviortree_cpp": "4",
}
# Every kind of dependency a package.xml can declare (format 1 to 3).
_DEPEND_TAGS: Final = frozenset(
    {
        "depend",
        "build_depend",
        "build_export_depend",
        "exec_depend",
        "run_depend",
        "test_depend",
        "buildtool_depend",
        "doc_depend",
    }
)
MAX_MANIFEST_BYTES: Final = 1024 * 1024

_PARSER: Final = etree.XMLParser(
    resolve_entities=False, no_network=True, load_dtd=False, huge_tree=False, recover=False
)
_FIND_PACKAGE: Final = re.compile(
    r"find_package\s*\(\s*(behaviortree_cpp_v3|behaviortree_cpp)\b", re.IGNORECASE
)
_CMAKE_COMMENT: Final = re.compile(r"#[^\n]*")
# An #include of a BehaviorTree.CPP header, at the start of a line (a // comment is not).
_INCLUDE: Final = re.compile(
    rb"^[ \t]*#[ \t]*include[ \t]*[<\"](behaviortree_cpp_v3|behaviortree_cpp)/", re.MULTILINE
)
_CPP_SUFFIXES: Final = frozenset({".cpp", ".hpp", ".h", ".cc", ".cxx", ".hh", ".hxx", ".ipp"})
_SKIP_DIRS: Final = frozenset({"build", "install", "log", "node_modules", "__pycache__"})
# Bounds of the include scan of one package: includes sit at the top of a file.
MAX_INCLUDE_FILES: Final = 5000
MAX_INCLUDE_BYTES: Final = 64 * 1024


@dataclass(frozen=True, slots=True)
class Manifest:
    """What a ``package.xml`` says: the package's name, folder and dependencies."""

    name: str
    folder: Path
    depends: frozenset[str]

    @property
    def btcpp(self) -> str | None:
        """The BehaviorTree.CPP major version the package depends on, if it names one
        (both named: version 4, which ROS 2 Jazzy and later ship)."""
        found = {v for k, v in BTCPP_PACKAGES.items() if k in self.depends}
        if not found:
            return None
        return max(found)


def _read_bytes(path: Path, limit: int) -> bytes | None:
    try:
        data = read_head(str(path), limit + 1)  # a FIFO or a device is never opened
    except FileError:
        return None
    return data if len(data) <= limit else None


def read_manifest(path: Path) -> Manifest | None:
    """The manifest at ``path`` (a ``package.xml``), or ``None`` if it cannot be read."""
    data = _read_bytes(path, MAX_MANIFEST_BYTES)
    if data is None:
        return None
    try:
        root = etree.fromstring(data, _PARSER)
    except etree.XMLSyntaxError:
        return None
    if not isinstance(root.tag, str) or root.tag != "package":
        return None
    name = ""
    depends: set[str] = set()
    for el in root:
        tag = el.tag
        if not isinstance(tag, str):
            continue
        text = (el.text or "").strip()
        if tag == "name":
            name = text
        elif tag in _DEPEND_TAGS and text:
            depends.add(text)
    folder = path.parent
    return Manifest(name or folder.name, folder, frozenset(depends))


def cmake_versions(path: Path) -> frozenset[str]:
    """The BehaviorTree.CPP versions a ``CMakeLists.txt`` finds with ``find_package``."""
    data = _read_bytes(path, MAX_MANIFEST_BYTES)
    if data is None:
        return frozenset()
    text = _CMAKE_COMMENT.sub("", data.decode("utf-8", "replace"))
    return frozenset(BTCPP_PACKAGES[m.group(1).lower()] for m in _FIND_PACKAGE.finditer(text))


def cmake_btcpp(path: Path) -> str | None:
    """The BehaviorTree.CPP version a ``CMakeLists.txt`` finds with ``find_package`` (both:
    4)."""
    found = cmake_versions(path)
    return max(found) if found else None


def cpp_includes(folder: Path) -> dict[str, Path]:
    """The BehaviorTree.CPP versions whose headers the C++ of the package at ``folder``
    includes, each with the first file that does (in sorted order; build folders, hidden
    folders and nested packages are skipped, and the scan is bounded)."""
    found: dict[str, Path] = {}
    seen = 0
    for dirpath, dirnames, filenames in os.walk(folder):
        here = Path(dirpath)
        dirnames[:] = sorted(
            d
            for d in dirnames
            if d not in _SKIP_DIRS
            and not d.startswith(".")
            and not is_file(here / d / "package.xml")
        )
        for name in sorted(filenames):
            if os.path.splitext(name)[1] not in _CPP_SUFFIXES:
                continue
            seen += 1
            if seen > MAX_INCLUDE_FILES:
                return found
            try:
                with open(here / name, "rb") as f:
                    data = f.read(MAX_INCLUDE_BYTES)
            except OSError:
                continue
            for m in _INCLUDE.finditer(data):
                found.setdefault(BTCPP_PACKAGES[m.group(1).decode()], here / name)
            if len(found) == len(BTCPP_PACKAGES):
                return found
    return found


def is_file(path: Path) -> bool:
    try:
        return os.path.isfile(path)
    except ValueError:
        return False


MAX_DEPTH: Final = 64


@dataclass(frozen=True, slots=True)
class Detected:
    """A BehaviorTree.CPP major version and what it was read from, for the user.
    ``conflict``: the build names both versions, so the version is unclear (``version``
    is ``None`` and ``source`` says what disagrees)."""

    version: str | None
    source: str
    conflict: bool = False


NOT_DETECTED: Final = Detected(None, "not detected")


class Packages:
    """The ROS package (nearest ``package.xml``) of each folder and the BehaviorTree.CPP
    version its build uses, cached per folder until a manifest or CMake file changes."""

    def __init__(self) -> None:
        self._package: dict[Path, Manifest | None] = {}
        self._version: dict[Path, Detected] = {}
        self._manifests: dict[Path, Manifest | None] = {}
        self._includes: dict[Path, dict[str, Path]] = {}

    def manifest(self, path: Path) -> Manifest | None:
        if path not in self._manifests:
            self._manifests[path] = read_manifest(path)
        return self._manifests[path]

    def package_of(self, folder: Path) -> Manifest | None:
        """The package whose folder holds ``folder``: the nearest ``package.xml`` above."""
        if folder in self._package:
            return self._package[folder]
        found: Manifest | None = None
        f = folder
        for _ in range(MAX_DEPTH):
            candidate = f / "package.xml"
            if is_file(candidate):
                found = self.manifest(candidate)
                break
            if f.parent == f:
                break
            f = f.parent
        self._package[folder] = found
        return found

    def btcpp_of(self, folder: Path) -> Detected:
        """The version the build of ``folder`` uses: its package's (see
        :meth:`package_btcpp`); outside a package, the nearest ``CMakeLists.txt`` above
        that finds BehaviorTree.CPP."""
        if folder in self._version:
            return self._version[folder]
        found = NOT_DETECTED
        f = folder
        for _ in range(MAX_DEPTH):
            if is_file(f / "package.xml"):
                found = self.package_btcpp(f)
                break  # a package's own files decide, never a folder above it
            cmake = f / "CMakeLists.txt"
            if is_file(cmake) and (versions := cmake_versions(cmake)):
                found = _decide({v: [f"{cmake} finds {_package_name(v)}"] for v in versions})
                break
            if f.parent == f:
                break
            f = f.parent
        self._version[folder] = found
        return found

    def package_btcpp(self, folder: Path) -> Detected:
        """The version the package at ``folder`` builds against.  What the build uses
        decides: the ``find_package`` of its ``CMakeLists.txt`` and the BehaviorTree.CPP
        headers its C++ includes; when they name one version, that one (a ``package.xml``
        that says otherwise is out of date), when both, the version is unclear.  Else its
        ``package.xml`` dependency."""
        build: dict[str, list[str]] = {}
        cmake = folder / "CMakeLists.txt"
        if is_file(cmake):
            for v in sorted(cmake_versions(cmake)):
                build.setdefault(v, []).append(f"{cmake} finds {_package_name(v)}")
        if folder not in self._includes:
            self._includes[folder] = cpp_includes(folder)
        for v, path in sorted(self._includes[folder].items()):
            build.setdefault(v, []).append(f"{path} includes <{_package_name(v)}/…>")
        manifest_path = folder / "package.xml"
        m = self.manifest(manifest_path)
        said = m.btcpp if m is not None else None
        if build:
            found = _decide(build)
            if found.version is not None and said is not None and said != found.version:
                found = Detected(
                    found.version,
                    f"{found.source}; the dependency on {_package_name(said)} in "
                    f"{manifest_path} is not what the build uses",
                )
            return found
        if said is not None:
            return Detected(said, f"{manifest_path} depends on {_package_name(said)}")
        return NOT_DETECTED

    def changed(self, path: Path) -> bool:
        """``path`` changed on disk: true (and the caches cleared) if it is a manifest or
        a CMake file.  A C++ file may include other headers now: the versions are read
        again (false: nothing else depends on it)."""
        if path.suffix in _CPP_SUFFIXES:
            self._includes.clear()
            self._version.clear()
            return False
        if path.name not in ("package.xml", "CMakeLists.txt"):
            return False
        self._package.clear()
        self._version.clear()
        self._manifests.clear()
        self._includes.clear()
        return True


def _decide(build: dict[str, list[str]]) -> Detected:
    """The version the build evidence names (``build``: version -> what says so), or,
    when it names both, a conflict that says which file says what."""
    if len(build) == 1:
        ((version, why),) = build.items()
        return Detected(version, " and ".join(why))
    said = "; ".join(
        f"{' and '.join(why)} (BehaviorTree.CPP {v})" for v, why in sorted(build.items())
    )
    return Detected(None, said, conflict=True)


def _package_name(version: str) -> str:
    return next(k for k, v in BTCPP_PACKAGES.items() if v == version)
