# SPDX-License-Identifier: Apache-2.0
"""
Inline the equation functions into the compositions that call them, once at import.

Each paper equation is one function of plain arithmetic (:mod:`.losses`,
:mod:`.speed`), and :mod:`.composition` composes them. On a Python float a
function call costs as much as the arithmetic inside it, and a single point
makes dozens. :func:`inline_equations` recompiles a composition builder with
every call of such a function replaced by the function's own return
expression, its parameters bound to the call's arguments: the same operations
in the same order (bitwise the same result, on floats and on arrays), with no
second copy of any equation in the source. A call is left as it is unless the
callee, named as ``function`` or ``module.function``, is a function whose body
is one ``return`` expression, neither name is bound anywhere in the builder,
each parameter never used gets a plain name or constant (nothing that could
fail is skipped), each used more than once gets one, or arithmetic without
calls that is then bound where the expression first reads it, ``(p := ...)``,
if nothing in the expression is evaluated conditionally (nothing is evaluated
twice or out of order), and the globals that expression reads are the same
objects in the builder's module (or builtins) and are not names the builder
binds (upper-case numbers, units, are put in as their values). A body of
``x = ...`` lines before the ``return`` folds in as ``(x := ...)`` where x is
first read, if nothing in it is evaluated conditionally (``x: T = ...; return x``, a typed
temporary, is its expression); each inlined call
gets its own name for x, so calls nested in each other's arguments do not
share it, and the calls an inlined expression makes are inlined in turn. A
traceback points at the builder's line of the call.

:func:`inline_per_class` compiles a builder once per class of one argument,
and inlines that argument's static methods as well: how a composition reads a
displacement law's equations in place (:mod:`.laws`).
"""

from __future__ import annotations

import ast
import builtins
import copy
import functools
import inspect
import numbers
import sys
from typing import Any, Callable, cast, TypeVar

Builder = TypeVar('Builder', bound=Callable[..., Any])


@functools.lru_cache(maxsize=None)
def _definitions(filename: str) -> dict[int, ast.FunctionDef]:
    """Return the function definitions of a source file by first line (a decorator's, if any)."""
    with open(filename, encoding='utf-8') as source:
        tree = ast.parse(source.read(), filename)
    return {min([n.lineno, *(d.lineno for d in n.decorator_list)]): n
            for n in ast.walk(tree) if isinstance(n, ast.FunctionDef)}


def _parse(func: Callable[..., Any]) -> ast.FunctionDef | None:
    """Return a copy of the syntax tree of a function defined in a source file, or None."""
    code = getattr(func, '__code__', None)
    try:
        filename = inspect.getsourcefile(func)
        node = _definitions(filename).get(code.co_firstlineno) if filename and code else None
    except (OSError, TypeError, SyntaxError, UnicodeDecodeError):  # no source to read
        return None
    return copy.deepcopy(node) if node is not None and node.name == func.__name__ else None


_STRAIGHT = (ast.BinOp, ast.UnaryOp, ast.Name, ast.Constant, ast.Attribute, ast.Call,
             ast.Tuple, ast.NamedExpr, ast.expr_context, ast.operator, ast.unaryop, ast.cmpop)
"""Nodes whose operands Python evaluates unconditionally, in field order."""


def _straight(node: ast.AST) -> bool:
    """Whether Python evaluates every operand of `node` unconditionally (one comparison, too)."""
    return isinstance(node, _STRAIGHT) or isinstance(node, ast.Compare) and len(node.ops) == 1


def _first_use(expr: ast.AST, name: str) -> ast.Name | None:
    """Return the `name` that `expr` reads first (depth first, in field order), or None."""
    for node in ast.iter_child_nodes(expr):
        if isinstance(node, ast.Name) and node.id == name:
            return node
        found = _first_use(node, name)
        if found is not None:
            return found
    return None


class _Bind(ast.NodeTransformer):
    """Fold ``name = value`` into an expression: ``(local := value)`` where it is read first."""

    def __init__(self, name: str, value: ast.expr, local: str, first: ast.Name) -> None:
        self.name, self.value, self.local, self.first = name, value, local, first

    def visit_Name(self, node: ast.Name) -> ast.expr:  # noqa: N802 (ast's name)
        if node.id != self.name:
            return node
        if node is self.first:
            return ast.NamedExpr(ast.Name(self.local, ast.Store()), self.value)
        return ast.Name(self.local, ast.Load())


def _bind(expr: ast.expr, name: str, value: ast.expr, local: str) -> ast.expr | None:
    """Return `expr` with ``name = value`` folded in, or None where the order is not plain."""
    first = _first_use(expr, name)
    if first is None or not all(_straight(n) for n in ast.walk(expr)):
        return None
    folded: ast.expr = _Bind(name, value, local, first).visit(expr)
    return folded


def _assigned(statement: ast.stmt) -> tuple[str, ast.expr] | None:
    """Return the name and value of ``x = e`` or ``x: T = e`` (a typed temporary), or None."""
    if isinstance(statement, ast.Assign) and len(statement.targets) == 1:
        target, value = statement.targets[0], statement.value
    elif isinstance(statement, ast.AnnAssign) and statement.value is not None:
        target, value = statement.target, statement.value
    else:
        return None
    return (target.id, value) if isinstance(target, ast.Name) else None


@functools.lru_cache(maxsize=None)
def _expression(func: Callable[..., Any]) -> tuple[tuple[str, ...], ast.expr] | None:
    """Return the parameters and the return expression of a function of plain expressions."""
    node = _parse(func)
    if node is None or node.args.vararg or node.args.kwarg or node.args.kwonlyargs:
        return None
    if node.args.defaults or node.args.posonlyargs:
        return None
    body = [s for s in node.body
            if not (isinstance(s, ast.Expr) and isinstance(s.value, ast.Constant))]
    if not isinstance(body[-1], ast.Return) or body[-1].value is None:
        return None
    expr: ast.expr | None = body[-1].value
    for statement in reversed(body[:-1]):  # x = e; return f(x)  ->  f((x' := e))
        target = _assigned(statement)
        if target is None or expr is None:
            return None
        name, value = target
        if isinstance(expr, ast.Name) and expr.id == name:  # x: T = e; return x  ->  e
            expr = value
        else:
            expr = _bind(expr, name, value, f'_{func.__name__}_{name}')
    return None if expr is None else (tuple(a.arg for a in node.args.args), expr)


class _Substitute(ast.NodeTransformer):
    """Replace the parameters' names by the call's arguments."""

    def __init__(self, values: dict[str, ast.expr]) -> None:
        self.values = values

    def visit_Name(self, node: ast.Name) -> ast.expr:  # noqa: N802 (ast's name)
        if node.id in self.values:
            return copy.deepcopy(self.values[node.id])
        return node


class _Rename(ast.NodeTransformer):
    """Rename names: an inlined call's own ``x := ...`` locals."""

    def __init__(self, names: dict[str, str]) -> None:
        self.names = names

    def visit_Name(self, node: ast.Name) -> ast.expr:  # noqa: N802 (ast's name)
        return ast.Name(self.names.get(node.id, node.id), node.ctx)


def _bound(tree: ast.AST) -> set[str]:
    """Return every name a function binds anywhere in it: its locals and its closures' locals."""
    bound = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Name) and not isinstance(node.ctx, ast.Load):
            bound.add(node.id)
        elif isinstance(node, ast.arg):
            bound.add(node.arg)
        elif isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            bound.add(node.name)
        elif isinstance(node, ast.alias):
            bound.add(node.asname or node.name.partition('.')[0])
        elif isinstance(node, (ast.ExceptHandler, ast.MatchAs, ast.MatchStar)) and node.name:
            bound.add(node.name)
        elif isinstance(node, ast.MatchMapping) and node.rest:
            bound.add(node.rest)
    return bound


class _Inliner(ast.NodeTransformer):
    """Inline the calls of one-expression functions of the builder's module."""

    def __init__(self, namespace: dict[str, Any], rebound: set[str],
                 classes: dict[str, type]) -> None:
        self.namespace, self.rebound, self.classes = namespace, rebound, classes
        self.sites = 0  # inlined calls so far: numbers their ``x := ...`` locals

    def _callee(self, func: ast.expr) -> Callable[..., Any] | None:
        """Return the function a call's ``name``, ``module.name`` or ``cls.static`` is, or None."""
        if (isinstance(func, ast.Attribute) and isinstance(func.value, ast.Name)
                and func.value.id in self.classes):
            static = inspect.getattr_static(self.classes[func.value.id], func.attr, None)
            return static.__func__ if isinstance(static, staticmethod) else None
        if isinstance(func, ast.Attribute) and isinstance(func.value, ast.Name):
            module = None if func.value.id in self.rebound else self.namespace.get(func.value.id)
            found = getattr(module, func.attr, None) if inspect.ismodule(module) else None
        elif isinstance(func, ast.Name) and func.id not in self.rebound:
            found = self.namespace.get(func.id)
        else:
            return None
        return found if inspect.isfunction(found) else None

    def visit_Call(self, node: ast.Call) -> ast.expr:  # noqa: N802 (ast's name)
        self.generic_visit(node)
        callee = self._callee(node.func)
        if callee is None or node.keywords:
            return node
        found = _expression(callee)
        if found is None or len(found[0]) != len(node.args):
            return node
        params, expr = found
        names = [n.id for n in ast.walk(expr) if isinstance(n, ast.Name)]
        values = dict(zip(params, node.args))
        local = {n.target.id for n in ast.walk(expr) if isinstance(n, ast.NamedExpr)
                 and isinstance(n.target, ast.Name)}
        for name in set(names) - set(params) - local:
            value = callee.__globals__.get(name, vars(builtins).get(name, self))
            if name.isupper() and (type(value) is float or isinstance(value, numbers.Integral)):
                number = value if type(value) is float else int(value)  # a flag: a uint8
                values[name] = ast.Constant(number)  # a unit or constant: its value
            elif value is not self.namespace.get(name, vars(builtins).get(name)) or (
                    name in self.rebound):
                return node  # the builder's module, or the builder itself, has another `name`
        twice = {}  # parameters read more than once, bound where first read: (p := argument)
        for param, value in values.items():
            if names.count(param) != 1 and not isinstance(value, (ast.Name, ast.Constant)):
                if not names.count(param) or any(isinstance(n, ast.Call) for n in ast.walk(
                        value)) or not all(_straight(n) for n in ast.walk(expr)):
                    return node  # the argument would be evaluated never, or out of order
                twice[param] = value
        self.sites += 1
        renamed = {name: self._unbound(f'{name}_{self.sites}') for name in local | set(twice)}
        inlined: ast.expr | None = _Substitute(
            {p: v for p, v in values.items() if p not in twice}).visit(
                _Rename(renamed).visit(copy.deepcopy(expr)))
        for param, value in twice.items():
            inlined = _bind(inlined, renamed[param], value, renamed[param]) if inlined else None
        if inlined is None:
            return node
        for part in ast.walk(inlined):  # the equation's lines are not the builder's: the call's
            if isinstance(part, ast.expr):
                ast.copy_location(part, node)
        result: ast.expr = self.visit(inlined)  # the calls the expression itself makes
        return result

    def _unbound(self, name: str) -> str:
        """Return `name`, or `name` with underscores appended, free in the builder and module."""
        while name in self.rebound or name in self.namespace:
            name += '_'
        return name


def _tests(node: ast.expr) -> bool:
    """Whether `node` is a comparison, or ``|`` of comparisons: a bool on Python floats."""
    if isinstance(node, ast.BinOp) and isinstance(node.op, ast.BitOr):
        return _tests(node.left) and _tests(node.right)
    return isinstance(node, ast.Compare) or isinstance(node, ast.BoolOp) and isinstance(
        node.op, ast.Or)


class _OnFloats(ast.NodeTransformer):
    """
    Write a rule's tests as Python does on floats: the same values, fewer operations.

    ``|`` of comparisons becomes ``or`` (the later tests skipped), and a test times a flag,
    ``(x < 0.0) * 2``, becomes ``(2 if x < 0.0 else 0)``.
    """

    def visit_BinOp(self, node: ast.BinOp) -> ast.expr:  # noqa: N802 (ast's name)
        self.generic_visit(node)
        if _tests(node):
            return ast.copy_location(ast.BoolOp(ast.Or(), [node.left, node.right]), node)
        if (isinstance(node.op, ast.Mult) and _tests(node.left)
                and isinstance(node.right, ast.Constant) and type(node.right.value) is int):
            return ast.copy_location(ast.IfExp(node.left, node.right, ast.Constant(0)), node)
        return node


def _compile(builder: Builder, classes: dict[str, type], floats: bool = False) -> Builder:
    """
    Return `builder` recompiled with its calls inlined; `classes`: arguments' types by name.

    With `floats`, the builder runs on Python floats only, and the rules it inlines (written
    for floats and arrays alike, ``(a < b) | (c < d)``) test as Python does on floats.
    """
    node = _parse(builder)
    if node is None:
        return builder
    node.decorator_list = []
    module = sys.modules[builder.__module__]
    inliner = _Inliner(vars(module), _bound(node), classes)
    inlined = inliner.visit(node)
    tree = ast.Module(body=[_OnFloats().visit(inlined) if floats else inlined], type_ignores=[])
    ast.fix_missing_locations(tree)
    namespace: dict[str, Any] = {}
    code = compile(tree, inspect.getsourcefile(builder) or '<inlined>', 'exec',
                   flags=annotations.compiler_flag, dont_inherit=True)  # as this module's
    exec(code, vars(module), namespace)  # noqa: S102 (our own source, recompiled)
    return cast(Builder, functools.wraps(builder)(namespace[builder.__name__]))


def inline_equations(builder: Builder) -> Builder:
    """
    Return a function builder recompiled with its equation calls inlined (see the module).

    Parameters
    ----------
    builder : callable
        A module-level function that builds and returns the compositions, [-]

    Returns
    -------
    callable
        The same builder, compiled from the inlined tree; `builder` itself where
        its source is not available.

    """
    return _compile(builder, {})


def inline_on_floats(builder: Builder) -> Builder:
    """
    Return a function of Python floats recompiled with its equation and rule calls inlined.

    As :func:`inline_equations`, and ``|`` of comparisons (how a rule written for floats and
    arrays alike combines its tests) becomes ``or``, which on floats gives the same bool and
    skips the tests after the first true one: the single-point path's form of the rules.

    Parameters
    ----------
    builder : callable
        A function or method that runs on Python floats only, [-]

    Returns
    -------
    callable
        The function, compiled from the inlined tree.

    """
    return _compile(builder, {}, floats=True)


def inline_per_class(argument: str) -> Callable[[Builder], Builder]:
    """
    Return a decorator that inlines a builder once per class of one of its arguments.

    Besides what :func:`inline_equations` inlines, a call ``argument.name(...)``
    of a static method of that argument's class is inlined too (and the calls its
    expression makes), so that a composition reads a displacement law's equations
    in place. The builder is compiled the first time it meets a class; objects
    of another class get their own compilation.

    Parameters
    ----------
    argument : str
        Name of the builder's argument whose class is specialised on, [-]

    Returns
    -------
    callable
        The decorator; its result calls the compilation for ``type(argument)``.

    """
    def decorate(builder: Builder) -> Builder:
        position = inspect.getfullargspec(builder).args.index(argument)
        compiled: dict[type, Builder] = {}

        @functools.wraps(builder)
        def specialised(*args: Any) -> Any:
            kind = type(args[position])
            func = compiled.get(kind)
            if func is None:
                func = compiled[kind] = _compile(builder, {argument: kind})
            return func(*args)
        return cast(Builder, specialised)
    return decorate
