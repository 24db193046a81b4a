# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""With no option, ``analyze`` and ``survey`` decide each record's excitation and window from
the record (analysis.choosing over core.choice): a free decay gives exactly ``--excitation
free``'s output, a driven record the identifier's modes; ``--paper`` and ``--excitation`` are
never overridden."""

import json

import numpy as np
import pytest

from vib_estimator.cli import main
from vib_estimator.sim.ambient import ambient_record
from vib_estimator.sim.frame import frame_record


def write(path, t, y, names=None):
    y = np.asarray(y).reshape(len(t), -1)
    names = names or [f'ch{i + 1}' for i in range(y.shape[1])]
    np.savetxt(
        path, np.column_stack([t, y]), delimiter=',', header=','.join(['t', *names]), comments=''
    )
    return path


def analyze(capsys, *args):
    assert main(['analyze', *map(str, args)]) == 0
    out, err = capsys.readouterr()
    return [json.loads(line) for line in out.splitlines()], err


@pytest.fixture
def free_decay(tmp_path):
    t = np.arange(0, 10, 0.002)
    y = np.exp(-0.01 * 2 * np.pi * 5 * t) * np.sin(2 * np.pi * 5 * t)
    y += 0.01 * np.random.default_rng(0).standard_normal(len(t))
    return write(tmp_path / 'decay.csv', t, y)


@pytest.fixture
def driven(tmp_path):
    t, y, _ = ambient_record(120, 200, [(2.0, 0.01, 1.0), (7.0, 0.01, 0.5)], 20, 1)
    return write(tmp_path / 'driven.csv', t, y)


def test_a_free_decay_gives_exactly_the_free_estimator_s_output(capsys, free_decay):
    rows, err = analyze(capsys, free_decay)
    assert 'analyze: excitation free (the default decides from the record' in err
    free, err_free = analyze(capsys, free_decay, '--excitation', 'free')
    assert rows == free and len(rows) > 10
    assert 'decides from the record' not in err_free


def test_a_driven_record_gets_the_identifier_and_its_modes(capsys, driven):
    rows, err = analyze(capsys, driven)
    assert 'analyze: excitation ambient (the default decides from the record' in err
    assert 'window 60 s (120 periods of 2 Hz)' in err
    f = np.array([r['frequency_hz'] for r in rows])
    for true in (2.0, 7.0):
        near = np.abs(f / true - 1) <= 0.02
        assert near.sum() > 20
    assert np.all(np.min(np.abs(f[:, None] / [2.0, 7.0] - 1), axis=1) <= 0.05)
    # the summary is per mode; the window option keeps its value
    assert 'mode 1: f = 2.0' in err and 'mode 2: f = 7.0' in err
    _, err = analyze(capsys, driven, '--ambient-window-s', '40')
    assert 'excitation ambient' in err
    rows_free, err = analyze(capsys, driven, '--excitation', 'free')
    assert 'decides' not in err and all(r['mode'] == 0 for r in rows_free)
    _, err = analyze(capsys, driven, '--paper')
    assert 'decides' not in err


def test_several_channels_of_a_driven_frame_get_the_joint_identifier(capsys, tmp_path):
    t, y, freqs, _ = frame_record(240, 40, seed=2)
    rows, err = analyze(capsys, write(tmp_path / 'frame.csv', t, y), '--columns', 'all')
    assert 'excitation ambient' in err and 'shape_ch5' in rows[0]
    f = np.array([r['frequency_hz'] for r in rows])
    found = [np.any(np.abs(f / true - 1) <= 0.01) for true in freqs]
    assert sum(found) >= 4


def test_survey_decides_each_recording(capsys, tmp_path, free_decay, driven):
    assert main(['survey', str(free_decay), str(driven), '--format', 'jsonl']) == 0
    rows = [json.loads(line) for line in capsys.readouterr().out.splitlines()]
    by = {}
    for r in rows:
        by.setdefault(r['recording'].rsplit('/', 1)[-1], []).append(r)
    assert [r['mode'] for r in by['decay.csv']] == [0]
    assert sorted(r['mode'] for r in by['driven.csv']) == [1, 2]
