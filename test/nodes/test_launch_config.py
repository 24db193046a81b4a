# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""config/estimator.yaml and launch/estimator.launch.py, checked without launch_ros.

The params file must hold EstimatorConfig's defaults (Section 5.3), load through rcl's own parser
into the node, and be what the launch file starts ``estimator_node`` with.
"""

from __future__ import annotations

import ast
import os
from pathlib import Path

import rclpy
import yaml

from vib_estimator.core import EstimatorConfig
from vib_estimator.core.config import PAPER
from vib_estimator.io.align import ALIGN_TOLERANCE_S
from vib_estimator.io.fields import DEFAULT_COMPONENT, INPUT_TYPES, WRENCH_STAMPED
from vib_estimator.nodes.baseline_monitor import DEFAULT_WINDOW_S
from vib_estimator.nodes.estimator_node import EstimatorNode
from vib_estimator.nodes.mode_markers import DEFAULTS as MODE_SHAPES
from vib_estimator.nodes.parameters import config_of

ROOT = Path(__file__).resolve().parents[2]
PARAMS = ROOT / 'config' / 'estimator.yaml'
LAUNCH = ROOT / 'launch' / 'estimator.launch.py'


def test_params_file_holds_the_defaults():
    params = yaml.safe_load(PARAMS.read_text())['/**']['ros__parameters']
    assert params.pop('input_type') == WRENCH_STAMPED
    assert params.pop('input_topic') == 'coupling_torque'
    assert params.pop('component') == DEFAULT_COMPONENT[WRENCH_STAMPED]
    assert params.pop('components') == []
    assert params.pop('input_topics') == []
    assert params.pop('sync_tolerance_s') == ALIGN_TOLERANCE_S
    for name, default in MODE_SHAPES.items():  # vibration/mode_shapes (nodes/mode_shapes.py)
        assert params.pop(name) == default, name
    assert params.pop('baseline_file') == params.pop('covariate_topics') == ''
    assert params.pop('health_window_s') == DEFAULT_WINDOW_S
    assert params.pop('decide_excitation') is True  # the node's own choice (estimator_node)
    defaults = EstimatorConfig()
    assert set(params) == set(EstimatorConfig.names())
    for name, value in params.items():
        default = getattr(defaults, name)
        expected = (
            [] if default is None else list(default) if isinstance(default, tuple) else default
        )
        assert value == expected and type(value) is type(expected), (name, value, expected)


def test_paper_params_file_holds_the_paper_configuration():
    params = yaml.safe_load((ROOT / 'config' / 'paper.yaml').read_text())['/**']['ros__parameters']
    assert params == PAPER
    assert EstimatorConfig().replace(**params) == EstimatorConfig.paper()


def test_params_file_loads_into_the_node():
    context = rclpy.Context()
    rclpy.init(
        context=context,
        domain_id=int(os.environ['ROS_DOMAIN_ID']),
        args=['--ros-args', '--params-file', str(PARAMS)],
    )
    try:
        node = EstimatorNode(context=context)
        assert config_of(node) == EstimatorConfig()  # every parameter as the file sets it
        assert node.get_parameter('band_hz').value == []
        assert node.get_parameter('components').value == []
        assert node.get_parameter('input_type').value == WRENCH_STAMPED
        node.destroy_node()
    finally:
        context.try_shutdown()


def test_every_core_parameter_has_a_description_and_numbers_a_range(ros_context):
    node = EstimatorNode(context=ros_context)
    try:
        names = EstimatorConfig.names()
        for name, descriptor in zip(names, node.describe_parameters(names)):
            assert descriptor.description, name
            default = getattr(EstimatorConfig(), name)
            if isinstance(default, (int, float)) and not isinstance(default, bool):
                assert descriptor.integer_range or descriptor.floating_point_range, name
    finally:
        node.destroy_node()


def test_params_file_comments_name_every_input_type():
    text = PARAMS.read_text()
    assert all(name in text for name in INPUT_TYPES)


def test_launch_file_starts_the_node_with_the_params_file():
    tree = ast.parse(LAUNCH.read_text())
    functions = [n.name for n in tree.body if isinstance(n, ast.FunctionDef)]
    assert 'generate_launch_description' in functions
    nodes = [
        n
        for n in ast.walk(tree)
        if isinstance(n, ast.Call)
        and getattr(n.func, 'id', getattr(n.func, 'attr', None)) == 'Node'
    ]
    assert len(nodes) == 1
    keywords = {k.arg: k.value for k in nodes[0].keywords}
    assert ast.literal_eval(keywords['package']) == 'vib_estimator'
    assert ast.literal_eval(keywords['executable']) == 'estimator_node'
    assert isinstance(keywords['parameters'], ast.List)
    strings = {n.value for n in ast.walk(tree) if isinstance(n, ast.Constant)}
    assert {'vib_estimator', 'config', PARAMS.name} <= strings
    assert PARAMS.is_file()


def test_launch_file_declares_the_arguments_a_deployment_needs():
    """params_file, namespace, use_sim_time and the input, each declared and each used."""
    tree = ast.parse(LAUNCH.read_text())
    calls = [n for n in ast.walk(tree) if isinstance(n, ast.Call)]
    declared = {
        ast.literal_eval(n.args[0])
        for n in calls
        if getattr(n.func, 'id', None) == 'DeclareLaunchArgument'
    }
    assert declared == {'params_file', 'namespace', 'use_sim_time', 'input_type', 'input_topic'}
    used = {
        ast.literal_eval(n.args[0])
        for n in calls
        if getattr(n.func, 'id', None) == 'LaunchConfiguration'
        and isinstance(n.args[0], ast.Constant)
    }
    inputs = next(
        ast.literal_eval(n.value)
        for n in tree.body
        if isinstance(n, ast.Assign) and n.targets[0].id == 'INPUT_ARGUMENTS'
    )
    assert used | set(inputs) == declared


def test_readme_parameter_table_states_the_defaults():
    """The README's estimator-parameter table lists each EstimatorConfig field with its default."""
    text = (ROOT / 'README.md').read_text()
    table = text.split('### Estimator parameters', 1)[1].split('\n## ', 1)[0]
    rows = {}
    for line in table.splitlines():
        cells = [c.strip() for c in line.strip('|').split('|')]
        if len(cells) >= 3 and cells[0].startswith('`'):
            rows[cells[0].strip('`')] = cells[1].strip('`').removesuffix(' s')
    defaults = EstimatorConfig()
    documented = set(EstimatorConfig.names())
    assert documented <= set(rows), documented - set(rows)
    for name in documented:
        default, shown = getattr(defaults, name), rows[name]
        if default is None:
            assert shown == 'off', name
        elif isinstance(default, bool):
            assert shown == str(default).lower(), name
        elif isinstance(default, str):
            assert shown == default, name
        else:
            assert float(shown) == default, (name, shown, default)


def _node_with(context, *ros_args):
    rclpy.init(
        context=context, domain_id=int(os.environ['ROS_DOMAIN_ID']), args=['--ros-args', *ros_args]
    )
    return EstimatorNode(context=context, cli_args=['--ros-args', *ros_args])


def test_params_file_applies_under_any_namespace_and_name(tmp_path):
    """Issue 22 case 3: keyed ``estimator_node:`` the file was ignored under a namespace."""
    changed = tmp_path / 'changed.yaml'
    changed.write_text(PARAMS.read_text().replace('min_fit: 0.9', 'min_fit: 0.75'))
    for remap in ('__ns:=/robot1', '__node:=x'):
        context = rclpy.Context()
        try:
            node = _node_with(context, '-r', remap, '--params-file', str(changed))
            assert node.get_parameter('min_fit').value == 0.75, remap
            assert config_of(node).min_fit == 0.75, remap
            assert node.params_file_warnings == []
            node.destroy_node()
        finally:
            context.try_shutdown()


def test_a_params_file_that_sets_nothing_for_the_node_is_warned_about(tmp_path):
    wrong = tmp_path / 'wrong.yaml'
    wrong.write_text('estimator_node:\n  ros__parameters:\n    min_fit: 0.75\n')
    unknown = tmp_path / 'unknown.yaml'
    unknown.write_text('/**:\n  ros__parameters:\n    min_fitt: 0.75\n')
    context = rclpy.Context()
    try:
        node = _node_with(
            context,
            '-r',
            '__ns:=/robot1',
            '--params-file',
            str(wrong),
            '--params-file',
            str(unknown),
        )
        assert node.get_parameter('min_fit').value == 0.9 == EstimatorConfig().min_fit
        first, second = node.params_file_warnings
        assert 'wrong.yaml sets nothing for /robot1/estimator_node' in first
        assert '"/**:"' in first and 'min_fitt' in second
        node.destroy_node()
    finally:
        context.try_shutdown()
