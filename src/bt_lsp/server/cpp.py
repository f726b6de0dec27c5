"""The C++ node catalog in the server: background reading, progress, C++ documents.

The XML's own diagnostics never wait for C++: a document's context uses the catalogs
already read (the last one while a newer is being read) and asks for the others, which a
worker thread reads one package scope at a time, with ``$/progress`` work-done progress
when the client supports it; then every open document's diagnostics are refreshed.
Open C++ documents are read from their text as edited (each change re-reads that file
only: the other files' facts are kept by content) and get the name-rule diagnostics of
their string literals.  Hover and definition of a C++-learned node or port reach its
registration, class and ``InputPort``/``OutputPort`` call.
"""

from __future__ import annotations

import asyncio
import itertools
import os
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING

from lsprotocol import types
from pygls.uris import from_fs_path

from bt_lsp.cpp.catalog import Catalog, CppNode, CppPort
from bt_lsp.cpp.facts import Span
from bt_lsp.ide.hover import file_link
from bt_lsp.project.cpp_models import CppModels
from bt_lsp.project.cpp_scan import CPP_SUFFIXES
from bt_lsp.rules.cpp_names import cpp_name_diagnostics
from bt_lsp.rules.diagnostics import Diagnostic
from bt_lsp.server.state import OpenDocument
from bt_lsp.syntax.document import Document

if TYPE_CHECKING:
    from bt_lsp.server.app import BtServer

CPP_LANGUAGES = frozenset({"cpp", "c", "cuda-cpp", "objective-cpp"})
# Watched so that an edit outside the editor re-reads the file (and a new package's
# manifest is seen).
WATCH_GLOBS = ("**/*.{cpp,hpp,h,cc,cxx,hh,hxx}", "**/package.xml")
_RESCAN_DELAY = 0.15  # seconds after the last C++ edit before the catalogs are read again
_tokens = itertools.count(1)


def is_cpp(od: OpenDocument) -> bool:
    return od.language_id in CPP_LANGUAGES or (
        od.path is not None and od.path.suffix in CPP_SUFFIXES
    )


class CppService:
    """Reads the catalogs the open documents need, one scan at a time, off the event loop."""

    def __init__(self, ls: BtServer) -> None:
        self.ls = ls
        self.models: CppModels | None = None
        self.progress_support = False
        self._pending: set[Path] = set()
        self._task: asyncio.Task[None] | None = None
        self._rescan: asyncio.TimerHandle | None = None

    def attach(self, params: types.InitializeParams) -> None:
        """Give the server's new workspace its C++ catalogs (at ``initialize``)."""
        window = params.capabilities.window
        self.progress_support = bool(window and window.work_done_progress)
        models = CppModels(self.ls.project.roots, self.ls.project.packages)
        models.mode = "background"
        ws = params.capabilities.workspace
        watch = ws.did_change_watched_files if ws is not None else None
        models.watched = bool(watch and watch.dynamic_registration)  # changes are reported
        models.on_missing = self.request
        self.ls.project.cpp = models
        self.models = models

    # --- reading in the background ---------------------------------------------------------

    def request(self, path: Path) -> None:
        """The catalog of the BT file at ``path`` is missing or stale: read it soon."""
        self._pending.add(path)
        if self._task is not None:
            return
        try:
            loop = asyncio.get_running_loop()
        except RuntimeError:
            return
        self._task = loop.create_task(self._run())

    async def _run(self) -> None:
        models = self.models
        if models is None:
            self._task = None
            return
        loop = asyncio.get_running_loop()
        token: str | None = None
        changed = False
        try:
            if self.progress_support:
                token = f"bt-lsp-cpp-{next(_tokens)}"
                try:
                    await asyncio.wait_for(
                        self.ls.work_done_progress.create_async(token), timeout=5
                    )
                    self.ls.work_done_progress.begin(
                        token,
                        types.WorkDoneProgressBegin(
                            title="bt-lsp: reading C++ node registrations",
                            percentage=0,
                            cancellable=False,
                        ),
                    )
                except Exception:
                    token = None
            while self._pending:
                paths = sorted(self._pending)
                self._pending.clear()
                scopes: dict[tuple[Path, ...], Path] = {}
                for p in paths:
                    s = self.ls.project.settings_for(p)
                    scopes.setdefault(models.files_for(p, s.sources, s.exclude), p)
                    other = models.other_packages_files(p, s)
                    if other:
                        scopes.setdefault(other, p)
                for files in scopes:
                    report = self._reporter(loop, token)
                    before = models.latest(files)
                    after = await loop.run_in_executor(None, models.catalog, files, report)
                    # Only a catalog that says something new changes the diagnostics (and
                    # a pull client's unchanged reports stay unchanged).
                    if (before is not None or after.nodes) and before != after:
                        changed = True
        except Exception:
            self.ls.log_error("reading the C++ node registrations")
        finally:
            if token is not None:
                self.ls.work_done_progress.end(
                    token, types.WorkDoneProgressEnd(message="C++ node catalog read")
                )
            self._task = None
        if changed:
            self.ls.publisher.refresh_all()  # the documents' contexts now find the catalogs read

    def _reporter(
        self, loop: asyncio.AbstractEventLoop, token: str | None
    ) -> Callable[[int, int], None] | None:
        if token is None:
            return None
        last = [-1]

        def report(done: int, total: int) -> None:
            pct = done * 100 // max(total, 1)
            if pct == last[0]:
                return
            last[0] = pct
            value = types.WorkDoneProgressReport(message=f"{done}/{total} files", percentage=pct)
            loop.call_soon_threadsafe(self.ls.work_done_progress.report, token, value)

        return report

    # --- C++ documents -----------------------------------------------------------------------

    def document_changed(self, od: OpenDocument, closed: bool = False) -> None:
        """An open C++ document was opened, edited or closed: read it again, soon."""
        if self.models is None or od.path is None or not is_cpp(od):
            return
        self.models.set_open(od.path, None if closed else od.doc.text)
        if self._rescan is not None:
            self._rescan.cancel()
        try:
            loop = asyncio.get_running_loop()
        except RuntimeError:
            return
        self._rescan = loop.call_later(_RESCAN_DELAY, self._refresh)

    def _refresh(self) -> None:
        self._rescan = None
        self.ls.publisher.refresh_all()  # each document's context asks for its (now stale) catalog

    def diagnostics(self, od: OpenDocument, doc: Document | None = None) -> list[Diagnostic]:
        """The name-rule diagnostics of an open C++ document's string literals (of
        ``doc``, a snapshot of it: a large one is read on the worker thread)."""
        if not is_cpp(od) or self.models is None:
            return []
        text = (doc or od.doc).text
        facts = self.models.scanner.facts(
            str(od.path or od.uri), text.encode("utf-8", "surrogatepass")
        )
        return cpp_name_diagnostics(facts, text)

    # --- hover and definition ----------------------------------------------------------------

    def _catalog(self, od: OpenDocument) -> Catalog | None:
        if self.models is None or od.path is None:
            return None
        s = self.ls.project.settings_for(od.path)
        return self.models.latest_catalog_for(od.path, s.sources, s.exclude)

    def lookup(self, od: OpenDocument, offset: int) -> tuple[CppNode, CppPort | None] | None:
        """The C++ node (and port) that the name at ``offset`` of a BT document names."""
        ref = od.doc.model.ref_at(offset)
        sym = ref.symbol if ref is not None else None
        cat = self._catalog(od) if sym is not None else None
        if sym is None or cat is None:
            return None
        if sym.kind == "model":
            node = cat.by_id.get(sym.name)
            return (node, None) if node is not None else None
        if sym.kind == "port" and sym.owner_kind == "model":
            node = cat.by_id.get(sym.owner)
            if node is not None:
                port = node.port(sym.name)
                return (node, port) if port is not None else None
        return None

    def _where(self, path: str, span: Span, markdown: bool = True) -> str:
        """``path`` relative to the workspace folder, with the line: a link to it in
        Markdown."""
        shown = self.models.shown(Path(path)) if self.models is not None else path
        shown = f"{shown}:{span[0] + 1}"
        return file_link(shown, path) if markdown else shown

    def hover_markdown(self, od: OpenDocument, offset: int, markdown: bool = True) -> str | None:
        """What the C++ says of the node or port at ``offset``: kind, class, where (linked
        when ``markdown``)."""
        found = self.lookup(od, offset)
        if found is None:
            return None
        node, port = found
        lines: list[str] = []
        if port is not None:
            p = port
            default = "no default" if p.default is None else f"default `{p.default}`"
            if p.default_is_expr:
                default += " (an expression, evaluated at run time)"
            lines.append(
                f"C++: {p.direction} port `{p.name}` of `{node.id}`, type `{p.type}`, "
                f"{default}; declared in {self._where(p.path, p.span, markdown)}."
            )
            if p.description:
                lines += ["", p.description]
            return "\n".join(lines)
        kind = node.kind or "node of unknown kind"
        cls = f" (class `{node.cls}`" if node.cls else ""
        if node.cls and node.class_path is not None and node.class_span is not None:
            cls += f", declared in {self._where(node.class_path, node.class_span, markdown)}"
        cls += ")" if node.cls else ""
        lines.append(
            f"C++: {kind} registered in {self._where(node.path, node.id_span, markdown)}{cls} "
            f"with `{node.form}`."
        )
        if node.authoritative:
            lines += ["", "Its registration and ports were read completely."]
        else:
            lines += ["", "Advisory, a static reading cannot know everything here:"]
            lines += [f"- {n}" for n in node.notes]
        return "\n".join(lines)

    def definition(self, od: OpenDocument, offset: int) -> list[types.Location] | None:
        """From a node type to its class and registration, from a port to its call."""
        found = self.lookup(od, offset)
        if found is None or self.models is None:
            return None
        node, port = found
        places: list[tuple[str, Span]] = []
        if port is not None:
            places.append((port.path, port.span))
        else:
            if node.class_path is not None and node.class_span is not None:
                places.append((node.class_path, node.class_span))
            places.append((node.path, node.id_span))
        out = []
        for path, span in places:
            uri = from_fs_path(path)
            if uri is None or not os.path.isabs(path):
                continue
            out.append(types.Location(uri=uri, range=self._range(Path(path), span)))
        return out or None

    def _range(self, path: Path, span: Span) -> types.Range:
        """``span`` (code-point columns) in the client's position encoding."""
        assert self.models is not None
        data = self.models.read(path) or b""
        lines = data.decode("utf-8", "replace").split("\n")

        def pos(line: int, col: int) -> types.Position:
            text = lines[line] if line < len(lines) else ""
            prefix = text[:col]
            enc = self.ls.encoding
            if enc == "utf-8":
                units = len(prefix.encode("utf-8", "surrogatepass"))
            elif enc == "utf-16":
                units = len(prefix.encode("utf-16-le", "surrogatepass")) // 2
            else:
                units = len(prefix)
            return types.Position(line, units)

        return types.Range(pos(span[0], span[1]), pos(span[2], span[3]))
