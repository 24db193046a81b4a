# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""``analyze --columns`` (CSV) and ``--components`` (bags): several channels, one set of modes
with their shapes."""

import json

import numpy as np
import pytest

from vib_estimator.cli import main
from vib_estimator.io.bags import write_channels
from vib_estimator.io.fields import IMU, JOINT_STATE, seconds_since
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
        (['--columns', 'a,b', '--excitation', 'auto'], 'need --excitation free or ambient'),
        (['--columns', 'a,x', *AMBIENT], "no column 'x'"),
        (['--columns', 'a,a', *AMBIENT], 'given twice'),
        (['--columns', 'a,b', '--column', 'c', *AMBIENT], 'not both'),
    ],
)
def test_bad_columns_are_one_error_line(record, capsys, options, message):
    assert main(['analyze', str(record), *options]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and 'error:' in err[0] and message in err[0]


# ---- bags: analyze BAG --components ------------------------------------------------------------
EPOCH_NS = 10**18
AXES = ['linear_acceleration.x', 'linear_acceleration.y', 'linear_acceleration.z']
JOINTS = ['effort[shoulder]', 'effort[elbow]', 'effort[wrist]']


@pytest.fixture(scope='module')
def bags(tmp_path_factory):
    """The same 80 s of three channels as an Imu bag, a JointState bag and a CSV file whose time
    column is the bags' time base (stamps since the first, as the node's)."""
    t, y = modal_record(80.0, 20.0, MODES, SHAPES, snr_db=20.0, seed=4)
    stamps = EPOCH_NS + np.round(t * 1e9).astype(np.int64)
    folder = tmp_path_factory.mktemp('channel_bags')
    write_channels(folder / 'imu', '/imu', IMU, AXES, stamps, y, 'tip')
    write_channels(folder / 'joints', '/joint_states', JOINT_STATE, JOINTS, stamps, y)
    csv = folder / 'same.csv'
    lines = [
        f'{s!r},{a!r},{b!r},{c!r}'
        for s, (a, b, c) in zip(seconds_since(stamps, stamps[0]).tolist(), y.tolist())
    ]
    csv.write_text('time,a,b,c\n' + '\n'.join(lines) + '\n')
    return folder


def renamed(row, names):
    """``row`` with the shape fields of channels ``names`` named as the CSV's a, b, c."""
    out = {}
    for key, value in row.items():
        for name, column in zip(names, 'abc'):
            if key.endswith('_' + name):
                key = key[: -len(name)] + column
        out[key] = value
    return out


def joint_rows(capsys, *argv):
    assert main(['analyze', *map(str, argv), *AMBIENT]) == 0
    out = capsys.readouterr()
    return [json.loads(line) for line in out.out.splitlines()], out.err


def test_components_of_a_bag_give_the_rows_of_the_same_csv_columns(bags, capsys):
    csv, _ = joint_rows(capsys, bags / 'same.csv', '--columns', 'all')
    assert len(csv) > 10  # (17-18: the 40 s window every 5 s once confirmed)
    for bag, names in ((bags / 'imu', AXES), (bags / 'joints', JOINTS)):
        rows, err = joint_rows(capsys, bag, '--components', ','.join(names))
        assert f'channels={",".join(names)}' in err and 'corrupt_records=0' in err
        assert [r.pop('stamp_ns') for r in rows] == [EPOCH_NS + round(r['t'] * 1e9) for r in rows]
        assert [renamed(r, names) for r in rows] == csv


def test_one_component_is_exactly_component(bags, capsys):
    one, _ = joint_rows(capsys, bags / 'imu', '--components', AXES[1])
    assert one == joint_rows(capsys, bags / 'imu', '--component', AXES[1])[0] and one


@pytest.mark.parametrize(
    'options, message',
    [
        (
            ['--components', ','.join(AXES[:2]), '--excitation', 'auto'],
            'need --excitation free or ambient',
        ),
        (['--components', 'linear_acceleration.x,torque.z', *AMBIENT], 'component of'),
        (['--components', 'linear_acceleration.x,,linear_acceleration.y', *AMBIENT], 'empty'),
        (['--components', ','.join(AXES), '--component', AXES[0], *AMBIENT], 'not both'),
        (['--columns', 'all', *AMBIENT], 'CSV files only'),
    ],
)
def test_bad_components_are_one_error_line(bags, capsys, options, message):
    assert main(['analyze', str(bags / 'imu'), *options]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and 'error:' in err[0] and message in err[0], err


def test_components_of_a_csv_file_are_refused(record, capsys):
    assert main(['analyze', str(record), '--components', 'a,b', *AMBIENT]) == 2
    assert '--components reads bags only' in capsys.readouterr().err


TOPICS = ['/joint1/wrench', '/joint2/wrench', '/joint3/wrench']


@pytest.fixture(scope='module')
def topic_bag(tmp_path_factory):
    """The channels of ``bags`` on three WrenchStamped topics of one bag (torque.z), a message of
    the second topic lost now and then, and a CSV file of the samples every topic has."""
    from vib_estimator.io.bags import BagWriter, channels_message
    from vib_estimator.io.fields import WRENCH_STAMPED

    t, y = modal_record(80.0, 20.0, MODES, SHAPES, snr_db=20.0, seed=4)
    stamps = EPOCH_NS + np.round(t * 1e9).astype(np.int64)
    lost = set(range(100, len(t), 97))
    folder = tmp_path_factory.mktemp('topic_bags')
    with BagWriter(folder / 'wrench') as bag:
        conns = [bag.add_topic(topic, WRENCH_STAMPED) for topic in TOPICS]
        for k, stamp in enumerate(stamps.tolist()):
            for i, conn in enumerate(conns):
                if not (i == 1 and k in lost):
                    msg = channels_message(WRENCH_STAMPED, stamp, '', ['torque.z'], [y[k, i]])
                    bag.write_message(conn, stamp, msg)
    keep = np.array([k not in lost for k in range(len(t))])
    csv = folder / 'kept.csv'
    kept = stamps[keep]
    lines = [
        f'{s!r},{a!r},{b!r},{c!r}'
        for s, (a, b, c) in zip(seconds_since(kept, kept[0]).tolist(), y[keep].tolist())
    ]
    csv.write_text('time,a,b,c\n' + '\n'.join(lines) + '\n')
    return folder, len(lost)


def test_several_topics_of_a_bag_are_aligned_by_stamp(topic_bag, capsys):
    """``--topics``: the fields of three topics joined by stamp give the rows of the CSV file of
    the samples every topic has; each lost message costs its stamp (counted)."""
    folder, lost = topic_bag
    csv, _ = joint_rows(capsys, folder / 'kept.csv', '--columns', 'all')
    assert len(csv) > 10  # (17-18: the 40 s window every 5 s once confirmed)
    rows, err = joint_rows(
        capsys, folder / 'wrench', '--topics', ','.join(TOPICS), '--component', 'torque.z'
    )
    names = [f'{topic}:torque.z' for topic in TOPICS]
    assert f'channels={",".join(names)}' in err
    assert f'dropped_unaligned={2 * lost}' in err and 'dropped_stalled=0' in err
    assert [r.pop('stamp_ns') for r in rows] == [EPOCH_NS + round(r['t'] * 1e9) for r in rows]
    assert [renamed(r, names) for r in rows] == csv


@pytest.mark.parametrize(
    'options, message',
    [
        (['--topics', ','.join(TOPICS), '--topic', TOPICS[0]], 'not both'),
        (['--topics', f'{TOPICS[0]},{TOPICS[0]}'], 'twice'),
        (['--topics', f'{TOPICS[0]},/nope'], "no topic '/nope'"),
        (['--topics', ','.join(TOPICS), '--excitation', 'auto'], 'need --excitation free'),
    ],
)
def test_bad_topics_are_one_error_line(topic_bag, capsys, options, message):
    assert main(['analyze', str(topic_bag[0] / 'wrench'), *options]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and 'error:' in err[0] and message in err[0], err
