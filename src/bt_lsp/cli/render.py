"""``bt-lsp render FILE``: one tree of a file as SVG, Mermaid or DOT.

The file's folder is the workspace, as ``bt-lsp check FOLDER`` sees it: its includes
resolve, other files' models give nodes their kinds, and SubTree calls expand into trees
of other files.  Exit status 0, or 2 with a message naming the problem (an unreadable
file, a file without trees, an unknown ``--tree``, an output that cannot be written).
"""

from __future__ import annotations

import os
import sys
from dataclasses import dataclass
from typing import TextIO

from bt_lsp.project.fileio import DEFAULT_MAX_BYTES, FileError, read_text
from bt_lsp.project.index import ProjectIndex, normalize
from bt_lsp.project.pictures import draw
from bt_lsp.project.settings import Settings
from bt_lsp.render import Format, document_trees, find_tree, main_tree, tree_id_of
from bt_lsp.syntax.document import Document


@dataclass(frozen=True)
class Options:
    format: Format = "svg"
    tree: str | None = None
    ports: bool = False
    expand_subtrees: bool = False
    output: str | None = None
    workspace: str | None = None
    max_bytes: int = DEFAULT_MAX_BYTES


def run(path: str, options: Options, out: TextIO | None = None, err: TextIO | None = None) -> int:
    out = out if out is not None else sys.stdout
    err = err if err is not None else sys.stderr

    def fail(message: str) -> int:
        err.write(f"bt-lsp: {message}\n")
        return 2

    try:
        decoded = read_text(path, options.max_bytes)
    except FileError as e:
        return fail(e.message)
    doc = Document(decoded.text, path)
    trees = document_trees(doc.model)
    if not trees:
        return fail(f"{path}: no <BehaviorTree> to render")
    if options.tree is not None:
        tree = find_tree(doc.model, options.tree)
        if tree is None:
            names = ", ".join(repr(tree_id_of(t)) for t in trees)
            return fail(f"{path}: no tree {options.tree!r} (its trees: {names})")
    else:
        tree = main_tree(doc.model)
        assert tree is not None
    root = options.workspace or os.path.dirname(os.path.abspath(path))
    workspace = ProjectIndex([root], Settings(max_document_bytes=options.max_bytes))
    text, _ = draw(
        workspace,
        normalize(path),
        doc,
        tree,
        options.format,
        ports=options.ports,
        expand_subtrees=options.expand_subtrees,
    )
    if not text.endswith("\n"):
        text += "\n"
    if options.output is None or options.output == "-":
        out.write(text)
        out.flush()
        return 0
    try:
        with open(options.output, "w", encoding="utf-8", newline="\n") as f:
            f.write(text)
    except OSError as e:
        return fail(f"cannot write {options.output}: {e.strerror or e}")
    return 0
