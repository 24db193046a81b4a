# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""estimator_node with several input topics (``input_topics``): samples aligned by header stamp,
a lost message and a stalled topic counted and reported, estimates those of the core's joint
estimator on the aligned samples."""

import numpy as np
import pytest
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from rclpy.node import Node
from rclpy.parameter import Parameter
from std_msgs.msg import Float64, Float64MultiArray

from vib_estimator.core import create_estimator
from vib_estimator.io import fields
from vib_estimator.io.fields import seconds_since
from vib_estimator.nodes.estimator_node import EstimatorNode, message_class
from vib_estimator.nodes.parameters import config_of
from vib_estimator.nodes.runner import StartupError, spin_until, spin_until_arrival

EPOCH_NS = 1_000_000_000 * 1_000_000_000
FS = 500.0
TOPICS = ['joint1/torque', 'joint2/torque', 'joint3/torque']
COMPONENT = 'torque.z'
CHANNELS = [f'/{t}:{COMPONENT}' for t in TOPICS]
PAPER = {'model': 'sinusoid', 'min_periods': 0.5, 'consistency_gate': False}
BATCH = 30  # per topic, below the node's input depth


def wrench(stamp_ns, value):
    msg = message_class(fields.WRENCH_STAMPED)()
    msg.header.stamp.sec, msg.header.stamp.nanosec = divmod(int(stamp_ns), 10**9)
    msg.header.frame_id = 'arm'
    msg.wrench.torque.z = float(value)
    return msg


def values_of(status):
    return {kv.key: kv.value for kv in status.values}


class TopicsProbe:
    """Publishes on the three topics, records mode 1's frequencies and shapes and diagnostics."""

    def __init__(self, context, executor, node):
        self.executor, self.node = executor, node
        self.probe = Node('probe', context=context)
        self.pubs = [
            self.probe.create_publisher(message_class(fields.WRENCH_STAMPED), t, 1000)
            for t in TOPICS
        ]
        self.frequencies, self.shapes, self.diagnostics = [], [], []
        subs = [
            self.probe.create_subscription(
                Float64,
                'vibration/mode1/frequency',
                lambda m: self.frequencies.append(m.data),
                100,
            ),
            self.probe.create_subscription(
                Float64MultiArray, 'vibration/mode1/shape', self.shapes.append, 100
            ),
            self.probe.create_subscription(
                DiagnosticArray, '/diagnostics', self.diagnostics.append, 10
            ),
        ]
        executor.add_node(node)
        executor.add_node(self.probe)
        assert spin_until(
            executor,
            lambda: (
                all(p.get_subscription_count() >= 1 for p in self.pubs)
                and all(s.get_publisher_count() >= 1 for s in subs)
            ),
            10.0,
        )
        self.sent = 0

    def accounted(self):
        c = self.node.counters
        return (
            c['aligned'] * len(TOPICS)
            + c['dropped_unaligned']
            + c['dropped_stalled']
            + c['skipped_stream_order']
            + self.node.pending_aligned
        )

    def publish(self, samples):
        """``samples``: (topic index, stamp, value), published in batches, each taken first."""
        for start in range(0, len(samples), BATCH):
            for i, stamp, value in samples[start : start + BATCH]:
                self.pubs[i].publish(wrench(stamp, value))
                self.sent += 1
            assert spin_until(self.executor, lambda: self.accounted() >= self.sent, 10.0), (
                self.accounted(),
                self.sent,
            )

    def wait_status(self, predicate, timeout=5.0) -> DiagnosticStatus:
        """Spin until a /diagnostics status satisfies ``predicate``; return it."""
        array = spin_until_arrival(
            self.executor, self.diagnostics, lambda a: predicate(a.status[0]), timeout
        )
        return array.status[0]


@pytest.fixture
def topics_probe(ros_context, executor):
    made = []

    def make(**overrides):
        params = {
            'input_topics': TOPICS,
            'component': COMPONENT,
            'modes': 1,
            **PAPER,
            **overrides,
        }
        node = EstimatorNode(
            context=ros_context,
            parameter_overrides=[Parameter(k, value=v) for k, v in params.items()],
        )
        made.append(node)
        return TopicsProbe(ros_context, executor, node)

    yield make
    for node in made:
        node.destroy_node()


def pluck(n=1500, seed=3):
    t = np.arange(n) / FS
    decay = np.exp(-0.3 * t) * np.sin(2 * np.pi * 5.0 * t + 0.3)
    shape = np.array([1.0, -0.6, 0.3])
    y = decay[:, None] * shape + 0.02 * np.random.default_rng(seed).standard_normal((n, 3))
    return [EPOCH_NS + round(i * 1e9 / FS) for i in range(n)], y, shape


def test_three_topics_are_aligned_by_stamp_and_estimated_jointly(topics_probe):
    """A pluck on three WrenchStamped topics, arriving interleaved out of step, one message lost
    on topic 2 now and then: the node publishes the joint estimator's estimates on the aligned
    samples (those of the stamps every topic has), each lost message costing its stamp only."""
    p = topics_probe()
    stamps, y, shape = pluck()
    lost = set(range(200, len(stamps), 173))
    rng = np.random.default_rng(1)
    samples = []
    for k, s in enumerate(stamps):
        order = rng.permutation(3)  # each stamp's three messages in a random order
        samples += [(int(i), s, y[k, i]) for i in order if not (i == 1 and k in lost)]
    p.publish(samples)
    keep = np.array([k not in lost for k in range(len(stamps))])
    c = p.node.counters
    assert c['aligned'] == int(keep.sum()) and c['dropped_unaligned'] == 2 * len(lost)
    kept = np.asarray(stamps, dtype=np.int64)[keep]
    expected = create_estimator(config_of(p.node), CHANNELS).process(
        seconds_since(kept, kept[0]), y[keep]
    )
    e = expected.estimates
    assert len(e) > 5
    assert spin_until(p.executor, lambda: len(p.shapes) >= len(e), 5.0)
    assert p.frequencies == e.frequency_hz.tolist()
    assert abs(np.median(e.frequency_hz) / 5.0 - 1) < 0.005
    assert p.shapes[0].layout.dim[1].label == ','.join(CHANNELS)
    data = np.array([m.data for m in p.shapes])
    assert np.allclose(np.median(data[:, :3], axis=0), shape / np.linalg.norm(shape), atol=0.03)
    status = p.wait_status(lambda s: 'channels' in values_of(s))
    assert values_of(status)['channels'] == ','.join(CHANNELS)


def test_a_stalled_topic_is_named_in_the_diagnostics_and_the_others_resume_with_it(
    topics_probe,
):
    p = topics_probe()
    stamps, y, _ = pluck(3000)
    first = [(i, s, y[k, i]) for k, s in enumerate(stamps[:500]) for i in range(3)]
    p.publish(first)
    assert p.node.counters['aligned'] == 500
    stall = [(i, s, y[k, i]) for k, s in enumerate(stamps[500:2000], 500) for i in (0, 1)]
    p.publish(stall)  # topic 3 silent for 3 s of stamps
    status = p.wait_status(lambda s: 'joint3' in s.message)
    assert status.level == DiagnosticStatus.WARN
    assert values_of(status)['lagging_topics'] == '/joint3/torque'
    assert p.node.counters['aligned'] == 500
    resumed = [(i, s, y[k, i]) for k, s in enumerate(stamps[2000:], 2000) for i in range(3)]
    p.publish(resumed)
    c = p.node.counters
    assert c['aligned'] == 500 + 1000
    assert c['dropped_unaligned'] + c['dropped_stalled'] == 2 * 1500
    status = p.wait_status(lambda s: values_of(s).get('lagging_topics') == '')


@pytest.mark.parametrize(
    'overrides, reason',
    [
        ({'input_topics': ['a', 'a']}, 'distinct'),
        ({'input_topics': ['a', 'b'], 'input_type': 'std_msgs/msg/Float64'}, 'stamped'),
        ({'input_topics': ['a', 'b'], 'excitation': 'auto'}, 'need excitation free or ambient'),
    ],
)
def test_bad_input_topics_stop_the_start(ros_context, overrides, reason):
    with pytest.raises(StartupError, match=reason):
        EstimatorNode(
            context=ros_context,
            parameter_overrides=[Parameter(k, value=v) for k, v in overrides.items()],
        )
