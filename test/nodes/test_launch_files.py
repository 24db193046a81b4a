# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""launch/*.launch.py run against stand-ins of launch and launch_ros (not installed here).

The stand-ins take the keywords of the real classes (``DeclareLaunchArgument(name, *,
default_value, description)``, ``OpaqueFunction(*, function)``, ``LaunchConfiguration(name)``
with ``.perform(context)``, ``launch_ros.actions.Node(*, executable, package, name, namespace,
parameters, ...)``), so a launch file is executed as ``ros2 launch`` would: its arguments declared,
its OpaqueFunction called with a context holding the arguments' values, and the nodes it returns
checked -- executables of setup.py, parameters files that exist under config/, each argument used,
and the set-up each file is for (use_sim_time when /clock is published, the overrides).
"""

from __future__ import annotations

import ast
import importlib.util
import sys
import types
from pathlib import Path

import ament_index_python.packages
import pytest
import yaml

ROOT = Path(__file__).resolve().parents[2]
LAUNCH = ROOT / 'launch'
CONFIG = ROOT / 'config'
FILES = sorted(p.name for p in LAUNCH.glob('*.launch.py'))


class LaunchDescription:
    def __init__(self, initial_entities=None):
        self.entities = list(initial_entities or [])


class DeclareLaunchArgument:
    def __init__(self, name, *, default_value=None, description=None, choices=None):
        self.name, self.default_value, self.description = name, default_value, description


class OpaqueFunction:
    def __init__(self, *, function, args=None, kwargs=None):
        self.function, self.args, self.kwargs = function, args or [], kwargs or {}


class LaunchConfiguration:
    #: every name performed, to check that each declared argument is used
    performed: set = set()

    def __init__(self, variable_name, *, default=None):
        self.name = variable_name

    def perform(self, context):
        LaunchConfiguration.performed.add(self.name)
        return context.launch_configurations[self.name]


class Node:
    #: launch_ros.actions.Node's keyword arguments (Jazzy): any other is a TypeError there
    ARGUMENTS = frozenset(
        'executable package name namespace exec_name parameters remappings ros_arguments '
        'arguments output emulate_tty'.split()
    )

    def __init__(self, **kwargs):
        unknown = set(kwargs) - self.ARGUMENTS
        if unknown or 'executable' not in kwargs:
            raise TypeError(f'launch_ros Node: unexpected {sorted(unknown)} or no executable')
        self.executable, self.package = kwargs['executable'], kwargs.get('package')
        self.name, self.namespace = kwargs.get('name'), kwargs.get('namespace')
        self.parameters = list(kwargs.get('parameters') or [])


def _entry_points():
    """The executables of setup.py's console_scripts."""
    tree = ast.parse((ROOT / 'setup.py').read_text())
    scripts = next(
        ast.literal_eval(n.values[n.keys.index(k)])
        for n in ast.walk(tree)
        if isinstance(n, ast.Dict)
        for k in n.keys
        if isinstance(k, ast.Constant) and k.value == 'console_scripts'
    )
    return {s.split('=')[0].strip() for s in scripts}


@pytest.fixture
def load(monkeypatch):
    """Import a launch file with the stand-ins; the package's share directory is the source tree
    (setup.py installs config/*.yaml and launch/*.py there as they are)."""
    for name in (
        'launch',
        'launch.actions',
        'launch.substitutions',
        'launch_ros',
        'launch_ros.actions',
    ):
        monkeypatch.setitem(sys.modules, name, types.ModuleType(name))
    sys.modules['launch'].LaunchDescription = LaunchDescription
    sys.modules['launch.actions'].DeclareLaunchArgument = DeclareLaunchArgument
    sys.modules['launch.actions'].OpaqueFunction = OpaqueFunction
    sys.modules['launch.substitutions'].LaunchConfiguration = LaunchConfiguration
    sys.modules['launch_ros.actions'].Node = Node

    def share(package):
        if package != 'vib_estimator':
            raise LookupError(package)
        return str(ROOT)

    monkeypatch.setattr(ament_index_python.packages, 'get_package_share_directory', share)

    def load_file(name):
        spec = importlib.util.spec_from_file_location(name.replace('.', '_'), LAUNCH / name)
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
        return module

    return load_file


def _launch(module, **arguments):
    """The declared arguments and the nodes started with ``arguments`` over their defaults, each
    node as (executable, namespace, [parameters files], {parameter overrides})."""
    description = module.generate_launch_description()
    declared = {e.name: e for e in description.entities if isinstance(e, DeclareLaunchArgument)}
    assert set(arguments) <= set(declared), set(arguments) - set(declared)
    values = {name: e.default_value for name, e in declared.items()}
    values.update(arguments)
    missing = {name for name, value in values.items() if value is None}
    assert not missing, f'required arguments not given: {missing}'
    context = types.SimpleNamespace(launch_configurations=values)
    nodes = []
    for entity in description.entities:
        if isinstance(entity, OpaqueFunction):
            nodes += entity.function(context, *entity.args, **entity.kwargs)
        else:
            assert isinstance(entity, (DeclareLaunchArgument, Node)), entity
            nodes += [entity] if isinstance(entity, Node) else []

    def value(v):
        return v.perform(context) if isinstance(v, LaunchConfiguration) else v

    started = {}
    for node in nodes:
        files = [value(p) for p in node.parameters if not isinstance(p, dict)]
        overrides = {
            k: value(v) for p in node.parameters if isinstance(p, dict) for k, v in p.items()
        }
        started[node.executable] = (value(node.namespace), files, overrides)
        assert node.package == 'vib_estimator' and node.name == node.executable
    return declared, started


@pytest.mark.parametrize('name', FILES)
def test_each_launch_file_starts_installed_executables_with_existing_files(name, load):
    LaunchConfiguration.performed = set()
    module = load(name)
    required = {'bag': str(ROOT / 'bags' / 'arm_5_3')} if 'replay' in name else {}
    declared, started = _launch(module, namespace='robot1', **required)
    assert set(started) <= _entry_points() and started
    for executable, (namespace, files, _) in started.items():
        assert namespace == 'robot1', executable
        assert len(files) == 1 and Path(files[0]).is_file(), (executable, files)
        if Path(files[0]).parent == CONFIG:
            assert '/**' in yaml.safe_load(Path(files[0]).read_text())
    assert {'namespace'} <= set(declared)
    assert set(declared) == LaunchConfiguration.performed  # every argument is used
    for argument in declared.values():
        assert argument.description, argument.name


def test_sim_estimator_uses_sim_time_when_the_simulator_publishes_clock(load, tmp_path):
    module = load('sim_estimator.launch.py')
    declared, started = _launch(module)
    assert set(started) == {'sim_node', 'estimator_node'}
    assert started['sim_node'][1] == [str(CONFIG / 'sim.yaml')] and started['sim_node'][2] == {}
    assert started['estimator_node'][1] == [str(CONFIG / 'estimator.yaml')]
    assert started['estimator_node'][2] == {'use_sim_time': False}  # speed 1: real time
    _, started = _launch(module, speed='10')
    assert started['sim_node'][2] == {'speed': 10.0}
    assert started['estimator_node'][2] == {'use_sim_time': True}
    _, started = _launch(module, publish_clock='true')
    assert started['sim_node'][2] == {'publish_clock': True}
    assert started['estimator_node'][2]['use_sim_time']
    fast = tmp_path / 'fast.yaml'  # a file's speed counts too
    fast.write_text((CONFIG / 'sim.yaml').read_text().replace('speed: 1.0', 'speed: 5.0'))
    _, started = _launch(module, sim_params_file=str(fast))
    assert started['estimator_node'][2]['use_sim_time']
    _, started = _launch(module, sim_params_file=str(fast), speed='1')
    assert not started['estimator_node'][2]['use_sim_time']


def test_replay_estimator_needs_a_bag_and_follows_the_replayers_clock(load):
    module = load('replay_estimator.launch.py')
    with pytest.raises(AssertionError, match='bag'):
        _launch(module)
    bag = str(ROOT / 'bags' / 'arm_5_3')
    _, started = _launch(module, bag=bag)
    assert set(started) == {'bag_replayer', 'estimator_node'}
    assert started['bag_replayer'][1:] == ([str(CONFIG / 'replayer.yaml')], {'bag': bag})
    assert started['estimator_node'][2] == {'use_sim_time': False}
    _, started = _launch(module, bag=bag, clock_hz='100', rate='2', input_topic='/coupling_torque')
    assert started['bag_replayer'][2] == {'bag': bag, 'clock_hz': 100.0, 'rate': 2.0}
    assert started['estimator_node'][2] == {
        'use_sim_time': True,
        'input_topic': '/coupling_torque',
    }


def test_estimator_shaper_shares_the_clock_and_sets_the_shaper(load):
    module = load('estimator_shaper.launch.py')
    _, started = _launch(module)
    assert set(started) == {'estimator_node', 'shaper_node'}
    assert started['shaper_node'][1:] == ([str(CONFIG / 'shaper.yaml')], {'use_sim_time': False})
    assert started['estimator_node'][2] == {'use_sim_time': False}
    _, started = _launch(
        module, use_sim_time='true', shaper='zv', input_type='sensor_msgs/msg/Imu'
    )
    assert started['shaper_node'][2] == {'use_sim_time': True, 'shaper': 'zv'}
    assert started['estimator_node'][2] == {
        'use_sim_time': True,
        'input_type': 'sensor_msgs/msg/Imu',
    }
