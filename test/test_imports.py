# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""The package's import graph: no cycle, none hidden by imports inside functions, and no private
name imported from another module of the package."""

from __future__ import annotations

import ast
from pathlib import Path
from typing import Dict, List, Set, Tuple

PACKAGE = Path(__file__).resolve().parents[1] / 'vib_estimator'
NAME = PACKAGE.name


def _modules() -> Dict[str, Path]:
    found = {}
    for path in PACKAGE.rglob('*.py'):
        parts = list(path.relative_to(PACKAGE.parent).with_suffix('').parts)
        if parts[-1] == '__init__':
            parts.pop()
        found['.'.join(parts)] = path
    return found


MODULES = _modules()


def _resolve(module: str, node: ast.ImportFrom) -> str:
    if not node.level:
        return node.module or ''
    base = module.split('.')
    is_package = MODULES[module].name == '__init__.py'
    base = base[: len(base) - node.level + (1 if is_package else 0)]
    return '.'.join(base + ([node.module] if node.module else []))


def _imports(module: str, top_level_only: bool) -> List[Tuple[str, str]]:
    """``(imported module, name or '')`` of every import of a package module in ``module``."""
    tree = ast.parse(MODULES[module].read_text())
    nodes = tree.body if top_level_only else list(ast.walk(tree))
    result = []
    for node in nodes:
        if isinstance(node, ast.Import):
            result.extend((a.name, '') for a in node.names if a.name.split('.')[0] == NAME)
        elif isinstance(node, ast.ImportFrom):
            target = _resolve(module, node)
            if target.split('.')[0] != NAME:
                continue
            for alias in node.names:
                sub = f'{target}.{alias.name}'
                result.append((sub, '') if sub in MODULES else (target, alias.name))
    return result


def _graph(top_level_only: bool) -> Dict[str, Set[str]]:
    graph = {}
    for module in MODULES:
        graph[module] = {
            m
            for m, _ in _imports(module, top_level_only)
            if m in MODULES and m != module and not module.startswith(m + '.')
        }  # a package's own __init__
    return graph


def _cycle(graph: Dict[str, Set[str]]) -> List[str]:
    """One cycle of ``graph`` as a list of modules, or []."""
    state: Dict[str, int] = {}
    stack: List[str] = []

    def visit(node: str) -> List[str]:
        state[node] = 1
        stack.append(node)
        for nxt in sorted(graph[node]):
            if state.get(nxt) == 1:
                return stack[stack.index(nxt) :] + [nxt]
            if nxt not in state:
                found = visit(nxt)
                if found:
                    return found
        stack.pop()
        state[node] = 2
        return []

    for node in sorted(graph):
        if node not in state:
            found = visit(node)
            if found:
                return found
    return []


def test_the_walker_finds_a_cycle():
    assert _cycle({'a': {'b'}, 'b': {'c'}, 'c': {'a'}}) == ['a', 'b', 'c', 'a']
    assert _cycle({'a': {'b'}, 'b': set(), 'c': {'a', 'b'}}) == []
    assert 'vib_estimator.io.bags' in _graph(True)['vib_estimator.io.streaming']


def test_no_import_cycle_at_module_level():
    assert _cycle(_graph(top_level_only=True)) == []


def test_no_cycle_even_through_imports_inside_functions():
    """The old ``bags <-> streaming <-> csv_reader`` cycle was held apart by imports inside
    functions: counted, the graph has no cycle either; and io/ imports nothing of the package
    inside a function."""
    assert _cycle(_graph(top_level_only=False)) == []
    io = sorted(m for m in MODULES if m.startswith(f'{NAME}.io'))
    late = {m: sorted(set(_imports(m, False)) - set(_imports(m, True))) for m in io}
    assert {m: v for m, v in late.items() if v} == {}


#: private names still imported across modules: core/ is restructured by another change (issue 23)
KNOWN_PRIVATE = set()


def test_no_private_name_is_imported_from_another_module():
    private = {
        (m, f'{target}.{name}')
        for m in MODULES
        for target, name in _imports(m, False)
        if name.startswith('_')
    }
    assert private - KNOWN_PRIVATE == set()


def _constants(module: str) -> Set[str]:
    """The upper-case constants ``module`` assigns at top level (leading ``_`` dropped)."""
    names = set()
    for node in ast.parse(MODULES[module].read_text()).body:
        targets = (
            node.targets
            if isinstance(node, ast.Assign)
            else ([node.target] if isinstance(node, ast.AnnAssign) else [])
        )
        for target in targets:
            elts = target.elts if isinstance(target, ast.Tuple) else [target]
            names.update(e.id.lstrip('_') for e in elts if isinstance(e, ast.Name))
    return {n for n in names if n.replace('_', '').isupper()}


def _defined_in(modules) -> Dict[str, List[str]]:
    where: Dict[str, List[str]] = {}
    for module in modules:
        for name in _constants(module):
            where.setdefault(name, []).append(module)
    return where


def test_constants_are_defined_once():
    """The MCAP magic and opcodes, message type names, axes, 2 pi, the diagnostics period: one
    definition each (issue 23); and no constant is defined in two io/ modules."""
    where = _defined_in(MODULES)
    for name in (
        'MAGIC',
        'OP_CHUNK',
        'OP_CHANNEL',
        'WRENCH_STAMPED',
        'XYZ',
        'TWO_PI',
        'DIAGNOSTICS_PERIOD',
    ):
        assert len(where.get(name, [])) == 1, (name, where.get(name))
    io = _defined_in(m for m in MODULES if m.startswith(f'{NAME}.io'))
    assert {n: m for n, m in io.items() if len(m) > 1} == {}


def test_the_exceptions_module_is_a_leaf_that_every_reader_uses():
    """errors.py imports nothing of the package (so anything can import it) and holds every
    exception class of the library, the nodes' ``StartupError`` included."""
    assert _graph(top_level_only=False)[f'{NAME}.errors'] == set()
    classes = {}
    for module, path in MODULES.items():
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.ClassDef) and any(
                getattr(b, 'id', getattr(b, 'attr', '')).endswith(('Error', 'Exception'))
                for b in node.bases
            ):
                classes[node.name] = module
    outside = {n: m for n, m in classes.items() if m != f'{NAME}.errors'}
    assert outside == {}
