"""Realistic BehaviorTree.CPP XML of any size, for benchmarks.

The document looks like the large files of real projects: a ``<root BTCPP_format="4">``
with a main tree, many ``<BehaviorTree>`` elements of nested controls and decorators,
custom nodes with ports (compact and explicit form, blackboard references and literals),
scripts, ``<SubTree>`` calls with remapped ports, and a ``<TreeNodesModel>`` declaring
every custom node and the ports of the called trees.  A few names break the name rules on
purpose (:class:`Planted` says which and what bt-lsp must report); apart from those the
document is clean.  The output is deterministic for a given size and seed and always
parses with lxml.

    python benchmarks/generate.py 1M out.xml [--seed 1] [--bad 5]
"""

from __future__ import annotations

import argparse
import random
import re
import sys
from dataclasses import dataclass, field

__all__ = ["Generated", "Planted", "generate", "parse_size"]

# Port types of custom nodes, with literal values that convert to them.
_TYPES: tuple[tuple[str, tuple[str, ...]], ...] = (
    ("std::string", ("map", "base_link", "front_camera", "dock_A", "left")),
    ("int", ("1", "3", "10", "42", "-1")),
    ("double", ("0.5", "1.25", "3.0", "0.05", "12.5")),
    ("bool", ("true", "false")),
    ("geometry_msgs::msg::PoseStamped", ()),
    ("std::vector<double>", ()),
)
_VERBS = (
    "Move", "Navigate", "Pick", "Place", "Check", "Wait", "Detect", "Follow", "Grasp", "Open",
    "Close", "Compute", "Publish", "Read", "Set", "Spin", "Dock", "Scan", "Track", "Plan",
)  # fmt: skip
_OBJECTS = (
    "Arm", "Base", "Gripper", "Door", "Goal", "Path", "Pose", "Target", "Battery", "Camera",
    "Object", "Waypoint", "Map", "Station", "Marker", "Trajectory", "Lidar", "Joint",
)  # fmt: skip
_PORT_WORDS = (
    "goal", "pose", "target", "speed", "timeout", "frame_id", "topic_name", "service_name",
    "tolerance", "max_retries", "distance", "object_id", "result", "path", "enabled", "level",
)  # fmt: skip
# Blackboard keys by the type of the ports that use them (one type per key in a tree).
_KEYS: dict[str, tuple[str, ...]] = {
    "std::string": ("map_id", "station", "frame", "object_name"),
    "int": ("retry_count", "attempts"),
    "double": ("battery_level", "distance_left"),
    "bool": ("detected", "docked"),
    "geometry_msgs::msg::PoseStamped": ("goal", "current_pose", "target_pose", "marker_pose"),
    "std::vector<double>": ("path", "trajectory", "waypoints", "plan"),
}
_ALL_KEYS = tuple(k for keys in _KEYS.values() for k in keys)
_CONTROLS = ("Sequence", "Fallback", "ReactiveSequence", "ReactiveFallback", "SequenceWithMemory")
_DECORATORS = (
    ("Inverter", ""),
    ("ForceSuccess", ""),
    ("RetryUntilSuccessful", ' num_attempts="3"'),
    ("Timeout", ' msec="5000"'),
    ("Repeat", ' num_cycles="2"'),
    ("KeepRunningUntilFailure", ""),
    ("Delay", ' delay_msec="200"'),
)
_SCRIPTS = (
    "retry_count := retry_count + 1",
    "detected := false",
    "battery_level &gt;= 20.0 &amp;&amp; detected",
    "station := 'dock_A'",
)


@dataclass(frozen=True, slots=True)
class Planted:
    """A name that breaks a rule on purpose: bt-lsp must report ``code`` on each of its
    ``count`` occurrences, whose text is ``name``."""

    code: str
    name: str
    count: int


@dataclass(frozen=True, slots=True)
class Generated:
    text: str
    planted: tuple[Planted, ...]
    trees: int
    models: int


@dataclass(slots=True)
class _Model:
    id: str
    category: str  # Action or Condition
    ports: list[tuple[str, str, str, str | None]]  # name, direction, type, default


@dataclass(slots=True)
class _Tree:
    id: str
    ports: list[str] = field(default_factory=list)  # input ports of its <SubTree> model


class _Writer:
    def __init__(self, rng: random.Random, models: list[_Model]) -> None:
        self.rng = rng
        self.models = models
        self.out: list[str] = []
        self.size = 0
        self.counter = 0
        self.rare_uses: dict[str, int] = {}  # uses of bad names, kept to a few each

    def line(self, depth: int, text: str) -> None:
        s = "  " * depth + text + "\n"
        self.out.append(s)
        self.size += len(s)

    def instance(self, base: str) -> str:
        self.counter += 1
        return f"{base} {self.counter}"

    def leaf(self, depth: int, callable_trees: list[_Tree], reactive: bool) -> None:
        """A leaf; ``reactive`` when its parent is a ReactiveSequence (whose children
        must be written in compact form)."""
        rng = self.rng
        r = rng.random()
        if r < 0.08 and callable_trees:
            t = rng.choice(callable_trees)
            name = self.instance(t.id)
            remaps = "".join(f' {p}="{{{rng.choice(_ALL_KEYS)}}}"' for p in t.ports)
            self.line(depth, f'<SubTree ID="{t.id}" name="{name}"{remaps}/>')
            return
        if r < 0.14:
            code = rng.choice(_SCRIPTS)
            self.line(depth, f'<Script code="{code}"/>')
            return
        if r < 0.18:
            self.line(depth, f'<Sleep msec="{rng.choice((100, 250, 500))}"/>')
            return
        if r < 0.20:
            key = rng.choice(_ALL_KEYS)
            self.line(depth, f'<SetBlackboard output_key="{key}" value="{{{key}}}"/>')
            return
        m = rng.choice(self.models)
        if ":" in m.id:
            # A bad model name is used a few times only.
            if reactive or self.rare_uses.get(m.id, 0) >= 3:
                m = next(x for x in self.models if ":" not in x.id)
            self.rare_uses[m.id] = self.rare_uses.get(m.id, 0) + 1
        attrs: list[str] = [f'name="{self.instance(m.id)}"']
        for pname, direction, ptype, default in m.ports:
            if default is not None and rng.random() < 0.5:
                continue
            if "." in pname:
                # A bad port name is given a few times only (it has a default).
                if self.rare_uses.get(pname, 0) >= 2:
                    continue
                self.rare_uses[pname] = self.rare_uses.get(pname, 0) + 1
            literals = dict(_TYPES)[ptype]
            if direction == "input" and literals and rng.random() < 0.6:
                attrs.append(f'{pname}="{rng.choice(literals)}"')
            else:
                attrs.append(f'{pname}="{{{rng.choice(_KEYS[ptype])}}}"')
        if ":" in m.id or (not reactive and rng.random() < 0.15):
            # A colon in an element name would be an undeclared XML namespace prefix.
            attrs.insert(0, f'ID="{m.id}"')
            tag = m.category
        else:
            tag = m.id
        if len(attrs) > 3:
            # Long tags wrap one attribute per line, as Groot writes them.
            pad = " " * (len(tag) + 2)
            self.line(depth, f"<{tag} {attrs[0]}")
            for a in attrs[1:-1]:
                self.line(depth, f"{pad}{a}")
            self.line(depth, f"{pad}{attrs[-1]}/>")
        else:
            self.line(depth, f"<{tag} {' '.join(attrs)}/>")

    def node(self, depth: int, levels: int, callable_trees: list[_Tree], reactive: bool) -> None:
        rng = self.rng
        if levels <= 0:
            self.leaf(depth, callable_trees, reactive)
            return
        if rng.random() < 0.25:
            tag, attrs = rng.choice(_DECORATORS)
            self.line(depth, f"<{tag}{attrs}>")
            self.node(depth + 1, levels - 1, callable_trees, False)
            self.line(depth, f"</{tag}>")
            return
        tag = rng.choice(_CONTROLS)
        inner = tag == "ReactiveSequence"
        self.line(depth, f'<{tag} name="{self.instance(tag)}">')
        for _ in range(rng.randint(2, 4)):
            if rng.random() < 0.45:
                self.node(depth + 1, levels - 1, callable_trees, inner)
            else:
                self.leaf(depth + 1, callable_trees, inner)
        self.line(depth, f"</{tag}>")


def _models(rng: random.Random, count: int) -> list[_Model]:
    out: list[_Model] = []
    seen: set[str] = set()
    while len(out) < count:
        mid = rng.choice(_VERBS) + rng.choice(_OBJECTS)
        if mid in seen:
            mid += str(len(out))
        seen.add(mid)
        ports: list[tuple[str, str, str, str | None]] = []
        for pname in rng.sample(_PORT_WORDS, rng.randint(1, 4)):
            ptype, literals = rng.choice(_TYPES)
            direction = rng.choice(("input", "input", "output")) if literals else "inout"
            default = rng.choice(literals) if literals and rng.random() < 0.3 else None
            ports.append((pname, direction, ptype, default))
        out.append(_Model(mid, "Condition" if mid.startswith("Check") else "Action", ports))
    return out


def _model_entries(models: list[_Model], extra_decls: dict[str, list[str]]) -> str:
    out: list[str] = []
    for m in models:
        out.append(f'    <{m.category} ID="{m.id}">\n')
        for pname, direction, ptype, default in m.ports:
            d = f' default="{default}"' if default is not None else ""
            t = ptype.replace("<", "&lt;").replace(">", "&gt;")
            out.append(f'      <{direction}_port name="{pname}" type="{t}"{d}/>\n')
        for pname in extra_decls.get(m.id, ()):
            out.append(f'      <input_port name="{pname}" type="std::string" default=""/>\n')
        out.append(f"    </{m.category}>\n")
    return "".join(out)


def _subtree_entry(t: _Tree) -> str:
    if not t.ports:
        return ""
    ports = "".join(f'      <input_port name="{p}" type="std::string"/>\n' for p in t.ports)
    return f'    <SubTree ID="{t.id}">\n{ports}    </SubTree>\n'


_BAD_KINDS = ("tree-space", "port-period", "model-colon", "decl-reserved", "decl-digit")


def generate(size: int, seed: int = 0, bad: int | None = None) -> Generated:
    """A document of about ``size`` bytes (UTF-8; within a few KB) with ``bad`` planted
    bad names (default: 4, plus one per 256 KB)."""
    rng = random.Random(seed)
    if bad is None:
        bad = 4 + size // 262_144
    models = _models(rng, min(300, 25 + size // 16_384))
    w = _Writer(rng, models)
    planted: list[Planted] = []
    kinds = [_BAD_KINDS[i % len(_BAD_KINDS)] for i in range(bad)]

    # Plant the model and port problems in the models first: they are written last.
    extra_decls: dict[str, list[str]] = {}
    for i, kind in enumerate(kinds):
        m = models[(i * 7 + 3) % len(models)]
        if kind == "port-period":
            pname = f"target.pose{i}"
            m.ports.append((pname, "input", "std::string", ""))
            # The declaration and every use of the node carry it; counted below.
        elif kind == "model-colon":
            m.id = f"nav:{m.id}{i}"
        elif kind == "decl-reserved":
            extra_decls.setdefault(m.id, []).append("_skipIf")
        elif kind == "decl-digit":
            extra_decls.setdefault(m.id, []).append(f"{i}nd_goal")

    # Trees: the body first (to know the size), the main tree calls a few of them.
    fixed = 400 + len(_model_entries(models, extra_decls))
    trees: list[_Tree] = []
    bodies: list[list[str]] = []
    bad_trees = [i for i, k in enumerate(kinds) if k == "tree-space"]
    n = 0
    while fixed + w.size < size or not trees:
        n += 1
        verb, obj = rng.choice(_VERBS), rng.choice(_OBJECTS)
        tid = f"{verb}{obj}Task{n}"
        if bad_trees and n % 3 == 0:
            tid = f"{verb} {obj} Task {n}"  # a space: model-name-forbidden-char
            bad_trees.pop()
        tree = _Tree(tid, rng.sample(("goal", "target", "speed"), rng.randint(0, 2)))
        # Trees call only trees written before them: no recursion.
        callable_trees = [t for t in trees[-12:] if " " not in t.id]
        start, before = len(w.out), w.size
        w.line(1, f'<BehaviorTree ID="{tid}">')
        w.node(2, rng.randint(2, 4), callable_trees, False)
        w.line(1, "</BehaviorTree>")
        if trees and fixed + w.size + len(_subtree_entry(tree)) > size * 1.01:
            del w.out[start:]  # this tree would overshoot the size: stop before it
            w.size = before
            break
        bodies.append(w.out[start:])
        trees.append(tree)
        fixed += len(_subtree_entry(tree))
    # Any tree-space name left (a very small document): rename the last tree.
    for _ in bad_trees:
        t = trees[-1]
        new = f"{t.id[:-1]} {t.id[-1]}"
        bodies[-1][0] = bodies[-1][0].replace(f'ID="{t.id}"', f'ID="{new}"')
        t.id = new

    out: list[str] = [
        '<?xml version="1.0" encoding="UTF-8"?>\n',
        '<root BTCPP_format="4" main_tree_to_execute="MainTree">\n',
        '  <BehaviorTree ID="MainTree">\n',
        '    <Sequence name="main">\n',
    ]
    for t in trees[-min(len(trees), 6) :] + [t for t in trees if " " in t.id]:
        remaps = "".join(f' {p}="{{{p}}}"' for p in t.ports)
        out.append(f'      <SubTree ID="{t.id}"{remaps}/>\n')
    out.append("    </Sequence>\n  </BehaviorTree>\n")
    for body in bodies:
        out.extend(body)
    out.append("  <TreeNodesModel>\n")
    out.append(_model_entries(models, extra_decls))
    out.extend(_subtree_entry(t) for t in trees)
    out.append("  </TreeNodesModel>\n</root>\n")
    text = "".join(out)

    # What bt-lsp must report, counted in the finished text.
    for i, kind in enumerate(kinds):
        m = models[(i * 7 + 3) % len(models)]
        if kind == "port-period":
            pname = f"target.pose{i}"
            uses = len(re.findall(rf"\s{re.escape(pname)}=", text))
            planted.append(Planted("port-name-forbidden-char", pname, uses + 1))  # + its decl
        elif kind == "model-colon":
            uses = text.count(f'"{m.id}"') + len(re.findall(rf"<{re.escape(m.id)}[\s/>]", text))
            planted.append(Planted("model-name-forbidden-char", m.id, uses))
        elif kind == "decl-reserved":
            planted.append(Planted("port-name-reserved-groot2", "_skipIf", 1))
        elif kind == "decl-digit":
            planted.append(Planted("port-name-leading-digit", f"{i}nd_goal", 1))
    for t in trees:
        if " " in t.id:
            planted.append(Planted("model-name-forbidden-char", t.id, text.count(f'"{t.id}"')))
    merged: dict[tuple[str, str], int] = {}
    for p in planted:
        merged[(p.code, p.name)] = merged.get((p.code, p.name), 0) + p.count
    return Generated(
        text,
        tuple(Planted(c, nm, k) for (c, nm), k in merged.items()),
        len(trees) + 1,
        len(models),
    )


_UNITS = {"": 1, "K": 1024, "M": 1024**2}


def parse_size(text: str) -> int:
    """``60K``, ``1M``, ``4M`` or a number of bytes."""
    m = re.fullmatch(r"\s*(\d+(?:\.\d+)?)\s*([KkMm]?)B?\s*", text)
    if m is None:
        raise argparse.ArgumentTypeError(f"invalid size {text!r} (e.g. 60K, 1M)")
    return int(float(m.group(1)) * _UNITS[m.group(2).upper()])


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("size", type=parse_size, help="bytes, or with K/M (powers of 1024)")
    parser.add_argument("output", help="file to write ('-' for stdout)")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--bad", type=int, default=None, help="planted bad names")
    args = parser.parse_args(argv)
    g = generate(args.size, args.seed, args.bad)
    if args.output == "-":
        sys.stdout.write(g.text)
    else:
        with open(args.output, "w", encoding="utf-8", newline="\n") as f:
            f.write(g.text)
    print(
        f"{len(g.text.encode())} bytes, {g.trees} trees, {g.models} models, "
        f"{sum(p.count for p in g.planted)} bad names",
        file=sys.stderr,
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
