# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""estimator_node with ``components``: several fields of one message identified jointly, in process
(fresh context, isolated domain): a 3-axis IMU, a multi-joint JointState, a 3-axis bag replayed
through the node giving ``analyze --components``'s estimates, and the parameter's checks.

Samples go out with explicit header stamps in batches as fast as the node takes them (each batch
waits for the node's counters); waits are on matched counts and counters, not sleeps.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
from diagnostic_msgs.msg import DiagnosticArray
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.qos import QoSProfile
from std_msgs.msg import Float64, Float64MultiArray

from vib_estimator.core.config import EstimatorConfig
from vib_estimator.core.multichannel import JointAmbientEstimator
from vib_estimator.core.shapes import SHAPE_ROWS
from vib_estimator.io import fields
from vib_estimator.io.bags import write_channels
from vib_estimator.io.fields import seconds_since
from vib_estimator.nodes.bag_replayer import BagReplayer
from vib_estimator.nodes.estimator_node import EstimatorNode, message_class
from vib_estimator.nodes.runner import StartupError, spin_until
from vib_estimator.sim.frame import modal_record

EPOCH_NS = 1_000_000_000 * 1_000_000_000
FS = 20.0
BATCH = 50
#: two modes seen by three channels (the 2.5 Hz one weak on the first)
MODES = [(1.0, 0.02, 1.0), (2.5, 0.02, 0.5)]
SHAPES = np.array([[1.0, 0.2], [0.6, -0.9], [0.2, 0.8]])
AMBIENT = {'excitation': 'ambient', 'ambient_window_s': 40.0, 'modes': 2}
IMU_AXES = [f'linear_acceleration.{a}' for a in 'xyz']
JOINTS = ['shoulder', 'elbow', 'wrist']


def record(seconds=120.0, seed=4):
    """(stamps ns, Y) of the two modes on three channels at FS."""
    t, y = modal_record(seconds, FS, MODES, SHAPES, snr_db=20.0, seed=seed)
    return [EPOCH_NS + round(s * 1e9) for s in t], y


def message(input_type, components, stamp_ns, values, joints=JOINTS):
    """A message of ``input_type`` with ``values`` in ``components`` (JointState: the joints
    ``joints``, in that order; one not among the components gets another value)."""
    msg = message_class(input_type)()
    msg.header.stamp.sec, msg.header.stamp.nanosec = divmod(int(stamp_ns), 10**9)
    given = dict(zip(components, values))
    if input_type == fields.JOINT_STATE:
        components = [f'effort[{j}]' for j in joints]
    for component in components:
        fields.component_setter(component, input_type)(msg, given.get(component, 7.0))
    return msg


class Probe:
    """Publishes samples; records each mode's frequencies and shapes and the diagnostics."""

    def __init__(self, context, executor, node, modes=2):
        self.executor, self.node = executor, node
        self.input_type = node.get_parameter('input_type').value
        self.probe = Node('probe', context=context)
        self.pub = self.probe.create_publisher(
            message_class(self.input_type), 'coupling_torque', 1000
        )
        self.frequency = {k: [] for k in range(1, modes + 1)}
        self.shape = {k: [] for k in range(1, modes + 1)}
        self.diagnostics = []
        subs = [
            self.probe.create_subscription(
                DiagnosticArray, '/diagnostics', self.diagnostics.append, 10
            )
        ]
        for k in range(1, modes + 1):
            subs.append(
                self.probe.create_subscription(
                    Float64,
                    f'vibration/mode{k}/frequency',
                    lambda m, k=k: self.frequency[k].append(m.data),
                    100,
                )
            )
            subs.append(
                self.probe.create_subscription(
                    Float64MultiArray, f'vibration/mode{k}/shape', self.shape[k].append, 100
                )
            )
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

    def taken(self):
        counters = self.node.counters
        return counters['received'] + counters['skipped_joint_missing']

    def publish(self, msgs):
        for start in range(0, len(msgs), BATCH):
            for msg in msgs[start : start + BATCH]:
                self.pub.publish(msg)
                self.sent += 1
            assert spin_until(self.executor, lambda: self.taken() >= self.sent, 10.0)

        def arrived():
            n = sum(len(v) for v in self.frequency.values())
            return n >= self.node.counters['estimates'] and n == sum(
                len(v) for v in self.shape.values()
            )

        assert spin_until(self.executor, arrived, 5.0)


@pytest.fixture
def make_probe(ros_context, executor):
    made = []

    def make(**overrides):
        node = EstimatorNode(
            context=ros_context,
            parameter_overrides=[Parameter(k, value=v) for k, v in overrides.items()],
        )
        made.append(node)
        return Probe(ros_context, executor, node)

    yield make
    for node in made:
        node.destroy_node()


def offline(stamps, y, names, skip=()):
    """What the joint identifier gives on these samples (``skip``: indices not fed)."""
    keep = np.setdiff1d(np.arange(len(stamps)), list(skip))
    stamps = np.asarray(stamps, dtype=np.int64)[keep]
    estimator = JointAmbientEstimator(EstimatorConfig().replace(**AMBIENT), names)
    return estimator.process(seconds_since(stamps, stamps[0]), y[keep])


def check_modes_and_shapes(p, names, expected):
    """The node published ``expected``'s frequencies on mode<k>/frequency and each one's shape
    on mode<k>/shape, the true shapes of MODES."""
    e = expected.estimates
    assert len(e) > 20 and set(e.mode.tolist()) == {1, 2}
    for k, (f, _, _), true in zip((1, 2), MODES, SHAPES.T):
        assert p.frequency[k] == e.frequency_hz[e.mode == k].tolist()
        assert abs(np.median(p.frequency[k]) / f - 1) < 0.02
        msg = p.shape[k][-1]
        rows, cols = msg.layout.dim
        assert rows.label == ','.join(SHAPE_ROWS) and cols.label == ','.join(names)
        assert (rows.size, cols.size, rows.stride) == (3, len(names), 3 * len(names))
        shapes = np.array([m.data[: len(names)] for m in p.shape[k]])
        unit = true / np.linalg.norm(true)
        unit *= np.sign(unit[np.argmax(np.abs(unit))])
        assert np.allclose(np.median(shapes, axis=0), unit, atol=0.1), (k, shapes[-1])
        phases = np.array([m.data[len(names) : 2 * len(names)] for m in p.shape[k]])
        off_real = np.abs((phases + 90) % 180 - 90)  # degrees from 0 or 180
        assert np.all(np.median(off_real, axis=0) < 10)  # a real mode


def test_three_axis_imu_gives_the_modes_with_their_shapes(make_probe):
    p = make_probe(input_type=fields.IMU, components=IMU_AXES, **AMBIENT)
    stamps, y = record()
    p.publish([message(fields.IMU, IMU_AXES, s, v) for s, v in zip(stamps, y)])
    check_modes_and_shapes(p, IMU_AXES, offline(stamps, y, IMU_AXES))

    def channels():  # what the statuses say the channels are
        values = [{kv.key: kv.value for kv in a.status[0].values} for a in p.diagnostics]
        return [v['channels'] for v in values if 'channels' in v]

    assert spin_until(p.executor, channels, 5.0)  # /diagnostics: 1 Hz
    assert channels()[0] == ','.join(IMU_AXES)


def test_joint_state_several_joints_missing_one_skips_the_sample(make_probe):
    names = [f'effort[{j}]' for j in JOINTS]
    p = make_probe(input_type=fields.JOINT_STATE, components=names, **AMBIENT)
    stamps, y = record(seed=5)
    absent = set(range(300, len(stamps), 97))
    orders = [JOINTS, JOINTS[::-1], ['wrist', 'shoulder', 'elbow']]
    p.publish(
        [
            message(
                fields.JOINT_STATE,
                names,
                s,
                v,
                ['shoulder', 'wrist'] if i in absent else orders[i % 3],
            )
            for i, (s, v) in enumerate(zip(stamps, y))
        ]
    )
    assert p.node.counters['skipped_joint_missing'] == len(absent)
    check_modes_and_shapes(p, names, offline(stamps, y, names, absent))


@pytest.mark.parametrize(
    'overrides, reason',
    [
        ({'components': IMU_AXES}, 'need excitation ambient'),
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
        context=ros_context,
        parameter_overrides=[Parameter('input_type', value=fields.IMU)],
    )
    try:
        assert node.get_parameter('components').value == []
        assert node.describe_parameter('components').description.startswith('several fields')
        refused = node.set_parameters([Parameter('components', value=IMU_AXES)])[0]
        assert not refused.successful and 'need excitation ambient' in refused.reason
        both = node.set_parameters_atomically(
            [Parameter('components', value=IMU_AXES), Parameter('excitation', value='ambient')]
        )
        assert both.successful
        refused = node.set_parameters([Parameter('excitation', value='free')])[0]
        assert not refused.successful and '3 components' in refused.reason
        empty = Parameter('components', Parameter.Type.STRING_ARRAY, [])
        assert node.set_parameters([empty])[0].successful
        assert node.set_parameters([Parameter('excitation', value='free')])[0].successful
    finally:
        node.destroy_node()


def test_three_axis_bag_replayed_through_the_node_gives_analyze_s_estimates(
    ros_context, executor, tmp_path, capsys, monkeypatch
):
    from vib_estimator.cli import main
    from vib_estimator.nodes import estimator_node

    stamps, y = record(100.0, seed=6)
    bag = tmp_path / 'imu'
    write_channels(bag, '/coupling_torque', fields.IMU, IMU_AXES, stamps, y, 'tip')
    options = ['--excitation', 'ambient', '--ambient-window-s', '40', '--modes', '2']
    assert main(['analyze', str(bag), '--components', ','.join(IMU_AXES), *options]) == 0
    rows = [json.loads(line) for line in capsys.readouterr().out.splitlines()]
    assert len(rows) > 20 and {'shape_linear_acceleration.y', 'stamp_ns', 'mac'} <= set(rows[0])
    monkeypatch.setattr(estimator_node, 'INPUT_DEPTH', len(stamps))  # no burst can drop one
    node = EstimatorNode(
        context=ros_context,
        parameter_overrides=[
            Parameter(k, value=v)
            for k, v in {'input_type': fields.IMU, 'components': IMU_AXES, **AMBIENT}.items()
        ],
    )
    replayer = BagReplayer(
        context=ros_context,
        parameter_overrides=[
            Parameter('bag', value=str(bag)),
            Parameter('start_paused', value=True),
            Parameter('rate', value=50.0),
        ],
    )
    listener = Node('listener', context=ros_context)
    got = {k: [] for k in (1, 2)}
    subs = [
        listener.create_subscription(
            Float64, f'vibration/mode{k}/frequency', got[k].append, QoSProfile(depth=1000)
        )
        for k in got
    ]
    for n in (node, replayer, listener):
        executor.add_node(n)
    assert spin_until(
        executor,
        lambda: (
            all(s.get_publisher_count() for s in subs)
            and node.count_publishers('/coupling_torque') > 0
        ),
        10,
    )
    replayer.resume()
    assert spin_until(executor, lambda: replayer.finished, 30)
    assert spin_until(executor, lambda: node.counters['received'] == len(stamps), 10)
    assert spin_until(executor, lambda: sum(map(len, got.values())) == len(rows), 5)
    for k in got:
        assert [m.data for m in got[k]] == [r['frequency_hz'] for r in rows if r['mode'] == k]
    node.destroy_node()
    replayer.destroy_node()
