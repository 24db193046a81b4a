# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""Geometry files (io/geometry.py): the shipped examples load, a shape moves the right points,
bad files are one GeometryError sentence naming the file and the entry."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from vib_estimator.errors import GeometryError
from vib_estimator.io.geometry import load_geometry, parse_geometry

GEOMETRIES = Path(__file__).resolve().parents[2] / 'config' / 'geometry'

GOOD = {
    'points': {'a': [0, 0, 0], 'b': [1, 0, 0], 'c': [1, 1, 0]},
    'channels': {
        'u': {'point': 'b', 'direction': 'y'},
        'v': {'point': ['b', 'c'], 'direction': [0, 0, 2]},
    },
    'lines': [['a', 'b'], ['b', 'c']],
    'fixed': ['a'],
}


def test_shipped_geometries_load_and_place_their_channels():
    names = {p.stem: load_geometry(p) for p in GEOMETRIES.glob('*.yaml')}
    assert set(names) >= {'shear_frame', 'arm', 'hct_setup1'}
    assert names['shear_frame'].channels == ('s1', 's2', 's3', 's4', 's5')
    assert names['hct_setup1'].channels == tuple(f'ch{k}' for k in range(1, 7))
    for g in names.values():
        assert len(g.lines) and g.fixed and np.allclose(np.linalg.norm(g.directions, axis=1), 1)


def test_displacements_move_each_channels_points_along_its_direction():
    g = parse_geometry(GOOD, 'good.yaml')
    d = g.displacements([2.0, 0.5], ('u', 'v'))
    assert np.allclose(d, [[0, 0, 0], [0, 2.0, 0.5], [0, 0, 0.5]])
    # the record's order, not the file's
    assert np.allclose(g.displacements([0.5, 2.0], ('v', 'u')), d)
    g.check_channels(('u',))
    with pytest.raises(GeometryError, match='does not place channel.*w'):
        g.check_channels(('u', 'w'))


def _bad(**change):
    data = {**GOOD, **change}
    return {k: v for k, v in data.items() if v is not None}


@pytest.mark.parametrize(
    'data, message',
    [
        ([1, 2], 'must be a mapping'),
        (_bad(colour='red'), 'unknown key.*colour'),
        (_bad(points=None), 'points: must be a non-empty mapping'),
        (_bad(points={'a': [0, 0]}), r'point a must be \[x, y, z\]'),
        (_bad(points={'a': [0, 0, float('nan')]}), r'point a must be \[x, y, z\]'),
        (_bad(channels={'u': {'point': 'z', 'direction': 'x'}}), 'unknown point.*z'),
        (_bad(channels={'u': {'point': 'a', 'direction': 'w'}}), "direction 'w' is not"),
        (_bad(channels={'u': {'point': 'a', 'direction': [0, 0, 0]}}), 'has no direction'),
        (_bad(channels={'u': {'point': 'a'}}), 'channel u: give'),
        (_bad(lines=[['a']]), r'line 1 must be \[point, point\]'),
        (_bad(lines=[['a', 'q']]), 'line 1 names unknown point.*q'),
        (_bad(fixed=['q']), 'fixed names unknown point.*q'),
    ],
)
def test_bad_geometry_is_one_sentence_naming_the_entry(data, message):
    with pytest.raises(GeometryError, match=message) as info:
        parse_geometry(data, 'bad.yaml')
    assert str(info.value).startswith('geometry bad.yaml: ') and '\n' not in str(info.value)


def test_unreadable_or_not_yaml_files(tmp_path):
    with pytest.raises(GeometryError, match='cannot read'):
        load_geometry(tmp_path / 'missing.yaml')
    bad = tmp_path / 'bad.yaml'
    bad.write_text('points: {a: [0, 0, 0]\nchannels: [')
    with pytest.raises(GeometryError, match='not valid YAML at line'):
        load_geometry(bad)


def test_numbered_points_and_channels_are_names_as_text():
    """pyOMA2-style numbering: points 1, 2, channels 1, 2 (YAML integers) work as names."""
    g = parse_geometry(
        {
            'points': {1: [0, 0, 0], 2: [0, 0, 1]},
            'channels': {1: {'point': 2, 'direction': 'X'}, 2: {'point': [2], 'direction': '+y'}},
            'lines': [[1, 2]],
            'fixed': [1],
        }
    )
    assert g.channels == ('1', '2') and g.fixed == (0,) and g.lines.tolist() == [[0, 1]]
    assert np.allclose(g.displacements([1.0, 2.0], ('1', '2')), [[0, 0, 0], [1.0, 2.0, 0]])
