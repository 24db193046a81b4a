# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""The ROS 2 nodes (one module each), their shared runner and parameter helpers."""

import sys

from .stopping import early

# before the node module's imports: Ctrl-C while they load exits 0, without a traceback
early(sys.argv[0] if sys.argv else '')
