# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""Reading and writing recordings: CSV, rosbag2/MCAP bags, message fields and stamps (no rclpy)."""
