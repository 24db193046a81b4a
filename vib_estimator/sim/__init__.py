# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""The flexible-arm model of Section 5 (Eqs. 19-23) and the paper's test signals (no rclpy)."""
