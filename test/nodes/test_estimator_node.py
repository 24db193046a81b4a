# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""estimator_node, in process (fresh context, isolated domain) and as an executable (SIGINT);
with several components (a 3-axis IMU, several joints), the joint identification and the shapes.

Samples are published with explicit header stamps in batches as fast as the node takes them (each
batch waits for the node's counters), never in real time; samples without a header
(std_msgs/Float64) are paced by a simulated /clock. Waits are on matched counts and counters, not
sleeps.
"""

from __future__ import annotations

import math
import os
import re
import signal
import subprocess
import sys
import time

import numpy as np
import pytest
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from rclpy.node import Node
from rclpy.parameter import Parameter
from rosgraph_msgs.msg import Clock
from std_msgs.msg import Float64, Float64MultiArray, Header
from std_srvs.srv import Trigger

from vib_estimator.core import Estimate, EstimatorConfig, FrequencyEstimator
from vib_estimator.core.ambient import AmbientEstimator
from vib_estimator.core.config import PAPER
from vib_estimator.core.shapes import SHAPE_ROWS
from vib_estimator.io import fields
from vib_estimator.io.fields import seconds_since
from vib_estimator.nodes import stream
from vib_estimator.nodes.estimator_node import EstimatorNode, message_class
from vib_estimator.nodes.parameters import config_of
from vib_estimator.nodes.runner import StartupError, spin_until, spin_until_arrival
from vib_estimator.sim.frame import modal_record

EPOCH_NS = 1_000_000_000 * 1_000_000_000  # synthetic stamps start in 2001, far from "now"
FS = 500.0
FRAME = 'arm_base'
BATCH = 50  # < the node's input depth: nothing is dropped
#: the outputs of one estimate, in publication order
OUTPUTS = ['frequency', 'damping_ratio', 'frequency_std', 'amplitude', 'reset']
JOINTS = ['shoulder', 'elbow', 'wrist']


def message(input_type, component, stamp_ns, value, joints=JOINTS):
    """A message of ``input_type`` with ``value`` in ``component`` (JointState: the joint of the
    component among ``joints``, in that order; the others get other values)."""
    msg = message_class(input_type)()
    if fields.has_header(input_type):
        msg.header.stamp.sec, msg.header.stamp.nanosec = divmod(int(stamp_ns), 10**9)
        msg.header.frame_id = FRAME
    if input_type == fields.JOINT_STATE:
        array, joint = component[:-1].split('[')
        for i, name in enumerate(joints):
            fields.component_setter(f'{array}[{name}]', input_type)(
                msg, value if name == joint else 100.0 + i
            )
    else:
        fields.component_setter(component, input_type)(msg, value)
    return msg


class Probe:
    """The test's side: publishes samples, records the outputs (in order) and diagnostics."""

    def __init__(self, context, executor, node: EstimatorNode, modes=0):
        self.executor = executor
        self.node = node
        self.input_type = fields.check_input_type(node.get_parameter('input_type').value)
        self.probe = Node('probe', context=context)
        self.pub = self.probe.create_publisher(
            message_class(self.input_type), 'coupling_torque', 1000
        )
        self.events = []  # (topic, value) or ('reset', stamp ns, frame_id), in order
        self.diagnostics = []
        topics = OUTPUTS + [
            f'mode{k}/{n}' for k in range(1, modes + 1) for n in ('frequency', 'reset')
        ]
        subs = [self._listen(topic) for topic in topics] + [
            self.probe.create_subscription(
                DiagnosticArray, '/diagnostics', self.diagnostics.append, 10
            )
        ]
        #: several components: each mode's vibration/mode<k>/shape messages
        self.shapes = {k: [] for k in range(1, modes + 1)}
        if len(node.get_parameter('components').value) >= 2:
            subs += [
                self.probe.create_subscription(
                    Float64MultiArray, f'vibration/mode{k}/shape', self.shapes[k].append, 100
                )
                for k in self.shapes
            ]
        executor.add_node(node)
        executor.add_node(self.probe)
        assert spin_until(
            executor,
            lambda: (
                self.pub.get_subscription_count() >= 1
                and all(s.get_publisher_count() >= 1 for s in subs)
            ),
            10.0,
        )
        self.sent = 0
        self.modes = modes

    def _listen(self, topic):
        if topic.endswith('reset'):
            return self.probe.create_subscription(
                Header,
                f'vibration/{topic}',
                lambda m: self.events.append(
                    (topic, m.stamp.sec * 1_000_000_000 + m.stamp.nanosec, m.frame_id)
                ),
                100,
            )
        return self.probe.create_subscription(
            Float64, f'vibration/{topic}', lambda m: self.events.append((topic, m.data)), 100
        )

    def taken(self):
        counters = self.node.counters
        return counters['received'] + counters['skipped_joint_missing']

    def publish(self, msgs):
        """Publish messages in batches, each taken by the node before the next."""
        for start in range(0, len(msgs), BATCH):
            for msg in msgs[start : start + BATCH]:
                self.pub.publish(msg)
                self.sent += 1
            assert spin_until(self.executor, lambda: self.taken() >= self.sent, 10.0), (
                f'node took {self.taken()} of {self.sent} samples'
            )
        self.wait_outputs()

    def wait_outputs(self):
        """Until the outputs of every estimate so far arrived (of every mode, with modes)."""

        def arrived():
            estimates = self.node.counters['estimates']
            if self.modes:
                mode1 = len(self.resets('mode1/reset'))
                estimates = max(
                    estimates
                    - sum(len(self.resets(f'mode{k}/reset')) for k in range(2, self.modes + 1)),
                    mode1,
                )
            return len(self.resets()) >= estimates and len(self.frequencies()) >= estimates

        # (returns once they arrived; a full suite on 2 loaded cores took over 5 s, twice, for
        # the outputs of a node that had just switched to the mode tracker)
        assert spin_until(self.executor, arrived, 20.0)

    def feed(self, stamps_ns, values, component='torque.z', joints=JOINTS):
        """Publish samples (stamp 0 = a zero stamp) of the node's input type."""
        self.publish(
            [message(self.input_type, component, s, v, joints) for s, v in zip(stamps_ns, values)]
        )

    def values(self, topic='frequency'):
        return [e[1] for e in self.events if e[0] == topic]

    def frequencies(self):
        return self.values('frequency')

    def resets(self, topic='reset'):
        return [e[1:] for e in self.events if e[0] == topic]

    def call(self, service, timeout=60.0):
        """Call a Trigger service of the node; the response (the first self-test may compile the
        kernel's batch path: a clean clone has no numba cache)."""
        client = self.probe.create_client(Trigger, f'/estimator_node/{service}')
        assert spin_until(self.executor, client.service_is_ready, timeout)
        future = client.call_async(Trigger.Request())
        assert spin_until(self.executor, future.done, timeout)
        self.probe.destroy_client(client)
        return future.result()

    def trigger_clients(self) -> dict:
        """Clients of the node's Trigger services (``reset``, ``self_test``), each with a deep
        reliable history (a burst of calls is answered whole), their services ready."""
        from rclpy.qos import QoSProfile, ReliabilityPolicy

        qos = QoSProfile(depth=1000, reliability=ReliabilityPolicy.RELIABLE)
        clients = {
            name: self.probe.create_client(Trigger, f'/estimator_node/{name}', qos_profile=qos)
            for name in ('reset', 'self_test')
        }
        for client in clients.values():
            assert spin_until(self.executor, client.service_is_ready, 60.0)
        return clients

    def wait_status(self, predicate, timeout=5.0) -> DiagnosticStatus:
        """Spin until a /diagnostics status satisfies ``predicate``; return it."""
        array = spin_until_arrival(
            self.executor, self.diagnostics, lambda a: predicate(a.status[0]), timeout
        )
        return array.status[0]

    def status_age(self, status: DiagnosticStatus, since: float) -> float:
        """Seconds from ``since`` (wall clock, before the samples were sent) to the stamp of the
        /diagnostics array of ``status`` (the node's clock, wall time here): a bound on the age
        of anything the status reports."""
        stamp = next(a.header.stamp for a in self.diagnostics if a.status[0] is status)
        return stamp.sec + 1e-9 * stamp.nanosec - since


def values_of(status: DiagnosticStatus) -> dict:
    return {kv.key: kv.value for kv in status.values}


def sine_stamps(n, start_ns=EPOCH_NS, fs=FS):
    """n stamps (int ns) at fs from start_ns."""
    return [start_ns + round(i * 1e9 / fs) for i in range(n)]


#: the node's mechanics are checked on short signals with the paper's half-period windows
#: (the defaults through the node: test_real_arm_node.py, test_launch_config.py)
PAPER_CONFIG = EstimatorConfig.paper()


def offline(stamps_ns, values, config=PAPER_CONFIG, origin=None):
    """What ``vib-estimator analyze`` computes for these samples."""
    stamps = np.asarray(stamps_ns, dtype=np.int64)
    t = seconds_since(stamps, stamps[0] if origin is None else origin)
    return FrequencyEstimator(config).process(t, values)


@pytest.fixture
def make_probe(ros_context, executor):
    """Build the node (with optional parameter overrides) and the probe around it."""
    made = []

    def make(modes=0, **overrides):
        if modes:
            overrides['modes'] = modes
        overrides = {**PAPER, **overrides}
        node = EstimatorNode(
            context=ros_context,
            parameter_overrides=[Parameter(k, value=v) for k, v in overrides.items()],
        )
        made.append(node)
        return Probe(ros_context, executor, node, modes)

    yield make
    for node in made:
        node.destroy_node()


def test_sine_gives_the_outputs_in_order(make_probe):
    p = make_probe()
    stamps = sine_stamps(2500)
    values = 0.7 * np.sin(2 * np.pi * 1.33 * (np.arange(2500) / FS))
    p.feed(stamps, values)
    expected = offline(stamps, values)
    assert len(expected) >= 5
    freqs = p.frequencies()
    assert len(freqs) == len(expected) == p.node.counters['estimates']
    assert all(abs(f - 1.33) < 1.33e-3 for f in freqs), freqs
    # frequency, damping ratio, its std, amplitude, then reset: one each per estimate
    assert [e[0] for e in p.events] == OUTPUTS * len(expected)
    assert all(math.isnan(d) for d in p.values('damping_ratio'))  # sinusoid: no damping
    np.testing.assert_array_equal(p.values('frequency_std'), expected.frequency_std_hz)
    assert p.values('amplitude') == expected.amplitude.tolist()
    assert all(abs(a - 0.7) < 0.7e-2 for a in p.values('amplitude'))
    # the reset stamped with the converging sample
    converging = [
        stamps[i]
        for i in np.searchsorted(seconds_since(np.asarray(stamps), stamps[0]), expected.t)
    ]
    assert p.resets() == [(s, FRAME) for s in converging]


def test_node_and_offline_give_the_same_floats(make_probe):
    rng = np.random.default_rng(7)
    n = 4000
    jitter = rng.integers(-200_000, 200_000, n)  # +-0.2 ms around 500 Hz
    stamps = [s + int(j) for s, j in zip(sine_stamps(n, EPOCH_NS + 123_456_789), jitter)]
    t = seconds_since(np.asarray(stamps), stamps[0])
    values = 0.1 * np.exp(-0.03 * t) * np.sin(2 * np.pi * 1.33 * t + 0.4) + rng.normal(0, 2e-4, n)
    p = make_probe(component='force.y')
    p.feed(stamps, values, component='force.y')
    expected = offline(stamps, values)
    assert len(expected) >= 5
    assert p.frequencies() == expected.frequency_hz.tolist()  # exactly
    assert [r[0] for r in p.resets()] == [stamps[i] for i in np.searchsorted(t, expected.t)]


def test_bad_input_is_counted_and_estimation_resumes(make_probe):
    p = make_probe(min_amplitude=0.05)
    assert p.wait_status(lambda s: True).level == DiagnosticStatus.STALE  # no input yet

    def sine(n, start, amplitude=1.0):
        stamps = sine_stamps(n, start)
        return stamps, list(amplitude * np.sin(2 * np.pi * 1.33 * np.arange(n) / FS))

    stamps, values = sine(500, EPOCH_NS)
    last = stamps[-1]
    step = stamps[1] - stamps[0]
    bad = [
        (last + step, math.nan),
        (last + 2 * step, math.inf),  # non-finite
        (last + 3 * step, 0.5),
        (last + 3 * step, 0.5),  # duplicate
        (last + 2 * step + step // 2, 0.5),  # out of order (< max_gap)
        (0, 0.1),
        (0, 0.2),
        (0, 0.3),
    ]  # zero stamps: receipt time
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
    ok = p.wait_status(
        lambda s: s.level == DiagnosticStatus.OK and values_of(s)['received'] == str(total)
    )
    kv = values_of(ok)
    assert ok.name == '/estimator_node' and ok.hardware_id == '/coupling_torque'
    assert kv['skipped_non_finite'] == '2'
    assert kv['skipped_duplicate'] == '1'
    assert kv['skipped_out_of_order'] == '1'
    assert kv['zero_stamps_replaced'] == '3'
    assert kv['gap_resets'] == '1'  # the 2 s gap
    assert kv['stamp_jumps'] == '1'  # to the receipt time (years ahead): a jump, not lost samples
    assert kv['time_jump_resets'] == '1'  # from the receipt time back to the stream
    assert int(kv['rejected_at_rest']) >= 1
    assert int(kv['used']) == total - 4
    assert kv['estimates'] == str(p.node.counters['estimates'])
    assert abs(float(kv['last_frequency_hz']) - 1.33) < 1.33e-3
    assert 0 < float(kv['last_convergence_time_s']) < 1.0
    assert kv['frequency_subscribers'] == '1'  # the probe's, matched (the demo waits on it)
    # input_rate_hz: the messages taken between two statuses over the time between them (the
    # statuses' stamps, ~1 s apart); the input came in bursts, so some intervals saw none
    seen = [
        (a.header.stamp.sec + 1e-9 * a.header.stamp.nanosec, values_of(a.status[0]))
        for a in p.diagnostics
    ]
    pairs = [
        (int(kv['received']) - int(prev['received']), t - t_prev, float(kv['input_rate_hz']))
        for (t_prev, prev), (t, kv) in zip(seen, seen[1:])
    ]
    assert sum(n for n, _, _ in pairs) == total - int(seen[0][1]['received'])
    assert any(n > 0 for n, _, _ in pairs)
    for n, dt, rate in pairs:
        assert rate == pytest.approx(n / dt, rel=0.1, abs=1e-12), (n, dt, rate)
    assert set(kv) >= set(p.node.counters) | {
        'last_frequency_hz',
        'last_convergence_time_s',
        'input_rate_hz',
    }


def test_parameter_changes(make_probe):
    """A refused change leaves the estimator running (its segment goes on); an accepted one
    restarts it with the new configuration on the same time origin: the published estimates are
    those of the offline estimator of each configuration over its samples."""
    p = make_probe()
    parts = np.cumsum([0, 1500, 750, 1500, 1500, 750, 1500])
    stamps = sine_stamps(parts[-1])
    values = np.sin(2 * np.pi * 1.33 * np.arange(parts[-1]) / FS)

    def feed(k, config):
        """Feed part k; its estimates must be ``config``'s over the part (from its start)."""
        before = len(p.frequencies())
        a, b = parts[k], parts[k + 1]
        p.feed(stamps[a:b], values[a:b])
        expected = offline(stamps[a:b], values[a:b], config, origin=stamps[0])
        assert len(expected) >= 2, (k, len(expected))
        assert p.frequencies()[before:] == expected.frequency_hz.tolist(), k

    feed(0, PAPER_CONFIG)
    # invalid: refused with a reason, the parameters and the estimator untouched
    names = [
        'window',
        'lowpass_damping',
        'band_hz',
        'model',
        'min_time',
        'component',
        'input_topic',
        'input_type',
    ]
    kept = {name: p.node.get_parameter(name).value for name in names}
    for name, value, reason in [
        ('window', 0, 'window out of range'),
        ('lowpass_damping', -1.0, 'out of range'),
        ('band_hz', [5.0, 1.0], 'band_hz must be'),
        ('model', 'foo', 'model must be'),
        ('min_time', 20.0, 'must be below max_window'),
        ('component', 'torque.w', 'torque.w'),
        ('input_topic', 'elsewhere', 'read-only'),
        ('window', 2.5, 'expected'),
        ('input_type', fields.IMU, 'read-only'),
        ('component', 'linear_acceleration.z', 'component of geometry_msgs/msg/Wrench'),
    ]:
        result = p.node.set_parameters([Parameter(name, value=value)])[0]
        assert not result.successful and reason in result.reason, (name, result.reason)
    assert {name: p.node.get_parameter(name).value for name in names} == kept
    # the segment went on through the refusals: the estimates of parts 0-1 as one stream
    before = len(p.frequencies())
    p.feed(stamps[parts[1] : parts[2]], values[parts[1] : parts[2]])
    whole = offline(stamps[: parts[2]], values[: parts[2]])
    assert len(whole) > before and p.frequencies() == whole.frequency_hz.tolist()
    # valid: a new estimator with the new configuration, same time origin
    assert p.node.set_parameters([Parameter('window', value=5)])[0].successful
    assert p.node.get_parameter('window').value == 5
    feed(2, PAPER_CONFIG.replace(window=5))
    assert p.node.counters['received'] == parts[3]  # counters span the change
    assert p.node.set_parameters([Parameter('band_hz', value=[0.5, 5.0])])[0].successful
    feed(3, PAPER_CONFIG.replace(window=5, band_hz=(0.5, 5.0)))
    assert p.node.set_parameters([Parameter('band_hz', Parameter.Type.DOUBLE_ARRAY, [])])[
        0
    ].successful
    feed(4, PAPER_CONFIG.replace(window=5))
    # set to the value in force (a storm of the same valid value): nothing restarts, the segment
    # of part 4 goes on through part 5 (a rebuild would start one at part 5)
    assert p.node.set_parameters([Parameter('window', value=5)])[0].successful
    before = len(p.frequencies())
    p.feed(stamps[parts[5] : parts[6]], values[parts[5] : parts[6]])
    five = PAPER_CONFIG.replace(window=5)
    went_on = offline(stamps[parts[4] : parts[6]], values[parts[4] : parts[6]], five, stamps[0])
    went_on = went_on.frequency_hz[went_on.t >= seconds_since(stamps[parts[5]], stamps[0])]
    restarted = offline(stamps[parts[5] : parts[6]], values[parts[5] : parts[6]], five, stamps[0])
    assert p.frequencies()[before:] == went_on.tolist() != restarted.frequency_hz.tolist()


def test_sigint_shuts_down_cleanly(ros_context):
    probe = Node('sigint_probe', context=ros_context)
    proc = subprocess.Popen(
        [os.path.join(os.path.dirname(sys.executable), 'estimator_node')],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        # a test run in a background job inherits SIGINT ignored: give the node the default
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
    )
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


SIM_START_NS = 5_000 * 10**9  # simulated time, far from the wall clock


def feed_on_sim_clock(p, values, component):
    """Publish /clock = SIM_START_NS + i / FS, then sample i with a zero (or no) stamp."""
    clock_pub = p.probe.create_publisher(Clock, '/clock', 10)
    assert spin_until(p.executor, lambda: clock_pub.get_subscription_count() >= 1, 10.0)
    clock = Clock()
    for i, value in enumerate(values):
        now_ns = SIM_START_NS + round(i * 1e9 / FS)
        clock.clock.sec, clock.clock.nanosec = divmod(now_ns, 10**9)
        clock_pub.publish(clock)
        assert spin_until(p.executor, lambda: p.node.get_clock().now().nanoseconds == now_ns, 5.0)
        p.pub.publish(message(p.input_type, component, 0, value))
        p.sent += 1
        assert spin_until(p.executor, lambda: p.node.counters['received'] >= p.sent, 5.0)
    p.wait_outputs()
    return [SIM_START_NS + round(i * 1e9 / FS) for i in range(len(values))]


def test_use_sim_time_zero_stamps_follow_the_simulated_clock(make_probe):
    """With use_sim_time, a zero stamp becomes the /clock time at receipt; estimates follow it."""
    p = make_probe(use_sim_time=True)
    values = np.sin(2 * np.pi * 1.33 * np.arange(800) / FS)  # 1.6 s at 500 Hz
    stamps = feed_on_sim_clock(p, values, 'torque.z')
    assert p.node.counters['zero_stamps_replaced'] == 800
    expected = offline(stamps, values)
    assert len(expected) >= 2 and p.frequencies() == expected.frequency_hz.tolist()
    assert all(SIM_START_NS < stamp < SIM_START_NS + 1_600_000_000 for stamp, _ in p.resets())
    assert all(abs(f / 1.33 - 1) < 1e-3 for f in p.frequencies())


# ---- input types ----------------------------------------------------------------------------
@pytest.mark.parametrize(
    'input_type, component',
    [
        (fields.IMU, 'linear_acceleration.y'),
        (fields.IMU, 'angular_velocity.z'),
        (fields.ACCEL_STAMPED, 'accel.linear.x'),
        (fields.VECTOR3_STAMPED, 'vector.z'),
        (fields.JOINT_STATE, 'effort[elbow]'),
        (fields.WRENCH_STAMPED, 'force.x'),
    ],
)
def test_each_input_type_end_to_end(make_probe, input_type, component):
    p = make_probe(input_type=input_type, component=component)
    stamps = sine_stamps(2000)
    values = 2.0 * np.sin(2 * np.pi * 1.33 * np.arange(2000) / FS + 0.3)
    p.feed(stamps, values, component)
    expected = offline(stamps, values)
    assert len(expected) >= 4
    assert p.frequencies() == expected.frequency_hz.tolist()
    assert all(abs(f / 1.33 - 1) < 1e-3 for f in p.frequencies())
    assert [e[0] for e in p.events] == OUTPUTS * len(expected)
    assert p.node.counters['received'] == 2000


@pytest.mark.parametrize(
    'name, input_type',
    [('std_msgs/Float64', fields.FLOAT64), ('std_msgs/msg/Float32', fields.FLOAT32)],
)
def test_float_input_is_timed_by_the_node_clock(make_probe, name, input_type):
    """std_msgs/Float64 and Float32 (a micro-ROS sensor's) have no header: receipt time on the
    node clock (here /clock)."""
    p = make_probe(input_type=name, use_sim_time=True)  # short name accepted
    assert p.input_type == input_type and p.node.get_parameter('component').value == 'data'
    values = np.sin(2 * np.pi * 1.33 * np.arange(800) / FS)
    values = values.astype(np.float32).astype(np.float64)  # (what a Float32 carries)
    stamps = feed_on_sim_clock(p, values, 'data')
    expected = offline(stamps, values)
    assert len(expected) >= 2 and p.frequencies() == expected.frequency_hz.tolist()
    assert all(abs(f / 1.33 - 1) < 1e-3 for f in p.frequencies())
    assert [e[0] for e in p.events] == OUTPUTS * len(expected)
    converging = [
        stamps[i]
        for i in np.searchsorted(seconds_since(np.asarray(stamps), stamps[0]), expected.t)
    ]
    assert p.resets() == [(s, '') for s in converging]
    assert p.node.counters['zero_stamps_replaced'] == 0


def test_joint_state_joint_found_by_name_absent_counted(make_probe):
    p = make_probe(input_type=fields.JOINT_STATE, component='position[wrist]')
    n = 2000
    stamps = sine_stamps(n)
    values = np.sin(2 * np.pi * 1.33 * np.arange(n) / FS)
    absent = set(range(300, 2000, 97))
    orders = [JOINTS, JOINTS[::-1], ['wrist', 'shoulder', 'elbow']]
    msgs = [
        message(
            fields.JOINT_STATE,
            'position[wrist]',
            s,
            v,
            ['shoulder', 'elbow'] if i in absent else orders[i % 3],
        )
        for i, (s, v) in enumerate(zip(stamps, values))
    ]
    p.publish(msgs)
    kept = [i for i in range(n) if i not in absent]
    expected = offline([stamps[i] for i in kept], values[kept])
    assert len(expected) >= 4 and p.frequencies() == expected.frequency_hz.tolist()
    assert p.node.counters['skipped_joint_missing'] == len(absent)
    assert p.node.counters['received'] == len(kept)
    status = p.wait_status(lambda s: values_of(s)['skipped_joint_missing'] == str(len(absent)))
    # the status that counted them says so (WARN, how many); once none lack it, OK again
    assert status.level == DiagnosticStatus.WARN, (status.level, status.message)
    missing_then = int(values_of(status)['skipped_joint_missing'])
    assert re.search(r'\b(\d+) messages without the joint', status.message), status.message
    said = int(re.search(r'\b(\d+) messages without the joint', status.message).group(1))
    assert 0 < said <= missing_then == len(absent)
    p.feed(sine_stamps(50, stamps[-1] + 2_000_000), values[:50], component='position[wrist]')
    ok = p.wait_status(
        lambda s: (
            values_of(s)['received'] == str(len(kept) + 50)
            and 'without the joint' not in s.message
        )
    )
    assert values_of(ok)['skipped_joint_missing'] == str(len(absent))


def test_component_is_checked_against_the_type(ros_context):
    for overrides, reason in [
        ({'input_type': fields.IMU, 'component': 'torque.z'}, 'component of sensor_msgs'),
        ({'input_type': 'foo_msgs/msg/Bar'}, 'input_type must be one of'),
        ({'input_type': fields.JOINT_STATE, 'component': 'effort'}, 'effort[NAME]'),
    ]:
        with pytest.raises(StartupError, match=reason.replace('[', r'\[')):
            EstimatorNode(
                context=ros_context,
                parameter_overrides=[Parameter(k, value=v) for k, v in overrides.items()],
            )
    node = EstimatorNode(
        context=ros_context, parameter_overrides=[Parameter('input_type', value=fields.IMU)]
    )
    try:
        assert node.get_parameter('component').value == 'linear_acceleration.z'
        refused = node.set_parameters([Parameter('component', value='torque.z')])[0]
        assert not refused.successful and 'linear_acceleration.x' in refused.reason
        assert node.set_parameters([Parameter('component', value='angular_velocity.x')])[
            0
        ].successful
        assert node.describe_parameter('input_type').read_only
    finally:
        node.destroy_node()


def test_a_component_of_another_type_is_one_error_line_and_exit_2():
    result = subprocess.run(
        [
            os.path.join(os.path.dirname(sys.executable), 'estimator_node'),
            '--ros-args',
            '-p',
            'input_type:=sensor_msgs/msg/Imu',
            '-p',
            'component:=torque.z',
        ],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert result.returncode == 2
    assert result.stderr.strip().splitlines() == [
        'error: component of sensor_msgs/msg/Imu must be one of linear_acceleration.x, '
        'linear_acceleration.y, linear_acceleration.z, angular_velocity.x, angular_velocity.y, '
        "angular_velocity.z, got 'torque.z'"
    ]


# ---- services -------------------------------------------------------------------------------
def test_reset_service_starts_a_new_segment_counters_kept(make_probe):
    p = make_probe()
    stamps = sine_stamps(2500)
    values = np.sin(2 * np.pi * 1.33 * np.arange(2500) / FS)
    p.feed(stamps[:420], values[:420])
    response = p.call('reset')
    assert response.success and 'new segment' in response.message
    p.feed(stamps[420:], values[420:])
    t = seconds_since(np.asarray(stamps), stamps[0])
    est = FrequencyEstimator(PAPER_CONFIG)
    first = est.process(t[:420], values[:420])
    est.reset()
    with_reset = (
        first.frequency_hz.tolist() + est.process(t[420:], values[420:]).frequency_hz.tolist()
    )
    assert with_reset != offline(stamps, values).frequency_hz.tolist()  # the reset shows
    assert p.frequencies() == with_reset
    assert p.node.counters['received'] == 2500


def test_self_test_service_and_band_above_nyquist(make_probe):
    p = make_probe()
    response = p.call('self_test')  # no input yet: the default rate and band
    assert response.success, response.message
    lines = response.message.splitlines()
    assert 'at 500 Hz sampling' in lines[0] and len(lines) == 4
    assert all('error' in line for line in lines[1:])
    # a band beyond the Nyquist frequency of a 200 Hz input: a warning, a counter, a failed test
    assert p.node.set_parameters([Parameter('band_hz', value=[20.0, 150.0])])[0].successful
    stamps = sine_stamps(600, fs=200.0)
    p.feed(stamps, np.sin(2 * np.pi * 30.0 * np.arange(600) / 200.0))
    warn = p.wait_status(lambda s: s.level == DiagnosticStatus.WARN)
    assert 'Nyquist frequency 100 Hz' in warn.message
    assert float(values_of(warn)['sample_rate_hz']) == pytest.approx(200.0)
    assert int(values_of(warn)['band_above_nyquist']) > 0
    response = p.call('self_test')
    assert not response.success and 'at 200 Hz sampling' in response.message
    assert 'above the Nyquist frequency 100 Hz' in response.message


# ---- modes ----------------------------------------------------------------------------------
def test_modes_one_publishes_mode1_topics(make_probe):
    p = make_probe(modes=1)
    stamps = sine_stamps(3000)
    values = np.sin(2 * np.pi * 1.33 * np.arange(3000) / FS)
    fed_at = time.time()
    p.feed(stamps, values)
    assert spin_until(
        p.executor, lambda: len(p.resets('mode1/reset')) >= len(p.frequencies()), 5.0
    )
    mode1 = p.values('mode1/frequency')
    assert len(mode1) >= 3 and mode1 == p.frequencies()
    assert p.resets('mode1/reset') == p.resets()
    assert abs(np.median(mode1) / 1.33 - 1) < 1e-3
    assert p.probe.count_publishers('/vibration/mode2/frequency') == 0
    status = p.wait_status(
        lambda s: values_of(s)['estimates'] == str(p.node.counters['estimates'])
    )
    kv = values_of(status)
    assert float(kv['mode1_frequency_hz']) == pytest.approx(mode1[-1], rel=1e-8)
    # the age of mode 1's last estimate: since it was published, on the node's clock
    assert 0 <= float(kv['mode1_age_s']) <= p.status_age(status, since=fed_at)
    assert 'mode2_frequency_hz' not in kv
    # switching modes off: the mode topics go
    assert p.node.set_parameters([Parameter('modes', value=0)])[0].successful
    assert spin_until(
        p.executor, lambda: p.probe.count_publishers('/vibration/mode1/frequency') == 0, 5.0
    )


def test_two_separated_modes_get_their_own_topics(make_probe):
    p = make_probe(modes=2)
    n = 5000  # 10 s at 500 Hz
    t = np.arange(n) / FS
    rng = np.random.default_rng(3)
    values = (
        np.sin(2 * np.pi * 1.33 * t)
        + 0.5 * np.sin(2 * np.pi * 8.5 * t + 1.0)
        + rng.normal(0, 1e-3, n)
    )
    p.feed(sine_stamps(n), values)
    assert spin_until(
        p.executor, lambda: len(p.values('mode1/frequency')) >= len(p.frequencies()), 5.0
    )  # mode 1's topic follows vibration/
    mode1, mode2 = p.values('mode1/frequency'), p.values('mode2/frequency')
    assert len(mode1) >= 3 and len(mode2) >= 3
    assert abs(np.median(mode1) / 1.33 - 1) < 0.01
    assert abs(np.median(mode2) / 8.5 - 1) < 0.01
    assert p.frequencies() == mode1  # vibration/frequency carries mode 1
    kv = values_of(p.wait_status(lambda s: True))
    assert abs(float(kv['mode2_frequency_hz']) / 8.5 - 1) < 0.02


class TwoBandTracker:
    """A stand-in for the mode tracker with the interface the node uses: two band-limited
    estimators, one per mode (the node's plumbing is tested independently of how modes are
    found)."""

    def __init__(self, config):
        self.config = config
        self._estimators = [
            FrequencyEstimator(config.replace(modes=0, band_hz=band))
            for band in ((0.5, 2.5), (20.0, 80.0))
        ]

    def update(self, t, y):
        found = [(k, e) for k, est in enumerate(self._estimators, 1) for e in est.update(t, y)]
        return [Estimate(**{**e.__dict__, 'mode': k}) for k, e in found]

    @property
    def counters(self):
        """Samples counted once, estimates and rejections summed over the modes."""
        first = self._estimators[0].counters
        return {
            name: first[name]
            if name in ('received', 'used')
            else sum(e.counters[name] for e in self._estimators)
            for name in first
        }

    def reset(self):
        for e in self._estimators:
            e.reset()


def test_each_mode_on_its_own_topics(make_probe, monkeypatch):
    monkeypatch.setattr(
        stream,
        'create_estimator',
        lambda config, channels=(): (
            TwoBandTracker(config) if config.modes else FrequencyEstimator(config)
        ),
    )
    p = make_probe(modes=2)
    n = 3000
    t = np.arange(n) / FS
    values = 0.5 * np.sin(2 * np.pi * 1.33 * t) + np.sin(2 * np.pi * 40.0 * t + 1.0)
    stamps = sine_stamps(n)
    fed_at = time.time()
    p.feed(stamps, values)
    tracker = TwoBandTracker(EstimatorConfig.paper(modes=2))  # the node's parameters
    expected = [
        e
        for ti, y in zip(seconds_since(np.asarray(stamps), stamps[0]), values)
        for e in tracker.update(ti, y)
    ]
    assert spin_until(
        p.executor,
        lambda: len(p.resets('mode2/reset')) >= len(p.values('mode2/frequency')) >= 1,
        5.0,
    )
    mode1, mode2 = p.values('mode1/frequency'), p.values('mode2/frequency')
    assert len(mode1) >= 3 and len(mode2) >= 3
    assert mode1 == [e.frequency_hz for e in expected if e.mode == 1]
    assert mode2 == [e.frequency_hz for e in expected if e.mode == 2]
    assert abs(np.median(mode2) / 40 - 1) < 0.01
    assert p.frequencies() == mode1 and p.resets() == p.resets('mode1/reset')
    # mode 1: its five outputs, then its mode topics; mode 2: its mode topics only
    order = [e[0] for e in p.events if not e[0].startswith('mode2')]
    assert order == (OUTPUTS + ['mode1/frequency', 'mode1/reset']) * len(mode1)
    assert [e[0] for e in p.events if e[0].startswith('mode2')] == [
        'mode2/frequency',
        'mode2/reset',
    ] * len(mode2)
    status = p.wait_status(
        lambda s: values_of(s)['estimates'] == str(p.node.counters['estimates'])
    )
    kv = values_of(status)
    assert float(kv['mode1_frequency_hz']) == pytest.approx(mode1[-1], rel=1e-8)
    assert float(kv['mode2_frequency_hz']) == pytest.approx(mode2[-1], rel=1e-8)
    assert 0 <= float(kv['mode2_age_s']) <= p.status_age(status, since=fed_at)
    assert float(kv['mode2_frequency_std_hz']) > 0
    assert int(kv['estimates']) == len(mode1) + len(mode2)


def test_simulated_accelerometer_end_to_end(ros_context, executor):
    """sim_node publishing sensor_msgs/Imu (tip acceleration) -> estimator_node with input_type
    Imu: the free vibration after the ramp at Eq. 23's frequency."""
    from vib_estimator.nodes.sim_node import SIM_TIME_ORIGIN_NS, SimNode
    from vib_estimator.sim.arm_model import natural_frequency_hz

    estimator = EstimatorNode(
        context=ros_context,
        parameter_overrides=[
            Parameter('input_type', value=fields.IMU),
            Parameter('input_topic', value='/imu_e2e/tip_imu'),
        ],
    )
    probe = Node('probe', context=ros_context)
    frequencies, resets = [], []
    subs = [
        probe.create_subscription(
            Float64, 'vibration/frequency', lambda m: frequencies.append(m.data), 100
        ),
        probe.create_subscription(
            Header,
            'vibration/reset',
            lambda m: resets.append(m.stamp.sec * 10**9 + m.stamp.nanosec),
            100,
        ),
    ]
    sim = SimNode(
        context=ros_context,
        namespace='imu_e2e',
        parameter_overrides=[
            Parameter('output_type', value=fields.IMU),
            Parameter('speed', value=10.0),
            Parameter('duration', value=5.0),
            Parameter('wait_for_subscribers', value=1),
        ],
    )
    nodes = (estimator, probe, sim)
    for node in nodes:
        executor.add_node(node)
    try:
        assert spin_until(executor, lambda: all(s.get_publisher_count() >= 1 for s in subs), 10.0)
        assert spin_until(executor, lambda: sim.finished, 60.0)
        assert spin_until(
            executor,
            lambda: len(frequencies) == len(resets) == estimator.counters['estimates'],
            5.0,
        )
    finally:
        for node in nodes:
            executor.remove_node(node)
            node.destroy_node()
    t = (np.array(resets) - SIM_TIME_ORIGIN_NS) * 1e-9  # simulated s since the first sample
    free = np.array(frequencies)[t > 1.5]  # after the 1 s ramp
    assert len(free) >= 3
    assert np.median(free) == pytest.approx(natural_frequency_hz(0.04555), rel=0.01)


def test_names_are_relative_so_namespaces_apply(ros_context, executor):
    node = EstimatorNode(
        context=ros_context, namespace='arm1', parameter_overrides=[Parameter('modes', value=2)]
    )
    probe = Node('probe', context=ros_context)
    expected_topics = {f'/arm1/vibration/{t}' for t in OUTPUTS} | {
        f'/arm1/vibration/mode{k}/{t}' for k in (1, 2) for t in ('frequency', 'reset')
    }
    expected_services = {'/arm1/estimator_node/reset', '/arm1/estimator_node/self_test'}

    def graph():
        topics = {
            n for n, _ in probe.get_publisher_names_and_types_by_node('estimator_node', '/arm1')
        }
        services = {
            n for n, _ in probe.get_service_names_and_types_by_node('estimator_node', '/arm1')
        }
        return topics, services

    try:
        for n in (node, probe):
            executor.add_node(n)
        assert spin_until(
            executor,
            lambda: expected_topics <= graph()[0] and expected_services <= graph()[1],
            10.0,
        ), graph()
        subscribed = {
            n for n, _ in probe.get_subscriber_names_and_types_by_node('estimator_node', '/arm1')
        }
        assert '/arm1/coupling_torque' in subscribed, subscribed
    finally:
        for n in (node, probe):
            executor.remove_node(n)
            n.destroy_node()


def test_simultaneous_service_calls_are_all_answered_while_estimating(make_probe):
    """Issue 22 case 7: 50 resets and 50 self-tests sent together while streaming were 21 answered.
    Now every call is answered (in turn) and the samples streamed meanwhile are all taken and
    estimated on."""
    p = make_probe()
    clients = p.trigger_clients()
    assert p.call('self_test').success  # compiled before the burst
    stamps = sine_stamps(5000)
    values = np.sin(2 * np.pi * 1.33 * np.arange(5000) / FS)
    p.feed(stamps[:1000], values[:1000])
    futures = [
        (name, clients[name].call_async(Trigger.Request()))
        for _ in range(50)
        for name in ('reset', 'self_test')
    ]
    p.feed(stamps[1000:], values[1000:])
    assert spin_until(p.executor, lambda: all(f.done() for _, f in futures), 60.0), (
        f'{sum(f.done() for _, f in futures)} of {len(futures)} answered'
    )
    answers = [(name, f.result()) for name, f in futures]
    assert all(r.success for name, r in answers if name == 'reset')
    assert all(
        r.success and r.message.startswith('passed') for name, r in answers if name == 'self_test'
    )
    assert p.node.counters['received'] == 5000
    assert len(p.frequencies()) > 5 and all(abs(f / 1.33 - 1) < 0.01 for f in p.frequencies())


# ---- several components of one message: the joint identification ------------------------------
#: two modes seen by three channels (the 2.5 Hz one weak on the first), 20 Hz
CHANNEL_MODES = [(1.0, 0.02, 1.0), (2.5, 0.02, 0.5)]
CHANNEL_SHAPES = np.array([[1.0, 0.2], [0.6, -0.9], [0.2, 0.8]])
AMBIENT = {'excitation': 'ambient', 'ambient_window_s': 40.0}
IMU_AXES = [f'linear_acceleration.{a}' for a in 'xyz']
EFFORTS = [f'effort[{j}]' for j in JOINTS]


def modal_samples(seconds=90.0, seed=4, fs=20.0):
    """(stamps ns, Y): CHANNEL_MODES on three channels."""
    t, y = modal_record(seconds, fs, CHANNEL_MODES, CHANNEL_SHAPES, snr_db=20.0, seed=seed)
    return [EPOCH_NS + round(s * 1e9) for s in t], y


def channels_message(input_type, components, stamp_ns, values, joints=JOINTS):
    """A message with ``values`` in ``components`` (JointState: those of ``joints`` only)."""
    msg = message(input_type, components[0], stamp_ns, values[0], joints)
    for component, value in zip(components[1:], values[1:]):
        if input_type != fields.JOINT_STATE or component[:-1].split('[')[1] in joints:
            fields.component_setter(component, input_type)(msg, value)
    return msg


def check_modes_and_shapes(p, stamps, y, skip=()):
    """The node published the joint identifier's estimates of the samples it took (all but
    ``skip``) on mode<k>/frequency, and each one's shape on mode<k>/shape: near the true ones."""
    keep = np.setdiff1d(np.arange(len(stamps)), list(skip))
    kept = np.asarray(stamps, dtype=np.int64)[keep]
    names = p.node.get_parameter('components').value
    expected = AmbientEstimator(config_of(p.node), names).process(
        seconds_since(kept, kept[0]), y[keep]
    )
    e = expected.estimates
    assert len(e) > 12 and set(e.mode.tolist()) == {1, 2}  # (20: every 5 s once confirmed)
    assert spin_until(p.executor, lambda: sum(map(len, p.shapes.values())) == len(e), 5.0)
    m = len(names)
    for k, (f, _, _), true in zip((1, 2), CHANNEL_MODES, CHANNEL_SHAPES.T):
        assert p.values(f'mode{k}/frequency') == e.frequency_hz[e.mode == k].tolist()
        assert abs(np.median(p.values(f'mode{k}/frequency')) / f - 1) < 0.02
        rows, cols = p.shapes[k][-1].layout.dim
        assert (rows.label, cols.label) == (','.join(SHAPE_ROWS), ','.join(names))
        assert (rows.size, rows.stride, cols.size, cols.stride) == (3, 3 * m, m, m)
        data = np.array([msg.data for msg in p.shapes[k]])
        unit = true / np.linalg.norm(true)
        unit *= np.sign(unit[np.argmax(np.abs(unit))])  # the largest entry positive
        assert np.allclose(np.median(data[:, :m], axis=0), unit, atol=0.1), (k, data[-1])
        off_real = np.abs((data[:, m : 2 * m] + 90) % 180 - 90)  # phase: degrees from 0 or 180
        assert np.all(np.median(off_real, axis=0) < 10)  # a real mode


def test_three_axis_imu_gives_the_modes_with_their_shapes(make_probe):
    p = make_probe(2, input_type=fields.IMU, components=IMU_AXES, **AMBIENT)
    stamps, y = modal_samples()
    p.publish([channels_message(fields.IMU, IMU_AXES, s, v) for s, v in zip(stamps, y)])
    check_modes_and_shapes(p, stamps, y)
    status = p.wait_status(lambda s: 'channels' in values_of(s))  # /diagnostics names them
    assert values_of(status)['channels'] == ','.join(IMU_AXES)


def test_three_axis_imu_free_decay_is_estimated_jointly(make_probe):
    """excitation free (the default) with three IMU axes: a pluck's joint free-decay estimates on
    mode1/frequency and their shapes on mode1/shape, those of the core's joint estimator."""
    from vib_estimator.core import create_estimator

    p = make_probe(1, input_type=fields.IMU, components=IMU_AXES)
    t = np.arange(2000) / FS
    decay = np.exp(-0.3 * t) * np.sin(2 * np.pi * 5.0 * t + 0.3)
    true = np.array([0.2, 1.0, -0.5])
    y = decay[:, None] * true + 0.02 * np.random.default_rng(9).standard_normal((len(t), 3))
    stamps = sine_stamps(len(t))
    p.publish([channels_message(fields.IMU, IMU_AXES, s, v) for s, v in zip(stamps, y)])
    expected = create_estimator(config_of(p.node), IMU_AXES).process(
        seconds_since(np.asarray(stamps, dtype=np.int64), stamps[0]), y
    )
    e = expected.estimates
    assert len(e) > 5 and set(e.mode.tolist()) == {1}
    assert spin_until(p.executor, lambda: len(p.shapes[1]) == len(e), 5.0)
    assert p.values('mode1/frequency') == e.frequency_hz.tolist()
    assert abs(np.median(e.frequency_hz) / 5.0 - 1) < 0.005
    data = np.array([msg.data for msg in p.shapes[1]])
    assert np.allclose(np.median(data[:, :3], axis=0), true / np.linalg.norm(true), atol=0.02)


def test_several_joints_a_message_without_one_is_skipped_and_counted(make_probe):
    p = make_probe(2, input_type=fields.JOINT_STATE, components=EFFORTS, **AMBIENT)
    stamps, y = modal_samples(seed=5)
    absent = set(range(300, len(stamps), 97))
    orders = [JOINTS, JOINTS[::-1], ['wrist', 'shoulder', 'elbow']]
    joints = [['shoulder', 'wrist'] if i in absent else orders[i % 3] for i in range(len(y))]
    p.publish(
        [
            channels_message(fields.JOINT_STATE, EFFORTS, s, v, j)
            for s, v, j in zip(stamps, y, joints)
        ]
    )
    assert p.node.counters['skipped_joint_missing'] == len(absent)
    check_modes_and_shapes(p, stamps, y, absent)


@pytest.mark.parametrize(
    'overrides, reason',
    [
        ({'components': IMU_AXES, 'excitation': 'auto'}, 'need excitation free or ambient'),
        ({'components': ['linear_acceleration.x', 'torque.z'], **AMBIENT}, 'component of'),
        ({'components': ['linear_acceleration.x'] * 2, **AMBIENT}, 'given twice'),
    ],
)
def test_bad_components_stop_the_start(ros_context, overrides, reason):
    with pytest.raises(StartupError, match=reason):
        EstimatorNode(
            context=ros_context,
            parameter_overrides=[
                Parameter(k, value=v) for k, v in {'input_type': fields.IMU, **overrides}.items()
            ],
        )


def test_components_are_validated_at_run_time(ros_context):
    node = EstimatorNode(
        context=ros_context, parameter_overrides=[Parameter('input_type', value=fields.IMU)]
    )
    try:
        assert node.get_parameter('components').value == []
        assert node.describe_parameter('components').description.startswith('several fields')
        refused = node.set_parameters_atomically(
            [Parameter('components', value=IMU_AXES), Parameter('excitation', value='auto')]
        )
        assert not refused.successful and 'need excitation free or ambient' in refused.reason
        both = node.set_parameters_atomically(
            [Parameter('components', value=IMU_AXES), Parameter('excitation', value='ambient')]
        )
        assert both.successful
        refused = node.set_parameters([Parameter('excitation', value='auto')])[0]
        assert not refused.successful and '3 components' in refused.reason
        assert node.set_parameters([Parameter('excitation', value='free')])[0].successful
        empty = Parameter('components', Parameter.Type.STRING_ARRAY, [])
        assert node.set_parameters([empty])[0].successful
        assert node.set_parameters([Parameter('excitation', value='free')])[0].successful
    finally:
        node.destroy_node()


@pytest.mark.parametrize('deciding', [True, False])
def test_a_driven_input_switches_the_default_to_the_identifier(make_probe, deciding):
    """``decide_excitation`` (default true): fed a mode driven throughout, the free-decay node
    sets its own excitation and window to analyze's decision over the last seconds (a
    building's 1.2 Hz fundamental: ~100 s); false keeps free and says on /diagnostics which
    excitation helps."""
    from vib_estimator.sim.ambient import ambient_record

    p = make_probe(decide_excitation=deciding)
    stream, primed = p.node._stream, []
    configure = stream.configure
    stream.configure = lambda *a, **k: primed.append(k.get('prime')) or configure(*a, **k)
    t, y, _ = ambient_record(75, 40, [(1.2, 0.015, 1.0)], 20, 1)
    p.feed([EPOCH_NS + round(s * 1e9) for s in t], y)
    if deciding:
        node = p.node
        assert spin_until(p.executor, lambda: config_of(node).excitation == 'ambient', 5.0)
        assert 90 <= node.get_parameter('ambient_window_s').value <= 110
        assert p.node._stream.decided
        # excitation and window at once: one identifier built and primed, not one a parameter
        assert primed == [True]
    else:
        status = p.wait_status(lambda s: 'looks driven' in s.message)
        assert 'excitation:=ambient' in status.message
        assert config_of(p.node).excitation == 'free'


def test_a_periodic_drive_sets_the_nodes_lines(make_probe):
    """``decide_excitation``: a mode driven by noise beside a cycle's lines (odd harmonics of
    0.8 Hz) sets the node's own ``lines_hz`` (a double array) with the identifier."""
    from vib_estimator.sim.ambient import ambient_record

    p = make_probe()
    t, y, _ = ambient_record(75, 40, [(5.0, 0.01, 1.0)], 30, 1)
    y = y + sum(1.5 / k * np.sin(2 * np.pi * k * 0.8 * t + k) for k in (1, 3, 5, 7, 9))
    p.feed([EPOCH_NS + round(s * 1e9) for s in t], y)
    node = p.node
    assert spin_until(p.executor, lambda: config_of(node).excitation == 'ambient', 5.0)
    lines = node.get_parameter('lines_hz').value
    assert len(lines) >= 5 and lines[0] == pytest.approx(0.8, rel=1e-3)


def test_a_silent_decay_of_several_modes_sets_the_nodes_modes(make_probe):
    """``decide_excitation``: a pluck of two beating modes, which the one-mode estimator cannot
    fit, sets the node's own ``modes`` to 3 (the mode tracker, primed with the decay so far):
    both modes are then published on their topics (test_stream.py has the rule)."""
    t = np.arange(0, 8, 1 / 500)
    tau = np.maximum(t - 1.0, 0)
    y = sum(
        a * np.exp(-0.003 * 2 * np.pi * f * tau) * np.sin(2 * np.pi * f * tau)
        for f, a in ((10.0, 1.0), (13.0, 0.5))
    )
    y += 1e-3 * np.random.default_rng(0).standard_normal(len(t))
    p = make_probe(**{name: getattr(EstimatorConfig(), name) for name in PAPER})  # defaults
    p.feed([EPOCH_NS + round(s * 1e9) for s in t], y)
    node = p.node
    assert spin_until(p.executor, lambda: config_of(node).modes == 3, 10.0)
    assert node.get_parameter('modes').value == 3 and config_of(node).excitation == 'free'
    assert p.node._stream.decided


def test_a_decay_whose_modes_ring_on_sets_the_nodes_modes_and_publishes_each(make_probe):
    """``decide_excitation``: an 8 / 21 / 55 Hz pluck (1 : 0.3 : 0.05), whose one-mode estimator
    follows 8 Hz alone, sets the node's own ``modes`` to 3 once the decay's last half still
    shows its modes (test_stream.py has the rule); the pluck's next seconds are then published
    on vibration/mode1..3/frequency, each mode within 2 % of its own."""
    t = np.arange(0, 10, 1 / FS)
    tau = np.maximum(t - 1.0, 0)
    truth = ((8.0, 1.0, 0.003), (21.0, 0.3, 0.002), (55.0, 0.05, 0.002))
    y = sum(
        a * np.exp(-z * 2 * np.pi * f * tau) * np.sin(2 * np.pi * f * tau) for f, a, z in truth
    )
    y += 1e-3 * np.random.default_rng(0).standard_normal(len(t))
    stamps = [EPOCH_NS + round(s * 1e9) for s in t]
    p = make_probe(**{name: getattr(EstimatorConfig(), name) for name in PAPER})  # defaults
    first = int(4 * FS)
    p.feed(stamps[:first], y[:first])
    node = p.node
    assert spin_until(p.executor, lambda: config_of(node).modes == 3, 10.0)
    assert node.get_parameter('modes').value == 3 and p.node._stream.decided
    subs = [p._listen(f'mode{k}/{n}') for k in (1, 2, 3) for n in ('frequency', 'reset')]
    assert spin_until(p.executor, lambda: all(s.get_publisher_count() >= 1 for s in subs), 10.0)
    p.modes = 3  # (Probe.wait_outputs: each mode's resets)
    p.publish([message(p.input_type, 'torque.z', s, v) for s, v in zip(stamps[first:], y[first:])])
    for k, (f, _, _) in enumerate(truth, 1):
        got = np.array(p.values(f'mode{k}/frequency'))
        assert len(got) >= 5 and np.mean(np.abs(got / f - 1) <= 0.02) >= 0.95, (k, got)
