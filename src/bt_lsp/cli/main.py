"""The ``bt-lsp`` command line: ``serve``, ``check``, ``models`` and ``--version``.

``check`` never imports the language server (or pygls): the server is imported only when
``serve`` runs.
"""

from __future__ import annotations

import argparse
import os
import re
import sys
from collections.abc import Sequence
from typing import TextIO

from bt_lsp import __version__
from bt_lsp.cli import live
from bt_lsp.project.fileio import DEFAULT_MAX_BYTES

_UNITS = {"": 1, "k": 1024, "m": 1024**2, "g": 1024**3}


def _size(text: str) -> int:
    """A size in bytes, with an optional ``K``/``M``/``G`` suffix (powers of 1024)."""
    m = re.fullmatch(r"\s*(\d+)\s*([kmg]?)i?b?\s*", text, re.IGNORECASE)
    if m is None or int(m.group(1)) <= 0:
        raise argparse.ArgumentTypeError(f"invalid size {text!r} (e.g. 64M)")
    return int(m.group(1)) * _UNITS[m.group(2).lower()]


def _port(text: str) -> int:
    try:
        port = int(text)
    except ValueError:
        port = -1
    if not 0 <= port <= 65535:
        raise argparse.ArgumentTypeError(f"invalid port {text!r}")
    return port


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="bt-lsp",
        description="Language server and checker for BehaviorTree.CPP XML.",
    )
    parser.add_argument("--version", action="version", version=f"bt-lsp {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")

    serve = sub.add_parser(
        "serve",
        help="run the language server (stdio by default)",
        description="Run the language server on stdio (default) or TCP.",
    )
    serve.add_argument("--stdio", action="store_true", help="talk over stdin/stdout (the default)")
    serve.add_argument("--tcp", action="store_true", help="listen on TCP instead of stdio")
    serve.add_argument("--host", default="127.0.0.1", help="TCP host (default: %(default)s)")
    serve.add_argument("--port", type=_port, default=2087, help="TCP port (default: %(default)s)")

    check = sub.add_parser(
        "check",
        help="check files and print their diagnostics",
        description=(
            "Check BehaviorTree.CPP XML files (directories are searched for *.xml) and print "
            "every diagnostic as 'path:line:col: severity code message'. Exit status: 0 no "
            "errors, 1 at least one error, 2 usage error or a file that cannot be read."
        ),
    )
    check.add_argument("paths", nargs="+", metavar="PATH", help="files or directories")
    check.add_argument(
        "--format",
        choices=("text", "json", "sarif"),
        default="text",
        help="output format (default: %(default)s)",
    )
    check.add_argument(
        "--output-format",
        choices=("concise", "full"),
        help="text output: one line per diagnostic (concise, the default), or with the "
        "source line and a caret under the range (full)",
    )
    check.add_argument(
        "--color",
        choices=("auto", "always", "never"),
        default="auto",
        help="colour the text output (default: auto, on a terminal unless NO_COLOR is set, "
        "or when FORCE_COLOR is)",
    )
    check.add_argument(
        "--statistics",
        action="store_true",
        help="print the number of diagnostics per code instead of the diagnostics ([*]: a "
        "fix that --fix applies fixes them all; [-]: some of them)",
    )
    check.add_argument(
        "--fix",
        action="store_true",
        help="apply every safe fix in place (the editor's preferred fixes), then report "
        "what is left",
    )
    check.add_argument(
        "--unsafe-fixes",
        action="store_true",
        help="with --fix, apply the unsafe fixes too (those that change what loads or runs: "
        "a typo guess, a placeholder port value, a new tree); --statistics counts them as "
        "fixable",
    )
    check.add_argument(
        "--severity",
        action="append",
        default=[],
        metavar="CODE=LEVEL",
        help="override a code's severity: error, warning, information, hint or off "
        "(repeatable; several may be joined with commas)",
    )
    check.add_argument(
        "--models",
        action="append",
        default=[],
        metavar="FILE",
        help="a node catalog (TreeNodesModel XML that BehaviorTree.CPP exported) to trust as "
        "what the application registers (repeatable; replaces the configuration's models)",
    )
    check.add_argument("--no-progress", action="store_true", help="never show the progress bar")
    check.add_argument(
        "--no-cpp",
        action="store_true",
        help="do not read the node catalog from the packages' C++ sources",
    )
    check.add_argument(
        "--max-file-size",
        type=_size,
        default=DEFAULT_MAX_BYTES,
        metavar="SIZE",
        help="refuse files larger than this, and take included files larger than this as "
        f"not found, as the server does (e.g. 64M; default: {DEFAULT_MAX_BYTES // 2**20}M)",
    )
    check.add_argument(
        "--config",
        metavar="FILE",
        help="the configuration file for every checked file (default: the nearest "
        "bt-lsp.toml or pyproject.toml with [tool.bt-lsp] above each file)",
    )
    check.add_argument(
        "--btcpp",
        choices=("auto", "3", "4"),
        help="the BehaviorTree.CPP major version (default: the configuration's, else "
        "detected from package.xml, CMakeLists.txt or BTCPP_format)",
    )
    check.add_argument(
        "--min-severity",
        choices=("error", "warning", "information", "hint"),
        help="print only diagnostics at least this severe (default: the configuration's "
        "min-severity, else hint: all)",
    )
    check.add_argument(
        "-q",
        "--quiet",
        action="store_true",
        help="print the diagnostics and errors only: no summary, notes or progress",
    )
    check.add_argument(
        "--verbose",
        action="store_true",
        help="say which files were skipped and which BehaviorTree.CPP version each is "
        "checked against",
    )
    check.add_argument(
        "--force-exclude",
        action="store_true",
        help="leave out a file named on the command line as a walk over its workspace "
        "would: in an exclude glob or a build, install, log, VCS or hidden folder, or not "
        "BehaviorTree.CPP XML (for pre-commit hooks, which name the changed files)",
    )
    check.add_argument(
        "--follow-symlinks",
        action="store_true",
        help="with --fix, also rewrite files that a folder links to from outside it",
    )
    check.set_defaults(subparser=check)

    models = sub.add_parser(
        "models",
        help="print the node catalog learned from C++ sources",
        description=(
            "Read the C++ files under PATH (registrations and providedPorts, no build) and "
            "print the nodes as a TreeNodesModel document (xml, BehaviorTree.CPP's "
            "writeTreeNodesModelXML shape) or as json with source positions and flags."
        ),
    )
    models.add_argument("paths", nargs="+", metavar="PATH", help="C++ files or directories")
    models.add_argument(
        "--format", choices=("xml", "json"), default="xml", help="output (default: %(default)s)"
    )
    models.add_argument("--verbose", action="store_true", help="show progress on stderr")
    models.add_argument("--no-cache", action="store_true", help="neither read nor write the cache")

    render = sub.add_parser(
        "render",
        help="draw one tree of a file as SVG, Mermaid or DOT",
        description=(
            "Draw a tree of a BehaviorTree.CPP XML file (the main tree unless --tree names "
            "another): node kinds, instance names and problems as 'check' finds them, with "
            "the file's folder as the workspace. Exit status: 0, or 2 for an unreadable "
            "file, an unknown tree or an output that cannot be written."
        ),
    )
    render.add_argument("file", metavar="FILE", help="the XML file")
    render.add_argument("--tree", metavar="ID", help="the tree to draw (default: the main tree)")
    render.add_argument(
        "--format",
        choices=("svg", "mermaid", "dot"),
        default="svg",
        help="output format (default: %(default)s)",
    )
    render.add_argument("--ports", action="store_true", help="show each node's ports")
    render.add_argument(
        "--expand-subtrees",
        action="store_true",
        help="draw each called tree below its SubTree node (recursive calls stay collapsed)",
    )
    render.add_argument("-o", "--output", metavar="OUT", help="write here instead of stdout")
    render.add_argument(
        "--workspace",
        metavar="DIR",
        help="the folder whose files count as the workspace (default: the file's folder)",
    )
    live.add_parsers(sub)
    debug = sub.add_parser(
        "debug-adapter",
        help="a Debug Adapter (DAP, on stdio) for a running tree (Groot2 protocol)",
        description=(
            "Speak the Debug Adapter Protocol on stdin and stdout, for an editor's debugger: "
            "an 'attach' request with the host and port of an executor's Groot2Publisher "
            "(default 127.0.0.1:1667; it connects, never listens), breakpoints on the lines "
            "of tree files, the blackboards as variables, continue, and the custom requests "
            "btLsp/succeedNode and btLsp/failNode. Needs pyzmq (pip install 'bt-lsp[live]')."
        ),
    )
    debug.add_argument("--stdio", action="store_true", help="talk over stdin/stdout (the only way)")
    return parser


def _serve(args: argparse.Namespace) -> int:
    from bt_lsp.server import serve

    serve(tcp=args.tcp, host=args.host, port=args.port)
    return 0


def _check(parser: argparse.ArgumentParser, args: argparse.Namespace) -> int:
    from bt_lsp.cli import check
    from bt_lsp.cli.formats.text import use_color
    from bt_lsp.rules.codes import Severity

    try:
        severities = check.parse_severities(args.severity)
    except ValueError as e:
        parser.error(f"--severity: {e}")
    if args.format != "text" and (args.output_format or args.statistics):
        flag = "--output-format" if args.output_format else "--statistics"
        parser.error(f"{flag} is for --format text")
    text = args.format == "text"
    color = text and use_color(args.color, _isatty(sys.stdout), os.environ)
    options = check.Options(
        format=args.format,
        fix=args.fix,
        unsafe_fixes=args.unsafe_fixes,
        severities=severities,
        progress=not args.no_progress,
        max_bytes=args.max_file_size,
        cpp=not args.no_cpp,
        config=args.config,
        models=tuple(os.path.abspath(m) for m in args.models),
        btcpp=args.btcpp,
        verbose=args.verbose and not args.quiet,
        follow_symlinks=args.follow_symlinks,
        min_severity=Severity.parse(args.min_severity) if args.min_severity else None,
        quiet=args.quiet,
        output_format=args.output_format or "concise",
        color=color,
        statistics=args.statistics,
        force_exclude=args.force_exclude,
    )
    return check.run(args.paths, options)


def _isatty(stream: TextIO) -> bool:
    try:
        return stream.isatty()
    except (AttributeError, ValueError, OSError):
        return False


def _render(args: argparse.Namespace) -> int:
    from bt_lsp.cli import render

    options = render.Options(
        format=args.format,
        tree=args.tree,
        ports=args.ports,
        expand_subtrees=args.expand_subtrees,
        output=args.output,
        workspace=args.workspace,
    )
    return render.run(args.file, options)


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; returns the exit status (2 for a usage error)."""
    parser = build_parser()
    try:
        args = parser.parse_args(argv)
        if args.command == "serve":
            return _serve(args)
        if args.command == "check":
            return _check(args.subparser, args)
        if args.command == "models":
            from bt_lsp.cli import models

            return models.run(
                args.paths, format=args.format, verbose=args.verbose, cache=not args.no_cache
            )
        if args.command == "render":
            return _render(args)
        if args.command == "debug-adapter":
            from bt_lsp.dap.adapter import main as debug_adapter

            return debug_adapter()
        if args.command == "replay":
            return live.replay(args.file, format=args.format, node=args.node)
        if args.command == "monitor":
            return live.monitor(
                args.address,
                rate=args.rate,
                once=args.once,
                plain=args.plain,
                blackboard=args.blackboard,
                timeout=args.timeout,
                duration=args.duration,
                map_path=args.map,
            )
        parser.print_help(sys.stderr)
        return 2
    except SystemExit as e:
        return e.code if isinstance(e.code, int) else (0 if e.code is None else 2)
    except KeyboardInterrupt:
        return 130
    except BrokenPipeError:
        # The reader went away (e.g. `| head`): stop quietly.
        try:
            devnull = os.open(os.devnull, os.O_WRONLY)
            os.dup2(devnull, sys.stdout.fileno())
        except (OSError, ValueError):
            pass
        return 1
