"""Find the project's C++ files, read their node facts (with an on-disk cache) and link them.

The cache holds one JSON file per file content (``sha256`` of the bytes and of the reader's
version), in ``$XDG_CACHE_HOME/bt-lsp/cpp`` (``~/.cache/bt-lsp/cpp``): written to a
temporary file and renamed into place, so concurrent processes never see half an entry;
an entry that does not load is ignored and written again.

Only files that can declare nodes are parsed first (a text test for ``providedPorts``,
``register`` ...); a base class or constant that the link could not find is then looked
for in the other files, which are read only when their text names it.
"""

from __future__ import annotations

import hashlib
import json
import os
import re
import tempfile
import threading
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Final

import tree_sitter

from bt_lsp import __version__
from bt_lsp.cpp.catalog import Catalog, LinkMemo, link
from bt_lsp.cpp.extract import extract, may_declare_nodes, parser
from bt_lsp.cpp.facts import FileFacts, from_json, to_json
from bt_lsp.cpp.library import library_facts
from bt_lsp.project.cpp_cmake import CMakeReader

CPP_SUFFIXES: Final = frozenset({".cpp", ".hpp", ".h", ".cc", ".cxx", ".hh", ".hxx", ".ipp"})
SKIP_DIRS: Final = frozenset({"build", "install", "log", ".git", "node_modules", "__pycache__"})
TEST_DIRS: Final = frozenset({"test", "tests"})
# Bumped whenever the facts' shape or meaning changes, so old cache entries are not read.
_FORMAT: Final = "4"
_LAZY_ROUNDS: Final = 3


def default_cache_dir() -> Path:
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "bt-lsp" / "cpp"


def find_cpp_files(paths: Iterable[str | Path], exclude: Sequence[str] = ()) -> list[Path]:
    """The C++ files among ``paths`` and under the directories among them, sorted.

    Build, install and log folders (and hidden ones) are skipped, and so is any path that
    matches one of the ``exclude`` globs (relative to the directory given).
    """
    out: list[Path] = []
    for p in map(Path, paths):
        if p.is_file():
            out.append(p)
            continue
        out.extend(_walk(p, exclude, skip_packages=False, skip_tests=False))
    return sorted(dict.fromkeys(out))


def cpp_sources(folder: Path, near: Path | None = None) -> list[Path]:
    """The C++ that a folder (a ROS package, a workspace, a plain CMake project) registers
    its nodes in: every C++ file under it, wherever the package keeps it (``src/``,
    ``include/``, ``plugins/``, ``nodes/``, ...), sorted.

    One rule for ``bt-lsp models``, ``check`` and the server.  Build, install, log and
    hidden folders are skipped; so are test folders (``test``, ``tests``: test programs
    register mocks under the IDs of the real nodes), but for the one that holds ``near``
    (a tree in a test folder sees the nodes its tests register).  A package folder does
    not hold the packages nested in it (each is a package of its own, seen through the
    dependencies).
    """
    if folder.is_file():
        return [folder]
    found = _walk(folder, (), skip_packages=(folder / "package.xml").is_file(), skip_tests=True)
    if near is not None:
        try:
            parts = near.relative_to(folder).parts[:-1]
        except ValueError:
            parts = ()
        for i, part in enumerate(parts):
            if part in TEST_DIRS:
                found.extend(_walk(folder.joinpath(*parts[: i + 1]), (), True, False))
                break
    return sorted(dict.fromkeys(found))


def _walk(base: Path, exclude: Sequence[str], skip_packages: bool, skip_tests: bool) -> list[Path]:
    out: list[Path] = []
    for root, dirs, files in os.walk(base):
        here = Path(root)
        dirs[:] = sorted(
            d
            for d in dirs
            if d not in SKIP_DIRS
            and not d.startswith(".")
            and not (skip_tests and d in TEST_DIRS)
            and not (skip_packages and (here / d / "package.xml").is_file())
        )
        for name in sorted(files):
            f = here / name
            # is_file: a FIFO named *.cpp would block the read of the catalog.
            if f.suffix in CPP_SUFFIXES and f.is_file() and not _excluded(f, base, exclude):
                out.append(f)
    return out


def _excluded(f: Path, base: Path, exclude: Sequence[str]) -> bool:
    if not exclude:
        return False
    rel = f.relative_to(base)
    return any(rel.match(g) or f.match(g) for g in exclude)


@dataclass
class Scanner:
    """Reads C++ files into facts, keeping each file's facts while its content is the same.

    One per process (the server keeps one for its workspace); ``cache_dir`` ``None``
    keeps facts in memory only.
    """

    cache_dir: Path | None = field(default_factory=default_cache_dir)
    _parser: tree_sitter.Parser = field(default_factory=parser, repr=False)
    _facts: dict[str, tuple[bytes, bytes, FileFacts]] = field(default_factory=dict, repr=False)
    _eager: dict[str, tuple[bytes, bool]] = field(default_factory=dict, repr=False)
    parsed: int = 0  # files parsed (not found in memory or on disk), for benchmarks and tests
    # The last catalog linked and what it was linked from (facts and bytes, by identity).
    _linked: tuple[object, Catalog] | None = field(default=None, repr=False)
    # What the last link made of each registration (linked again only where a change
    # touches it), and the files it read lazily (read again first, so that the link
    # sees the same files and keeps what it can).
    memo: LinkMemo = field(default_factory=LinkMemo, repr=False)
    _lazy: set[str] = field(default_factory=set, repr=False)
    # Which source files the projects' CMake builds (read again when a CMakeLists changes).
    cmake: CMakeReader = field(default_factory=CMakeReader, repr=False)
    _lock: threading.Lock = field(default_factory=threading.Lock, repr=False)

    def facts(self, path: str, data: bytes) -> FileFacts:
        """The facts of ``data`` (the text of ``path``), from memory, the cache or a parse.

        The same bytes object as last time (a caller that keeps what it read) is not even
        hashed again.
        """
        with self._lock:  # the catalogs' thread and the analysis worker share the parser
            return self._facts_of(path, data)

    def _facts_of(self, path: str, data: bytes) -> FileFacts:
        kept = self._facts.get(path)
        if kept is not None and kept[0] is data:
            return kept[2]
        key = hashlib.sha256(_FORMAT.encode() + __version__.encode() + b"\0" + data).digest()
        if kept is not None and kept[1] == key:
            self._facts[path] = (data, key, kept[2])
            return kept[2]
        f = self._load(key)
        if f is None:
            f = extract(data, self._parser)
            self.parsed += 1
            self._store(key, f)
        if kept is not None and kept[2] == f:
            f = kept[2]  # the same facts: the same object, so the catalog is kept too
        self._facts[path] = (data, key, f)
        return f

    def may_declare_nodes(self, path: str, data: bytes) -> bool:
        """:func:`~bt_lsp.cpp.extract.may_declare_nodes`, remembered for the same bytes."""
        hit = self._eager.get(path)
        if hit is not None and hit[0] is data:
            return hit[1]
        found = may_declare_nodes(data)
        self._eager[path] = (data, found)
        return found

    def _entry(self, key: bytes) -> Path | None:
        if self.cache_dir is None:
            return None
        h = key.hex()
        return self.cache_dir / h[:2] / f"{h[2:40]}.json"

    def _load(self, key: bytes) -> FileFacts | None:
        entry = self._entry(key)
        if entry is None:
            return None
        try:
            with open(entry, "rb") as fh:
                return from_json(json.loads(fh.read()))
        except (OSError, ValueError, TypeError, KeyError, IndexError):
            return None  # absent or corrupt: read the file again and rewrite it

    def _store(self, key: bytes, f: FileFacts) -> None:
        entry = self._entry(key)
        if entry is None:
            return
        try:
            entry.parent.mkdir(parents=True, exist_ok=True)
            fd, tmp = tempfile.mkstemp(dir=entry.parent, prefix=".tmp-", suffix=".json")
            try:
                with os.fdopen(fd, "w", encoding="utf-8") as fh:
                    json.dump(to_json(f), fh, separators=(",", ":"))
                os.replace(tmp, entry)
            except BaseException:
                os.unlink(tmp)
                raise
        except OSError:
            pass  # a cache that cannot be written only costs time

    def forget(self, path: str) -> None:
        self._facts.pop(path, None)
        self._eager.pop(path, None)


ReadFile = Callable[[Path], bytes | None]


def _read(path: Path) -> bytes | None:
    try:
        return path.read_bytes()
    except OSError:
        return None


def scan(
    files: Sequence[Path],
    scanner: Scanner | None = None,
    *,
    read: ReadFile = _read,
    progress: Callable[[int, int], None] | None = None,
) -> Catalog:
    """The catalog of the nodes registered in ``files``.

    ``read`` gives a file's bytes (the server passes open documents' text); ``progress``
    is called with (files done, files in all).
    """
    sc = scanner or Scanner()
    texts: dict[str, bytes] = {}
    for f in files:
        data = read(f)
        if data is not None:
            texts[str(f)] = data
    eager = [p for p, d in texts.items() if sc.may_declare_nodes(p, d)]
    eager_set = set(eager)
    rest = [p for p in texts if p not in eager_set]
    read_facts: dict[str, FileFacts] = {}
    total = len(eager)
    for i, p in enumerate(eager):
        read_facts[p] = sc.facts(p, texts[p])
        if progress is not None:
            progress(i + 1, total)
    not_built = sc.cmake.not_built([Path(p) for p in texts], texts)
    # An edit that changes no fact (inside a function body, the same lines) keeps the
    # facts object, and so the catalog: nothing is linked again.
    key = (
        tuple((p, id(f)) for p, f in read_facts.items()),
        tuple((p, id(texts[p])) for p in rest),
        tuple(sorted(not_built)),
    )
    if sc._linked is not None and sc._linked[0] == key:
        return sc._linked[1]
    catalog = _link_lazily(sc, texts, read_facts, rest, not_built)
    sc._linked = (key, catalog)
    return catalog


def _link_lazily(
    sc: Scanner,
    texts: dict[str, bytes],
    read_facts: dict[str, FileFacts],
    rest: list[str],
    not_built: dict[str, str],
) -> Catalog:
    """Link, then read the other files that name what the catalog misses, and again."""
    eager = set(read_facts)
    again = [p for p in rest if p in sc._lazy]
    for p in again:
        read_facts[p] = sc.facts(p, texts[p])
    rest = [p for p in rest if p not in sc._lazy]
    catalog = link(sorted(read_facts.items()), library_facts(), sc.memo, not_built)
    for _ in range(_LAZY_ROUNDS):
        names = set(catalog.missing)
        names.update(m.name for f in read_facts.values() for m in f.macros)
        names.update(h.name for f in read_facts.values() for h in f.helpers)
        if not names or not rest:
            break
        wanted = re.compile(
            rb"\b(?:" + b"|".join(re.escape(m.encode()) for m in sorted(names)) + rb")\b"
        )
        more = [p for p in rest if wanted.search(texts[p])]
        if not more:
            break
        for p in more:
            read_facts[p] = sc.facts(p, texts[p])
        more_set = set(more)
        rest = [p for p in rest if p not in more_set]
        catalog = link(sorted(read_facts.items()), library_facts(), sc.memo, not_built)
    sc._lazy = {p for p in read_facts if p not in eager}
    return catalog
