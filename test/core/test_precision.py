# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""Seeded Monte Carlo: refined estimates at the exact Cramer-Rao bound, calibrated std, targets.

Signals: the simulated arm's second mode (1.33 Hz, A = 0.1, Ts = 2 ms) at 40 dB SNR, random phase
per record; the bound is :func:`vib_estimator.analysis.bounds.model_crb` on the samples each
estimate used. Seeds are fixed; the tolerances leave the ~10 % sampling error of a ratio over >= 50
estimates (measured ratios 0.9-1.1, ``benchmarks/bench_precision.py``).
"""

import math

import numpy as np
import pytest

from vib_estimator.analysis.bounds import model_crb
from vib_estimator.core import EstimatorConfig, FrequencyEstimator, estimate
from vib_estimator.sim.signals import fig1_signal

#: the paper's estimator (Eq. 1 over half-period windows), which these tests check
PAPER = EstimatorConfig.paper()

F0, AMP, TS = 1.33, 0.1, 0.002
SD = AMP / math.sqrt(2 * 1e4)  # 40 dB


def _runs(model, periods, zeta=0.0, offset=0.0, records=12, refine=4):
    err, bound, z, norm = [], [], [], []
    rng = np.random.default_rng(int(periods * 10) + len(model))
    for _ in range(records):
        t = np.arange(0.0, max(6.0, 3 * periods / F0), TS)
        phase = rng.uniform(0, 2 * math.pi)
        wn = 2 * math.pi * F0
        y = AMP * np.exp(-zeta * wn * t) * np.sin(wn * math.sqrt(1 - zeta**2) * t + phase)
        y = y + offset + rng.normal(0, SD, len(t))
        e = estimate(t, y, EstimatorConfig.paper(model=model, min_periods=periods, refine=refine))
        for k in range(len(e)):
            i1 = int(round(e.t[k] / TS))
            b, _ = model_crb(
                model, t[i1 - int(e.samples[k]) + 1 : i1 + 1], AMP, F0, phase, SD, zeta
            )
            err.append(e.frequency_hz[k] - F0)
            bound.append(b)
            norm.append((e.frequency_hz[k] - F0) / b)
            z.append((e.frequency_hz[k] - F0) / e.frequency_std_hz[k])
    rms = lambda v: math.sqrt(np.mean(np.square(v)))  # noqa: E731
    return len(err), rms(norm), rms(z)


@pytest.mark.parametrize(
    'model,zeta,offset',
    [('sinusoid', 0, 0), ('damped-sinusoid', 0.01, 0), ('biased-sinusoid', 0, 0.3)],
)
@pytest.mark.parametrize('periods', [0.5, 2, 10])
def test_spread_within_1_5_bounds_and_std_calibrated(model, zeta, offset, periods):
    n, ratio, calib = _runs(model, periods, zeta, offset, records=12 if periods < 10 else 8)
    assert n >= (8 if periods == 10 else 30)
    assert ratio < 1.5
    assert 0.75 < calib < 1.3


def test_the_paper_estimator_alone_loses_precision_over_long_windows():
    """The reason for refine: the algebraic estimate over 2 periods is far from the bound."""
    _, ratio, _ = _runs('sinusoid', 2, refine=0)
    assert ratio > 3


def _fig1_first_estimates(target):
    t = np.arange(0.0, 1.0, 0.002)
    first, errors, rel_std = [], [], []
    for seed in range(20):
        est = FrequencyEstimator(EstimatorConfig.paper(target_std_rel=target, min_periods=0.0))
        e = est.process(t, fig1_signal(t, seed=seed))
        first.append(e.t[0])
        errors.append(abs(2 * math.pi * e.frequency_hz[0] / 10 - 1))
        rel_std.append(e.frequency_std_hz[0] * 2 * math.pi / 10)
    return np.array(first), np.array(errors), np.array(rel_std)


def test_target_std_rel_publishes_fig1_within_a_fraction_of_a_period():
    """Fig. 1 (sin(10 t + 1) + U(-0.01, 0.01) per 2 ms sample): first estimate by t = 0.12 s.

    Published when its predicted relative std reaches 1 %, so its error is within 1 % at one
    sigma (the exact bound over the samples up to 0.12 s is 0.90 %: an unbiased estimator is
    within 1 % on at most 73 % of seeds): within 1 % on most seeds and within 3 % on all.
    """
    first, errors, rel_std = _fig1_first_estimates(0.01)
    assert np.all(rel_std <= 0.0105)
    assert first.max() <= 0.12
    assert errors.max() < 0.03
    assert np.mean(errors < 0.01) >= 0.55


def test_a_three_sigma_target_puts_every_fig1_seed_within_1_percent_in_a_third_of_a_period():
    first, errors, _ = _fig1_first_estimates(0.003)
    assert first.max() <= 0.21  # 0.33 periods of 10 rad/s
    assert errors.max() < 0.01


@pytest.mark.parametrize('model', ['sinusoid', 'biased-sinusoid', 'damped-sinusoid'])
@pytest.mark.parametrize('refine', [0, 4])
def test_clean_signals_stay_exact_with_and_without_refinement(model, refine):
    f = 2.0
    t = np.arange(0.0, 5.0, 1 / (150 * f))
    y = (
        0.7
        * np.exp(-0.01 * 2 * math.pi * f * t * (model == 'damped-sinusoid'))
        * np.sin(2 * math.pi * f * math.sqrt(1 - 1e-4 * (model == 'damped-sinusoid')) * t + 0.4)
    )
    if model == 'biased-sinusoid':
        y = y + 0.5
    e = estimate(t, y, EstimatorConfig.paper(model=model, refine=refine))
    assert len(e) >= 10
    assert np.max(np.abs(e.frequency_hz / f - 1)) < 1e-5


def test_long_windows_are_not_cut_short_by_default():
    t = np.arange(0.0, 60.0, TS)
    y = np.sin(2 * math.pi * 0.4 * t) + np.random.default_rng(0).normal(0, 0.01, len(t))
    est = FrequencyEstimator(EstimatorConfig.paper(min_periods=20))
    e = est.process(t, y)
    assert len(e) >= 1 and np.all(e.convergence_time * 0.4 >= 19)
    assert est.counters['max_window_resets'] == 0


def test_damped_model_publishes_long_decaying_windows_at_the_bound():
    """20 periods of a sine decaying with zeta = 0.01 (the amplitude falls to 28 %): the quality
    gate judges the refined damped model's own residual, so these windows publish, at the bound."""
    n, ratio, calib = _runs('damped-sinusoid', 20, zeta=0.01, records=80)
    assert n >= 120
    assert ratio < 1.5
    assert 0.8 < calib < 1.25


def _records(zeta, sd, periods, records, seed):
    """Seeded records of the mode, 4 windows (>= 6 s) long, random phase (as the benchmark)."""
    rng = np.random.default_rng(seed)
    wn = 2 * math.pi * F0
    for _ in range(records):
        t = np.arange(0.0, max(6.0, 4 * periods / F0), TS)
        phase = rng.uniform(0, 2 * math.pi)
        y = AMP * np.exp(-zeta * wn * t) * np.sin(wn * math.sqrt(1 - zeta**2) * t + phase)
        yield t, y + rng.normal(0.0, sd, len(t)), phase


def test_long_damped_windows_start_from_the_half_period_damping():
    """5 periods of a decaying mode at 20 dB: the long-window fit starts at the segment's first
    converged half-period (f, zeta). The algebraic damping of the whole long segment is
    meaningless (|zeta| ~ 0.5 here); started there, the 8th record's fit settled 27 stds off
    (-1.7 %, R^2 0.94; the optimum from any sensible start has R^2 0.987)."""
    sd = AMP / math.sqrt(2 * 100.0)
    norm = []
    for t, y, phase in _records(0.01, sd, 5, 8, seed=520):
        e = estimate(t, y, EstimatorConfig.paper(model='damped-sinusoid', min_periods=5))
        for k in range(len(e)):
            i1 = int(round(e.t[k] / TS))
            b, _ = model_crb(
                'damped-sinusoid', t[i1 - int(e.samples[k]) + 1 : i1 + 1], AMP, F0, phase, sd, 0.01
            )
            norm.append((e.frequency_hz[k] - F0) / b)
    assert len(norm) >= 20
    assert np.max(np.abs(norm)) < 5


def _band_calibration(periods, records):
    """RMS of error / std with band_hz [f/2, 2f], windows that start after the prefilter's
    start-up (3 s), 40 dB."""
    z = []
    for t, y, _ in _records(0.0, SD, periods, records, seed=11):
        e = estimate(t, y, EstimatorConfig.paper(min_periods=periods, band_hz=(F0 / 2, 2 * F0)))
        for k in range(len(e)):
            if e.t[k] - e.convergence_time[k] > 3.0:
                z.append((e.frequency_hz[k] - F0) / e.frequency_std_hz[k])
    return len(z), math.sqrt(np.mean(np.square(z))), np.median(np.abs(z)) / 0.6745


def test_band_prefilter_std_is_calibrated_on_windows_long_against_its_correlation_time():
    """band_hz colours the noise: the std is the least-squares sandwich under the prefilter's
    noise covariance, with the input noise level from the residual (white-noise std of the
    band-passed residual: error/std RMS ~13). 5 periods (3.8 s, against 1 / (f_hi - f_lo) =
    0.5 s)."""
    n, calib, _ = _band_calibration(5, 12)
    assert n >= 20
    assert 0.75 < calib < 1.3


def test_band_prefilter_std_over_half_a_period_is_within_a_factor_2():
    """Half a period of band-passed noise leaves the residual ~0.16 degrees of freedom, so the
    noise level is rough and error/std heavy-tailed: RMS 1.4-2.3 over six seeds (2.8-3.0 in
    bench_precision with the noise-bandwidth rescaling this replaced; 0.98 with the true noise
    level), its robust scale (median |error/std| / 0.6745) 1.25-1.6."""
    n, rms, scale = _band_calibration(0.5, 16)
    assert n >= 100
    assert 0.9 < scale < 2.0
    assert rms < 2.6
