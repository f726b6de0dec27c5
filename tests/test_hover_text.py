"""Hover text: Markdown or plain text, narrow lists, where a name comes from (said as a
fact), the quick fix's count of places, and blackboard keys."""

from __future__ import annotations

import re

from bt_lsp.ide.hover import hover_at
from bt_lsp.rules.context import Context
from bt_lsp.syntax.document import Document

KEYS = (
    '<root BTCPP_format="4" main_tree_to_execute="Main">\n'
    '  <BehaviorTree ID="Main">\n'
    "    <Sequence>\n"
    '      <ComputePath path="{goal}" start="{pose}"/>\n'
    '      <FollowPath path="{goal}"/>\n'
    '      <ScriptCondition code="goal != 0"/>\n'
    '      <Unknown thing="{goal}"/>\n'
    "    </Sequence>\n"
    "  </BehaviorTree>\n"
    "  <TreeNodesModel>\n"
    '    <Action ID="ComputePath">\n'
    '      <output_port name="path" type="nav_msgs::msg::Path"/>\n'
    '      <input_port name="start" type="Pose"/>\n'
    "    </Action>\n"
    '    <Action ID="FollowPath"><input_port name="path" type="nav_msgs::msg::Path"/></Action>\n'
    "  </TreeNodesModel>\n"
    "</root>\n"
)


def _hover(text: str, needle: str, into: int = 1, *, markdown: bool = True, nth: int = 0) -> str:
    doc = Document(text, "/ws/a.xml")
    start = -1
    for _ in range(nth + 1):
        start = text.index(needle, start + 1)
    found = hover_at(doc, start + into, Context.from_document(doc), markdown=markdown)
    assert found is not None, needle
    assert found.markdown is markdown
    return found.text


def test_a_key_shows_where_it_is_written_and_read_and_its_types() -> None:
    text = _hover(KEYS, "{goal}", into=2)
    assert text == (
        "**Blackboard key `goal` of the tree `Main`**\n"
        "\n"
        "Written by:\n"
        "- `ComputePath` port `path` (line 4), `nav_msgs::msg::Path`\n"
        "\n"
        "Read by:\n"
        "- `FollowPath` port `path` (line 5), `nav_msgs::msg::Path`\n"
        "- `Unknown` port `thing` (line 7), direction unknown\n"
        "\n"
        "In scripts:\n"
        "- `ScriptCondition` `code` (line 6)\n"
        "\n"
        "Port types: `nav_msgs::msg::Path`"
    )
    # From its use in a script too.
    assert _hover(KEYS, "goal != 0", into=1).startswith("**Blackboard key `goal`")


def test_plain_text_has_no_markup() -> None:
    doc = (
        '<root BTCPP_format="4"><BehaviorTree ID="Main Tree">'
        '<Sleep msec="1"/></BehaviorTree></root>'
    )
    for needle in ("Main Tree", "Sleep", "msec"):
        text = _hover(doc, needle, markdown=False)
        assert "**" not in text and "`" not in text, text
        assert not any(line.startswith("|") for line in text.splitlines()), text
    bad = _hover(doc, "Main Tree", markdown=False)
    assert bad.startswith("Model name 'Main Tree' breaks the BehaviorTree.CPP naming rules\n")
    assert "- column 5 (line 1, col 46): ' ' (space), whitespace:" in bad
    assert "Suggested replacement: 'Main_Tree' (the quick fix renames 1 place)" in bad
    assert "- 'msec': input, 'unsigned int', no default" in _hover(doc, "Sleep", markdown=False)
    key = _hover(KEYS, "{goal}", into=2, markdown=False)
    assert key.startswith("Blackboard key 'goal' of the tree 'Main'\n")


def test_where_a_name_comes_from_is_a_fact_not_an_error() -> None:
    doc = (
        '<root BTCPP_format="4"><BehaviorTree ID="Main">'
        '<Sequence><SubTree ID="Elsewhere"/><Spin/></Sequence></BehaviorTree></root>'
    )
    call = _hover(doc, "Elsewhere")
    assert call == (
        "**SubTree call of the tree `Elsewhere`**\n"
        "\n"
        "No file of the workspace defines this tree: it comes from elsewhere, such as an "
        "installed package."
    )
    spin = _hover(doc, "Spin")
    assert spin == (
        "**Node type `Spin`**\n"
        "\n"
        "Registered in code: no TreeNodesModel entry in the workspace declares this node type."
    )
    for text in (call, spin):
        assert "Not declared" not in text


def test_a_bad_call_of_a_tree_defined_elsewhere_says_why_there_is_no_fix() -> None:
    doc = (
        '<root BTCPP_format="4"><BehaviorTree ID="Main">'
        '<SubTree ID="Open Right Gripper"/></BehaviorTree></root>'
    )
    text = _hover(doc, "Open Right Gripper")
    assert text.endswith(
        "No quick fix renames it: the tree 'Open Right Gripper' is not defined in the "
        "workspace (it comes from elsewhere, such as an installed package, and keeps its ID "
        "there); rename it where it is defined first, then this reference."
    )
    assert "Suggested replacement" not in text


def test_a_node_learned_from_cpp_says_where_relative_with_a_link() -> None:
    from dataclasses import replace
    from types import MappingProxyType

    from bt_lsp.rules.context import ModelDecl

    text = '<root BTCPP_format="4"><BehaviorTree ID="T"><Dock/></BehaviorTree></root>\n'
    doc = Document(text, "/ws/trees/a.xml")
    decl = ModelDecl(
        "Dock", "Action", (), "/ws/src/app/src/main.cpp", 0, 6, "cpp", "src/app/src/main.cpp:21"
    )
    ctx = replace(Context.from_document(doc), models=MappingProxyType({"Dock": decl}))
    at = text.index("Dock") + 1
    md = hover_at(doc, at, ctx, markdown=True)
    assert md is not None
    assert (
        "Action registered in [src/app/src/main.cpp:21](file:///ws/src/app/src/main.cpp#L21)."
        in md.text
    )
    plain = hover_at(doc, at, ctx, markdown=False)
    assert plain is not None
    assert "Action registered in src/app/src/main.cpp:21." in plain.text
    assert "/ws/src" not in plain.text


# A name with an asterisk, a backslash and a space, and a port declared with a reserved
# name: the hover lists the characters and states the rules, whose text has '*', '\',
# '_' and '<'.
BAD_CHARS = (
    '<root BTCPP_format="4">\n'
    '  <BehaviorTree ID="a*b\\c d"><AlwaysSuccess/></BehaviorTree>\n'
    '  <TreeNodesModel><SubTree ID="S"><input_port name="_skipIf"/></SubTree></TreeNodesModel>\n'
    "</root>\n"
)


def _outside_code(markdown: str) -> str:
    """The Markdown with its code spans and bold markers taken out."""
    text = re.sub(r"``.*?``|`[^`]*`", "", markdown)
    return text.replace("**", "")


def test_markdown_hover_shows_special_characters_the_same_everywhere() -> None:
    # Outside code spans no '\' (Neovim 0.7 hides it before punctuation or a space, 0.11
    # shows an escape as typed), no '*' or '_' (emphasis in Neovim 0.7) and no '<'.
    for needle, into in (("a*b", 1), ("_skipIf", 1)):
        md = _hover(BAD_CHARS, needle, into)
        prose = _outside_code(md)
        for char in "\\*_<":
            assert char not in prose, (char, md)
    md = _hover(BAD_CHARS, "a*b")
    assert "path separators (/ backslash :), wildcards (`*` ? `|`)" in md
    assert "`'*'` (asterisk)" in md
    assert "U+005C (backslash)" in md
    assert "' ' (space)" in md  # nothing to protect: as the diagnostic says it
    md = _hover(BAD_CHARS, "_skipIf")
    assert "`_skipIf`, `_successIf`" in md and "`<SubTree>`" in md
    # Plain text is as the diagnostics say it.
    plain = _hover(BAD_CHARS, "a*b", markdown=False)
    assert "path separators (/ \\ :), wildcards (* ? |)" in plain
    assert "'\\\\' (backslash)" in plain and "'*' (asterisk)" in plain


def test_a_name_whose_backslash_inline_code_hides_is_shown_in_a_code_block() -> None:
    """Neovim 0.7 hides a backslash before punctuation, a space or the closing backtick
    even in inline code; a code block shows it in every client (the e2e test
    test_hover_shows_markup_characters_as_written sees it in both Neovims)."""
    for name in ("Main\\*Tree", "Main\\ Tree", "Main\\_Tree", "Main\\"):
        text = (
            f'<root BTCPP_format="4"><BehaviorTree ID="{name}"><AlwaysSuccess/>'
            "</BehaviorTree></root>\n"
        )
        md = _hover(text, name)
        assert md.splitlines()[:5] == [
            "**Model name breaks the BehaviorTree.CPP naming rules:**",
            "```text",
            name,
            "```",
            "",
        ], md
        plain = _hover(text, name, markdown=False)
        assert plain.startswith(f"Model name '{name}' breaks the BehaviorTree.CPP naming rules\n")
    # A backslash before a letter shows in inline code everywhere.
    assert _hover(BAD_CHARS, "a*b").startswith("**Model name `a*b\\c d` breaks")
