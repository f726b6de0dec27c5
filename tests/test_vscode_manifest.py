"""The VS Code extension's settings schema: every setting the server reads is declared,
with a schema VS Code accepts (no ``$ref``: settings schemas cannot point to definitions),
and the extension sends them all."""

from __future__ import annotations

import json
import re
from pathlib import Path
from typing import Any

from bt_lsp.rules.registry import CODES

REPO = Path(__file__).resolve().parent.parent
EXT = REPO / "editors" / "vscode"
SETTINGS_PY = REPO / "src" / "bt_lsp" / "project" / "settings.py"
# Read by the extension itself, not by the server.
CLIENT_ONLY = {"server.command", "trace.server", "importStrategy", "interpreter"}
JSON_TYPES = {"string", "number", "integer", "boolean", "array", "object", "null"}
LEVELS = ["error", "warning", "information", "hint", "off"]


def properties() -> dict[str, Any]:
    manifest = json.loads((EXT / "package.json").read_text(encoding="utf-8"))
    props: dict[str, Any] = manifest["contributes"]["configuration"]["properties"]
    return props


def server_keys() -> set[str]:
    """The keys Settings.parse reads from the btLsp section."""
    return set(re.findall(r'raw\.get\("(\w+)"\)', SETTINGS_PY.read_text(encoding="utf-8")))


def walk(schema: Any, where: str) -> list[str]:
    """Problems in a JSON schema fragment: a $ref, definitions, an unknown type."""
    out: list[str] = []
    if isinstance(schema, dict):
        for bad in ("$ref", "definitions", "$defs"):
            if bad in schema:
                out.append(f"{where}: {bad}")
        t = schema.get("type")
        for name in [t] if isinstance(t, str) else (t or []):
            if name not in JSON_TYPES:
                out.append(f"{where}: type {name!r}")
        for k, v in schema.items():
            out.extend(walk(v, f"{where}.{k}"))
    elif isinstance(schema, list):
        for i, v in enumerate(schema):
            out.extend(walk(v, f"{where}[{i}]"))
    return out


def test_schema_has_no_ref_and_only_known_types() -> None:
    problems = [p for key, schema in properties().items() for p in walk(schema, key)]
    assert problems == []


def test_every_server_setting_is_declared_and_nothing_else() -> None:
    keys = server_keys()
    assert {"debounceMs", "severity", "maxDocumentBytes", "rosPackages", "modelFiles"} <= keys
    declared = {k.removeprefix("btLsp.") for k in properties()}
    assert keys - declared == set()
    assert declared - CLIENT_ONLY == keys
    for key in keys:
        schema = properties()[f"btLsp.{key}"]
        assert schema.get("type") in JSON_TYPES, key
        assert "default" in schema and ("markdownDescription" in schema or "description" in schema)


def test_defaults_are_the_servers() -> None:
    from bt_lsp.project.settings import Settings

    props = properties()
    d = Settings()
    assert props["btLsp.debounceMs"]["default"] == d.debounce_ms
    assert props["btLsp.maxDocumentBytes"]["default"] == d.max_document_bytes
    assert props["btLsp.btcpp"]["default"] == d.btcpp
    assert props["btLsp.btcpp"]["enum"] == ["auto", "3", "4"]
    # Settings.parse takes the declared defaults as they are.
    parsed = Settings.parse({k.removeprefix("btLsp."): v["default"] for k, v in props.items()})
    assert parsed == d


def test_severity_levels_inline_for_known_codes() -> None:
    sev = properties()["btLsp.severity"]
    assert sev["additionalProperties"] == {"type": "string", "enum": LEVELS}
    # Written by scripts/docs_gen.py (tests/test_docs.py checks it is up to date).
    assert list(sev["properties"]) == list(CODES)
    for schema in sev["properties"].values():
        assert schema == {"type": "string", "enum": LEVELS}


def test_extension_sends_every_server_setting() -> None:
    source = (EXT / "src" / "extension.ts").read_text(encoding="utf-8")
    m = re.search(r"const SERVER_SETTINGS = \[([^\]]*)\]", source)
    assert m is not None
    assert set(re.findall(r"'(\w+)'", m.group(1))) == server_keys()


def test_open_settings_opens_where_the_server_command_can_be_set() -> None:
    source = (EXT / "src" / "extension.ts").read_text(encoding="utf-8")
    scope = properties()["btLsp.server.command"]["scope"]
    assert scope == "machine-overridable"
    # User settings, or the remote machine's in a remote window, never the default tab.
    assert "'workbench.action.openSettings'" not in source
    body = source[source.index("function openServerCommandSetting") :]
    body = body[: body.index("\n}\n")]
    assert "vscode.env.remoteName" in body
    assert "'workbench.action.openRemoteSettings'" in body
    assert "'workbench.action.openGlobalSettings'" in body
    # The setting that fixes it: the interpreter for the bundled server, else the command.
    assert "query: bundle ? 'btLsp.interpreter' : 'btLsp.server.command'" in body
    assert properties()["btLsp.interpreter"]["scope"] == "machine-overridable"
