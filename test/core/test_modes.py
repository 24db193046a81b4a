# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""Several modes at once: the mode tracker (pure core, no rclpy)."""

import math
from pathlib import Path

import numpy as np
import pytest

from vib_estimator.core import COUNTER_NAMES, EstimatorConfig, FrequencyEstimator, create_estimator
from vib_estimator.core.modes import FINDER_COUNTERS, ModeTracker
from vib_estimator.io.csv_reader import read_csv_series

CFG = EstimatorConfig(modes=3, model='damped-sinusoid')
FS = 1000.0
REAL = (
    Path(__file__).resolve().parents[3] / 'shared' / 'real-data' / 'aluminium_cantilever_adxl357'
)


def decay(t, t0, f, amplitude, zeta=0.002, phase=0.4):
    """A damped sine starting at t0 (zero before)."""
    tt = np.maximum(t - t0, 0.0)
    w = 2 * np.pi * f
    return (t >= t0) * amplitude * np.exp(-zeta * w * tt) * np.sin(w * tt + phase)


def noise(t, std, seed):
    return std * np.random.default_rng(seed).standard_normal(len(t))


@pytest.mark.parametrize('seed', [0, 1, 2])
def test_a_single_mode_gives_one_mode_and_no_second(seed):
    t = np.arange(0, 12, 1 / FS)
    y = decay(t, 1.0, 12.0, 1.0) + noise(t, 0.003, seed)
    tr = ModeTracker(CFG)
    e = tr.process(t, y)
    assert len(e) > 100
    assert set(e.mode) == {1}
    assert np.median(np.abs(e.frequency_hz / 12 - 1)) < 0.003
    assert np.mean(np.abs(e.frequency_hz / 12 - 1) > 0.03) <= 0.02
    assert [s.mode for s in tr.status()] == [1]


@pytest.mark.parametrize('seed', [0, 1])
def test_two_modes_numbered_by_frequency(seed):
    t = np.arange(0, 8, 1 / FS)
    y = decay(t, 0.5, 8.0, 1.0) + decay(t, 0.5, 21.0, 0.3, 0.001) + noise(t, 0.003, seed)
    tr = ModeTracker(CFG)
    e = tr.process(t, y)
    late = e.t > 3.0  # once both are numbered
    for mode, f in ((1, 8.0), (2, 21.0)):
        sel = late & (e.mode == mode)
        assert np.sum(sel) > 10
        assert abs(np.median(e.frequency_hz[sel]) / f - 1) < 0.005
    status = tr.status()
    assert [s.mode for s in status] == [1, 2]
    assert status[0].band_hz[1] <= status[1].band_hz[0]  # the bands do not overlap
    assert set(tr.mode_counters()) == {1, 2}
    assert tr.counters['modes_found'] >= 2


@pytest.mark.parametrize('seed', [0, 1, 2])
def test_excited_modes_are_estimated_within_two_periods(seed):
    """Silence, then two modes: the first estimate of each lies within 2 % and comes less than 2
    periods of the lower one after the excitation (the scales go fast when the energy jumps)."""
    t = np.arange(0, 4, 1 / FS)
    y = decay(t, 1.0, 8.0, 1.0) + decay(t, 1.0, 21.0, 0.3, 0.001) + noise(t, 0.003, seed)
    e = ModeTracker(CFG).process(t, y)
    for f in (8.0, 21.0):
        near = np.abs(e.frequency_hz / f - 1) < 0.06
        assert abs(e.frequency_hz[near][0] / f - 1) < 0.02
        assert (e.t[near][0] - 1.0) * 8.0 < 2.0


def test_a_close_pair_is_estimated_within_two_periods():
    """Two modes 30 % apart (10 / 13 Hz, 1 : 0.5, SNR 30 dB for the weaker), 5 seeds: over the
    seeds the median time from the excitation to each mode's first estimate within 2 % is below 2
    periods of the lower one (the undamped refinement publishes from windows of 1.4 periods; the
    previous rule waited for 2.6) and the early estimates stay near a mode."""
    t = np.arange(0, 4, 1 / FS)
    firsts = []
    for seed in range(5):
        phases = np.random.default_rng(seed).uniform(0, 6.28, 2)
        y = (
            decay(t, 1.0, 10.0, 1.0, 0.003, phases[0])
            + decay(t, 1.0, 13.0, 0.5, 0.003, phases[1])
            + noise(t, 0.5 / math.sqrt(2) * 10**-1.5, seed)
        )
        e = ModeTracker(CFG).process(t, y)
        rel = np.abs(e.frequency_hz[:, None] / np.array([10.0, 13.0]) - 1)
        assert np.mean(np.min(rel, axis=1) > 0.03) <= 0.05
        firsts.append([(e.t[rel[:, k] < 0.02][0] - 1.0) * 10.0 for k in range(2)])
    assert np.all(np.median(firsts, axis=0) < 2.0)


@pytest.mark.parametrize('seed', [1013, 1023])
def test_a_close_pair_s_first_estimates_agree_with_the_poles_before_them(seed):
    """Two modes 15-42 % apart plucked together (16.9 / 19.4 Hz at 1 : 0.74 in 32 dB, 10.1 /
    14.3 Hz at 1 : 0.93 in 36 dB; zeta 0.7-0.8 %; ``modes`` 3): a close pair's first estimates
    come from the undamped refinement of short windows and must lie within
    ``CONSISTENCY_FIRST`` (3 %) of the pole before them, so every mode's first estimate is
    within 2 % of its true frequency (1.5 and 1.2 % at worst). At 1000x a merged pole of a
    window straddling both is published as a first estimate: 3.7 and 2.3 % off (a scratch
    sweep of 80 such pairs: the worst first estimate worse on 7, better on 1 by 0.01 %)."""
    rng = np.random.default_rng(seed)
    f1, ratio = rng.uniform(5, 20), rng.uniform(1.12, 1.45)
    a2, snr, zeta = rng.uniform(0.2, 1.0), rng.uniform(25, 40), rng.uniform(0.001, 0.01)
    phases = rng.uniform(0, 6.28, 2)
    t = np.arange(0, 4, 1 / FS)
    y = sum(
        (t >= 1.0)
        * a
        * np.exp(-zeta * 2 * np.pi * f * (t - 1.0))
        * np.sin(2 * np.pi * f * math.sqrt(1 - zeta**2) * (t - 1.0) + ph)
        for f, a, ph in ((f1, 1.0, phases[0]), (f1 * ratio, a2, phases[1]))
    )
    y = y + a2 / math.sqrt(2) * 10 ** (-snr / 20) * rng.standard_normal(len(t))
    e = ModeTracker(EstimatorConfig(modes=3)).process(t, y)
    rel = np.min(np.abs(e.frequency_hz[:, None] / np.array([f1, f1 * ratio]) - 1), axis=1)
    firsts = [rel[np.flatnonzero(e.mode == m)[0]] for m in np.unique(e.mode)]
    assert len(firsts) >= 2 and max(firsts) <= 0.02, firsts


def test_a_mode_appears_and_one_disappears():
    t = np.arange(0, 16, 1 / FS)
    first = decay(t, 0.5, 9.0, 1.0, 0.0) * (t < 7.0)  # stops at 7 s (into the noise)
    second = decay(t, 6.0, 30.0, 0.5, 0.0)  # starts at 6 s
    y = first + second + noise(t, 0.002, 5)
    tr = ModeTracker(CFG)
    e = tr.process(t, y)
    near9 = np.abs(e.frequency_hz / 9 - 1) < 0.02
    near30 = np.abs(e.frequency_hz / 30 - 1) < 0.02
    assert np.mean(near9 | near30) > 0.98
    assert np.sum(near9) > 30 and np.sum(near30) > 100
    assert e.t[near30].min() > 6.0 and e.t[near30].min() < 6.5  # picked up within 15 periods
    assert e.t[near9].max() < 7.5  # stops with the mode
    assert np.all(e.mode[near30 & (e.t > 9)] == 1)  # alone again: it is mode 1
    assert tr.counters['modes_lost'] >= 1
    assert [round(s.frequency_hz) for s in tr.status()] == [30]


def test_noise_alone_publishes_nothing():
    t = np.arange(0, 20, 1 / FS)
    tr = ModeTracker(CFG)
    e = tr.process(t, noise(t, 1.0, 3))
    assert len(e) == 0
    assert tr.status() == []
    assert set(COUNTER_NAMES) <= set(tr.counters) and tr.counters['estimates'] == 0


def test_harmonics_of_a_clipped_mode_are_no_modes():
    t = np.arange(0, 10, 1 / FS)
    y = np.clip(decay(t, 0.5, 11.0, 1.0, 0.001), -0.5, 0.5) + noise(t, 0.002, 4)
    tr = ModeTracker(CFG)
    e = tr.process(t, y)
    assert len(e) > 50
    assert set(e.mode) == {1}
    # while it is clipped hard the waveform is no sine: estimates up to ~3 % high, still mode 1
    assert np.all(np.abs(e.frequency_hz / 11 - 1) < 0.05)


def test_streaming_and_batch_give_the_same_floats():
    rng = np.random.default_rng(7)
    t = np.cumsum(rng.uniform(0.0008, 0.0012, 9000))
    y = decay(t, 0.3, 9.0, 1.0) + decay(t, 0.3, 25.0, 0.4) + noise(t, 0.003, 8) + 0.05
    y[1000] = np.nan
    t[2000] = t[1999]  # a duplicate stamp
    batch = ModeTracker(CFG)
    parts = [batch.process(t[:4000], y[:4000]), batch.process(t[4000:], y[4000:])]
    stream = ModeTracker(CFG)
    got = [e for a, b in zip(t, y) for e in stream.update(a, b)]
    freqs = np.concatenate([p.frequency_hz for p in parts])
    assert len(got) == len(freqs) > 20
    np.testing.assert_array_equal([e.frequency_hz for e in got], freqs)
    np.testing.assert_array_equal([e.mode for e in got], np.concatenate([p.mode for p in parts]))
    np.testing.assert_array_equal([e.t for e in got], np.concatenate([p.t for p in parts]))
    assert batch.counters == stream.counters
    assert batch.counters['skipped_non_finite'] == 1
    assert batch.counters['skipped_duplicate'] == 1
    assert len({e.mode for e in got}) == 2


def test_interface():
    assert isinstance(create_estimator(EstimatorConfig()), FrequencyEstimator)
    tr = create_estimator(EstimatorConfig(modes=2))
    assert isinstance(tr, ModeTracker) and tr.config.modes == 2
    with pytest.raises(ValueError):
        ModeTracker(EstimatorConfig())
    with pytest.raises(ValueError):
        tr.process(np.zeros(3), np.zeros(4))
    t = np.arange(0, 4, 1 / FS)
    tr.process(t, decay(t, 0.2, 10.0, 1.0))
    assert set(FINDER_COUNTERS) <= set(tr.counters)
    assert 'rejected_inconsistent' in tr.counters
    tr.reset()
    before = tr.counters['received']
    tr.restart()
    assert tr.status() == [] and tr.counters['received'] == before
    e = tr.process(t + 10, decay(t, 0.2, 10.0, 1.0))
    assert len(e) > 10 and math.isclose(np.median(e.frequency_hz), 10.0, rel_tol=0.003)


def test_plot_colours_the_modes(tmp_path):
    """Each mode is one series of its own colour and legend entry "mode k" in the frequency
    panel, and its frequency is marked on the spectrum; no estimate: nothing marked."""
    from vib_estimator.analysis.plotting import plot_estimates

    t = np.arange(0, 5, 1 / FS)
    y = decay(t, 0.5, 8.0, 1.0) + decay(t, 0.5, 21.0, 0.3, 0.001) + noise(t, 0.003, 0)
    e = ModeTracker(CFG).process(t, y)
    modes = sorted(set(e.mode.tolist()))
    assert modes[:2] == [1, 2]
    out = tmp_path / 'modes.png'
    fig = plot_estimates(str(out), t, y, e.t, e.frequency_hz, e.convergence_time, mode=e.mode)
    estimates, spectrum = fig.axes[1], fig.axes[3]
    series = {line.get_label(): line for line in estimates.get_lines()}
    assert set(series) == {'mode 1', 'mode 2'}
    assert series['mode 1'].get_color() != series['mode 2'].get_color()
    marks = sorted(float(line.get_xdata()[0]) for line in spectrum.get_lines()[1:])
    assert np.allclose(marks, [8.0, 21.0], rtol=0.01)
    fig = plot_estimates(
        str(tmp_path / 'none.png'),
        t,
        y,
        e.t[:0],
        e.frequency_hz[:0],
        e.convergence_time[:0],
        mode=e.mode[:0],
    )
    spectrum = fig.axes[3]
    assert [line.get_label() for line in spectrum.get_lines()] == ['Welch PSD']  # nothing marked


REFERENCE = {30: 16.360, 40: 9.392, 50: 6.054, 60: 4.268}
REAL_F2 = {50: 39.63, 60: 27.35}  # the authors' second modes (benchmarks/bench_modes.py)


@pytest.mark.skipif(not REAL.is_dir(), reason='../shared/real-data is not beside the repository')
@pytest.mark.parametrize('length', sorted(REFERENCE))
def test_real_beams_mode_1_without_a_band(length):
    f1 = REFERENCE[length]
    csv = read_csv_series(REAL / f'{length}cm_uniform_1000Hz.csv')
    raw = np.load(next(REAL.glob(f'raw_{length}cm_*.npy')))
    for t, y in ((csv.t, csv.y), (raw[0] - raw[0, 0], raw[1])):
        e = ModeTracker(CFG).process(t, y)
        m1 = e.frequency_hz[e.mode == 1]
        assert len(m1) > 100
        assert abs(np.median(m1) / f1 - 1) < 0.003
        # the other published estimates are higher modes of the beam (6.45 f1, 17-19 f1, ...):
        # at most 1 % of all lies neither near f1 nor above 5 f1
        r = e.frequency_hz / f1
        assert np.mean((np.abs(r - 1) > 0.03) & (r < 5)) <= 0.01
        others = e.frequency_hz[e.mode >= 2]
        near2 = np.abs(others / (6.45 * f1) - 1) < 0.03
        if length >= 50:  # the second mode rings for seconds on the longer beams
            assert np.sum(near2) > 50
            assert abs(np.median(others[near2]) / REAL_F2[length] - 1) < 0.02


def test_a_pole_that_moved_from_the_last_is_not_published():
    """``CONSISTENCY`` (1 %): a 5 Hz decay (zeta 1 %) with a 13 Hz one, ringing into white noise
    of 0.2: the poles of the noisy tail that moved more than 1 % from the mode's previous one are
    not published (``rejected_inconsistent``); what publishes stays within 3 % of 5 Hz, 77 %
    within 1 % (without the rule 4.1 %, 60 %)."""
    rng = np.random.default_rng(0)
    t = np.arange(int(8 * FS)) / FS
    y = np.exp(-0.01 * 2 * np.pi * 5 * t) * np.sin(2 * np.pi * 5 * t)
    y += 0.3 * np.exp(-0.02 * 2 * np.pi * 13 * t) * np.sin(2 * np.pi * 13 * t)
    y += 0.2 * rng.standard_normal((3, len(t)))[2]  # (the noise measured)
    tracker = create_estimator(EstimatorConfig(modes=2))
    est = tracker.process(t, y)
    err = np.abs(est.frequency_hz / 5.0 - 1)
    err = err[err < 0.1]
    assert len(err) >= 20 and err.max() < 0.03 and np.mean(err < 0.01) >= 0.7
    assert tracker.counters['rejected_inconsistent'] > 0


def test_a_stronger_mode_near_twice_a_weaker_one_is_no_harmonic():
    """``HARMONIC_RATIO`` (2): a pole near 2 f of a pole is a harmonic only when that pole is at
    least twice as strong; a 10.04 Hz mode (0.4 % from 2 x 5 Hz) twice as strong as the 5 Hz one
    is a mode of its own: both are found and numbered."""
    t = np.arange(0, 8, 1 / FS)
    y = decay(t, 0.5, 5.0, 0.5) + decay(t, 0.5, 10.04, 1.0) + noise(t, 0.003, 0)
    e = ModeTracker(CFG).process(t, y)
    late = e.t > 3.0
    for mode, f in ((1, 5.0), (2, 10.04)):
        sel = late & (e.mode == mode)
        assert np.sum(sel) > 10 and abs(np.median(e.frequency_hz[sel]) / f - 1) < 0.005


def test_a_clean_decay_publishes_from_windows_under_a_period():
    """``C_FAST``, ``DEV_MAX``, ``DEV_N``: on a clean decay of three separate modes (8 / 21 / 55
    Hz, 1 : 0.3 : 0.05, noise 52 dB under the weakest) each mode moves to its fast scale (at most
    one period of 8 Hz) once its poles there have kept within 0.5 % of the longer window's: the
    dominant mode's median window is under one of its periods (1.54 before the rule), every mode
    stays within 2 %, and the first estimates come as early as before."""
    t = np.arange(0, 11, 1 / FS)
    y = (
        decay(t, 1.0, 8.0, 1.0, 0.003)
        + decay(t, 1.0, 21.0, 0.3, 0.002)
        + decay(t, 1.0, 55.0, 0.05, 0.002)
        + noise(t, 0.05 / math.sqrt(2) * 10**-1.5, 0)
    )
    e = ModeTracker(EstimatorConfig(modes=3)).process(t, y)
    rel = e.frequency_hz[:, None] / np.array([8.0, 21.0, 55.0]) - 1
    near = np.argmin(np.abs(rel), axis=1)
    err = np.abs(rel[np.arange(len(e)), near])
    assert np.mean(err <= 0.02) >= 0.99
    periods = e.convergence_time[near == 0] * 8.0
    assert np.median(periods) <= 1.0
    for k in range(3):
        first = e.t[(near == k) & (err <= 0.02)][0]
        assert (first - 1.0) * 8.0 < 2.0


def test_a_clean_close_pair_publishes_from_windows_of_two_periods():
    """A close pair (10 / 13 Hz, 1 : 0.5, noise 52 dB under the weaker), not resolved under a
    period, moves to its fast scale of at most ``C_CAP`` (2) periods instead (its long windows hold
    2.8): the dominant mode's median window is under 2 of its periods (2.72 before), 99 % within
    2 %."""
    t = np.arange(0, 11, 1 / FS)
    y = (
        decay(t, 1.0, 10.0, 1.0, 0.003)
        + decay(t, 1.0, 13.0, 0.5, 0.003)
        + noise(t, 0.05 / math.sqrt(2) * 10**-1.5, 1)
    )
    e = ModeTracker(EstimatorConfig(modes=3)).process(t, y)
    rel = e.frequency_hz[:, None] / np.array([10.0, 13.0]) - 1
    near = np.argmin(np.abs(rel), axis=1)
    assert np.mean(np.abs(rel[np.arange(len(e)), near]) <= 0.02) >= 0.99
    assert np.median(e.convergence_time[near == 0] * 10.0) <= 2.0


@pytest.mark.parametrize('seed', [0, 1, 2])
def test_a_damped_mode_ringing_down_onto_an_offset_publishes_from_under_a_period(seed):
    """A 2.7 %-damped 1.86 Hz mode ringing down onto an offset of 0.3 (200 Hz, 42 dB): over the
    fast scale's window (under a period) an offset and the sinusoid are nearly collinear, and a
    fit of both scattered the poles there by 1.5-3 % from the longer window's, which the mode
    then kept (1.79 periods); analysed less the longer window's level, the fast window's poles
    keep within 0.5 % of it: the median window under a period (until the mode rings down to
    ~27 dB), 95 % within 2 % (the last few, in the noise, as before: 96-100 %)."""
    fs = 200.0
    t = np.arange(0, 30, 1 / fs)
    y = 0.3 + decay(t, 3.8, 1.86, 1.0, 0.027) + noise(t, 10 ** (-42 / 20) / math.sqrt(2), seed)
    e = ModeTracker(EstimatorConfig(modes=3)).process(t, y)
    assert len(e) > 20
    assert np.mean(np.abs(e.frequency_hz / 1.86 - 1) <= 0.02) >= 0.95
    assert np.median(e.convergence_time) * 1.86 <= 1.0


@pytest.mark.parametrize('seed', [0, 1, 2])
def test_a_noisy_mode_keeps_its_longer_window(seed):
    """``DEV_MAX`` from above: a 12 Hz decay at 30 dB, whose poles over a period scatter by
    ~0.6 %, keeps publishing mostly from its longer window: 99 % of its estimates within 2 %
    (every window under a period: 95-96 %)."""
    t = np.arange(0, 11, 1 / FS)
    y = decay(t, 1.0, 12.0, 1.0, 0.003, 1.0) + noise(t, 1 / math.sqrt(2) * 10**-1.5, seed)
    e = ModeTracker(CFG).process(t, y)
    assert len(e) > 100
    assert np.mean(np.abs(e.frequency_hz / 12.0 - 1) <= 0.02) >= 0.99


def test_a_weak_mode_near_a_multiple_of_a_strong_one_is_found_early():
    """A pole of the 8 Hz mode with under a cycle in a short window does not count (``C_TRACK``):
    its rough frequency's 7th multiple would make the weak 55 Hz mode (1 : 0.05, 1.8 % from
    56 Hz) a suspect harmonic in the short windows that find it first. Over 5 seeds the median
    time from the pluck to its first estimate within 2 % is under 0.13 s (94 ms; those poles
    counted: 165 ms)."""
    t = np.arange(0, 3, 1 / FS)
    first = []
    for seed in range(5):
        y = (
            decay(t, 1.0, 8.0, 1.0, 0.003)
            + decay(t, 1.0, 21.0, 0.3, 0.002)
            + decay(t, 1.0, 55.0, 0.05, 0.002)
            + noise(t, 0.05 / math.sqrt(2) * 10**-1.5, seed)
        )
        e = ModeTracker(EstimatorConfig(modes=3)).process(t, y)
        first.append(e.t[np.abs(e.frequency_hz / 55.0 - 1) <= 0.02][0] - 1.0)
    assert np.median(first) < 0.13, first


@pytest.mark.parametrize('seed', [0, 1, 2, 3, 4])
def test_a_merged_pole_gives_way_to_the_modes_it_hid(seed):
    """6 / 9 / 14 Hz at 1 : 0.5 : 0.2 (35 dB for the weakest): the first short windows after the
    excitation read merged poles (6.9 Hz: 14 Hz is its "harmonic"; 13.1-13.4 Hz: 14 Hz lies within
    DUPLICATE_TOL of it). One published once, or not yet, is lost as soon as a window as long
    sees poles on both sides of it and not it (``_unresolved``: seeds 0 and 3 fail without it);
    one not yet published claims the poles within DUPLICATE_TOL (seed 1 fails without it: the
    mode drifted to 15.1 Hz with the short windows' noisy poles and blocked 14.0 Hz as
    unresolved). 14 Hz is found within 3.5 periods of 6 Hz (before these rules: 4.87-5.15 on
    seeds 0-3), the others as before (at most 2.2)."""
    t = np.arange(0, 4, 1 / FS)
    tt = np.maximum(t - 1.0, 0.0)
    rng = np.random.default_rng(seed)
    y = np.zeros_like(t)
    for f, a, z in ((6.0, 1.0, 0.003), (9.0, 0.5, 0.003), (14.0, 0.2, 0.002)):
        w = 2 * np.pi * f
        y += a * np.exp(-z * w * tt) * np.sin(w * np.sqrt(1 - z * z) * tt + rng.uniform(0, 6.28))
    y = y * (t >= 1.0) + 0.2 / math.sqrt(2) * 10**-1.75 * rng.standard_normal(len(t))
    e = ModeTracker(EstimatorConfig(modes=3)).process(t, y)
    for f, most in ((6.0, 2.2), (9.0, 2.2), (14.0, 3.5)):
        ok = np.abs(e.frequency_hz / f - 1) < 0.02
        assert (e.t[ok][0] - 1.0) * 6.0 <= most, f'{f} Hz'


@pytest.mark.parametrize('fs', [500.0, 1000.0])
def test_modes_above_a_24th_of_the_sample_rate_are_tracked_and_numbered(fs):
    """30 and 48.5 Hz at 500 Hz (60 and 97 Hz at 1 kHz): the lowest mode lies above fs / 24, so
    even the shortest scale's window (48 samples) holds more than ``C_CAP`` periods of it. That
    scale publishes them (before: no scale did: 13 estimates, the modes found and lost 13 times
    over, each publishing only its first estimate). Every estimate carries its mode's number:
    the 30 Hz one's first estimate and the 48.5 Hz one's came in one analysis, the higher one
    first, and both read 1 before the numbers were given after the analysis."""
    t = np.arange(0, 4, 1 / fs)
    f1, f2 = 30.0 * fs / 500.0, 48.5 * fs / 500.0
    rng = np.random.default_rng(0)
    y = decay(t, 1.0, f1, 1.0, 0.002, rng.uniform(0, 6.28))
    y += decay(t, 1.0, f2, 0.5, 0.002, rng.uniform(0, 6.28)) + 0.01 * rng.standard_normal(len(t))
    tr = ModeTracker(EstimatorConfig(modes=3))
    e = tr.process(t, y)
    for f, number in ((f1, 1), (f2, 2)):
        near = np.abs(e.frequency_hz / f - 1) < 0.02
        assert np.sum(near) >= 100 and np.all(e.mode[near] == number)
    assert (
        np.mean(np.abs(e.frequency_hz / f1 - 1) < 0.02)
        + np.mean(np.abs(e.frequency_hz / f2 - 1) < 0.02)
        >= 0.98
    )
    assert tr.counters['modes_lost'] <= 3


@pytest.mark.parametrize('seed', [0, 1])
def test_a_mode_above_a_tenth_of_the_rate_rising_without_a_jump_is_found(seed):
    """``HOP_TOP``: above 0.1 fs only level 0 counts a pole, and without a jump in the input's
    energy (no wake) only its idle analyses look for new modes there. A 150 Hz sine of 0.6
    starting at 1.5 s beside a steady 10 Hz one of 1 (the blocks' energy up 36 %: no wake; no
    harmonic: 10 Hz not twice as strong) is found within 0.5 s (62 ms; those analyses 1000 times
    rarer: never) and tracked."""
    t = np.arange(0, 4, 1 / FS)
    y = np.sin(2 * np.pi * 10 * t) + 0.6 * np.sin(2 * np.pi * 150 * t) * (t >= 1.5)
    e = ModeTracker(CFG).process(t, y + noise(t, 0.003, seed))
    near = np.abs(e.frequency_hz / 150.0 - 1) < 0.02
    assert np.sum(near) > 100
    assert e.t[near][0] - 1.5 < 0.5


@pytest.mark.parametrize('seed', [0, 1])
def test_a_mode_above_a_tenth_of_the_rate_is_tracked_from_level_0(seed):
    """``NU_HI``: 10 and 150 Hz decays (0.5 : 1, the higher one never twice weaker: no
    harmonic). At level 1 150 Hz lies at 0.3 cycles per sample, on its anti-alias filter's edge,
    and at level 2 aliases to 100 Hz: counted there, the 150 Hz mode would publish from windows
    that no longer hold it (found and lost 18 times, 86 estimates). Only level 0 counts it: found
    once, never lost, 286 estimates."""
    t = np.arange(0, 4, 1 / FS)
    y = decay(t, 0.5, 10.0, 0.5) + decay(t, 0.5, 150.0, 1.0, 0.0002) + noise(t, 0.003, seed)
    tr = ModeTracker(CFG)
    e = tr.process(t, y)
    assert np.sum(np.abs(e.frequency_hz / 150.0 - 1) < 0.02) > 200
    assert tr.counters['modes_found'] == 2 and tr.counters['modes_lost'] == 0
    # its poles on the edge of levels 1-2 are counted (the counter was never incremented)
    alone = ModeTracker(CFG)
    alone.process(t, decay(t, 0.5, 10.0, 0.5) + noise(t, 0.003, seed))
    assert tr.counters['rejected_band_edge'] > alone.counters['rejected_band_edge'] + 10


@pytest.mark.parametrize('seed', [0, 1])
def test_a_noisy_close_pair_publishes_from_windows_under_three_periods(seed):
    """``C_CAP_CLOSE``: a close pair (10 / 13 Hz, 1 : 0.5, 30 dB for the weaker), too noisy for
    its fast scale, publishes from windows long enough to resolve it but no longer (2.72 periods
    of 10 Hz; with no cap 5.4 to 10.9: estimates that lag a change by a second): every estimate
    within 2 % of a mode and from a window under 3 periods."""
    t = np.arange(0, 8, 1 / FS)
    y = (
        decay(t, 1.0, 10.0, 1.0, 0.003, 0.3)
        + decay(t, 1.0, 13.0, 0.5, 0.003, 1.1)
        + noise(t, 0.5 / math.sqrt(2) * 10**-1.5, seed)
    )
    e = ModeTracker(CFG).process(t, y)
    rel = np.min(np.abs(e.frequency_hz[:, None] / np.array([10.0, 13.0]) - 1), axis=1)
    assert len(e) > 200 and np.mean(rel < 0.02) >= 0.99
    assert np.max(e.convergence_time) * 10.0 < 3.0


@pytest.mark.parametrize('seed', [0, 1])
def test_a_mode_near_a_high_multiple_of_a_stronger_one_is_no_harmonic(seed):
    """``MAX_HARMONIC`` (9): only the 2nd to 9th multiples of a stronger pole are suspect (a
    clipped mode's higher harmonics are too weak to count). A 60.4 Hz mode (1 : 0.1) 0.7 % from
    12 x 5 Hz is a mode: 170 estimates, none rejected as a harmonic (its 12th multiple suspect:
    20, 150 rejected)."""
    t = np.arange(0, 5, 1 / FS)
    y = decay(t, 1.0, 5.0, 1.0, 0.003) + decay(t, 1.0, 60.4, 0.1) + noise(t, 0.003, seed)
    tr = ModeTracker(CFG)
    e = tr.process(t, y)
    assert np.sum(np.abs(e.frequency_hz / 60.4 - 1) < 0.02) > 100
    assert tr.counters['rejected_harmonic'] <= 5


@pytest.mark.parametrize('seed', [0, 2])
def test_a_weak_mode_near_twice_a_strong_one_publishes_once_found(seed):
    """A 13.3 Hz mode at 0.13 of a 6.9 Hz one, 3.6 % from its double: its poles in the windows
    that find it (under ``SUSPECT_CYCLES`` cycles) are suspect harmonics, but the longer ones
    find it, and once found it is judged by ``HARMONIC_TOL`` alone: its publishing windows (2
    periods of 6.9 Hz: 3.9 of its cycles) are never that long. 132-142 estimates within 2 %
    over seeds 0-3; the suspect rule applied to them too (until 7 Dec 2026), 0-1 (145-170
    ``rejected_harmonic``); read as suspect at any length (``SUSPECT_CYCLES`` 1000 x), none."""
    t = np.arange(0, 8, 1 / FS)
    y = decay(t, 1.0, 6.9, 1.0, 0.0024) + decay(t, 1.0, 13.3, 0.13, 0.0022) + noise(t, 0.003, seed)
    e = ModeTracker(CFG).process(t, y)
    assert np.sum(np.abs(e.frequency_hz / 13.3 - 1) < 0.02) > 100


@pytest.mark.parametrize('seed', [0, 1])
def test_a_rough_pole_is_suspect_only_as_near_a_multiple_as_its_window_resolves(seed):
    """``SUSPECT_TOL`` (0.16 / cycles): a pole seen over c cycles is a suspect harmonic within
    0.16 / c of a multiple of a 3 x stronger one -- what a window of c cycles resolves. A 17 Hz
    mode at 0.2 of an 8 Hz one (6 % from its double) is found from its windows of 3-5 cycles:
    its first estimate 0.26 s after the pluck, seeds 0-3 (8 % at any length: 0.49-0.6 s; until
    7 Dec 2026, the found mode's estimates suspect too, none)."""
    t = np.arange(0, 4, 1 / FS)
    y = decay(t, 1.0, 8.0, 1.0, 0.002) + decay(t, 1.0, 17.0, 0.2, 0.002) + noise(t, 0.003, seed)
    e = ModeTracker(CFG).process(t, y)
    ok = np.abs(e.frequency_hz / 17.0 - 1) < 0.02
    assert np.any(ok) and e.t[ok][0] - 1.0 < 0.4


def test_a_mode_plucked_beside_a_weaker_one_near_half_its_frequency_is_no_suspect():
    """``SUSPECT_RATIO`` (3): a rough pole near a multiple of another is suspect only when that
    one is 3 x stronger. A 10.4 Hz mode plucked at 2.5 s beside a 5 Hz one ringing at half its
    amplitude (4 % from its double) is found from its first short windows: its first estimate
    0.2 s after the pluck (any pole suspect, ``SUSPECT_RATIO`` 0.001 x: 0.63 s, 20 rejected as
    harmonics)."""
    t = np.arange(0, 6, 1 / FS)
    y = decay(t, 0.5, 5.0, 0.5) + decay(t, 2.5, 10.4, 1.0) + noise(t, 0.003, 0)
    e = ModeTracker(CFG).process(t, y)
    ok = np.abs(e.frequency_hz / 10.4 - 1) < 0.02
    assert np.any(ok) and e.t[ok][0] - 2.5 < 0.4


@pytest.mark.parametrize('seed', [0, 1])
def test_a_gap_too_long_to_bridge_restarts_the_windows(seed):
    """``MAX_FILL`` (64 steps): 12 and 31 Hz ringing, 100 ms of samples missing at 3 s. A gap
    that long is not bridged by a straight line: the levels restart, and the modes publish again
    from windows that start after it, the short ones first: > 55 estimates in the 0.5 s after
    the gap, every one within 2 % (64-72 over seeds 0-9; bridged, the modes wait for their
    longer windows to clear the line: 42-45)."""
    t = np.arange(0, 4, 1 / FS)
    y = decay(t, 0.5, 12.0, 1.0, 0.001) + decay(t, 0.5, 31.0, 0.3, 0.001) + noise(t, 0.003, seed)
    keep = (t < 3.0) | (t >= 3.1)
    e = ModeTracker(CFG).process(t[keep], y[keep])
    err = np.min(np.abs(e.frequency_hz[:, None] / np.array([12.0, 31.0]) - 1), axis=1)
    assert np.all(err < 0.02)
    assert np.sum((e.t > 3.1) & (e.t < 3.6)) > 55
