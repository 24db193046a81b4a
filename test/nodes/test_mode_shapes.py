# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""``estimator_node``'s ``vibration/mode_shapes`` (nodes/mode_markers.py, nodes/mode_shapes.py):
with a ``geometry_file``, one deformed shape per published mode, consistent with the node's
``vibration/mode<k>/shape`` and with the geometry; DELETEALL first, stable ids."""

from __future__ import annotations

import numpy as np
import pytest
from rclpy.node import Node
from rclpy.parameter import Parameter
from std_msgs.msg import Float64MultiArray
from visualization_msgs.msg import Marker, MarkerArray

from vib_estimator.core.shapes import mac
from vib_estimator.io import fields
from vib_estimator.io.geometry import load_geometry, parse_geometry
from vib_estimator.nodes.estimator_node import EstimatorNode, message_class
from vib_estimator.nodes.mode_markers import ModeShapeMarkers
from vib_estimator.nodes.runner import StartupError, spin_until
from vib_estimator.sim.frame import modal_record

AXES = [f'linear_acceleration.{a}' for a in 'xyz']
#: a mast: the x axis at the top, y in the middle, z (read as x) low
GEOMETRY = f"""
name: test mast
points: {{base: [0, 0, 0], p1: [0, 0, 1], p2: [0, 0, 2], p3: [0, 0, 3]}}
channels:
  {AXES[0]}: {{point: p3, direction: x}}
  {AXES[1]}: {{point: p2, direction: x}}
  {AXES[2]}: {{point: p1, direction: x}}
lines: [[base, p1], [p1, p2], [p2, p3]]
fixed: [base]
"""
MODES = [(1.0, 0.02, 1.0), (2.5, 0.02, 0.5)]
SHAPES = np.array([[1.0, 0.2], [0.6, -0.9], [0.2, 0.8]])
EPOCH_NS = 1_700_000_000_000_000_000
BATCH = 200


def test_markers_are_deleteall_then_each_modes_with_stable_ids():
    g = parse_geometry(__import__('yaml').safe_load(GEOMETRY))
    m = ModeShapeMarkers(g, AXES, 0.1, 2.0)
    m.update(2, 2.5, 0.02, np.array([0.3, -0.9, 0.3]))
    m.update(1, 1.0, float('nan'), np.array([1.0, 0.6, 0.2]))
    specs = m.markers(0.0)
    assert specs[0].kind == 'delete_all'
    assert [(s.ns, s.id) for s in specs[1:]] == [
        (ns, k) for k in (1, 2) for ns in ('undeformed', 'deformed', 'sensors', 'label')
    ]
    assert specs[4].text == 'mode 1\n1 Hz, ζ not estimated'
    sensors = specs[3].points - (g.points[[1, 2, 3]] + m.origin(1))  # p1, p2, p3
    # at t = 0 the largest deflection, 0.1 of the structure's extent, along x
    assert np.allclose(sensors[:, 0], 0.1 * g.size * np.array([0.2, 0.6, 1.0]))
    assert np.allclose(specs[3].colours[:, 0], [0.2, 0.6, 1.0])  # red: the amplitude
    quarter = m.markers(0.5)[3].points - (g.points[[1, 2, 3]] + m.origin(1))
    assert np.allclose(quarter, 0.0, atol=1e-12)  # a real shape passes rest a quarter on


def imu(stamp_ns, values):
    msg = message_class(fields.IMU)()
    msg.header.stamp.sec, msg.header.stamp.nanosec = divmod(stamp_ns, 1_000_000_000)
    for component, value in zip(AXES, values):
        fields.component_setter(component, fields.IMU)(msg, float(value))
    return msg


@pytest.fixture
def node_with_geometry(ros_context, executor, tmp_path):
    path = tmp_path / 'mast.yaml'
    path.write_text(GEOMETRY)
    overrides = {
        'input_type': fields.IMU,
        'components': AXES,
        'excitation': 'ambient',
        'ambient_window_s': 40.0,
        'modes': 2,
        'geometry_file': str(path),
        'frame_id': 'mast',
        'mode_shapes_rate_hz': 20.0,
    }
    node = EstimatorNode(
        context=ros_context,
        parameter_overrides=[Parameter(k, value=v) for k, v in overrides.items()],
    )
    return node, load_geometry(path)


def test_mode_shapes_topic_draws_each_published_shape_on_the_geometry(
    ros_context, executor, node_with_geometry
):
    node, geometry = node_with_geometry
    probe = Node('probe', context=ros_context)
    pub = probe.create_publisher(message_class(fields.IMU), 'coupling_torque', 1000)
    arrays, shapes = [], {1: [], 2: []}
    subs = [probe.create_subscription(MarkerArray, 'vibration/mode_shapes', arrays.append, 100)]
    subs += [
        probe.create_subscription(
            Float64MultiArray, f'vibration/mode{k}/shape', shapes[k].append, 100
        )
        for k in shapes
    ]
    executor.add_node(node)
    executor.add_node(probe)
    assert spin_until(
        executor,
        lambda: pub.get_subscription_count() >= 1 and all(s.get_publisher_count() for s in subs),
        10.0,
    )
    t, y = modal_record(90.0, 20.0, MODES, SHAPES, snr_db=20.0, seed=4)
    for start in range(0, len(t), BATCH):
        for s, v in zip(t[start : start + BATCH], y[start : start + BATCH]):
            pub.publish(imu(EPOCH_NS + round(s * 1e9), v))
        sent = min(start + BATCH, len(t))
        assert spin_until(executor, lambda: node.counters['received'] >= sent, 10.0)
    assert spin_until(executor, lambda: all(shapes.values()), 5.0)
    last = {k: np.array(shapes[k][-1].data[:3]) for k in shapes}  # signed amplitudes
    seen = len(arrays)
    assert spin_until(executor, lambda: len(arrays) >= seen + 12, 5.0)  # > a half period
    check_markers(arrays[seen:], last, geometry, node)


def check_markers(arrays, shapes, geometry, node):
    """Each array: DELETEALL, then per mode the wireframe at rest on the geometry and the
    deformed one whose displacement is the mode's published shape (MAC >= 0.99 at the array
    of largest deflection)."""
    best = {k: (0.0, None) for k in shapes}
    rest = geometry.points[geometry.lines.reshape(-1)]
    for array in arrays:
        markers = array.markers
        assert markers[0].action == Marker.DELETEALL and markers[0].header.frame_id == 'mast'
        by = {(m.ns, m.id): m for m in markers[1:]}
        assert set(by) == {
            (ns, k) for k in shapes for ns in ('undeformed', 'deformed', 'sensors', 'label')
        }
        for k in shapes:
            still = np.array([(p.x, p.y, p.z) for p in by['undeformed', k].points])
            origin = still - rest
            assert np.allclose(origin, origin[0])  # the geometry, shifted as a whole
            moved = np.array([(p.x, p.y, p.z) for p in by['deformed', k].points]) - still
            size = float(np.abs(moved).max())
            if size > best[k][0]:
                best[k] = (size, moved)
            assert by['label', k].text.startswith(f'mode {k}\n')
    pairs = geometry.lines.reshape(-1)
    for k, shape in shapes.items():
        expected = geometry.displacements(shape, node.get_parameter('components').value)[pairs]
        assert best[k][1] is not None
        assert mac(best[k][1].ravel(), expected.ravel()) >= 0.99, (k, best[k], expected)


def test_a_geometry_that_does_not_place_a_channel_stops_the_start(ros_context, tmp_path):
    path = tmp_path / 'g.yaml'
    path.write_text(GEOMETRY.replace(f'  {AXES[2]}: {{point: p1, direction: x}}\n', ''))
    overrides = {
        'input_type': fields.IMU,
        'components': AXES,
        'excitation': 'ambient',
        'geometry_file': str(path),
    }
    with pytest.raises(StartupError, match='does not place channel.*linear_acceleration.z'):
        EstimatorNode(
            context=ros_context,
            parameter_overrides=[Parameter(k, value=v) for k, v in overrides.items()],
        )


def test_channels_changed_to_ones_the_geometry_does_not_place_stop_the_drawing(
    ros_context, node_with_geometry
):
    node, _ = node_with_geometry
    shapes = node._mode_shapes
    shapes.update(type('E', (), {'mode': 1, 'frequency_hz': 1.0, 'damping': 0.02})(), np.ones(3))
    assert shapes.markers.modes
    result = node.set_parameters([Parameter('components', value=['angular_velocity.x', AXES[1]])])
    assert result[0].successful
    assert not shapes.active and not shapes.markers.modes  # nothing stale is drawn
    result = node.set_parameters([Parameter('components', value=AXES[:2])])
    assert result[0].successful and shapes.active and shapes.markers.channels == tuple(AXES[:2])
