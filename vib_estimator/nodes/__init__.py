# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""The ROS 2 nodes (one module each), their shared runner and parameter helpers."""
