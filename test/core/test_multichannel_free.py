# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""Joint free-decay estimation of several channels (seeded, tolerant)."""

import math

import numpy as np
import pytest

from vib_estimator.core import EstimatorConfig, create_estimator
from vib_estimator.core.multichannel_free import JointFreeEstimator, joint_fit
from vib_estimator.core.shapes import mac

FS = 500.0
NAMES = ('a', 'b', 'c')
SHAPE = np.array([1.0, -0.6, 0.2])


def decay(f, zeta, seconds=6.0, phase=0.3):
    t = np.arange(int(seconds * FS)) / FS
    wn = 2 * math.pi * f
    return t, np.exp(-zeta * wn * t) * np.sin(wn * math.sqrt(1 - zeta**2) * t + phase)


def plucked(seed, noise=0.02, f=5.0, zeta=0.01):
    """One mode of shape SHAPE on three channels, white noise of ``noise`` on each."""
    t, y = decay(f, zeta)
    rng = np.random.default_rng(seed)
    return t, y[:, None] * SHAPE + noise * rng.standard_normal((len(t), len(SHAPE)))


def rms(x):
    return math.sqrt(float(np.mean(np.square(x))))


def test_noiseless_fit_is_exact():
    t, y = decay(5.0, 0.01, seconds=0.3)
    u = t - t.mean()
    fit = joint_fit(u, y[:, None] * SHAPE, [2 * math.pi * 5.1], [0.0])
    wn = 2 * math.pi * 5.0
    assert fit.omega == pytest.approx(wn * math.sqrt(1 - 1e-4), rel=1e-9)
    assert fit.sigma == pytest.approx(0.01 * wn, rel=1e-6)
    assert mac(fit.amplitudes, SHAPE) == pytest.approx(1.0, abs=1e-12)


@pytest.mark.parametrize(
    'config',
    [EstimatorConfig(), EstimatorConfig(model='damped-sinusoid')],
    ids=['default', 'damped'],
)
def test_joint_beats_the_best_channel_and_its_std_is_calibrated(config):
    """Ten seeds: the joint RMS error is at most the best channel's alone (measured 0.40 against
    0.50 % default, 0.39 against 0.44 % damped) and the CRB std is calibrated (1.09, 1.14)."""
    joint, z, single = [], [], [[] for _ in NAMES]
    for seed in range(10):
        t, y = plucked(seed)
        est = create_estimator(config, NAMES).process(t, y).estimates
        joint += list(est.frequency_hz / 5.0 - 1)
        z += list((est.frequency_hz - 5.0) / est.frequency_std_hz)
        for c in range(len(NAMES)):
            single[c] += list(create_estimator(config).process(t, y[:, c]).frequency_hz / 5.0 - 1)
    assert len(joint) >= 150
    assert rms(joint) <= min(rms(s) for s in single)
    assert 0.8 <= rms(z) <= 1.4


def test_shape_damping_and_mode_identity():
    t, y = plucked(3)
    result = create_estimator(EstimatorConfig(), NAMES).process(t, y)
    est = result.estimates
    assert len(result) > 10 and set(est.mode.tolist()) == {1}
    assert np.all([mac(s, SHAPE) > 0.995 for s in result.shapes])
    assert np.all(np.abs(result.shapes[:, 0].imag) < 1e-12) and np.all(
        result.shapes[:, 0].real > 0
    )
    assert math.isnan(result.mac[0]) and np.all(result.mac[1:] > 0.99)
    assert np.median(est.damping) == pytest.approx(0.01, rel=0.15)
    assert np.all(result.shape_std > 0) and np.all(result.shape_std < 0.05)


def test_a_mode_invisible_on_some_channels_is_found_on_the_others():
    """5 Hz on channels a and b only, 17 Hz on c only: both modes, each with its true shape."""
    t, low = decay(5.0, 0.01)
    _, high = decay(17.0, 0.005, phase=1.0)
    shapes = {5.0: np.array([1.0, 0.7, 0.0]), 17.0: np.array([0.0, 0.0, 1.0])}
    y = low[:, None] * shapes[5.0] + 0.5 * high[:, None] * shapes[17.0]
    y += 0.01 * np.random.default_rng(4).standard_normal(y.shape)
    result = create_estimator(EstimatorConfig(modes=2), NAMES).process(t, y)
    est = result.estimates
    for f, shape in shapes.items():
        near = np.abs(est.frequency_hz / f - 1) < 0.02
        assert np.count_nonzero(near) >= 5
        assert np.median(np.abs(est.frequency_hz[near] / f - 1)) < 0.005
        assert np.median([mac(s, shape) for s in result.shapes[near]]) > 0.99
    off = np.min(np.abs(est.frequency_hz[:, None] / np.array([5.0, 17.0]) - 1), axis=1) > 0.02
    assert np.count_nonzero(off) <= 0.05 * len(est)


@pytest.mark.parametrize(
    'config', [EstimatorConfig(), EstimatorConfig(modes=1)], ids=['one', 'modes']
)
def test_streaming_and_chunks_equal_batch(config):
    t, y = plucked(5)
    batch = create_estimator(config, NAMES).process(t, y)
    stream = create_estimator(config, NAMES)
    got = [e for ti, yi in zip(t, y) for e in stream.update(ti, yi)]
    chunked = create_estimator(config, NAMES)
    parts = [chunked.process(t[i : i + 700], y[i : i + 700]) for i in range(0, len(t), 700)]
    assert len(got) == len(batch) > 5
    assert [e.frequency_hz for e in got] == batch.estimates.frequency_hz.tolist()
    assert np.array_equal(np.array([e.shape for e in got]), batch.shapes)
    assert np.concatenate([p.estimates.frequency_hz for p in parts]).tolist() == (
        batch.estimates.frequency_hz.tolist()
    )
    assert stream.counters == batch_counters(config, t, y)


def batch_counters(config, t, y):
    est = create_estimator(config, NAMES)
    est.process(t, y)
    return est.counters


def test_bad_rows_are_counted_and_change_nothing_else():
    t, y = plucked(6)
    clean = create_estimator(EstimatorConfig(), NAMES).process(t, y)
    bad_t = np.insert(t, [100, 200, 300], [np.nan, t[199], t[250]])
    bad_y = np.insert(
        y, [100, 200, 300], [[1.0, 2.0, 3.0], [0.0, 0.0, 0.0], [5.0, 5.0, 5.0]], axis=0
    )
    bad_y[500, 1] = np.inf
    est = create_estimator(EstimatorConfig(), NAMES)
    got = est.process(bad_t, bad_y)
    c = est.counters
    assert (c['skipped_non_finite'], c['skipped_duplicate'], c['skipped_out_of_order']) == (
        2,
        1,
        1,
    )
    assert c['received'] == len(bad_t) and c['used'] == len(bad_t) - 4
    assert np.all(np.isfinite(got.estimates.frequency_hz)) and len(got) > 10
    late = got.estimates.t > t[510]  # after the bad rows' windows, the same estimates
    assert (
        got.estimates.frequency_hz[late].tolist()
        == clean.estimates.frequency_hz[clean.estimates.t > t[510]].tolist()
    )


@pytest.mark.parametrize('back', [True, False], ids=['time-back', 'gap'])
def test_a_stream_whose_time_went_back_or_paused_is_followed(back):
    """A pluck, then the same pluck again with stamps from 0 (a bag looping, a source restarted)
    or 10 s after the first ended (a gap beyond max_gap): one restart counted (the one input
    policy, core.estimator.accept_sample), no sample skipped, the second pluck estimated as the
    first (the same floats), in batch, in chunks and sample by sample."""
    t, y = plucked(7)
    again = t if back else t + t[-1] + 10.0
    tt, yy = np.concatenate([t, again]), np.concatenate([y, y])
    first = create_estimator(EstimatorConfig(), NAMES).process(t, y)
    est = create_estimator(EstimatorConfig(), NAMES)
    got = est.process(tt, yy)
    c = est.counters
    assert c['used'] == c['received'] == len(tt)
    assert (c['time_jump_resets'], c['gap_resets']) == ((1, 0) if back else (0, 1))
    second = got.estimates.frequency_hz[len(first) :]
    assert len(got) == 2 * len(first) > 10
    assert np.allclose(second, first.estimates.frequency_hz, rtol=1e-9, atol=0)
    stream = create_estimator(EstimatorConfig(), NAMES)
    streamed = [e.frequency_hz for ti, yi in zip(tt, yy) for e in stream.update(ti, yi)]
    assert streamed == got.estimates.frequency_hz.tolist() and stream.counters == c
    chunked = create_estimator(EstimatorConfig(), NAMES)
    parts = [chunked.process(tt[i : i + 900], yy[i : i + 900]) for i in range(0, len(tt), 900)]
    assert np.concatenate([p.estimates.frequency_hz for p in parts]).tolist() == (
        got.estimates.frequency_hz.tolist()
    )


def test_factory_and_refusals():
    assert isinstance(create_estimator(EstimatorConfig(), NAMES), JointFreeEstimator)
    with pytest.raises(ValueError, match='free or ambient'):
        create_estimator(EstimatorConfig(excitation='auto'), NAMES)
    with pytest.raises(ValueError, match='at least 2 channels'):
        JointFreeEstimator(EstimatorConfig(), ('a',), lambda: None)
    with pytest.raises(ValueError, match='expected 3 channel values'):
        create_estimator(EstimatorConfig(), NAMES).update(0.0, [1.0, 2.0])


def test_restart_forgets_the_modes_and_keeps_the_counters():
    t, y = plucked(7)
    est = create_estimator(EstimatorConfig(), NAMES)
    first = est.process(t, y)
    before = est.counters
    est.restart()
    assert est.counters == before  # kept, the channels' estimators' included
    again = est.process(t + t[-1] + 1.0, y)  # the same pluck later: the same estimates
    assert again.estimates.frequency_hz == pytest.approx(first.estimates.frequency_hz, rel=1e-9)
    assert again.estimates.mode.tolist() == first.estimates.mode.tolist()
    assert np.isnan(again.mac[0])  # a new first estimate: the modes were forgotten
    assert est.counters['estimates'] == 2 * before['estimates']
    assert est.counters['rejected_fit'] == 2 * before['rejected_fit']


def test_a_fit_that_ran_off_from_its_start_is_not_published():
    """``MAX_MOVE`` (10 %): 5 Hz on channels a and c, a 7 Hz mode 3 x stronger on b and c; a
    joint fit started from a channel's 5 Hz estimate that the 7 Hz mode pulled away is rejected
    (``rejected_joint``): every published estimate lies within 5 % of a mode (published, one lay
    13.7 % off)."""
    t, low = decay(5.0, 0.01)
    _, high = decay(7.0, 0.01, phase=1.0)
    y = np.column_stack((low, 3 * high, 3 * high + 0.2 * low))
    y += 0.02 * np.random.default_rng(0).standard_normal(y.shape)
    estimator = create_estimator(EstimatorConfig(), NAMES)
    est = estimator.process(t, y).estimates
    off = np.min(np.abs(est.frequency_hz[:, None] / np.array([5.0, 7.0]) - 1), axis=1)
    assert len(est) >= 40 and estimator.counters['rejected_joint'] >= 1
    assert off.max() < 0.05


def test_the_other_mode_is_a_term_of_the_fit_when_the_window_resolves_it():
    """``MIN_SEPARATION`` (0.5 cycles): 5 and 7.5 Hz on every channel (``modes`` 2); each joint
    fit carries the other mode as a term when the window holds half a cycle of their difference:
    RMS errors 0.21 and 0.18 % (the other mode left out of every fit: 0.79 and 1.33 %; taken in
    however close, unresolved ones included: 0.65 and 0.52 %)."""
    t, low = decay(5.0, 0.01)
    _, high = decay(7.5, 0.01, phase=1.0)
    y = np.column_stack((low + 0.8 * high, low - 0.5 * high, 0.3 * low + high))
    y += 0.02 * np.random.default_rng(0).standard_normal(y.shape)
    est = create_estimator(EstimatorConfig(modes=2), NAMES).process(t, y).estimates
    for f in (5.0, 7.5):
        err = est.frequency_hz / f - 1
        err = err[np.abs(err) < 0.03]
        assert len(err) >= 15 and rms(err) < 0.004, (f, len(err), rms(err))


def test_a_mode_that_rang_out_is_no_term_of_the_later_fits():
    """``CONTEXT_S`` (2 s): 5 Hz (zeta 0.3 %) and 7.5 Hz (zeta 5 %, rung out within a second) on
    three channels (``modes`` 2), 4 seeds: the 5 Hz mode's joint fits after 4 s carry no 7.5 Hz
    term, whose last estimate is seconds old; RMS error 0.089 % pooled (0.075-0.109 a seed), none
    beyond 2 %. At 1000x every fit keeps the rung-out mode as a term and fits the noise with it:
    0.40 % (0.11-0.66 a seed), 2 estimates beyond 2 % (at 0.001x the other mode is never a term:
    test_the_other_mode_is_a_term_of_the_fit_when_the_window_resolves_it)."""
    t = np.arange(int(12 * FS)) / FS
    errors = []
    for seed in range(4):
        low, high = decay(5.0, 0.003, 12.0), decay(7.5, 0.05, 12.0, phase=1.0)
        y = np.column_stack(
            (low[1] + 0.8 * high[1], low[1] - 0.5 * high[1], 0.3 * low[1] + high[1])
        )
        y += 0.02 * np.random.default_rng(seed).standard_normal(y.shape)
        est = create_estimator(EstimatorConfig(modes=2), NAMES).process(t, y).estimates
        errors += list(est.frequency_hz[est.t > 4.0] / 5.0 - 1)
    errors = np.array(errors)
    near = errors[np.abs(errors) < 0.03]
    assert len(near) >= 150 and np.all(np.abs(errors[np.abs(errors) < 0.1]) <= 0.02)
    assert rms(near) < 0.0015, rms(near)


@pytest.mark.parametrize('halvings', [None, 0, 4000])
def test_a_step_that_does_not_help_is_halved_a_few_times(monkeypatch, halvings):
    """Gauss-Newton from a start 8 % off over 10 periods overshoots: its first step, halved,
    lowers the residual and the fit converges (without halving it stopped at 4.69 Hz, 6 % off).
    A noiseless decay started at its exact parameters: no step can lower a residual at the
    rounding level, and the fit gives up after a few trial steps (``HALVINGS`` at 1000x: ~4000
    evaluations of the model)."""
    from vib_estimator.core import multichannel_free

    if halvings is not None:
        monkeypatch.setattr(multichannel_free, 'HALVINGS', halvings)
    basis, calls = multichannel_free._basis, []
    monkeypatch.setattr(multichannel_free, '_basis', lambda *a: calls.append(1) or basis(*a))
    t, y = decay(5.0, 0.01, seconds=2.0)
    u, wn = t - t.mean(), 2 * math.pi * 5.0
    noisy = y[:, None] * SHAPE + 0.02 * np.random.default_rng(0).standard_normal((len(t), 3))
    fit = joint_fit(u, noisy, [2 * math.pi * 5.4], [0.0])
    converged = abs(fit.omega / wn - 1) < 1e-3
    del calls[:]
    exact = joint_fit(u, y[:, None] * SHAPE, [wn * math.sqrt(1 - 1e-4)], [0.01 * wn])
    kept = exact.omega == pytest.approx(wn * math.sqrt(1 - 1e-4), rel=1e-9)
    assert (converged and kept and len(calls) <= 20) == (halvings is None)
