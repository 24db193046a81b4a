"""estimator_node, in process (fresh context, isolated domain) and as an executable (SIGINT).

Samples are published with explicit header stamps in batches as fast as the node takes them (each
batch waits for the node's ``received`` counter), never in real time; waits are on matched counts
and counters, not sleeps.
"""
from __future__ import annotations

import math
import os
import signal
import subprocess
import sys
import time

import numpy as np
import pytest
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from geometry_msgs.msg import WrenchStamped
from rclpy.node import Node
from rclpy.parameter import Parameter
from std_msgs.msg import Float64, Header

from vib_estimator.core import EstimatorConfig, FrequencyEstimator
from vib_estimator.nodes.estimator_node import EstimatorNode
from vib_estimator.nodes.runner import spin_until
from vib_estimator.io.fields import seconds_since

EPOCH_NS = 1_000_000_000 * 1_000_000_000   # synthetic stamps start in 2001, far from "now"
FS = 500.0
FRAME = 'arm_base'
BATCH = 50                                  # < the node's input depth: nothing is dropped


class Probe:
    """The test's side: publishes WrenchStamped samples, records outputs and diagnostics."""

    def __init__(self, context, executor, node: EstimatorNode):
        self.executor = executor
        self.node = node
        self.probe = Node('probe', context=context)
        self.pub = self.probe.create_publisher(WrenchStamped, 'coupling_torque', 1000)
        self.events = []                      # ('f', Hz) and ('r', stamp ns, frame_id), in order
        self.diagnostics = []
        subs = [
            self.probe.create_subscription(Float64, 'vibration/frequency',
                                           lambda m: self.events.append(('f', m.data)), 100),
            self.probe.create_subscription(
                Header, 'vibration/reset',
                lambda m: self.events.append(
                    ('r', m.stamp.sec * 1_000_000_000 + m.stamp.nanosec, m.frame_id)), 100),
            self.probe.create_subscription(DiagnosticArray, '/diagnostics',
                                           self.diagnostics.append, 10),
        ]
        executor.add_node(node)
        executor.add_node(self.probe)
        assert spin_until(executor, lambda: self.pub.get_subscription_count() >= 1
                          and all(s.get_publisher_count() >= 1 for s in subs), 10.0)
        self.sent = 0

    def feed(self, stamps_ns, values, component='torque.z'):
        """Publish samples (stamp 0 = a zero stamp) in batches, each taken before the next."""
        vector, axis = component.split('.')
        for start in range(0, len(stamps_ns), BATCH):
            for stamp, value in zip(stamps_ns[start:start + BATCH], values[start:start + BATCH]):
                msg = WrenchStamped()
                msg.header.stamp.sec, msg.header.stamp.nanosec = divmod(int(stamp), 10 ** 9)
                msg.header.frame_id = FRAME
                setattr(getattr(msg.wrench, vector), axis, float(value))
                self.pub.publish(msg)
                self.sent += 1
            assert spin_until(self.executor,
                              lambda: self.node.counters['received'] >= self.sent, 10.0), \
                f'node took {self.node.counters["received"]} of {self.sent} samples'
        # the outputs of the last batch
        assert spin_until(self.executor, lambda: len(self.resets()) >= self.node.counters[
            'estimates'] and len(self.frequencies()) >= self.node.counters['estimates'], 5.0)

    def frequencies(self):
        return [e[1] for e in self.events if e[0] == 'f']

    def resets(self):
        return [e[1:] for e in self.events if e[0] == 'r']

    def wait_status(self, predicate, timeout=5.0) -> DiagnosticStatus:
        """Spin until a /diagnostics status satisfies ``predicate``; return it."""
        start = len(self.diagnostics)

        def found():
            return any(predicate(a.status[0]) for a in self.diagnostics[start:])
        assert spin_until(self.executor, found, timeout), \
            [(a.status[0].level, a.status[0].message) for a in self.diagnostics[start:]]
        return next(a.status[0] for a in self.diagnostics[start:] if predicate(a.status[0]))


def values_of(status: DiagnosticStatus) -> dict:
    return {kv.key: kv.value for kv in status.values}


def sine_stamps(n, start_ns=EPOCH_NS, fs=FS):
    """n stamps (int ns) at fs from start_ns."""
    return [start_ns + round(i * 1e9 / fs) for i in range(n)]


def offline(stamps_ns, values, config=EstimatorConfig(), origin=None):
    """What ``vib-estimator analyze`` computes for these samples."""
    stamps = np.asarray(stamps_ns, dtype=np.int64)
    t = seconds_since(stamps, stamps[0] if origin is None else origin)
    return FrequencyEstimator(config).process(t, values)


@pytest.fixture
def make_probe(ros_context, executor):
    """Build the node (with optional parameter overrides) and the probe around it."""
    made = []

    def make(**overrides):
        node = EstimatorNode(context=ros_context, parameter_overrides=[
            Parameter(k, value=v) for k, v in overrides.items()])
        made.append(node)
        return Probe(ros_context, executor, node)
    yield make
    for node in made:
        node.destroy_node()


def test_sine_gives_frequency_then_reset(make_probe):
    p = make_probe()
    stamps = sine_stamps(2500)
    values = np.sin(2 * np.pi * 1.33 * (np.arange(2500) / FS))
    p.feed(stamps, values)
    expected = offline(stamps, values)
    assert len(expected) >= 5
    freqs = p.frequencies()
    assert len(freqs) == len(expected) == p.node.counters['estimates']
    assert all(abs(f - 1.33) < 1.33e-3 for f in freqs), freqs
    # frequency then reset, one each, the reset stamped with the converging sample
    assert [e[0] for e in p.events] == ['f', 'r'] * len(expected)
    converging = [stamps[i] for i in np.searchsorted(
        seconds_since(np.asarray(stamps), stamps[0]), expected.t)]
    assert p.resets() == [(s, FRAME) for s in converging]


def test_node_and_offline_give_the_same_floats(make_probe):
    rng = np.random.default_rng(7)
    n = 4000
    jitter = rng.integers(-200_000, 200_000, n)           # +-0.2 ms around 500 Hz
    stamps = [s + int(j) for s, j in zip(sine_stamps(n, EPOCH_NS + 123_456_789), jitter)]
    t = seconds_since(np.asarray(stamps), stamps[0])
    values = (0.1 * np.exp(-0.03 * t) * np.sin(2 * np.pi * 1.33 * t + 0.4)
              + rng.normal(0, 2e-4, n))
    p = make_probe(component='force.y')
    p.feed(stamps, values, component='force.y')
    expected = offline(stamps, values)
    assert len(expected) >= 5
    assert p.frequencies() == expected.frequency_hz.tolist()   # exactly
    assert [r[0] for r in p.resets()] == [stamps[i] for i in np.searchsorted(t, expected.t)]


def test_bad_input_is_counted_and_estimation_resumes(make_probe):
    p = make_probe(min_amplitude=0.05)
    assert p.wait_status(lambda s: True).level == DiagnosticStatus.STALE   # no input yet

    def sine(n, start, amplitude=1.0):
        stamps = sine_stamps(n, start)
        return stamps, list(amplitude * np.sin(2 * np.pi * 1.33 * np.arange(n) / FS))

    stamps, values = sine(500, EPOCH_NS)
    last = stamps[-1]
    step = stamps[1] - stamps[0]
    bad = [(last + step, math.nan), (last + 2 * step, math.inf),   # non-finite
           (last + 3 * step, 0.5), (last + 3 * step, 0.5),        # duplicate
           (last + 2 * step + step // 2, 0.5),                     # out of order (< max_gap)
           (0, 0.1), (0, 0.2), (0, 0.3)]                           # zero stamps: receipt time
    stamps += [s for s, _ in bad]
    values += [v for _, v in bad]
    # back to the stream (a backward jump from the receipt time), then a 2 s gap, then rest
    more, more_values = sine(500, last + 10 * step)
    rest, rest_values = sine(1000, more[-1] + 2_000_000_000, amplitude=0.01)
    p.feed(stamps + more, values + more_values)
    estimates_before_rest = p.node.counters['estimates']
    assert estimates_before_rest >= 1
    p.feed(rest, rest_values)
    warn = p.wait_status(lambda s: s.level == DiagnosticStatus.WARN)
    assert 'rejected_at_rest' in warn.message
    resumed, resumed_values = sine(1500, rest[-1] + step)
    p.feed(resumed, resumed_values)
    assert p.node.counters['estimates'] >= estimates_before_rest + 3
    total = p.sent
    ok = p.wait_status(lambda s: s.level == DiagnosticStatus.OK
                       and values_of(s)['received'] == str(total))
    kv = values_of(ok)
    assert ok.name == '/estimator_node' and ok.hardware_id == '/coupling_torque'
    assert kv['skipped_non_finite'] == '2'
    assert kv['skipped_duplicate'] == '1'
    assert kv['skipped_out_of_order'] == '1'
    assert kv['zero_stamps_replaced'] == '3'
    assert kv['gap_resets'] == '2'          # to the receipt time, and the 2 s gap
    assert kv['time_jump_resets'] == '1'    # from the receipt time back to the stream
    assert int(kv['rejected_at_rest']) >= 1
    assert int(kv['used']) == total - 4
    assert kv['estimates'] == str(p.node.counters['estimates'])
    assert abs(float(kv['last_frequency_hz']) - 1.33) < 1.33e-3
    assert 0 < float(kv['last_convergence_time_s']) < 1.0
    assert float(kv['input_rate_hz']) >= 0
    assert set(kv) >= set(p.node.counters) | {'last_frequency_hz', 'last_convergence_time_s',
                                              'input_rate_hz'}


def test_parameter_changes(make_probe):
    p = make_probe()
    stamps = sine_stamps(1500)
    values = np.sin(2 * np.pi * 1.33 * np.arange(3000) / FS)
    p.feed(stamps, values[:1500])
    before = len(p.frequencies())
    # invalid: refused with a reason, the estimator untouched
    estimator = p.node._estimator
    for name, value, reason in [
            ('window', 0, 'window out of range'), ('lowpass_damping', -1.0, 'out of range'),
            ('band_hz', [5.0, 1.0], 'band_hz must be'), ('model', 'foo', 'model must be'),
            ('min_time', 20.0, 'must be below max_window'), ('component', 'torque.w', 'torque.w'),
            ('input_topic', 'elsewhere', 'read-only'), ('window', 2.5, 'expected')]:
        result = p.node.set_parameters([Parameter(name, value=value)])[0]
        assert not result.successful and reason in result.reason, (name, result.reason)
    assert p.node._estimator is estimator
    # valid: a new estimator with the new configuration, same time origin
    assert p.node.set_parameters([Parameter('window', value=5)])[0].successful
    assert p.node._estimator.config.window == 5
    assert p.node.get_parameter('window').value == 5
    later = sine_stamps(3000)[1500:]
    p.feed(later, values[1500:])
    expected = offline(later, values[1500:], EstimatorConfig().replace(window=5),
                       origin=stamps[0])
    assert len(expected) >= 2
    assert p.frequencies()[before:] == expected.frequency_hz.tolist()
    assert p.node.counters['received'] == 3000        # counters span the change
    assert p.node.set_parameters([Parameter('band_hz', value=[0.5, 5.0])])[0].successful
    assert p.node._estimator.config.band_hz == (0.5, 5.0)
    assert p.node.set_parameters(
        [Parameter('band_hz', Parameter.Type.DOUBLE_ARRAY, [])])[0].successful
    assert p.node._estimator.config.band_hz is None


def test_sigint_shuts_down_cleanly(ros_context):
    probe = Node('sigint_probe', context=ros_context)
    proc = subprocess.Popen(
        [os.path.join(os.path.dirname(sys.executable), 'estimator_node')],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
        # a test run in a background job inherits SIGINT ignored: give the node the default
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    try:
        deadline = time.monotonic() + 20
        while probe.count_subscribers('/coupling_torque') < 1 and time.monotonic() < deadline:
            time.sleep(0.05)
        assert probe.count_subscribers('/coupling_torque') == 1
        proc.send_signal(signal.SIGINT)
        _, err = proc.communicate(timeout=10)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.communicate()
        probe.destroy_node()
    assert proc.returncode == 0, err
    assert 'Traceback' not in err, err


def test_use_sim_time_zero_stamps_follow_the_simulated_clock(make_probe):
    """With use_sim_time, a zero stamp becomes the /clock time at receipt; estimates follow it."""
    from rosgraph_msgs.msg import Clock

    p = make_probe(use_sim_time=True)
    clock_pub = p.probe.create_publisher(Clock, '/clock', 10)
    assert spin_until(p.executor, lambda: clock_pub.get_subscription_count() >= 1, 10.0)
    start_ns = 5_000 * 10 ** 9                 # simulated time, far from the wall clock
    clock = Clock()
    for i in range(800):                        # 1.6 s of a 1.33 Hz sine at 500 Hz
        now_ns = start_ns + i * 2_000_000
        clock.clock.sec, clock.clock.nanosec = divmod(now_ns, 10 ** 9)
        clock_pub.publish(clock)
        assert spin_until(p.executor, lambda: p.node.get_clock().now().nanoseconds == now_ns,
                          5.0)
        msg = WrenchStamped()                   # header stamp left at zero
        msg.wrench.torque.z = math.sin(2 * math.pi * 1.33 * i / FS)
        p.pub.publish(msg)
        p.sent += 1
        assert spin_until(p.executor, lambda: p.node.counters['received'] >= p.sent, 5.0)
    assert spin_until(p.executor, lambda: len(p.resets()) >= 2, 5.0)
    assert p.node.counters['zero_stamps_replaced'] == 800
    assert all(start_ns < stamp < start_ns + 1_600_000_000 for stamp, _ in p.resets())
    assert all(abs(f / 1.33 - 1) < 1e-3 for f in p.frequencies())
