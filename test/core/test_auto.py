# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""excitation = auto: free decay or driven, per stretch (seeded, tolerant)."""

import math

import numpy as np
import pytest

from vib_estimator.core import EstimatorConfig
from vib_estimator.core.auto import AutoEstimator, is_driven, is_free_decay
from vib_estimator.core.modes import create_estimator
from vib_estimator.sim.ambient import ambient_record, sdof_response

FS, F, ZETA = 500.0, 5.0, 0.01
AUTO = EstimatorConfig(excitation='auto')
#: the stretches of the record below, s: free decay, driven, forcing off + a pluck at 145 s
FREE1, DRIVEN, FREE2, PLUCK = (0.0, 20.0), (20.0, 140.0), (140.0, 170.0), 145.0
#: a change of regime is recognised within this (s): a few of the envelope's 1 s blocks
MARGIN = 10.0


def _decay(n, amplitude, phase):
    t = np.arange(n) / FS
    w = 2 * math.pi * F
    return amplitude * np.exp(-ZETA * w * t) * np.sin(w * math.sqrt(1 - ZETA**2) * t + phase)


def free_driven_free(seed=0):
    """A free decay (20 s), the mode driven by white noise (120 s), the forcing off and a pluck
    5 s later (30 s); white noise 26 dB below the driven variance."""
    rng = np.random.default_rng(seed)
    n1, n2, n3 = (int(round((b - a) * FS)) for a, b in (FREE1, DRIVEN, FREE2))
    y = np.concatenate(
        (_decay(n1, 3.0, 0.3), sdof_response(n2, FS, F, ZETA, 1.0, rng), np.zeros(n3))
    )
    k = int(round(PLUCK * FS))
    y[k:] += _decay(len(y) - k, 3.0, 1.0)
    y += 0.05 * rng.standard_normal(len(y))
    return np.arange(len(y)) / FS, y


@pytest.fixture(scope='module')
def record():
    t, y = free_driven_free()
    return t, y, create_estimator(AUTO).process(t, y)


def _stretch(e, lo, hi):
    m = (e.t >= lo) & (e.t < hi)
    ambient = e.convergence_time[m] >= 0.9 * AUTO.ambient_window_s  # the identifier's window
    return e.frequency_hz[m] / F - 1, ambient


def test_each_stretch_has_the_right_kind_of_estimates(record):
    t, y, e = record
    # the free decay: exactly excitation free's estimates
    free = create_estimator(AUTO.replace(excitation='free')).process(t, y)
    first = e.t < FREE1[1]
    np.testing.assert_array_equal(e.frequency_hz[first], free.frequency_hz[free.t < FREE1[1]])
    np.testing.assert_array_equal(e.damping[first], free.damping[free.t < FREE1[1]])
    err, ambient = _stretch(e, *FREE1)
    assert len(err) >= 10 and not ambient.any() and np.all(np.abs(err) < 0.02)
    # driven, once recognised: the identifier's estimates, within tolerance
    err, ambient = _stretch(e, DRIVEN[0] + MARGIN, DRIVEN[1])
    assert len(err) >= 50 and np.mean(ambient) >= 0.95
    assert np.mean(np.abs(err[ambient]) <= 0.02) >= 0.95 and np.all(np.abs(err) < 0.05)
    # back to free after the pluck: the free-decay estimates again
    err, ambient = _stretch(e, PLUCK + 1.0, FREE2[1])
    assert len(err) >= 10 and not ambient.any() and np.mean(np.abs(err) <= 0.02) >= 0.95
    # one mode, one identity across the stretches (a transient estimate far off, in the change to
    # driven, is a mode of its own for a window)
    near = np.abs(e.frequency_hz / F - 1) <= 0.02
    assert np.all(e.mode[near & (e.t >= DRIVEN[0] + 2 * AUTO.ambient_window_s)] == 1)


def test_counters_and_streaming_equal_batch(record):
    t, y, e = record
    n = int(60 * FS)  # the free decay and 40 s of driving
    batch = create_estimator(AUTO).process(t[:n], y[:n])
    stream = create_estimator(AUTO)
    out = [x for i in range(n) for x in stream.update(t[i], y[i])]
    assert len(out) == len(batch) > 0
    np.testing.assert_array_equal([x.frequency_hz for x in out], batch.frequency_hz)
    np.testing.assert_array_equal([x.mode for x in out], batch.mode)
    c = stream.counters
    assert c['estimates'] == c['estimates_free'] + c['estimates_driven'] == len(out)
    assert c['estimates_free'] > 0 and c['estimates_driven'] > 0 and c['driven_blocks'] > 0
    assert c['received'] == n


def test_envelope_test_and_config():
    decay = np.exp(-0.3 * np.arange(10))
    assert not is_driven(decay)
    assert not is_driven(np.r_[1e-4, 1e-4, decay])  # quiet, then a pluck
    assert is_driven(np.r_[decay[:5], 0.9, decay[5:]])  # rises again: forced
    assert isinstance(create_estimator(AUTO), AutoEstimator)
    with pytest.raises(ValueError, match='excitation'):
        EstimatorConfig(excitation='sometimes').validate()


def test_a_driven_stretch_ends_when_the_structure_rings_down():
    """Driven (an amplitude that wanders smoothly up and down), then the forcing off: the state
    goes back to free once the envelope has rung down, with no onset."""
    from vib_estimator.core.auto import DRIVEN as DRIVEN_STATE
    from vib_estimator.core.auto import FREE as FREE_STATE
    from vib_estimator.core.auto import Envelope

    rng = np.random.default_rng(1)
    t = np.arange(0.0, 80.0, 1 / FS)
    on = t < 40.0
    amp = np.where(on, 1 + 0.6 * np.sin(2 * np.pi * t / 7), 0.0)
    off = amp[on][-1] * np.exp(-0.6 * (t - 40.0))  # then a free decay
    amp = np.where(on, amp, off)
    y = amp * np.sin(2 * np.pi * F * t) + 1e-4 * rng.standard_normal(len(t))
    env = Envelope(1.0)
    states = []
    for a, b in zip(t.tolist(), y.tolist()):
        env.update(a, b)
        states.append(env.state)
    states = np.array(states)
    assert np.mean(states[(t > 15) & (t < 40)] == DRIVEN_STATE) == 1.0
    assert np.all(states[t > 60] == FREE_STATE) and env.changes['rang_down'] == 1


def test_the_free_decay_test_tells_a_decay_from_a_driven_mode():
    """A damped sinusoid in white noise (with an offset; 4 periods after a pluck from rest) is a
    free decay, a white-noise-driven mode (zeta 1 % and 0.2 %) is not, 2 periods are too short."""
    rng = np.random.default_rng(3)
    t = np.arange(int(2 * FS)) / FS
    y = 0.3 + 0.01 * rng.standard_normal(len(t))
    y[t >= 0.5] += _decay(int(np.sum(t >= 0.5)), 2.0, 0.4)
    end = int((0.5 + 4 / F) * FS)
    assert is_free_decay(t[:end], y[:end], F) is True
    assert is_free_decay(t, y, F * 1.02) is True  # the frequency refined from the blocks
    assert is_free_decay(t[: int(2 / F * FS)], y[: int(2 / F * FS)], F) is None
    for zeta in (0.01, 0.002):
        y = sdof_response(len(t), FS, F, zeta, 1.0, rng) + 0.02 * rng.standard_normal(len(t))
        assert is_free_decay(t, y, F) is False


def test_a_ringing_that_settles_into_a_limit_cycle_is_free():
    """A ringing whose frequency rises 0.8 F -> F as its amplitude falls 3 -> 1 (2 s), then a
    limit cycle (as the real arm's): not one decay over the test's 8 periods, but its last 2.5
    periods are one within the noise."""
    from vib_estimator.core.auto import RECENT_PERIODS, decay_misfit

    rng = np.random.default_rng(4)
    t = np.arange(int(3 * FS)) / FS
    u = np.minimum(t / 2.0, 1.0)
    phase = 2 * math.pi * np.cumsum(F * (0.8 + 0.2 * u)) / FS
    y = (1 + 2 * (1 - u) ** 2) * np.sin(phase) + 0.001 * rng.standard_normal(len(t))
    whole = decay_misfit(t, y, F)
    assert whole is not None and whole[1] > 0.02  # the whole window: no single decay
    assert decay_misfit(t, y, F, RECENT_PERIODS)[1] < 0.005
    assert is_free_decay(t, y, F) is True


@pytest.mark.parametrize('zeta', [0.01, 0.002])
def test_a_driven_record_publishes_no_free_decay_estimate(zeta):
    """Driven from its first sample (a record that starts free for the envelope): the free-decay
    estimates of its first seconds fail the test, so only the identifier's are published."""
    t, y, _ = ambient_record(60.0, FS, [(F, zeta, 1.0)], 26.0, 5)
    est = create_estimator(AUTO)
    e = est.process(t, y)
    assert len(e) >= 20 and est.counters['not_free_decay'] > 0
    assert est.counters['estimates_free'] == 0
    assert np.all(e.convergence_time >= 0.9 * AUTO.ambient_window_s)
    assert np.all(np.abs(e.frequency_hz / F - 1) < 0.05)


def test_envelope_feed_equals_sample_by_sample():
    """Envelope.feed (block by block, what a batch uses) gives exactly the states and counts of
    update (sample by sample, what a node uses), in chunks that split blocks, across a pluck, a
    driven stretch, a ring-down, NaNs, duplicate and out-of-order stamps and a gap."""
    from vib_estimator.core.auto import Envelope

    rng = np.random.default_rng(5)
    fs = 200.0
    t = np.arange(0, 120, 1 / fs)
    y = 0.01 * rng.standard_normal(len(t))
    pluck = (t >= 10) & (t < 40)
    y[pluck] += np.exp(-0.3 * (t[pluck] - 10)) * np.sin(2 * np.pi * 3 * t[pluck])
    driven = (t >= 50) & (t < 90)
    y[driven] += np.convolve(rng.standard_normal(int(driven.sum())), np.ones(20) / 20, 'same')
    y[rng.choice(len(t), 200, replace=False)] = np.nan
    t = t.copy()
    dup = rng.choice(len(t) - 1, 100, replace=False)
    t[dup + 1] = t[dup]  # duplicates
    back = rng.choice(len(t) - 1, 50, replace=False)
    t[back + 1] -= 0.5 / fs  # out of order
    t[t > 100] += 3.0  # a gap
    one, chunked = Envelope(1.0), Envelope(1.0)
    states = []
    for a, b in zip(t.tolist(), y.tolist()):
        one.update(a, b)
        states.append(one.state == 'driven')
    valid, driven_out = [], []
    for lo in range(0, len(t), 777):
        v, d = chunked.feed(t[lo : lo + 777], y[lo : lo + 777])
        valid.append(v)
        driven_out.append(d)
    np.testing.assert_array_equal(np.concatenate(driven_out), states)
    assert one.blocks == chunked.blocks and one.changes == chunked.changes
    assert one.changes['became_driven'] >= 1 and one.changes['onsets'] >= 1
    kept, last = [], -math.inf  # the rule: finite and later than the last kept
    for a, b in zip(t.tolist(), y.tolist()):
        kept.append(math.isfinite(b) and a > last)
        last = a if kept[-1] else last
    np.testing.assert_array_equal(np.concatenate(valid), kept)
    assert not all(kept)
