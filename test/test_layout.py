# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""The layout shows the architecture: pure libraries without rclpy, thin nodes, short functions."""

from __future__ import annotations

import ast
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[1] / 'vib_estimator'
#: subpackages that hold no ROS code: they are tested alone and usable without a ROS install
PURE = ('core', 'io', 'sim', 'analysis', 'control')
#: the only modules at the top of the package (errors: the library's exceptions, imported by all;
#: extras: the optional packages' import and fallback, used by io, core and analysis alike)
TOP = {'__init__.py', 'cli.py', 'errors.py', 'extras.py'}
#: no function longer than this (lines, decorators excluded)
MAX_FUNCTION_LINES = 80
#: ROS packages a pure module must not import: every ROS package package.xml runs on (its
#: python3-* keys are the plain Python libraries)
ROS_MODULES = {
    e.text
    for e in ET.parse(PACKAGE.parent / 'package.xml').getroot()
    if e.tag in ('exec_depend', 'depend') and not e.text.startswith('python3-')
}


def _modules():
    return sorted(PACKAGE.rglob('*.py'))


def _imports(tree):
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            yield from (a.name.split('.')[0] for a in node.names)
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            yield node.module.split('.')[0]


def test_top_of_the_package_holds_only_the_entry_points():
    assert {p.name for p in PACKAGE.glob('*.py')} == TOP
    for sub in PACKAGE.iterdir():
        if sub.is_dir() and sub.name != '__pycache__':
            assert (sub / '__init__.py').exists(), f'{sub.name}/ is not a package'


@pytest.mark.parametrize('sub', PURE)
def test_pure_subpackages_import_no_ros(sub):
    folder = PACKAGE / sub
    assert (folder / '__init__.py').exists(), f'{sub}/ is missing'
    for path in folder.rglob('*.py'):
        ros = set(_imports(ast.parse(path.read_text()))) & ROS_MODULES
        assert not ros, f'{path.relative_to(PACKAGE)} imports {sorted(ros)}'


def test_no_function_is_longer_than_the_limit():
    long = []
    for path in _modules():
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                lines = node.end_lineno - node.lineno + 1
                if lines > MAX_FUNCTION_LINES:
                    long.append(
                        f'{path.relative_to(PACKAGE)}:{node.lineno} {node.name} ({lines} lines)'
                    )
    assert not long, 'functions longer than {} lines: {}'.format(MAX_FUNCTION_LINES, long)


def test_tests_mirror_the_package():
    tests = Path(__file__).resolve().parent
    for sub in PACKAGE.iterdir():
        if sub.is_dir() and sub.name != '__pycache__' and any(sub.glob('[!_]*.py')):
            assert (tests / sub.name).is_dir(), f'test/{sub.name}/ missing for {sub.name}/'
