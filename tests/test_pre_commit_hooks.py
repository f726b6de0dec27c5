"""The pre-commit hooks of ``.pre-commit-hooks.yaml``, run by the real ``pre-commit`` on a
scratch repository, the way another project uses them: a bad tree ID blocks the commit, the
fix hook renames it, and the XML that is not BehaviorTree.CPP's (``package.xml``) is never
reported.  The hooks get the committed files: a broken tree that the commit does not touch
is not reported (nor fixed), while a SubTree that an untouched file defines still resolves.

The hook repository is a fresh git repository holding this checkout's working tree (what
``pip install`` needs and the hooks file), so uncommitted changes are what is tested.
pre-commit installs it into its own virtual environment with pip, as configured here.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
import yaml  # pre-commit's own dependency (the dev extra)

ROOT = Path(__file__).resolve().parent.parent
# What pre-commit needs to install bt-lsp from the hook repository.
HOOK_REPO_FILES = (".pre-commit-hooks.yaml", "pyproject.toml", "README.md", "LICENSE", "src")

BAD = """\
<root BTCPP_format="4" main_tree_to_execute="Main Tree">
  <BehaviorTree ID="Main Tree">
    <SubTree ID="Dock"/>
  </BehaviorTree>
</root>
"""
# Defines the tree that BAD calls, committed before: each file is checked in its project.
DOCK = """\
<root BTCPP_format="4">
  <BehaviorTree ID="Dock">
    <AlwaysSuccess/>
  </BehaviorTree>
</root>
"""
# A broken tree committed before the hooks: a commit that does not touch it passes it by.
OLD = """\
<root BTCPP_format="4" main_tree_to_execute="Old Tree">
  <BehaviorTree ID="Old Tree">
    <SubTree ID="Gone"/>
  </BehaviorTree>
</root>
"""
PACKAGE = """\
<?xml version="1.0"?>
<package format="3"><name>robot</name><version>0.0.0</version></package>
"""


def _git(cwd: Path, *args: str, env: dict[str, str]) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        ["git", "-c", "user.name=Test", "-c", "user.email=test@example.com", *args],
        cwd=cwd,
        env=env,
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
    )


def test_hooks_file_defines_both_hooks() -> None:
    hooks = {h["id"]: h for h in yaml.safe_load((ROOT / ".pre-commit-hooks.yaml").read_text())}
    assert set(hooks) == {"bt-lsp", "bt-lsp-fix"}
    for hook in hooks.values():
        assert hook["language"] == "python"
        assert hook["files"] == r"\.xml$"
        assert hook["types"] == ["xml"]
        assert hook["entry"].startswith("bt-lsp check")
        # The changed files are passed, and left out as a walk over the folder would.
        assert hook.get("pass_filenames", True) is True
        assert "--force-exclude" in hook["entry"].split()
        assert hook["require_serial"] is True
    assert "--fix" in hooks["bt-lsp-fix"]["entry"].split()
    assert "--fix" not in hooks["bt-lsp"]["entry"].split()


@pytest.mark.slow
def test_a_bad_name_blocks_the_commit_and_the_fix_hook_repairs_it(tmp_path: Path) -> None:
    if shutil.which("git") is None:
        pytest.fail("git is needed to run pre-commit")
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "VIRTUAL_ENV")}
    env["PRE_COMMIT_HOME"] = str(tmp_path / "cache")  # a fresh hook environment
    env["GIT_CONFIG_NOSYSTEM"] = "1"
    env["HOME"] = str(tmp_path)  # no user git configuration (hooksPath, templates)

    hooks = tmp_path / "hooks"
    hooks.mkdir()
    for name in HOOK_REPO_FILES:
        source = ROOT / name
        if source.is_dir():
            shutil.copytree(
                source, hooks / name, ignore=shutil.ignore_patterns("__pycache__", "*.egg-info")
            )
        else:
            shutil.copy2(source, hooks / name)
    for args in (["init", "-q"], ["add", "-A"], ["commit", "-q", "-m", "hooks"]):
        assert _git(hooks, *args, env=env).returncode == 0
    rev = _git(hooks, "rev-parse", "HEAD", env=env).stdout.strip()

    project = tmp_path / "project"
    (project / "trees").mkdir(parents=True)
    (project / "legacy").mkdir()
    # Committed before the hooks are installed: files the next commits do not touch.
    (project / "trees" / "dock.xml").write_text(DOCK, encoding="utf-8")
    (project / "legacy" / "old.xml").write_text(OLD, encoding="utf-8")
    assert _git(project, "init", "-q", env=env).returncode == 0
    for args in (["add", "-A"], ["commit", "-q", "-m", "before"]):
        assert _git(project, *args, env=env).returncode == 0
    (project / "trees" / "main.xml").write_text(BAD, encoding="utf-8")
    (project / "package.xml").write_text(PACKAGE, encoding="utf-8")
    config = project / ".pre-commit-config.yaml"

    def use(hook: str) -> None:
        repo = {"repo": str(hooks), "rev": rev, "hooks": [{"id": hook}]}
        config.write_text(yaml.safe_dump({"repos": [repo]}), encoding="utf-8")

    use("bt-lsp")
    installed = subprocess.run(
        [sys.executable, "-m", "pre_commit", "install"],
        cwd=project,
        env=env,
        capture_output=True,
        text=True,
        timeout=60,
        check=False,
    )
    assert installed.returncode == 0, installed.stdout + installed.stderr

    # The check hook: the commit is refused, and says why; package.xml is not reported.
    assert _git(project, "add", "-A", env=env).returncode == 0
    blocked = _git(project, "commit", "-m", "trees", env=env)
    out = blocked.stdout + blocked.stderr
    assert blocked.returncode != 0, out
    assert "model-name-forbidden-char" in out, out
    assert "package.xml" not in out, out
    assert "error unknown-subtree" not in out, out  # Dock is defined in dock.xml
    assert "old.xml" not in out and "Old Tree" not in out, out  # not in the commit
    assert _git(project, "rev-list", "--count", "HEAD", env=env).stdout.strip() == "1"

    # The fix hook: it renames the tree (and its use in main_tree_to_execute), which
    # pre-commit reports as a failure (files were modified); the fixed files then commit.
    use("bt-lsp-fix")
    assert _git(project, "add", "-A", env=env).returncode == 0
    fixed = _git(project, "commit", "-m", "trees", env=env)
    out = fixed.stdout + fixed.stderr
    assert fixed.returncode != 0, out
    text = (project / "trees" / "main.xml").read_text(encoding="utf-8")
    assert 'ID="Main_Tree"' in text and 'main_tree_to_execute="Main_Tree"' in text, text
    assert "Main Tree" not in text
    assert (project / "package.xml").read_text(encoding="utf-8") == PACKAGE
    assert (project / "legacy" / "old.xml").read_text(encoding="utf-8") == OLD

    assert _git(project, "add", "-A", env=env).returncode == 0
    committed = _git(project, "commit", "-m", "trees", env=env)
    assert committed.returncode == 0, committed.stdout + committed.stderr

    # A commit of XML that is not BehaviorTree.CPP's only: the hook runs and passes.
    use("bt-lsp")
    (project / "package.xml").write_text(PACKAGE.replace("0.0.0", "0.0.1"), encoding="utf-8")
    assert _git(project, "add", "-A", env=env).returncode == 0
    only = _git(project, "commit", "-m", "version", env=env)
    out = only.stdout + only.stderr
    assert only.returncode == 0, out
    assert "bt-lsp check" in out and "Passed" in out, out
