# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""Baseline trackers (Section 5.4): convergence with the paper's gains, step convergence of the ODE
integration, streaming = batch, and the Cramer-Rao bound against a direct Fisher computation."""

from __future__ import annotations

import math

import numpy as np
import pytest

from vib_estimator.analysis import baselines
from vib_estimator.analysis.baselines import SlidingDFT, hold_last, matrix_pencil
from vib_estimator.analysis.bounds import crlb_frequency_std, fisher_frequency_std, window_crlb_std
from vib_estimator.core.threads import blas_controller

FS = 500.0
ODE_TRACKERS = (baselines.ZiaraniKonrad, baselines.Hou, baselines.MojiriBakhshai)


def sine(amplitude, f=1.33, seconds=20.0, phase=0.3, noise=0.0, seed=0):
    t = np.arange(int(seconds * FS)) / FS
    y = amplitude * np.sin(2 * np.pi * f * t + phase)
    return t, y + noise * np.random.default_rng(seed).standard_normal(len(t))


def settle_time(t, f_hat, f, tol):
    """Time after which |f_hat / f - 1| <= tol for good (inf if it is outside at the end)."""
    bad = np.flatnonzero(~(np.abs(f_hat / f - 1) <= tol))
    if not len(bad):
        return 0.0
    return math.inf if bad[-1] == len(t) - 1 else t[bad[-1] + 1]


@pytest.mark.parametrize('cls', ODE_TRACKERS + (SlidingDFT,))
def test_converges_on_clean_sine_with_the_papers_gains(cls):
    # 1 N m: the paper's gains were used on a coupling torque in N m; at this amplitude all three
    # adaptive trackers converge within seconds (MB's Eq. 33: A^2 xi2 / 2 = 0.625 < 1)
    t, y = sine(1.0)
    f_hat = cls().process(t, y)
    assert settle_time(t, f_hat, 1.33, 0.01) < 8.0
    assert abs(f_hat[-1] / 1.33 - 1) < 2e-3  # the DFT's documented bias bound


def test_adaptation_slows_on_arm_scale_torque():
    """At the simulated arm's ~0.3 N m the paper's gains still converge, but ZK and MB need many
    seconds: their adaptation rates scale with A^2 (Hou's too, but it starts fast enough)."""
    t, y = sine(0.3, seconds=60.0)
    times = {cls.name: settle_time(t, cls().process(t, y), 1.33, 0.01) for cls in ODE_TRACKERS}
    assert times['Hou'] < 3.0
    assert 10.0 < times['Ziarani-Konrad'] < 60.0
    assert 10.0 < times['Mojiri-Bakhshai'] < 60.0


@pytest.mark.parametrize('cls', ODE_TRACKERS)
@pytest.mark.parametrize('amplitude', [0.3, 1.0])
def test_integration_is_step_converged(cls, amplitude):
    # noisy input: the first-order hold sees a rough signal, the stiffest case for the sub-steps
    t, y = sine(amplitude, seconds=10.0, noise=0.01 * amplitude)
    default = cls().process(t, y)
    halved = cls(substeps=8).process(t, y)
    assert np.max(np.abs(default - halved)) < 1e-5 * np.max(np.abs(halved))


@pytest.mark.parametrize('cls', ODE_TRACKERS + (SlidingDFT,))
def test_streaming_equals_batch_and_skips_bad_samples(cls):
    t, y = sine(1.0, seconds=4.0, noise=0.01)
    t = t.copy()
    y = y.copy()
    y[100] = np.nan
    t[200] = t[199]  # duplicate stamp
    batch = cls().process(t, y)
    tracker = cls()
    stream = np.array([np.nan if (f := tracker.update(a, b)) is None else f for a, b in zip(t, y)])
    np.testing.assert_array_equal(stream, batch)
    np.testing.assert_array_equal(batch[[100, 200]], batch[[99, 199]])
    split = cls()
    np.testing.assert_array_equal(
        np.concatenate([split.process(t[:777], y[:777]), split.process(t[777:], y[777:])]), batch
    )
    tracker.reset()
    np.testing.assert_array_equal(tracker.process(t, y), batch)


def test_initial_estimates_are_3_hz_and_dft_waits_for_a_window():
    t, y = sine(0.2, seconds=3.0)
    for cls in ODE_TRACKERS:
        assert cls().update(0.0, 0.2) == pytest.approx(3.0)
    tracker = SlidingDFT()
    n = tracker.window_samples
    assert n == 1000
    dft = tracker.process(t, y)
    assert np.isnan(dft[: n - 1]).all() and np.isfinite(dft[n - 1 :]).all()


def test_hold_last():
    v = np.array([np.nan, 1.0, np.nan, np.nan, 2.0, np.nan])
    np.testing.assert_array_equal(hold_last(v), [np.nan, 1, 1, 1, 2, 2])
    np.testing.assert_array_equal(hold_last(v, 5.0), [5, 1, 1, 1, 2, 2])
    assert len(hold_last(np.empty(0))) == 0


@pytest.mark.parametrize('f,phase', [(1.33, 0.3), (10.0, 1.0), (47.0, 2.5)])
def test_crlb_matches_fisher_information(f, phase):
    # 5000 samples at 2 ms: >= 13 periods, where the closed form is exact to O(1/N)
    closed = crlb_frequency_std(0.2, 0.004, 2e-3, 5000)
    direct = fisher_frequency_std(0.2, f, phase, 0.004, 2e-3, 5000)
    assert closed == pytest.approx(direct, rel=0.02)


def test_window_crlb_uses_the_windows_amplitude_and_phase():
    t = np.arange(189) * 2e-3
    for phase in (0.0, 1.0, 2.0):
        y = 0.2 * np.sin(2 * np.pi * 1.33 * t + phase) + 0.05
        assert window_crlb_std(y, 2e-3, 1.33, 0.004) == pytest.approx(
            fisher_frequency_std(0.2, 1.33, phase, 0.004, 2e-3, 189), rel=1e-6
        )
    # scaling of the closed form: std ~ sigma / (A N^1.5)
    assert crlb_frequency_std(0.4, 0.004, 2e-3, 4000) == pytest.approx(
        crlb_frequency_std(0.2, 0.004, 2e-3, 2000) / 2 / 2**1.5, rel=1e-3
    )


@pytest.mark.parametrize('zeta', [0.0, 0.004, 0.02])
def test_matrix_pencil_is_exact_on_a_clean_damped_sine_and_nan_on_too_short_a_window(zeta):
    t = np.arange(400) / FS
    wn = 2 * np.pi * 1.33
    y = 0.1 * np.exp(-zeta * wn * t) * np.sin(wn * math.sqrt(1 - zeta**2) * t + 0.4)
    f, z = matrix_pencil(y, 1 / FS)
    assert f == pytest.approx(1.33, rel=1e-9) and z == pytest.approx(zeta, abs=1e-9)
    assert math.isnan(matrix_pencil(y[:8], 1 / FS)[0])


def test_the_pencils_svd_runs_on_one_blas_thread(monkeypatch):
    """OpenBLAS's threads made a sliding pencil 20x slower on a busy 2-core machine."""
    threads = []
    svd = np.linalg.svd

    def spy(*args, **kwargs):
        threads.extend(
            lib['num_threads'] for lib in blas_controller().info() if lib['user_api'] == 'blas'
        )
        return svd(*args, **kwargs)

    monkeypatch.setattr(np.linalg, 'svd', spy)
    t, y = sine(0.1, seconds=3.0)
    f = baselines.SlidingMatrixPencil(FS, window_s=1.0, hop=250).process(t, y)
    assert threads and set(threads) == {1}
    assert f[-1] == pytest.approx(1.33, rel=1e-6)
