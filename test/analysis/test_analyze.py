"""``vib-estimator analyze`` on CSV files and bags, and its handling of bad input."""
import json

import numpy as np
import pytest

from vib_estimator.io.bags import WrenchSeries, write_wrench_series
from vib_estimator.cli import main
from vib_estimator.core import EstimatorConfig, estimate
from vib_estimator.io.fields import seconds_since


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
    np.savetxt(path, np.column_stack([t, 5 * y, y]), delimiter=',', header='time,other,torque',
               comments='')
    assert main(['analyze', str(path), '--column', 'torque']) == 0
    rows = jsonl(capsys.readouterr().out)
    expected = estimate(t, y)
    assert len(rows) == len(expected) > 5
    assert [r['frequency_hz'] for r in rows] == expected.frequency_hz.tolist()
    assert [r['t'] for r in rows] == expected.t.tolist()
    assert all(abs(r['frequency_hz'] / 1.33 - 1) < 0.01 for r in rows)


def test_csv_with_comments_and_no_header_and_options(tmp_path, capsys, samples):
    t, y = samples
    path = tmp_path / 'sig.csv'
    path.write_text('# recorded by hand\n' + '\n'.join(f'{a},{b + 0.5}' for a, b in zip(t, y)))
    png = tmp_path / 'fig.png'
    assert main(['analyze', str(path), '--model', 'biased-sinusoid', '--band-hz', '0.5', '5',
                 '--format', 'csv', '--plot', str(png)]) == 0
    out = capsys.readouterr()
    lines = out.out.splitlines()
    assert lines[0].startswith('t,frequency_hz')
    cfg = EstimatorConfig(model='biased-sinusoid', band_hz=(0.5, 5.0))
    assert len(lines) - 1 == len(estimate(t, y + 0.5, cfg)) > 3
    assert 'estimates=' in out.err
    assert png.stat().st_size > 10_000


def test_bag_input_uses_header_stamps(tmp_path, capsys, samples):
    t, y = samples
    stamps = 1_700_000_000_000_000_000 + np.round(t * 1e9).astype(np.int64)
    write_wrench_series(tmp_path / 'bag', WrenchSeries(stamps, y, 'arm', '/coupling_torque'))
    assert main(['analyze', str(tmp_path / 'bag'), '--format', 'jsonl']) == 0
    rows = jsonl(capsys.readouterr().out)
    expected = estimate(seconds_since(stamps, stamps[0]), y)
    assert [r['frequency_hz'] for r in rows] == expected.frequency_hz.tolist()
    assert rows[0]['stamp_ns'] in stamps
    assert main(['analyze', str(tmp_path / 'bag'), '--format', 'table']) == 0
    assert 'f (Hz)' in capsys.readouterr().out


@pytest.mark.parametrize('content, args, message', [
    (None, [], 'no such file'),
    ('t,y\n', [], 'no data rows'),
    ('t,y\n0,1\n1,2\n', ['--column', 'z'], "no column 'z'"),
    ('t,y\n0,1\n0.002,x\n', [], 'not numbers'),
    ('t,y\n0,1\n0.002,2\n0.001,3\n', [], 'not strictly increasing'),
    ('t,y\n0,1\n0,2\n', [], 'not strictly increasing'),
    ('t,y\n0,1\n', ['--window', '0'], 'window'),
    ('t,y\n0,1\n', ['--max-window', '-1'], 'max_window'),
])
def test_bad_input_is_one_line_and_exit_code_2(tmp_path, capsys, content, args, message):
    path = tmp_path / 'in.csv'
    if content is not None:
        path.write_text(content)
    assert main(['analyze', str(path)] + args) == 2
    err = capsys.readouterr().err
    assert message in err and len(err.strip().splitlines()) == 1 and 'Traceback' not in err


@pytest.mark.parametrize('make, message', [
    (lambda p: p.mkdir(), 'bag'),
    (lambda p: p.with_suffix('.mcap').write_bytes(b'not an mcap file at all'), 'mcap'),
])
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
