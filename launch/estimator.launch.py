"""Launch the frequency estimator with the Section 5.3 parameters of config/estimator.yaml.

``ros2 launch vib_estimator estimator.launch.py`` (needs launch_ros, i.e. a full ROS 2 install).
The input (``input_type``, ``input_topic``, ``component``) and every estimator parameter, ``modes``
included, are in that file: copy it to use another sensor (e.g. ``sensor_msgs/msg/Imu``,
``linear_acceleration.z``).
"""
import os

from ament_index_python.packages import get_package_share_directory
from launch import LaunchDescription
from launch_ros.actions import Node


def generate_launch_description():
    """One estimator_node reading its parameters from share/vib_estimator/config."""
    params = os.path.join(get_package_share_directory('vib_estimator'), 'config',
                          'estimator.yaml')
    return LaunchDescription([
        Node(package='vib_estimator', executable='estimator_node', name='estimator_node',
             parameters=[params], output='screen', emulate_tty=True),
    ])
