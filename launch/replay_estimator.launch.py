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
import os

import yaml
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


def _file_parameter(path, name):
    """The value a parameters file gives ``name`` (any node key), or None."""
    with open(path) as f:
        data = yaml.safe_load(f) or {}
    values = [section.get('ros__parameters', {}).get(name) for section in data.values()
              if isinstance(section, dict)]
    return next((v for v in values if v is not None), None)


def _nodes(context):
    """bag_replayer playing ``bag`` (``rate``, ``clock_hz`` over its file); estimator_node with
    use_sim_time when the replayer publishes /clock."""
    replayer_file = LaunchConfiguration('replayer_params_file').perform(context)
    replayer = {'bag': LaunchConfiguration('bag').perform(context)}
    for name in ('rate', 'clock_hz'):
        value = LaunchConfiguration(name).perform(context)
        if value:
            replayer[name] = float(value)
    clock_hz = replayer.get('clock_hz', _file_parameter(replayer_file, 'clock_hz')) or 0.0
    estimator = {'use_sim_time': float(clock_hz) > 0}
    for name in INPUT_ARGUMENTS:
        value = LaunchConfiguration(name).perform(context)
        if value:
            estimator[name] = value
    namespace = LaunchConfiguration('namespace')
    return [
        Node(package=PACKAGE, executable='bag_replayer', name='bag_replayer', namespace=namespace,
             parameters=[replayer_file, replayer], output='screen', emulate_tty=True),
        Node(package=PACKAGE, executable='estimator_node', name='estimator_node',
             namespace=namespace,
             parameters=[LaunchConfiguration('estimator_params_file'), estimator],
             output='screen', emulate_tty=True),
    ]


def generate_launch_description():
    """bag_replayer and estimator_node, their parameters from share/vib_estimator/config."""
    return LaunchDescription([
        DeclareLaunchArgument('bag', description='the bag directory, or .mcap / .db3 file, to '
                                                 'play (required)'),
        DeclareLaunchArgument('replayer_params_file', default_value=_config('replayer.yaml'),
                              description='parameters file of bag_replayer'),
        DeclareLaunchArgument('estimator_params_file', default_value=_config('estimator.yaml'),
                              description='parameters file of estimator_node'),
        DeclareLaunchArgument('namespace', default_value='',
                              description='namespace of the nodes, their topics and services'),
        DeclareLaunchArgument('rate', default_value='',
                              description='playback speed factor (empty: the file\'s)'),
        DeclareLaunchArgument('clock_hz', default_value='',
                              description='publish /clock at this rate; > 0: use_sim_time '
                                          '(empty: the file\'s)'),
        DeclareLaunchArgument('input_type', default_value='',
                              description='estimator input message type (empty: the file\'s)'),
        DeclareLaunchArgument('input_topic', default_value='',
                              description='estimator input topic (empty: the file\'s)'),
        OpaqueFunction(function=_nodes),
    ])
