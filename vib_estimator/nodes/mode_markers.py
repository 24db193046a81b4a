# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""The markers of ``vibration/mode_shapes`` (RViz): each published mode's shape on the structure's
geometry, animated (no rclpy: :class:`MarkerSpec` is what the node turns into
``visualization_msgs/Marker``).

Per publication, in order: a ``DELETEALL`` (RViz forgets markers of modes no longer shown), then
per mode k (ids = k in every namespace, so a marker is replaced, not accumulated):

* ``undeformed``: the wireframe at rest, grey (``LINE_LIST``);
* ``deformed``: the wireframe displaced by the mode's shape at the animation's phase
  ``2 pi t / period_s``, each vertex coloured by its amplitude (blue: still, red: the largest);
* ``sensors``: the channels' points, displaced (``SPHERE_LIST``);
* ``label``: ``mode k`` and ``f Hz, ζ`` (two lines) above it (``TEXT_VIEW_FACING``).

Mode k is drawn beside mode 1, shifted along x by (k - 1) x :data:`SPACING` x the structure's
extent, its largest displacement ``scale`` x that extent. A shape moves each channel's points
along its direction (:meth:`..io.geometry.Geometry.displacements`): one channel's shape is 1.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Optional, Sequence

import numpy as np

from ..io.geometry import Geometry

#: the node's parameters of the markers and their defaults
DEFAULTS = {
    'geometry_file': '',
    'frame_id': 'world',
    'mode_shapes_rate_hz': 10.0,
    'mode_shapes_scale': 0.1,
    'mode_shapes_period_s': 2.0,
}
#: modes side by side: mode k's origin is (k - 1) x this x the structure's extent along x
SPACING = 2.0
#: line width and sensor size, fractions of the structure's extent
LINE_WIDTH = 0.006
SENSOR_SIZE = 0.02
#: the label's height, a fraction of the extent, and its place above the structure
TEXT_SIZE = 0.04
GREY = (0.6, 0.6, 0.6, 0.8)
WHITE = (1.0, 1.0, 1.0, 1.0)


@dataclass(frozen=True)
class MarkerSpec:
    """One marker: its namespace and id, ``kind`` (``delete_all``, ``line_list``,
    ``sphere_list``, ``text``), ``points`` (N x 3, m), per-point ``colours`` (N x 4, RGBA in
    [0, 1]) or one ``colour``, ``scale`` (x, y, z as RViz reads them), ``text`` and its
    ``position``."""

    ns: str
    id: int
    kind: str
    points: np.ndarray = field(default_factory=lambda: np.empty((0, 3)))
    colours: Optional[np.ndarray] = None
    colour: tuple = WHITE
    scale: tuple = (1.0, 1.0, 1.0)
    text: str = ''
    position: tuple = (0.0, 0.0, 0.0)


def amplitude_colours(amplitude: np.ndarray) -> np.ndarray:
    """RGBA per point: blue where ``amplitude`` is 0, red where it is the largest."""
    a = np.asarray(amplitude, dtype=float)
    a = a / a.max() if a.size and a.max() > 0 else np.zeros_like(a)
    return np.column_stack((a, 0.25 * np.ones_like(a), 1.0 - a, np.ones_like(a)))


class ModeShapeMarkers:
    """The latest shape of each mode and the markers that draw them (see the module doc)."""

    def __init__(self, geometry: Geometry, channels: Sequence[str], scale: float, period_s: float):
        geometry.check_channels(channels)
        self.geometry = geometry
        self.channels = tuple(channels)
        self.scale = scale
        self.period_s = period_s
        #: mode -> (frequency Hz, damping ratio, complex shape, one entry per channel)
        self.modes: dict[int, tuple[float, float, np.ndarray]] = {}

    def update(self, mode: int, frequency_hz: float, damping: float, shape=None) -> None:
        """A new estimate of ``mode`` (its ``shape`` None: one channel, the shape 1)."""
        shape = np.ones(len(self.channels)) if shape is None else np.asarray(shape)
        self.modes[max(1, int(mode))] = (float(frequency_hz), float(damping), shape)

    def origin(self, mode: int) -> np.ndarray:
        """Where mode ``mode``'s drawing is shifted to."""
        extent = max(float(np.ptp(self.geometry.points[:, 0])), 0.5 * self.geometry.size)
        return np.array([(mode - 1) * SPACING * extent, 0.0, 0.0])

    def deformed(self, mode: int, t: float) -> tuple[np.ndarray, np.ndarray]:
        """(the points of ``mode``'s drawing at time ``t``, s: rest + the displacement at the
        animation's phase; each point's amplitude, m), shifted by :meth:`origin`."""
        _, _, shape = self.modes[mode]
        disp = self.geometry.displacements(shape, self.channels)
        amp = np.linalg.norm(np.abs(disp), axis=1)
        peak = float(amp.max()) if amp.size else 0.0
        gain = self.scale * self.geometry.size / peak if peak > 0 else 0.0
        phase = np.exp(2j * math.pi * t / self.period_s)
        moved = self.geometry.points + gain * (disp * phase).real
        return moved + self.origin(mode), gain * amp

    def markers(self, t: float) -> list[MarkerSpec]:
        """The markers at time ``t`` (s, any origin): ``DELETEALL`` first, then each mode's."""
        g = self.geometry
        size = g.size
        pairs = g.lines.reshape(-1)
        out = [MarkerSpec('', 0, 'delete_all')]
        for k in sorted(self.modes):
            f, zeta, _ = self.modes[k]
            points, amp = self.deformed(k, t)
            rest = g.points + self.origin(k)
            width = (LINE_WIDTH * size,) * 3
            sensors = sorted({p for pts in g.channel_points for p in pts})
            zeta_text = f'ζ {zeta:.4f}' if math.isfinite(zeta) else 'ζ not estimated'
            top = rest.max(axis=0) if len(rest) else np.zeros(3)
            out += [
                MarkerSpec('undeformed', k, 'line_list', rest[pairs], colour=GREY, scale=width),
                MarkerSpec(
                    'deformed',
                    k,
                    'line_list',
                    points[pairs],
                    amplitude_colours(amp[pairs]),
                    scale=(2 * LINE_WIDTH * size,) * 3,
                ),
                MarkerSpec(
                    'sensors',
                    k,
                    'sphere_list',
                    points[sensors],
                    amplitude_colours(amp[sensors]),
                    scale=(SENSOR_SIZE * size,) * 3,
                ),
                MarkerSpec(
                    'label',
                    k,
                    'text',
                    text=f'mode {k}\n{f:.4g} Hz, {zeta_text}',
                    scale=(0.0, 0.0, TEXT_SIZE * size),
                    position=(
                        float(rest[:, 0].mean()),
                        float(rest[:, 1].mean()),
                        float(top[2] + 0.12 * size),
                    ),
                ),
            ]
        return out
