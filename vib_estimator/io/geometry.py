# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""Geometry files: where the sensors are, so that a mode shape can be drawn on the structure
(``analyze --report --geometry``, ``estimator_node``'s ``geometry_file``; docs/geometry.md).

A small YAML mapping (pure: no rclpy)::

    name: five-storey shear frame          # optional, shown in titles
    points:                                # name: [x, y, z], metres
      base_l: [0.0, 0.0, 0.0]
      f1_l: [0.0, 0.0, 3.0]
    channels:                              # the record's channel name: where and which way
      s1: {point: f1_l, direction: x}      # direction: x, -y, z ... or [dx, dy, dz]
      s2: {point: [f2_l, f2_r], direction: [1, 0, 0]}   # several points moving together
    lines:                                 # optional: point pairs drawn as the wireframe
      - [base_l, f1_l]
    fixed: [base_l]                        # optional: points that do not move (supports)

A channel's value moves each of its points along its (unit) direction; a point with several
channels (e.g. an x and a y sensor) moves by their sum; a point without a channel does not move.
Unknown keys, missing points, a zero direction and the like are one :class:`GeometryError`
sentence naming the file and the entry.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Sequence

import numpy as np

from ..errors import GeometryError

#: the keys of a geometry file (``points`` and ``channels`` required)
KEYS = ('name', 'points', 'channels', 'lines', 'fixed')
#: the keys of a channel entry (both required)
CHANNEL_KEYS = ('point', 'direction')
#: the named directions a channel may give
AXES = {'x': (1.0, 0.0, 0.0), 'y': (0.0, 1.0, 0.0), 'z': (0.0, 0.0, 1.0)}


@dataclass(frozen=True)
class Geometry:
    """A loaded geometry: ``points`` (P x 3, m) named ``point_names``; per channel (in
    ``channels`` order) the indices of its points and its unit ``directions`` (C x 3); ``lines``
    (L x 2 point indices); ``fixed`` point indices; ``name`` and the ``path`` read."""

    name: str
    path: str
    point_names: tuple[str, ...]
    points: np.ndarray
    channels: tuple[str, ...]
    channel_points: tuple[tuple[int, ...], ...]
    directions: np.ndarray
    lines: np.ndarray
    fixed: tuple[int, ...]

    @property
    def size(self) -> float:
        """The structure's extent (the diagonal of its bounding box, m; 1 for a single point)."""
        span = float(np.linalg.norm(np.ptp(self.points, axis=0)))
        return span if span > 0 else 1.0

    def displacements(self, values: Sequence, channels: Sequence[str]) -> np.ndarray:
        """The points' displacements (P x 3, real or complex as ``values``) for one value per
        channel of ``channels`` (the record's order; each must be in the geometry)."""
        values = np.asarray(values)
        out = np.zeros((len(self.points), 3), dtype=np.result_type(values, float))
        index = {name: i for i, name in enumerate(self.channels)}
        for name, value in zip(channels, values):
            i = index[name]
            for p in self.channel_points[i]:
                out[p] += value * self.directions[i]
        return out

    def check_channels(self, channels: Sequence[str]) -> None:
        """GeometryError unless every one of the record's ``channels`` is placed here."""
        missing = [c for c in channels if c not in self.channels]
        if missing:
            raise GeometryError(
                f'geometry {self.path} does not place channel(s) {", ".join(missing)} of the '
                f'record (it places {", ".join(self.channels)}): add them under channels:'
            )


def _where(path, what: str) -> str:
    return f'geometry {path}: {what}'


def _vector(path, what: str, value) -> np.ndarray:
    """Three finite numbers (GeometryError naming ``what`` otherwise)."""
    ok = isinstance(value, (list, tuple)) and len(value) == 3
    ok = ok and all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in value)
    if not ok or not all(math.isfinite(v) for v in value):
        raise GeometryError(
            _where(path, f'{what} must be [x, y, z] (three numbers), got {value!r}')
        )
    return np.array(value, dtype=float)


def _direction(path, name: str, value) -> np.ndarray:
    """A channel's unit direction from ``x``, ``-y`` ... or three numbers."""
    if isinstance(value, str):
        axis = value.strip().lower()
        sign = -1.0 if axis.startswith('-') else 1.0
        if axis.lstrip('+-') not in AXES:
            raise GeometryError(
                _where(path, f'channel {name}: direction {value!r} is not x, y, z, -x, -y, -z')
            )
        return sign * np.array(AXES[axis.lstrip('+-')])
    v = _vector(path, f'channel {name}: direction', value)
    norm = float(np.linalg.norm(v))
    if norm == 0.0:
        raise GeometryError(_where(path, f'channel {name}: direction [0, 0, 0] has no direction'))
    return v / norm


def _point_refs(path, what: str, value, index: dict) -> tuple[int, ...]:
    """The indices of one point name or a list of them (names compared as text: ``1`` and
    ``'1'`` are one point)."""
    names = value if isinstance(value, list) else [value]
    if not names or any(isinstance(n, (list, dict)) or n is None for n in names):
        raise GeometryError(_where(path, f'{what} must be a point name or a list of them'))
    names = [str(n) for n in names]
    unknown = [n for n in names if n not in index]
    if unknown:
        raise GeometryError(
            _where(path, f'{what} names unknown point(s) {", ".join(unknown)} (not under points:)')
        )
    return tuple(index[n] for n in names)


def _mapping(path, data, key: str) -> dict:
    value = data.get(key)
    if not isinstance(value, dict) or not value:
        raise GeometryError(_where(path, f'{key}: must be a non-empty mapping'))
    return value


def _channels(path, data, index: dict):
    names, points, directions = [], [], []
    for name, entry in _mapping(path, data, 'channels').items():
        if not isinstance(entry, dict) or set(entry) != set(CHANNEL_KEYS):
            raise GeometryError(
                _where(
                    path, f'channel {name}: give {{point: NAME, direction: x|y|z|[dx, dy, dz]}}'
                )
            )
        names.append(str(name))
        points.append(_point_refs(path, f'channel {name}: point', entry['point'], index))
        directions.append(_direction(path, name, entry['direction']))
    return tuple(names), tuple(points), np.array(directions)


def _lines(path, data, index: dict) -> np.ndarray:
    lines = data.get('lines') or []
    if not isinstance(lines, list):
        raise GeometryError(_where(path, 'lines: must be a list of [point, point] pairs'))
    out = []
    for i, pair in enumerate(lines):
        if not isinstance(pair, list) or len(pair) != 2:
            raise GeometryError(_where(path, f'line {i + 1} must be [point, point], got {pair!r}'))
        out.append(_point_refs(path, f'line {i + 1}', pair, index))
    return np.array(out, dtype=int).reshape(-1, 2)


def parse_geometry(data, path: str = '<geometry>') -> Geometry:
    """The :class:`Geometry` of a file's loaded YAML ``data`` (GeometryError if invalid)."""
    if not isinstance(data, dict):
        raise GeometryError(_where(path, 'must be a mapping with points: and channels:'))
    unknown = sorted(str(k) for k in data if k not in KEYS)
    if unknown:
        raise GeometryError(
            _where(path, f'unknown key(s) {", ".join(unknown)} (known: {", ".join(KEYS)})')
        )
    raw = _mapping(path, data, 'points')
    names = tuple(str(n) for n in raw)
    points = np.array([_vector(path, f'point {n}', raw[n]) for n in raw]).reshape(-1, 3)
    index = {str(n): i for i, n in enumerate(raw)}
    channels, channel_points, directions = _channels(path, data, index)
    fixed = data.get('fixed') or []
    fixed = _point_refs(path, 'fixed', fixed, index) if fixed else ()
    return Geometry(
        str(data.get('name') or Path(path).stem),
        str(path),
        names,
        points,
        channels,
        channel_points,
        directions,
        _lines(path, data, index),
        fixed,
    )


def load_geometry(path) -> Geometry:
    """Read and check a geometry file (GeometryError: unreadable, not YAML, or invalid)."""
    import yaml

    try:
        text = Path(path).read_text()
    except OSError as err:
        raise GeometryError(f'geometry {path}: cannot read ({err.strerror or err})') from None
    try:
        data = yaml.safe_load(text)
    except yaml.YAMLError as err:
        mark = getattr(err, 'problem_mark', None)
        where = f' at line {mark.line + 1}' if mark is not None else ''
        raise GeometryError(f'geometry {path}: not valid YAML{where}') from None
    return parse_geometry(data, str(path))
