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
import os

from ament_index_python.packages import get_package_share_directory
from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, OpaqueFunction
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node

PACKAGE = 'vib_estimator'
#: launch arguments whose empty value leaves the estimator's parameters file's setting in place
INPUT_ARGUMENTS = ('input_type', 'input_topic')


def _config(name):
    """A parameters file of the package's share/vib_estimator/config."""
    return os.path.join(get_package_share_directory(PACKAGE), 'config', name)


def _nodes(context):
    """estimator_node and shaper_node, the arguments' values over their files'."""
    sim_time = LaunchConfiguration('use_sim_time').perform(context).lower() == 'true'
    estimator = {'use_sim_time': sim_time}
    for name in INPUT_ARGUMENTS:
        value = LaunchConfiguration(name).perform(context)
        if value:
            estimator[name] = value
    shaper = {'use_sim_time': sim_time}
    name = LaunchConfiguration('shaper').perform(context)
    if name:
        shaper['shaper'] = name
    namespace = LaunchConfiguration('namespace')
    return [
        Node(package=PACKAGE, executable='estimator_node', name='estimator_node',
             namespace=namespace,
             parameters=[LaunchConfiguration('estimator_params_file'), estimator],
             output='screen', emulate_tty=True),
        Node(package=PACKAGE, executable='shaper_node', name='shaper_node', namespace=namespace,
             parameters=[LaunchConfiguration('shaper_params_file'), shaper],
             output='screen', emulate_tty=True),
    ]


def generate_launch_description():
    """estimator_node and shaper_node, their parameters from share/vib_estimator/config."""
    return LaunchDescription([
        DeclareLaunchArgument('estimator_params_file', default_value=_config('estimator.yaml'),
                              description='parameters file of estimator_node'),
        DeclareLaunchArgument('shaper_params_file', default_value=_config('shaper.yaml'),
                              description='parameters file of shaper_node'),
        DeclareLaunchArgument('namespace', default_value='',
                              description='namespace of the nodes, their topics and services'),
        DeclareLaunchArgument('use_sim_time', default_value='false',
                              description='true: time from /clock'),
        DeclareLaunchArgument('shaper', default_value='',
                              description='input shaper (empty: the file\'s)'),
        DeclareLaunchArgument('input_type', default_value='',
                              description='estimator input message type (empty: the file\'s)'),
        DeclareLaunchArgument('input_topic', default_value='',
                              description='estimator input topic (empty: the file\'s)'),
        OpaqueFunction(function=_nodes),
    ])
