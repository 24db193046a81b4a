# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""Node tests start from compiled kernels: the estimator node builds an estimator whose kernels
are already in memory at once, so the tests' time-outs measure the node, not numba. (A cold start,
the warm-up in the background, has its own tests in test_warmup.py.)"""

from __future__ import annotations

import pytest


@pytest.fixture(scope='session', autouse=True)
def warm_kernels():
    from vib_estimator.core.warmup import warm_all

    warm_all(report=lambda line: None)
