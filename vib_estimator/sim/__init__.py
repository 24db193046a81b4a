"""The flexible-arm model of Section 5 (Eqs. 19-23) and the paper's test signals (no rclpy)."""
