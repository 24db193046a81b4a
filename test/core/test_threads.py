# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""The identifiers' small dense linear algebra runs on one BLAS thread, whatever the caller set."""

import numpy as np
import pytest

from vib_estimator.core import EstimatorConfig
from vib_estimator.core.ambient import AmbientEstimator
from vib_estimator.core.threads import blas_controller, one_blas_thread
from vib_estimator.sim.ambient import ambient_record

FS = 500.0
CONFIG = EstimatorConfig(excitation='ambient', ambient_window_s=10.0)

threadpoolctl = pytest.importorskip('threadpoolctl')


def blas_threads():
    return {lib['num_threads'] for lib in blas_controller().info() if lib['user_api'] == 'blas'}


@pytest.fixture
def eig_threads(monkeypatch):
    """The BLAS thread counts seen at each ``np.linalg.eig`` call, under a caller's 2 threads
    (so that the test fails on a one-core machine too if the identifiers do not limit them)."""
    seen = []
    eig = np.linalg.eig

    def spy(*args, **kwargs):
        seen.extend(blas_threads())
        return eig(*args, **kwargs)

    monkeypatch.setattr(np.linalg, 'eig', spy)
    with blas_controller().limit(limits=2, user_api='blas'):
        yield seen
        assert blas_threads() == {2}  # the caller's setting is restored


@pytest.fixture(scope='module')
def record():
    """A 14 s one-mode record (made before the spy: the simulator calls eig too)."""
    t, y, _ = ambient_record(14.0, FS, [(5.0, 0.01, 1.0)], 26.0, 3)
    return t, y


def test_ambient_batch_and_streaming_run_on_one_blas_thread(record, eig_threads):
    t, y = record
    batch = AmbientEstimator(CONFIG).process(t, y)
    assert eig_threads and set(eig_threads) == {1}
    eig_threads.clear()
    streaming = AmbientEstimator(CONFIG)
    for ti, yi in zip(t, y):
        streaming.update(ti, yi)
    assert eig_threads and set(eig_threads) == {1}
    assert len(batch) and np.all(np.abs(batch.frequency_hz / 5.0 - 1) < 0.05)


def test_joint_identifier_runs_on_one_blas_thread(record, eig_threads):
    t, y = record
    columns = np.column_stack([y, -0.5 * y + 0.01 * np.sin(t)])
    estimates = AmbientEstimator(CONFIG, ('a', 'b')).process(t, columns)
    assert eig_threads and set(eig_threads) == {1}
    assert len(estimates) and np.all(np.abs(estimates.estimates.frequency_hz / 5.0 - 1) < 0.05)


def test_one_blas_thread_limits_numpys_and_scipys_blas():
    import scipy.linalg  # noqa: F401 -- its OpenBLAS loaded, whatever ran before

    assert {lib['filepath'] for lib in blas_controller().info()} >= {
        lib['filepath'] for lib in threadpoolctl.threadpool_info() if lib['user_api'] == 'blas'
    }
    with blas_controller().limit(limits=2, user_api='blas'):
        with one_blas_thread():
            assert blas_threads() == {1}
        assert blas_threads() == {2}
