"""``bt-lsp models``: the node catalog learned from C++, as BehaviorTree.CPP would write it.

``--format xml`` prints a ``<TreeNodesModel>`` document in the shape of BehaviorTree.CPP's
``writeTreeNodesModelXML`` (Groot2 loads it as a palette; Nav2's ``nav2_tree_nodes.xml``
has the same shape), ``--format json`` every node with its source positions and flags.
What the reading could not know is never written as a fact: a node of unknown kind and a
default given by an expression appear as XML comments.
"""

from __future__ import annotations

import json
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Any, TextIO

from lxml import etree

from bt_lsp.cpp.catalog import Catalog, CppNode, CppPort
from bt_lsp.cpp.facts import Span
from bt_lsp.project.cpp_scan import Scanner, cpp_sources, default_cache_dir, scan

_PORT_TAGS = {"input": "input_port", "output": "output_port", "inout": "inout_port"}


def _comment(text: str) -> etree._Comment:
    # "--" may not appear in an XML comment
    return etree.Comment(" " + text.replace("--", "- -") + " ")


def to_xml(catalog: Catalog) -> str:
    root = etree.Element("root", BTCPP_format="4")
    model = etree.SubElement(root, "TreeNodesModel")
    for node in sorted(catalog.nodes, key=lambda n: n.id):
        if node.kind is None:
            model.append(_comment(f"{node.id}: kind unknown ({'; '.join(node.notes)})"))
            continue
        el = etree.SubElement(model, node.kind, ID=node.id)
        for note in node.notes:
            el.append(_comment(note))
        for p in node.ports:
            attrs = {"name": p.name}
            if p.type != "AnyTypeAllowed":
                attrs["type"] = p.type
            if p.default is not None and not p.default_is_expr:
                attrs["default"] = p.default
            port = etree.SubElement(el, _PORT_TAGS[p.direction], attrs)
            if p.default_is_expr:
                port.append(_comment(f"default: {p.default}"))
            if p.description:
                if len(port):
                    port[-1].tail = p.description
                else:
                    port.text = p.description
    etree.indent(root, space="  ")
    return etree.tostring(root, encoding="unicode") + "\n"


def _pos(path: str, span: Span) -> dict[str, Any]:
    return {
        "path": path,
        "line": span[0] + 1,
        "column": span[1] + 1,
        "endLine": span[2] + 1,
        "endColumn": span[3] + 1,
    }


def _port_json(p: CppPort) -> dict[str, Any]:
    return {
        "name": p.name,
        "direction": p.direction,
        "type": p.type,
        "default": p.default,
        "defaultIsExpression": p.default_is_expr,
        "description": p.description,
        "declared": _pos(p.path, p.span),
    }


def _node_json(n: CppNode) -> dict[str, Any]:
    return {
        "id": n.id,
        "kind": n.kind,
        "class": n.cls,
        "form": n.form,
        "registered": _pos(n.path, n.id_span),
        "classDeclared": None
        if n.class_path is None or n.class_span is None
        else _pos(n.class_path, n.class_span),
        "authoritative": n.authoritative,
        "flags": list(n.flags),
        "notes": list(n.notes),
        "ports": [_port_json(p) for p in n.ports],
    }


def to_json(catalog: Catalog) -> str:
    doc = {
        "nodes": [_node_json(n) for n in sorted(catalog.nodes, key=lambda n: n.id)],
        "unresolved": [
            {"form": u.form, "name": u.text, **_pos(u.path, u.span)} for u in catalog.unresolved
        ],
    }
    return json.dumps(doc, indent=2, ensure_ascii=False) + "\n"


def run(
    paths: Sequence[str],
    *,
    format: str = "xml",
    verbose: bool = False,
    cache: bool = True,
    out: TextIO | None = None,
    err: TextIO | None = None,
) -> int:
    """Print the catalog of the C++ under ``paths``; 2 when a path does not exist."""
    out = out or sys.stdout
    err = err or sys.stderr
    missing = [p for p in paths if not Path(p).exists()]
    for p in missing:
        print(f"bt-lsp models: {p}: no such file or directory", file=err)
    # The same C++ as ``check`` and the server read for a package: every folder of it but
    # build output and tests.
    files = sorted({f for p in paths if p not in missing for f in cpp_sources(Path(p))})
    show = verbose or err.isatty()

    def progress(done: int, total: int) -> None:
        if show:
            end = "\n" if done == total else ""
            print(f"\rreading C++: {done}/{total} files", end=end, file=err, flush=True)

    scanner = Scanner(default_cache_dir() if cache else None)
    catalog = scan(files, scanner, progress=progress)
    out.write(to_xml(catalog) if format == "xml" else to_json(catalog))
    return 2 if missing else 0
