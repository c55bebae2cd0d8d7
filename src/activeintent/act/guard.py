"""Static allow-list for model-written robot programs (the first sandbox layer).

A program may only use plain Python control flow, functions, comprehensions and the names the
robot API provides. Everything that can reach the interpreter's internals is refused before the
program runs: imports, every name or attribute starting with ``_``, introspection builtins,
frame/generator/code attributes (which need no underscore), ``str.format`` (whose format
strings can walk attributes), classes, ``global``/``nonlocal``, ``yield``, ``async`` (also
asynchronous comprehensions) and ``with``; numpy's raw-memory and file attributes; and every
way of naming a dtype that is not a plain numeric literal (no object, void or structured
arrays): ``dtype=`` keywords, the dtype argument given by position to ``np`` functions and to
array methods (``a.cumsum(0, 'O')``, ``a.astype(t)``), ``*``/``**`` unpacking into such calls,
such methods taken without being called (``f = a.cumsum``) and rebinding the name ``np``.

A check of source text cannot close every hole: it is only the first layer. What contains a
program is the worker's isolation (namespaces, seccomp, resource limits: see ``sandbox`` and
``docs/security.md``), which holds even with this guard switched off.
"""

from __future__ import annotations

import ast

MAX_PROGRAM_CHARS = 20_000

ALLOWED_NODES: tuple[type[ast.AST], ...] = (
    ast.Module, ast.Expr, ast.Assign, ast.AugAssign, ast.For, ast.While, ast.If, ast.Break,
    ast.Continue, ast.Pass, ast.FunctionDef, ast.Return, ast.arguments, ast.arg, ast.keyword,
    ast.Name, ast.Load, ast.Store, ast.Del, ast.Delete, ast.Constant, ast.JoinedStr,
    ast.FormattedValue, ast.List, ast.Tuple, ast.Set, ast.Dict, ast.ListComp, ast.SetComp,
    ast.DictComp, ast.GeneratorExp, ast.comprehension, ast.BinOp, ast.UnaryOp, ast.BoolOp,
    ast.Compare, ast.Call, ast.Attribute, ast.Subscript, ast.Slice, ast.Starred, ast.IfExp,
    ast.Lambda, ast.Assert, ast.Try, ast.ExceptHandler, ast.Raise, ast.NamedExpr,
    # operators and contexts
    ast.operator, ast.unaryop, ast.boolop, ast.cmpop, ast.expr_context,
)

# Builtins and module names that give access to code, files, frames or the interpreter.
FORBIDDEN_NAMES = frozenset({
    "exec", "eval", "compile", "open", "getattr", "setattr", "delattr", "hasattr", "globals",
    "locals", "vars", "dir", "breakpoint", "input", "help", "memoryview", "type", "object",
    "super", "classmethod", "staticmethod", "property", "id", "exit", "quit", "copyright",
    "credits", "license", "bytearray", "issubclass", "aiter", "anext",
    "importlib", "builtins", "os", "sys", "subprocess", "socket", "ctypes", "signal",
})

# Attributes without an underscore that still lead to frames, code, globals, files or formatting.
FORBIDDEN_ATTRIBUTES = frozenset({
    "format", "format_map", "mro", "with_traceback",
    "gi_frame", "gi_code", "gi_yieldfrom", "gi_running", "gi_suspended",
    "cr_frame", "cr_code", "cr_await", "cr_origin", "ag_frame", "ag_code", "ag_await",
    "f_back", "f_globals", "f_locals", "f_builtins", "f_code", "f_trace", "f_lasti",
    "tb_frame", "tb_next", "co_code", "co_consts", "co_names",
    "func_globals", "func_code", "func_closure", "func_defaults", "im_func", "im_self",
    "im_class", "cell_contents",
    # numpy: file access and raw memory
    "tofile", "dump", "dumps", "ctypes", "load", "save", "savez", "savetxt", "loadtxt",
    "fromfile", "genfromtxt", "fromregex", "memmap", "lib", "ctypeslib", "testing", "f2py",
    "distutils", "compat", "source", "lookfor", "info", "show_config", "DataSource",
    # numpy: views over raw memory, strides, buffers and in-place reinterpretation
    "strides", "data", "base", "view", "getfield", "setfield", "setflags", "tobytes", "tostring",
    "frombuffer", "fromstring", "stride_tricks", "as_strided", "from_dlpack", "byte_bounds",
})
# ``dtype=`` values and ``astype`` arguments a program may write: numeric types only.
ALLOWED_DTYPE_NAMES = frozenset({"int", "float", "bool", "complex"})
ALLOWED_DTYPE_ATTRIBUTES = frozenset({
    "float16", "float32", "float64", "int8", "int16", "int32", "int64", "uint8", "uint16", "uint32",
    "uint64", "bool_", "complex64", "complex128",
})
ALLOWED_DTYPE_STRINGS = frozenset({
    "int", "float", "bool", "complex", "int8", "int16", "int32", "int64", "uint8", "uint16",
    "uint32", "uint64", "float16", "float32", "float64", "complex64", "complex128", "i1", "i2",
    "i4", "i8", "u1", "u2", "u4", "u8", "f2", "f4", "f8", "c8", "c16", "b1", "?", "i", "f", "d",
})
# Where a dtype may be passed by position: ``np`` functions (receiver ``np``) and the array
# methods of the same or other names. Index of the dtype among the positional arguments.
NP_DTYPE_POSITIONS = {
    "array": 1, "asarray": 1, "zeros": 1, "ones": 1, "full": 2, "zeros_like": 1, "ones_like": 1,
    "arange": 3, "linspace": 5, "eye": 3, "sum": 2, "prod": 2, "cumsum": 2, "mean": 2, "std": 2, "var": 2,
}
METHOD_DTYPE_POSITIONS = {
    "astype": 0, "sum": 1, "prod": 1, "cumsum": 1, "cumprod": 1, "mean": 1, "std": 1, "var": 1, "trace": 3,
}
# Names whose meaning the dtype checks rely on.
PROTECTED_NAMES = frozenset({"np", *ALLOWED_DTYPE_NAMES})
FORBIDDEN_ATTRIBUTE_PREFIXES = ("_", "gi_", "cr_", "ag_", "f_", "tb_", "co_", "func_", "im_")


class GuardError(ValueError):
    """The program uses something the sandbox does not allow (message says what and where)."""


def _where(node: ast.AST) -> str:
    line = getattr(node, "lineno", None)
    return f" (line {line})" if line else ""


def _check_name(name: str, node: ast.AST, binds: bool = False) -> None:
    if binds and name in PROTECTED_NAMES:
        # ``np.<name>`` must stay the restricted numpy, and a dtype written ``float`` a float.
        raise GuardError(f"the name {name!r} cannot be rebound{_where(node)}")
    if name != "_" and name.startswith("_"):
        raise GuardError(f"names starting with '_' are not allowed: {name!r}{_where(node)}")
    if name in FORBIDDEN_NAMES:
        raise GuardError(
            f"{name!r} is not available in robot programs{_where(node)}; "
            "use only the robot API, np and basic builtins (no imports, no introspection)"
        )


def _check_attribute(attr: str, node: ast.AST) -> None:
    if attr in FORBIDDEN_ATTRIBUTES or attr.startswith(FORBIDDEN_ATTRIBUTE_PREFIXES):
        raise GuardError(f"attribute {attr!r} is not allowed{_where(node)}")


def _is_np(node: ast.expr) -> bool:
    return isinstance(node, ast.Name) and node.id == "np"


def _rooted_at_np(node: ast.expr) -> bool:
    while isinstance(node, (ast.Attribute, ast.Subscript)):
        node = node.value
    return _is_np(node)


def _check_dtype(value: ast.expr, node: ast.AST) -> None:
    ok = (
        (isinstance(value, ast.Name) and value.id in ALLOWED_DTYPE_NAMES)
        or (isinstance(value, ast.Attribute) and _is_np(value.value) and value.attr in ALLOWED_DTYPE_ATTRIBUTES)
        or (isinstance(value, ast.Constant) and isinstance(value.value, str)
            and value.value.lstrip("<>=|") in ALLOWED_DTYPE_STRINGS)
        or (isinstance(value, ast.Constant) and value.value is None)
    )
    if not ok:
        raise GuardError(
            f"only numeric dtypes written literally (float, int, bool, np.float64, 'f8', ...) are "
            f"allowed{_where(node)}"
        )


def _dtype_position(func: ast.expr) -> int | None:
    """Where ``func`` (the callee) takes a dtype by position, or None."""
    if not isinstance(func, ast.Attribute):
        return None
    if _is_np(func.value):
        return NP_DTYPE_POSITIONS.get(func.attr)
    return METHOD_DTYPE_POSITIONS.get(func.attr)


def _check_call(node: ast.Call) -> None:
    for kw in node.keywords:
        if kw.arg == "dtype":
            _check_dtype(kw.value, node)
    position = _dtype_position(node.func)
    if position is None:
        return
    name = node.func.attr  # type: ignore[attr-defined]
    if any(isinstance(a, ast.Starred) for a in node.args) or any(kw.arg is None for kw in node.keywords):
        raise GuardError(f"arguments of {name}() must be written out, without * or ** unpacking{_where(node)}")
    if name == "astype" and not node.args and not any(kw.arg == "dtype" for kw in node.keywords):
        raise GuardError(f"astype needs a dtype{_where(node)}")
    if len(node.args) > position:
        _check_dtype(node.args[position], node)


def _check_method_reference(node: ast.Attribute, parent: ast.AST | None) -> None:
    """An array method that takes a dtype must be called where it is named: held in a variable
    or passed on, its dtype argument could no longer be checked."""
    if node.attr in METHOD_DTYPE_POSITIONS and not _is_np(node.value):
        if not (isinstance(parent, ast.Call) and parent.func is node):
            raise GuardError(f"the method {node.attr!r} may only be called directly{_where(node)}")


def check_program(source: str) -> ast.Module:
    """Parse ``source`` and refuse anything outside the allow-list; return the checked tree."""
    if not isinstance(source, str):
        raise GuardError(f"a program must be text, not {type(source).__name__}")
    if len(source) > MAX_PROGRAM_CHARS:
        raise GuardError(f"program too long ({len(source)} characters; limit {MAX_PROGRAM_CHARS})")
    try:
        tree = ast.parse(source, filename="<program>", mode="exec")
    except SyntaxError as e:
        raise GuardError(f"syntax error on line {e.lineno}: {e.msg}") from None
    except (ValueError, RecursionError, MemoryError) as e:  # null bytes, absurd nesting
        raise GuardError(f"program cannot be parsed: {type(e).__name__}") from None
    parents: dict[ast.AST, ast.AST] = {}
    for node in ast.walk(tree):
        for child in ast.iter_child_nodes(node):
            parents[child] = node
        if not isinstance(node, ALLOWED_NODES):
            kind = type(node).__name__
            hint = " (no imports: the robot API and np are already available)" if "Import" in kind else ""
            raise GuardError(f"{kind} statements/expressions are not allowed{hint}{_where(node)}")
        if isinstance(node, ast.Name):
            _check_name(node.id, node, binds=not isinstance(node.ctx, ast.Load))
        elif isinstance(node, ast.Attribute):
            _check_attribute(node.attr, node)
            _check_method_reference(node, parents.get(node))
            if not isinstance(node.ctx, ast.Load) and _rooted_at_np(node):
                raise GuardError(f"np's attributes cannot be changed{_where(node)}")
        elif isinstance(node, (ast.FunctionDef, ast.Lambda)):
            if isinstance(node, ast.FunctionDef):
                _check_name(node.name, node, binds=True)
            args = node.args
            for a in [*args.posonlyargs, *args.args, *args.kwonlyargs, args.vararg, args.kwarg]:
                if a is not None:
                    _check_name(a.arg, node, binds=True)
        elif isinstance(node, ast.comprehension) and node.is_async:
            raise GuardError(f"asynchronous comprehensions are not allowed{_where(node.target)}")
        elif isinstance(node, ast.Call):
            _check_call(node)
        elif isinstance(node, ast.keyword) and node.arg is not None:
            _check_name(node.arg, node)
        elif isinstance(node, ast.ExceptHandler) and node.name:
            _check_name(node.name, node, binds=True)
    return tree
