"""Reading and writing recordings: CSV, rosbag2/MCAP bags, message fields and stamps (no rclpy)."""
