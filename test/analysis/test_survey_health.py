# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""``survey`` with a learned baseline: covariates in the rows, compensated changes, alarms on the
damaged days only, since when, the saved baseline read back, the plot, bad arguments."""

import contextlib
import importlib.util
import io
import json
from pathlib import Path

import numpy as np
import pytest

from vib_estimator.analysis import health
from vib_estimator.cli import main
from vib_estimator.core import health_model as hm

ROOT = Path(__file__).resolve().parents[2]
EPOCH = 1_767_225_600 * 10**9
DAY = 86_400 * 10**9
COLUMN = 'covariate_/temperature:temperature'
DAMAGED = 12  # days 12.. have a 1 % lower frequency


def _make_fleet():
    spec = importlib.util.spec_from_file_location('make_fleet', ROOT / 'scripts/make_fleet.py')
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope='module')
def fleet(tmp_path_factory):
    """16 days of a 4 s sine (2 Hz at 0 degC, -0.2 %/degC) and a /temperature topic."""
    root = tmp_path_factory.mktemp('fleet')
    writer = _make_fleet().write_temperature_day
    rng = np.random.default_rng(0)
    t = np.arange(0, 4, 0.005)
    truth = []
    for day in range(16):
        celsius = rng.uniform(-10, 10)
        f = 2.0 * (1 - 0.002 * celsius) * (1 + 0.0003 * rng.standard_normal())
        f *= 0.99 if day >= DAMAGED else 1.0
        y = 0.3 * np.sin(2 * np.pi * f * t + day) + 0.003 * rng.standard_normal(len(t))
        stamps = EPOCH + day * DAY + np.round(t * 1e9).astype(np.int64)
        writer(root / f'day_{day:02d}', stamps, y, celsius + 0.01 * rng.standard_normal(4))
        truth.append(celsius)
    return root, np.array(truth)


def _survey(capsys, *args):
    code = main(
        ['survey', *map(str, args), '--topic', '/accel', '--format', 'jsonl', '--jobs', '1']
    )
    out = capsys.readouterr()
    return code, [json.loads(line) for line in out.out.splitlines()], out.err


@pytest.fixture(scope='module')
def learned(fleet, tmp_path_factory):
    """The fleet's rows against a baseline learned from its first 10 days, and the saved
    baseline."""
    root, _ = fleet
    saved = tmp_path_factory.mktemp('baseline') / 'base.yaml'
    out, err = io.StringIO(), io.StringIO()
    args = ['--covariates', '/temperature:temperature', '--baseline-records', '10']
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(
            [
                'survey',
                str(root),
                '--topic',
                '/accel',
                '--format',
                'jsonl',
                '--jobs',
                '1',
                *args,
                '--save-baseline',
                str(saved),
            ]
        )
    assert code == 0, err.getvalue()
    return [json.loads(line) for line in out.getvalue().splitlines()], saved


def test_learned_baseline_alarms_on_the_damaged_days_only(fleet, learned, capsys):
    root, celsius = fleet
    rows, saved = learned
    assert len(rows) == 16
    assert np.allclose([r[COLUMN] for r in rows], celsius, atol=0.02)
    assert [r['baseline_mode'] for r in rows] == [1] * 16
    assert [r['alarm'] for r in rows] == [d >= DAMAGED for d in range(16)]
    damaged = rows[DAMAGED:]
    assert all(r['alarm_since'] == rows[DAMAGED]['start_utc'] for r in damaged)
    assert all(
        -0.012 < r['change_lo'] < r['change_rel'] < r['change_hi'] < -0.008 for r in damaged
    )
    # uncompensated, the temperature's +-2 % swing hides the 1 % damage
    raw = np.array([r['frequency_hz'] for r in rows])
    assert np.ptp(raw[:DAMAGED]) > 0.02 * 2
    # the saved baseline gives the same rows
    code, again, _ = _survey(capsys, root, '--baseline', saved)
    assert code == 0
    keys = ('change_rel', 'change_lo', 'change_hi', 'alarm', 'alarm_since', 'residual_z')
    assert [[r[k] for k in keys] for r in again] == [[r[k] for k in keys] for r in rows]
    assert hm.load(saved).covariates == ['/temperature:temperature']


def test_without_covariates_the_swing_is_alarmed(fleet, capsys):
    """The same fleet against a baseline without the temperature: its spread is the swing's,
    so the damage is not told apart -- the reason for the covariates."""
    root, _ = fleet
    code, rows, _ = _survey(capsys, root, '--baseline-records', 10)
    assert code == 0
    assert sum(r['alarm'] for r in rows[DAMAGED:]) < 4


def test_cusum_and_plot(fleet, capsys, tmp_path):
    root, _ = fleet
    png = tmp_path / 'health.png'
    code, rows, _ = _survey(
        capsys,
        root,
        '--covariates',
        '/temperature:temperature',
        '--baseline-until',
        '2026-01-10',
        '--false-alarm',
        '0.01',
        '--plot',
        png,
    )
    assert code == 0
    assert all('cusum' in r for r in rows)
    assert rows[-1]['cusum'] < -hm.cusum_threshold(0.01) and rows[-1]['alarm']
    assert png.is_file()
    baseline = hm.learn(
        [r for r in rows[:10]], ['/temperature:temperature'], lambda r: [r[COLUMN]]
    )
    fig = health.plot_health(rows, tmp_path / 'again.png', baseline)
    alarm_marks = [line for line in fig.axes[1].get_lines() if line.get_label() == 'alarm']
    assert len(alarm_marks[0].get_xdata()) == sum(r['alarm'] for r in rows)


@pytest.mark.parametrize(
    'args, message',
    [
        (['--save-baseline', 'b.yaml'], 'needs --baseline-records'),
        (['--baseline-records', '5', '--baseline', '1.0'], 'not both'),
        (['--false-alarm', '0.5'], 'needs a learned baseline'),
        (['--baseline-records', '5', '--false-alarm', '2'], 'must be in'),
        (['--covariates', ':x'], 'neither TOPIC:FIELD'),
        (['--baseline-until', 'soon', '--covariates', 'a'], 'ISO 8601'),
        (['--baseline-records', '5'], 'only 1 recording(s)'),
    ],
)
def test_bad_arguments(fleet, capsys, args, message):
    root, _ = fleet
    assert main(['survey', str(root / 'day_00'), *args]) == 2
    err = capsys.readouterr().err
    errors = [line for line in err.splitlines() if 'error:' in line]
    assert len(errors) == 1 and message in errors[0] and 'Traceback' not in err
    # the options are checked before any recording is read; what the rows must hold, after
    # the search says what it found
    assert err.count('\n') == 1 or err.startswith('vib-estimator survey: 1 recording(s) found')


def test_a_missing_covariate_is_an_error_row(fleet, capsys):
    root, _ = fleet
    code, rows, err = _survey(capsys, root / 'day_00', '--covariates', '/humidity:data')
    assert code == 0
    assert rows[0]['error'].startswith('covariate:') and 'humidity' in rows[0]['error']
    assert np.isfinite(rows[0]['frequency_hz'])


def test_csv_covariate_columns(tmp_path, capsys):
    """CSV recordings: the covariate is a column by name; Unix time gives the start."""
    rng = np.random.default_rng(1)
    t = np.arange(0, 6, 0.004)
    for day in range(7):
        celsius = rng.uniform(-10, 10)
        f = 2.0 * (1 - 0.002 * celsius) * (0.99 if day == 6 else 1.0)
        y = np.sin(2 * np.pi * f * t) + 0.003 * rng.standard_normal(len(t))
        temp = celsius + 0.01 * rng.standard_normal(len(t))
        np.savetxt(
            tmp_path / f'day{day}.csv',
            np.column_stack([EPOCH / 1e9 + day * 86400 + t, y, temp]),
            delimiter=',',
            header='t,accel,temperature',
            comments='',
        )
    code = main(
        [
            'survey',
            str(tmp_path),
            '--column',
            'accel',
            '--covariates',
            'temperature',
            '--baseline-records',
            '6',
            '--format',
            'jsonl',
            '--jobs',
            '1',
        ]
    )
    rows = [json.loads(line) for line in capsys.readouterr().out.splitlines()]
    assert code == 0
    assert [r['alarm'] for r in rows] == [False] * 6 + [True]
    assert rows[-1]['start_utc'] == '2026-01-07T00:00:00Z' == rows[-1]['alarm_since']
    assert all(np.isfinite(r['covariate_temperature']) for r in rows)


def test_the_node_side_judges_a_recording_as_survey(fleet, learned):
    """A day's estimates and temperatures through LiveHealth (the node's core, the day one
    window, summarised as the node does) give survey's compensated change and alarm."""
    from vib_estimator.analysis.analyze import estimate_signal
    from vib_estimator.analysis.survey import DEFAULT_MODEL
    from vib_estimator.core import EstimatorConfig
    from vib_estimator.io.covariates import covariate_means
    from vib_estimator.io.streaming import open_signal
    from vib_estimator.nodes.baseline_monitor import window_frequency

    root, _ = fleet
    rows, saved = learned
    baseline = hm.load(saved)
    config = EstimatorConfig(model=DEFAULT_MODEL)
    for day in (3, DAMAGED + 1):
        path = root / f'day_{day:02d}'
        est = estimate_signal(open_signal(path, '/accel'), config).estimates
        live = hm.LiveHealth(baseline, baseline.covariates, 1e6, summarise=window_frequency)
        live.covariate(0, covariate_means(path, baseline.covariates)[0])
        for k in range(len(est.t)):
            live.estimate(
                est.t[k],
                1,
                est.frequency_hz[k],
                est.frequency_std_hz[k],
                est.convergence_time[k],
            )
        (result,) = live.close()
        assert result.change.change_rel == pytest.approx(rows[day]['change_rel'], abs=1e-12)
        assert result.alarm == rows[day]['alarm'] == (day >= DAMAGED)
