"""Document-level rules: the ``<root>`` element, its sections, includes and nesting.

* ``root-element`` (error): the top element is not ``<root>``; BehaviorTree.CPP: "The XML
  must have a root node called <root>".  Range: the top element's name (an empty range at
  the start when the document has no element).
* ``missing-format`` (warning): ``<root>`` without ``BTCPP_format``; BehaviorTree.CPP 4
  loads the file and prints "Warnings: The first tag of the XML (<root>) should contain
  the attribute [BTCPP_format="4"]".  Range: ``root``.  Fix: add ``BTCPP_format="4"``.
  Not reported when the project builds against BehaviorTree.CPP 3, which has no such
  attribute (``Context.btcpp_version``), nor for a document that is nothing but a
  ``<TreeNodesModel>`` (a palette, which BehaviorTree.CPP never loads as a tree file); a
  hint when the version is not detected or unclear, and the message says so.
* ``duplicate-model-section`` (error): every ``<TreeNodesModel>`` after the first.
* ``missing-id`` (error) for ``<Action|Condition|Control|Decorator|SubTree>`` written
  directly under ``<root>`` without ``ID`` while a ``<TreeNodesModel>`` exists (a check
  BehaviorTree.CPP makes at load time).  Range: the element name.
* ``include-missing-path`` (error): ``<include>`` without ``path``.  Range: ``include``.
* ``include-ros-pkg`` (warning): ``ros_pkg`` names a package the settings do not map
  (BehaviorTree.CPP resolves it only when built with ROS support).  Range: the value.
* ``no-main-tree`` (information): the document defines several trees and no
  ``main_tree_to_execute``; ``createTreeFromFile`` on it fails with "[main_tree_to_execute]
  was not specified correctly", but applications that call ``createTree("ID")`` and
  documents included by others are fine, so it is only reported for documents no
  workspace document includes.  Range: ``root``.
* ``no-tree`` (warning): a ``<root>`` with no ``<BehaviorTree>``, no ``<TreeNodesModel>``
  and no ``<include>``.  BehaviorTree.CPP loads it without complaint and registers
  nothing; ``createTreeFromText``/``createTreeFromFile`` on it fails ("Can't find a tree").
  A warning, not an error: an application may load it next to the files that hold its
  trees and create those.  Range: ``root``.
* ``nesting-depth`` (warning): an element more than 256 levels below its ``<BehaviorTree>``
  ("Maximum XML nesting depth exceeded (limit: 256)", BehaviorTree.CPP releases from
  February 2026 on, pull request 1091; earlier ones recurse without a limit).  Range: the
  first such element's name in each tree.
"""

from __future__ import annotations

from typing import Final

from bt_lsp.rules.codes import BT, Severity, define, safe, unsafe
from bt_lsp.rules.semantics.base import State, quoted
from bt_lsp.syntax.elements import EXPLICIT_TAGS, Element

# The codes of these rules (see bt_lsp.rules.registry).
ROOT_ELEMENT: Final = define(
    "root-element",
    Severity.ERROR,
    "the top element is not `<root>`",
    BT,
    doc="""
        A BehaviorTree.CPP document's top element must be `<root>`: otherwise loading fails with
        `The XML must have a root node called <root>`. `bt-lsp check` skips other XML it
        recognizes when walking a folder (`package.xml`, launch files, URDF), but a file named on
        the command line or opened as a tree is checked.
        """,
    why="""
        The file does not load. Most often the tree was pasted without its `<root>` wrapper.
        """,
    bad="""
        <?xml version="1.0" encoding="UTF-8"?>
        <BehaviorTree ID="Main">
          <AlwaysSuccess/>
        </BehaviorTree>
        """,
    good="""
        <root BTCPP_format="4">
          <BehaviorTree ID="Main">
            <AlwaysSuccess/>
          </BehaviorTree>
        </root>
        """,
    since="Every version.",
)
MISSING_FORMAT: Final = define(
    "missing-format",
    Severity.WARNING,
    "`<root>` has no `BTCPP_format`",
    BT,
    fixes={
        # Version 4 reads a file without the attribute as version 4 anyway: only the
        # warning goes.
        "add": safe('Add BTCPP_format="4" to <root>', "the project builds against version 4"),
        # The file may be a version 3 one, which the attribute would make bt-lsp and Groot2
        # read as version 4.
        "add-unknown-version": unsafe(
            'Add BTCPP_format="4" to <root>', "no BehaviorTree.CPP version was detected"
        ),
    },
    doc="""
        BehaviorTree.CPP 4 reads a `<root>` without `BTCPP_format` as version 4, and prints
        `Warnings: The first tag of the XML (<root>) should contain the attribute
        [BTCPP_format="4"]`. A warning when the project builds against version 4; a hint when
        its version is not detected or unclear (the file may be for 3, which has no such
        attribute); not reported for a version 3 project nor for a file that is only a
        `<TreeNodesModel>` (a palette).
        """,
    why="""
        Groot2 and bt-lsp read the attribute to know the format; without it a version 3 file
        and a version 4 file look the same.
        """,
    bad="""
        <root>
          <BehaviorTree ID="Main">
            <AlwaysSuccess/>
          </BehaviorTree>
        </root>
        """,
    good="""
        <root BTCPP_format="4">
          <BehaviorTree ID="Main">
            <AlwaysSuccess/>
          </BehaviorTree>
        </root>
        """,
    since="BehaviorTree.CPP 4.",
)
DUPLICATE_MODEL_SECTION: Final = define(
    "duplicate-model-section",
    Severity.ERROR,
    "a second `<TreeNodesModel>` section",
    BT,
    doc="""
        A document may have one `<TreeNodesModel>` only: BehaviorTree.CPP 4 checks it when it
        loads the XML and throws (`Only a single node <TreeNodesModel> is supported`). Every
        section after the first is reported.
        """,
    why="The file does not load; merge the sections into one.",
    bad="""
        <root BTCPP_format="4">
          <TreeNodesModel>
            <Action ID="Dock"/>
          </TreeNodesModel>
          <TreeNodesModel>
            <Action ID="Undock"/>
          </TreeNodesModel>
        </root>
        """,
    good="""
        <root BTCPP_format="4">
          <TreeNodesModel>
            <Action ID="Dock"/>
            <Action ID="Undock"/>
          </TreeNodesModel>
        </root>
        """,
    since="BehaviorTree.CPP 4 (3.x does not read `<TreeNodesModel>`).",
)
INCLUDE_MISSING_PATH: Final = define(
    "include-missing-path",
    Severity.ERROR,
    "an `<include>` without `path`",
    BT,
    doc="""
        An `<include>` names the file it loads in `path` (relative to the including file, or
        under the ROS package of `ros_pkg`). BehaviorTree.CPP throws when it loads a document
        with an `<include>` that has none: `Invalid <include> tag: missing 'path'
        attribute`.
        """,
    why="The file does not load.",
    bad="""
        <root BTCPP_format="4">
          <include ros_pkg="dock_bt"/>
        </root>
        """,
    good="""
        <root BTCPP_format="4">
          <include path="dock.xml"/>
        </root>
        """,
    since="Every version.",
)
INCLUDE_ROS_PKG: Final = define(
    "include-ros-pkg",
    Severity.WARNING,
    "an `<include ros_pkg>` whose package bt-lsp cannot resolve",
    BT,
    doc="""
        `<include ros_pkg="dock_bt" path="trees/dock.xml"/>` loads `path` under the package's
        share folder; BehaviorTree.CPP resolves it only when built with ROS support, and
        otherwise fails: `Using attribute [ros_pkg] in <include>, but this library was
        compiled without ROS support`. bt-lsp finds the packages of the workspace; for
        another, map it to its share folder in the `rosPackages` setting (`ros-packages` in
        `bt-lsp.toml`), or the included trees stay unknown. Not reported for an absolute
        `path`, where BehaviorTree.CPP ignores `ros_pkg`. The example is reported outside a
        workspace that holds `dock_bt`.
        """,
    why="""
        The trees of the included file are not known: its SubTree calls cannot be checked.
        """,
    bad="""
        <root BTCPP_format="4">
          <include ros_pkg="dock_bt" path="trees/dock.xml"/>
        </root>
        """,
    since="Every version built with ROS support.",
)
NO_MAIN_TREE: Final = define(
    "no-main-tree",
    Severity.INFORMATION,
    "several trees and no `main_tree_to_execute`",
    BT,
    doc="""
        A document with several trees and no `main_tree_to_execute` on `<root>`:
        `createTreeFromFile` and `createTreeFromText` on it throw (`[main_tree_to_execute] was not
        specified correctly`), but an application that names the tree
        (`createTree("Main")`) is fine, so it is information only. Not reported for a document
        another one of the workspace includes.
        """,
    why="""
        Which tree runs is then decided only in the C++; naming it in the file documents it.
        """,
    bad="""
        <root BTCPP_format="4">
          <BehaviorTree ID="Main">
            <SubTree ID="Dock"/>
          </BehaviorTree>
          <BehaviorTree ID="Dock">
            <AlwaysSuccess/>
          </BehaviorTree>
        </root>
        """,
    good="""
        <root BTCPP_format="4" main_tree_to_execute="Main">
          <BehaviorTree ID="Main">
            <SubTree ID="Dock"/>
          </BehaviorTree>
          <BehaviorTree ID="Dock">
            <AlwaysSuccess/>
          </BehaviorTree>
        </root>
        """,
    since="Every version.",
)
NO_TREE: Final = define(
    "no-tree",
    Severity.WARNING,
    "a `<root>` with no tree, no node models and no include: nothing to create",
    BT,
    doc="""
        A `<root>` with no `<BehaviorTree>`, no `<TreeNodesModel>` and no `<include>`.
        BehaviorTree.CPP loads it without complaint and registers nothing; creating a tree
        from it alone fails (`Can't find a tree`). A warning, not an error: an application may
        load it beside the files that hold its trees.
        """,
    why="Most often an empty or truncated file, or trees written outside `<root>`.",
    bad='<root BTCPP_format="4"/>',
    good="""
        <root BTCPP_format="4">
          <BehaviorTree ID="Main">
            <AlwaysSuccess/>
          </BehaviorTree>
        </root>
        """,
    since="Every version.",
)
NESTING_DEPTH: Final = define(
    "nesting-depth",
    Severity.WARNING,
    "a tree nested deeper than 256 levels (rejected by BehaviorTree.CPP 4 releases from "
    "February 2026 on)",
    BT,
    doc="""
        An element more than 256 levels below its `<BehaviorTree>`. BehaviorTree.CPP releases
        from February 2026 on (pull request 1091) throw when they load it (`Maximum XML
        nesting depth exceeded (limit: 256)`); earlier ones, those of ROS 2 Humble and Jazzy
        among them, recurse without a limit, so it is a warning naming the release. The first
        such element of each tree is reported. (No example: it takes 257 levels.)
        """,
    why="""
        The file stops loading when the project moves to a newer release; so deep a tree is
        almost always generated or broken.
        """,
    since="BehaviorTree.CPP 4 releases from February 2026 on.",
)


MAX_DEPTH: Final = 256
# Element depth in the model: <root> 0, <BehaviorTree> 1, so a node at model depth d is
# d - 1 levels below its tree.
DEPTH_LIMIT: Final = MAX_DEPTH + 1

_ID_TAGS: Final = EXPLICIT_TAGS | {"SubTree"}


def check_root(st: State) -> None:
    root = st.model.root  # the first element, when there is one
    if root is None:
        st.add(
            0,
            0,
            "root-element",
            "The document has no <root> element; BehaviorTree.CPP fails to load it "
            "('Error parsing the XML')",
        )
        return
    if root.name != "root":
        st.add(
            root.name_start,
            root.name_end,
            "root-element",
            f"The top element is <{root.name}>; BehaviorTree.CPP requires a root node "
            "called <root>",
        )
    else:
        declared = root.attr("BTCPP_format") is not None
        version = st.ctx.btcpp_version
        unclear = st.ctx.btcpp_unclear
        # A BTCPP_format in a version 3 project is a note for a later move to 4; in a
        # project whose build names both versions it settles nothing.
        st.v4 = not unclear and ((declared and version != "3") or version == "4")
        st.v3 = version == "3"
        # BehaviorTree.CPP 3 has no BTCPP_format to add: the advice is for version 4 only,
        # and only for a document BehaviorTree.CPP loads (a palette is read by Groot).
        if not declared and version != "3" and not _palette_only(st):
            st.add(
                root.name_start,
                root.name_end,
                "missing-format",
                _missing_format_message(version, unclear),
                None if version == "4" else Severity.HINT,
            )
    # Only the children that a rule looks at closely are made (a large document has
    # thousands of trees).
    model = st.model
    models_sections = model.root_children_named(("TreeNodesModel",))
    for extra in models_sections[1:]:
        st.add(
            extra.name_start,
            extra.name_end,
            "duplicate-model-section",
            "Only a single <TreeNodesModel> is supported; merge this section into the first",
        )
    trees = model.root_child_names().count("BehaviorTree")
    for c in model.root_children_named(("include",)):
        _check_include(st, c)
    for c in model.root_children_named(_ID_TAGS) if models_sections else ():
        if c.attr("ID") is None:
            st.add(
                c.name_start,
                c.name_end,
                "missing-id",
                f"<{c.name}> directly under <root> has no ID attribute; with a "
                "<TreeNodesModel> present BehaviorTree.CPP requires one (model entries "
                "belong inside <TreeNodesModel>)",
            )
    if (
        root.name == "root"
        and not trees
        and not models_sections
        and not model.root_children_named(("include",))
    ):
        st.add(
            root.name_start,
            root.name_end,
            "no-tree",
            "This <root> has no <BehaviorTree>, no <TreeNodesModel> and no <include>: loading "
            "it registers nothing, and creating a tree from it alone fails with 'Can't find a "
            "tree'",
        )
    if (
        root.name == "root"
        and trees > 1
        and root.attr("main_tree_to_execute") is None
        and not st.ctx.included_by
    ):
        st.add(
            root.name_start,
            root.name_end,
            "no-main-tree",
            f"The document defines {trees} trees but no main_tree_to_execute; loading it with "
            "createTreeFromFile/Text fails unless the application names the tree to create",
        )


def _check_include(st: State, el: Element) -> None:
    if el.attr("path") is None:
        st.add(
            el.name_start,
            el.name_end,
            "include-missing-path",
            "<include> has no path attribute (BehaviorTree.CPP: missing 'path' attribute)",
        )
        return
    pkg = el.attr("ros_pkg")
    if pkg is None or pkg.value is None:
        return
    path = el.value("path") or ""
    if path.startswith("/"):
        return  # BehaviorTree.CPP ignores ros_pkg for an absolute path
    if pkg.value in st.ctx.ros_pkg_paths:
        return
    s, e = el.span_of_value(pkg)
    st.add(
        s,
        e,
        "include-ros-pkg",
        f"ROS package {quoted(pkg.value)} is unknown to bt-lsp, so this include cannot be "
        "followed; BehaviorTree.CPP resolves ros_pkg only when built with ROS support (map "
        "the package to its share directory in the btLsp.rosPackages setting)",
    )


def check_depth(st: State, el: Element, tree_flagged: list[bool]) -> None:
    """Report the first element of a tree that is nested too deep."""
    if el.depth > DEPTH_LIMIT and not tree_flagged[0]:
        tree_flagged[0] = True
        st.add(
            el.name_start,
            el.name_end,
            "nesting-depth",
            f"<{el.name}> is nested {el.depth - 1} levels below its <BehaviorTree>; "
            f"BehaviorTree.CPP releases from February 2026 on (pull request 1091) reject "
            f"trees deeper than {MAX_DEPTH} levels (earlier ones recurse without a limit)",
        )


def _palette_only(st: State) -> bool:
    """Whether the document is nothing but a ``<TreeNodesModel>`` (a Groot palette or a
    node catalog): BehaviorTree.CPP never loads it as a tree file, so it never prints its
    format warning for it."""
    names = set(st.model.root_child_names())
    return "TreeNodesModel" in names and not names & {"BehaviorTree", "include"}


def _missing_format_message(version: str | None, unclear: bool = False) -> str:
    """What BehaviorTree.CPP 4 does with a ``<root>`` without ``BTCPP_format``, for the
    project's version (4, unclear, or not detected)."""
    said = 'BehaviorTree.CPP 4 loads the file and prints a warning asking for BTCPP_format="4"'
    if version == "4":
        return f'<root> has no BTCPP_format attribute; {said}: add BTCPP_format="4"'
    why = (
        "the project's build names both BehaviorTree.CPP 3 and 4, so its version is unclear"
        if unclear
        else "the project's version was not detected"
    )
    return (
        f"<root> has no BTCPP_format attribute; {said}; BehaviorTree.CPP 3 has no such "
        f"attribute, and {why} (set btcpp to 3 or 4): add "
        'BTCPP_format="4" if the file is written for version 4'
    )
