# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""``vib-estimator analyze`` on CSV files and bags, and its handling of bad input."""

import argparse
import json
import re

import numpy as np
import pytest

from vib_estimator.analysis.choosing import prepare
from vib_estimator.cli import main
from vib_estimator.core import EstimatorConfig, estimate
from vib_estimator.core.choice import decide
from vib_estimator.io.bags import WrenchSeries, write_wrench_series
from vib_estimator.io.fields import seconds_since


def decided(t, y, config=None):
    """What ``analyze`` with no ``--excitation`` estimates (:func:`.choosing.prepare`):
    ``config`` (default: the defaults; its model or band given as options) with the free-decay
    window (and model) its decision gives (core.choice.fast_window), on the samples less the
    offset it gives."""
    given = config is not None
    args = argparse.Namespace(
        excitation=None,
        paper=False,
        min_periods=None,
        ambient_window_s=None,
        model=config.model if given else None,
        band_hz=config.band_hz if given else None,
    )
    config, d, _ = prepare(args, config or EstimatorConfig(), t, y, 1, 'analyze')
    return estimate(t, y - d.offset if np.isfinite(d.offset) else y, config)


@pytest.fixture
def samples():
    rng = np.random.default_rng(5)
    t = np.arange(0, 8, 0.002)
    return t, 0.2 * np.sin(2 * np.pi * 1.33 * t + 0.4) + 0.002 * rng.standard_normal(len(t))


def jsonl(text):
    return [json.loads(line) for line in text.splitlines()]


def test_csv_estimates_equal_the_core(tmp_path, capsys, samples):
    t, y = samples
    path = tmp_path / 'sig.csv'
    np.savetxt(
        path,
        np.column_stack([t, 5 * y, y]),
        delimiter=',',
        header='time,other,torque',
        comments='',
    )
    assert main(['analyze', str(path), '--column', 'torque']) == 0
    rows = jsonl(capsys.readouterr().out)
    expected = decided(t, y)
    assert decide(t, y).min_periods == 0.9  # a clean pluck (core.choice.fast_window)
    assert len(rows) == len(expected) > 5
    assert [r['frequency_hz'] for r in rows] == expected.frequency_hz.tolist()
    assert [r['t'] for r in rows] == expected.t.tolist()
    assert all(abs(r['frequency_hz'] / 1.33 - 1) < 0.01 for r in rows)


def test_csv_in_milliseconds_and_semicolons_gives_the_same_estimates(tmp_path, capsys, samples):
    """A logger's ``time_ms;y`` with decimal commas: the estimates of the same record in seconds
    and decimal points, and one line that says the time's unit (before: read as seconds, a
    1.33 Hz mode was a 0.00133 Hz one: no estimate, no word why)."""
    t, y = samples
    plain, logged = tmp_path / 'a.csv', tmp_path / 'b.csv'
    plain.write_text('t,y\n' + '\n'.join(f'{a:.3f},{b:.6f}' for a, b in zip(t, y)))
    logged.write_text(
        'time_ms;y\n'
        + '\n'.join(f'{a * 1000:.0f};{b:.6f}'.replace('.', ',') for a, b in zip(t, y))
    )
    outputs = []
    for path in (plain, logged):
        assert main(['analyze', str(path), '--format', 'jsonl']) == 0
        outputs.append(capsys.readouterr())
    first, second = (jsonl(o.out) for o in outputs)
    assert len(first) > 5 and len(second) == len(first)  # (the stamps differ by rounding)
    for key in ('t', 'frequency_hz'):
        assert np.allclose([r[key] for r in second], [r[key] for r in first], rtol=1e-9)
    said = [ln for ln in outputs[1].err.splitlines() if 'time column time_ms read in ms' in ln]
    assert len(said) == 1 and 'time column' not in outputs[0].err


def test_csv_with_comments_and_no_header_and_options(tmp_path, capsys, samples):
    t, y = samples
    path = tmp_path / 'sig.csv'
    path.write_text('# recorded by hand\n' + '\n'.join(f'{a},{b + 0.5}' for a, b in zip(t, y)))
    png = tmp_path / 'fig.png'
    assert (
        main(
            [
                'analyze',
                str(path),
                '--model',
                'biased-sinusoid',
                '--band-hz',
                '0.5',
                '5',
                '--format',
                'csv',
                '--plot',
                str(png),
            ]
        )
        == 0
    )
    out = capsys.readouterr()
    lines = out.out.splitlines()
    assert lines[0].startswith('t,frequency_hz')
    cfg = EstimatorConfig(model='biased-sinusoid', band_hz=(0.5, 5.0))
    expected = decided(t, y + 0.5, cfg)
    assert len(lines) - 1 == len(expected) > 3
    column = lines[0].split(',').index('frequency_hz')
    assert [float(ln.split(',')[column]) for ln in lines[1:]] == expected.frequency_hz.tolist()
    assert re.search(rf'\bestimates={len(expected)}\b', out.err)
    assert png.is_file()  # what the figure shows: the plotting tests


def test_bag_input_uses_header_stamps(tmp_path, capsys, samples):
    t, y = samples
    stamps = 1_700_000_000_000_000_000 + np.round(t * 1e9).astype(np.int64)
    write_wrench_series(tmp_path / 'bag', WrenchSeries(stamps, y, 'arm', '/coupling_torque'))
    assert main(['analyze', str(tmp_path / 'bag'), '--format', 'jsonl']) == 0
    rows = jsonl(capsys.readouterr().out)
    expected = decided(seconds_since(stamps, stamps[0]), y)
    assert [r['frequency_hz'] for r in rows] == expected.frequency_hz.tolist()
    assert (
        rows[0]['stamp_ns']
        == stamps[np.searchsorted(seconds_since(stamps, stamps[0]), expected.t[0])]
    )
    assert main(['analyze', str(tmp_path / 'bag'), '--format', 'table']) == 0
    header, *table = capsys.readouterr().out.splitlines()
    assert header.split()[:4] == ['t', '(s)', 'f', '(Hz)']
    assert len(table) == len(expected) > 5  # one row per estimate: t, f as printed
    np.testing.assert_allclose([float(r.split()[0]) for r in table], expected.t, atol=5e-5)
    np.testing.assert_allclose(
        [float(r.split()[1]) for r in table], expected.frequency_hz, atol=5e-7
    )
    assert [int(r.split()[5]) for r in table] == expected.samples.tolist()


@pytest.mark.parametrize(
    'content, args, message',
    [
        (None, [], 'no such file'),
        ('t,y\n', [], 'no data rows'),
        ('t,y\n0,1\n1,2\n', ['--column', 'z'], "no column 'z'"),
        ('t,y\n0,1\n0.002,x\n', [], 'not numbers'),
        ('t,y\n0,1\n0.002,2\n0.001,3\n', [], 'not strictly increasing'),
        ('t,y\n0,1\n0,2\n', [], 'not strictly increasing'),
        ('t,y\n0,1\n', ['--window', '0'], 'window'),
        ('t,y\n0,1\n', ['--max-window', '-1'], 'max_window'),
    ],
)
def test_bad_input_is_one_line_and_exit_code_2(tmp_path, capsys, content, args, message):
    path = tmp_path / 'in.csv'
    if content is not None:
        path.write_text(content)
    assert main(['analyze', str(path)] + args) == 2
    err = capsys.readouterr().err
    assert message in err and len(err.strip().splitlines()) == 1 and 'Traceback' not in err


@pytest.mark.parametrize(
    'make, message',
    [
        (lambda p: p.mkdir(), 'bag'),
        (lambda p: p.with_suffix('.mcap').write_bytes(b'not an mcap file at all'), 'mcap'),
    ],
)
def test_bad_bags_are_refused(tmp_path, capsys, make, message):
    target = tmp_path / 'bag'
    make(target)
    path = target if target.exists() else target.with_suffix('.mcap')
    assert main(['analyze', str(path)]) == 2
    err = capsys.readouterr().err
    assert message in err.lower() and 'Traceback' not in err


def test_unknown_topic_lists_the_available_ones(tmp_path, capsys, samples):
    t, y = samples
    stamps = np.round(t * 1e9).astype(np.int64) + 1
    write_wrench_series(tmp_path / 'bag', WrenchSeries(stamps, y, 'arm', '/coupling_torque'))
    assert main(['analyze', str(tmp_path / 'bag'), '--topic', '/nope']) == 2
    err = capsys.readouterr().err
    assert '/nope' in err and '/coupling_torque' in err


def test_every_input_type_of_a_bag_and_the_topic_choice(tmp_path, capsys, samples):
    """An Imu topic (component checked against its type), a Float64 topic (log time), and the
    default topic refused when there are several."""
    from vib_estimator.io.bags import TYPESTORE, BagWriter

    t, y = samples
    stamps = 1_700_000_000_000_000_000 + np.round(t * 1e9).astype(np.int64)
    T = TYPESTORE.types
    with BagWriter(tmp_path / 'bag') as bag:
        imu = bag.add_topic('/imu', 'sensor_msgs/msg/Imu')
        raw = bag.add_topic('/raw', 'std_msgs/msg/Float64')
        for s, v in zip(stamps.tolist(), y.tolist()):
            header = T['std_msgs/msg/Header'](
                stamp=T['builtin_interfaces/msg/Time'](sec=s // 10**9, nanosec=s % 10**9),
                frame_id='imu_link',
            )
            vec = T['geometry_msgs/msg/Vector3']
            msg = T['sensor_msgs/msg/Imu'](
                header=header,
                orientation=T['geometry_msgs/msg/Quaternion'](0.0, 0.0, 0.0, 1.0),
                orientation_covariance=np.zeros(9),
                angular_velocity=vec(0.0, 0.0, 0.0),
                angular_velocity_covariance=np.zeros(9),
                linear_acceleration=vec(v, 0.0, 9.8),
                linear_acceleration_covariance=np.zeros(9),
            )
            bag.write_message(imu, s + 123_456, msg)  # received later than stamped
            bag.write_message(raw, s, T['std_msgs/msg/Float64'](data=v))
    expected = decided(seconds_since(stamps, stamps[0]), y).frequency_hz.tolist()
    for args in (['--topic', '/imu', '--component', 'linear_acceleration.x'], ['--topic', '/raw']):
        assert main(['analyze', str(tmp_path / 'bag')] + args) == 0
        assert [r['frequency_hz'] for r in jsonl(capsys.readouterr().out)] == expected
    assert main(['analyze', str(tmp_path / 'bag')]) == 2
    err = capsys.readouterr().err
    assert (
        f'choose one with --topic, e.g. `vib-estimator analyze {tmp_path / "bag"} --topic /imu`: '
        '/imu (sensor_msgs/msg/Imu), /raw' in err
    )
    assert (
        main(['analyze', str(tmp_path / 'bag'), '--topic', '/imu', '--component', 'torque.z']) == 2
    )
    assert 'linear_acceleration.x' in capsys.readouterr().err


def test_band_above_nyquist_is_an_error(tmp_path, capsys, samples):
    t, y = samples  # 500 Hz: Nyquist 250 Hz
    path = tmp_path / 'sig.csv'
    np.savetxt(path, np.column_stack([t, y]), delimiter=',')
    assert main(['analyze', str(path), '--band-hz', '1', '300']) == 2
    err = capsys.readouterr().err
    assert 'above the Nyquist frequency 250 Hz' in err and len(err.strip().splitlines()) == 1
    assert main(['analyze', str(path), '--band-hz', '1', '200']) == 0


def test_excitation_ambient_equals_the_core_and_bad_window_is_refused(tmp_path, capsys):
    from vib_estimator.core import create_estimator
    from vib_estimator.sim.ambient import ambient_record

    t, y, _ = ambient_record(30.0, 500.0, [(5.0, 0.01, 1.0)], 26.0, 0)
    path = tmp_path / 'ambient.csv'
    np.savetxt(path, np.column_stack((t, y)), delimiter=',', header='t,y', comments='')
    assert main(['analyze', str(path), '--excitation', 'ambient', '--ambient-window-s', '20']) == 0
    rows = jsonl(capsys.readouterr().out)
    config = EstimatorConfig(excitation='ambient', ambient_window_s=20.0)
    ref = create_estimator(config).process(*np.loadtxt(path, delimiter=',', skiprows=1).T)
    assert len(rows) == len(ref) > 0
    assert [r['frequency_hz'] for r in rows] == list(ref.frequency_hz)
    assert [r['mode'] for r in rows] == list(ref.mode)
    assert main(['analyze', str(path), '--excitation', 'ambient', '--ambient-window-s', '1']) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err[-1].startswith('vib-estimator analyze: error: ambient_window_s')


def test_excitation_auto_equals_the_core_and_free_on_a_free_decay(tmp_path, capsys):
    from vib_estimator.core import create_estimator

    t = np.arange(0.0, 8.0, 0.002)
    y = np.exp(-0.2 * t) * np.sin(2 * np.pi * 1.33 * t + 0.4) + 1e-3 * np.cos(40.0 * t)
    path = tmp_path / 'decay.csv'
    np.savetxt(path, np.column_stack((t, y)), delimiter=',', header='t,y', comments='')
    assert main(['analyze', str(path), '--excitation', 'auto']) == 0
    rows = jsonl(capsys.readouterr().out)
    t, y = np.loadtxt(path, delimiter=',', skiprows=1).T
    ref = create_estimator(EstimatorConfig(excitation='auto')).process(t, y)
    free = create_estimator(EstimatorConfig()).process(t, y)
    assert len(rows) == len(ref) == len(free) > 0
    assert [r['frequency_hz'] for r in rows] == list(ref.frequency_hz) == list(free.frequency_hz)
    assert {r['mode'] for r in rows} == {1}


def test_options_keep_the_record_as_read(tmp_path, capsys):
    """The decided model and offset (a decay whose offset its tail gives) are the default's:
    ``--paper``, ``--excitation free``, ``--model`` and ``--min-periods`` estimate the samples as
    read, exactly as the core does with those options."""
    t = np.arange(0, 20, 0.002)
    y = 0.5 + np.exp(-0.01 * 2 * np.pi * 2 * t) * np.sin(2 * np.pi * 2 * t + 1)
    y += 0.003 * np.random.default_rng(2).standard_normal(len(t))
    assert decide(t, y).model == 'damped-sinusoid' and abs(decide(t, y).offset - 0.5) < 1e-3
    path = tmp_path / 'decay.csv'
    np.savetxt(path, np.column_stack([t, y]), delimiter=',', header='t,y', comments='')
    for options, config in (
        (['--paper'], EstimatorConfig.paper()),
        (['--excitation', 'free'], EstimatorConfig()),
        (['--model', 'damped-sinusoid'], EstimatorConfig(model='damped-sinusoid')),
        (['--min-periods', '0.9'], EstimatorConfig(min_periods=0.9)),
    ):
        assert main(['analyze', str(path), '--format', 'jsonl', *options]) == 0
        rows = jsonl(capsys.readouterr().out)
        expected = estimate(t, y, config)
        assert [r['frequency_hz'] for r in rows] == expected.frequency_hz.tolist(), options
