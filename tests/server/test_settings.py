"""Settings: initializationOptions, workspace/configuration, didChangeConfiguration;
debounceMs and per-code severity overrides (including "off")."""

from __future__ import annotations

import asyncio
from typing import Any

import pytest
from lsprotocol import types

from tests.server.conftest import (
    PROFILES,
    BtClient,
    Profile,
    clients,
    eventually,
    names_only,
    partial,
)

pytestmark = pytest.mark.asyncio(loop_scope="module")

SEVERITY = {"port-name-reserved": "warning", "instance-name-control-char": "off"}
PROFILES["init-options"] = Profile(
    "visual-studio-code", init_options={"debounceMs": 0, "severity": SEVERITY}
)
PROFILES["min-severity"] = Profile(
    "visual-studio-code", init_options={"debounceMs": 0, "minSeverity": "error"}
)
# debounceMs from initializationOptions, severities from workspace/configuration.
PROFILES["configuration"] = Profile(
    "visual-studio-code", init_options={"debounceMs": 0}, configuration={"severity": SEVERITY}
)
PROFILES["configuration-pull"] = Profile(
    "neovim@v0.11.0", init_options=None, configuration={"severity": SEVERITY}
)

DOC = (
    '<root BTCPP_format="4">\n'
    '  <BehaviorTree ID="T">\n'
    '    <Sequence name="a&#7;b">\n'
    '      <Go goal="1"/>\n'
    "    </Sequence>\n"
    "  </BehaviorTree>\n"
    "  <TreeNodesModel>\n"
    '    <Action ID="Go"><input_port name="goal"/></Action>\n'
    '    <SubTree ID="T"><input_port name="name" default="x"/></SubTree>\n'
    '    <Action ID="Bad.Id"/>\n'
    "  </TreeNodesModel>\n"
    "</root>\n"
)
Sev = types.DiagnosticSeverity
DEFAULTS = {
    ("instance-name-control-char", Sev.Error),
    ("port-name-reserved", Sev.Error),
    ("model-name-forbidden-char", Sev.Error),
}
OVERRIDDEN = {("port-name-reserved", Sev.Warning), ("model-name-forbidden-char", Sev.Error)}


def _levels(diags: list[types.Diagnostic]) -> set[tuple[str, Any]]:
    return {(str(d.code), d.severity) for d in names_only(diags)}


async def _levels_now(client: BtClient, uri: str, want: set[tuple[str, Any]]) -> None:
    """Wait until the document's name diagnostics have the ``want``ed severities."""
    if client.pull:
        await eventually(
            lambda: client.pull_report(uri),
            lambda r: (
                isinstance(r, types.RelatedFullDocumentDiagnosticReport)
                and _levels(list(r.items)) == want
            ),
            f"pulled severities {want}",
        )
    else:
        try:
            await client.wait_until(
                lambda: (
                    True
                    if (last := client.latest(uri)) is not None
                    and _levels(list(last.diagnostics)) == want
                    else None
                ),
                f"pushed severities {want}",
            )
        except AssertionError as exc:
            seen = [(p.version, _levels(list(p.diagnostics))) for p in client.published[uri]]
            raise AssertionError(f"{exc}; pushed: {seen}") from None


async def _no_debounce(client: BtClient, uri: str, text: str, version: int) -> int:
    """Two edits sent back to back both get published: nothing waits for a pause."""
    enc = client.encoding
    client.change(uri, version + 1, partial(text, 0, 0, " ", enc))
    client.change(uri, version + 2, partial(" " + text, 0, 1, "", enc))
    await client.pushed(uri, version + 2)
    got = [p.version for p in client.published[uri]]
    assert version + 1 in got, got
    return version + 2


def _configure(client: BtClient, section: dict[str, Any] | None) -> None:
    """Send didChangeConfiguration: with the btLsp section, or null (the server re-reads
    workspace/configuration)."""
    settings = {"btLsp": section} if section is not None else None
    client.workspace_did_change_configuration(types.DidChangeConfigurationParams(settings=settings))


@clients("init-options")
async def test_initialization_options(client: BtClient) -> None:
    uri = client.open(DOC)
    assert _levels(await client.pushed(uri, 1)) == OVERRIDDEN
    await _no_debounce(client, uri, DOC, 1)


@clients("min-severity")
async def test_min_severity_publishes_the_errors_only(client: BtClient) -> None:
    """The hint of Go's port without a default is not published, the errors are."""
    uri = client.open(DOC.replace('<Go goal="1"/>', "<Go/>"))
    published = await client.pushed(uri, 1)
    assert {str(d.code) for d in published} == {c for c, _ in DEFAULTS}
    assert {d.severity for d in published} == {Sev.Error}
    _configure(client, {"minSeverity": "hint"})
    await client.wait_until(
        lambda: (
            True
            if (last := client.latest(uri)) is not None
            and "missing-port-without-default" in {str(d.code) for d in last.diagnostics}
            else None
        ),
        "the hint published with minSeverity hint",
    )


@clients("configuration", "configuration-pull")
async def test_workspace_configuration_at_startup(client: BtClient) -> None:
    await client.wait_until(
        lambda: True if client.configuration_requests else None, "workspace/configuration"
    )
    uri = client.open(DOC)
    await _levels_now(client, uri, OVERRIDDEN)
    if not client.pull:
        # debounceMs from initializationOptions still holds: the sections are merged.
        await _no_debounce(client, uri, DOC, 1)


@clients("configuration", "configuration-pull", "vscode", "nvim-0.11")
async def test_did_change_configuration_rereads_the_section(client: BtClient) -> None:
    uri = client.open(DOC)
    await client.diags(uri, 1)
    before = client.configuration_requests
    old = client.get_configuration(section="btLsp")
    first = await client.pull_report(uri) if client.pull else None
    try:
        client.set_configuration(
            {"debounceMs": 0, "severity": {"model-name-forbidden-char": "hint", **SEVERITY}},
            section="btLsp",
        )
        _configure(client, None)
        await _levels_now(
            client,
            uri,
            {("port-name-reserved", Sev.Warning), ("model-name-forbidden-char", Sev.Hint)},
        )
        assert client.configuration_requests > before
        if first is not None:
            # The same document version, but the settings changed: not "unchanged".
            assert isinstance(first, types.RelatedFullDocumentDiagnosticReport)
            report = await client.pull_report(uri, previous=first.result_id)
            assert isinstance(report, types.RelatedFullDocumentDiagnosticReport)
            assert report.result_id != first.result_id
    finally:
        client.set_configuration(old, section="btLsp")
        _configure(client, None)
    await _levels_now(client, uri, _expected_at_start(client))


def _expected_at_start(client: BtClient) -> set[tuple[str, Any]]:
    return (
        OVERRIDDEN
        if client.profile.configuration or client.profile_name == "init-options"
        else DEFAULTS
    )


@clients("nvim-0.7", "vscode")
async def test_did_change_configuration_with_the_settings(client: BtClient) -> None:
    uri = client.open(DOC)
    assert _levels(await client.pushed(uri, 1)) == DEFAULTS
    try:
        _configure(client, {"debounceMs": 0, "severity": SEVERITY})
        await _levels_now(client, uri, OVERRIDDEN)
        _configure(client, {"debounceMs": 0, "severity": {"model-name-forbidden-char": "off"}})
        await _levels_now(
            client,
            uri,
            {("port-name-reserved", Sev.Error), ("instance-name-control-char", Sev.Error)},
        )
    finally:
        _configure(client, {"debounceMs": 0})
    await _levels_now(client, uri, DEFAULTS)


@clients("vscode")
async def test_a_late_configuration_answer_does_not_undo_newer_settings(client: BtClient) -> None:
    uri = client.open(DOC)
    assert _levels(await client.pushed(uri, 1)) == DEFAULTS
    old = client.get_configuration(section="btLsp")
    client.configuration_gate = asyncio.Event()
    try:
        asked = client.configuration_requests
        client.set_configuration(
            {"severity": {"model-name-forbidden-char": "off"}}, section="btLsp"
        )
        _configure(client, None)  # the server asks; the answer is held back ...
        await client.wait_until(
            lambda: True if client.configuration_requests > asked else None,
            "workspace/configuration",
        )
        _configure(client, {"debounceMs": 0, "severity": SEVERITY})  # ... newer settings
        await _levels_now(client, uri, OVERRIDDEN)
        client.configuration_gate.set()  # now the old answer arrives
        await client.barrier()
        client.change(uri, 2, partial(DOC, 0, 0, " ", client.encoding))
        assert _levels(await client.pushed(uri, 2)) == OVERRIDDEN
    finally:
        client.configuration_gate.set()
        client.configuration_gate = None
        client.set_configuration(old, section="btLsp")
        _configure(client, {"debounceMs": 0})
    await _levels_now(client, uri, DEFAULTS)


@clients("vscode")
async def test_bad_settings_are_logged_and_ignored(client: BtClient) -> None:
    uri = client.open(DOC)
    await client.pushed(uri, 1)
    seen = len(client.log_messages)
    try:
        _configure(
            client,
            {
                "debounceMs": "soon",
                "severity": {
                    "no-such-code": "error",
                    "model-name-empty": "loud",
                    "port-name-reserved": "warning",
                },
            },
        )

        def warned() -> list[str] | None:
            texts = [m.message for m in client.log_messages[seen:]]
            joined = "\n".join(texts)
            if all(w in joined for w in ("debounceMs", "no-such-code", "loud")):
                return texts
            return None

        await client.wait_until(warned, "warnings about the bad settings")
        assert all(
            m.type == types.MessageType.Warning
            for m in client.log_messages[seen:]
            if "bt-lsp settings" in m.message
        )
        # The good part still applies.
        await _levels_now(
            client,
            uri,
            {
                ("port-name-reserved", Sev.Warning),
                ("instance-name-control-char", Sev.Error),
                ("model-name-forbidden-char", Sev.Error),
            },
        )
    finally:
        _configure(client, {"debounceMs": 0})
    await _levels_now(client, uri, DEFAULTS)


@clients("vscode")
@pytest.mark.parametrize(
    "value",
    [float("inf"), float("nan"), 10**400, -5, True, 1e300],
    ids=["inf", "nan", "10**400", "-5", "true", "1e300"],
)
async def test_absurd_debounce_values(client: BtClient, value: object) -> None:
    uri = client.open(DOC)
    await client.pushed(uri, 1)
    seen = len(client.log_messages)
    try:
        _configure(client, {"debounceMs": value})
        await client.barrier()
        client.change(uri, 2, partial(DOC, 0, 0, " ", client.encoding))
        await client.barrier()  # still answering
        assert client.error is None
    finally:
        _configure(client, {"debounceMs": 0})
    # Nothing is stuck: the next change is published right away.
    client.change(uri, 3, partial(" " + DOC, 0, 1, "", client.encoding))
    assert _levels(await client.pushed(uri, 3)) == DEFAULTS
    errors = [m.message for m in client.log_messages[seen:] if m.type == types.MessageType.Error]
    assert errors == [], errors


@clients("vscode")
async def test_debounce_waits_for_a_pause(client: BtClient) -> None:
    uri = client.open(DOC)
    await client.pushed(uri, 1)
    loop = asyncio.get_running_loop()
    try:
        _configure(client, {"debounceMs": 300})
        await client.barrier()
        text = DOC
        sent = 0.0
        for version in range(2, 7):
            client.change(uri, version, partial(text, 0, 0, " ", client.encoding))
            text = " " + text
            sent = loop.time()
        await client.pushed(uri, 6)
        waited = loop.time() - sent
        versions = [p.version for p in client.published[uri]]
        assert versions[-1] == 6 and not set(versions) & {2, 3, 4, 5}, versions
        assert waited >= 0.25, waited
    finally:
        _configure(client, {"debounceMs": 0})
