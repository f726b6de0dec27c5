"""The documentation site's promises that can drift: the generated pages are what
``scripts/docs_gen.py`` makes of the registry and the settings schema, each diagnostic links
to its page, each page's examples really get (and lose) the code, and the schema names
exactly the keys the code reads."""

from __future__ import annotations

import importlib.util
import re
from pathlib import Path
from types import ModuleType
from typing import Any

import pytest

from bt_lsp.project.config import KEYS as CONFIG_KEYS
from bt_lsp.project.config import ConfigError, load_config
from bt_lsp.project.schema import KEYS
from bt_lsp.project.settings import Settings
from bt_lsp.rules.analysis import analyze
from bt_lsp.rules.codes import DOCS_URL
from bt_lsp.rules.registry import CODES
from bt_lsp.syntax.document import Document

ROOT = Path(__file__).resolve().parent.parent

# The codes whose page must have all its prose (the name rules and the most common ones).
DOCUMENTED = (
    "model-name-empty",
    "model-name-reserved",
    "model-name-forbidden-char",
    "port-name-empty",
    "port-name-leading-digit",
    "port-name-reserved",
    "port-name-forbidden-char",
    "instance-name-control-char",
    "undeclared-port",
    "unknown-node",
    "missing-required-port",
    "invalid-port-value",
    "blackboard-type-mismatch",
    "unknown-subtree",
    "child-count",
    "root-element",
    "xml-syntax",
    "script-syntax",
)


def _docs_gen() -> ModuleType:
    spec = importlib.util.spec_from_file_location("docs_gen", ROOT / "scripts" / "docs_gen.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_generated_pages_are_up_to_date() -> None:
    """A code or a setting added, removed or changed without running
    ``python scripts/docs_gen.py`` fails here."""
    stale = [str(p.relative_to(ROOT)) for p in _docs_gen().stale()]
    assert stale == [], f"run python scripts/docs_gen.py: {stale}"


def test_every_code_links_to_its_page() -> None:
    yml = (ROOT / "mkdocs.yml").read_text(encoding="utf-8")
    assert f"site_url: {DOCS_URL}\n" in yml
    for code, c in CODES.items():
        assert c.url == f"{DOCS_URL}rules/{code}/"
        page = ROOT / "docs" / "rules" / f"{code}.md"
        assert page.is_file(), code
        assert f"      - rules/{code}.md\n" in yml, code
        text = page.read_text(encoding="utf-8")
        assert f"# {code}\n" in text and c.severity.label in text


@pytest.mark.parametrize("code", DOCUMENTED)
def test_the_common_codes_have_their_prose(code: str) -> None:
    c = CODES[code]
    assert c.doc and c.why and c.bad and c.good and c.since, code
    assert "BehaviorTree.CPP" in c.doc
    page = (ROOT / "docs" / "rules" / f"{code}.md").read_text(encoding="utf-8")
    for part in (c.doc, c.why, c.bad, c.good):
        assert part in page


@pytest.mark.parametrize("code", list(CODES))
def test_every_code_has_its_prose(code: str) -> None:
    """Every code's page says what BehaviorTree.CPP does, why it matters and since when: a
    new code without that prose fails here."""
    c = CODES[code]
    assert c.doc and c.why and c.since, code
    page = (ROOT / "docs" / "rules" / f"{code}.md").read_text(encoding="utf-8")
    assert c.doc in page and c.why in page, code


def _document(example: str) -> str:
    """An example as a whole document: it is one (``<?xml``, ``<root``), a set of trees, or
    a tree's body."""
    if example.startswith(("<?xml", "<root")):
        return example
    if example.startswith("<BehaviorTree"):
        return f'<root BTCPP_format="4">\n{example}\n</root>\n'
    return (
        f'<root BTCPP_format="4">\n<BehaviorTree ID="Main">\n{example}\n</BehaviorTree>\n</root>\n'
    )


@pytest.mark.parametrize("code", [c for c in CODES if CODES[c].bad or CODES[c].good])
def test_examples_get_and_lose_the_code(code: str) -> None:
    """The page's bad example is reported with its code, the good one is not."""
    c = CODES[code]
    if c.bad:
        found = {d.code for d in analyze(Document(_document(c.bad)))}
        assert code in found, (code, found)
    if c.good:
        found = {d.code for d in analyze(Document(_document(c.good)))}
        assert code not in found, (code, found)


def test_the_schema_names_every_setting_the_parser_reads() -> None:
    source = (ROOT / "src" / "bt_lsp" / "project" / "settings.py").read_text(encoding="utf-8")
    read = set(re.findall(r'raw\.get\("(\w+)"\)', source))
    assert read == {k.setting for k in KEYS if k.setting is not None}
    assert tuple(k.file for k in KEYS if k.file is not None) == CONFIG_KEYS


# A value of each documented type, as the editor sends it and as the file writes it.
_SETTING_VALUES: dict[str, Any] = {
    "modelFiles": ["nodes.xml"],
    "btcpp": "3",
    "severity": {"unknown-node": "off"},
    "rosPackages": {"pkg": "/opt/pkg"},
    "debounceMs": 0,
    "maxDocumentBytes": 1000,
    "minSeverity": "warning",
}
_FILE_VALUES: dict[str, str] = {
    "models": '["nodes.xml"]',
    "btcpp": '"3"',
    "severity": '{ unknown-node = "off" }',
    "min-severity": '"warning"',
    "exclude": '["generated"]',
    "ros-packages": '{ pkg = "pkg" }',
    "sources": '["src/**"]',
}


@pytest.mark.parametrize("key", [k for k in KEYS if k.setting is not None], ids=str)
def test_each_documented_setting_takes_effect(key: Any) -> None:
    problems: list[str] = []
    parsed = Settings.parse({"btLsp": {key.setting: _SETTING_VALUES[key.setting]}}, problems)
    assert problems == []
    assert parsed != Settings(), key.setting


@pytest.mark.parametrize("key", [k for k in KEYS if k.file is not None], ids=str)
def test_each_documented_file_key_is_read(key: Any, tmp_path: Path) -> None:
    path = tmp_path / "bt-lsp.toml"
    path.write_text(f"{key.file} = {_FILE_VALUES[key.file]}\n", encoding="utf-8")
    try:
        config = load_config(path)
    except ConfigError as e:  # pragma: no cover - the failure message
        pytest.fail(str(e))
    assert config is not None
    assert config.over(Settings()) != Settings(), key.file
