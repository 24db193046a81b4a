# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""The mathematics, with no rclpy: configuration, the compiled kernel, the estimator API.

Public API: :class:`EstimatorConfig`, :class:`FrequencyEstimator`, :class:`Estimate`,
:class:`EstimateArrays`, :func:`estimate`, ``MODELS``, ``COUNTER_NAMES``.
"""

from .config import MODELS, EstimatorConfig
from .estimator import COUNTER_NAMES, Estimate, EstimateArrays, FrequencyEstimator, estimate

__all__ = [
    'MODELS',
    'COUNTER_NAMES',
    'EstimatorConfig',
    'Estimate',
    'EstimateArrays',
    'FrequencyEstimator',
    'estimate',
]
