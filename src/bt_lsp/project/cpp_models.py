"""The C++ node catalog each BT file sees: its package's and its dependencies' nodes.

A file inside a ROS package (the nearest ``package.xml``) sees the C++ of that package and
of the packages it depends on that are in the same workspace (colcon ``src/``), not every
node of the workspace; a file outside any package sees the C++ under the workspace
folders.  A package's C++ is every C++ file of the package, wherever it keeps it
(:func:`~bt_lsp.project.cpp_scan.cpp_sources`, the rule ``bt-lsp models`` follows too), or
what the ``sources`` globs of the configuration name; build, install and log folders,
test folders (but for the one holding the tree) and the ``exclude`` globs are skipped.

Files are read once and again only after :meth:`CppModels.file_changed` (or when their
modification time or size changed, for the command line); their facts come from the
content-keyed cache of :mod:`bt_lsp.project.cpp_scan`.  The nodes become
:class:`~bt_lsp.rules.context.ModelDecl` values whose path is the C++ file and whose span
is the ID's string literal, in code points.

A BT file's registrations are *all known* (so a node type missing from them is an error,
as BehaviorTree.CPP fails with "Node not recognized") only when nothing outside the C++
read can register a node for it: see :meth:`CppModels.completeness`.
"""

from __future__ import annotations

import glob
import os
import re
import threading
from collections.abc import Callable, Iterable, Sequence
from dataclasses import replace
from pathlib import Path
from types import MappingProxyType
from typing import Final, NamedTuple

from bt_lsp.cpp.catalog import FLAG_DUPLICATE_ID, FLAG_NOT_BUILT, Catalog, CppNode
from bt_lsp.cpp.extract import extract
from bt_lsp.cpp.facts import Span
from bt_lsp.project.cpp_scan import CPP_SUFFIXES, Scanner, cpp_sources, find_cpp_files, scan
from bt_lsp.project.packages import BTCPP_PACKAGES, Manifest, Packages, is_file
from bt_lsp.project.settings import Settings
from bt_lsp.rules.builtins import Category, Direction, PortModel
from bt_lsp.rules.builtins_v3 import builtins_for
from bt_lsp.rules.context import Context, ModelDecl, ModelSource
from bt_lsp.rules.cpp_names import cpp_name_diagnostics
from bt_lsp.rules.decls import NOT_BUILT
from bt_lsp.rules.diagnostics import Diagnostic

MAX_CPP_FILES: Final = 20000
_SKIP: Final = frozenset({"build", "install", "log", "node_modules", "__pycache__"})

Progress = Callable[[int, int], None]
#: A dependency that is not in the workspace: its manifest (``None`` when it is not found)
#: and the node catalogs it ships.
Resolve = Callable[[str], tuple[Manifest | None, Sequence[Path]]]

# C++ that registers nodes chosen at run time: plugin libraries named by a parameter.
_DYNAMIC: Final = re.compile(
    rb"\b(?:registerFromPlugin|registerFromROSPlugins|RegisterRosNode|"
    rb"BT_RegisterRosNodeFromPlugin|plugin_lib_names|SharedLibrary)\b"
)
# A function-like macro whose body registers nodes (its continuation lines included).
_REGISTERING_MACRO: Final = re.compile(
    rb"#[ \t]*define[ \t]+(\w+)\((?:[^\n]*\\\r?\n)*[^\n]*"
    rb"\b(?:registerNodeType|registerBuilder|registerSimple\w*)\b"
)
# Dependencies that cannot register BehaviorTree.CPP nodes, found or not: generated
# interface packages, build tools and the ROS client and transform libraries.
_NO_NODES_SUFFIXES: Final = ("_msgs", "_srvs", "_interfaces", "_cmake", "_cmake_module")
_NO_NODES_PREFIXES: Final = ("ament_", "rosidl_", "ament_cmake")
_NO_NODES: Final = frozenset(
    {
        "rclcpp",
        "rclcpp_action",
        "rclcpp_components",
        "rclcpp_lifecycle",
        "rclpy",
        "rcutils",
        "rcpputils",
        "rmw",
        "tf2",
        "tf2_ros",
        "tf2_eigen",
        "tf2_geometry_msgs",
        "eigen",
        "eigen3",
        "boost",
        "yaml-cpp",
        "yaml_cpp_vendor",
        "launch",
        "launch_ros",
        "ros2launch",
        "rosbag2_cpp",
        "gtest",
        "gmock",
    }
)


class Completeness(NamedTuple):
    """Whether a BT file's registrations are all known; if not, ``why`` (for messages).
    ``shipped`` are the node catalogs that stand for dependencies whose C++ is not
    visible."""

    complete: bool
    why: str = ""
    shipped: frozenset[str] = frozenset()


class CppModels:
    """The C++ catalogs of one workspace (thread-safe: the server scans in the background)."""

    def __init__(
        self,
        roots: Sequence[Path],
        packages: Packages | None = None,
        scanner: Scanner | None = None,
    ) -> None:
        self.roots = list(roots)
        self.packages = packages or Packages()
        self.scanner = scanner or Scanner()
        self._lock = threading.RLock()
        self._bytes: dict[Path, tuple[tuple[int, int], bytes | None]] = {}
        self._overlay: dict[Path, bytes] = {}  # open C++ documents, as edited
        self._workspace_packages: dict[str, Manifest] | None = None
        self._catalogs: dict[tuple[Path, ...], tuple[int, Catalog]] = {}
        self._files: dict[
            tuple[Path, tuple[str, ...], tuple[str, ...]], tuple[int, tuple[Path, ...]]
        ] = {}
        self._known: set[Path] = set()
        # Per package: the C++ of the workspace packages it does not see (see
        # other_packages_files), found again when a C++ file or a manifest appears or goes.
        self._other_files: dict[tuple[Path, tuple[str, ...]], tuple[int, tuple[Path, ...]]] = {}
        # The folders searched for C++ files, with their modification times when searched:
        # without watched files, one that changed (a file created or deleted in it) means
        # the file lists are found again (see :meth:`revalidate`).
        self._folder_stamps: dict[Path, int] = {}
        self.tree_generation = 0  # bumps when a C++ file or manifest appears or goes
        self._decls: dict[tuple[int, str | None], MappingProxyType[str, ModelDecl]] = {}
        self._line_starts: dict[Path, tuple[bytes, list[int]]] = {}
        self.generation = 0
        # "sync" reads the C++ when a context needs it (the command line); "background"
        # uses only catalogs already read and calls ``on_missing`` for the others (the
        # server reads them in a thread, then refreshes the diagnostics).
        self.mode = "sync"
        self.on_missing: Callable[[Path], None] | None = None
        # Called while a catalog is read in "sync" mode (the command line's progress line).
        self.progress: Progress | None = None
        # True when every change of a file is reported (the editor watches them): a file
        # read once is not looked at again until :meth:`file_changed`.
        self.watched = False
        self._complete: dict[tuple[Path, tuple[Path, ...]], tuple[int, Completeness]] = {}

    # --- which files ---------------------------------------------------------------------

    def workspace_packages(self) -> dict[str, Manifest]:
        """The ROS packages under the workspace folders, by name (the first of a name)."""
        if self._workspace_packages is None:
            found: dict[str, Manifest] = {}
            for root in self.roots:
                for dirpath, dirnames, filenames in os.walk(root):
                    dirnames[:] = sorted(
                        d for d in dirnames if d not in _SKIP and not d.startswith(".")
                    )
                    if "package.xml" in filenames:
                        m = self.packages.manifest(Path(dirpath) / "package.xml")
                        if m is not None:
                            found.setdefault(m.name, m)
            self._workspace_packages = found
        return self._workspace_packages

    def visible_packages(self, path: Path) -> list[Manifest] | None:
        """The package of ``path`` and the workspace packages it depends on (transitively);
        ``None`` when ``path`` is in no package."""
        own = self.packages.package_of(path.parent)
        if own is None:
            return None
        ws = self.workspace_packages()
        out: dict[str, Manifest] = {own.name: own}
        todo = [own]
        while todo:
            m = todo.pop()
            for dep in sorted(m.depends):
                d = ws.get(dep)
                if d is not None and d.name not in out:
                    out[d.name] = d
                    todo.append(d)
        return list(out.values())

    def files_for(
        self, path: Path, sources: Sequence[str] = (), exclude: Sequence[str] = ()
    ) -> tuple[Path, ...]:
        """The C++ files whose registrations the BT file at ``path`` sees (found again only
        when a C++ file or a manifest appears or goes)."""
        key = (path.parent, tuple(sources), tuple(exclude))
        with self._lock:
            hit = self._files.get(key)
            if hit is not None and hit[0] == self.tree_generation:
                return hit[1]
            generation = self.tree_generation
        files = self._find(path, sources, exclude)
        folders = {} if self.watched else self._searched_folders(path, files)
        with self._lock:
            if generation == self.tree_generation:
                self._files[key] = (generation, files)
                self._known.update(files)
                self._folder_stamps.update(folders)
        return files

    def _searched_folders(self, path: Path, files: tuple[Path, ...]) -> dict[Path, int]:
        """The folders whose modification time says whether a C++ file was created or
        deleted where :meth:`_find` looked for ``path``: the package folders (or
        workspace folders), their ``src`` and ``include``, the folders below them that
        were walked, and those of the files found (the ``sources`` globs' too)."""
        pkgs = self.visible_packages(path)
        tops = (
            [m.folder for m in pkgs]
            if pkgs is not None
            else [r if r.is_dir() else r.parent for r in self.roots]
        )
        found: dict[Path, int] = {}
        for top in tops:
            for folder in (top, top / "src", top / "include"):
                stamp = _mtime(folder)
                if stamp is not None:
                    found[folder] = stamp
        for f in files:
            for folder in f.parents:
                if folder in found:
                    break
                stamp = _mtime(folder)
                if stamp is None:
                    break
                found[folder] = stamp
                if not any(_under(folder, t) for t in tops):
                    break
        return found

    def revalidate(self) -> bool:
        """Without watched files: forget the C++ files whose modification time or size
        changed since they were read (deleted ones too), and find the files again when a
        folder searched changed (a file created or deleted in it).  Only stats: the files
        read and the folders searched.  ``True`` if anything changed."""
        if self.watched:
            return False
        with self._lock:
            read = [(p, stamp) for p, (stamp, _) in self._bytes.items()]
            folders = list(self._folder_stamps.items())
        changed = [p for p, stamp in read if _file_stamp(p) != stamp]
        for p in changed:
            self.file_changed(p)
        moved = [d for d, t in folders if _mtime(d) != t]
        if moved:
            with self._lock:
                for d in moved:
                    self._folder_stamps.pop(d, None)
                self._workspace_packages = None
                self.tree_generation += 1
                self.generation += 1
        return bool(changed or moved)

    def _find(
        self, path: Path, sources: Sequence[str] = (), exclude: Sequence[str] = ()
    ) -> tuple[Path, ...]:
        pkgs = self.visible_packages(path)
        folders = (
            [m.folder for m in pkgs]
            if pkgs is not None
            else [r if r.is_dir() else r.parent for r in self.roots]
        )
        if sources:
            found = _glob(sources)
            if pkgs is not None:
                found = [f for f in found if any(_under(f, d) for d in folders)]
        else:
            found = []
            for folder in folders:
                found.extend(cpp_sources(folder, path))
        if exclude:
            found = [f for f in found if not any(f.match(g) for g in exclude)]
        return tuple(sorted(dict.fromkeys(found))[:MAX_CPP_FILES])

    # --- reading -------------------------------------------------------------------------

    def read(self, path: Path) -> bytes | None:
        """The bytes of the C++ file at ``path`` (an open document's text as edited)."""
        return self._read(path)

    def _read(self, path: Path) -> bytes | None:
        with self._lock:
            over = self._overlay.get(path)
            if over is not None:
                return over
            if self.watched:
                kept = self._bytes.get(path)
                if kept is not None:
                    return kept[1]
            try:
                st = path.stat()
            except (OSError, ValueError):
                return None
            stamp = (st.st_mtime_ns, st.st_size)
            hit = self._bytes.get(path)
            if hit is not None and hit[0] == stamp:
                return hit[1]
            try:
                data: bytes | None = path.read_bytes()
            except OSError:
                data = None
            self._bytes[path] = (stamp, data)
            return data

    def catalog(self, files: tuple[Path, ...], progress: Progress | None = None) -> Catalog:
        """The catalog of ``files``, linked again only when one of them changed."""
        with self._lock:
            hit = self._catalogs.get(files)
            if hit is not None and hit[0] == self.generation:
                return hit[1]
            generation = self.generation
        cat = scan(list(files), self.scanner, read=self._read, progress=progress or self.progress)
        with self._lock:
            kept = self._catalogs.get(files)
            if kept is None or kept[0] <= generation:
                self._catalogs[files] = (generation, cat)
        return cat

    def catalog_for(
        self,
        path: Path,
        sources: Sequence[str] = (),
        exclude: Sequence[str] = (),
        progress: Progress | None = None,
    ) -> Catalog:
        return self.catalog(self.files_for(path, sources, exclude), progress)

    def latest_catalog_for(
        self, path: Path, sources: Sequence[str] = (), exclude: Sequence[str] = ()
    ) -> Catalog | None:
        """The last catalog read for ``path`` (maybe stale), without reading anything."""
        return self._latest(self.files_for(path, sources, exclude))[0]

    def latest(self, files: tuple[Path, ...]) -> Catalog | None:
        """The last catalog read for ``files`` (maybe stale)."""
        return self._latest(files)[0]

    def _latest(self, files: tuple[Path, ...]) -> tuple[Catalog | None, bool]:
        with self._lock:
            hit = self._catalogs.get(files)
            if hit is None:
                return None, False
            return hit[1], hit[0] == self.generation

    # --- changes -------------------------------------------------------------------------

    def file_changed(self, path: Path) -> bool:
        """A file changed on disk; true when it is one this reads (C++ or a package.xml)."""
        if path.suffix not in CPP_SUFFIXES and path.name != "package.xml":
            return False
        with self._lock:
            self._bytes.pop(path, None)
            gone = not path.exists()
            if path.name == "package.xml" or path not in self._known or gone:
                self._workspace_packages = None
                self.tree_generation += 1
            if gone:  # created again later, it is a new file: the file lists change again
                self._known.discard(path)
            self.generation += 1
        return True

    def set_open(self, path: Path, text: str | None) -> None:
        """An open C++ document's text (``None`` when it is closed)."""
        with self._lock:
            if text is None:
                self._overlay.pop(path, None)
            else:
                self._overlay[path] = text.encode("utf-8", "surrogatepass")
            self.generation += 1

    # --- as models -----------------------------------------------------------------------

    def context_with_models(
        self, ctx: Context, path: Path, settings: Settings, resolve: Resolve | None = None
    ) -> Context:
        """``ctx`` with the C++ nodes ``path`` sees among its models, and whether they are
        all the nodes registered (see :meth:`completeness`; ``resolve`` finds the
        dependencies that are not in the workspace).

        A node read completely (authoritative) wins over a ``<TreeNodesModel>``
        declaration of the same ID; one with flags only fills a gap.  The catalog a
        workspace package ships is what its author wrote next to the C++ that is read
        here: for a node that C++ does not register where it was read, it is advisory (a
        hand-kept catalog may lag behind the code BehaviorTree.CPP registers).
        """
        files = self.files_for(path, settings.sources, settings.exclude)
        if self.mode == "sync":
            cat: Catalog | None = self.catalog(files)
        else:  # the last catalog read, while a newer one is read in the background
            cat, fresh = self._latest(files)
            if not fresh and self.on_missing is not None:
                self.on_missing(path)
        if cat is None:
            return ctx
        known = self.completeness(path, files, cat, resolve)
        own = self._catalogs_with_cpp(ctx, files)
        merged = dict(ctx.models)
        _demote_own_catalogs(merged, own, cat)
        others: list[ModelDecl] = []
        if not known.complete:
            # A node of another workspace package may be loaded by name at run time (Nav2's
            # plugin libraries): known, but advisory.
            others = self._other_packages_decls(path, settings, ctx.btcpp_version)
        if not cat.nodes and not known.complete and not others:
            # No C++ nodes: the messages need not say what was not read.
            if not own:
                return ctx
            return replace(
                ctx, models=MappingProxyType(merged), sources=(*ctx.sources, ("cpp", own))
            )
        builtins = builtins_for(ctx.btcpp_version)
        decls = self.decls(cat, ctx.btcpp_version)
        for id_, d in decls.items():
            node = cat.by_id[id_]
            if id_ not in merged:
                merged[id_] = d
            elif node.authoritative:
                merged[id_] = _with_catalog_types(d, merged[id_])
            elif FLAG_DUPLICATE_ID in node.flags and merged[id_].authoritative:
                # Two classes register the ID (one maybe in a program that is not built):
                # which one the program that loads this tree registers is not known, so
                # no port list of the ID is: a catalog says what one program registered.
                merged[id_] = d
        for d in others:
            merged.setdefault(d.id, d)
        registered: frozenset[str] | None = None
        if known.complete:
            # The C++ nodes (those of unknown kind too) and what catalogs say is registered
            # (those of the packages whose C++ is not visible among them).
            registered = frozenset(n.id for n in cat.nodes if n.id not in builtins) | {
                i for i, d in ctx.models.items() if d.authoritative or d.path in known.shipped
            }
        return replace(
            ctx,
            models=MappingProxyType(merged),
            registered=registered,
            incomplete=known.why,
            sources=(*ctx.sources, ("cpp", id(decls), known, tuple(others))),
        )

    def other_packages_files(self, path: Path, settings: Settings) -> tuple[Path, ...]:
        """The C++ files of the workspace packages that the package of ``path`` neither is
        nor depends on (none outside a package, or with ``sources``: then every file read
        is already seen)."""
        pkgs = self.visible_packages(path)
        if pkgs is None or settings.sources:
            return ()
        key = (pkgs[0].folder, tuple(settings.exclude))
        with self._lock:
            hit = self._other_files.get(key)
            if hit is not None and hit[0] == self.tree_generation:
                return hit[1]
            generation = self.tree_generation
        mine = {m.folder for m in pkgs}
        others = [m for m in self.workspace_packages().values() if m.folder not in mine]
        files: list[Path] = []
        for m in sorted(others, key=lambda m: str(m.folder)):
            files.extend(cpp_sources(m.folder, path))
        if settings.exclude:
            files = [f for f in files if not any(f.match(g) for g in settings.exclude)]
        found = tuple(sorted(dict.fromkeys(files))[:MAX_CPP_FILES])
        with self._lock:
            if generation == self.tree_generation:
                self._other_files[key] = (generation, found)
                self._known.update(found)
        return found

    def _other_packages_decls(
        self, path: Path, settings: Settings, version: str | None
    ) -> list[ModelDecl]:
        """The nodes of :meth:`other_packages_files` as advisory models."""
        key = self.other_packages_files(path, settings)
        if not key:
            return []
        if self.mode == "sync":
            cat: Catalog | None = self.catalog(key)
        else:  # read by the server in the background, with the file's own scope
            cat, fresh = self._latest(key)
            if not fresh and self.on_missing is not None:
                self.on_missing(path)
        if cat is None:
            return []
        return [d._replace(source="cpp-other-package") for d in self.decls(cat, version).values()]

    def _catalogs_with_cpp(self, ctx: Context, files: tuple[Path, ...]) -> frozenset[str]:
        """The shipped ROS catalogs among ``ctx``'s models whose package's C++ is among
        ``files`` (a workspace package, not an installed one)."""
        out: set[str] = set()
        for p in {d.path for d in ctx.models.values() if d.source == "ros" and d.path}:
            m = self.packages.package_of(Path(p).parent)
            if m is not None and any(_under(f, m.folder) for f in files):
                out.add(p)
        return frozenset(out)

    def completeness(
        self, path: Path, files: tuple[Path, ...], cat: Catalog, resolve: Resolve | None = None
    ) -> Completeness:
        """Whether the C++ read is every registration the BT file at ``path`` can meet.

        It is when the file's ROS package has C++ that creates a ``BehaviorTreeFactory``
        (the application is here, not in a package that loads these trees from elsewhere),
        no C++ read loads plugin libraries chosen at run time (``registerFromPlugin``,
        Nav2's ``plugin_lib_names``) or registers an ID that is not a literal, and every
        dependency of the package and of its workspace dependencies that depends on
        BehaviorTree.CPP is resolved: its C++ is in the workspace, or it ships a node
        catalog.  A dependency that is not found counts as unresolved, but for those that
        cannot register nodes (``*_msgs``, ``ament_*``, ``rclcpp``, ...).
        """
        key = (path.parent, files)
        with self._lock:
            hit = self._complete.get(key)
            if hit is not None and hit[0] == self.generation:
                return hit[1]
            generation = self.generation
        found = self._completeness(path, files, cat, resolve)
        with self._lock:
            if len(self._complete) > 256:
                self._complete.clear()
            self._complete[key] = (generation, found)
        return found

    def _completeness(
        self, path: Path, files: tuple[Path, ...], cat: Catalog, resolve: Resolve | None
    ) -> Completeness:
        own = self.packages.package_of(path.parent)
        if own is None:
            return Completeness(False, "the file is in no ROS package")
        pkgs = self.visible_packages(path) or [own]
        texts = [(f, self._read(f) or b"") for f in files]
        if not any(b"BehaviorTreeFactory" in d for f, d in texts if _under(f, own.folder)):
            return Completeness(
                False,
                f"no C++ of package {own.name} creates a BehaviorTreeFactory: its trees run "
                "in an application bt-lsp does not see",
            )
        for f, d in texts:
            if _DYNAMIC.search(d):
                return Completeness(False, f"{self.shown(f)} loads node plugins chosen at run time")
            unread = self._unread_macro(f, d)
            if unread is not None:
                return Completeness(
                    False, f"macro {unread} of {self.shown(f)} registers nodes in a form not read"
                )
        if cat.unresolved:
            u = cat.unresolved[0]
            where = f"{self.shown(Path(u.path))}:{u.span[0] + 1}"
            return Completeness(False, f"the ID registered at {where} is not known statically")
        names = {m.name for m in pkgs}
        shipped: set[str] = set()
        for m in pkgs:
            for dep in sorted(m.depends - names):
                if dep in BTCPP_PACKAGES or _registers_no_nodes(dep):
                    continue
                manifest, catalogs = resolve(dep) if resolve is not None else (None, ())
                if manifest is None:
                    return Completeness(False, f"dependency {dep} of {m.name} is not found")
                if not manifest.depends & BTCPP_PACKAGES.keys():
                    continue
                if not catalogs:
                    return Completeness(
                        False,
                        f"dependency {dep} of {m.name} depends on BehaviorTree.CPP, and "
                        "neither its C++ nor a node catalog it ships is visible",
                    )
                shipped.update(str(c) for c in catalogs)
        return Completeness(True, "", frozenset(shipped))

    def _unread_macro(self, path: Path, data: bytes) -> str | None:
        """A macro of ``data`` whose body registers nodes but that the reader did not
        understand (``registerNodeType<ns::Name>``): its registrations are unknown."""
        if b"define" not in data:
            return None
        names = {m.group(1).decode() for m in _REGISTERING_MACRO.finditer(data)}
        if not names:
            return None
        read = {m.name for m in self.scanner.facts(str(path), data).macros}
        unread = sorted(names - read)
        return unread[0] if unread else None

    def shown(self, path: Path) -> str:
        """``path`` relative to the workspace folder that holds it (as given otherwise)."""
        for root in self.roots:
            folder = root if root.is_dir() else root.parent
            if _under(path, folder):
                return path.relative_to(folder).as_posix()
        return str(path)

    def decls(
        self, catalog: Catalog, version: str | None = None
    ) -> MappingProxyType[str, ModelDecl]:
        """The catalog's nodes as models by ID (the built-ins of the BehaviorTree.CPP
        ``version``, which a factory refuses to register again, and nodes of unknown kind
        left out: a node's category cannot be guessed).  A v3 project's own ``Sleep`` is
        kept: 3.8 has no such built-in."""
        builtins = builtins_for(version)
        key = (id(catalog), version)
        with self._lock:
            hit = self._decls.get(key)
            if hit is not None:
                return hit
        out: dict[str, ModelDecl] = {}
        for n in catalog.nodes:
            if n.id in builtins or n.kind is None or n.id in out:
                continue
            out[n.id] = self.decl(n)
        proxy = MappingProxyType(out)
        with self._lock:
            if len(self._decls) > 64:
                self._decls.clear()
            self._decls[key] = proxy
        return proxy

    def decl(self, n: CppNode) -> ModelDecl:
        start, end = self.offsets(Path(n.path), n.id_span)
        ports = tuple(
            PortModel(
                p.name,
                _direction(p.direction),
                p.type,
                p.default,
                p.description,
                p.resolved,
                p.classes,
            )
            for p in n.ports
        )
        # A node read completely is what BehaviorTree.CPP registers (authoritative); one
        # with flags stays advisory.
        source: ModelSource = "cpp" if n.authoritative else "cpp-partial"
        where = f"{self.shown(Path(n.path))}:{n.id_span[0] + 1}"
        if FLAG_NOT_BUILT in n.flags:
            where += NOT_BUILT
        return ModelDecl(n.id, _category(n.kind), ports, n.path, start, end, source, where)

    def offsets(self, path: Path, span: Span) -> tuple[int, int]:
        """The code-point offsets of ``span`` in the file at ``path``."""
        data = self._read(path) or b""
        with self._lock:
            hit = self._line_starts.get(path)
            if hit is None or hit[0] is not data:
                text = data.decode("utf-8", "replace")
                starts = [0]
                for i, ch in enumerate(text):
                    if ch == "\n":
                        starts.append(i + 1)
                hit = (data, starts)
                self._line_starts[path] = hit
        starts = hit[1]

        def at(line: int, col: int) -> int:
            return (starts[line] if line < len(starts) else starts[-1]) + col

        return at(span[0], span[1]), at(span[2], span[3])


def cpp_diagnostics(text: str, scanner: Scanner | None = None) -> list[Diagnostic]:
    """The name-rule diagnostics of a C++ source's string literals."""
    data = text.encode("utf-8", "surrogatepass")
    facts = scanner.facts("<document>", data) if scanner is not None else extract(data)
    return cpp_name_diagnostics(facts, text)


def _with_catalog_types(cpp: ModelDecl, other: ModelDecl) -> ModelDecl:
    """The C++ model, with the port types of an authoritative catalog of the same node.

    The C++ says which ports there are (a catalog may be older than the code); a catalog
    spells their types as BehaviorTree.CPP exports them, where the C++ spells them as
    written (``ActionResult::_error_code_type``, ``PoseStamped`` under a ``using``), so
    types compared across nodes of both sources agree.
    """
    if not other.authoritative:
        return cpp
    types = {p.name: p.type for p in other.ports if p.type}
    if not any(p.name in types and types[p.name] != p.type for p in cpp.ports):
        return cpp
    ports = tuple(
        replace(p, type=types[p.name], resolved=None, classes=frozenset())
        if p.name in types and types[p.name] != p.type
        else p
        for p in cpp.ports
    )
    return cpp._replace(ports=ports)


def _category(kind: str | None) -> Category:
    if kind == "Condition":
        return "Condition"
    if kind == "Control":
        return "Control"
    if kind == "Decorator":
        return "Decorator"
    return "Action"


def _registers_no_nodes(dep: str) -> bool:
    return (
        dep in _NO_NODES or dep.endswith(_NO_NODES_SUFFIXES) or dep.startswith(_NO_NODES_PREFIXES)
    )


def _direction(d: str) -> Direction:
    return "output" if d == "output" else "inout" if d == "inout" else "input"


def _mtime(folder: Path) -> int | None:
    try:
        return os.stat(folder).st_mtime_ns
    except (OSError, ValueError):
        return None


def _file_stamp(path: Path) -> tuple[int, int] | None:
    """What :meth:`CppModels._read` keeps a file's bytes by (``None``: not there)."""
    try:
        st = path.stat()
    except (OSError, ValueError):
        return None
    return (st.st_mtime_ns, st.st_size)


def _under(f: Path, folder: Path) -> bool:
    try:
        f.relative_to(folder)
    except ValueError:
        return False
    return True


def _demote_own_catalogs(
    models: dict[str, ModelDecl], catalogs: frozenset[str], cat: Catalog
) -> None:
    """Make the models of ``catalogs`` (shipped by packages whose C++ was read) advisory
    for the nodes the C++ read does not register: what BehaviorTree.CPP registers is that
    C++, in a form or a place not read, and the catalog may not match it."""
    if not catalogs:
        return
    for id_, d in models.items():
        if d.source == "ros" and d.path in catalogs and id_ not in cat.by_id:
            models[id_] = d._replace(source="ros-workspace")


def _glob(patterns: Iterable[str]) -> list[Path]:
    """The C++ files the ``sources`` globs name (a folder matched means its C++ files)."""
    out: list[Path] = []
    for g in patterns:
        for m in sorted(glob.glob(g, recursive=True)):
            p = Path(m)
            if p.is_dir():
                out.extend(find_cpp_files([p]))
            elif p.suffix in CPP_SUFFIXES and is_file(p):
                out.append(p)
    return out
