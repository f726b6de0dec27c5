"""The project around the documents, through the protocol: a broken bt-lsp.toml is one
diagnostic on that file, its severities apply, it is read again when it changes (on disk
or as edited), and the BehaviorTree.CPP version is in the hover on <root> and the log."""

from __future__ import annotations

from pathlib import Path

import pytest
from lsprotocol import types
from pygls.uris import from_fs_path

from tests.server.conftest import BtClient, clients, eventually

pytestmark = pytest.mark.asyncio(loop_scope="module")

TREE = (
    '<root main_tree_to_execute="T">\n'
    '  <BehaviorTree ID="T"><AlwaysSuccess/></BehaviorTree>\n'
    "</root>\n"
)


def uri_of(path: Path) -> str:
    uri = from_fs_path(str(path))
    assert uri is not None
    return uri


def open_file(client: BtClient, path: Path, text: str, language: str = "xml") -> str:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text, encoding="utf-8")
    uri = uri_of(path)
    client.opened.add(uri)
    client.text_document_did_open(
        types.DidOpenTextDocumentParams(
            text_document=types.TextDocumentItem(
                uri=uri, language_id=language, version=1, text=text
            )
        )
    )
    return uri


async def config_diagnostics(client: BtClient, uri: str, want_count: int) -> list[types.Diagnostic]:
    def check() -> list[types.Diagnostic] | None:
        last = client.latest(uri)
        if last is not None and len(last.diagnostics) == want_count:
            return list(last.diagnostics)
        return None

    return await client.wait_until(check, f"{want_count} diagnostics on {uri}")


async def severity_of(client: BtClient, uri: str, code: str, want: object) -> None:
    async def get() -> object:
        if client.pull:
            report = await client.pull_report(uri)
            assert isinstance(report, types.RelatedFullDocumentDiagnosticReport)
            found = list(report.items)
        else:
            last = client.latest(uri)
            found = list(last.diagnostics) if last is not None else []
        return next((d.severity for d in found if d.code == code), None)

    await eventually(get, lambda s: s == want, f"{code} at {want}")


def watched(client: BtClient, path: Path, kind: types.FileChangeType) -> None:
    client.workspace_did_change_watched_files(
        types.DidChangeWatchedFilesParams(changes=[types.FileEvent(uri=uri_of(path), type=kind)])
    )


@clients("vscode", "nvim-0.11")
async def test_broken_config_is_one_diagnostic_on_it_then_fixed(
    client: BtClient, tmp_path: Path
) -> None:
    config = tmp_path / "bt-lsp.toml"
    config.write_text('btcpp = "4"\n[severity]\nmissing-format = "eror"\n', encoding="utf-8")
    # The build says version 4, so the format advice is a warning without the configuration.
    (tmp_path / "CMakeLists.txt").write_text("find_package(behaviortree_cpp)\n", encoding="utf-8")
    doc = open_file(client, tmp_path / "tree.xml", TREE)
    [d] = await config_diagnostics(client, uri_of(config), 1)
    assert d.code == "config-error"
    assert d.severity == types.DiagnosticSeverity.Error
    assert d.range.start == types.Position(2, 0)
    assert d.range.end == types.Position(2, len('missing-format = "eror"'))
    assert '"eror"' in d.message and "missing-format" in d.message
    # The broken file is ignored: the defaults apply.
    await severity_of(client, doc, "missing-format", types.DiagnosticSeverity.Warning)

    config.write_text('btcpp = "4"\n[severity]\nmissing-format = "error"\n', encoding="utf-8")
    watched(client, config, types.FileChangeType.Changed)
    assert await config_diagnostics(client, uri_of(config), 0) == []
    await severity_of(client, doc, "missing-format", types.DiagnosticSeverity.Error)


@clients("vscode")
async def test_syntax_error_position_and_edits_of_the_open_file(
    client: BtClient, tmp_path: Path
) -> None:
    config = tmp_path / "bt-lsp.toml"
    config.write_text("[severity]\n", encoding="utf-8")
    (tmp_path / "CMakeLists.txt").write_text("find_package(behaviortree_cpp)\n", encoding="utf-8")
    doc = open_file(client, tmp_path / "tree.xml", TREE)
    await severity_of(client, doc, "missing-format", types.DiagnosticSeverity.Warning)
    cfg_uri = open_file(client, config, "[severity]\n", language="toml")
    # Edited, not saved: the editor's text is the configuration.
    client.replace(cfg_uri, 2, '[severity]\nmissing-format = "hint"\n')
    await severity_of(client, doc, "missing-format", types.DiagnosticSeverity.Hint)
    client.replace(cfg_uri, 3, '[severity]\nmissing-format = "hint\n')
    [d] = await config_diagnostics(client, cfg_uri, 1)
    assert d.code == "config-error" and "TOML syntax error" in d.message
    assert d.range.start.line == 1
    client.replace(cfg_uri, 4, '[severity]\nmissing-format = "off"\n')
    assert await config_diagnostics(client, cfg_uri, 0) == []
    await severity_of(client, doc, "missing-format", None)


@clients("vscode", "nvim-0.11")
async def test_version_of_a_v3_package_in_hover_and_log(client: BtClient, tmp_path: Path) -> None:
    (tmp_path / "pkg").mkdir()
    (tmp_path / "pkg" / "package.xml").write_text(
        '<package format="3"><name>pkg</name><depend>behaviortree_cpp_v3</depend></package>',
        encoding="utf-8",
    )
    seen = len(client.log_messages)
    doc = open_file(client, tmp_path / "pkg" / "trees" / "t.xml", TREE)
    diags = await client.diags(doc, 1)
    assert "missing-format" not in {d.code for d in diags}  # no v4 advice for v3
    hover = await client.hover(doc, types.Position(0, 2))
    assert hover is not None and isinstance(hover.contents, types.MarkupContent)
    assert "BehaviorTree.CPP 3" in hover.contents.value
    assert "package.xml" in hover.contents.value
    assert hover.range == types.Range(types.Position(0, 1), types.Position(0, 5))

    def logged() -> list[str] | None:
        found = [
            m.message
            for m in client.log_messages[seen:]
            if "BehaviorTree.CPP 3" in m.message and m.type == types.MessageType.Info
        ]
        return found or None

    [line] = await client.wait_until(logged, "the version in the log")
    assert str(tmp_path / "pkg") in line


@clients("nvim-0.11")
async def test_a_pull_client_pulls_the_error_of_an_open_config_file(
    client: BtClient, tmp_path: Path
) -> None:
    config = tmp_path / "bt-lsp.toml"
    config.write_text('[severity]\nmissing-format = "eror"\n', encoding="utf-8")
    open_file(client, tmp_path / "tree.xml", TREE)
    cfg_uri = open_file(client, config, config.read_text(encoding="utf-8"), language="toml")

    async def items() -> list[types.Diagnostic]:
        report = await client.pull_report(cfg_uri)
        assert isinstance(report, types.RelatedFullDocumentDiagnosticReport)
        return list(report.items)

    [d] = await eventually(items, lambda found: len(found) == 1, "the config error")
    assert d.code == "config-error" and '"eror"' in d.message
    assert (d.range.start, d.range.end) == (
        types.Position(1, 0),
        types.Position(1, len('missing-format = "eror"')),
    )
