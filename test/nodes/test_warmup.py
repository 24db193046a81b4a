# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""A node is live from its first second: a cold start (empty numba cache) answers its services and
publishes /diagnostics while its kernels compile, estimates with them uncompiled meanwhile (the
default configuration) or holds its input (the others), and Ctrl-C leaves a cache the next start
uses. The warm-up's bookkeeping itself is tested without ROS below."""

from __future__ import annotations

import math
import os
import signal
import subprocess
import sys
import time

import numpy as np
import pytest

from vib_estimator.core import EstimatorConfig, create_estimator
from vib_estimator.core.estimator import FrequencyEstimator
from vib_estimator.io.fields import seconds_since
from vib_estimator.nodes.stream import (
    WARMUP_BUFFER,
    WARMUP_MESSAGE,
    EstimatorStream,
    interpretable,
)


def _tone(n, rate=500.0, f=4.0):
    t = np.arange(n) / rate
    return t, np.sin(2 * np.pi * f * t) + 0.01 * np.cos(3 * t)


def test_held_samples_are_drained_in_order_into_the_estimator(monkeypatch):
    from vib_estimator.nodes import stream as S

    # a compile key the session fixture did not warm, held as a configuration that has no
    # uncompiled estimator (ambient, auto, several channels) is
    monkeypatch.setattr(S, 'interpretable', lambda config, channels: False)
    config = EstimatorConfig(refine=0, band_hz=(1.0, 20.0))
    stream = EstimatorStream(config, time.monotonic(), background=True)
    assert not stream.ready and stream.compiling
    assert not stream.ready
    ok, why = stream.self_test()
    assert not ok and why.startswith('busy')
    ok, why = stream.reset()
    assert not ok and WARMUP_MESSAGE in why
    assert stream.status(time.monotonic()).message == WARMUP_MESSAGE
    t, y = _tone(2000)
    stamps = (1_000_000_000 + np.round(t * 1e9)).astype(np.int64)
    for k in range(len(t)):
        stream.hold(int(stamps[k]), float(y[k]), k)
    deadline = time.monotonic() + 120
    drained = None
    while drained is None and time.monotonic() < deadline:
        drained = stream.poll()
        time.sleep(0.005)
    assert drained is not None and stream.ready
    got = [(tag, e.frequency_hz) for tag, estimates in drained for e in estimates]
    base = np.array([seconds_since(int(s), int(stamps[0])) for s in stamps])  # the node's base
    direct = FrequencyEstimator(config).process(base, y)
    assert [f for _, f in got] == list(direct.frequency_hz)  # the same floats, in order
    tags = [tag for tag, _ in got]
    assert tags == sorted(tags) and len(tags) == len(direct) > 5
    assert stream.counters['received'] == len(t) and stream.counters['dropped_warmup'] == 0


def test_the_default_estimates_uncompiled_while_it_compiles_then_switches_unseen():
    config = EstimatorConfig(refine=0)  # a compile key the session fixture did not warm
    assert interpretable(config, ()) and interpretable(EstimatorConfig(), ())
    stream = EstimatorStream(config, time.monotonic(), background=True)
    assert stream.ready and stream.compiling and stream.estimator.interpreted
    assert stream.reset()[0]
    ok, why = stream.self_test()  # uncompiled too: no waiting for the compile
    assert ok, why
    status = stream.status(time.monotonic())
    assert status.message != WARMUP_MESSAGE and status.values['warmup_s'] >= 0.0
    t, y = _tone(2000)
    stamps = (1_000_000_000 + np.round(t * 1e9)).astype(np.int64)
    got = []
    for k in range(1000):
        got += [e.frequency_hz for e in stream.feed(int(stamps[k]), float(y[k]))]
    uncompiled = len(got)
    assert stream.estimator.interpreted  # only poll switches, between two samples
    deadline = time.monotonic() + 120
    drained = None
    while drained is None and time.monotonic() < deadline:
        drained = stream.poll()
        time.sleep(0.005)
    assert drained is not None and list(drained) == [] and not stream.compiling
    assert not stream.estimator.interpreted and 'warmup_s' not in stream.status(0.0).values
    for k in range(1000, len(t)):
        got += [e.frequency_hz for e in stream.feed(int(stamps[k]), float(y[k]))]
    base = np.array([seconds_since(int(s), int(stamps[0])) for s in stamps])  # the node's base
    direct = FrequencyEstimator(config).process(base, y)
    assert got == list(direct.frequency_hz) and 0 < uncompiled < len(got)  # the same floats
    assert stream.counters['received'] == len(t) and stream.counters['dropped_warmup'] == 0


#: the mode tracker uncompiled: its subspace fit's sums are not reassociated as compiled
#: (subspace.FAST), so its floats differ from the compiled ones, on a noisy signal (this one) by
#: 5e-13 (frequency) to 3e-12 (amplitude) relative; on a noise-free one, whose short-window fits
#: are ill-conditioned, by up to 1e-8 and 1e-7 (the compiled tracker's floats move as much from
#: one CPU to another). The estimates (count, stamps, modes) are the same
UNCOMPILED_MODES_RTOL = 1e-10


@pytest.mark.parametrize(
    'config',
    [EstimatorConfig(refine=0, band_hz=(1.0, 20.0)), EstimatorConfig(refine=0, modes=3)],
    ids=['band_hz', 'modes: 3'],
)
def test_band_and_modes_estimate_uncompiled_while_they_compile(config, monkeypatch):
    """band_hz and the mode tracker, too, estimate at once (not held) while their kernels
    compile, then switch to them between two samples: the batch run's estimates (band_hz: the
    same floats; the mode tracker: UNCOMPILED_MODES_RTOL)."""
    from vib_estimator.nodes import stream as S

    monkeypatch.setattr(S, 'is_warm', lambda config: False)  # a warm-up, however compiled
    assert interpretable(config, ())
    stream = EstimatorStream(config, time.monotonic(), background=True)
    assert stream.ready and stream.compiling and stream.estimator.interpreted
    ok, why = stream.self_test()  # its tones uncompiled would hold the data path up for seconds
    assert not ok and why.startswith('busy')
    t, y = _tone(3000)
    if config.modes:  # a second mode for the tracker, and noise
        y = y + 0.5 * np.sin(2 * np.pi * 11.0 * t)
        y += 0.01 * np.random.default_rng(1).standard_normal(len(t))
    stamps = (1_000_000_000 + np.round(t * 1e9)).astype(np.int64)
    got = []
    for k in range(1500):
        got += stream.feed(int(stamps[k]), float(y[k]))
    uncompiled = len(got)
    deadline = time.monotonic() + 180
    while stream.poll() is None and time.monotonic() < deadline:
        time.sleep(0.005)
    assert not stream.compiling and not stream.estimator.interpreted
    for k in range(1500, len(t)):
        got += stream.feed(int(stamps[k]), float(y[k]))
    base = np.array([seconds_since(int(s), int(stamps[0])) for s in stamps])  # the node's base
    direct = create_estimator(config).process(base, y)
    assert 0 < uncompiled < len(got) == len(direct)
    assert [e.t for e in got] == list(direct.t) and [e.mode for e in got] == list(direct.mode)
    rtol = UNCOMPILED_MODES_RTOL if config.modes else 0.0
    for col in ('frequency_hz', 'amplitude', 'fit'):
        np.testing.assert_allclose([getattr(e, col) for e in got], getattr(direct, col), rtol)


def test_held_samples_are_fed_in_slices_and_later_ones_wait_behind(monkeypatch):
    """poll(budget_s) feeds at least one held sample and stops at its budget (the node's other
    callbacks run between slices); samples held meanwhile are fed after the rest, the estimates
    those of the whole stream in order, and the stream is ready once none is left."""
    from vib_estimator.nodes import stream as S

    monkeypatch.setattr(S, 'is_warm', lambda config: False)  # a warm-up, however compiled
    monkeypatch.setattr(S, 'interpretable', lambda config, channels: False)  # held meanwhile
    config = EstimatorConfig(band_hz=(1.0, 20.0))
    stream = EstimatorStream(config, time.monotonic(), background=True)
    assert not stream.ready and stream.compiling
    t, y = _tone(2000)
    stamps = (1_000_000_000 + np.round(t * 1e9)).astype(np.int64)
    for k in range(1000):
        stream.hold(int(stamps[k]), float(y[k]), k)
    deadline = time.monotonic() + 120
    while stream.poll(0.0) is None and time.monotonic() < deadline:  # the first slice: 1 sample
        time.sleep(0.005)
    got, polls, k = [], 1, 1000
    while not stream.ready:
        if k < len(t):  # one more arrives during each slice
            stream.hold(int(stamps[k]), float(y[k]), k)
            k += 1
        got += stream.poll(0.0)
        polls += 1
    assert polls == len(t) == stream.counters['received']  # one sample a zero-budget slice
    assert stream.poll(0.0) is None and stream.warmup_held == 1000
    base = np.array([seconds_since(int(s), int(stamps[0])) for s in stamps])
    direct = FrequencyEstimator(config).process(base, y)
    assert [e.frequency_hz for _, estimates in got for e in estimates] == list(direct.frequency_hz)
    assert [tag for tag, _ in got] == sorted(tag for tag, _ in got) and len(direct) > 5


def test_a_full_warmup_buffer_drops_the_oldest_and_counts_them():
    stream = EstimatorStream(
        EstimatorConfig(refine=0, model='damped-sinusoid'), time.monotonic(), background=True
    )
    first_drop = [stream.hold(k, 0.0, k) for k in range(WARMUP_BUFFER + 3)]
    assert first_drop.count(True) == 1 and first_drop[WARMUP_BUFFER]
    assert stream.health.node_counters['dropped_warmup'] == 3
    assert stream.held_samples == WARMUP_BUFFER


# ---- a real cold start, in a subprocess with an empty NUMBA_CACHE_DIR ---------------------------
class Watcher:
    """This test's ROS side: the node's /diagnostics, its services, and an input publisher."""

    def __init__(self, context):
        import rclpy
        from diagnostic_msgs.msg import DiagnosticArray
        from geometry_msgs.msg import WrenchStamped
        from std_srvs.srv import Trigger

        from vib_estimator.nodes.runner import make_executor

        self.node = rclpy.create_node('warmup_watcher', context=context)
        self.executor = make_executor(context)
        self.executor.add_node(self.node)
        self.statuses = []
        self.node.create_subscription(
            DiagnosticArray, '/diagnostics', lambda m: self.statuses.extend(m.status), 10
        )
        self.pub = self.node.create_publisher(WrenchStamped, 'coupling_torque', 1000)
        self.msg = WrenchStamped()
        self.self_test = self.node.create_client(Trigger, '/estimator_node/self_test')
        self.reset = self.node.create_client(Trigger, '/estimator_node/reset')
        self.request = Trigger.Request
        self.sent = 0

    def spin_until(self, predicate, timeout):
        from vib_estimator.nodes.runner import spin_until

        return spin_until(self.executor, predicate, timeout)

    def call(self, client):
        """The service's answer, the request sent again every 5 s (30 s at most): the first
        start's server can stay in the graph a while after its process ended, and a request
        sent before the new server is matched reaches only the old one (once in a suite run)."""
        assert self.spin_until(client.service_is_ready, 30)
        futures = []
        for _ in range(6):
            futures.append(client.call_async(self.request()))
            if self.spin_until(lambda: any(f.done() for f in futures), 5):
                return next(f for f in futures if f.done()).result()
        raise AssertionError('the service did not answer')

    def publish(self, n):
        for k in range(n):
            ns = 1_000_000_000 + self.sent * 2_000_000
            self.msg.header.stamp.sec, self.msg.header.stamp.nanosec = divmod(ns, 10**9)
            self.msg.wrench.torque.z = math.sin(2 * math.pi * 4.0 * self.sent / 500.0)
            self.pub.publish(self.msg)
            self.sent += 1
            if k % 50 == 49:
                # a stream, not a burst: the node listens over UDP (runner.stall_safe_transports),
                # whose socket holds ~200 small datagrams while the node is busy compiling
                self.spin_until(lambda: False, 0.05)

    def last(self, name='/estimator_node'):
        mine = [s for s in self.statuses if s.name == name]
        return (mine[-1], {kv.key: kv.value for kv in mine[-1].values}) if mine else (None, {})

    def close(self):
        self.executor.shutdown()
        self.node.destroy_node()


def _start_node(cache):
    env = dict(os.environ, NUMBA_CACHE_DIR=str(cache))
    code = 'import sys; from vib_estimator.nodes.estimator_node import main; sys.exit(main())'
    return subprocess.Popen(
        [sys.executable, '-c', code],
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )


def _interrupt(proc):
    proc.send_signal(signal.SIGINT)
    out, err = proc.communicate(timeout=30)
    return proc.returncode, out + err


def test_a_cold_node_is_live_while_it_compiles_and_ctrl_c_keeps_the_cache(ros_context, tmp_path):
    from diagnostic_msgs.msg import DiagnosticStatus

    watcher = Watcher(ros_context)
    try:
        # first start, interrupted while it compiles: exit 0, no traceback, a partial cache
        proc = _start_node(tmp_path)
        assert watcher.spin_until(lambda: watcher.last()[0] is not None, 30)
        status, values = watcher.last()
        # the default configuration estimates with its kernels uncompiled while they compile
        assert status.level != DiagnosticStatus.ERROR and status.message != WARMUP_MESSAGE
        assert 'warmup_s' in values, values
        assert watcher.spin_until(lambda: watcher.pub.get_subscription_count() > 0, 30)
        watcher.spin_until(lambda: False, 1.0)  # discovery settles both ways
        watcher.publish(400)
        assert watcher.spin_until(lambda: int(watcher.last()[1].get('estimates', 0)) > 0, 30)
        assert 'warmup_s' in watcher.last()[1], 'estimates only once compiled'
        # interrupted once a first kernel is compiled and kept (numba saves each one as it ends;
        # how soon after the first status that is depends on the machine's load)
        assert watcher.spin_until(lambda: any(tmp_path.rglob('*.nbi')), 120), 'nothing kept'
        code, output = _interrupt(proc)
        assert code == 0 and 'Traceback' not in output, output
        # second start on that cache: live at once, services answer, estimates, compiled
        watcher.statuses.clear()
        watcher.sent = 0
        proc = _start_node(tmp_path)
        try:
            result = watcher.call(watcher.self_test)
            warming = watcher.last()[0] is None or watcher.last()[0].message == WARMUP_MESSAGE
            if warming and not result.success:
                assert result.message.startswith('busy'), result.message
            assert watcher.spin_until(lambda: watcher.pub.get_subscription_count() > 0, 30)
            watcher.spin_until(lambda: False, 1.0)  # discovery settles both ways
            watcher.publish(400)
            ready = watcher.spin_until(
                lambda: (
                    watcher.last()[0] is not None
                    and watcher.last()[0].message != WARMUP_MESSAGE
                    and 'warmup_s' not in watcher.last()[1]
                ),
                240,
            )
            assert ready, 'the kernels never became ready'
            watcher.publish(400)
            assert watcher.spin_until(
                lambda: int(watcher.last()[1].get('received', 0)) >= watcher.sent, 10
            )
            values = watcher.last()[1]
            assert int(values['received']) == watcher.sent and values['dropped_warmup'] == '0'
            assert int(values['estimates']) > 0
            assert watcher.call(watcher.reset).success
        finally:
            code, output = _interrupt(proc)
        assert code == 0 and 'Traceback' not in output, output
    finally:
        watcher.close()
