"""Vibration control with the estimated frequency: input shapers (pure numpy/scipy, no rclpy)."""
