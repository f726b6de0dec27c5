"""Fixtures shared by test modules of different folders."""

from __future__ import annotations

import os
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent


@dataclass(frozen=True)
class Built:
    """``python -m build`` of the checkout: its output and the folder of its sdist and wheel."""

    run: subprocess.CompletedProcess[str]
    dist: Path


def clean_env() -> dict[str, str]:
    """The environment without what would make a new virtual environment import this
    checkout."""
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "VIRTUAL_ENV")}
    env["PYTHONDONTWRITEBYTECODE"] = "1"
    return env


@pytest.fixture(scope="session")
def built_package(tmp_path_factory: pytest.TempPathFactory) -> Built:
    """The sdist, then the wheel built from it (a file missing from the sdist breaks the
    wheel), made once per session: the packaging test checks them and the VS Code packages
    bundle the wheel (both modules run on one worker under pytest -n)."""
    where = tmp_path_factory.mktemp("build")
    dist = where / "dist"
    run = subprocess.run(
        [sys.executable, "-m", "build", "--outdir", str(dist), str(ROOT)],
        cwd=where,
        env=clean_env(),
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
    )
    return Built(run, dist)
