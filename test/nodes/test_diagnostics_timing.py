# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""/diagnostics stay timely while estimator_node is behind its work (issue 40: a soak once saw
them silent for 3.2 s, and 5.4 s at a start on a loaded machine). The node's single
EventsExecutor thread runs the 1-s timer's event after every event queued before it, so:

* the samples held during a warm-up are fed in slices (``DRAIN_SLICE_S`` a turn), the timer's
  event between them (fed at once they were one long callback);
* a node behind its input (a backlog: here each sample made to cost 2 ms, as on a starved CPU)
  publishes its diagnostics from the data path once the timer's are ``DIAGNOSTICS_OVERDUE`` late;
* a ``~/self_test`` of a configuration not tested yet runs in a thread, its calls answered once it
  is done (run in the executor's callback, under the identifier, it held /diagnostics silent for
  3.8-5.2 s in soaks on a loaded machine).

In process, through the node's topic; the publication times of /diagnostics are recorded at the
node's publisher (a subscriber in the same executor would wait behind the same queue)."""

from __future__ import annotations

import threading
import time

import numpy as np
from std_srvs.srv import Trigger

from vib_estimator.nodes import estimator_node as E
from vib_estimator.nodes import stream as S
from vib_estimator.nodes.runner import spin_until

from .test_estimator_node import make_probe, message, sine_stamps, values_of

__all__ = ['make_probe']  # the fixture, used by name

#: the samples of each phase, and what each costs the node (busy wall time, s): 4 s of work each
SAMPLES = 2000
COST_S = 0.002
#: the most samples fed between two publications: with the timer and the overdue limit, at most
#: a second and a half's (750: each sample costs at least COST_S; fewer when the machine is
#: loaded); a whole phase's (2000) when the diagnostics wait behind it. Counted in samples, not
#: seconds, so that a loaded machine slowing the whole test does not fail it.
MOST_BETWEEN = SAMPLES // 2


class Recorder:
    """Stands for the node's /diagnostics publisher: at each publication, the samples fed."""

    def __init__(self, publisher):
        self.publisher = publisher
        self.fed = 0  # samples fed so far (counted by :meth:`slow`)
        self.at = []  # self.fed at each publication

    def publish(self, msg) -> None:
        self.at.append(self.fed)
        self.publisher.publish(msg)

    def slow(self, feed):
        """``feed`` costing :data:`COST_S` of wall time a sample (a node starved of CPU)."""

        def fed(stamp, value):
            until = time.perf_counter() + COST_S
            while time.perf_counter() < until:
                pass
            self.fed += 1
            return feed(stamp, value)

        return fed

    def between(self, start: int, end: int) -> list:
        """The samples fed between publications, from ``start`` fed to ``end``."""
        marks = [start] + [n for n in self.at if start < n < end] + [end]
        return list(np.diff(marks))


def test_a_node_behind_its_work_publishes_its_diagnostics_every_second(make_probe, monkeypatch):
    # a warm-up held until the test lets it end (its kernels are compiled: it ends at once)
    release = threading.Event()
    monkeypatch.setattr(S, 'is_warm', lambda config: False)
    monkeypatch.setattr(S, 'warm', lambda config: release.wait(60.0))
    monkeypatch.setattr(S, 'interpretable', lambda config, channels: False)  # held meanwhile
    p = make_probe()
    node = p.node
    recorder = Recorder(node._diagnostics_pub)
    node._diagnostics_pub = recorder
    node._stream.feed = recorder.slow(node._stream.feed)
    node._feed = node._stream.feed
    stamps = sine_stamps(2 * SAMPLES)
    values = np.sin(2 * np.pi * 1.33 * np.arange(2 * SAMPLES) / 500.0)
    msgs = [message(p.input_type, 'torque.z', s, v) for s, v in zip(stamps, values)]

    # 1. the warm-up's held samples, fed in slices
    for msg in msgs[:SAMPLES]:
        p.pub.publish(msg)
    assert spin_until(p.executor, lambda: node._stream.held_samples == SAMPLES, 20.0)
    assert not node._ready and recorder.fed == 0
    release.set()
    assert spin_until(p.executor, lambda: node._ready, 60.0), node._stream.held_samples
    between = recorder.between(0, SAMPLES)
    assert recorder.fed == SAMPLES and max(between) <= MOST_BETWEEN, between

    # 2. a backlog of input in front of the timer's event
    for msg in msgs[SAMPLES:]:
        p.pub.publish(msg)
    t0 = time.monotonic()
    assert spin_until(p.executor, lambda: node.counters['received'] == 2 * SAMPLES, 60.0)
    seconds = time.monotonic() - t0
    between = recorder.between(SAMPLES, 2 * SAMPLES)
    assert max(between) <= MOST_BETWEEN, between
    # and not more often than the timer's period (one from the data path per late turn)
    assert len(between) - 1 <= seconds / E.H.DIAGNOSTICS_PERIOD + 2, (between, seconds)
    assert node.counters['received'] == 2 * SAMPLES and node.counters['samples_missing'] == 0


def test_a_burst_of_self_tests_holds_neither_diagnostics_nor_input_nor_other_calls(
    make_probe, monkeypatch
):
    # the self-test's run held until the test lets it go on (then the real one: the identifier's
    # tones, a configuration not tested yet)
    release = threading.Event()
    runs, expired = [], []
    real = S.in_process  # (the tones' own process)

    def held(*args):
        runs.append(args)
        if not release.wait(10.0):  # (in the executor's thread: it held everything that long)
            expired.append(args)
        return real(*args)

    monkeypatch.setattr(S, 'in_process', held)
    p = make_probe(excitation='ambient')
    clients = p.trigger_clients()
    # input first: the tones are made for its rate (a rate measured meanwhile is another run)
    stamps = sine_stamps(1000)
    values = np.sin(2 * np.pi * 1.33 * np.arange(1000) / 500.0)
    p.feed(stamps[:500], values[:500])
    p.wait_status(lambda status: values_of(status).get('sample_rate_hz', 'nan') != 'nan')
    tests = [clients['self_test'].call_async(Trigger.Request()) for _ in range(20)]
    assert spin_until(p.executor, lambda: len(runs) == 1, 10.0)
    # while it runs: diagnostics, input taken, another service answered
    arrived = len(p.diagnostics)
    assert spin_until(p.executor, lambda: len(p.diagnostics) >= arrived + 3, 8.0)
    assert not expired, 'the self-test held the executor thread'
    p.feed(stamps[500:], values[500:])
    reset = clients['reset'].call_async(Trigger.Request())
    assert spin_until(p.executor, reset.done, 10.0) and reset.result().success
    assert not any(f.done() for f in tests) and p.node.counters['received'] == 1000
    release.set()
    assert spin_until(p.executor, lambda: all(f.done() for f in tests), 60.0)
    answers = {(f.result().success, f.result().message) for f in tests}
    assert len(runs) == 1 and len(answers) == 1, answers  # one run answers the burst
    ok, message = answers.pop()
    assert ok and message.startswith('passed: 3 tones at 500 Hz'), message
    # a call now finds the result kept
    again = clients['self_test'].call_async(Trigger.Request())
    assert spin_until(p.executor, again.done, 10.0) and again.result().message == message
    assert len(runs) == 1
