"""The VS Code packages that bring their own server (scripts/vscode_bundle.py) and the script
that installs it at first start (editors/vscode/python/bootstrap.py).

Fast tests run bootstrap.py on a made-up bundle. The slow one builds the five platform
packages (wheels come from editors/vscode/.wheels-cache, filled from the package index on a
first run) and checks that each holds, for every bundled Python version, the binary wheels of
its platform; on linux-x64 it also unpacks one and runs bt-lsp from it with a Python that has
nothing installed.
"""

from __future__ import annotations

import json
import platform
import subprocess
import sys
import tomllib
import zipfile
from pathlib import Path

import pytest
from packaging.requirements import Requirement

import bt_lsp
from tests.conftest import Built

# The packages are built into editors/vscode/bundled/ and the wheel in the source tree's
# build/: slow, and on one worker under pytest -n.
pytestmark = [pytest.mark.slow, pytest.mark.xdist_group("vscode-bundle")]

ROOT = Path(__file__).resolve().parent.parent
EXT = ROOT / "editors" / "vscode"
BOOTSTRAP = EXT / "python" / "bootstrap.py"
REQUIREMENTS = EXT / "python" / "requirements.txt"
PYTHONS = {"cp311", "cp312", "cp313"}
THIS_PYTHON = f"cp{sys.version_info[0]}{sys.version_info[1]}"

# What the platform part of a binary wheel's name must say, per VS Code target.
PLATFORM_WORDS: dict[str, tuple[tuple[str, ...], ...]] = {
    "linux-x64": (("manylinux",), ("x86_64",)),
    "linux-arm64": (("manylinux",), ("aarch64",)),
    "darwin-x64": (("macosx",), ("x86_64", "universal2")),
    "darwin-arm64": (("macosx",), ("arm64", "universal2")),
    "win32-x64": (("win_amd64",),),
}


def _pins() -> dict[str, str]:
    pins = {}
    for line in REQUIREMENTS.read_text(encoding="utf-8").splitlines():
        line = line.split("#", 1)[0].strip()
        if line:
            name, version = line.split("==")
            pins[name.lower().replace("_", "-")] = version
    return pins


def test_pins_satisfy_the_dependencies() -> None:
    """A dependency raised in pyproject.toml without a new pin would bundle a version bt-lsp
    refuses (pip download then fails at package time; this says why first).  The ``live``
    extra is bundled too: the extension's server connects to running trees."""
    pins = _pins()
    project = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]
    for spec in [*project["dependencies"], *project["optional-dependencies"]["live"]]:
        req = Requirement(spec)
        name = req.name.lower().replace("_", "-")
        assert name in pins, f"{name} is not pinned in {REQUIREMENTS.name}"
        assert req.specifier.contains(pins[name]), f"{name}=={pins[name]} does not satisfy {spec}"


# --- bootstrap.py on a made-up bundle ---------------------------------------------------------


def _fake_extension(tmp_path: Path, members: dict[str, str], keys: list[str]) -> Path:
    """An extension folder with python/bootstrap.py and a bundle of one wheel (``members``:
    name -> text) listed for the Python versions ``keys``."""
    ext = tmp_path / "ext"
    (ext / "python").mkdir(parents=True)
    (ext / "python" / "bootstrap.py").write_bytes(BOOTSTRAP.read_bytes())
    wheels = ext / "bundled" / "wheels"
    wheels.mkdir(parents=True)
    name = "demo-1.0-py3-none-any.whl"
    with zipfile.ZipFile(wheels / name, "w") as zf:
        for member, text in members.items():
            zf.writestr(member, text)
    manifest = {
        "target": "linux-x64",
        "btLsp": "0.0.0",
        "pythons": ["3.11", "3.12", "3.13"],
        "wheels": {key: [name] for key in keys},
    }
    (ext / "bundled" / "manifest.json").write_text(json.dumps(manifest), encoding="utf-8")
    return ext


def _install(ext: Path, storage: Path) -> tuple[int, dict[str, object]]:
    run = subprocess.run(
        [sys.executable, "-I", str(ext / "python" / "bootstrap.py"), "install", str(storage)],
        capture_output=True,
        text=True,
        timeout=60,
        check=False,
    )
    lines = run.stdout.strip().splitlines()
    return run.returncode, (json.loads(lines[-1]) if lines else {"stderr": run.stderr})


def test_bootstrap_unpacks_once_for_this_python(tmp_path: Path) -> None:
    members = {
        "demo/__init__.py": "VALUE = 1\n",
        "demo-1.0.data/purelib/demo_extra.py": "",
        "demo-1.0.data/scripts/demo-script": "#!/bin/sh\n",
        "demo-1.0.dist-info/METADATA": "Name: demo\n",
    }
    ext = _fake_extension(tmp_path, members, [THIS_PYTHON])
    storage = tmp_path / "storage"
    code, answer = _install(ext, storage)
    assert code == 0 and answer["ok"] is True, answer
    folder = Path(str(answer["path"]))
    assert folder.parent == storage and folder.name.startswith(f"linux-x64-{THIS_PYTHON}-")
    assert (folder / "demo" / "__init__.py").read_text() == "VALUE = 1\n"
    assert (folder / "demo_extra.py").exists()  # .data/purelib goes to the top level
    assert not any("demo-script" in p.name for p in folder.rglob("*"))
    # A second start finds it and does not unpack again.
    (folder / "demo" / "__init__.py").write_text("VALUE = 2\n")
    assert _install(ext, storage) == (0, answer)
    assert (folder / "demo" / "__init__.py").read_text() == "VALUE = 2\n"
    assert sorted(p.name for p in storage.iterdir()) == [folder.name]


def test_bootstrap_runs_the_server_or_the_debug_adapter(tmp_path: Path) -> None:
    """``serve FOLDER ARGS`` and ``debug-adapter FOLDER ARGS`` run that bt-lsp command from
    FOLDER (here a stand-in bt_lsp that prints its argv)."""
    cli = tmp_path / "site" / "bt_lsp" / "cli"
    cli.mkdir(parents=True)
    (cli.parent / "__init__.py").write_text('__version__ = "9.9"\n', encoding="utf-8")
    (cli / "__init__.py").write_text("", encoding="utf-8")
    (cli / "main.py").write_text(
        "import sys\n\ndef main(argv):\n    sys.stdout.write(repr(argv))\n    return 0\n",
        encoding="utf-8",
    )
    for verb in ("serve", "debug-adapter"):
        run = subprocess.run(
            [sys.executable, "-I", str(BOOTSTRAP), verb, str(cli.parent.parent), "--stdio"],
            capture_output=True,
            text=True,
            timeout=60,
            check=False,
        )
        assert run.returncode == 0, run.stderr
        assert run.stdout == repr([verb, "--stdio"])
        assert "bt-lsp 9.9 (bundled" in run.stderr


def test_bootstrap_refuses_a_python_it_has_no_wheels_for(tmp_path: Path) -> None:
    other = sorted(PYTHONS - {THIS_PYTHON})
    ext = _fake_extension(tmp_path, {"demo/__init__.py": ""}, other)
    code, answer = _install(ext, tmp_path / "storage")
    assert code == 3 and answer["ok"] is False, answer
    version = ".".join(str(n) for n in sys.version_info[:3])
    supported = "3.11, 3.12, 3.13"
    assert answer["reason"] == f"this package bundles bt-lsp for Python {supported}, not {version}"
    assert not (tmp_path / "storage").exists() or not any((tmp_path / "storage").iterdir())


def test_bootstrap_refuses_a_wheel_that_writes_outside(tmp_path: Path) -> None:
    ext = _fake_extension(tmp_path, {"../escaped.py": ""}, [THIS_PYTHON])
    storage = tmp_path / "storage"
    code, _ = _install(ext, storage)
    assert code != 0
    assert not (tmp_path / "escaped.py").exists()
    assert not any(storage.iterdir())  # the half-unpacked folder is gone


# --- the five platform packages ---------------------------------------------------------------


@pytest.fixture(scope="module")
def packages(tmp_path_factory: pytest.TempPathFactory, built_package: Built) -> dict[str, Path]:
    if not (EXT / "node_modules" / "@vscode" / "vsce").is_dir():
        pytest.fail(
            "editors/vscode has no node_modules: run `bash editors/vscode/e2e/setup.sh`",
            pytrace=False,
        )
    out = tmp_path_factory.mktemp("vsix")
    # bt-lsp's wheel is the one the packaging test checks, built once for both.
    assert built_package.run.returncode == 0, built_package.run.stderr[-3000:]
    (wheel,) = built_package.dist.glob("bt_lsp-*.whl")
    script = [sys.executable, str(ROOT / "scripts" / "vscode_bundle.py")]
    run = subprocess.run(
        [*script, "--out", str(out), "--wheel", str(wheel)],
        capture_output=True,
        text=True,
        timeout=900,
        check=False,
    )
    assert run.returncode == 0, run.stdout[-3000:] + run.stderr[-3000:]
    return {target: out / f"bt-lsp-{target}.vsix" for target in PLATFORM_WORDS}


def _wheel_tags(name: str) -> tuple[str, str, str, str]:
    """(distribution, python tag, abi tag, platform tag) of a wheel file name."""
    parts = name.removesuffix(".whl").split("-")
    return parts[0], parts[-3], parts[-2], parts[-1]


@pytest.mark.slow
@pytest.mark.parametrize("target", sorted(PLATFORM_WORDS))
def test_platform_package_holds_its_wheels(packages: dict[str, Path], target: str) -> None:
    with zipfile.ZipFile(packages[target]) as vsix:
        names = set(vsix.namelist())
        vsixmanifest = vsix.read("extension.vsixmanifest").decode("utf-8")
        manifest = json.loads(vsix.read("extension/bundled/manifest.json"))
        package_json = json.loads(vsix.read("extension/package.json"))
    assert f'TargetPlatform="{target}"' in vsixmanifest
    assert manifest["target"] == target and manifest["pythons"] == ["3.11", "3.12", "3.13"]
    assert {"extension/python/bootstrap.py", "extension/dist/extension.js"} <= names
    assert f"extension/{package_json['icon']}" in names
    assert set(manifest["wheels"]) == PYTHONS

    shipped = {n.removeprefix("extension/bundled/wheels/") for n in names if n.endswith(".whl")}
    listed = {w for wheels in manifest["wheels"].values() for w in wheels}
    assert shipped == listed  # every wheel is used by some Python, and every one is there
    pins = _pins()
    for key, wheels in manifest["wheels"].items():
        by_dist = {_wheel_tags(w)[0].lower().replace("_", "-"): _wheel_tags(w) for w in wheels}
        assert set(by_dist) == {"bt-lsp", *pins}, (key, sorted(by_dist))
        assert f"bt_lsp-{bt_lsp.__version__}-py3-none-any.whl" in wheels
        for dist, (_, py, abi, plat) in by_dist.items():
            if dist in ("lxml", "pyzmq", "tree-sitter", "tree-sitter-cpp"):
                # Binary: for this CPython version (or the stable ABI) and this platform.
                minor = int(py.removeprefix("cp3"))
                stable = abi == "abi3" and minor <= int(key.removeprefix("cp3"))
                assert (py, abi) == (key, key) or stable, (key, dist, py, abi)
                for words in PLATFORM_WORDS[target]:
                    assert any(w in plat for w in words), (key, dist, plat)
            else:
                assert (py, abi, plat) == ("py3", "none", "any"), (key, dist)


@pytest.mark.slow
@pytest.mark.skipif(
    not (sys.platform == "linux" and platform.machine() == "x86_64"), reason="runs linux-x64 code"
)
def test_linux_package_runs_bt_lsp_from_its_wheels(
    packages: dict[str, Path], tmp_path: Path
) -> None:
    """Unpacked with the base interpreter (no site-packages of the virtual environment), the
    bundle alone checks a tree (lxml and tree-sitter come from its wheels) and has what the
    live monitor needs (pyzmq's ZeroMQ and rich)."""
    with zipfile.ZipFile(packages["linux-x64"]) as vsix:
        vsix.extractall(tmp_path / "vsix")
    ext = tmp_path / "vsix" / "extension"
    python = str(Path(getattr(sys, "_base_executable", sys.executable)).resolve())
    run = subprocess.run(
        [python, "-I", str(ext / "python" / "bootstrap.py"), "install", str(tmp_path / "storage")],
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )
    assert run.returncode == 0, run.stdout + run.stderr
    folder = json.loads(run.stdout.strip().splitlines()[-1])["path"]
    tree = tmp_path / "tree.xml"
    tree.write_text(
        '<root BTCPP_format="4">'
        '<BehaviorTree ID="Main Tree"><AlwaysSuccess/></BehaviorTree></root>\n'
    )
    code = (
        "import sys; sys.path.insert(0, sys.argv[1]); import lxml, tree_sitter_cpp, bt_lsp;"
        "import zmq, rich, bt_lsp.live.client;"
        "mods = (lxml, tree_sitter_cpp, bt_lsp, zmq, rich);"
        "assert all(m.__file__.startswith(sys.argv[1]) for m in mods), mods;"
        "assert zmq.zmq_version_info() >= (4,);"
        "from bt_lsp.cli.main import main; sys.exit(main(['check', sys.argv[2]]))"
    )
    checked = subprocess.run(
        [python, "-I", "-c", code, folder, str(tree)],
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )
    assert checked.returncode == 1, checked.stdout + checked.stderr
    assert "model-name-forbidden-char" in checked.stdout, checked.stdout


# --- what the Marketplace and Open VSX show, and what the packages may hold -----------------


def test_marketplace_metadata_is_complete() -> None:
    manifest = json.loads((EXT / "package.json").read_text(encoding="utf-8"))
    for key in ("icon", "galleryBanner", "categories", "keywords", "license", "repository"):
        assert manifest.get(key), key
    assert manifest["license"] == "Apache-2.0" and (EXT / "LICENSE").exists()
    assert manifest["repository"]["url"].startswith("https://github.com/")
    assert len(manifest["keywords"]) <= 30  # vsce refuses more
    icon = (EXT / manifest["icon"]).read_bytes()
    # A PNG of at least 128x128 pixels (the Marketplace's minimum).
    assert icon[:8] == b"\x89PNG\r\n\x1a\n"
    width, height = int.from_bytes(icon[16:20], "big"), int.from_bytes(icon[20:24], "big")
    assert width >= 128 and height >= 128
    # A workspace must not choose which program runs.
    restricted = manifest["capabilities"]["untrustedWorkspaces"]["restrictedConfigurations"]
    assert {"btLsp.server.command", "btLsp.interpreter", "btLsp.importStrategy"} <= set(restricted)


def test_packages_take_the_bundle_and_git_does_not() -> None:
    ignore = (EXT / ".vscodeignore").read_text(encoding="utf-8").splitlines()
    for kept in ("!python/bootstrap.py", "!bundled/manifest.json", "!bundled/wheels/*.whl"):
        assert kept in ignore
    gitignore = (ROOT / ".gitignore").read_text(encoding="utf-8").splitlines()
    assert {"editors/vscode/.wheels-cache/", "editors/vscode/bundled/"} <= set(gitignore)
