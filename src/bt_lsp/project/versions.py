"""Which BehaviorTree.CPP major version a file is built for: the rules differ between 3
and 4 (port remapping, scripts, the built-in nodes), so every file's check needs it."""

from __future__ import annotations

from pathlib import Path

from bt_lsp.project.documents import Documents
from bt_lsp.project.package_scope import PackageScope
from bt_lsp.project.packages import Detected, Packages
from bt_lsp.project.settings_index import SettingsIndex
from bt_lsp.syntax.document import Document


class BtcppVersions:
    """The version of each file, from its settings, its package's build and manifest,
    its dependencies' manifests, and its own ``BTCPP_format``."""

    def __init__(
        self,
        settings: SettingsIndex,
        packages: Packages,
        scope: PackageScope,
        documents: Documents,
    ) -> None:
        self._settings = settings
        self._packages = packages
        self._scope = scope
        self._documents = documents

    def of(self, path: Path, doc: Document | None = None) -> Detected:
        """The BehaviorTree.CPP major version the file at ``path`` is built for: the
        ``btcpp`` setting if not ``auto``, else what its package's build uses
        (``CMakeLists.txt`` and C++ includes, then ``package.xml``: see
        :meth:`Packages.package_btcpp`; unclear when they name both versions), else its
        dependencies' ``package.xml``, else the document's ``BTCPP_format``."""
        chosen = self._settings.for_path(path).btcpp
        if chosen in ("3", "4"):
            return Detected(chosen, "the btcpp setting")
        found = self._packages.btcpp_of(path.parent)
        if found.version is not None or found.conflict:
            return found
        # A package that does not name BehaviorTree.CPP builds against the version of the
        # packages it depends on (a tutorial package over its library package).
        for folder in self._scope.package_folders(path)[1:]:
            m = self._packages.manifest(folder / "package.xml")
            if m is not None and m.btcpp is not None:
                return Detected(
                    m.btcpp,
                    f"{m.folder / 'package.xml'} (of the dependency {m.name}) names "
                    f"BehaviorTree.CPP {m.btcpp}",
                )
        doc = doc if doc is not None else self._documents.document(path)
        root = doc.model.root if doc is not None else None
        if root is not None and root.name == "root":
            written = (root.value("BTCPP_format") or "").strip()
            if written in ("3", "4"):
                return Detected(written, "the document's BTCPP_format=\"" + written + '"')
        return found
