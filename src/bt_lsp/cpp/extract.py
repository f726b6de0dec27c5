"""One C++ file's node facts, read from its tree-sitter syntax tree.

No preprocessor and nothing compiled: a query finds the few places that matter (the
registering calls, ``providedPorts``/``providedBasicPorts`` definitions, classes, string
constants, registering macros), and only those are walked in Python, which keeps the cost
close to tree-sitter's own parse.  Whatever a form does not match is kept as an
``unknown`` step, so the catalog can say that a port list is incomplete instead of
guessing.
"""

from __future__ import annotations

import re
from collections.abc import Iterator
from functools import cache
from typing import Final

import tree_sitter
import tree_sitter_cpp

from bt_lsp.cpp.facts import (
    ClassFacts,
    FileFacts,
    Helper,
    HelperCall,
    MacroCall,
    MacroTemplate,
    Op,
    PortFacts,
    PortsFn,
    Registration,
    Span,
)
from bt_lsp.cpp.names import last_name, split_top, squash, strip_args, unescape
from bt_lsp.cpp.tree_walk import declared_name, enclosing_call, template_args, up, up_to

Node = tree_sitter.Node

_PORT_FUNCTIONS: Final = {
    "InputPort": "input",
    "OutputPort": "output",
    "BidirectionalPort": "inout",
}
_TEMPLATE_REGISTRARS: Final = frozenset({"registerNodeType", "registerBuilder"})
_SIMPLE_REGISTRARS: Final = {
    "registerSimpleAction": "Action",
    "registerSimpleCondition": "Condition",
    "registerSimpleDecorator": "Decorator",
}
# Only files holding one of these are parsed at first (the others are read when they name a
# base class, constant or macro that the catalog misses).
_KEYWORDS: Final = (
    b"providedPorts",
    b"providedBasicPorts",
    b"registerNodeType",
    b"registerBuilder",
    b"registerSimple",
    b"registerBehavior",
    b"BT_REGISTER",
    b"CreateRosNodePlugin",
    b"CreateManifest",
)
# Every keyword holds one of these: most files hold none, and are told apart by four
# searches instead of nine.
_KEYWORD_PARTS: Final = (b"provided", b"register", b"REGISTER", b"Create")
assert all(any(w in k for w in _KEYWORD_PARTS) for k in _KEYWORDS)
# The places that matter, found in the text (in C, much faster than a query over every
# identifier) and then looked up in the tree: the match must be the node found there.
_CALLEES: Final = re.compile(
    rb"\b(?:registerNodeType|registerBuilder|registerSimpleAction|registerSimpleCondition"
    rb"|registerSimpleDecorator|providedPorts|providedBasicPorts|CreateManifest|registerBehavior)\b"
)
_CLASS_KEYWORD: Final = re.compile(rb"\b(?:class|struct)\b")
_DEFINE: Final = re.compile(rb"#[ \t]*define\b")
_CONST_STRING: Final = re.compile(rb"\b(?:const|constexpr)\b[^;{}\n]*?(\")")
_CLASS_TYPES: Final = frozenset({"class_specifier", "struct_specifier"})

# Invocations of macros that may register nodes (ALL_CAPS names, or names that say so),
# with one to four arguments: a type, then strings or names (an ID, constructor
# arguments such as ``params``; more than two but for logging and test macros).  Found
# in the text, because a macro invoked without a trailing semicolon parses as anything.
# The macros of logging and test libraries, which take several arguments and register
# nothing (most ALL_CAPS calls with more than two arguments in real code).
_NOT_REGISTRARS: Final = (
    "RCLCPP_",
    "RCUTILS_",
    "ROS_",
    "RMW_",
    "EXPECT_",
    "ASSERT_",
    "SPDLOG_",
    "LOG_",
    "BOOST_",
    "TEST",
    "INSTANTIATE_",
    "PLUGINLIB_",
    "CLASS_LOADER_",
)
_MACRO_ARG: Final = rb"(?:,[ \t\r\n]*(\"(?:[^\"\\\n]|\\.)*\"|[A-Za-z0-9_][\w:.]*))?[ \t\r\n]*"
_MACRO_CALL: Final = re.compile(
    rb"\b([A-Z][A-Z0-9_]{2,}|\w*(?:[Rr]egist|Plugin)\w*)[ \t]*\([ \t\r\n]*"
    rb"([A-Za-z_][\w:]*(?:<[^()<>;\n]*>)?)[ \t\r\n]*" + _MACRO_ARG * 3 + rb"\)"
)
_MACRO_BODY: Final = re.compile(
    r"(registerNodeType|registerBuilder)\s*<\s*((?:::)?[A-Za-z_]\w*(?:\s*::\s*[A-Za-z_]\w*)*)\s*>"
    r"\s*\(\s*"
    r"(?:#\s*([A-Za-z_]\w*)|([A-Za-z_]\w*)|\"((?:[^\"\\]|\\.)*)\")"
)


# A macro whose body calls a function template or makes an object of a class template
# with a parameter as its class and a stringified parameter (or a literal) as the ID:
# ``#define REG(T) static Registrar<T> reg_##T(#T);``, ``#define REG(T) reg<T>(f, #T)``.
# It registers when the function or class is a registering helper of the project.
_MACRO_HELPER: Final = re.compile(
    r"\b([A-Za-z_]\w*)\s*<\s*((?:::)?[A-Za-z_]\w*(?:\s*::\s*[A-Za-z_]\w*)*)\s*>\s*"
    r"(?:[A-Za-z_][\w#]*\s*)?[({]\s*(?:[^(){};\"]*?,\s*)?"
    r"(?:#\s*([A-Za-z_]\w*)|\"((?:[^\"\\]|\\.)*)\")"
)
# Calls that may be of a project's registering helper: a function template called with
# template arguments (``reg<MyNode>(factory, "MyNode")``), or a function whose name says
# it registers.  Only those with a string literal among their arguments are kept.
_HELPER_CALL: Final = re.compile(rb"\b([A-Za-z_]\w*)[ \t]*(?:<[^;{}()]*?>[ \t\r\n]*\(|\()")
_REGISTRAR_OBJECT: Final = re.compile(
    rb"\b([A-Za-z_]\w*)[ \t]*<[^;{}()]*?>[ \t\r\n]*[A-Za-z_]\w*[ \t]*[({][ \t\r\n]*\""
)
_HELPER_NAME: Final = re.compile(r"[Rr]egist|^[Rr]eg(?:[A-Z_]|$)|^add[A-Z]")
_NOT_HELPERS: Final = frozenset(
    {
        *_PORT_FUNCTIONS,
        *_TEMPLATE_REGISTRARS,
        *_SIMPLE_REGISTRARS,
        "registerBehavior",
        "CreateManifest",
        "CreateBuilder",
        "make_shared",
        "make_unique",
        "getInput",
        "setOutput",
        "get",
        "set",
        "static_cast",
        "dynamic_cast",
        "reinterpret_cast",
        "const_cast",
        "registerScriptingEnum",
        "registerFromPlugin",
        "registerFromROSPlugins",
        "registerBehaviorTreeFromFile",
        "registerBehaviorTreeFromText",
        "registerPolymorphicCast",
        "unregisterBuilder",
    }
)


@cache
def _language() -> tree_sitter.Language:
    return tree_sitter.Language(tree_sitter_cpp.language())


def parser() -> tree_sitter.Parser:
    """A C++ parser (one per caller: tree-sitter parsers are not shared across threads)."""
    return tree_sitter.Parser(_language())


def may_declare_nodes(source: bytes) -> bool:
    """Whether ``source`` can hold a registration or a port list (a cheap text test: a
    few short words that every keyword holds first, then the keywords)."""
    return any(w in source for w in _KEYWORD_PARTS) and any(k in source for k in _KEYWORDS)


def extract(source: bytes, parser_: tree_sitter.Parser | None = None) -> FileFacts:
    """The node facts of one C++ file's text."""
    tree = (parser_ or parser()).parse(source)
    return _Reader(source).read(tree.root_node)


class _Reader:
    def __init__(self, source: bytes) -> None:
        self.src = source
        self.ascii = source.isascii()
        self.classes: list[ClassFacts] = []
        self.fns: list[PortsFn] = []
        self.regs: list[Registration] = []
        self.macros: list[MacroTemplate] = []
        self.helpers: list[Helper] = []
        self.constants: dict[str, str] = {}
        self._seen_calls: set[int] = set()

    # --- text and positions ------------------------------------------------------------

    def text(self, n: Node) -> str:
        return self.src[n.start_byte : n.end_byte].decode("utf-8", "replace")

    def _col(self, byte: int, point_col: int) -> int:
        if self.ascii:
            return point_col
        line_start = byte - point_col
        return len(self.src[line_start:byte].decode("utf-8", "replace"))

    def span(self, n: Node) -> Span:
        s, e = n.start_point, n.end_point
        return (s[0], self._col(n.start_byte, s[1]), e[0], self._col(n.end_byte, e[1]))

    def _span_of_bytes(self, start: int, end: int) -> Span:
        def point(b: int) -> tuple[int, int]:
            line = self.src.count(b"\n", 0, b)
            ls = self.src.rfind(b"\n", 0, b) + 1
            return line, len(self.src[ls:b].decode("utf-8", "replace"))

        return (*point(start), *point(end))

    # --- the file ----------------------------------------------------------------------

    def read(self, root: Node) -> FileFacts:
        src = self.src
        for m in _DEFINE.finditer(src):
            n = up(root.descendant_for_byte_range(m.start(), m.end()), 2)
            if n is not None and n.type == "preproc_def":
                self._define(n)
            elif n is not None and n.type == "preproc_function_def":
                self._macro(n)
        for m in _CONST_STRING.finditer(src):
            lit = root.descendant_for_byte_range(m.start(1), m.start(1) + 1)
            decl = up_to(lit, ("declaration", "field_declaration"), 5)
            if (
                decl is not None
                and decl.parent is not None
                and decl.parent.type
                in (
                    "translation_unit",
                    "declaration_list",
                )
            ):
                self._file_constant(decl)
        for m in _CLASS_KEYWORD.finditer(src):
            kw = root.descendant_for_byte_range(m.start(), m.end())
            cls = kw.parent if kw is not None else None
            if (
                cls is not None
                and cls.type in _CLASS_TYPES
                and cls.start_byte == m.start()
                and cls.child_by_field_name("body") is not None
            ):
                self._class(cls)
        for m in _CALLEES.finditer(src):
            n = root.descendant_for_byte_range(m.start(), m.end())
            if (
                n is not None
                and n.type in ("identifier", "field_identifier")
                and n.start_byte == m.start()
                and n.end_byte == m.end()
            ):
                self._callee(n)
        calls = tuple(self._macro_calls(root)) if self.src.find(b"(") >= 0 else ()
        return FileFacts(
            tuple(self.classes),
            tuple(self.fns),
            tuple(sorted(self.regs, key=lambda r: r.span)),
            tuple(self.macros),
            calls,
            self.constants,
            tuple(self.helpers),
            tuple(self._helper_calls(root)) if b'"' in self.src else (),
        )

    # --- constants ---------------------------------------------------------------------

    def _define(self, n: Node) -> None:
        name, value = n.child_by_field_name("name"), n.child_by_field_name("value")
        if name is None or value is None:
            return
        v = self.text(value).strip()
        if len(v) >= 2 and v[0] == '"' and v[-1] == '"':
            self.constants[self.text(name)] = unescape(v[1:-1])

    def _string_constant(self, decl: Node) -> tuple[str, str] | None:
        """``name, value`` of a declaration of one string constant, else ``None``."""
        if "const" not in self.text(decl).split("=", 1)[0] and decl.type != "preproc_def":
            return None
        for d in decl.children_by_field_name("declarator"):
            value = d.child_by_field_name("value") if d.type == "init_declarator" else None
            target = d.child_by_field_name("declarator") if d.type == "init_declarator" else d
            if value is None:
                value = decl.child_by_field_name("default_value")
            if value is not None and value.type in ("initializer_list", "argument_list"):
                inner = value.named_children
                value = inner[0] if len(inner) == 1 else None
            if value is None or target is None:
                continue
            s = self.string(value)
            name = declared_name(target)
            if s is not None and name is not None:
                return self.text(name), s
        return None

    def _file_constant(self, n: Node) -> None:
        c = self._string_constant(n)
        if c is not None:
            self.constants.setdefault(c[0], c[1])

    # --- strings -----------------------------------------------------------------------

    def string(self, n: Node) -> str | None:
        """The value of a string literal (or concatenation of them), else ``None``."""
        if n.type == "string_literal":
            out: list[str] = []
            for c in n.named_children:
                if c.type == "string_content":
                    out.append(self.text(c))
                elif c.type == "escape_sequence":
                    out.append(unescape(self.text(c)))
            return "".join(out)
        if n.type == "raw_string_literal":
            for c in n.named_children:
                if c.type == "raw_string_content":
                    return self.text(c)
            return ""
        if n.type == "user_defined_literal":  # "x"s, "x"sv
            inner = n.named_children
            if (
                len(inner) == 2
                and inner[1].type == "literal_suffix"
                and self.text(inner[1]) in ("s", "sv")
            ):
                return self.string(inner[0])
            return None
        if n.type == "concatenated_string":
            parts = [self.string(c) for c in n.named_children]
            if any(p is None for p in parts):
                return None
            return "".join(p for p in parts if p is not None)
        if n.type == "call_expression":  # std::string("x"), BT::StringView{"x"}
            fn = n.child_by_field_name("function")
            args = n.child_by_field_name("arguments")
            if fn is not None and args is not None and self.text(fn) in _STRING_TYPES:
                a = args.named_children
                if len(a) == 1:
                    return self.string(a[0])
        return None

    # --- classes -----------------------------------------------------------------------

    def _class(self, n: Node) -> None:
        name_node = n.child_by_field_name("name")
        body = n.child_by_field_name("body")
        if name_node is None or body is None:
            return
        name = strip_args(self.text(name_node))
        qual = "::".join([*self._scopes(n), name])
        bases: list[str] = []
        for c in n.named_children:
            if c.type == "base_class_clause":
                bases.extend(
                    squash(self.text(b))
                    for b in c.named_children
                    if b.type not in ("access_specifier", "comment", "virtual")
                )
        params: tuple[str, ...] = ()
        parent = n.parent
        if parent is not None and parent.type == "template_declaration":
            plist = parent.child_by_field_name("parameters")
            if plist is not None:
                params = tuple(p for p in map(self._template_param, plist.named_children) if p)
        using_ports: str | None = None
        aliases: dict[str, str] = {}
        constants: dict[str, str] = {}
        declared: list[str] = []
        for m in body.named_children:
            if m.type in ("field_declaration", "declaration"):
                fn = self._declared_ports_fn(m)
                if fn is not None:
                    declared.append(fn)
                    continue
            if m.type == "using_declaration":
                t = self.text(m)
                if "providedPorts" in t:
                    target = t.removeprefix("using").strip().rstrip(";").strip()
                    using_ports = squash(target.rsplit("::", 1)[0])
            elif m.type == "alias_declaration":
                an, at = m.child_by_field_name("name"), m.child_by_field_name("type")
                if an is not None and at is not None:
                    aliases[self.text(an)] = squash(self.text(at))
            elif m.type in ("field_declaration", "declaration"):
                kv = self._string_constant(m)
                if kv is not None:
                    constants[kv[0]] = kv[1]
        self.classes.append(
            ClassFacts(
                name,
                qual,
                self.span(name_node),
                tuple(bases),
                params,
                using_ports,
                aliases,
                constants,
                tuple(declared),
            )
        )

    def _declared_ports_fn(self, m: Node) -> str | None:
        """``providedPorts``/``providedBasicPorts`` when ``m`` declares it without a body."""
        for d in m.children_by_field_name("declarator"):
            while d.type in ("pointer_declarator", "reference_declarator"):
                inner = d.child_by_field_name("declarator")
                if inner is None:
                    break
                d = inner
            if d.type == "function_declarator":
                name = d.child_by_field_name("declarator")
                if name is not None and self.text(name) in ("providedPorts", "providedBasicPorts"):
                    return self.text(name)
        return None

    def _template_param(self, p: Node) -> str | None:
        for c in p.named_children:
            if c.type in ("type_identifier", "identifier"):
                return self.text(c)
        return None

    def _scopes(self, n: Node) -> list[str]:
        """The namespaces and classes enclosing ``n``, outermost first."""
        out: list[str] = []
        p = n.parent
        while p is not None:
            if p.type in ("namespace_definition", "class_specifier", "struct_specifier"):
                nm = p.child_by_field_name("name")
                if nm is not None:
                    out.append(strip_args(self.text(nm)))
            p = p.parent
        out.reverse()
        return out

    # --- calls and definitions ---------------------------------------------------------

    def _callee(self, ident: Node) -> None:
        name = self.text(ident)
        if name in ("providedPorts", "providedBasicPorts"):
            self._ports_fn(ident, name)
            return
        call = enclosing_call(ident)
        if call is None or call.id in self._seen_calls:
            return
        self._seen_calls.add(call.id)
        args_node = call.child_by_field_name("arguments")
        if args_node is None:
            return
        args = [a for a in args_node.named_children if a.type != "comment"]
        targs = template_args(call.child_by_field_name("function"))
        if name in _TEMPLATE_REGISTRARS and targs:
            if args:
                self._registration(name, args[0], targs[0], None, None, call)
        elif name == "registerBuilder" and args and args[0].type == "call_expression":
            manifest = args[0]
            mf = manifest.child_by_field_name("function")
            margs_node = manifest.child_by_field_name("arguments")
            mt = template_args(mf)
            if mf is None or margs_node is None or not mt or "CreateManifest" not in self.text(mf):
                return
            margs = margs_node.named_children
            if margs:
                ops = self._ports_arg(margs[1], call) if len(margs) > 1 else None
                self._registration("CreateManifest", margs[0], mt[0], None, ops, call)
        elif name in _SIMPLE_REGISTRARS and args:
            ops = self._ports_arg(args[2], call) if len(args) > 2 else ()
            self._registration(name, args[0], None, _SIMPLE_REGISTRARS[name], ops, call)
        elif name == "registerBehavior" and targs and len(args) >= 2:
            self._registration(name, args[1], targs[0], None, None, call)

    def _registration(
        self,
        form: str,
        id_node: Node,
        cls: str | None,
        kind: str | None,
        ops: tuple[Op, ...] | None,
        call: Node,
    ) -> None:
        value = self.string(id_node)
        if self._helper(form, id_node, value, cls, ops, call):
            return
        ref = None if value is not None else squash(self.text(id_node))
        self.regs.append(
            Registration(form, value, ref, self.span(id_node), cls, kind, ops, self.span(call))
        )

    def _helper(
        self,
        form: str,
        id_node: Node,
        value: str | None,
        cls: str | None,
        ops: tuple[Op, ...] | None,
        call: Node,
    ) -> bool:
        """Record the registration as a helper's when its class is a template parameter or
        its ID a parameter of the function around it (registered for each caller)."""
        fn = up_to(call, ("function_definition",), 64)
        if fn is None:
            return False
        decl = fn.child_by_field_name("declarator")
        while decl is not None and decl.type != "function_declarator":
            decl = decl.child_by_field_name("declarator")
        if decl is None:
            return False
        name_node, plist = (
            decl.child_by_field_name("declarator"),
            decl.child_by_field_name("parameters"),
        )
        if name_node is None or plist is None:
            return False
        params: list[str] = []
        for p in plist.named_children:
            d = p.child_by_field_name("declarator")
            nm = declared_name(d) if d is not None else None
            params.append(self.text(nm) if nm is not None else "")
        tparams: tuple[str, ...] = ()
        holder = fn.parent
        if holder is not None and holder.type == "field_declaration_list":
            # A member (a registrar's constructor): the class template's parameters.
            holder = holder.parent.parent if holder.parent is not None else None
        if holder is not None and holder.type == "template_declaration":
            tl = holder.child_by_field_name("parameters")
            if tl is not None:
                tparams = tuple(p for p in map(self._template_param, tl.named_children) if p)
        id_text = self.text(id_node).strip()
        id_param = params.index(id_text) if value is None and id_text in params else -1
        cls_tparam = tparams.index(cls) if cls is not None and cls in tparams else -1
        if id_param < 0 and cls_tparam < 0:
            return False
        if id_param < 0 and value is None:
            return False  # an ID that is neither a literal nor a parameter: unresolved
        self.helpers.append(
            Helper(
                last_name(strip_args(self.text(name_node))),
                form,
                cls_tparam,
                None if cls_tparam >= 0 else cls,
                id_param,
                value,
                ops,
                self.span(call),
            )
        )
        return True

    def _helper_calls(self, root: Node) -> Iterator[HelperCall]:
        yield from self._registrar_objects(root)
        for m in _HELPER_CALL.finditer(self.src):
            name = m.group(1).decode()
            templated = m.group(0).rstrip(b"( \t\r\n").endswith(b">")
            if name in _NOT_HELPERS or not (templated or _HELPER_NAME.search(name)):
                continue
            ident = root.descendant_for_byte_range(m.start(1), m.end(1))
            if ident is None or ident.type != "identifier" or ident.start_byte != m.start(1):
                continue
            call = enclosing_call(ident)
            if call is None or call.id in self._seen_calls:
                continue
            args_node = call.child_by_field_name("arguments")
            if args_node is None:
                continue
            args = [a for a in args_node.named_children if a.type != "comment"]
            values = tuple(self.string(a) for a in args)
            if all(v is None for v in values) and not (
                (templated and len(args) >= 2) or (args and _HELPER_NAME.search(name))
            ):
                continue
            yield HelperCall(
                name,
                tuple(template_args(call.child_by_field_name("function"))),
                tuple(squash(self.text(a)) for a in args),
                values,
                tuple(self.span(a) for a in args),
                self.span(call),
            )

    def _registrar_objects(self, root: Node) -> Iterator[HelperCall]:
        """Objects of a class template made with a string argument, which may be of a
        registrar: ``static Registrar<MyNode> reg("MyNode");``."""
        for m in _REGISTRAR_OBJECT.finditer(self.src):
            ident = root.descendant_for_byte_range(m.start(1), m.end(1))
            if ident is None or ident.type != "type_identifier":
                continue
            decl = up_to(ident, ("declaration",), 4)
            tt = ident.parent
            if decl is None or tt is None or tt.type != "template_type":
                continue
            for d in decl.children_by_field_name("declarator"):
                if d.type != "init_declarator":
                    continue
                value = d.child_by_field_name("value")
                if value is None or value.type not in ("argument_list", "initializer_list"):
                    continue
                args = [a for a in value.named_children if a.type != "comment"]
                values = tuple(self.string(a) for a in args)
                if all(v is None for v in values):
                    continue
                targs = tt.child_by_field_name("arguments")
                inner = self.text(targs)[1:-1] if targs is not None else ""
                yield HelperCall(
                    self.text(ident),
                    tuple(squash(a) for a in split_top(inner)),
                    tuple(squash(self.text(a)) for a in args),
                    values,
                    tuple(self.span(a) for a in args),
                    self.span(d),
                )

    def _ports_fn(self, ident: Node, name: str) -> None:
        decl = ident.parent
        owner_parts: list[str] = []
        if decl is not None and decl.type == "qualified_identifier":
            scope = decl.child_by_field_name("scope")
            if scope is not None:
                owner_parts.append(strip_args(self.text(scope)))
            while decl is not None and decl.type == "qualified_identifier":
                decl = decl.parent
        if decl is None or decl.type != "function_declarator":
            return
        fn = decl.parent
        while fn is not None and fn.type in ("pointer_declarator", "reference_declarator"):
            fn = fn.parent
        if fn is None or fn.type != "function_definition":
            return
        body = fn.child_by_field_name("body")
        if body is None:
            return
        scopes = self._scopes(fn)
        owner = "::".join([*scopes, *owner_parts]) if owner_parts or scopes else ""
        if not owner:
            return
        param: str | None = None
        params = decl.child_by_field_name("parameters")
        if params is not None:
            for p in params.named_children:
                d = p.child_by_field_name("declarator")
                if d is not None:
                    nm = declared_name(d)
                    param = self.text(nm) if nm is not None else None
        self.fns.append(PortsFn(owner, name, param, self.ports_body(body, param), self.span(fn)))

    # --- port lists --------------------------------------------------------------------

    def ports_body(self, body: Node, param: str | None) -> tuple[Op, ...]:
        """The steps of a ``providedPorts`` body: locals, ``insert``/``emplace``, ``return``."""
        local: dict[str, list[Op]] = {}
        if param:
            local[param] = [Op("param")]
        result: tuple[Op, ...] | None = None
        extra: list[Op] = []
        for st in body.named_children:
            t = st.type
            if t == "comment":
                continue
            if t == "declaration":
                self._declare(st, local)
                continue
            if t == "expression_statement" and st.named_children:
                e = st.named_children[0]
                if e.type == "call_expression" and self._insert(e, local):
                    continue
                extra.append(Op("unknown", ref=squash(self.text(st))))
                continue
            if t == "return_statement":
                vals = st.named_children
                result = self.ports_expr(vals[0], local) if vals else ()
                break
            extra.append(Op("unknown", ref=squash(self.text(st))[:80]))
        if result is None:
            return (*extra, Op("unknown", ref="no return of a port list"))
        return (*extra, *result)

    def _declare(self, st: Node, local: dict[str, list[Op]]) -> None:
        """The port lists a declaration statement makes (``PortsList p = {…};``)."""
        for d in st.children_by_field_name("declarator"):
            if d.type == "init_declarator":
                target = d.child_by_field_name("declarator")
                value = d.child_by_field_name("value")
                if target is not None and value is not None:
                    if value.type == "argument_list":
                        inner = value.named_children
                        ops = (
                            self.ports_expr(inner[0], local)
                            if len(inner) == 1
                            else ((Op("unknown", ref=self.text(value)),) if inner else ())
                        )
                    else:
                        ops = self.ports_expr(value, local)
                    local[self.text(target)] = list(ops)
            elif d.type == "identifier":
                local[self.text(d)] = []

    def _locals_before(self, call: Node, names: set[str]) -> dict[str, list[Op]]:
        """The port lists named ``names`` that the statements before ``call``'s, in its
        block, build: ``PortsList ports = {…}; ports.insert(…);`` then the call."""
        st: Node | None = call
        while st is not None and st.parent is not None and st.parent.type != "compound_statement":
            st = st.parent
        local: dict[str, list[Op]] = {}
        if st is None or st.parent is None:
            return local
        for prev in st.parent.named_children:
            if prev.start_byte >= st.start_byte:
                break
            if prev.type == "declaration" and any(
                (nm := declared_name(d)) is not None and self.text(nm) in names
                for d in prev.children_by_field_name("declarator")
            ):
                self._declare(prev, local)
            elif prev.type == "expression_statement" and prev.named_children:
                e = prev.named_children[0]
                if e.type == "call_expression":
                    self._insert(e, local)
                elif e.type == "assignment_expression":
                    left, right = e.child_by_field_name("left"), e.child_by_field_name("right")
                    if left is not None and right is not None and self.text(left) in names:
                        local[self.text(left)] = list(self.ports_expr(right, local))
        return local

    def _ports_arg(self, arg: Node, call: Node) -> tuple[Op, ...]:
        """The port list an argument of a registering call gives (maybe a local)."""
        local = self._locals_before(call, {self.text(arg)}) if arg.type == "identifier" else {}
        return self.ports_expr(arg, local)

    def _insert(self, call: Node, local: dict[str, list[Op]]) -> bool:
        fn = call.child_by_field_name("function")
        args_node = call.child_by_field_name("arguments")
        if fn is None or args_node is None or fn.type != "field_expression":
            return False
        obj, field = fn.child_by_field_name("argument"), fn.child_by_field_name("field")
        if obj is None or field is None or self.text(field) not in ("insert", "emplace"):
            return False
        target = local.get(self.text(obj))
        if target is None:
            return False
        args = args_node.named_children
        if len(args) == 2 and self.text(args[0]).endswith(".begin()"):
            src = self.text(args[0])[: -len(".begin()")]
            target.extend(
                local.get(src, [Op("unknown", ref=src)]) if src in local else self._range(src)
            )
        elif len(args) == 1:
            a = args[0]
            if a.type == "initializer_list" and not self._is_port_call(a):
                target.extend(self.ports_expr(a, local))
            else:
                target.append(self.port_item(a))
        else:
            target.append(Op("unknown", ref=squash(self.text(call))))
        return True

    def _range(self, src: str) -> list[Op]:
        if src.endswith("providedPorts()"):
            return [Op("ref", ref=strip_args(src.rsplit("::", 1)[0]) if "::" in src else "")]
        return [Op("unknown", ref=src)]

    def _is_port_call(self, n: Node) -> bool:
        return n.type == "call_expression" and self._port_direction(n) is not None

    def ports_expr(self, n: Node, local: dict[str, list[Op]]) -> tuple[Op, ...]:
        """The steps of an expression that yields a port list."""
        t = n.type
        if t == "initializer_list":
            return tuple(self.port_item(c) for c in n.named_children if c.type != "comment")
        if t == "identifier" and self.text(n) in local:
            return tuple(local[self.text(n)])
        if t == "compound_literal_expression":
            value = n.child_by_field_name("value")
            if value is not None and last_name(self.text(n.child_by_field_name("type") or n)) == (
                "PortsList"
            ):
                return self.ports_expr(value, local)
        if t == "call_expression":
            fn = n.child_by_field_name("function")
            args_node = n.child_by_field_name("arguments")
            if fn is not None and args_node is not None:
                fname = strip_args(self.text(fn))
                last = last_name(fname)
                args = args_node.named_children
                if last == "PortsList":
                    return self.ports_expr(args[0], local) if len(args) == 1 else ()
                scope = fname.rsplit("::", 1)[0] if "::" in fname else ""
                if last == "providedPorts" and not args:
                    return (Op("ref", ref=scope),)
                if last == "providedBasicPorts" and len(args) <= 1:
                    inner = self.ports_expr(args[0], local) if args else ()
                    return (Op("basic", ref=scope, ops=inner),)
                # A helper not followed (``appendPorts(Base::providedPorts(), {…})``): its
                # result is unknown, the port lists given to it are kept.
                given = [
                    op
                    for a in args
                    if self._is_port_list(a, local)
                    for op in self.ports_expr(a, local)
                ]
                if given:
                    return (Op("unknown", ref=squash(self.text(n))[:80]), *given)
        if t == "parenthesized_expression" and n.named_children:
            return self.ports_expr(n.named_children[0], local)
        return (Op("unknown", ref=squash(self.text(n))[:80]),)

    def _is_port_list(self, n: Node, local: dict[str, list[Op]]) -> bool:
        """Whether ``n`` is plainly a port list: ``{InputPort…}``, a local port list,
        ``X::providedPorts()``."""
        if n.type == "initializer_list":
            return any(self._is_port_call(c) for c in n.named_children)
        if n.type == "identifier":
            return self.text(n) in local
        if n.type == "call_expression":
            fn = n.child_by_field_name("function")
            return fn is not None and last_name(strip_args(self.text(fn))) in (
                "providedPorts",
                "providedBasicPorts",
            )
        return False

    def _port_direction(self, call: Node) -> str | None:
        fn = call.child_by_field_name("function")
        if fn is None:
            return None
        return _PORT_FUNCTIONS.get(last_name(strip_args(self.text(fn))))

    def port_item(self, n: Node) -> Op:
        """One element of a port list: a port call, else an unknown step."""
        if n.type == "call_expression":
            direction = self._port_direction(n)
            args_node = n.child_by_field_name("arguments")
            if direction is not None and args_node is not None:
                args = [a for a in args_node.named_children if a.type != "comment"]
                if args:
                    return Op("port", self._port(n, direction, args))
        return Op("unknown", ref=squash(self.text(n))[:80])

    def _port(self, call: Node, direction: str, args: list[Node]) -> PortFacts:
        targs = template_args(call.child_by_field_name("function"))
        type_ = targs[0] if targs else None
        name_node = args[0]
        name = self.string(name_node)
        name_ref = None if name is not None else squash(self.text(name_node))
        default: str | None = None
        is_expr = literal = False
        desc_node: Node | None = None
        if len(args) == 2:
            desc_node = args[1]
        elif len(args) >= 3:
            default, is_expr, literal = self._default(args[1])
            desc_node = args[2]
        desc = (self.string(desc_node) if desc_node is not None else "") or ""
        return PortFacts(
            direction,
            type_,
            name,
            name_ref,
            self.span(name_node),
            default,
            is_expr,
            desc,
            self.span(call),
            literal,
        )

    def _default(self, n: Node) -> tuple[str, bool, bool]:
        """A default's text, whether it is an expression, whether a number/bool literal."""
        s = self.string(n)
        if s is not None:
            return s, False, False
        text = squash(self.text(n))
        if n.type in ("number_literal", "true", "false") or (
            n.type == "unary_expression" and re.fullmatch(r"[-+]\s*[\d.][\w.']*", text)
        ):
            return text.replace(" ", ""), False, True
        return text, True, False

    # --- macros ------------------------------------------------------------------------

    def _macro(self, n: Node) -> None:
        name, params, value = (
            n.child_by_field_name("name"),
            n.child_by_field_name("parameters"),
            n.child_by_field_name("value"),
        )
        if name is None or params is None or value is None:
            return
        body = re.sub(r"\\\r?\n", " ", self.text(value))  # continuation lines joined
        m = _MACRO_BODY.search(body)
        if m is not None:
            form, cls_text, str_p, id_p, lit = m.groups()
        else:
            h = _MACRO_HELPER.search(body)
            if h is None or h.group(1) in _NOT_HELPERS:
                return
            (form, cls_text, str_p, lit), id_p = h.groups(), None
        plist = tuple(self.text(p) for p in params.named_children)
        cls_text = re.sub(r"\s+", "", cls_text)
        # The class is a parameter, or a name made of parameters (``ns::name``).
        cls_p = next((p for p in cls_text.split("::") if p in plist), None)
        if cls_p is None:
            return
        id_name = str_p or id_p
        if id_name is not None and id_name not in plist:
            return
        self.macros.append(
            MacroTemplate(
                self.text(name),
                plist,
                form,
                plist.index(cls_p),
                plist.index(id_name) if id_name is not None else -1,
                str_p is not None,
                None if lit is None else unescape(lit),
                "" if cls_text == cls_p else cls_text,
            )
        )

    def _macro_calls(self, root: Node) -> Iterator[MacroCall]:
        own = {m.name for m in self.macros}
        for m in _MACRO_CALL.finditer(self.src):
            name = m.group(1).decode()
            if name in _SIMPLE_REGISTRARS or name in _TEMPLATE_REGISTRARS:
                continue
            groups = [g for g in (2, 3, 4, 5) if m.group(g) is not None]
            if len(groups) > 2 and name not in own and name.startswith(_NOT_REGISTRARS):
                continue  # RCLCPP_INFO(logger, "...", x): logging, not registering
            at = root.descendant_for_byte_range(m.start(1), m.end(1))
            if at is None or at.type in ("comment", "string_content", "preproc_arg"):
                continue
            p = at.parent
            if p is not None and p.type in ("preproc_function_def", "preproc_def"):
                continue
            yield MacroCall(
                name,
                tuple(m.group(g).decode("utf-8", "replace") for g in groups),
                tuple(self._span_of_bytes(m.start(g), m.end(g)) for g in groups),
                self._span_of_bytes(m.start(), m.end()),
            )


_STRING_TYPES: Final = frozenset(
    {"std::string", "string", "BT::StringView", "StringView", "std::string_view"}
)
