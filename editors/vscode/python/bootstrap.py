# ruff: noqa: UP031, UP036, RUF005 -- it must parse and report on any Python 3 (see below).
"""Installs and runs the bt-lsp server bundled in a platform-specific VS Code extension.

The extension package holds bt-lsp and its dependencies as wheels for one platform and for
each supported Python minor version (``bundled/manifest.json`` lists which wheels belong to
which version). The extension runs this file with the Python it found, always with ``-I``
(isolated: neither PYTHONPATH nor the user's site-packages can shadow the bundled modules).

    python -I bootstrap.py install STORAGE
        Unpacks the wheels for this Python into a folder under STORAGE (once; later calls
        find it) and prints one JSON line: {"ok": true, "path": ..., "python": "3.12.4"}.
        Exit 3 with {"ok": false, "reason": ...} when this Python cannot run the bundle.
    python -I bootstrap.py serve FOLDER [ARGS...]
        Runs ``bt-lsp serve ARGS`` from FOLDER (the path the install step printed).
    python -I bootstrap.py debug-adapter FOLDER [ARGS...]
        Runs ``bt-lsp debug-adapter ARGS`` from FOLDER (the editor's debugger).

A wheel is a zip whose top level is what goes on sys.path, so unpacking it is an install
that needs neither pip nor venv (Debian's python3 has neither by default). The binary
wheels (lxml, tree-sitter) are built for one CPython minor version: the folder is per version.

It must stay importable by any Python 3 so that an old one gets a clear message, not a
SyntaxError: no annotations that need 3.10+, no match statement.
"""

import hashlib
import json
import os
import shutil
import sys
import tempfile
import zipfile

# This file is python/bootstrap.py in the extension; the bundle is in bundled/ beside python/.
BUNDLED = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "bundled")
MANIFEST = os.path.join(BUNDLED, "manifest.json")
WHEELS = os.path.join(BUNDLED, "wheels")
COMPLETE = ".bt-lsp-complete"
EXIT_UNSUPPORTED = 3


def _say(payload):
    sys.stdout.write(json.dumps(payload) + "\n")
    sys.stdout.flush()


def _version_key():
    return "cp%d%d" % sys.version_info[:2]


def _python_text():
    return "%d.%d.%d" % sys.version_info[:3]


def _load_manifest():
    with open(MANIFEST, encoding="utf-8") as f:
        return json.load(f)


def _bundle_id(manifest, key):
    """The folder name: changes whenever the wheels for this Python change."""
    digest = hashlib.sha256()
    for name in sorted(manifest["wheels"][key]):
        digest.update(name.encode("utf-8") + b"\0")
    return "%s-%s-%s" % (manifest["target"], key, digest.hexdigest()[:12])


def _member_target(name):
    """Where a wheel member goes, relative to the folder; None to skip it.

    ``<dist>.data/purelib/x`` and ``platlib/x`` belong at the top level; scripts, headers
    and data files are not needed to import the packages.
    """
    parts = name.split("/")
    if any(p in ("", ".", "..") for p in parts[:-1]) or os.path.isabs(name) or "\\" in name:
        raise ValueError("unsafe path in wheel: %r" % name)
    if parts[0].endswith(".data"):
        if len(parts) > 2 and parts[1] in ("purelib", "platlib"):
            return "/".join(parts[2:])
        return None
    return name


def _unpack(wheel, dest):
    with zipfile.ZipFile(wheel) as zf:
        for info in zf.infolist():
            rel = _member_target(info.filename)
            if rel is None or info.is_dir():
                continue
            out = os.path.join(dest, *rel.split("/"))
            os.makedirs(os.path.dirname(out), exist_ok=True)
            with zf.open(info) as src, open(out, "wb") as dst:
                shutil.copyfileobj(src, dst)
            mode = (info.external_attr >> 16) & 0o777
            if mode & 0o111:
                os.chmod(out, mode | 0o644)


def _prune(storage, keep, key):
    """Removes the folders of earlier bundles for this Python version (another window may
    run another Python: its folder stays)."""
    for name in os.listdir(storage):
        path = os.path.join(storage, name)
        if name != keep and ("-%s-" % key) in name and os.path.isdir(path):
            shutil.rmtree(path, ignore_errors=True)


def install(storage):
    if sys.version_info < (3, 11):
        reason = "Python %s is too old: bt-lsp needs 3.11 or newer" % _python_text()
        _say({"ok": False, "reason": reason})
        return EXIT_UNSUPPORTED
    manifest = _load_manifest()
    key = _version_key()
    if key not in manifest["wheels"]:
        supported = ", ".join(manifest["pythons"])
        _say(
            {
                "ok": False,
                "reason": "this package bundles bt-lsp for Python %s, not %s"
                % (supported, _python_text()),
            }
        )
        return EXIT_UNSUPPORTED
    bundle = _bundle_id(manifest, key)
    os.makedirs(storage, exist_ok=True)
    dest = os.path.join(storage, bundle)
    if not os.path.exists(os.path.join(dest, COMPLETE)):
        # Unpacked beside it, then renamed: another window starting at the same time either
        # wins the rename or finds the complete folder.
        tmp = tempfile.mkdtemp(prefix=".tmp-", dir=storage)
        try:
            for name in manifest["wheels"][key]:
                _unpack(os.path.join(WHEELS, name), tmp)
            with open(os.path.join(tmp, COMPLETE), "w", encoding="utf-8") as f:
                f.write(bundle + "\n")
            if os.path.exists(dest):
                shutil.rmtree(dest, ignore_errors=True)
            try:
                os.rename(tmp, dest)
            except OSError:
                if not os.path.exists(os.path.join(dest, COMPLETE)):
                    raise
        finally:
            shutil.rmtree(tmp, ignore_errors=True)
        _prune(storage, bundle, key)
    _say({"ok": True, "path": dest, "python": _python_text(), "executable": sys.executable})
    return 0


def serve(folder, args, command="serve"):
    sys.path.insert(0, folder)
    import bt_lsp
    from bt_lsp.cli.main import main

    sys.stderr.write(
        "bt-lsp %s (bundled, %s) on Python %s (%s)\n"
        % (bt_lsp.__version__, os.path.dirname(bt_lsp.__file__), _python_text(), sys.executable)
    )
    sys.stderr.flush()
    return main([command] + list(args))


def entry(argv):
    if len(argv) >= 2 and argv[0] == "install":
        return install(argv[1])
    if len(argv) >= 2 and argv[0] in ("serve", "debug-adapter"):
        return serve(argv[1], argv[2:], argv[0])
    sys.stderr.write(
        "usage: bootstrap.py install STORAGE | serve FOLDER [ARGS...]"
        " | debug-adapter FOLDER [ARGS...]\n"
    )
    return 2


if __name__ == "__main__":
    sys.exit(entry(sys.argv[1:]))
