"""A large document's name diagnostics are published first, then the complete set."""

from __future__ import annotations

import re

import pytest
from lsprotocol import types

from bt_lsp.rules.names import PROJECT_NAME_CODES
from tests.server.conftest import (
    PROFILES,
    BtClient,
    Marked,
    Profile,
    clients,
    marked,
    names_only,
    summary,
)

pytestmark = pytest.mark.asyncio(loop_scope="module")

PROFILES["early-severity"] = Profile(
    "visual-studio-code",
    init_options={
        "debounceMs": 0,
        "severity": {"port-name-forbidden-char": "warning", "instance-name-control-char": "off"},
    },
)

# One tree, repeated to make the document large.
FILLER = (
    '  <BehaviorTree ID="Tree{i}">\n'
    '    <Sequence name="step 😋 {i}">\n'
    '      <AlwaysSuccess name="é{i}"/>\n'
    "      <!-- <Not.A.Node/> -->\n"
    "    </Sequence>\n"
    "  </BehaviorTree>\n"
)

# Bad names after non-ASCII characters on their line (their UTF-16, UTF-8 and UTF-32
# columns differ), at the start and the end of the document.
HEAD = (
    '<root BTCPP_format="4" main_tree_to_execute="Tree0">{newline}'
    '  <BehaviorTree ID="⟦First Tree⟧">\n'
    '    <Sequence name="⟦😋 a&#127;b⟧">\n'
    '      <⟦😋Do.It⟧ ⟦a.b⟧="1"/>\n'
    '      <SubTree ID="Missing"/>\n'
    "    </Sequence>\n"
    "  </BehaviorTree>\n"
)
TAIL = (
    "  <TreeNodesModel>\n"
    '    <Action ID="Go"><input_port name="name"/></Action>\n'
    "  </TreeNodesModel>\n"
    '  <BehaviorTree ID="⟦Last.Tree⟧"><Go/></BehaviorTree>\n'
    "</root>\n"
)


def big_document(newline: str = "\n") -> tuple[Marked, list[str]]:
    filler = "".join(FILLER.format(i=i) for i in range(1700))
    doc = marked(HEAD.format(newline=newline) + filler + TAIL)
    codes = [
        "model-name-forbidden-char",
        "instance-name-control-char",
        "model-name-forbidden-char",
        "port-name-forbidden-char",
        "model-name-forbidden-char",
    ]
    return doc, codes


def _full(d: types.Diagnostic) -> tuple[object, ...]:
    return (d.code, d.range, d.message, d.severity, d.data, d.source, d.code_description)


# What only the complete set says: where a name whose target is outside the workspace must
# change first (the early pass reads the document alone).
_WORKSPACE_CLAUSE = re.compile(r"; the (?:node type|tree)\b.* until then$")


def _early(d: types.Diagnostic) -> types.Diagnostic:
    found = _WORKSPACE_CLAUSE.search(d.message)
    if found is None:
        return d
    cut = found.start()
    return types.Diagnostic(
        d.range,
        d.message[:cut],
        d.severity,
        d.code,
        d.code_description,
        d.source,
        data=d.data,
    )


def _assert_names_of(
    first: types.PublishDiagnosticsParams, complete: types.PublishDiagnosticsParams
) -> None:
    """``first`` holds the name diagnostics of ``complete``, field for field (but for the
    workspace's clause of the complete set's messages, and for the reserved name of a
    declared port, which depends on the project: only the complete set has it)."""
    assert [_full(d) for d in first.diagnostics] == [
        _full(_early(d))
        for d in names_only(complete.diagnostics)
        if d.code not in PROJECT_NAME_CODES
    ]
    assert any(d.code == "port-name-reserved-groot2" for d in complete.diagnostics)
    assert any(_WORKSPACE_CLAUSE.search(d.message) for d in complete.diagnostics)


async def _publications(
    client: BtClient, uri: str, count: int = 2
) -> list[types.PublishDiagnosticsParams]:
    """The document's publications once ``count`` arrived (the complete set of a large
    document comes from the worker thread), and whatever a request after brings."""
    await client.wait_until(
        lambda: len(client.published.get(uri, [])) >= count or None, f"{count} publications"
    )
    await client.barrier()  # the early names are published while the open is handled
    return client.published.get(uri, [])


@clients("vscode", "nvim-0.7", "emacs", "vscode-utf8")
@pytest.mark.parametrize("newline", ["\n", "\r\n"])
async def test_names_first_then_everything(client: BtClient, newline: str) -> None:
    doc, codes = big_document(newline)
    assert len(doc.text) >= 256 * 1024
    uri = client.open(doc.text)
    try:
        first, complete = await _publications(client, uri)
        assert first.version == complete.version == 1
        expected = sorted(
            (c, (r.start.line, r.start.character, r.end.line, r.end.character))
            for c, r in zip(codes, doc.ranges(client.encoding), strict=True)
        )
        assert summary(first.diagnostics) == expected
        _assert_names_of(first, complete)
        assert any(d not in names_only(complete.diagnostics) for d in complete.diagnostics)
    finally:
        client.close(uri)


@clients("early-severity")
async def test_names_first_follow_the_severity_settings(client: BtClient) -> None:
    doc, _ = big_document()
    uri = client.open(doc.text)
    try:
        first, complete = await _publications(client, uri)
        levels = {(str(d.code), d.severity) for d in first.diagnostics}
        assert ("port-name-forbidden-char", types.DiagnosticSeverity.Warning) in levels
        assert "instance-name-control-char" not in {code for code, _ in levels}
        _assert_names_of(first, complete)
    finally:
        client.close(uri)


@clients("vscode")
async def test_small_or_malformed_documents_are_published_once(client: BtClient) -> None:
    doc, _ = big_document()
    small = '<root BTCPP_format="4"><BehaviorTree ID="a b"/></root>'
    malformed = doc.text.replace("</root>", "")
    for text in (small, malformed):
        uri = client.open(text)
        try:
            (only,) = await _publications(client, uri, 1)
            assert "model-name-forbidden-char" in {d.code for d in only.diagnostics}
        finally:
            client.close(uri)


@clients("nvim-0.11")
async def test_pull_clients_get_no_early_push(client: BtClient) -> None:
    doc, codes = big_document()
    uri = client.open(doc.text)
    try:
        assert await _publications(client, uri, 0) == []
        report = await client.pull_report(uri)
        assert isinstance(report, types.RelatedFullDocumentDiagnosticReport)
        # The complete set: the early names and the declared port's reserved name.
        assert sorted(str(d.code) for d in names_only(report.items)) == sorted(
            [*codes, "port-name-reserved-groot2"]
        )
    finally:
        client.close(uri)
