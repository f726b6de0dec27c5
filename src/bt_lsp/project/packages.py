"""ROS package manifests (``package.xml``) and CMake files, read for what bt-lsp needs:
a package's name, what it depends on, and which BehaviorTree.CPP it builds against.

Manifests are parsed with lxml without entities, DTDs or network access, and bounded in
size; a manifest that cannot be read or parsed counts as a package without dependencies.
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


def cmake_btcpp(path: Path) -> str | None:
    """The BehaviorTree.CPP version a ``CMakeLists.txt`` finds with ``find_package``."""
    data = _read_bytes(path, MAX_MANIFEST_BYTES)
    if data is None:
        return None
    text = _CMAKE_COMMENT.sub("", data.decode("utf-8", "replace"))
    found = {BTCPP_PACKAGES[m.group(1).lower()] for m in _FIND_PACKAGE.finditer(text)}
    return max(found) if found else None


def is_file(path: Path) -> bool:
    try:
        return os.path.isfile(path)
    except ValueError:
        return False


MAX_DEPTH: Final = 64


@dataclass(frozen=True, slots=True)
class Detected:
    """A BehaviorTree.CPP major version and what it was read from, for the user."""

    version: str | None
    source: str


NOT_DETECTED: Final = Detected(None, "not detected")


class Packages:
    """The ROS package (nearest ``package.xml``) of each folder and the BehaviorTree.CPP
    version its build uses, cached per folder until a manifest or CMake file changes."""

    def __init__(self) -> None:
        self._package: dict[Path, Manifest | None] = {}
        self._version: dict[Path, Detected] = {}
        self._manifests: dict[Path, Manifest | None] = {}

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
        """The version the build of ``folder`` uses: its package's ``package.xml``
        dependency, else that package's ``CMakeLists.txt``; outside a package, the nearest
        ``CMakeLists.txt`` above that finds BehaviorTree.CPP."""
        if folder in self._version:
            return self._version[folder]
        found = NOT_DETECTED
        f = folder
        for _ in range(MAX_DEPTH):
            manifest_path = f / "package.xml"
            cmake = f / "CMakeLists.txt"
            if is_file(manifest_path):
                m = self.manifest(manifest_path)
                if m is not None and m.btcpp is not None:
                    found = Detected(
                        m.btcpp, f"{manifest_path} depends on {_package_name(m.btcpp)}"
                    )
                elif is_file(cmake) and (v := cmake_btcpp(cmake)) is not None:
                    found = Detected(v, f"{cmake} finds {_package_name(v)}")
                break  # a package's own files decide, never a folder above it
            if is_file(cmake) and (v := cmake_btcpp(cmake)) is not None:
                found = Detected(v, f"{cmake} finds {_package_name(v)}")
                break
            if f.parent == f:
                break
            f = f.parent
        self._version[folder] = found
        return found

    def changed(self, path: Path) -> bool:
        """``path`` changed on disk: true (and the caches cleared) if it is a manifest or
        a CMake file."""
        if path.name not in ("package.xml", "CMakeLists.txt"):
            return False
        self._package.clear()
        self._version.clear()
        self._manifests.clear()
        return True


def _package_name(version: str) -> str:
    return next(k for k, v in BTCPP_PACKAGES.items() if v == version)
