# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
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

from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, OpaqueFunction
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node

from vib_estimator.nodes.launching import (
    COMMON_ARGUMENTS,
    file_parameter,
    given,
    node_action,
    params_file_argument,
    truthy,
)


def _nodes(context):
    """sim_node with the speed/publish_clock arguments over its file; estimator_node with
    use_sim_time when sim_node publishes /clock."""

    def value(name):
        return LaunchConfiguration(name).perform(context)

    sim_file = value('sim_params_file')
    sim = {**given(value, ['speed'], float), **given(value, ['publish_clock'], truthy)}
    speed, publish_clock = (
        sim.get(name, file_parameter(sim_file, name)) for name in ('speed', 'publish_clock')
    )
    clock = truthy(publish_clock) or float(speed or 1.0) != 1.0
    namespace, estimator_file = (
        LaunchConfiguration(name) for name in ('namespace', 'estimator_params_file')
    )
    return [
        node_action(Node, 'sim_node', namespace, [sim_file, sim]),
        node_action(Node, 'estimator_node', namespace, [estimator_file, {'use_sim_time': clock}]),
    ]


def generate_launch_description():
    """sim_node and estimator_node, their parameters from share/vib_estimator/config."""
    arguments = dict(
        [
            params_file_argument('sim', 'sim_node'),
            params_file_argument('estimator', 'estimator_node'),
        ]
    )
    arguments['namespace'] = COMMON_ARGUMENTS['namespace']
    arguments['speed'] = (
        '',
        "simulated seconds per wall-clock second (empty: the file's); "
        'other than 1: /clock and use_sim_time',
    )
    arguments['publish_clock'] = (
        '',
        "true: /clock and use_sim_time even at speed 1 (empty: the file's)",
    )
    return LaunchDescription(
        [
            DeclareLaunchArgument(name, default_value=default, description=description)
            for name, (default, description) in arguments.items()
        ]
        + [OpaqueFunction(function=_nodes)]
    )
