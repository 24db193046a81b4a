"""Launch the simulated arm and the frequency estimator on it: sim_node + estimator_node.

``ros2 launch vib_estimator sim_estimator.launch.py`` (needs launch_ros, i.e. a full ROS 2
install). Arguments (``name:=value``; ``--show-args`` lists them):

* ``sim_params_file``, ``estimator_params_file``: the nodes' parameters files (default: the
  package's ``config/sim.yaml`` and ``config/estimator.yaml``, keyed ``/**:``);
* ``namespace``: the namespace of both nodes (their topics and services move with them);
* ``speed``, ``publish_clock``: sim_node's (empty = the file's). When the simulator publishes
  ``/clock`` (``speed`` other than 1, or ``publish_clock``) the estimator runs with
  ``use_sim_time``, so its clock follows the simulated stamps.

The simulator publishes ``coupling_torque`` (``geometry_msgs/msg/WrenchStamped``, ``torque.z``),
the estimator's default input; its estimates appear on ``vibration/frequency`` etc., to compare
with the simulator's ``vibration/ground_truth``.
"""
import os

import yaml
from ament_index_python.packages import get_package_share_directory
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, OpaqueFunction
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node

PACKAGE = 'vib_estimator'


def _config(name):
    """A parameters file of the package's share/vib_estimator/config."""
    return os.path.join(get_package_share_directory(PACKAGE), 'config', name)


def _file_parameter(path, name):
    """The value a parameters file gives ``name`` (any node key), or None."""
    with open(path) as f:
        data = yaml.safe_load(f) or {}
    values = [section.get('ros__parameters', {}).get(name) for section in data.values()
              if isinstance(section, dict)]
    return next((v for v in values if v is not None), None)


def _nodes(context):
    """sim_node with the speed/publish_clock arguments over its file; estimator_node with
    use_sim_time when sim_node publishes /clock."""
    sim_file = LaunchConfiguration('sim_params_file').perform(context)
    overrides = {}
    speed = LaunchConfiguration('speed').perform(context)
    if speed:
        overrides['speed'] = float(speed)
    publish_clock = LaunchConfiguration('publish_clock').perform(context)
    if publish_clock:
        overrides['publish_clock'] = publish_clock.lower() == 'true'
    effective = {name: overrides.get(name, _file_parameter(sim_file, name))
                 for name in ('speed', 'publish_clock')}
    clock = bool(effective['publish_clock']) or float(effective['speed'] or 1.0) != 1.0
    namespace = LaunchConfiguration('namespace')
    return [
        Node(package=PACKAGE, executable='sim_node', name='sim_node', namespace=namespace,
             parameters=[sim_file, overrides], output='screen', emulate_tty=True),
        Node(package=PACKAGE, executable='estimator_node', name='estimator_node',
             namespace=namespace,
             parameters=[LaunchConfiguration('estimator_params_file'), {'use_sim_time': clock}],
             output='screen', emulate_tty=True),
    ]


def generate_launch_description():
    """sim_node and estimator_node, their parameters from share/vib_estimator/config."""
    return LaunchDescription([
        DeclareLaunchArgument('sim_params_file', default_value=_config('sim.yaml'),
                              description='parameters file of sim_node'),
        DeclareLaunchArgument('estimator_params_file', default_value=_config('estimator.yaml'),
                              description='parameters file of estimator_node'),
        DeclareLaunchArgument('namespace', default_value='',
                              description='namespace of the nodes, their topics and services'),
        DeclareLaunchArgument('speed', default_value='',
                              description='simulated seconds per wall-clock second (empty: the '
                                          'file\'s); other than 1: /clock and use_sim_time'),
        DeclareLaunchArgument('publish_clock', default_value='',
                              description='true: /clock and use_sim_time even at speed 1 '
                                          '(empty: the file\'s)'),
        OpaqueFunction(function=_nodes),
    ])
