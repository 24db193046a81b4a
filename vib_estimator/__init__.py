# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""vib_estimator: fast on-line frequency and damping estimation of lightly damped vibrations.

Layout (one role per subpackage; nothing in ``core``, ``io``, ``sim``, ``analysis`` or ``control``
imports rclpy):

* ``core``     -- the mathematics: configuration, the compiled kernel, the estimator API
* ``io``       -- CSV and bag reading/writing, message field access and stamps
* ``sim``      -- the flexible-arm model (Eqs. 19-23) and the paper's test signals
* ``analysis`` -- offline commands and studies: analyze, reproduce, compare, baselines, bounds
* ``control``  -- what the estimate is for (input shaping)
* ``nodes``    -- the ROS 2 nodes, one module each, and their shared runner and parameter helpers
* ``cli``      -- the ``vib-estimator`` dispatcher; ``demo`` -- the live demo

The core's public API is importable from the top: ``from vib_estimator import create_estimator``
(loaded on first use, so ``vib-estimator --help`` and the nodes start without compiling anything
they do not need).
"""

from importlib import import_module

#: the names of ``vib_estimator.core.__all__`` (written out: importing core would load numba)
_CORE = tuple(
    'MODELS COUNTER_NAMES KINDS EstimatorConfig Estimate EstimateArrays Estimator '
    'FrequencyEstimator create_estimator estimate'.split()
)
__all__ = list(_CORE)


def __getattr__(name):
    if name in _CORE:
        return getattr(import_module('.core', __name__), name)
    raise AttributeError(f'module {__name__!r} has no attribute {name!r}')
