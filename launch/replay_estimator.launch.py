# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""Launch the frequency estimator on a recorded bag: bag_replayer + estimator_node.

``ros2 launch vib_estimator replay_estimator.launch.py bag:=<bag>`` (needs launch_ros, i.e. a full
ROS 2 install; ``bags/arm_5_3`` is a bag of the package). Arguments (``name:=value``):

* ``bag`` (required): the bag directory, or ``.mcap`` / ``.db3`` file, to play;
* ``replayer_params_file``, ``estimator_params_file``: the nodes' parameters files (default: the
  package's ``config/replayer.yaml`` and ``config/estimator.yaml``, keyed ``/**:``);
* ``namespace``: the namespace of both nodes. The replayer publishes the topic names recorded in
  the bag (``/coupling_torque``: absolute, so not moved by the namespace); give ``input_topic`` (or
  the replayer's ``remap``) to connect them otherwise;
* ``rate``: playback speed factor (empty = the file's);
* ``clock_hz``: publish ``/clock`` at this rate (empty = the file's); when > 0 the estimator runs
  with ``use_sim_time``;
* ``input_type``, ``input_topic``: the estimator's input (empty = the file's).
"""

from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, OpaqueFunction
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node

from vib_estimator.nodes.launching import (
    COMMON_ARGUMENTS,
    INPUT_ARGUMENTS,
    file_parameter,
    given,
    node_action,
    params_file_argument,
)


def _nodes(context):
    """bag_replayer playing ``bag`` (``rate``, ``clock_hz`` over its file); estimator_node with
    use_sim_time when the replayer publishes /clock."""

    def value(name):
        return LaunchConfiguration(name).perform(context)

    replayer_file = value('replayer_params_file')
    replayer = {'bag': value('bag'), **given(value, ['rate', 'clock_hz'], float)}
    clock_hz = replayer.get('clock_hz', file_parameter(replayer_file, 'clock_hz')) or 0.0
    estimator = {'use_sim_time': float(clock_hz) > 0, **given(value, INPUT_ARGUMENTS)}
    namespace, estimator_file = (
        LaunchConfiguration(name) for name in ('namespace', 'estimator_params_file')
    )
    return [
        node_action(Node, 'bag_replayer', namespace, [replayer_file, replayer]),
        node_action(Node, 'estimator_node', namespace, [estimator_file, estimator]),
    ]


def generate_launch_description():
    """bag_replayer and estimator_node, their parameters from share/vib_estimator/config."""
    arguments = {'bag': (None, 'the bag directory, or .mcap / .db3 file, to play (required)')}
    arguments.update(
        [
            params_file_argument('replayer', 'bag_replayer'),
            params_file_argument('estimator', 'estimator_node'),
        ]
    )
    arguments['namespace'] = COMMON_ARGUMENTS['namespace']
    arguments['rate'] = ('', "playback speed factor (empty: the file's)")
    arguments['clock_hz'] = (
        '',
        "publish /clock at this rate; > 0: use_sim_time (empty: the file's)",
    )
    arguments.update((name, COMMON_ARGUMENTS[name]) for name in INPUT_ARGUMENTS)
    return LaunchDescription(
        [
            DeclareLaunchArgument(name, default_value=default, description=description)
            for name, (default, description) in arguments.items()
        ]
        + [OpaqueFunction(function=_nodes)]
    )
