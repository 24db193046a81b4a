# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""Launch the frequency estimator with the parameters of config/estimator.yaml (Section 5.3).

``ros2 launch vib_estimator estimator.launch.py`` (needs launch_ros, i.e. a full ROS 2 install).
Arguments (``name:=value``; ``ros2 launch vib_estimator estimator.launch.py --show-args``):

* ``params_file``: the parameters file (default: the package's ``config/estimator.yaml``; keyed
  ``/**:`` it applies under any node name and namespace);
* ``namespace``: the node's namespace (its topics and services move with it);
* ``use_sim_time``: ``true`` to take time from ``/clock`` (a bag replayed with ``clock_hz``, the
  simulator with ``publish_clock``);
* ``input_type``, ``input_topic``: the input (read-only parameters; empty = the file's value).

Every other estimator parameter, ``modes`` included, is in the parameters file: copy it to use
another sensor (e.g. ``sensor_msgs/msg/Imu``, ``linear_acceleration.z``).
"""

import os

from ament_index_python.packages import get_package_share_directory
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, OpaqueFunction
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node

#: launch arguments whose empty value leaves the parameters file's setting in place
INPUT_ARGUMENTS = ('input_type', 'input_topic')


def _estimator(context):
    """The estimator node, with the arguments' values as parameters over the file's."""
    overrides = {
        'use_sim_time': LaunchConfiguration('use_sim_time').perform(context).lower() == 'true'
    }
    for name in INPUT_ARGUMENTS:
        value = LaunchConfiguration(name).perform(context)
        if value:
            overrides[name] = value
    return [
        Node(
            package='vib_estimator',
            executable='estimator_node',
            name='estimator_node',
            namespace=LaunchConfiguration('namespace'),
            parameters=[LaunchConfiguration('params_file'), overrides],
            output='screen',
            emulate_tty=True,
        )
    ]


def generate_launch_description():
    """One estimator_node reading its parameters from share/vib_estimator/config (or
    ``params_file``)."""
    default_params = os.path.join(
        get_package_share_directory('vib_estimator'), 'config', 'estimator.yaml'
    )
    return LaunchDescription(
        [
            DeclareLaunchArgument(
                'params_file',
                default_value=default_params,
                description='parameters file of estimator_node',
            ),
            DeclareLaunchArgument(
                'namespace',
                default_value='',
                description='namespace of the node, its topics and services',
            ),
            DeclareLaunchArgument(
                'use_sim_time', default_value='false', description='true: time from /clock'
            ),
            DeclareLaunchArgument(
                'input_type',
                default_value='',
                description="input message type (empty: the file's)",
            ),
            DeclareLaunchArgument(
                'input_topic', default_value='', description="input topic (empty: the file's)"
            ),
            OpaqueFunction(function=_estimator),
        ]
    )
