"""The ROS 2 nodes (one module each), their shared runner and parameter helpers."""
