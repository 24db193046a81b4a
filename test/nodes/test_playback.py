# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""nodes.playback: the replayer's schedule on a fake steady clock, without rclpy."""

from __future__ import annotations

import subprocess
import sys
from dataclasses import dataclass

import pytest

from vib_estimator.nodes.playback import EmptyPlayback, Playback, StartGate

S = 1_000_000_000  # ns per second


@dataclass
class Msg:
    log_time_ns: int


def bag(times_s, first_ns=0):
    return lambda: iter([Msg(int(t * S)) for t in times_s if int(t * S) >= first_ns])


def played(playback, now_s):
    return [m.log_time_ns / S for m in playback.due(int(now_s * S))]


def test_imports_no_rclpy():
    code = 'import sys, vib_estimator.nodes.playback; assert "rclpy" not in sys.modules'
    subprocess.run([sys.executable, '-c', code], check=True, timeout=60)


def test_messages_are_due_at_their_log_time_divided_by_rate():
    playback = Playback(bag([10, 11, 12, 14]), 10 * S, rate=2.0)
    assert played(playback, 100) == []  # not started
    playback.start(100 * S)
    assert played(playback, 100) == [10]
    assert played(playback, 100.49) == []
    assert played(playback, 100.5) == [11]
    assert played(playback, 102.0) == [12, 14]  # late ticks catch up, in order
    assert playback.finished


def test_pause_resume_rate_and_play_next_move_the_anchor():
    playback = Playback(bag([0, 1, 2, 3, 4]), 0)
    playback.start(0)
    assert played(playback, 0.5) == [0]
    assert playback.pause(int(0.5 * S)) and not playback.pause(S)
    assert played(playback, 10) == [] and playback.bag_time_ns(10 * S) == S // 2
    assert playback.play_next(10 * S).log_time_ns == S  # at once, bag time = its log time
    assert playback.bag_time_ns(11 * S) == S
    assert playback.resume(20 * S) and not playback.resume(20 * S)
    assert playback.play_next(20 * S) is None  # only while paused
    assert played(playback, 21) == [2]
    playback.set_rate(4.0, 21 * S)  # bag time 2 s, from now 4x
    assert playback.bag_time_ns(21 * S) == 2 * S
    assert played(playback, 21.25) == [3] and played(playback, 21.5) == [4]


def test_loop_starts_over_from_the_first_message():
    playback = Playback(bag([5, 6]), 5 * S, loop=True)
    playback.start(0)
    assert played(playback, 1) == [5, 6] and playback.loops == 1 and not playback.finished
    assert played(playback, 1) == [5]  # the loop restarts at the end's tick time
    assert played(playback, 2) == [6] and playback.loops == 2


def test_start_offset_and_empty_playback():
    assert played_all(Playback(bag([0, 1, 2], first_ns=S), S)) == [1, 2]
    with pytest.raises(EmptyPlayback):
        Playback(bag([0, 1], first_ns=5 * S), 5 * S)


def played_all(playback):
    playback.start(0)
    return played(playback, 1e6)


def test_start_paused_holds_at_the_first_message():
    playback = Playback(bag([0, 1]), 0, paused=True)
    playback.start(0)
    assert played(playback, 5) == []
    playback.resume(5 * S)
    assert played(playback, 5) == [0] and played(playback, 6) == [1]


def test_start_gate_waits_for_subscribers_delay_and_timeout():
    gate = StartGate(0, delay_s=1.0, wait_timeout_s=5.0)
    assert not gate.is_open(int(0.5 * S), True)  # delay first
    assert gate.is_open(S, True) and not gate.timed_out
    gate = StartGate(0, delay_s=0.0, wait_timeout_s=5.0)
    assert not gate.is_open(int(4.9 * S), False)
    assert gate.is_open(5 * S, False) and gate.timed_out  # plays anyway, and says so
    gate = StartGate(0, delay_s=0.0, wait_timeout_s=0.0)
    assert gate.is_open(0, False)  # wait_timeout 0: at once
