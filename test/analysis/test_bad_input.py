# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""Issue 22 in the command line: a Hypothesis fuzz of the CSV reader through ``vib-estimator
analyze`` (random bytes, random numbers in CSV rows), strict JSONL for every estimate, and a run
without estimates that says why."""

from __future__ import annotations

import contextlib
import io
import json
import math
import os
import tempfile

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from vib_estimator import cli
from vib_estimator.sim.ambient import ambient_record

CELLS = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True),
    st.sampled_from([1e308, -1e308, 5e-324, 0.0, 'nan', 'inf', '', 'x', '1e999']),
    st.floats(-5.0, 5.0),
)


def analyze(data: bytes, *options):
    """(exit code, stdout, stderr) of ``vib-estimator analyze`` on a file holding ``data``."""
    fd, path = tempfile.mkstemp(suffix='.csv')
    try:
        os.write(fd, data)
        os.close(fd)
        out, err = io.StringIO(), io.StringIO()
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            code = cli.main(['analyze', path, *options])
        return code, out.getvalue(), err.getvalue()
    finally:
        os.unlink(path)


def check_run(code, out, err):
    """Exit 0 with valid JSON lines of finite estimates, or exit 2 with one error line."""
    if code == 2:
        assert out == '' and len(err.strip().splitlines()) == 1 and 'error: ' in err, err
        return
    assert code == 0, err
    for line in out.splitlines():
        row = json.loads(line, parse_constant=lambda c: (_ for _ in ()).throw(ValueError(c)))
        for key in ('t', 'frequency_hz', 'fit', 'amplitude', 'convergence_time_s'):
            assert isinstance(row[key], (int, float)) and math.isfinite(row[key]), row


@settings(max_examples=60, deadline=None)
@given(data=st.binary(max_size=400))
def test_fuzz_random_bytes_error_or_valid_output(data):
    check_run(*analyze(data))


@settings(max_examples=40, deadline=None)
@given(
    rows=st.lists(st.tuples(CELLS, CELLS), max_size=60),
    header=st.booleans(),
    keep_time=st.booleans(),
)
def test_fuzz_random_cells_mixed_into_a_sine(rows, header, keep_time):
    """Random cells replace values (``keep_time``: the stamps stay increasing, so the estimator
    sees them) or are inserted as rows (times too: mostly refused, one error line)."""
    t = np.arange(0, 3, 0.002).tolist()
    lines = [f'{a!r},{b!r}' for a, b in zip(t, np.sin(2 * np.pi * 3 * np.array(t)).tolist())]
    for i, (a, b) in enumerate(rows):
        at = (i * 97) % len(lines)
        if keep_time:
            lines[at] = f'{t[at]!r},{b}'
        else:
            lines.insert(at, f'{a},{b}')
    text = ('t,y\n' if header else '') + '\n'.join(lines) + '\n'
    check_run(*analyze(text.encode()))


def test_jsonl_is_strict_json_for_an_absurd_sample():
    """Issue 22 case 2: one sample at 1e300 wrote "amplitude": Infinity and a NaN fit."""
    t = np.arange(0, 10, 0.002)
    wn = 2 * np.pi * 3
    y = np.exp(-0.01 * wn * t) * np.sin(wn * t)
    y[1234] = 1e300
    text = 't,y\n' + ''.join(f'{a!r},{b!r}\n' for a, b in zip(t.tolist(), y.tolist()))
    code, out, err = analyze(text.encode(), '--model', 'damped-sinusoid')
    check_run(code, out, err)
    rows = [json.loads(line) for line in out.splitlines()]
    assert len(rows) > 10 and all(abs(r['frequency_hz'] / 3 - 1) < 1e-3 for r in rows)
    assert 'skipped_outlier=1' in err


def test_no_estimate_says_why():
    """Issue 22 case 8: the default model on a clean damped sine gave 0 estimates, no word why
    (``--excitation free``: the configured model; the default now decides the damped model for
    it, issue 37, and estimates it)."""
    t = np.arange(0, 10, 0.002)
    wn = 2 * np.pi * 3
    text = 't,y\n' + ''.join(
        f'{a!r},{b!r}\n'
        for a, b in zip(t.tolist(), (np.exp(-0.02 * wn * t) * np.sin(wn * t)).tolist())
    )
    code, out, err = analyze(text.encode(), '--format', 'jsonl')
    rows = [json.loads(line) for line in out.splitlines()]
    assert code == 0 and len(rows) > 5 and 'damped-sinusoid' in err
    assert all(
        abs(r['frequency_hz'] / 3 - 1) < 0.005 and abs(r['damping'] / 0.02 - 1) < 0.1 for r in rows
    )
    code, out, err = analyze(text.encode(), '--format', 'table', '--excitation', 'free')
    assert code == 0 and 'estimates=0' in err
    why = [line for line in err.splitlines() if line.startswith('analyze: no estimate: ')]
    assert len(why) == 1 and 'never fired' in why[0] and 'damped-sinusoid' in why[0]
    assert 'open_segment_samples=4993' in err


def test_a_constant_signal_says_it_is_at_rest():
    """A flat column (a sensor unplugged, the wrong column) said "held back by the quality gate
    (rejected_at_rest=18): check --min-fit, --max-damping ..." -- options that cannot help."""
    t = np.arange(0, 30, 0.002)
    text = 't,y\n' + ''.join(f'{a!r},0.25\n' for a in t.tolist())
    code, out, err = analyze(text.encode(), '--format', 'jsonl')
    why = [line for line in err.splitlines() if line.startswith('analyze: no estimate: ')]
    assert code == 0 and out == '' and len(why) == 1
    assert 'at rest' in why[0] and 'rejected_at_rest=' in why[0] and '--min-fit' not in why[0]


def test_a_constant_signal_in_operation_says_so():
    """A constant column (an IMU axis at rest, an offset) through the output-only identifiers:
    one channel, several, and a constant beside moving channels. The halvings of a constant
    window hold only the filter's rounding: identified, it raised ZeroDivisionError (one
    channel) or OverflowError (all channels), and one exactly-0 channel beside moving ones made
    the joint identifier publish nothing."""
    t, moving, _ = ambient_record(60, 100, [(3.0, 0.01, 1.0)], 25, 4)
    table = np.column_stack([t, np.zeros_like(t), np.full_like(t, 9.81), moving, 0.5 * moving])
    text = 't,zero,offset,a,b\n' + ''.join(
        ','.join(repr(v) for v in row) + '\n' for row in table.tolist()
    )
    for columns in (['--column', 'offset'], ['--column', 'zero'], ['--columns', 'zero,offset']):
        code, out, err = analyze(text.encode(), *columns, '--excitation', 'ambient')
        assert code == 0 and out == '' and 'Traceback' not in err
        assert 'flat_windows=' in err and 'estimates=0' in err
        if columns[0] == '--column':
            assert 'no estimate: the signal is constant' in err
    code, out, err = analyze(
        text.encode(), '--columns', 'zero,a,b', '--excitation', 'ambient', '--format', 'jsonl'
    )
    rows = [json.loads(line) for line in out.splitlines()]
    assert code == 0 and len(rows) >= 5  # (6: 30-32 s, then the 30 s window every 5 s)
    assert all(abs(r['frequency_hz'] / 3 - 1) < 0.05 and r['shape_zero'] == 0 for r in rows)


def test_gaps_are_counted_in_analyze_and_survey_rows(tmp_path):
    """Issue 22 case 1 in the command line: the gaps and the samples lost are in analyze's
    summary and in each survey row."""
    t = np.arange(0, 20, 0.002)
    keep = np.ones(len(t), bool)
    for start in (1000, 3000, 6000):
        keep[start : start + 100] = False  # three 200 ms gaps (< max_gap)
    path = tmp_path / 'gappy.csv'
    y = np.sin(2 * np.pi * 2 * t[keep])
    path.write_text(
        't,y\n' + ''.join(f'{a!r},{b!r}\n' for a, b in zip(t[keep].tolist(), y.tolist()))
    )
    code, _, err = analyze(path.read_bytes())
    assert code == 0 and 'gaps=3' in err and 'samples_lost=300' in err
    out = io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(io.StringIO()):
        assert cli.main(['survey', str(path), '--format', 'csv']) == 0
    header, row = out.getvalue().splitlines()[:2]
    values = dict(zip(header.split(','), row.split(',')))
    assert values['gaps'] == '3' and values['samples_lost'] == '300'


def test_white_noise_says_it_is_noise():
    """A sensor at rest (white noise, 30 s at 1 kHz): its spectrum's strongest peak stands under
    ``FLAT_DB`` and no other above what its noise reaches by chance; the line says it is noise
    (it said "the convergence test (Eqs. 16-17) never fired ... --model damped-sinusoid", then,
    its chance peaks read as several modes, "the mode tracker found no mode")."""
    t = np.arange(0, 30, 0.001)
    y = np.random.default_rng(0).standard_normal(len(t))
    text = 't,y\n' + ''.join(f'{a!r},{b!r}\n' for a, b in zip(t.tolist(), y.tolist()))
    code, out, err = analyze(text.encode(), '--format', 'jsonl')
    why = [line for line in err.splitlines() if line.startswith('analyze: no estimate: ')]
    assert code == 0 and out == ''
    assert len(why) == 1 and 'the spectrum is flat' in why[0] and 'noise, no mode' in why[0]
    assert 'Eqs. 16-17' not in why[0] and '--min-fit' not in why[0]


def test_a_numpy_file_gets_one_error_line_that_says_how_to_write_it_as_a_csv(tmp_path):
    """A lab's ``numpy.save`` of (time, signal) rows is no bag nor CSV: exit 2, one ``error:``
    line that says how to write it as a CSV file (it said only that it is not a bag)."""
    path = tmp_path / 'rec.npy'
    np.save(path, np.zeros((2, 100)))
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = cli.main(['analyze', str(path)])
    check_run(code, out.getvalue(), err.getvalue())
    assert code == 2 and 'a NumPy array: write it as one' in err.getvalue()
