# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""``survey``'s weighted summary (:mod:`vib_estimator.analysis.interval`): unbiased on damped
records, and its 95 % interval covers the truth, on independent and on overlapping estimates."""

import math

import numpy as np

from vib_estimator.analysis import interval as I
from vib_estimator.analysis import survey as S
from vib_estimator.core import EstimatorConfig, create_estimator
from vib_estimator.sim.signals import plucked_decays

DAYS = 40


def sliding_estimates(rng, duration=180.0, window=30.0, hop=1.0, sigma=0.01):
    """Estimates as the ambient estimator makes them: the mean of a white sequence (1 value per
    s, std ``sigma`` sqrt(window)) over a ``window`` slid by ``hop``: each estimate's std is
    ``sigma``, consecutive ones share ``1 - hop / window`` of their noise."""
    noise = rng.standard_normal(int(duration)) * sigma * math.sqrt(window)
    ends = np.arange(window, duration + hop / 2, hop)
    values = np.array([noise[int(e - window) : int(e)].mean() for e in ends])
    return values, np.full(len(ends), sigma), ends, np.full(len(ends), window)


def test_overlapping_estimates_are_counted_as_the_windows_they_are_worth():
    rng = np.random.default_rng(3)
    covered, naive = [], []
    for _ in range(400):
        x, s, t, span = sliding_estimates(rng)
        c = I.combine(x, s, t, span)
        covered.append(c.lo <= 0.0 <= c.hi)
        indep = I.combine(x, s, t)  # the same estimates taken as independent
        naive.append(indep.lo <= 0.0 <= indep.hi)
    assert 5.0 < c.n_eff < 6.5  # 180 s of 30 s windows: ~6, the first window's start lost
    assert np.mean(covered) >= 0.92
    assert np.mean(naive) < 0.75  # what treating them as independent would claim


def test_understated_stds_are_caught_by_the_scatter():
    rng = np.random.default_rng(4)
    covered = []
    for _ in range(300):
        x = 2.0 * rng.standard_normal(50)  # the estimates scatter twice their stds
        c = I.combine(x, np.ones(50), np.arange(50.0), np.full(50, 0.5))
        covered.append(c.lo <= 0.0 <= c.hi)
    assert c.birge > 2.0 and np.mean(covered) >= 0.9


def test_screen_and_edges():
    x = np.r_[np.full(20, 1.0) + 1e-4 * np.arange(20), 5.0]  # one spurious estimate
    c = I.combine(x, np.full(21, 1e-3), np.arange(21.0))
    assert c.kept == 20 and abs(c.value - 1.00095) < 1e-4
    assert math.isnan(I.combine(np.array([1.0]), np.array([0.1]), np.array([0.0])).lo)
    assert I.combine(np.array([np.nan]), np.array([0.1]), np.array([0.0])) == I.NOTHING
    no_std = I.combine(np.arange(10.0), np.full(10, np.nan), np.arange(10.0))
    assert no_std.lo < 4.5 < no_std.hi  # equal weights, the scatter's interval


def test_damped_days_unbiased_and_covered():
    """40 identical days of free decays (zeta 0.004): the survey's default summary of each day is
    within 0.05 % of the truth (median over days) and its interval holds it on >= 85 % of the days
    (95 % expected); the damping likewise covered."""
    config = EstimatorConfig(model=S.DEFAULT_MODEL)
    f0, zeta = 5.0, 0.004
    errors, f_in, z_in = [], [], []
    for day in range(DAYS):
        t, y = plucked_decays(100 + day, f0, zeta)
        est = create_estimator(config).process(t, y)
        row = S.summarise(est, np.ones(len(est), dtype=bool))
        errors.append(row['frequency_hz'] / f0 - 1)
        f_in.append(row['frequency_lo_hz'] <= f0 <= row['frequency_hi_hz'])
        z_in.append(row['damping_lo'] <= zeta <= row['damping_hi'])
    assert abs(np.median(errors)) < 5e-4
    assert np.mean(f_in) >= 0.85
    assert np.mean(z_in) >= 0.75


def test_summary_median_is_the_former_summary():
    t, y = plucked_decays(7)
    est = create_estimator(EstimatorConfig(model=S.DEFAULT_MODEL)).process(t, y)
    take = np.ones(len(est), dtype=bool)
    old = S.summarise(est, take, 'median')
    assert (old['frequency_hz'], old['frequency_lo_hz'], old['frequency_hi_hz']) == (
        S.median_interval(est.frequency_hz)
    )
    assert 'frequency_std_hz' not in old and old['damping'] == np.median(est.damping)
    new = S.summarise(est, take)
    assert new['frequency_median_hz'] == old['frequency_hz']
    assert new['damping_lo'] < new['damping'] < new['damping_hi']
    assert new['effective_estimates'] > 10
