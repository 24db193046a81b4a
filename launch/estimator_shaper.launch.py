# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""Launch the frequency estimator and the input shaper it drives: estimator_node + shaper_node.

``ros2 launch vib_estimator estimator_shaper.launch.py`` (needs launch_ros, i.e. a full ROS 2
install). shaper_node shapes ``reference`` into ``position_command`` for the estimates on
``vibration/frequency`` (and ``vibration/damping_ratio``) of estimator_node, which reads the
sensor of its parameters file. Arguments (``name:=value``; ``--show-args`` lists them):

* ``estimator_params_file``, ``shaper_params_file``: the nodes' parameters files (default: the
  package's ``config/estimator.yaml`` and ``config/shaper.yaml``, keyed ``/**:``);
* ``namespace``: the namespace of both nodes (their topics and services move with them);
* ``use_sim_time``: ``true`` to take time from ``/clock`` (both nodes; the shaper then ticks on
  each ``/clock``, e.g. the simulator's ``lockstep``);
* ``shaper``: the shaper (empty = the file's; settable at run time, ``ros2 param set``);
* ``input_type``, ``input_topic``: the estimator's input (empty = the file's).
"""

from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, OpaqueFunction
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node

from vib_estimator.nodes.launching import (
    COMMON_ARGUMENTS,
    INPUT_ARGUMENTS,
    given,
    node_action,
    params_file_argument,
    truthy,
)


def _nodes(context):
    """estimator_node and shaper_node, the arguments' values over their files'."""

    def value(name):
        return LaunchConfiguration(name).perform(context)

    clock = {'use_sim_time': truthy(value('use_sim_time'))}
    namespace = LaunchConfiguration('namespace')
    return [
        node_action(
            Node,
            'estimator_node',
            namespace,
            [
                LaunchConfiguration('estimator_params_file'),
                {**clock, **given(value, INPUT_ARGUMENTS)},
            ],
        ),
        node_action(
            Node,
            'shaper_node',
            namespace,
            [LaunchConfiguration('shaper_params_file'), {**clock, **given(value, ['shaper'])}],
        ),
    ]


def generate_launch_description():
    """estimator_node and shaper_node, their parameters from share/vib_estimator/config."""
    arguments = dict(
        [
            params_file_argument('estimator', 'estimator_node'),
            params_file_argument('shaper', 'shaper_node'),
        ]
    )
    arguments.update((name, COMMON_ARGUMENTS[name]) for name in ('namespace', 'use_sim_time'))
    arguments['shaper'] = ('', "input shaper (empty: the file's)")
    arguments.update((name, COMMON_ARGUMENTS[name]) for name in INPUT_ARGUMENTS)
    return LaunchDescription(
        [
            DeclareLaunchArgument(name, default_value=default, description=description)
            for name, (default, description) in arguments.items()
        ]
        + [OpaqueFunction(function=_nodes)]
    )
