# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""The stamps' cadence (nodes/cadence.py, no rclpy): every gap counted whatever its length, a
drained backlog told from a live stream, a jump not counted as lost samples (issue 40)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from vib_estimator.nodes import cadence as C

PERIOD = 2_000_000  # ns: 500 Hz
#: the node takes a backlogged message in 40 us of steady time
TAKE_S = 40e-6


class Stream:
    """A source at 500 Hz of stamps, ``speed`` stamp seconds per steady second, seen by a
    :class:`~vib_estimator.nodes.cadence.Cadence`."""

    def __init__(self, speed=1.0, seed=0):
        self.cadence = C.Cadence()
        self.k = 0  # the next sample the source makes
        self.now = 100.0
        self.speed = speed
        self.jumps = []
        self.rng = np.random.default_rng(seed)

    @property
    def counters(self):
        return self.cadence.counters

    def live(self, n):
        """n samples taken as they are made (steady time jittered by 10 % of a period)."""
        for _ in range(n):
            self.now += PERIOD * 1e-9 / self.speed * (1 + 0.1 * self.rng.uniform(-1, 1))
            self.take(self.k)
            self.k += 1

    def take(self, k):
        if self.cadence.observe(1_000_000_000_000 + k * PERIOD, self.now):
            self.jumps.append(k)

    def source_gap(self, missing):
        """The source skips ``missing`` samples (steady time goes on)."""
        self.now += missing * PERIOD * 1e-9 / self.speed
        self.k += missing

    def stall(self, seconds, depth):
        """The node stops for ``seconds`` while the source goes on; a keep-last queue of
        ``depth`` keeps the newest, which the node then drains; the samples lost."""
        made = round(seconds * self.speed / (PERIOD * 1e-9))
        self.now += seconds
        first = self.k + max(made - depth, 0)
        for k in range(first, self.k + made):
            self.now += TAKE_S
            self.take(k)
        self.k += made
        return first - (self.k - made)


@pytest.mark.parametrize('speed', [1.0, 10.0])
def test_every_gap_in_the_cadence_is_counted_whatever_its_length(speed):
    s = Stream(speed)
    s.live(3000)
    missing = [1, 2, 3, 9, 50, 700]
    for m in missing:
        s.source_gap(m)
        s.live(600)
    c = s.counters
    assert c['cadence_gaps'] == len(missing)
    assert c['samples_missing'] == c['missing_in_gaps'] == sum(missing)
    assert c['lost_in_queue'] == 0 and c['stamp_jumps'] == 0 and not s.jumps


@pytest.mark.parametrize('speed', [1.0, 10.0])
def test_a_stall_that_overflows_the_queue_is_lost_in_the_queue(speed):
    """A 4-s stop of the node (SIGSTOP) with a keep-last queue of 1000: the samples it missed
    were made and replaced in the queue, not a gap of the source (was: "0 gaps (10003 samples
    lost)"); a source gap after it is still a gap."""
    s = Stream(speed)
    s.live(3000)
    lost = s.stall(4.0, 1000)
    assert lost == round(4.0 * speed * 500) - 1000
    s.live(100)
    s.source_gap(5)
    s.live(600)
    c = s.counters
    assert c['cadence_gaps'] == 2 and c['lost_in_queue'] == lost
    assert c['missing_in_gaps'] == 5 and c['samples_missing'] == lost + 5
    assert c['stamp_jumps'] == 0


def test_a_forward_jump_is_one_jump_not_samples_lost():
    s = Stream(10.0)
    s.live(3000)
    s.k += round(4290e9 / PERIOD)  # the stamps jump 4290 s ahead in one period of steady time
    s.live(600)
    c = s.counters
    assert s.jumps == [s.k - 600] and c['stamp_jumps'] == 1
    assert c['samples_missing'] == 0 and c['cadence_gaps'] == 0


def test_a_long_absence_of_the_source_is_a_gap_not_a_jump():
    """The source gone for 10 s of steady time, its stamps 10 s on: missing, not a jump."""
    s = Stream(1.0)
    s.live(3000)
    s.source_gap(5000)
    s.live(600)
    assert s.counters['missing_in_gaps'] == 5000 and s.counters['stamp_jumps'] == 0


def test_a_gap_when_the_stream_stops_is_counted_at_the_next_flush():
    s = Stream(1.0)
    s.live(3000)
    s.source_gap(7)
    assert not s.cadence.gap_pending
    s.live(1)
    assert s.counters['samples_missing'] == 0  # not told apart yet
    assert s.cadence.gap_pending  # (the node keeps the sampling rate over such a status)
    s.cadence.flush(s.now + 0.1)
    assert s.counters['samples_missing'] == 0 and s.cadence.gap_pending
    s.cadence.flush(s.now + 1.0)
    assert s.counters['samples_missing'] == s.counters['missing_in_gaps'] == 7
    assert not s.cadence.gap_pending


def test_a_step_back_is_followed_and_a_small_one_ignored():
    s = Stream(1.0)
    s.live(3000)
    s.take(s.k - 3)  # out of order: the core skips it; no gap when the stream goes on
    s.live(10)
    assert s.counters['samples_missing'] == 0
    s.k = 0  # the source restarted with time going back
    s.live(600)
    c = s.counters
    assert c['samples_missing'] == 0 and c['stamp_jumps'] == 0 and c['cadence_gaps'] == 0


def test_messages_stamped_behind_the_last_are_taken_for_the_watchdog():
    """A source restarted 0.3 s back in time (within ``back_ns``: its stamps stay behind the last
    one followed, the core skips them as out of order): the cadence keeps its last stamp, but
    every message is taken, so the watchdog sees no silence (before, it saw none taken for as
    long as the stamps stayed behind, and re-created the subscription of a live source)."""
    cadence = C.Cadence(back_ns=500_000_000)
    for k in range(100):  # 1 kHz, in real time
        cadence.observe(k * 1_000_000, 10.0 + k * 1e-3)
    for k in range(200):  # restarted 0.3 s back: 0.2 s of stamps still behind the last
        cadence.observe(k * 1_000_000 - 200_000_000, 11.0 + k * 1e-3)
    assert cadence.taken_at == pytest.approx(11.199)
    c = cadence.counters
    assert c['stamp_jumps'] == 0 and c['cadence_gaps'] == 0  # (the stamps behind: not followed)
    # read from the last stamp followed (10.099 s), the watchdog would call it silent
    assert fired(C.Watchdog(), 11.2, 14.0, 10.099) != []
    assert fired(C.Watchdog(), 11.2, 14.0, cadence.taken_at) == []


def fired(w, start, stop, taken_at, matched=1, period=1e-4, step=1.0):
    """The times a watchdog checked every ``step`` s from ``start`` to ``stop`` said to
    re-create."""
    times = np.arange(start, stop, step)
    return [float(t) for t in times if w.check(float(t), taken_at, matched, period)]


def test_the_watchdog_recreates_a_silent_subscription_once_then_backs_off():
    w = C.Watchdog()
    assert fired(w, 0.0, 10.0, 0.0) == []  # nothing ever received: not armed
    assert fired(w, 10.0, 100.0, 9.5) == [13.0, 19.0, 31.0, 55.0]  # 3 s, then 6, 12, 24 ...
    assert w.episode == 4
    assert fired(w, 100.0, 200.0, 9.5, matched=0) == []  # nobody publishes: nothing to recover
    assert fired(w, 200.0, 205.0, 200.5) == [204.0] and w.episode == 1  # data again: new episode


def test_the_watchdog_waits_for_many_expected_periods():
    w = C.Watchdog()
    assert fired(w, 1.0, 12.0, 1.0, period=0.01) == [11.0]  # 100 Hz: 1000 periods = 10 s


def test_the_watchdog_does_not_count_the_time_the_node_itself_was_held():
    """A SIGSTOP of the node: no check for 3 s, then no data yet -- not a silence of the input
    (the soak saw one re-creation after a stop of the node); a real silence after it still is."""
    w = C.Watchdog()
    assert fired(w, 10.0, 11.0, 9.9) == []
    assert fired(w, 14.0, 16.0, 9.9) == []  # held from 10 to 14
    assert fired(w, 16.0, 20.0, 9.9) == [17.0]  # 3 s after the node ran again


def test_a_message_taken_just_before_the_node_was_held_does_not_start_the_silence_there():
    """The estimator_node's log of a 5-s SIGSTOP: checked at 37.27 s, a message taken at 37.72 s,
    stopped, checked again at 42.73 s -- it re-created the subscription at once ('no message
    taken for 5.0 s'): the silence was measured from the message taken before the stall."""
    w = C.Watchdog()
    for t in (35.25, 36.25, 37.25):
        assert not w.check(t, t, 1, math.nan)  # data flows
    assert not w.check(42.75, 37.75, 1, math.nan)  # held from 37.75: the silence starts now
    assert [t for t in (43.75, 44.75, 46.0) if w.check(t, 37.75, 1, math.nan)] == [46.0]


@pytest.mark.parametrize(
    'name, factor, test',
    [
        ('DRAIN_RATIO', 1e-3, test_every_gap_in_the_cadence_is_counted_whatever_its_length),
        ('DRAIN_RATIO', 1e3, test_a_stall_that_overflows_the_queue_is_lost_in_the_queue),
        ('JUMP_RATIO', 1e-3, test_a_stall_that_overflows_the_queue_is_lost_in_the_queue),
        ('JUMP_RATIO', 1e3, test_a_forward_jump_is_one_jump_not_samples_lost),
        ('GAP_FACTOR', 1e3, test_every_gap_in_the_cadence_is_counted_whatever_its_length),
        ('DECIDE_AFTER_S', 1e3, test_a_gap_when_the_stream_stops_is_counted_at_the_next_flush),
        ('DECIDE_AFTER_S', 1e-3, test_a_gap_when_the_stream_stops_is_counted_at_the_next_flush),
        ('RATE_WINDOW_S', 1e3, test_a_stall_that_overflows_the_queue_is_lost_in_the_queue),
        (
            'WATCHDOG_MIN_S',
            1e3,
            test_the_watchdog_recreates_a_silent_subscription_once_then_backs_off,
        ),
        (
            'WATCHDOG_MIN_S',
            1e-3,
            test_the_watchdog_recreates_a_silent_subscription_once_then_backs_off,
        ),
        ('WATCHDOG_PERIODS', 1e3, test_the_watchdog_waits_for_many_expected_periods),
        ('WATCHDOG_PERIODS', 1e-3, test_the_watchdog_waits_for_many_expected_periods),
        (
            'WATCHDOG_HELD_S',
            1e3,
            test_the_watchdog_does_not_count_the_time_the_node_itself_was_held,
        ),
        (
            'WATCHDOG_HELD_S',
            1e-3,
            test_the_watchdog_recreates_a_silent_subscription_once_then_backs_off,
        ),
        (
            'WATCHDOG_HELD_S',
            1e3,
            test_a_message_taken_just_before_the_node_was_held_does_not_start_the_silence_there,
        ),
    ],
)
def test_the_constants_are_pinned(monkeypatch, name, factor, test):
    """Set to 0.001x or 1000x, each constant fails a test."""
    monkeypatch.setattr(C, name, getattr(C, name) * factor)
    with pytest.raises(AssertionError):
        test(10.0) if 'speed' in test.__code__.co_varnames else test()
