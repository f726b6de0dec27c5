"""Paths as the project keys its files: absolute and normalized, so that one file reached
by two spellings (``a/../b.xml``, ``./b.xml``) is read, cached and diagnosed once."""

from __future__ import annotations

import os
from pathlib import Path


def normalize(path: str | os.PathLike[str]) -> Path:
    """An absolute, normalized path (``..`` folded lexically, symlinks kept)."""
    return Path(os.path.normpath(os.path.abspath(os.fspath(path))))
