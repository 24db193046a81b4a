# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""The mathematics, with no rclpy: configuration, the compiled kernel, the estimators.

Public API: :class:`EstimatorConfig`; :func:`create_estimator` ``(config, channels=())``, the
estimator of a configuration (the table :data:`KINDS` of :mod:`.factory`: which estimator serves
which excitation, one channel or several); :class:`Estimator`, the interface every estimator has
(``update``, ``process``, ``reset``, ``restart``, ``config``, ``channels``, ``counters``);
:class:`Estimate`, :class:`EstimateArrays`; :class:`FrequencyEstimator` (the paper's algebraic
estimator) and :func:`estimate`; ``MODELS``, ``COUNTER_NAMES``.
"""

from .config import MODELS, EstimatorConfig
from .estimator import (
    COUNTER_NAMES,
    Estimate,
    EstimateArrays,
    Estimator,
    FrequencyEstimator,
)
from .factory import KINDS, create_estimator, estimate

__all__ = [
    'MODELS',
    'COUNTER_NAMES',
    'KINDS',
    'EstimatorConfig',
    'Estimate',
    'EstimateArrays',
    'Estimator',
    'FrequencyEstimator',
    'create_estimator',
    'estimate',
]
