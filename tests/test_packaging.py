"""The package as users get it: ``python -m build`` makes an sdist and a wheel that
``twine check`` accepts, without a setuptools deprecation warning, and the wheel installed
into a fresh virtual environment gives a working ``bt-lsp`` command.

Dependencies come from wherever pip is configured to look (an index or a local mirror);
nothing here imports the checkout's sources into the new environment.
"""

from __future__ import annotations

import re
import subprocess
import sys
import tomllib
import venv
from pathlib import Path

import pytest

import bt_lsp
from tests.conftest import Built, clean_env

# On the worker that builds the VS Code packages (pytest -n): they share editors/vscode/.
pytestmark = pytest.mark.xdist_group("vscode-bundle")

ROOT = Path(__file__).resolve().parent.parent


def _run(
    argv: list[str | Path], cwd: Path, env: dict[str, str]
) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [str(a) for a in argv],
        cwd=cwd,
        env=env,
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
    )


def test_the_version_is_written_once() -> None:
    """``bt-lsp --version``, SARIF and the C++ catalog cache key read ``__version__``; the
    package metadata must take it from there, not repeat it."""
    project = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]
    assert "version" not in project
    assert "version" in project["dynamic"]
    dynamic = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["tool"][
        "setuptools"
    ]["dynamic"]
    assert dynamic["version"] == {"attr": "bt_lsp.__version__"}
    assert re.fullmatch(r"\d+\.\d+\.\d+(?:[ab]\d+|rc\d+)?", bt_lsp.__version__)


@pytest.mark.slow
def test_build_check_install_and_run(tmp_path: Path, built_package: Built) -> None:
    env = clean_env()
    dist = built_package.dist
    # The sdist, then the wheel built from it: a file missing from the sdist breaks the wheel.
    built = built_package.run
    assert built.returncode == 0, built.stdout + built.stderr
    output = built.stdout + built.stderr
    assert "deprecat" not in output.lower(), output
    wheels = sorted(dist.glob("*.whl"))
    sdists = sorted(dist.glob("*.tar.gz"))
    assert [w.name for w in wheels] == [f"bt_lsp-{bt_lsp.__version__}-py3-none-any.whl"]
    assert [s.name for s in sdists] == [f"bt_lsp-{bt_lsp.__version__}.tar.gz"]

    twine = _run(
        [sys.executable, "-m", "twine", "check", "--strict", *wheels, *sdists], tmp_path, env
    )
    assert twine.returncode == 0, twine.stdout + twine.stderr

    env_dir = tmp_path / "venv"
    # Without a pip of its own (ensurepip took a quarter of the test): this pip installs
    # into it.
    venv.EnvBuilder(with_pip=False).create(env_dir)
    python = env_dir / "bin" / "python"
    pip: list[str | Path] = [sys.executable, "-m", "pip", "--python", python, "install"]
    pip += ["--quiet", wheels[0]]
    installed = _run(pip, tmp_path, env)
    assert installed.returncode == 0, installed.stdout + installed.stderr

    # Run from elsewhere, so the checkout cannot be imported by accident.
    bt = env_dir / "bin" / "bt-lsp"
    where = _run([python, "-c", "import bt_lsp; print(bt_lsp.__file__)"], tmp_path, env)
    assert Path(where.stdout.strip()).is_relative_to(env_dir), where.stdout + where.stderr
    version = _run([bt, "--version"], tmp_path, env)
    assert version.returncode == 0, version.stderr
    assert version.stdout.strip() == f"bt-lsp {bt_lsp.__version__}"

    # The bundled example breaks every name rule once: exit status 1, the codes printed.
    checked = _run([bt, "check", ROOT / "examples"], tmp_path, env)
    assert checked.returncode == 1, checked.stdout + checked.stderr
    for code in ("model-name-forbidden-char", "port-name-leading-digit", "model-name-reserved"):
        assert code in checked.stdout, checked.stdout
