# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""excitation = ambient: output-only identification of driven modes (seeded, tolerant)."""

import math

import numpy as np
import pytest

from vib_estimator.core import EstimatorConfig, FrequencyEstimator, create_estimator
from vib_estimator.core.ambient import AmbientEstimator
from vib_estimator.core.whittle import sdof_density, whittle_fisher, whittle_std
from vib_estimator.sim.ambient import ambient_record
from vib_estimator.sim.signals import fig1_signal

FS = 500.0
AMBIENT = EstimatorConfig(excitation='ambient', ambient_window_s=20.0)


def _run(modes, seed, duration=60.0, snr=26.0, config=AMBIENT):
    t, y, noise = ambient_record(duration, FS, modes, snr, seed)
    return AmbientEstimator(config).process(t, y), noise


@pytest.fixture
def one_second_hop(monkeypatch):
    """An analysis every second whatever the window (the mechanisms' tests count analyses)."""
    from vib_estimator.core import ambient

    monkeypatch.setattr(ambient, 'HOP_SHARE', 0.0)


def test_whittle_bound_matches_the_issue_figures():
    # 5 Hz, zeta 1 %, 26 dB: 0.40 % over 20 s, 0.23 % over 60 s (issue 20)
    noise = 10**-2.6
    rel = [whittle_std([(5.0, 0.01, 1.0)], noise, FS, int(T * FS))[0][0] / 5.0 for T in (20, 60)]
    assert rel[0] == pytest.approx(0.0040, rel=0.03)
    assert rel[1] == pytest.approx(0.0023, rel=0.03)


@pytest.mark.parametrize('noise', [1e-3, 0.1])
def test_fisher_over_active_bins_equals_the_full_sum(noise):
    """The bins left out carry no information on the modes (a pair far above the noise, and one
    whose skirts sink into it within a few half-widths: counting only the bins 10 x above the
    noise, its dampings' bounds were 13-28 % too large)."""
    modes, n = [(8.0, 0.01, 1.0), (8.8, 0.02, 0.5)], 6000
    w = 2 * math.pi * np.arange(1, (n + 1) // 2) / n
    theta = [x for m in modes for x in m] + [noise]

    def density(th):
        return th[-1] + sum(
            sdof_density(np.cos(w), *th[3 * j : 3 * j + 3], 1 / FS) for j in range(2)
        )

    s0 = density(theta)
    grads = []
    for i in range(len(theta)):
        hi, lo = list(theta), list(theta)
        h = 1e-6 * theta[i]
        hi[i] += h
        lo[i] -= h
        grads.append((density(hi) - density(lo)) / (2 * h) / s0)
    full = np.array(grads) @ np.array(grads).T
    fast = whittle_fisher(modes, noise, FS, n)
    cov_full, cov_fast = np.linalg.inv(full), np.linalg.inv(fast)
    np.testing.assert_allclose(
        np.diag(cov_fast)[[0, 1, 3, 4]], np.diag(cov_full)[[0, 1, 3, 4]], rtol=0.02
    )


def test_single_mode():
    est, _ = _run([(5.0, 0.01, 1.0)], seed=1)
    assert len(est) >= 9  # at 22 s (3 analyses a second apart confirm it), then every 4 s
    assert set(est.mode) == {1}
    err = np.abs(est.frequency_hz / 5.0 - 1)
    assert np.mean(err <= 0.02) >= 0.95 and err.max() < 0.05
    assert 0.5 < np.median(est.damping) / 0.01 < 2.0
    assert 0.5 < np.median(est.amplitude) < 1.5  # RMS of the modal response, variance 1
    assert np.all(est.convergence_time == pytest.approx(20.0, abs=0.01))  # the window used
    assert np.all(np.isfinite(est.frequency_std_hz)) and np.all(est.frequency_std_hz > 0)
    assert np.all(np.diff(est.t) >= 0.99)
    assert np.median(np.diff(est.t)) == pytest.approx(4.0)  # a fifth of the window


@pytest.mark.parametrize('factor', [0.001, 1000])
def test_a_pole_near_nyquist_is_not_published(monkeypatch, factor):
    """Poles above ``ssi.NU_MAX`` (0.45) of the sampling rate are dropped: a 47 Hz mode sampled
    at 100 Hz, where a real recorder's anti-alias filter bends it, is not published, the 10 Hz
    mode beside it is (26 estimates). At 1000x the 47 Hz mode is published too (and a 46 Hz
    one: 56 estimates); at 0.001x nothing is."""
    from vib_estimator.core import ssi

    t, y, _ = ambient_record(120.0, 100.0, [(10.0, 0.01, 1.0), (47.0, 0.01, 1.0)], 26.0, 3)

    def right():
        est = AmbientEstimator(AMBIENT).process(t, y)
        f = np.asarray(est.frequency_hz)
        return len(f) >= 10 and np.all(np.abs(f / 10.0 - 1) <= 0.02)

    assert right()
    monkeypatch.setattr(ssi, 'NU_MAX', ssi.NU_MAX * factor)
    assert not right()


def test_the_update_period_is_a_fifth_of_the_window_from_1_to_5_s():
    """Once its modes are confirmed, a window is analysed every fifth of its length, at least
    every second (a short window: an estimate a second) and at most every 5 s (a long window on a
    short record still gives estimates enough): 4 s -> 1 s, 20 s -> 4 s, 40 s -> 5 s. A 30 s
    window every second cost ~310x real time per 500 Hz channel; every 5 s ~1100x."""
    fs = 100.0
    t, y, _ = ambient_record(100.0, fs, [(5.0, 0.01, 1.0)], 26.0, 2)
    for window, hop in ((4.0, 1.0), (20.0, 4.0), (40.0, 5.0)):
        config = EstimatorConfig(excitation='ambient', ambient_window_s=window)
        est = AmbientEstimator(config).process(t, y)
        assert len(est) >= 10 and np.median(np.diff(est.t)) == pytest.approx(hop), window


def test_two_modes_numbered_by_frequency():
    est, _ = _run([(5.0, 0.01, 1.0), (17.0, 0.005, 0.3)], seed=2, snr=22.0)
    assert set(est.mode) == {1, 2}
    for mode, f in ((1, 5.0), (2, 17.0)):
        err = np.abs(est.frequency_hz[est.mode == mode] / f - 1)
        assert np.mean(err <= 0.02) >= 0.95, mode


def test_close_pair_resolved():
    est, _ = _run([(8.0, 0.01, 1.0), (8.8, 0.01, 0.8)], seed=0)
    for mode, f in ((1, 8.0), (2, 8.8)):
        f_mode = est.frequency_hz[est.mode == mode]
        assert len(f_mode) >= 8 and abs(np.median(f_mode) / f - 1) < 0.01, mode


def test_a_mode_that_appears_above_a_published_one_is_published():
    """A 40 Hz mode that starts at 30 s above a 5 Hz mode published since 22 s: the full-rate
    search that finds it (one analysis in ``SEARCH_EVERY``) is followed by analyses at a rate
    that keeps it, a second apart, until it is confirmed (8 analyses running beside a published
    mode): first published at 41 s (seeds 0-2), then every 4 s; before the fix, never (the
    analyses between two searches ran at the 5 Hz mode's rate, where 40 Hz is out of band, so
    it was never seen 8 running). The 5 Hz mode keeps its accuracy at the faster rate."""
    from vib_estimator.sim.ambient import sdof_response

    rng = np.random.default_rng(0)
    n = int(80 * FS)
    t = np.arange(n) / FS
    y = sdof_response(n, FS, 5.0, 0.01, 1.0, rng)
    late = t >= 30.0
    y[late] += sdof_response(int(late.sum()), FS, 40.0, 0.01, 1.0, rng)
    y += 10**-1.3 * rng.standard_normal(n)
    est = AmbientEstimator(AMBIENT).process(t, y)
    high = np.abs(est.frequency_hz / 40.0 - 1) < 0.02
    assert high.sum() >= 9 and est.t[high][0] <= 50.0
    assert set(est.mode[high]) == {2}
    low = est.mode == 1
    assert np.mean(np.abs(est.frequency_hz[low] / 5.0 - 1) <= 0.02) >= 0.95


def test_the_full_rate_search_runs_in_one_analysis_in_five(monkeypatch):
    """Once a mode is published, an analysis identifies at its mode's rate (one SSI pass); one in
    five also searches the full rate for a higher mode first (a second pass, which costs as much):
    on a 5 Hz record 18 passes in 13 analyses (the first 3, which confirm the mode, all search; a
    search at every analysis: 26; at none, a mode appearing above the published one is never
    found, as the test above checks)."""
    from vib_estimator.core import ssi

    passes = []
    modes_at = ssi.modes_at
    monkeypatch.setattr(ssi, 'modes_at', lambda *a: passes.append(1) or modes_at(*a))
    t, y, _ = ambient_record(60.0, FS, [(5.0, 0.01, 1.0)], 26.0, 1)
    estimator = AmbientEstimator(AMBIENT)
    est = estimator.process(t, y)
    analyses = estimator.counters['analyses']
    assert len(est) >= 9
    assert analyses < len(passes) <= 1.5 * analyses + 1, (len(passes), analyses)


def _wandering(seed, steps, rel, step_s, steady_s=0.0, fs=100.0):
    """A 5 Hz mode (zeta 1 %, 26 dB) whose frequency is ``5 (1 + rel x_k)`` over its k-th
    ``step_s`` stretch (``x_k``: ``rel`` a float, standard normal draws; a str, +-1 in turn),
    then 5 Hz for ``steady_s``."""
    from vib_estimator.sim.ambient import sdof_response

    rng = np.random.default_rng(seed)
    n = int(step_s * fs)
    x = rng.standard_normal(steps) if isinstance(rel, float) else (-1.0) ** np.arange(steps)
    rel = float(rel)
    parts = [sdof_response(n, fs, 5.0 * (1 + rel * xk), 0.01, 1.0, rng) for xk in x]
    parts.append(sdof_response(int(steady_s * fs), fs, 5.0, 0.01, 1.0, rng))
    y = np.concatenate(parts)
    return np.arange(len(y)) / fs, y + 10**-1.3 * rng.standard_normal(len(y))


def test_frequency_std_is_calibrated():
    """RMS of error / own std. On a stationary record the Whittle stds are nearly right; on one
    whose mode moves by +-1.2 % every 20 s window (a structure whose temperature moves), they
    are about half the scatter (RMS 1.9-2.7 uncalibrated, 2.1-2.3 on seeds 0-1): the
    calibration against the mode's own earlier estimates (``HISTORY_WINDOWS``) brings it to
    1.2-1.9 (1.2 on seeds 0-1). Consecutive windows overlap (few independent values): the bands
    are wide."""

    def rms_z(records):
        z = []
        for t, y in records:
            est = AmbientEstimator(AMBIENT).process(t, y)
            z.extend((est.frequency_hz - 5.0) / est.frequency_std_hz)
        return math.sqrt(np.mean(np.square(z)))

    stationary = [ambient_record(60.0, FS, [(5.0, 0.01, 1.0)], 26.0, s)[:2] for s in (3, 4)]
    assert 0.4 < rms_z(stationary) < 2.5
    assert 0.6 < rms_z([_wandering(s, 8, '0.012', 20.0) for s in (0, 1)]) < 1.65


def test_std_calibration_forgets_an_earlier_stretch(one_second_hop):
    """The calibration reads the mode's estimates of the last ``HISTORY_WINDOWS`` (4) windows
    only: 85 s after a stretch whose mode alternated by +-1.4 % every window, the stds are
    those of an estimator started after that stretch (remembered, 0.98-1.35 x theirs)."""
    t, y = _wandering(2, 5, '0.014', 20.0, steady_s=120.0)
    after = t >= 100.0
    whole = AmbientEstimator(AMBIENT).process(t, y)
    fresh = AmbientEstimator(AMBIENT).process(t[after], y[after])
    late_w, late_f = whole.t >= 205.0, fresh.t >= 205.0
    assert late_w.sum() >= 15
    np.testing.assert_array_equal(whole.t[late_w], fresh.t[late_f])
    np.testing.assert_allclose(whole.frequency_hz[late_w], fresh.frequency_hz[late_f], rtol=1e-9)
    np.testing.assert_allclose(
        whole.frequency_std_hz[late_w], fresh.frequency_std_hz[late_f], rtol=1e-6
    )


def test_streaming_equals_batch_and_bad_samples_are_counted():
    t, y, _ = ambient_record(26.0, FS, [(5.0, 0.01, 1.0)], 26.0, 5)
    y = y.copy()
    y[3000] = np.nan
    t = np.delete(t, 5000)
    y = np.delete(y, 5000)
    t[7000] = t[6999]  # a duplicate stamp
    batch = AmbientEstimator(AMBIENT)
    b = batch.process(t, y)
    stream = AmbientEstimator(AMBIENT)
    s = [e for ti, yi in zip(t, y) for e in stream.update(ti, yi)]
    assert len(b) == len(s) > 0
    np.testing.assert_array_equal(b.frequency_hz, [e.frequency_hz for e in s])
    assert batch.counters == stream.counters
    c = batch.counters
    assert c['skipped_non_finite'] == 1 and c['skipped_duplicate'] == 1
    assert c['received'] == len(t) and c['used'] == len(t) - 2
    assert np.all(np.isfinite(b.frequency_hz)) and np.all(np.isfinite(b.damping))


def test_gap_starts_a_new_window():
    t, y, _ = ambient_record(55.0, FS, [(5.0, 0.01, 1.0)], 26.0, 6)
    t = np.where(t > 27.0, t + 5.0, t)  # a 5 s gap
    est = AmbientEstimator(AMBIENT)
    e = est.process(t, y)
    assert est.counters['gap_resets'] == 1
    assert np.any(e.t < 27.0) and np.any(e.t > 52.0)
    # no window straddles the gap: the first estimate after it comes a window after it
    assert not np.any((e.t > 27.0) & (e.t < 52.0))


def test_reset_starts_a_new_window():
    t, y, _ = ambient_record(40.0, FS, [(5.0, 0.01, 1.0)], 26.0, 7)
    half = FS * 25  # 25 s
    kept, reset = AmbientEstimator(AMBIENT), AmbientEstimator(AMBIENT)
    for est in (kept, reset):
        est.process(t[: int(half)], y[: int(half)])
    reset.reset()
    assert len(kept.process(t[int(half) :], y[int(half) :])) > 0
    assert len(reset.process(t[int(half) :], y[int(half) :])) == 0  # 15 s < the window


def test_factory_and_free_unchanged():
    assert isinstance(create_estimator(AMBIENT), AmbientEstimator)
    assert isinstance(create_estimator(EstimatorConfig()), FrequencyEstimator)
    t = np.arange(0, 20, 1e-3)
    y = fig1_signal(t)
    ref = FrequencyEstimator(EstimatorConfig()).process(t, y)
    free = create_estimator(EstimatorConfig(excitation='free', ambient_window_s=99.0)).process(
        t, y
    )
    assert len(ref) > 0
    np.testing.assert_array_equal(ref.frequency_hz, free.frequency_hz)
    np.testing.assert_array_equal(ref.frequency_std_hz, free.frequency_std_hz)


def test_config_validation():
    with pytest.raises(ValueError, match='excitation'):
        EstimatorConfig(excitation='driven').validate()
    with pytest.raises(ValueError, match='ambient_window_s'):
        EstimatorConfig(excitation='ambient', ambient_window_s=0.5).validate()


@pytest.mark.parametrize('excitation, level', [('ambient', 0.02), ('random', 0.3)])
def test_driven_arm(excitation, level):
    from vib_estimator.sim.arm_model import simulate_driven

    rec = simulate_driven(45.0, excitation, level, seed=2)
    est = AmbientEstimator(AMBIENT).process(rec.t, rec.torque)
    f0 = rec.f_true[0]
    assert len(est) >= 6  # (22-25 s in, then every 4 s: 7 and 11)
    err = np.abs(est.frequency_hz / f0 - 1)
    assert np.median(err) < 0.01 and np.mean(err <= 0.02) >= 0.9


def test_mode_counters_count_each_modes_estimates():
    t, y, _ = ambient_record(40.0, FS, [(5.0, 0.01, 1.0), (17.0, 0.005, 0.3)], 25.0, 8)
    est = AmbientEstimator(AMBIENT)
    e = est.process(t, y)
    counts = est.mode_counters()
    assert sorted(counts) == sorted(set(e.mode)) == [1, 2]
    assert sum(c['estimates'] for c in counts.values()) == len(e) == est.counters['estimates']


def test_modes_limits_to_the_strongest():
    t, y, _ = ambient_record(40.0, FS, [(5.0, 0.01, 1.0), (17.0, 0.005, 0.05)], 25.0, 9)
    both = AmbientEstimator(AMBIENT).process(t, y)
    one = AmbientEstimator(AMBIENT.replace(modes=1)).process(t, y)
    assert set(both.mode) == {1, 2}
    assert set(one.mode) == {1} and np.all(np.abs(one.frequency_hz / 5.0 - 1) < 0.02)


def test_a_record_too_slow_to_decimate_is_identified_at_every_analysis():
    """At 20 Hz the modes at 2 and 6 Hz leave no halving to make: the analyses that do not search
    (4 in 5) identify at the input rate instead of finding nothing."""
    t, y, _ = ambient_record(180, 20.0, [(2.0, 0.01, 1.0), (6.0, 0.01, 0.5)], 25, seed=1)
    estimator = AmbientEstimator(EstimatorConfig(excitation='ambient', ambient_window_s=30.0))
    est = estimator.process(t, y)
    analyses = estimator.counters['analyses']
    for f in (2.0, 6.0):
        near = np.abs(est.frequency_hz / f - 1) < 0.03
        assert near.sum() >= 0.8 * analyses, (f, near.sum(), analyses)
        assert abs(np.median(est.frequency_hz[near]) / f - 1) < 0.01


def test_a_strong_mode_found_after_a_weaker_one_publishes_in_a_short_record():
    """A 20 s record of 5 Hz (variance 1) and 17 Hz (0.3) through 10 s windows: 9 analyses.
    When the 17 Hz mode publishes first, the stronger 5 Hz mode beside it is a mode, not a
    statistical pole (``identity.ModeRegister.need``): it publishes after 3 analyses, not 8 --
    which this record does not have (seed 0: the 5 Hz mode was never published)."""
    config = EstimatorConfig(excitation='ambient', ambient_window_s=10.0)
    for seed in (0, 1):
        t, y, _ = ambient_record(20, 500, [(5.0, 0.01, 1.0), (17.0, 0.005, 0.3)], 20, seed)
        f = AmbientEstimator(config).process(t, y).frequency_hz
        for mode in (5.0, 17.0):
            assert np.sum(np.abs(f / mode - 1) < 0.02) >= 3, (seed, mode, f)
        assert np.all((np.abs(f / 5.0 - 1) < 0.05) | (np.abs(f / 17.0 - 1) < 0.05)), f


def test_a_long_window_s_statistical_poles_beside_a_mode_are_not_published():
    """``BESIDE_SHARE``: 600 s of 0.7 + 2.3 Hz at 100 Hz through the default's 171 s window
    (120 periods of 0.7 Hz). Consecutive windows share most of their samples: with 8 analyses
    running beside the published modes (``CONFIRM_BESIDE`` alone), poles at 2.46 Hz (seed 1)
    and 2.1 Hz (seed 2) published 5-6 estimates; with analyses spanning a quarter of the window
    (43), none. Both true modes keep publishing throughout."""
    config = EstimatorConfig(excitation='ambient', ambient_window_s=171.4)
    for seed in (1, 2):
        t, y, _ = ambient_record(600, 100, [(0.7, 0.01, 1.0), (2.3, 0.01, 0.3)], 20, seed)
        f = AmbientEstimator(config).process(t, y).frequency_hz
        near = [np.abs(f / mode - 1) < 0.02 for mode in (0.7, 2.3)]
        assert np.all(near[0] | near[1]), (seed, f[~(near[0] | near[1])])
        assert min(np.sum(near[0]), np.sum(near[1])) >= 80, (seed, len(f))


def test_publication_rule_scripted(monkeypatch, one_second_hop):
    """The identity rule alone (ambient.identify scripted per analysis): the first mode publishes
    after 3 analyses (``CONFIRM``); a published one missing from one analysis publishes again as
    soon as it is seen; a pole beside a published mode publishes only after 8 analyses running
    (``CONFIRM_BESIDE``; shorter runs: a coloured excitation's statistical poles, which last 1-8
    analyses, never publish). The expectations are the documented figures, not the constants."""
    from vib_estimator.core import ambient
    from vib_estimator.core.ssi import WindowModes

    confirm, beside = 3, 8
    short = range(10, 10 + beside - 1)  # one analysis too few
    long = range(30, 30 + beside + 4)
    calls = []

    def scripted(cascade, fs, *args):
        k = len(calls) + 1  # the analysis' number
        calls.append(k)
        rows = [] if k == 6 else [(5.0, 0.01, 1.0, 0.01, 0.001)]
        rows += [(7.0, 0.01, 0.1, 0.01, 0.001)] if k in short else []
        rows += [(9.0, 0.01, 0.1, 0.01, 0.001)] if k in long else []
        rows = np.array(rows).reshape(-1, 5)
        ones = np.ones((len(rows), 1))
        modes = WindowModes(*rows[:, :2].T, rows[:, 2:3], *rows[:, 3:].T, ones + 0j, 0 * ones)
        return modes, 1.5

    monkeypatch.setattr(ambient, 'identify', scripted)
    fs = 100.0
    t = np.arange(0, 70, 1 / fs)
    est = AmbientEstimator(AMBIENT).process(t, np.random.default_rng(0).standard_normal(len(t)))
    n = len(calls)
    assert n >= 45
    # the analysis of each estimate, from its stamp (one a second, the window's 20 s first)
    k = np.round(est.t - AMBIENT.ambient_window_s).astype(int) + 1
    by_f = {f: k[est.frequency_hz == f].tolist() for f in (5.0, 7.0, 9.0)}
    assert by_f[5.0] == [j for j in range(confirm, n + 1) if j != 6]
    assert by_f[7.0] == []
    assert by_f[9.0] == list(range(long[0] + beside - 1, long[-1] + 1))
    # numbered by frequency among the published: the 9 Hz mode is 2 while both publish
    assert set(est.mode[est.frequency_hz == 9.0]) == {2}
    assert set(est.mode[est.frequency_hz == 5.0]) == {1}


def test_memory_is_flat_over_a_long_stream(one_second_hop):
    """Memory stays flat however long the stream (issue 20: an hour of input), through ``auto``
    (the identifier, the free-decay estimator, the envelope and its test): once numpy's and
    scipy's own caches have filled (the first ~600 analyses), ten more minutes of input (600
    analyses) add less than 32 bytes per analysis -- a buffer, history or list that kept every
    sample, estimate or analysis would add at least 2 MB, 100 kB or 34 kB (a 2-tuple, 56 bytes,
    each). (The Fourier cosines' cache, at most 16 window lengths, is emptied, and the cyclic
    garbage collected, before each reading.) What those ten minutes do add is a fill that slows
    down, not a leak (4 Dec, the same stream on to 90 minutes, per ten from the tenth: 9.7, 3.5,
    3.6, 2.5, 1.7, 1.6, 1.5, 0.9 kB); after the rest of the suite, without the collection, it
    read 10.5 kB, beyond the 16 bytes per analysis (9.6 kB) this test first allowed."""
    import gc
    import tracemalloc

    from vib_estimator.core import create_estimator, whittle

    fs, block = 200.0, 60.0
    est = create_estimator(EstimatorConfig(excitation='auto', ambient_window_s=30.0))
    t, y, _ = ambient_record(block, fs, [(5.0, 0.01, 1.0), (17.0, 0.005, 0.3)], 25.0, 3)
    tracemalloc.start()
    try:
        used = []
        for k in range(20):
            estimates = est.process(t + k * block, y)
            assert k == 0 or len(estimates) >= 100  # two modes a second
            whittle.fourier_cosines.cache_clear()
            gc.collect()
            used.append(tracemalloc.get_traced_memory()[0])
    finally:
        tracemalloc.stop()
    analyses = 10 * block  # one a second, the last ten blocks
    assert used[-1] - used[9] < 32 * analyses, [u - used[9] for u in used]


def test_samples_fed_one_at_a_time_between_batches_resets_and_gaps_are_the_streams():
    # samples fed alone wait in a list until an analysis is due: a batch, a reset or a gap in
    # between must see them where the buffer would have held them
    t, y, _ = ambient_record(100.0, FS, [(5.0, 0.01, 1.0)], 26.0, 8)
    t = np.where(t > 70.0, t + 5.0, t)  # a gap (in a batch): a new window
    cut = np.searchsorted(t, [13.3, 31.7, 44.1, 66.9, 72.0])
    streamed, mixed = AmbientEstimator(AMBIENT), AmbientEstimator(AMBIENT)
    want, got = [], []
    for k, (a, b) in enumerate(zip((0, *cut), (*cut, len(t)))):
        if k == 3:  # a reset after samples fed alone
            streamed.reset()
            mixed.reset()
        want += [e.frequency_hz for ti, yi in zip(t[a:b], y[a:b]) for e in streamed.update(ti, yi)]
        if k % 2:
            got += mixed.process(t[a:b], y[a:b]).frequency_hz.tolist()
        else:
            got += [e.frequency_hz for ti, yi in zip(t[a:b], y[a:b]) for e in mixed.update(ti, yi)]
    assert len(want) >= 6
    assert got == want
    assert mixed.counters == streamed.counters


def test_a_mode_too_weak_to_tell_within_2_percent_is_not_published():
    """A 1 Hz mode at zeta 3 % over 10 s windows (10 periods, 2 correlation times) in 10 dB of
    noise: its predicted frequency std is 2.4-3.3 %, its estimates would err by up to 3 %: none
    is published, each counted ``rejected_uncertain``."""
    t, y, _ = ambient_record(60.0, 50.0, [(1.0, 0.03, 1.0)], 10.0, 0)
    est = AmbientEstimator(EstimatorConfig(excitation='ambient', ambient_window_s=10.0))
    assert len(est.process(t, y)) == 0
    assert est.counters['rejected_uncertain'] > 10


def test_a_mode_on_a_large_offset_is_no_flat_window():
    """A position in a world frame: a 2 Hz mode of 1 mm RMS on an offset of 1e7 m (RMS 1e-10 of
    the mean, 7 digits above float64's rounding) is identified; a window is constant only to
    rounding (its RMS within 1e-12 of its mean: at 1e-9 every window here read flat)."""
    t, y, _ = ambient_record(60.0, 50.0, [(2.0, 0.01, 1.0)], 26.0, 0)
    est = AmbientEstimator(EstimatorConfig(excitation='ambient', ambient_window_s=20.0))
    e = est.process(t, 1e7 + 1e-3 * y)
    assert len(e) >= 5 and abs(np.median(e.frequency_hz) / 2.0 - 1) < 0.02
    assert est.counters['flat_windows'] == 0


def _mode_beside_a_line(seconds=120.0):
    """A 5 Hz mode driven by noise and a drive's line at 3 Hz (a sinusoid, the identifier reads
    it as a mode in some windows)."""
    t, y, _ = ambient_record(seconds, 100.0, [(5.0, 0.01, 1.0)], 30, 2)
    return t, y + 0.3 * np.sin(2 * np.pi * 3.0 * t)


@pytest.mark.parametrize('factor', [None, 0.001, 1000])
def test_modes_at_a_drive_s_lines_are_dropped(monkeypatch, factor):
    """``lines_hz``: the identifier drops a mode within LINE_TOL of a line (the decision's line,
    refined to ~0.1 %: here 0.3 % off), counted ``rejected_line``; the mode beside it stays.
    LINE_TOL at 0.001x keeps the line, at 1000x drops the mode too."""
    from vib_estimator.core import ambient

    t, y = _mode_beside_a_line()
    config = EstimatorConfig(excitation='ambient', ambient_window_s=20.0)
    plain = create_estimator(config).process(t, y)
    assert np.any(np.abs(plain.frequency_hz / 3.0 - 1) < 0.001)  # the line, read as a mode
    if factor is not None:
        monkeypatch.setattr(ambient, 'LINE_TOL', ambient.LINE_TOL * factor)
    est = create_estimator(config.replace(lines_hz=[3.0 * 1.003])).process(t, y)
    at_line = np.abs(est.frequency_hz / 3.0 - 1) < 0.01
    at_mode = np.abs(est.frequency_hz / 5.0 - 1) < 0.02
    # the mode at every analysis: a fifth of the window apart after the first window
    dropped = not np.any(at_line) and np.sum(at_mode) >= (t[-1] - 20.0) / 4.0
    assert dropped == (factor is None)


def test_lines_hz_is_validated():
    assert EstimatorConfig().replace(lines_hz=[1, 3.0]).lines_hz == (1, 3.0)
    for bad in ([0.0], [math.nan], [-1.0]):
        with pytest.raises(ValueError, match='lines_hz'):
            EstimatorConfig().replace(lines_hz=bad)


def test_cluster_medians_are_numpy_s():
    """ssi.medians: numpy.median's floats over the rows (odd and even counts, NaN, ties)."""
    from vib_estimator.core.ssi import medians

    rng = np.random.default_rng(3)
    for rows in range(1, 12):
        a = rng.standard_normal((rows, 5))
        a[:, 1] = np.round(a[:, 1])
        a[rng.integers(0, rows), 2] = np.nan
        a[:, 3] = [math.inf, -math.inf, 1.0, 0.0][rows % 4]
        want = np.median(a, axis=0)
        got = medians(a)
        assert np.array_equal(got, want, equal_nan=True)
        assert np.all(np.signbit(got[~np.isnan(got)]) == np.signbit(want[~np.isnan(want)]))
