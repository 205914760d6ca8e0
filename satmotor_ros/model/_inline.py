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
is one ``return`` expression, neither name is rebound in the builder, each
parameter used more than once gets a plain name or constant (so nothing is
evaluated twice), and the globals that expression reads are the same objects
in the builder's module. Tracebacks still point at the builder's lines.
"""

from __future__ import annotations

import ast
import copy
import functools
import inspect
import sys
import textwrap
from typing import Any, Callable, cast, TypeVar

Builder = TypeVar('Builder', bound=Callable[..., Any])


def _parse(func: Callable[..., Any]) -> ast.FunctionDef | None:
    """Return the syntax tree of a function defined in a source file, or None."""
    try:
        node = ast.parse(textwrap.dedent(inspect.getsource(func))).body[0]
    except (OSError, TypeError, SyntaxError):  # no source, or a lambda inside an expression
        return None
    return node if isinstance(node, ast.FunctionDef) else None


@functools.lru_cache(maxsize=None)
def _expression(func: Callable[..., Any]) -> tuple[tuple[str, ...], ast.expr] | None:
    """Return the parameters and the return expression of a one-expression function."""
    node = _parse(func)
    if node is None or node.args.vararg or node.args.kwarg or node.args.kwonlyargs:
        return None
    if node.args.defaults or node.args.posonlyargs:
        return None
    body = [s for s in node.body
            if not (isinstance(s, ast.Expr) and isinstance(s.value, ast.Constant))]
    if len(body) != 1 or not isinstance(body[0], ast.Return) or body[0].value is None:
        return None
    return tuple(a.arg for a in node.args.args), body[0].value


class _Substitute(ast.NodeTransformer):
    """Replace the parameters' names by the call's arguments."""

    def __init__(self, values: dict[str, ast.expr]) -> None:
        self.values = values

    def visit_Name(self, node: ast.Name) -> ast.expr:  # noqa: N802 (ast's name)
        if node.id in self.values:
            return copy.deepcopy(self.values[node.id])
        return node


class _Inliner(ast.NodeTransformer):
    """Inline the calls of one-expression functions of the builder's module."""

    def __init__(self, namespace: dict[str, Any], rebound: set[str]) -> None:
        self.namespace, self.rebound = namespace, rebound

    def _callee(self, func: ast.expr) -> Callable[..., Any] | None:
        """Return the function a call's ``name`` or ``module.name`` refers to, or None."""
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
        for name in set(names) - set(params):
            if callee.__globals__.get(name, self) is not self.namespace.get(name, None):
                return node  # it reads a global the builder's module does not share
        values = dict(zip(params, node.args))
        for param, value in values.items():
            if names.count(param) > 1 and not isinstance(value, (ast.Name, ast.Constant)):
                return node  # the argument would be evaluated more than once
        inlined = _Substitute(values).visit(copy.deepcopy(expr))
        return ast.copy_location(inlined, node)


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
    node = _parse(builder)
    if node is None:
        return builder
    node.decorator_list = []
    rebound = {n.id for n in ast.walk(node)
               if isinstance(n, ast.Name) and not isinstance(n.ctx, ast.Load)}
    rebound |= {a.arg for n in ast.walk(node) if isinstance(n, ast.arguments)
                for a in (*n.posonlyargs, *n.args, *n.kwonlyargs)}
    module = sys.modules[builder.__module__]
    tree = ast.Module(body=[_Inliner(vars(module), rebound).visit(node)], type_ignores=[])
    ast.increment_lineno(tree, builder.__code__.co_firstlineno - 1)
    ast.fix_missing_locations(tree)
    namespace: dict[str, Any] = {}
    code = compile(tree, inspect.getsourcefile(builder) or '<inlined>', 'exec',
                   flags=annotations.compiler_flag, dont_inherit=True)  # as this module's
    exec(code, vars(module), namespace)  # noqa: S102 (our own source, recompiled)
    return cast(Builder, functools.wraps(builder)(namespace[builder.__name__]))
