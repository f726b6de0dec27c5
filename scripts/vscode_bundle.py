"""Build the platform-specific VS Code packages that bring their own bt-lsp server.

Each package (``bt-lsp-<target>.vsix``) holds bt-lsp's wheel, built from this checkout, and the
wheels of its dependencies for that platform and for each bundled CPython minor version
(lxml, pyzmq and tree-sitter are binary and built per version), with ``bundled/manifest.json``
saying which wheels belong to which version. At first start the extension runs
``python/bootstrap.py`` with the Python it found, which unpacks them into the extension's
storage.

    python scripts/vscode_bundle.py                       # the five targets -> editors/vscode
    python scripts/vscode_bundle.py --target linux-x64    # only one
    python scripts/vscode_bundle.py --out DIR --python 3.11

Downloaded wheels are kept in editors/vscode/.wheels-cache (ignored by git): once a target and
Python version have been resolved there, later runs neither resolve nor download again.
Needs `npm ci` in editors/vscode (for vsce) and, for a first download, the package index.
"""

from __future__ import annotations

import argparse
import hashlib
import importlib.util
import json
import shutil
import subprocess
import sys
import tempfile
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
EXT = ROOT / "editors" / "vscode"
REQUIREMENTS = EXT / "python" / "requirements.txt"
STAGE = EXT / "bundled"
CACHE = EXT / ".wheels-cache"
PYTHONS = ("3.11", "3.12", "3.13")

# VS Code target -> pip --platform tags (pip also accepts older macOS versions and universal2).
# manylinux_2_28 (glibc 2.28): lxml 6 publishes manylinux_2_26/2_28 wheels only.
TARGETS: dict[str, tuple[str, ...]] = {
    "linux-x64": ("manylinux_2_28_x86_64", "manylinux_2_17_x86_64", "manylinux2014_x86_64"),
    "linux-arm64": ("manylinux_2_28_aarch64", "manylinux_2_17_aarch64", "manylinux2014_aarch64"),
    "darwin-x64": ("macosx_10_15_x86_64",),
    "darwin-arm64": ("macosx_11_0_arm64",),
    "win32-x64": ("win_amd64",),
}


def _run(argv: list[str], cwd: Path = ROOT) -> subprocess.CompletedProcess[str]:
    return subprocess.run(argv, cwd=cwd, capture_output=True, text=True, check=False)


def _check(result: subprocess.CompletedProcess[str], what: str) -> None:
    if result.returncode != 0:
        sys.exit(f"vscode_bundle: {what} failed:\n{result.stdout[-3000:]}\n{result.stderr[-3000:]}")


def build_wheel(out: Path) -> Path:
    """bt-lsp's own wheel, built from the checkout (``python -m build --wheel`` when the
    ``build`` package is there, otherwise pip's equivalent)."""
    if importlib.util.find_spec("build") is not None:
        argv = [sys.executable, "-m", "build", "--wheel", "--outdir", str(out), str(ROOT)]
    else:
        argv = [sys.executable, "-m", "pip", "wheel", "--no-deps", "-q", "-w", str(out), str(ROOT)]
    _check(_run(argv), "building the bt-lsp wheel")
    (wheel,) = out.glob("bt_lsp-*.whl")
    return wheel


def _dependencies() -> list[str]:
    project = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]
    return [*project["dependencies"], *project["optional-dependencies"]["live"]]


def _resolution_key(target: str, python: str) -> str:
    """What decides the set of wheels for a target and Python: the pins, bt-lsp's
    dependencies and the platform tags."""
    digest = hashlib.sha256()
    for part in (REQUIREMENTS.read_text(encoding="utf-8"), *_dependencies(), target, python):
        digest.update(part.encode("utf-8") + b"\0")
    digest.update(" ".join(TARGETS[target]).encode("utf-8"))
    return digest.hexdigest()[:16]


def dependency_wheels(target: str, python: str, bt_wheel: Path, cache: Path) -> list[Path]:
    """The wheels of bt-lsp's dependencies for ``target`` and CPython ``python``, from the
    cache when this resolution was done before, else from ``pip download`` (offline first)."""
    cache.mkdir(parents=True, exist_ok=True)
    record = cache / f"resolved-{target}-cp{python.replace('.', '')}.json"
    key = _resolution_key(target, python)
    if record.exists():
        known = json.loads(record.read_text(encoding="utf-8"))
        files = [cache / name for name in known["wheels"]]
        if known["key"] == key and all(f.exists() for f in files):
            return files
    with tempfile.TemporaryDirectory() as tmp:
        base = [sys.executable, "-m", "pip", "download", "-q", "--disable-pip-version-check"]
        base += ["--only-binary=:all:", "--implementation", "cp", "--python-version", python]
        for tag in TARGETS[target]:
            base += ["--platform", tag]
        base += ["--dest", tmp, "--find-links", str(cache), "-r", str(REQUIREMENTS), str(bt_wheel)]
        result = _run([*base, "--no-index"])
        if result.returncode != 0:
            result = _run(base)
        _check(result, f"pip download for {target}, Python {python}")
        names = sorted(p.name for p in Path(tmp).glob("*.whl") if not p.name.startswith("bt_lsp-"))
        for name in names:
            if not (cache / name).exists():
                shutil.copy2(Path(tmp) / name, cache / name)
    record.write_text(json.dumps({"key": key, "wheels": names}, indent=1), encoding="utf-8")
    return [cache / name for name in names]


def stage(target: str, pythons: list[str], bt_wheel: Path, cache: Path) -> dict[str, object]:
    """Fills editors/vscode/bundled with the wheels and manifest for ``target``."""
    if STAGE.exists():
        shutil.rmtree(STAGE)
    wheels_dir = STAGE / "wheels"
    wheels_dir.mkdir(parents=True)
    shutil.copy2(bt_wheel, wheels_dir / bt_wheel.name)
    per_python: dict[str, list[str]] = {}
    for python in pythons:
        deps = dependency_wheels(target, python, bt_wheel, cache)
        for dep in deps:
            if not (wheels_dir / dep.name).exists():
                shutil.copy2(dep, wheels_dir / dep.name)
        key = f"cp{python.replace('.', '')}"
        per_python[key] = sorted([bt_wheel.name, *(d.name for d in deps)])
    manifest: dict[str, object] = {
        "target": target,
        "btLsp": bt_wheel.name.split("-")[1],
        "pythons": pythons,
        "platformTags": list(TARGETS[target]),
        "wheels": per_python,
    }
    (STAGE / "manifest.json").write_text(json.dumps(manifest, indent=1) + "\n", encoding="utf-8")
    return manifest


def package(target: str, out: Path) -> Path:
    vsix = out / f"bt-lsp-{target}.vsix"
    options = json.dumps({"target": target, "packagePath": str(vsix)})
    _check(_run(["node", str(EXT / "scripts" / "pack.js"), options], cwd=EXT), f"vsce for {target}")
    return vsix


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--target", action="append", choices=sorted(TARGETS))
    parser.add_argument("--python", action="append", choices=PYTHONS)
    parser.add_argument("--out", type=Path, default=EXT)
    parser.add_argument("--cache", type=Path, default=CACHE)
    parser.add_argument("--wheel", type=Path, help="bt-lsp's wheel (default: built now)")
    args = parser.parse_args(argv)
    targets: list[str] = args.target or list(TARGETS)
    pythons: list[str] = sorted(set(args.python or PYTHONS))
    if not (EXT / "node_modules" / "@vscode" / "vsce").is_dir():
        sys.exit("vscode_bundle: run `npm ci` in editors/vscode (or editors/vscode/e2e/setup.sh)")
    args.out.mkdir(parents=True, exist_ok=True)
    prepublish = _run(["npm", "run", "--silent", "vscode:prepublish"], cwd=EXT)
    _check(prepublish, "npm run vscode:prepublish")
    with tempfile.TemporaryDirectory() as tmp:
        bt_wheel = args.wheel or build_wheel(Path(tmp))
        try:
            for target in targets:
                stage(target, pythons, bt_wheel, args.cache)
                print(package(target, args.out.resolve()))
        finally:
            # A later `npm run package` (the package without a server) must not take them.
            shutil.rmtree(STAGE, ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
