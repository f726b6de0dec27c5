"""Each file's settings: the command-line flags over its configuration file
(:mod:`bt_lsp.project.config`) over the editor's settings.

Made once per folder and kept, the same object, while none of them changes: the other
objects of the project index key their caches by the settings object.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace
from pathlib import Path

from bt_lsp.project.config import ConfigError, Configs, Layer
from bt_lsp.project.paths import normalize
from bt_lsp.project.settings import Settings


class SettingsIndex:
    """The settings of the files under ``roots``: ``editor`` (the editor's, or the
    defaults), each file's configuration file from ``configs`` over them, and
    ``overrides`` (command-line flags) over both."""

    def __init__(
        self,
        roots: Sequence[Path],
        editor: Settings,
        configs: Configs,
        overrides: Layer | None = None,
    ) -> None:
        self.roots = roots
        self.editor = editor
        self.configs = configs
        self.overrides = overrides
        # Folder -> (the editor settings they were made from, the folder's settings).
        self._scoped: dict[Path, tuple[Settings, Settings]] = {}

    def for_path(self, path: Path) -> Settings:
        """The settings of the file at ``path``: command-line flags over its configuration
        file over the editor settings (the same object while none of them changes)."""
        folder = path.parent
        hit = self._scoped.get(folder)
        if hit is not None and hit[0] is self.editor:
            return hit[1]
        scoped = self._editor_settings()
        config = self.configs.for_path(path)
        if config is not None and not isinstance(config, ConfigError):
            scoped = config.over(scoped)
        if self.overrides is not None:
            scoped = self.overrides.over(scoped)
        if scoped == self.editor:
            scoped = self.editor
        self._scoped[folder] = (self.editor, scoped)
        return scoped

    def _editor_settings(self) -> Settings:
        """The editor settings with their relative model files resolved against the first
        workspace folder, as they always were."""
        models = tuple(self.model_files())
        if models == self.editor.models:
            return self.editor
        return replace(self.editor, models=models)

    def model_path(self, model: Path) -> Path:
        """A ``models`` entry as an absolute path (relative to the first workspace folder)."""
        return normalize(model if model.is_absolute() or not self.roots else self.roots[0] / model)

    def model_files(self) -> list[Path]:
        """The model files named in the editor settings."""
        return [self.model_path(mp) for mp in self.editor.models]

    def set_editor(self, settings: Settings) -> None:
        self.editor = settings
        self._scoped.clear()

    def config_edited(self, path: Path, text: str | None) -> bool:
        """A configuration file open in an editor changed (``None``: closed); true if
        ``path`` may be one, and then every file's settings are made again."""
        if not self.configs.set_text(normalize(path), text):
            return False
        self._scoped.clear()
        return True

    def forget(self) -> None:
        """Make every file's settings again (a configuration file or a manifest changed)."""
        self._scoped.clear()

    def errors(self) -> list[ConfigError]:
        """The configuration files read so far that cannot be used."""
        return self.configs.errors()
