# SPDX-License-Identifier: Apache-2.0
"""No import cycles: the import graph of a package, lazy imports in functions included."""

import ast
from pathlib import Path

import pytest

import satmotor_ros

ROOT = Path(satmotor_ros.__file__).parent


def _module_name(path: Path) -> str:
    parts = path.relative_to(ROOT.parent).with_suffix('').parts
    return '.'.join(parts[:-1] if parts[-1] == '__init__' else parts)


def _imported(node: ast.AST, module: str, is_package: bool) -> list[str]:
    if isinstance(node, ast.Import):
        return [alias.name for alias in node.names]
    if not isinstance(node, ast.ImportFrom):
        return []
    base = module if is_package else module.rpartition('.')[0]
    for _ in range(node.level - 1):
        base = base.rpartition('.')[0]
    source = node.module or ''
    if node.level:
        source = f'{base}.{source}' if source else base
    # `from package import name` imports the submodule package.name when there is one.
    return [source] + [f'{source}.{alias.name}' for alias in node.names]


def _is_type_checking(test: ast.expr) -> bool:
    return (isinstance(test, ast.Name) and test.id == 'TYPE_CHECKING'
            or isinstance(test, ast.Attribute) and test.attr == 'TYPE_CHECKING')


def _runtime_nodes(tree: ast.AST) -> list[ast.AST]:
    """Return every node of `tree` that can run: not under ``if TYPE_CHECKING:``."""
    found, todo = [], [tree]
    while todo:
        node = todo.pop()
        found.append(node)
        if isinstance(node, ast.If) and _is_type_checking(node.test):
            todo.extend(node.orelse)
        else:
            todo.extend(ast.iter_child_nodes(node))
    return found


def import_graph(package: str) -> dict[str, set[str]]:
    """
    Map each module of `package` to the modules of `package` it imports anywhere in its body.

    Imports under ``if TYPE_CHECKING:`` never run and are left out.

    Parameters
    ----------
    package : str
        Dotted name of a subpackage of satmotor_ros (or satmotor_ros itself), [-]

    Returns
    -------
    dict of str to set of str
        Module -> imported modules, both inside `package`; a package's ``__init__`` is
        not counted as imported by its own submodules.

    """
    directory = ROOT.parent.joinpath(*package.split('.'))
    files = {_module_name(path): path for path in directory.rglob('*.py')}
    graph: dict[str, set[str]] = {}
    for module, path in files.items():
        is_package = path.name == '__init__.py'
        targets: set[str] = set()
        for node in _runtime_nodes(ast.parse(path.read_text(encoding='utf-8'))):
            targets.update(t for t in _imported(node, module, is_package) if t in files)
        # Importing a.b.c runs a and a.b first; that parent edge is no cycle of the code.
        graph[module] = {t for t in targets if t != module and not module.startswith(t + '.')}
    return graph


def cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """
    Find the strongly connected components of more than one module (Tarjan).

    Parameters
    ----------
    graph : dict of str to set of str
        Module -> imported modules, [-]

    Returns
    -------
    list of list of str
        Each cycle's modules, sorted.

    """
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    found: list[list[str]] = []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        for w in graph[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                found.append(sorted(component))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return found


def test_the_cycle_finder_sees_a_cycle_through_a_lazy_import():
    graph = {'a': {'b'}, 'b': {'c'}, 'c': {'a'}, 'd': {'a'}}
    assert cycles(graph) == [['a', 'b', 'c']]
    assert cycles({'a': {'b'}, 'b': set()}) == []


def test_the_graph_leaves_out_imports_only_for_type_checking():
    tree = ast.parse('from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n    import a\n'
                     'else:\n    import b\ndef f():\n    import c\n')
    names = {alias.name for node in _runtime_nodes(tree) if isinstance(node, ast.Import)
             for alias in node.names}
    assert names == {'b', 'c'}


def test_the_graph_counts_imports_inside_functions():
    graph = import_graph('satmotor_ros.cli')
    assert 'satmotor_ros.cli._demo_ros' in graph['satmotor_ros.cli.demo']


@pytest.mark.parametrize('package', ['satmotor_ros.cli', 'satmotor_ros.model'])
def test_package_has_no_import_cycle(package):
    assert cycles(import_graph(package)) == []
