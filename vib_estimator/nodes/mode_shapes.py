# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""``estimator_node``'s ``vibration/mode_shapes`` (visualization_msgs/MarkerArray, for RViz): with
a ``geometry_file``, each published mode's shape on the structure, animated (the markers:
:mod:`.mode_markers`; this module declares the parameters and converts).

Parameters (read-only): ``geometry_file`` (docs/geometry.md; '' = off, no topic), ``frame_id``
(of the markers), ``mode_shapes_rate_hz`` (publications a second, steady clock),
``mode_shapes_scale`` (the largest displacement drawn, a fraction of the structure's extent),
``mode_shapes_period_s`` (one cycle of the animation; the modes move slowed down or sped up to
it). A geometry that cannot be read, or that does not place every channel, stops the start
(one ``error:`` line).
"""

from __future__ import annotations

import time
from typing import Optional

from builtin_interfaces.msg import Duration
from geometry_msgs.msg import Point
from rclpy.clock import Clock, ClockType
from rclpy.node import Node
from std_msgs.msg import ColorRGBA, Header
from visualization_msgs.msg import Marker, MarkerArray

from ..errors import GeometryError, StartupError
from ..io.geometry import load_geometry
from .mode_markers import DEFAULTS, MarkerSpec, ModeShapeMarkers
from .parameters import declare, descriptor

#: the Marker type and action of each MarkerSpec kind
KINDS = {
    'line_list': (Marker.LINE_LIST, Marker.ADD),
    'sphere_list': (Marker.SPHERE_LIST, Marker.ADD),
    'text': (Marker.TEXT_VIEW_FACING, Marker.ADD),
    'delete_all': (Marker.ARROW, Marker.DELETEALL),
}
#: the parameters' descriptions and ranges
DESCRIPTIONS = {
    'geometry_file': (
        'a geometry file (points, channels, lines: docs/geometry.md) placing every channel: '
        "vibration/mode_shapes draws each mode's shape on it for RViz ('' = off)",
        None,
    ),
    'frame_id': ('frame_id of the vibration/mode_shapes markers', None),
    'mode_shapes_rate_hz': ('vibration/mode_shapes publications a second', (0.1, 60.0)),
    'mode_shapes_scale': (
        'the largest displacement drawn, a fraction of the structure extent',
        (0.0, 10.0),
    ),
    'mode_shapes_period_s': ('one cycle of the mode shape animation, s', (0.1, 60.0)),
}


def marker_message(spec: MarkerSpec, header) -> Marker:
    """The visualization_msgs/Marker of ``spec`` (lifetime 0: kept until replaced)."""
    kind, action = KINDS[spec.kind]
    m = Marker(header=header, ns=spec.ns, id=spec.id, type=kind, action=action)
    m.pose.orientation.w = 1.0
    m.lifetime = Duration()
    if action == Marker.DELETEALL:
        return m
    m.scale.x, m.scale.y, m.scale.z = (float(v) for v in spec.scale)
    m.color = ColorRGBA(r=spec.colour[0], g=spec.colour[1], b=spec.colour[2], a=spec.colour[3])
    m.points = [Point(x=float(x), y=float(y), z=float(z)) for x, y, z in spec.points]
    if spec.colours is not None:
        m.colors = [ColorRGBA(r=c[0], g=c[1], b=c[2], a=c[3]) for c in spec.colours.tolist()]
    if spec.kind == 'text':
        m.text = spec.text
        m.pose.position.x, m.pose.position.y, m.pose.position.z = spec.position
    return m


class ModeShapesPublisher:
    """``vibration/mode_shapes`` of a node: the latest shape of each mode, published on a timer."""

    def __init__(self, node: Node, markers: ModeShapeMarkers, frame_id: str, rate_hz: float):
        self._node = node
        self.markers = markers
        self._frame_id = frame_id
        #: false while the channels are ones the geometry does not place
        self.active = True
        self._pub = node.create_publisher(MarkerArray, 'vibration/mode_shapes', 10)
        steady = Clock(clock_type=ClockType.STEADY_TIME)
        node.create_timer(1.0 / rate_hz, self.publish, clock=steady)

    @staticmethod
    def declare(node: Node) -> dict:
        """Declare the parameters (before the params-file check); their values."""
        return {
            name: declare(node, name, default, descriptor(*DESCRIPTIONS[name], read_only=True))
            for name, default in DEFAULTS.items()
        }

    @classmethod
    def create(cls, node: Node, values: dict, channels) -> Optional['ModeShapesPublisher']:
        """With a ``geometry_file`` among the parameter ``values``, the publisher (StartupError
        for a geometry that cannot be read or does not place ``channels``); else None."""
        if not values['geometry_file']:
            return None
        try:
            markers = ModeShapeMarkers(
                load_geometry(values['geometry_file']),
                channels,
                values['mode_shapes_scale'],
                values['mode_shapes_period_s'],
            )
        except GeometryError as err:
            raise StartupError(str(err)) from None
        return cls(node, markers, values['frame_id'], values['mode_shapes_rate_hz'])

    def set_channels(self, channels) -> None:
        """The channels changed (a parameter): the shapes drawn so far are dropped; channels the
        geometry does not place stop the drawing (logged)."""
        self.markers.modes.clear()
        try:
            self.markers = ModeShapeMarkers(
                self.markers.geometry, channels, self.markers.scale, self.markers.period_s
            )
            self.active = True
        except GeometryError as err:
            self._node.get_logger().warn(f'vibration/mode_shapes stops: {err}')
            self.active = False

    def update(self, estimate, shape=None) -> None:
        """A published estimate (and its complex shape, several channels)."""
        if self.active:
            self.markers.update(estimate.mode, estimate.frequency_hz, estimate.damping, shape)

    def publish(self) -> None:
        """One MarkerArray: DELETEALL, then each mode's markers at the animation's phase."""
        if not self.markers.modes:
            return
        header = Header(stamp=self._node.get_clock().now().to_msg(), frame_id=self._frame_id)
        specs = self.markers.markers(time.monotonic())
        self._pub.publish(MarkerArray(markers=[marker_message(s, header) for s in specs]))
