# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""``analyze --columns``: several CSV channels, one set of modes with their shapes."""

import json

import numpy as np
import pytest

from vib_estimator.cli import main
from vib_estimator.sim.frame import modal_record

MODES = [(1.0, 0.02, 1.0), (2.5, 0.02, 0.5)]
SHAPES = np.array([[1.0, 0.5], [0.6, -0.9], [0.2, 0.8]])
AMBIENT = ['--excitation', 'ambient', '--ambient-window-s', '40']


@pytest.fixture(scope='module')
def record(tmp_path_factory):
    t, y = modal_record(160.0, 20.0, MODES, SHAPES, snr_db=20.0, seed=4)
    path = tmp_path_factory.mktemp('channels') / 'three.csv'
    np.savetxt(path, np.column_stack((t, y)), delimiter=',', header='time,a,b,c', comments='')
    return path


def test_columns_all_gives_both_modes_with_their_shapes(record, capsys, tmp_path):
    plot = tmp_path / 'shapes.png'
    assert main(['analyze', str(record), '--columns', 'all', *AMBIENT, '--plot', str(plot)]) == 0
    out = capsys.readouterr()
    rows = [json.loads(line) for line in out.out.splitlines()]
    assert rows and {'shape_a', 'shape_phase_deg_c', 'shape_std_b', 'mac'} <= set(rows[0])
    for (f, _, _), shape in zip(MODES, SHAPES.T):
        near = [r for r in rows if abs(r['frequency_hz'] / f - 1) < 0.02]
        assert len(near) > 10
        got = np.median([[r[f'shape_{c}'] for c in 'abc'] for r in near], axis=0)
        unit = shape / np.linalg.norm(shape)
        unit *= np.sign(unit[np.argmax(np.abs(unit))])  # the largest entry positive
        assert np.allclose(got, unit, atol=0.1)
    assert 'channels=a,b,c' in out.err and 'shape: a ' in out.err
    assert plot.stat().st_size > 0


def test_csv_format_has_the_shape_columns(record, capsys):
    assert main(['analyze', str(record), '--columns', 'a,2', *AMBIENT, '--format', 'csv']) == 0
    header = capsys.readouterr().out.splitlines()[0].split(',')
    assert {'shape_a', 'shape_b', 'shape_std_a', 'mac'} <= set(header)
    assert 'shape_c' not in header


def test_one_column_is_exactly_column(record, capsys):
    assert main(['analyze', str(record), '--columns', 'b', *AMBIENT]) == 0
    one = capsys.readouterr().out
    assert main(['analyze', str(record), '--column', 'b', *AMBIENT]) == 0
    assert one == capsys.readouterr().out and one


@pytest.mark.parametrize(
    'options, message',
    [
        (['--columns', 'a,b'], 'need --excitation ambient'),
        (['--columns', 'a,x', *AMBIENT], "no column 'x'"),
        (['--columns', 'a,a', *AMBIENT], 'given twice'),
        (['--columns', 'a,b', '--column', 'c', *AMBIENT], 'not both'),
    ],
)
def test_bad_columns_are_one_error_line(record, capsys, options, message):
    assert main(['analyze', str(record), *options]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and 'error:' in err[0] and message in err[0]
