# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""config/<executable>.yaml of sim_node, shaper_node, bag_replayer and bag_recorder (issue 23).

Each file holds exactly the parameters its node declares, with the node's defaults (read from a
node started without the file: a default changed in the node and not in the file fails), a
comment on each, under ``/**:``; and it loads into the node through rcl's own parser
(``--params-file``), under a namespace too. (estimator_node's file: test_launch_config.py.)
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest
import rclpy
import yaml

from vib_estimator.nodes.bag_recorder import BagRecorder
from vib_estimator.nodes.bag_replayer import BagReplayer
from vib_estimator.nodes.shaper_node import ShaperNode
from vib_estimator.nodes.sim_node import SimNode

ROOT = Path(__file__).resolve().parents[2]
BAG = ROOT / 'bags' / 'arm_5_3'
#: parameters rclpy declares on every node: not the node's own, so not in its file
ROS_PARAMETERS = {'use_sim_time', 'start_type_description_service'}


def _required(tmp_path):
    """Per file: the node class and the ``-p`` values a start needs (the file leaves them empty),
    and one of the file's settings changed, to show the file is read."""
    return {
        'sim.yaml': (SimNode, [], ('noise_std: 0.004', 'noise_std: 0.25'), ('noise_std', 0.25)),
        'shaper.yaml': (ShaperNode, [], ('median_of: 1', 'median_of: 5'), ('median_of', 5)),
        'replayer.yaml': (
            BagReplayer,
            [f'bag:={BAG}'],
            ('wait_timeout: 5.0', 'wait_timeout: 2.5'),
            ('wait_timeout', 2.5),
        ),
        'recorder.yaml': (
            BagRecorder,
            [f'output:={tmp_path / "bag"}', 'topics:=[chatter]'],
            ('flush_period: 1.0', 'flush_period: 0.5'),
            ('flush_period', 0.5),
        ),
    }


FILES = ('sim.yaml', 'shaper.yaml', 'replayer.yaml', 'recorder.yaml')


def _parameters(node_class, *ros_args):
    """The node's own parameters and their values (None: declared without a value), started in a
    fresh context with ``ros_args``."""
    args = ['--ros-args', *ros_args]
    context = rclpy.Context()
    rclpy.init(context=context, domain_id=int(os.environ['ROS_DOMAIN_ID']), args=args)
    try:
        node = node_class(context=context, cli_args=args)
        names = set(node.list_parameters([], 0).names) - ROS_PARAMETERS
        values = {name: node.get_parameter_or(name).value for name in names}
        node.destroy_node()
        return values
    finally:
        context.try_shutdown()


def _file(name):
    path = ROOT / 'config' / name
    return path, yaml.safe_load(path.read_text())


def _overrides(required):
    return [arg for value in required for arg in ('-p', value)]


@pytest.mark.parametrize('name', FILES)
def test_file_holds_the_declared_parameters_with_their_defaults(name, tmp_path):
    node_class, required, _, _ = _required(tmp_path)[name]
    path, data = _file(name)
    assert list(data) == ['/**'] and list(data['/**']) == ['ros__parameters']
    params = data['/**']['ros__parameters']
    defaults = _parameters(node_class, *_overrides(required))
    assert set(params) == set(defaults)
    given = {value.split(':=')[0] for value in required}
    for key, value in params.items():
        if key in given:  # required: the file leaves it empty
            assert value in ('', []), key
            continue
        default = [] if defaults[key] is None else defaults[key]  # a string array without value
        assert value == default and type(value) is type(default), (key, value, default)
    lines = path.read_text().split('/**:', 1)[1].splitlines()
    for key in params:
        line = next(line for line in lines if line.strip().startswith(f'{key}:'))
        assert '#' in line, f'{name}: {key} has no comment'


@pytest.mark.parametrize('name', FILES)
def test_file_loads_into_the_node_under_any_namespace(name, tmp_path):
    node_class, required, (old, new), (key, expected) = _required(tmp_path)[name]
    path, data = _file(name)
    changed = tmp_path / name
    text = path.read_text()
    assert text.count(old) == 1
    changed.write_text(text.replace(old, new))
    values = _parameters(
        node_class, '-r', '__ns:=/robot1', '--params-file', str(changed), *_overrides(required)
    )
    assert values[key] == expected
    given = {value.split(':=')[0] for value in required}
    for param, value in data['/**']['ros__parameters'].items():
        if param not in given and param != key:
            assert (values[param] if values[param] is not None else []) == value, param
