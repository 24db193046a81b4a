# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""``survey --columns`` (CSV) and ``--components`` (bags): a joint identification per recording,
its modes' median shapes, and the alarm against a baseline."""

import json

import numpy as np
import pytest

from vib_estimator.analysis import survey as S
from vib_estimator.cli import main
from vib_estimator.core import EstimatorConfig
from vib_estimator.extras import WARNING
from vib_estimator.io.bags import WrenchSeries, write_channels, write_wrench_series
from vib_estimator.io.fields import IMU
from vib_estimator.sim.frame import modal_record

MODES = [(1.0, 0.02, 1.0), (2.5, 0.02, 0.5)]
SHAPES = np.array([[1.0, 0.5], [0.6, -0.9], [0.2, 0.8]])
#: the changed recording's frequencies: a stiffness loss of ~19 %
CHANGED = 0.9
AMBIENT = ['--excitation', 'ambient', '--ambient-window-s', '40']
#: the median summary: these 80 s records hold two windows' worth of independent estimates, too
#: few for the weighted interval to resolve a 10 % change
ALARM = ['--summary', 'median', '--alarm-rel', '0.02']
EPOCH_NS = 1_767_225_600 * 10**9
DAY_NS = 86_400 * 10**9
AXES = ['linear_acceleration.x', 'linear_acceleration.y', 'linear_acceleration.z']


def record(day, scale=1.0, shapes=SHAPES):
    return modal_record(
        80.0, 20.0, [(f * scale, z, v) for f, z, v in MODES], shapes, snr_db=20.0, seed=day
    )


def write_csv(path, t, y):
    np.savetxt(path, np.column_stack((t, y)), delimiter=',', header='time,a,b,c', comments='')


def unit_shapes():
    """The exact shapes, unit length, largest entry positive (as the estimates')."""
    out = SHAPES / np.linalg.norm(SHAPES, axis=0)
    return (out * np.sign(out[np.argmax(np.abs(out), axis=0), range(len(MODES))])).T


@pytest.fixture(scope='module')
def csv_fleet(tmp_path_factory):
    """Three days of three channels a, b, c: the baseline, the same structure, a changed one."""
    folder = tmp_path_factory.mktemp('csv_fleet')
    for day, scale in enumerate((1.0, 1.0, CHANGED)):
        write_csv(folder / f'day{day}.csv', *record(day, scale))
    return sorted(folder.glob('day*.csv'))


def survey_rows(capsys, *argv):
    code = main(['survey', *map(str, argv), '--format', 'jsonl', '--jobs', '1'])
    out = capsys.readouterr()
    return code, [json.loads(line) for line in out.out.splitlines()], out.err


def check_modes(rows, names, scale):
    """Both modes, their frequencies, median shapes and MACs."""
    assert [r['mode'] for r in rows] == [1, 2]
    for row, (f, _, _), shape in zip(rows, MODES, unit_shapes()):
        assert not row['error'] and row['estimates'] >= 6  # (9: every 5 s once confirmed)
        assert abs(row['frequency_hz'] / (f * scale) - 1) < 0.02
        got = [row[f'shape_{n}'] for n in names]
        assert np.allclose(got, shape, atol=0.1), (got, shape)
        assert all(0 < row[f'shape_std_{n}'] < 0.2 for n in names)
        assert row['mac'] > 0.95


def test_columns_all_gives_the_modes_with_their_shapes_and_the_changed_day_alarms(
    csv_fleet, capsys, tmp_path
):
    base, same, changed = csv_fleet
    moved = tmp_path / 'moved.csv'  # the same frequencies, the sensors a and c swapped
    write_csv(moved, *record(3, shapes=SHAPES[::-1]))
    code, rows, err = survey_rows(
        capsys, same, changed, moved, '--columns', 'all', '--baseline', base, *AMBIENT, *ALARM
    )
    # nothing on stderr but, without pyarrow (Ubuntu 24.04's numpy 1.26), its one warning line
    assert code == 0 and [ln for ln in err.splitlines() if not ln.startswith(WARNING)] == []
    assert {r['component'] for r in rows} == {'a,b,c'} and {r['topic'] for r in rows} == {''}
    by_day = {n: [r for r in rows if r['recording'] == str(n)] for n in (same, changed, moved)}
    check_modes(by_day[same], 'abc', 1.0)
    check_modes(by_day[changed], 'abc', CHANGED)
    assert not any(r['alarm'] for r in by_day[same])
    assert all(r['alarm'] for r in by_day[changed])
    for row in by_day[changed]:
        assert abs(row['change_rel'] - (CHANGED - 1)) < 0.02
    assert all(r['mac_to_baseline'] > 0.95 for r in by_day[same] + by_day[changed])
    check_modes(by_day[moved], 'cba', 1.0)
    assert not any(r['alarm'] for r in by_day[moved])  # the alarm is the frequency's
    # the exact shapes' MAC with the mirrored ones: 0.29 and 0.90
    macs = [r['mac_to_baseline'] for r in by_day[moved]]
    assert macs[0] < 0.4 and macs[1] < 0.93, macs


def test_one_column_is_exactly_column(csv_fleet, capsys):
    argv = ['survey', str(csv_fleet[0]), *AMBIENT, '--jobs', '1', '--format', 'csv']
    assert main([*argv, '--columns', 'b']) == 0
    one = capsys.readouterr().out
    assert main([*argv, '--column', 'b']) == 0
    assert one == capsys.readouterr().out and 'shape' not in one


def test_parallel_jobs_give_the_same_rows_and_files_hold_the_shape_columns(csv_fleet, tmp_path):
    options = S.Options(
        EstimatorConfig(excitation='ambient', ambient_window_s=40.0), columns='a,c'
    )
    local = S.survey(csv_fleet, options, jobs=1)
    assert json.dumps(S.survey(csv_fleet, options, jobs=2)) == json.dumps(local)
    assert {r['component'] for r in local} == {'a,c'} and 'shape_b' not in local[0]
    out = tmp_path / 'rows.csv'
    S.write_file(local, out)
    header = out.read_text().splitlines()[0].split(',')
    assert header[: len(S.COLUMNS)] == list(S.COLUMNS)
    assert header[len(S.COLUMNS) :] == ['shape_a', 'shape_c', 'shape_std_a', 'shape_std_c', 'mac']


def test_an_unknown_column_is_that_recordings_error_row(csv_fleet, tmp_path, capsys):
    short = tmp_path / 'two.csv'
    t, y = record(5)
    np.savetxt(
        short, np.column_stack((t, y[:, :2])), delimiter=',', header='time,a,b', comments=''
    )
    code, rows, err = survey_rows(capsys, csv_fleet[0], short, '--columns', 'a,b,c', *AMBIENT)
    assert code == 0
    good = [r for r in rows if r['recording'] == str(csv_fleet[0])]
    bad = [r for r in rows if r['recording'] == str(short)]
    assert len(good) == 2 and not any(r['error'] for r in good)
    assert len(bad) == 1 and "no column 'c'" in bad[0]['error']
    assert err.count('error:') == 1 and str(short) in err


@pytest.fixture(scope='module')
def bag_fleet(tmp_path_factory):
    """Two days of a tip IMU's three axes (the baseline and the changed structure) and a torque
    bag, which has none of the IMU's fields."""
    folder = tmp_path_factory.mktemp('bag_fleet')
    for day, scale in enumerate((1.0, CHANGED)):
        t, y = record(10 + day, scale)
        stamps = EPOCH_NS + day * DAY_NS + np.round(t * 1e9).astype(np.int64)
        write_channels(folder / f'imu{day}', '/imu', IMU, AXES, stamps, y, 'tip')
    t = np.arange(0, 20, 0.05)
    write_wrench_series(
        folder / 'torque',
        WrenchSeries(EPOCH_NS + np.round(t * 1e9).astype(np.int64), np.sin(t), 'arm', '/torque'),
    )
    return folder


def test_components_of_a_bag_fleet(bag_fleet, capsys):
    base = bag_fleet / 'imu0'
    code, rows, err = survey_rows(
        capsys, bag_fleet, '--components', ','.join(AXES), '--baseline', base, *AMBIENT, *ALARM
    )
    assert code == 0
    by_bag = {
        name: [r for r in rows if r['recording'] == str(bag_fleet / name)]
        for name in ('imu0', 'imu1', 'torque')
    }
    for name, scale in (('imu0', 1.0), ('imu1', CHANGED)):
        check_modes(by_bag[name], AXES, scale)
        assert {r['topic'] for r in by_bag[name]} == {'/imu'}
        assert {r['component'] for r in by_bag[name]} == {','.join(AXES)}
        assert by_bag[name][0]['start_utc'].startswith('2026-01-0')
        assert all(r['alarm'] == (name == 'imu1') for r in by_bag[name])
    (torque,) = by_bag['torque']
    assert 'no topic' in torque['error'] and 'linear_acceleration.x' in torque['error']
    assert err.count('error:') == 1


@pytest.mark.parametrize(
    'options, message',
    [
        (['--columns', 'a,b', '--excitation', 'auto'], 'need --excitation free or ambient'),
        (['--columns', 'all', '--excitation', 'auto'], 'need --excitation free or ambient'),
        (
            ['--components', ','.join(AXES[:2]), '--excitation', 'auto'],
            'need --excitation free or ambient',
        ),
        (['--columns', 'a,b', '--column', 'c', *AMBIENT], 'not both'),
        (['--components', ','.join(AXES), '--component', AXES[0], *AMBIENT], 'not both'),
        (['--columns', 'a,,b', *AMBIENT], 'empty'),
        (['--components', f'{AXES[0]},{AXES[0]}', *AMBIENT], 'twice'),
    ],
)
def test_bad_channel_arguments_are_one_error_line(csv_fleet, capsys, options, message):
    assert main(['survey', str(csv_fleet[0]), *options]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and 'error:' in err[0] and message in err[0], err
