# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""The estimator node's processing without ROS (nodes/stream.py): time base, estimator
replacement, counters, status (the reset service: test_estimator_node.py)."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from vib_estimator.core import EstimatorConfig, FrequencyEstimator
from vib_estimator.core.choice import decide
from vib_estimator.nodes import health as H
from vib_estimator.nodes.stream import EstimatorStream

EPOCH_NS = 1_700_000_000 * 10**9
#: a real aluminium beam's free decay (``../shared/real-data``, beside the repository or above)
BEAM_50 = next(
    (
        p / 'shared' / 'real-data' / 'aluminium_cantilever_adxl357' / '50cm_uniform_1000Hz.csv'
        for p in Path(__file__).resolve().parents[2].parents
        if (p / 'shared' / 'real-data').is_dir()
    ),
    Path('/nonexistent'),
)


def sine(n, start=0, fs=500.0):
    stamps = EPOCH_NS + np.round(np.arange(start, start + n) * 1e9 / fs).astype(np.int64)
    return stamps, np.sin(2 * np.pi * 1.33 * np.arange(start, start + n) / fs)


def feed(stream, stamps, values):
    return [e for s, v in zip(stamps, values) for e in stream.feed(int(s), float(v))]


def test_same_floats_as_offline_with_epoch_stamps():
    stamps, values = sine(4000)  # 8 s: >= 5 windows of 1.25 periods (the default)
    stream = EstimatorStream(EstimatorConfig(), now=0.0)
    online = feed(stream, stamps, values)
    offline = FrequencyEstimator().process((stamps - stamps[0]) * 1e-9, values)
    assert len(online) >= 5 and [e.frequency_hz for e in online] == offline.frequency_hz.tolist()
    assert stream.last_t == (stamps[-1] - stamps[0]) * 1e-9


def test_configure_keeps_the_origin_and_the_counters():
    stamps, values = sine(3000)
    stream = EstimatorStream(EstimatorConfig(), now=0.0)
    feed(stream, stamps[:1000], values[:1000])
    stream.configure(EstimatorConfig(window=5))
    assert stream.config.window == 5
    later = feed(stream, stamps[1000:2000], values[1000:2000])
    expected = FrequencyEstimator(EstimatorConfig(window=5)).process(
        (stamps[1000:2000] - stamps[0]) * 1e-9, values[1000:2000]
    )
    assert [e.frequency_hz for e in later] == expected.frequency_hz.tolist()
    assert stream.counters['received'] == 2000
    assert stream.counters['estimates'] == stream.health.totals({})['estimates'] + len(expected)


def test_status_knows_the_sampling_rate_and_the_last_estimate():
    stamps, values = sine(1001)
    stream = EstimatorStream(EstimatorConfig(band_hz=(10.0, 300.0)), now=0.0)
    for e in feed(stream, stamps, values):
        stream.published(e, now=0.5)
    status = stream.status(now=1.0)
    assert status.values['sample_rate_hz'] == 500.0
    assert status.level == H.WARN and 'Nyquist' in status.message  # 300 Hz > 250 Hz
    assert status.values['band_above_nyquist'] == 1001
    ok, message = stream.self_test()
    assert not ok and 'at 500 Hz sampling' in message


@settings(max_examples=40, deadline=None)
@given(
    samples=st.lists(
        st.tuples(
            st.one_of(st.integers(0, 2**63 - 1), st.integers(-(10**9), 10**9)),
            st.one_of(
                st.floats(allow_nan=True, allow_infinity=True),
                st.sampled_from([1e308, -1e308, 5e-324, 0.0]),
                st.floats(-2.0, 2.0),
            ),
        ),
        max_size=200,
    )
)
def test_fuzz_the_message_path_publishes_only_finite_numbers(samples):
    """Issue 22: random stamps (ns, any order) and values mixed into a clean 500 Hz sine through
    the node's message path: no exception, every estimate's numbers finite (damping and stds
    finite or NaN = not computed), every sample counted exactly once, a valid status."""
    import math

    from vib_estimator.nodes.health import format_value

    s = EstimatorStream(EstimatorConfig(), 0.0)
    n = 3000
    clean = [(10**18 + i * 2_000_000, math.sin(2 * math.pi * 3 * i / 500)) for i in range(n)]
    for i, sample in enumerate(samples):
        clean.insert((i * 131) % n, (10**18 + sample[0], sample[1]))
    estimates = [e for stamp, value in clean for e in s.feed(stamp, value)]
    c = s.counters
    assert (
        c['received']
        == len(clean)
        == sum(
            c[k]
            for k in (
                'used',
                'skipped_non_finite',
                'skipped_duplicate',
                'skipped_out_of_order',
                'skipped_outlier',
            )
        )
    )
    for e in estimates:
        assert all(
            math.isfinite(v) for v in (e.t, e.frequency_hz, e.fit, e.amplitude, e.convergence_time)
        )
        assert not any(math.isinf(v) for v in (e.damping, e.frequency_std_hz, e.damping_std))
    status = s.status(1.0)
    assert all(isinstance(format_value(v), str) for v in status.values.values())


def test_a_burst_of_self_tests_runs_the_tones_once(monkeypatch):
    """The node shares one executor thread with the data path: a burst of ~/self_test calls costs
    one run of the tones (seeded: a function of configuration and rate), a change of either a new
    one."""
    from vib_estimator.nodes import stream as stream_module

    runs = []
    real = stream_module.in_process
    monkeypatch.setattr(
        stream_module,
        'in_process',
        lambda config, rate: runs.append((config, rate)) or real(config, rate),
    )
    s = stream_module.EstimatorStream(EstimatorConfig(), 0.0)
    answers = [s.self_test() for _ in range(50)]
    assert len(runs) == 1 and answers[0][0] and len(set(answers)) == 1
    s.configure(EstimatorConfig(window=5))
    assert s.self_test()[0] and len(runs) == 2


def test_a_self_test_running_is_not_replaced_when_the_configuration_or_rate_changes(monkeypatch):
    """One run at a time: calls waiting for a run get its result even if the configuration (or
    the input's rate, which moves with its losses) changed meanwhile; replaced at each change,
    the run never finished and its calls were never answered. The next call tests what is
    live."""
    import threading

    from vib_estimator.nodes import stream as stream_module

    runs, release = [], threading.Event()

    def slow(config, rate):
        runs.append(config)
        release.wait(30.0)
        return True, f'window {config.window}'

    monkeypatch.setattr(stream_module, 'in_process', slow)
    s = stream_module.EstimatorStream(EstimatorConfig(), 0.0)
    assert s.self_test(wait=False) is None
    for window in (5, 6, 7):  # changes while it runs: still one run
        s.configure(EstimatorConfig(window=window))
        assert s.self_test(wait=False) is None
    assert len(runs) == 1
    release.set()
    assert s.self_test() == (True, f'window {EstimatorConfig().window}')
    assert s.self_test() == (True, 'window 7') and len(runs) == 2


def test_a_band_s_self_test_lasts_for_its_prefilter():
    """With ``band_hz``, each tone lasts 10 periods of the band's lower edge too: the 2-20 Hz
    band's 11.25 Hz tone (10 of its periods, 0.89 s) gave no estimate and the self-test failed,
    the band-filtered estimator's first estimate coming after its prefilter settled."""
    from vib_estimator.nodes.self_test import run_tone, self_test

    config = EstimatorConfig(band_hz=(2.0, 20.0))
    ok, text = self_test(config, 500.0)
    assert ok, text
    assert run_tone(config, 11.25, 500.0).estimates >= 20
    assert run_tone(config.replace(band_hz=(0.5, 20.0)), 11.25, 500.0).estimates >= 100


def test_the_self_test_runs_in_a_process_of_its_own_or_here_said(monkeypatch):
    """The tones run in a child Python process (their records and estimators never in the
    node's memory): the same answer as in this process, the configuration's tuples carried
    over; with no child process (here: no Python where the node's was), here, and the
    answer says so."""
    from vib_estimator.nodes import self_test as self_test_module

    config = EstimatorConfig(min_periods=2.0, lines_hz=(50.0, 100.0))
    assert self_test_module.in_process(config, 400.0) == self_test_module.self_test(config, 400.0)
    monkeypatch.setattr(sys, 'executable', '/nonexistent/python')
    assert self_test_module.in_process(config, 400.0) is None
    ok, text = EstimatorStream(config, 0.0).self_test()
    assert ok and text.endswith('(run in the node: no process of its own)')


# ---- several channels (the node's components) ---------------------------------------------------
def test_channels_one_is_the_single_channel_stream_several_the_joint_identifier():
    from vib_estimator.core.ambient import AmbientEstimator
    from vib_estimator.nodes.stream import check_channels
    from vib_estimator.sim.frame import modal_record

    stamps, values = sine(4000)
    one = EstimatorStream(EstimatorConfig(), now=0.0, channels=('torque.z',))
    plain = EstimatorStream(EstimatorConfig(), now=0.0)

    def floats(stream):
        return [
            (e.t, e.frequency_hz, e.frequency_std_hz, e.amplitude)
            for e in feed(stream, stamps, values)
        ]

    assert floats(one) == floats(plain)  # bit for bit
    names = ('a', 'b', 'c')
    with pytest.raises(ValueError, match='3 components .* need excitation free or ambient'):
        check_channels(names, EstimatorConfig(excitation='auto'))
    config = EstimatorConfig(excitation='ambient', ambient_window_s=20.0)
    t, y = modal_record(60.0, 20.0, [(1.0, 0.02, 1.0)], np.array([[1.0], [0.5], [-0.3]]), 20.0)
    stamps = EPOCH_NS + np.round(t * 1e9).astype(np.int64)
    stream = EstimatorStream(config, now=0.0, channels=names)
    got = [e for s, row in zip(stamps, y.tolist()) for e in stream.feed(int(s), tuple(row))]
    expected = AmbientEstimator(config, names).process((stamps - stamps[0]) * 1e-9, y)
    assert all(e.shape is not None for e in got) and len(got) == len(expected) > 6
    assert [e.frequency_hz for e in got] == expected.estimates.frequency_hz.tolist()
    for e in got:
        stream.published(e, now=0.5)
    assert stream.status(now=1.0).values['channels'] == 'a,b,c'
    with pytest.raises(ValueError, match='need excitation free or ambient'):
        stream.configure(EstimatorConfig(excitation='auto'), names)  # refused: unchanged
    stream.configure(config, ())  # back to one channel: counters kept, no channels key
    assert stream.counters['received'] == len(t) and 'channels' not in stream.status(2.0).values


def test_several_channels_of_free_decays_are_estimated_jointly():
    """excitation free with three channels: the joint free-decay estimator's floats, shapes."""
    from vib_estimator.core import create_estimator

    names = ('x', 'y', 'z')
    stamps = EPOCH_NS + np.round(np.arange(3000) * 1e9 / 500.0).astype(np.int64)
    t = (stamps - stamps[0]) * 1e-9
    decay = np.exp(-0.3 * t) * np.sin(2 * np.pi * 5.0 * t + 0.3)
    rng = np.random.default_rng(8)
    y = decay[:, None] * np.array([0.2, 1.0, -0.5]) + 0.02 * rng.standard_normal((len(t), 3))
    stream = EstimatorStream(EstimatorConfig(), now=0.0, channels=names)
    got = [e for s, row in zip(stamps, y.tolist()) for e in stream.feed(int(s), tuple(row))]
    expected = create_estimator(EstimatorConfig(), names).process(t, y)
    assert all(e.shape is not None for e in got) and len(got) == len(expected) > 6
    assert [e.frequency_hz for e in got] == expected.estimates.frequency_hz.tolist()
    assert np.array_equal([e.shape for e in got], expected.shapes)
    assert stream.status(now=1.0).values['channels'] == 'x,y,z'


def test_a_driven_input_to_the_free_estimator_is_said_in_the_status_once_logged():
    """The node cannot see its input ahead: when the free-decay estimator is fed a response that
    looks driven throughout (core.choice.DrivenWatch), /diagnostics say so and which excitation
    helps; not for a free decay ringing down into noise, nor under excitation ambient."""
    from vib_estimator.sim.ambient import ambient_record

    def run(config, t, y):
        stream = EstimatorStream(config, now=0.0)
        stamps = EPOCH_NS + np.round(t * 1e9).astype(np.int64)
        statuses = []
        for k in range(0, len(t), 100):  # a status a second of the 100 Hz input
            feed(stream, stamps[k : k + 100], y[k : k + 100])
            statuses.append(stream.status(now=1.0 + k / 100))
        return statuses

    t, y, _ = ambient_record(240, 100, [(1.2, 0.015, 1.0)], 20, 1)
    statuses = run(EstimatorConfig(), t, y)
    said = [s for s in statuses if 'the input looks driven' in s.message]
    assert said and all(s.level == H.WARN for s in said)
    assert 'excitation:=ambient' in said[-1].message
    assert statuses[-1] in said  # still said at the end
    logged = [s.log for s in statuses if s.log and 'looks driven' in s.log]
    assert len(logged) == 1  # logged when it starts, not every second
    assert not any(
        'looks driven' in s.message for s in run(EstimatorConfig(excitation='ambient'), t, y)
    )
    t = np.arange(0, 240, 0.01)
    y = np.exp(-0.01 * 2 * np.pi * 2 * t) * np.sin(2 * np.pi * 2 * t)
    y += 0.002 * np.random.default_rng(0).standard_normal(len(t))
    assert not any('looks driven' in s.message for s in run(EstimatorConfig(), t, y))


def decisions(stream, t, y, step=100, estimates=None):
    """Feed ``(t, y)`` (one status a ``step`` samples, i.e. a second at 100 Hz), applying each
    :meth:`EstimatorStream.decision` as the node does (primed); the (second, decision) pairs.
    ``estimates``: a list that gets (second, excitation, estimate) of each estimate."""
    stamps = EPOCH_NS + np.round(t * 1e9).astype(np.int64)
    out = []
    for k in range(0, len(t), step):
        for s, v in zip(stamps[k : k + step].tolist(), y[k : k + step].tolist()):
            for e in stream.feed(s, v):
                if estimates is not None:
                    estimates.append((k // step, stream.config.excitation, e))
        stream.status(now=1.0 + k / step)
        decision = stream.decision() if stream.deciding else None  # (as the node asks)
        if decision is not None:
            out.append((k // step, decision))
            stream.configure(stream.config.replace(**decision.changes()), prime=True)
            stream.decided = True
    return out


def test_the_deciding_stream_goes_to_the_identifier_when_driven_and_back_when_free():
    """``decide_excitation``: a mode driven throughout sends the free-decay estimator to the
    identifier (analyze's decision over the last seconds: its window for the 1.2 Hz
    fundamental) once half the watched span is in, without a hint, primed with those seconds
    (its first estimate once a window is in since the start, not since the switch; the primer
    uncounted); a pluck later sends it to ``auto`` (its free stretches' estimates those of
    the free-decay estimator, the identifier's again in a driven one: no second wait for the
    watch); a decay ringing down into noise never leaves free."""
    from vib_estimator.core.choice import WATCH_S
    from vib_estimator.sim.ambient import ambient_record

    t, y, _ = ambient_record(150, 100, [(1.2, 0.015, 1.0)], 20, 1)
    ring_t = np.arange(0, 200, 0.01)
    ring = 50 * np.exp(-0.01 * 2 * np.pi * 2 * ring_t) * np.sin(2 * np.pi * 2 * ring_t)
    ring += 0.002 * np.random.default_rng(0).standard_normal(len(ring_t))
    stream = EstimatorStream(EstimatorConfig(), now=0.0, deciding=True)
    got_estimates = []
    got = decisions(
        stream,
        np.concatenate([t, t[-1] + 0.01 + ring_t]),
        np.concatenate([y, ring]),
        estimates=got_estimates,
    )
    assert [d.excitation for _, d in got] == ['ambient', 'auto']
    (went, driven), (back, _) = got
    assert WATCH_S / 2 <= went <= WATCH_S / 2 + 5 and 90 <= driven.window_s <= 110
    assert 150 <= back < 150 + WATCH_S and stream.config.excitation == 'auto'
    assert stream.config.ambient_window_s == driven.window_s  # (the driven decision's stays)
    # under auto: the ring's free estimates, and (its first seconds, before its envelope
    # closed the pluck's block) the driven mode of the window before the pluck
    off = [
        min(abs(e.frequency_hz / f - 1) for f in (1.2, 2.0))
        for _, x, e in got_estimates
        if x == 'auto'
    ]
    assert max(off) < 0.05 and np.mean(np.array(off) < 0.02) >= 0.95
    of_ring = [
        e for _, x, e in got_estimates if x == 'auto' and abs(e.frequency_hz / 2 - 1) < 0.02
    ]
    assert len(of_ring) >= 20
    assert not any('looks driven' in m for m in stream.status(now=1e3).message.split(';'))
    driven_estimates = [(k, e) for k, x, e in got_estimates if x == 'ambient']
    assert driven_estimates[0][0] <= driven.window_s + 5  # primed: not went + window
    assert all(abs(e.frequency_hz / 1.2 - 1) < 0.02 for _, e in driven_estimates)
    assert stream.counters['received'] == len(t) + len(ring_t)
    quiet = EstimatorStream(EstimatorConfig(), now=0.0, deciding=True)
    assert all(d.excitation == 'free' for _, d in decisions(quiet, ring_t, ring))


def test_a_stream_driven_now_and_in_part_is_decided_without_waiting_for_the_ring_to_leave(
    monkeypatch,
):
    """A mode driven throughout under a start's ring 25 x its driven level (an arm driven at
    its tip after its ramp): once its envelope reads it driven, the deciding stream asks
    ``decide`` as soon as the watched seconds' driven share is above ``FREE_BELOW`` (decide then
    says ``auto``: the ring is still in them), not once the ring has left them (``ambient``, 20 s
    later); what runs meanwhile (free) publishes nothing of the driven mode."""
    import vib_estimator.nodes.stream as stream_module
    from vib_estimator.core.choice import DRIVEN_ABOVE
    from vib_estimator.sim.ambient import sdof_response

    fs, f, zeta = 100.0, 1.3, 0.01
    rng = np.random.default_rng(0)
    t = np.arange(0, 200, 1 / fs)
    y = sdof_response(len(t), fs, f, zeta, 1.0, rng)
    w = 2 * np.pi * f
    y += 25 * np.std(y) * np.exp(-zeta * w * t) * np.sin(w * t)
    y += 0.05 * np.std(y) * rng.standard_normal(len(t))

    def first_driven():
        got = decisions(EstimatorStream(EstimatorConfig(), now=0.0, deciding=True), t, y)
        return next((k, d.excitation) for k, d in got if d.excitation != 'free')

    second, excitation = first_driven()
    assert second <= 130 and excitation == 'auto'
    monkeypatch.setattr(stream_module, 'FREE_BELOW', DRIVEN_ABOVE)  # driven throughout only
    assert first_driven()[0] >= second + 15


def test_the_deciding_stream_publishes_no_free_estimate_of_a_driven_input_before_it_decides():
    """Before it decides (20 s here), the deciding stream's free-decay estimator publishes
    only estimates whose signal passes the free-decay test (as ``auto``'s free stretches): a
    driven mode's free estimates, up to 4.5 % off here, are held back and counted
    (``not_free_decay``, one of the held-back counters the status names); a free decay's are
    those of ``free``, float for float; without ``decide_excitation`` they are published."""
    from vib_estimator.sim.ambient import ambient_record

    t, y, _ = ambient_record(55, 500, [(5.0, 0.01, 1.0)], 20, 0)

    def run(deciding, t, y, until=np.inf):
        """The stream, its estimates until its first decision (or second ``until``), and the
        second of that decision."""
        stream = EstimatorStream(EstimatorConfig(), now=0.0, deciding=deciding)
        got = []
        decided = decisions(stream, t, y, step=500, estimates=got)
        until = decided[0][0] if decided else until
        return stream, [e for k, _, e in got if k <= until], until

    deciding, published, until = run(True, t, y)
    assert 19 <= until <= 22  # (core.choice.EARLY_S: a 30-s window, half read)
    undecided, held, _ = run(False, t, y, until)
    off = [abs(e.frequency_hz / 5 - 1) for e in held]
    assert max(off) > 0.04 and undecided.counters['not_free_decay'] == 0
    assert all(abs(e.frequency_hz / 5 - 1) <= 0.02 for e in published)
    assert len(published) <= 2 and deciding.counters['not_free_decay'] >= len(held) - 2
    early = EstimatorStream(EstimatorConfig(), now=0.0, deciding=True)
    assert not decisions(early, t[:7500], y[:7500], step=500)  # 15 s: not decided yet
    assert 'not_free_decay' in early.status(now=16.0).message
    # decided, the identifier runs: what held the free estimator back is no longer its reason
    assert 'not_free_decay' not in deciding.status(now=56.0).message
    ring_t = np.arange(0, 12, 0.002)
    ring = np.exp(-0.01 * 2 * np.pi * 5 * ring_t) * np.sin(2 * np.pi * 5 * ring_t)
    ring += 0.002 * np.random.default_rng(0).standard_normal(len(ring_t))
    _, free, _ = run(True, ring_t, ring)  # (until the decay's window is decided)
    offline = FrequencyEstimator().process(np.round(ring_t * 1e9).astype(np.int64) * 1e-9, ring)
    assert len(free) >= 5
    assert [e.frequency_hz for e in free] == offline.frequency_hz.tolist()[: len(free)]


def test_after_its_decision_the_status_says_how_much_of_the_window_it_holds():
    """A driven input decided at ~20 s for a 30-s window: until that window is full, the status
    is OK and says how much of it is held (the primed seconds and those since), not the free
    estimator's holds before the decision; then the identifier's estimates."""
    from vib_estimator.sim.ambient import ambient_record

    t, y, _ = ambient_record(36, 500, [(5.0, 0.01, 1.0)], 20, 0)
    stream = EstimatorStream(EstimatorConfig(), now=0.0, deciding=True)
    got = []
    (at, decision), *_ = decisions(stream, t, y, step=500, estimates=got)
    assert 19 <= at <= 22 and decision.excitation == 'ambient' and decision.window_s == 30
    first = min(k for k, _, _ in got)
    assert 30 <= first <= 32  # (a window of input since the start)
    again = EstimatorStream(EstimatorConfig(), now=0.0, deciding=True)
    decisions(again, t[:13500], y[:13500], step=500)  # until 27 s
    status = again.status(now=28.0)
    assert status.level == H.OK, status.message
    held = float(status.message.split(': ')[1].split(' s of its 30 s window held')[0])
    assert 26.5 <= held <= 27.5  # (27 s of input: the stream time of its last sample)
    assert 'window held' not in stream.status(now=37.0).message


def plucked(modes, seconds=12.0, rate=500.0):
    """A pluck at 1 s of ``modes`` ((f, amplitude, zeta), ...) in 1e-3 of white noise."""
    t = np.arange(0, seconds, 1 / rate)
    tau = np.maximum(t - 1.0, 0)
    y = sum(
        a * np.exp(-z * 2 * np.pi * f * tau) * np.sin(2 * np.pi * f * tau) for f, a, z in modes
    )
    return t, y + 1e-3 * np.random.default_rng(0).standard_normal(len(t))


@pytest.mark.parametrize('factor', [1e-3, 1e3])
def test_a_silent_decay_of_several_modes_goes_to_the_mode_tracker(monkeypatch, factor):
    """A pluck of a 10 and a 13 Hz mode beats: the one-mode estimator publishes nothing. After
    ``SILENT_S`` s of silence while the input rings, the deciding stream asks analyze's decision
    over its last seconds and takes the mode tracker (``modes`` 3, primed): both modes, within
    2 %, from 3 s after the pluck. A beam's pluck (4.27 Hz, and a 26.7 Hz mode that dies in a
    second) keeps the one-mode estimator: it is never silent that long. ``SILENT_S`` at 0.001x
    sends the beam to the tracker (its first second's spectrum), at 1000x leaves the pair
    silent."""
    from vib_estimator.core import choice

    def run(modes):
        stream = EstimatorStream(EstimatorConfig(), now=0.0, deciding=True)
        got = []
        decided = decisions(stream, *plucked(modes), step=500, estimates=got)
        return decided, np.array([e.frequency_hz for _, _, e in got]), stream

    def right():
        decided, f, stream = run(((10.0, 1.0, 0.003), (13.0, 0.5, 0.003)))
        pair = (
            [(x.excitation, x.modes) for _, x in decided] == [('free', 3)]
            and decided[0][0] <= 4
            and stream.config.modes == 3
            and all(np.any(np.abs(f / m - 1) <= 0.02) for m in (10.0, 13.0))
            and np.all(np.min(np.abs(f[:, None] / [10.0, 13.0] - 1), axis=1) <= 0.02)
        )
        decided, f, _ = run(((4.27, 1.0, 0.005), (26.7, 1.0, 0.02)))  # (its window decided)
        one = all(x.excitation == 'free' and not x.modes for _, x in decided)
        return pair and one and len(f) >= 30 and np.all(np.abs(f / 4.27 - 1) <= 0.02)

    assert right()
    monkeypatch.setattr(choice, 'SILENT_S', choice.SILENT_S * factor)
    assert not right()


def noisy_pluck(f: float, rate: float, zeta: float, snr_db: float, seconds: float = 40.0):
    """A pluck at 1 s of one mode (a random phase), ``snr_db`` above white noise."""
    rng = np.random.default_rng(0)
    t = np.arange(0, seconds, 1 / rate)
    tau = np.maximum(t - 1.0, 0)
    wave = np.sin(2 * np.pi * f * np.sqrt(1 - zeta**2) * tau + rng.uniform(0, 2 * np.pi))
    y = np.exp(-zeta * 2 * np.pi * f * tau) * wave * (t >= 1)
    return t, y + 10 ** (-snr_db / 20) / np.sqrt(2) * rng.standard_normal(len(t))


@pytest.mark.parametrize('factor', [1e-3, 1e3])
def test_a_decay_its_free_estimator_leaves_silent_goes_to_the_mode_tracker(monkeypatch, factor):
    """A 5 Hz pluck at 20 samples a period in 20 dB: the free estimator's convergence test never
    passes (no estimate in 40 s). Once it has been silent since the onset for ``SILENT_PERIODS``
    periods (and ``SILENT_S`` s), the deciding stream takes the mode tracker (the node's form of
    analyze's rescue): 13 estimates, within 2 %. A 0.5 Hz pluck (40 dB, 50 Hz), whose free
    estimator's first estimate comes 3.5 periods after it, keeps the free estimator.
    ``SILENT_PERIODS`` at 0.001x sends the slow pluck to the tracker 2.6 periods after the
    onset, at 1000x leaves the noisy one silent."""
    from vib_estimator.core import choice

    def run(record):
        stream = EstimatorStream(EstimatorConfig(), now=0.0, deciding=True)
        got = []
        decided = decisions(stream, *record[:2], step=record[2], estimates=got)
        return decided, np.array([e.frequency_hz for _, _, e in got])

    noisy = (*noisy_pluck(5.0, 100.0, 0.005, 20.0), 100)
    slow = (*noisy_pluck(0.5, 50.0, 0.01, 40.0), 50)

    def right():
        decided, f = run(noisy)
        silent = [x for _, x in decided if 'no free estimate for' in x.reason]
        rescued = len(silent) == 1 and silent[0].modes == 3 and len(f) >= 10
        decided, g = run(slow)
        kept = not any(x.modes for _, x in decided) and len(g) >= 5
        return rescued and np.all(np.abs(f / 5 - 1) <= 0.02) and kept

    assert right()
    monkeypatch.setattr(choice, 'SILENT_PERIODS', choice.SILENT_PERIODS * factor)
    assert not right()


@pytest.mark.parametrize('seed', [0, 5])
def test_a_pluck_its_free_estimator_reads_once_or_twice_goes_to_the_mode_tracker(seed):
    """Two 5 Hz plucks (zeta 0.5 %) in 20 dB at 20 samples a period, at 1 and 30 s: the free
    estimator's window, decided at 3 s, gives 1-2 estimates after the first pluck and none for
    ``SILENT_PERIODS`` periods while it rings: fewer than ``RESCUE_BELOW``, no reading, so the
    stream takes the mode tracker then (before 7 Dec 2026 only a free estimator silent since the
    onset was; these two seeds stayed free, or switched at 36 s) and the second pluck gets 40 or
    more estimates, all within 2 % (6 before)."""
    rng = np.random.default_rng(seed)
    t = np.arange(0, 60, 0.01)
    y = np.zeros_like(t)
    for start in (1.0, 30.0):
        tau = np.maximum(t - start, 0)
        wave = np.sin(2 * np.pi * 5 * tau + rng.uniform(0, 6.28))
        y += np.exp(-0.005 * 2 * np.pi * 5 * tau) * wave * (t >= start) * (t < start + 29)
    y += 0.1 / np.sqrt(2) * rng.standard_normal(len(t))
    stream = EstimatorStream(EstimatorConfig(), now=0.0, deciding=True)
    got = []
    decided = decisions(stream, t, y, step=100, estimates=got)
    rescued = [k for k, x in decided if x.modes and 'while the decay rings' in x.reason]
    assert rescued and rescued[0] <= 10, [(k, x.reason[-90:]) for k, x in decided]
    second = np.array([e.frequency_hz for k, _, e in got if k >= 30])
    assert len(second) >= 40 and np.all(np.abs(second / 5 - 1) <= 0.02)


@pytest.mark.parametrize('factor', [1e-3, 1e3])
def test_a_steady_oscillation_that_is_no_decay_goes_to_the_mode_tracker(monkeypatch, factor):
    """A limit cycle (``sim.signals.limit_cycle``, the real arm's kind) is no free decay: the
    free-decay test holds back every free estimate of it, and the node stayed silent (0-3
    estimates in 120 s). Once ``HELD_RUN`` estimates running were held back and the watch has
    read the stream free and live over half its span (60 s), the deciding stream takes the mode
    tracker: estimates at the cycle's frequency (within 5 %, median within 1.5 %: its phase
    wanders). A slow, lightly damped decay (1 Hz, 0.1 %: live for all of 90 s) keeps the free
    estimator. ``HELD_RUN`` at 0.001x sends the decay to the tracker, at 1000x leaves the limit
    cycle silent."""
    from vib_estimator.core import choice
    from vib_estimator.sim.signals import limit_cycle

    def run(t, y, rate):
        stream = EstimatorStream(EstimatorConfig(), now=0.0, deciding=True)
        got = []
        decided = decisions(stream, t, y, step=rate, estimates=got)
        return decided, np.array([e.frequency_hz for _, _, e in got])

    def right():
        decided, f = run(*limit_cycle(90.0, 200.0), 200)
        steady = [(s, x) for s, x in decided if 'a steady oscillation' in x.reason]
        tracked = len(steady) == 1 and steady[0][1].modes == 3 and 60 <= steady[0][0] <= 66
        err = np.abs(f / 1.8116 - 1)
        cycle = tracked and len(f) >= 30 and np.all(err <= 0.05) and np.median(err) <= 0.015
        t = np.arange(0, 90, 0.01)
        decay = np.exp(-0.001 * 2 * np.pi * t) * np.sin(2 * np.pi * t + 0.3)
        rng = np.random.default_rng(1)
        decided, g = run(t, decay + 1e-3 * rng.standard_normal(len(t)), 100)
        free = not any(x.modes for _, x in decided) and len(g) >= 60
        return cycle and free and np.all(np.abs(g - 1) <= 0.02)

    assert right()
    monkeypatch.setattr(choice, 'HELD_RUN', round(choice.HELD_RUN * factor))
    assert not right()


def test_a_limit_cycle_after_a_step_s_ringing_goes_to_the_mode_tracker():
    """A step's ringing (30 mm at 1.6 Hz, zeta 6 %) into a limit cycle: the watch, whose largest
    block is the ringing's, reads the steady level after it driven (93 % at 60 s), while
    :func:`core.choice.decide` over the kept samples reads a free decay of one mode, and the
    free-decay test holds back every free estimate: the node stayed silent (0-2 estimates in
    120 s). With ``HELD_RUN`` estimates held, that contradiction is a steady oscillation after a
    transient: the mode tracker, estimates within 5 % of the cycle."""
    from vib_estimator.sim.signals import step_into_limit_cycle

    t, y = step_into_limit_cycle(80.0, 1000.0, 1)
    stream = EstimatorStream(EstimatorConfig(), now=0.0, deciding=True)
    got = []
    decided = decisions(stream, t, y, step=1000, estimates=got)
    steady = [(s, x) for s, x in decided if 'a steady oscillation' in x.reason]
    assert len(steady) == 1 and steady[0][1].modes == 3 and 60 <= steady[0][0] <= 66, decided
    f = np.array([e.frequency_hz for _, _, e in got])
    assert len(f) >= 30 and np.all(np.abs(f / 1.8116 - 1) <= 0.05)


def test_a_clean_decay_sets_the_streams_window_as_analyze_decides_it():
    """Once its free stretch has shown a decay (core.choice.decay_zeta), the deciding stream
    takes analyze's window for it (``min_periods`` 0.9 and its ``early_std_rel``): a clean
    2 Hz decay's later estimates after ~0.9 periods, all within 2 %. A decay damped at 3 % gets
    no such window (core.choice.FAST_ZETA): the mode tracker (core.choice.heavily_damped), 90 %
    of its later estimates within 2 % (its tail in the noise: 2.2 %); a decay that never rings
    down into its window (none shown: a driven response's first seconds) is not read."""
    import sys
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / 'core'))
    from test_choice import pluck_with_a_move

    def run(zeta):
        t, y = pluck_with_a_move(0.0, 45.0, zeta=zeta)
        stream = EstimatorStream(EstimatorConfig(), now=0.0, deciding=True)
        got = []
        decided = decisions(stream, t, y, step=1000, estimates=got)
        late = [e for k, _, e in got if decided and k > decided[0][0]]
        return decided, late, stream

    decided, late, stream = run(0.003)
    assert [(d.excitation, d.min_periods) for _, d in decided] == [('free', 0.9)]
    assert decided[0][0] <= 10 and stream.config.min_periods == 0.9
    assert stream.config.early_std_rel > 0 and len(late) >= 10
    assert np.median([e.convergence_time * 2.0 for e in late]) <= 0.95
    assert all(abs(e.frequency_hz / 2 - 1) <= 0.02 for e in late)
    decided, late, stream = run(0.03)
    assert [d.modes for _, d in decided] == [3] and np.isnan(decided[0][1].min_periods)
    assert 'damped at 3.0 %' in decided[0][1].reason and len(late) >= 10
    assert stream.config.min_periods == EstimatorConfig().min_periods
    errors = np.array([abs(e.frequency_hz / 2 - 1) for e in late])
    assert np.mean(errors <= 0.02) >= 0.9 and np.all(errors <= 0.05)


THREE = ((8.0, 1.0, 0.003), (21.0, 0.3, 0.002), (55.0, 0.05, 0.002))


def each_mode(estimates, truth):
    """Per true mode (the estimates attributed to the nearest): (count, share within 2 %)."""
    f = np.array([e.frequency_hz for e in estimates])
    rel = f[:, None] / np.asarray(truth) - 1
    near = np.argmin(np.abs(rel), axis=1)
    ok = np.abs(rel[np.arange(len(f)), near]) <= 0.02
    return [(int(np.sum(near == k)), float(np.mean(ok[near == k]))) for k in range(len(truth))]


def test_a_decay_whose_modes_ring_on_goes_to_the_mode_tracker():
    """An 8 / 21 / 55 Hz pluck (1 : 0.3 : 0.05): the one-mode estimator follows 8 Hz and is never
    silent, but the decay's last half still shows its modes (``LASTING_SHARE``): the deciding
    stream takes the mode tracker (``modes`` 3, primed) 2 s after the pluck, and all three modes
    are then reported, each within 2 % (the 55 Hz one until it rings down into the noise)."""
    got = []
    stream = EstimatorStream(EstimatorConfig(), now=0.0, deciding=True)
    decided = decisions(stream, *plucked(THREE), step=500, estimates=got)
    assert [(x.excitation, x.modes) for _, x in decided] == [('free', 3)]
    assert decided[0][0] <= 3 and stream.config.modes == 3
    after = [e for k, _, e in got if k > decided[0][0]]
    per_mode = each_mode(after, [m[0] for m in THREE])
    assert all(n >= 20 and within >= 0.95 for n, within in per_mode), per_mode


def test_a_structure_moved_again_is_no_decay_of_several_modes(monkeypatch):
    """The arm moved at random times (1.5 s +- 50 %, seed 1): a stretch the envelope read as one
    decay since an onset (6 s; the later moves' onsets unseen) showed the arm's 1.33 Hz and the
    moves' 2.33 Hz, and its last half too -- the mode tracker, at 10 s, and estimates up to 24 %
    off until the driven decision. Its last half is no free decay at 1.33 Hz: no tracker, every
    estimate within 2 % (the 8 / 21 / 55 Hz pluck, whose last half is one, goes on to it:
    test_a_decay_whose_modes_ring_on_goes_to_the_mode_tracker)."""
    from vib_estimator.core import choice
    from vib_estimator.sim import arm_model

    rec = arm_model.back_and_forth(110, 1.5, 0.5, 1.0, 0.5, seed=1)
    f0 = float(rec.f_true[0])

    def run():
        got = []
        stream = EstimatorStream(EstimatorConfig(), now=0.0, deciding=True)
        decided = decisions(stream, rec.t, rec.torque, step=500, estimates=got)
        return [(x.excitation, x.modes) for _, x in decided], [e.frequency_hz for *_, e in got]

    decided, f = run()
    assert decided == [('ambient', 0)] and f and all(abs(v / f0 - 1) < 0.02 for v in f)
    monkeypatch.setattr(choice, 'is_free_decay', lambda *args: None)  # untested: as before
    decided, f = run()
    assert decided[0] == ('free', 3) and max(abs(v / f0 - 1) for v in f) > 0.05


@pytest.mark.skipif(not BEAM_50.is_file(), reason='../shared/real-data is absent')
@pytest.mark.parametrize('factor', [1e-3, 1e3])
def test_modes_that_ring_on_are_read_in_the_decays_last_half(monkeypatch, factor):
    """``LASTING_SHARE``: the 8 / 21 / 55 Hz pluck goes to the mode tracker, the real 50 cm beam,
    whose 39 Hz mode shows beside the 6.05 Hz one in its first seconds only, keeps one estimator
    (0.9 periods). At 0.001x the last share is too short to read (the pluck stays with 8 Hz
    alone), at 1000x it is the whole decay (the beam goes to the tracker)."""
    from vib_estimator.core import choice
    from vib_estimator.io.csv_reader import read_csv_series

    beam = read_csv_series(BEAM_50)

    def right():
        streams = [EstimatorStream(EstimatorConfig(), now=0.0, deciding=True) for _ in range(2)]
        three = decisions(streams[0], *plucked(THREE), step=500)
        one = decisions(streams[1], beam.t - beam.t[0], np.ravel(beam.y), step=1000)
        return [d.modes for _, d in three] == [3] and [
            (d.modes, d.min_periods) for _, d in one
        ] == [(0, 0.9)]

    assert right()
    monkeypatch.setattr(choice, 'LASTING_SHARE', choice.LASTING_SHARE * factor)
    assert not right()


class Counted:
    """``core.choice``'s free-decay tests and window reads (``decide`` without ``stream``),
    counted."""

    def __init__(self, monkeypatch):
        from vib_estimator.core import choice

        self.tests = self.reads = 0
        test, read = choice.is_free_decay, choice.decide

        def counting_test(*args):
            self.tests += 1
            return test(*args)

        def counting_read(*args, **kw):
            self.reads += 'stream' not in kw
            return read(*args, **kw)

        monkeypatch.setattr(choice, 'is_free_decay', counting_test)
        monkeypatch.setattr(choice, 'decide', counting_read)

    def run(self, t, y, step=500):
        """Decisions, the estimates up to the first, and (tests, reads) of a deciding stream."""
        self.tests = self.reads = 0
        stream = EstimatorStream(EstimatorConfig(), now=0.0, deciding=True)
        got = []
        decided = decisions(stream, t, y, step=step, estimates=got)
        early = [e for k, _, e in got if not decided or k <= decided[0][0]]
        return decided, early, (self.tests, self.reads)


@pytest.mark.parametrize('factor', [1e-3, 1e3])
def test_a_free_stretch_that_passed_the_free_decay_test_is_trusted(monkeypatch, factor):
    """A free stretch whose estimates passed the free-decay test ``TRUSTED_PASSES`` times
    running (no onset, no block read driven between) is trusted: a 12 s pluck's ~40 estimates
    take at most 5 tests (each ~1 ms: 4 us a sample at an estimate a period; the first, from
    the pluck's first period since the kernel restarts its segment there, too short to test),
    while a driven input's are all tested, none published before the decision."""
    from vib_estimator.core import choice
    from vib_estimator.sim.ambient import ambient_record

    counted = Counted(monkeypatch)

    def right():
        _, free, (tests, _) = counted.run(*plucked(((5.0, 1.0, 0.005),)))
        t, y, _ = ambient_record(50, 500, [(5.0, 0.01, 1.0)], 20, 0)
        _, driven, (shaken, _) = counted.run(t, y)
        return 1 <= tests <= 5 and len(free) >= 5 and driven == [] and shaken >= 20

    assert right()
    monkeypatch.setattr(choice, 'TRUSTED_PASSES', round(choice.TRUSTED_PASSES * factor))
    assert not right()


@pytest.mark.skipif(not BEAM_50.is_file(), reason='../shared/real-data is absent')
@pytest.mark.parametrize('factor', [1e-3, 1e3])
def test_a_decay_showing_several_modes_is_read_again_for_its_window(monkeypatch, factor):
    """The real 50 cm beam's first seconds show its 39 Hz mode beside the 6.05 Hz one: its
    window is read again, a second later (``WINDOW_READS``), and gets 0.9 periods; a decay of
    three modes is read at most that often (each read twice, the decay and its last half, whose
    rule is off here: ``LASTING_SHARE`` 0; 12 reads in 30 s)."""
    from vib_estimator.core import choice
    from vib_estimator.io.csv_reader import read_csv_series

    counted = Counted(monkeypatch)
    beam = read_csv_series(BEAM_50)
    monkeypatch.setattr(choice, 'LASTING_SHARE', 0.0)  # (its last half too short to read)

    def right():
        decided, _, _ = counted.run(beam.t - beam.t[0], np.ravel(beam.y), step=1000)
        _, _, (_, reads) = counted.run(*plucked(THREE, 30.0))
        return [d.min_periods for _, d in decided] == [0.9] and reads <= 2 * 6

    assert right()
    monkeypatch.setattr(choice, 'WINDOW_READS', round(choice.WINDOW_READS * factor))
    assert not right()


def test_an_identifier_that_finds_no_mode_says_which_window_helps():
    """Under excitation ambient, a 30 s window on a 0.3 Hz mode publishes nothing: after two
    windows (and a minute) the status says why in words -- the window's correlation times of the
    input's lowest peak -- and which ambient_window_s helps (not a counter alone); logged once."""
    from vib_estimator.sim.ambient import ambient_record

    t, y, _ = ambient_record(150, 100, [(0.3, 0.01, 1.0)], 20, 1)
    stream = EstimatorStream(EstimatorConfig(excitation='ambient', ambient_window_s=30.0), 0.0)
    stamps = EPOCH_NS + np.round(t * 1e9).astype(np.int64)
    statuses = []
    for k in range(0, len(t), 100):
        assert not feed(stream, stamps[k : k + 100], y[k : k + 100])
        statuses.append(stream.status(now=k / 100))
    said = [k for k, s in enumerate(statuses) if 'ambient_window_s:=300' in s.message]
    assert said and said[0] == 60 and said == list(range(60, len(statuses)))
    assert '1.1 correlation times of the 0.3 Hz peak' in statuses[-1].message
    assert sum('ambient_window_s:=' in (s.log or '') for s in statuses) == 1


def test_a_periodic_drive_s_lines_go_to_the_identifier_and_leave_with_the_next_decision():
    """The stream decides as ``analyze`` does: a cycle's lines beside a driven mode set
    ``lines_hz`` with the identifier (its estimates the mode's alone); a later decision without
    a periodic drive clears them."""
    from vib_estimator.sim.ambient import ambient_record

    t, y, _ = ambient_record(150, 100, [(5.0, 0.01, 1.0)], 30, 0)
    cycle = sum(1.5 / k * np.sin(2 * np.pi * k * 0.8 * t + k) for k in (1, 3, 5, 7, 9))
    stream = EstimatorStream(EstimatorConfig(), now=0.0, deciding=True)
    estimates = []
    got = decisions(stream, t, y + cycle, estimates=estimates)
    assert got and got[0][1].excitation == 'ambient'
    assert stream.config.lines_hz and stream.config.lines_hz[0] == pytest.approx(0.8, rel=1e-3)
    driven = [e.frequency_hz for _, x, e in estimates if x == 'ambient']
    assert driven and all(abs(f / 5.0 - 1) < 0.02 for f in driven)
    assert stream.counters['rejected_line'] > 0
    stream.configure(stream.config.replace(**decide(t, y).changes()))
    assert stream.config.lines_hz is None and stream.config.excitation == 'ambient'
    # from the identifier to auto (the choice's way out of a driven decision, when the stream
    # reads free): what the driven decisions set stays, for the next driven stretch
    from vib_estimator.core.choice import Decision

    stream.configure(stream.config.replace(lines_hz=[0.8], band_hz=[0.5, 45.0]))
    window = stream.config.ambient_window_s
    out = Decision('auto', 12.0, 0.0, np.nan, np.nan, (), 'freed', keeps=True)
    stream.configure(stream.config.replace(**out.changes()))
    assert stream.config.excitation == 'auto' and stream.config.lines_hz == (0.8,)
    assert stream.config.band_hz == (0.5, 45.0) and stream.config.ambient_window_s == window
