# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""Vibration control with the estimated frequency: input shapers (pure numpy/scipy, no rclpy)."""
