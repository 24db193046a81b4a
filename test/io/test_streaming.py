# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""Streaming readers: same samples as the reference readers, every input type, bounded blocks."""

import os
import shutil
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from vib_estimator.io import csv_reader, mcap, streaming
from vib_estimator.io.bags import (
    TYPESTORE,
    BagError,
    BagWriter,
    WrenchSeries,
    read_wrench_series,
    write_wrench_series,
)
from vib_estimator.io.cdr import DOUBLE_INDEX
from vib_estimator.io.csv_reader import CsvError, read_csv_series
from vib_estimator.io.fields import (
    FLOAT32,
    INPUT_TYPES,
    JOINT_STATE,
    component_getter,
    has_header,
)
from vib_estimator.io.streaming import open_signal

EPOCH = 1_700_000_000_000_000_000
# ../shared relative to the repo; VIB_SHARED names it elsewhere (a worktree)
SHARED_BAGS = (
    Path(os.environ.get('VIB_SHARED', Path(__file__).resolve().parents[3] / 'shared'))
    / 'ros2-bags'
)


def collect(signal):
    parts = list(signal.blocks())
    return tuple(np.concatenate(p) for p in zip(*parts)), parts


def make_message(msgtype, stamp, frame, value, k):
    """A rosbags message of ``msgtype`` whose every double is distinct (value + index)."""
    T = TYPESTORE.types
    header = T['std_msgs/msg/Header'](
        stamp=T['builtin_interfaces/msg/Time'](sec=stamp // 10**9, nanosec=stamp % 10**9),
        frame_id=frame,
    )
    v3 = lambda a: T['geometry_msgs/msg/Vector3'](x=a, y=a + 1, z=a + 2)  # noqa: E731
    if msgtype in ('std_msgs/msg/Float64', 'std_msgs/msg/Float32'):
        return T[msgtype](data=value)
    if msgtype == 'geometry_msgs/msg/WrenchStamped':
        return T[msgtype](
            header=header,
            wrench=T['geometry_msgs/msg/Wrench'](force=v3(value), torque=v3(value + 3)),
        )
    if msgtype == 'geometry_msgs/msg/AccelStamped':
        return T[msgtype](
            header=header,
            accel=T['geometry_msgs/msg/Accel'](linear=v3(value), angular=v3(value + 3)),
        )
    if msgtype == 'geometry_msgs/msg/Vector3Stamped':
        return T[msgtype](header=header, vector=v3(value))
    if msgtype == 'sensor_msgs/msg/Imu':
        q = T['geometry_msgs/msg/Quaternion'](x=0.0, y=0.0, z=0.0, w=1.0)
        cov = np.arange(9, dtype=np.float64)
        return T[msgtype](
            header=header,
            orientation=q,
            orientation_covariance=cov,
            angular_velocity=v3(value),
            angular_velocity_covariance=cov,
            linear_acceleration=v3(value + 3),
            linear_acceleration_covariance=cov,
        )
    names = ['joint1', 'joint2'] if k % 3 else ['joint2']  # joint1 absent every 3rd
    arr = np.array([value, -value][: len(names)])
    return T[JOINT_STATE](header=header, name=names, position=arr, velocity=arr, effort=arr)


@pytest.mark.parametrize('storage', ['mcap', 'sqlite3'])
@pytest.mark.parametrize('msgtype', INPUT_TYPES)
def test_every_type_equals_the_rosbags_deserialiser(tmp_path, msgtype, storage):
    frames = ['', 'a', 'arm_base', 'seven77', 'a_much_longer_frame_name']  # all alignments
    n = 300
    stamps = EPOCH + np.arange(n, dtype=np.int64) * 2_000_000 + 7
    msgs = [make_message(msgtype, int(s), frames[k % 5], 0.1 * k, k) for k, s in enumerate(stamps)]
    with BagWriter(tmp_path / 'bag', storage) as bag:
        conn = bag.add_topic('/x', msgtype)
        for k, (s, m) in enumerate(zip(stamps.tolist(), msgs)):
            bag.write_message(conn, s + 1000, m)  # log time after the stamp
    components = (
        ['effort[joint1]', 'position[joint2]']
        if msgtype == JOINT_STATE
        else list(DOUBLE_INDEX[msgtype])
    )
    for component in components:
        get = component_getter(component, msgtype)
        keep = [k for k, m in enumerate(msgs) if get(m) is not None]
        signal = open_signal(tmp_path / 'bag', component=component)
        (t, y), _ = collect(signal)
        exact = [
            float(np.float32(get(msgs[k])) if msgtype == FLOAT32 else get(msgs[k])) for k in keep
        ]
        assert y.tolist() == exact
        base = stamps if has_header(msgtype) else stamps + 1000
        assert signal.origin_ns == base[keep[0]]
        assert t.tolist() == ((base[keep] - base[keep[0]]) * 1e-9).tolist()
        assert signal.skipped == n - len(keep)


def test_fast_path_is_taken_and_matches_the_reference_reader(tmp_path):
    n = 50_000
    stamps = EPOCH + np.arange(n, dtype=np.int64) * 2_000_000
    y = np.sin(np.arange(n) * 0.01)
    write_wrench_series(tmp_path / 'bag', WrenchSeries(stamps, y, 'arm', '/w'))
    plan = mcap.read_plan(sorted((tmp_path / 'bag').glob('*.mcap')), '/w')
    assert len(plan) > 1  # several chunks, indexed
    (t, values), parts = collect(open_signal(tmp_path / 'bag'))
    ref = read_wrench_series(tmp_path / 'bag')
    assert np.array_equal(values, ref.values)
    assert np.array_equal(t, (ref.stamps_ns - ref.stamps_ns[0]) * 1e-9)


def test_blocks_are_bounded_whatever_the_length(tmp_path, monkeypatch):
    """Constant memory by construction: no block exceeds the block size, however long the file."""
    monkeypatch.setattr(streaming, 'BLOCK_SAMPLES', 4096)
    monkeypatch.setattr(streaming, 'MCAP_BATCH_MESSAGES', 2048)
    monkeypatch.setattr(csv_reader, 'CSV_BLOCK_BYTES', 1 << 16)
    n = 200_000
    t = np.arange(n) * 0.001
    path = tmp_path / 'big.csv'
    np.savetxt(path, np.column_stack([t, np.cos(t)]), delimiter=',', header='t,y', comments='')
    (tt, yy), parts = collect(open_signal(path))
    assert len(parts) > 20 and max(len(p[0]) for p in parts) <= (1 << 16) // 10
    assert np.array_equal(tt, t) and np.array_equal(yy, np.cos(t))
    stamps = EPOCH + np.arange(60_000, dtype=np.int64) * 1_000_000
    write_wrench_series(tmp_path / 'bag', WrenchSeries(stamps, np.zeros(60_000), 'f', '/w'))
    _, parts = collect(open_signal(tmp_path / 'bag'))
    # a batch of chunks (the batch size, plus one chunk of ~13k messages of 1 MB) on top of a
    # full block at most
    assert len(parts) > 3 and max(len(p[0]) for p in parts) < 4096 + 2048 + 20_000


@pytest.mark.parametrize(
    'text',
    [
        '# comment\nt,y\n0,1\n# in between\n0.5, 2\n1,\n2,nan\n',  # exact-rules fallback
        't,y,z\n0,1,9\n0.5,2,9\n1,3,9,extra\n',  # ragged rows
        '0,1\n0.5,2\n1,inf\n',  # no header
    ],
)
def test_csv_fast_and_exact_paths_agree(tmp_path, text):
    path = tmp_path / 'a.csv'
    path.write_text(text)
    series = read_csv_series(path)
    rows = [
        line.split(',')
        for line in text.splitlines()
        if line and not line.startswith('#') and not line.startswith('t')
    ]
    expect = [float(r[1]) if r[1].strip() else float('nan') for r in rows]
    assert np.array_equal(series.y, expect, equal_nan=True)


@pytest.mark.parametrize(
    'text',
    [
        't,a,b,c\n' + '\n'.join(f'{i * 0.01},{i},{-i},{i % 7}' for i in range(3000)),  # arrow
        '# comment\nt,a,b,c\n0,1,2,3\n# in between\n0.1,2,,4\n0.2,3,4,nan\n0.3,4,5,6\n',  # exact
        '0,1,2,3\n0.5,2,3,4\n1,inf,4,5\n',  # no header
    ],
)
def test_csv_columns_in_one_pass_are_each_column_read_alone(tmp_path, monkeypatch, text):
    monkeypatch.setattr(csv_reader, 'CSV_BLOCK_BYTES', 1 << 12)  # several arrow blocks
    path = tmp_path / 'a.csv'
    path.write_text(text)
    names = csv_reader.column_names(path, 'all')
    t, y, got = csv_reader.read_csv_columns(path, ','.join(reversed(names)))
    assert got == names[::-1] and y.shape == (len(t), len(names))
    for k, name in enumerate(got):
        alone = read_csv_series(path, name)
        assert np.array_equal(t, alone.t) and np.array_equal(y[:, k], alone.y, equal_nan=True)


def dialect_texts():
    """One record (time, two signals) written as a spreadsheet or an instrument exports it."""
    t = np.arange(3000) * 0.002
    rows = np.column_stack([t, np.sin(2 * np.pi * 3 * t), np.cos(t)])
    lines = [[f'{v:.9g}' for v in row] for row in rows]
    rows = np.array([[float(v) for v in row] for row in lines])  # as written
    return rows, {
        'a.csv': 'time_s,a,b\n' + '\n'.join(','.join(r) for r in lines),
        'semicolon.csv': 'time_s;a;b\n' + '\n'.join(';'.join(r) for r in lines),
        'comma.csv': 'time_s;a;b\n' + '\n'.join(';'.join(r).replace('.', ',') for r in lines),
        'tabs.tsv': 'time_s\ta\tb\n' + '\n'.join('\t'.join(r) for r in lines),
        'spaces.asc': '\n'.join(''.join(f'{c:>16}' for c in r) for r in lines),
        'spaces.dat': '# time_s, a, b\n' + '\n'.join(' '.join(r) for r in lines),
        # Excel's "CSV UTF-8": a byte-order mark first, CRLF line ends (a German one: ; and ,)
        'excel.csv': '\ufefftime_s;a;b\r\n'
        + '\r\n'.join(';'.join(r).replace('.', ',') for r in lines),
        'bom.csv': '\ufeff' + '\r\n'.join(','.join(r) for r in lines),
    }


@pytest.mark.parametrize('name', list(dialect_texts()[1]))
def test_csv_with_semicolons_tabs_spaces_or_a_decimal_comma_reads_the_same(tmp_path, name):
    """A European spreadsheet's ``0,25;1,5``, a tab-separated export, a whitespace-aligned
    ``.asc``/``.dat`` table (the building's original files), Excel's byte-order mark and CRLF
    (the mark read as a header before: the first row lost): the same samples as the comma file,
    by the fast reader and by the exact rules, each column."""
    rows, texts = dialect_texts()
    path = tmp_path / name
    path.write_text(texts[name], encoding='utf-8')
    assert streaming.is_csv(path)
    layout = csv_reader.csv_layout(path)
    names = csv_reader.column_names(path, 'all')
    assert len(names) == 2 and layout.time_scale == 1.0
    t, y, _ = csv_reader.read_csv_columns(path, 'all')
    assert np.array_equal(t, rows[:, 0]) and np.array_equal(y, rows[:, 1:])
    (tt, yy), _ = collect(open_signal(path))
    exact = np.array([(ti, *yi) for ti, yi in csv_reader.iter_csv_column_rows(layout)])
    assert np.array_equal(tt, t) and np.array_equal(yy, rows[:, 1])
    assert np.array_equal(exact, rows[:, :2])


@pytest.mark.parametrize(
    'name, scale', [('time_ms', 1e-3), ('t [us]', 1e-6), ('stamp_ns', 1e-9), ('time', 1.0)]
)
def test_a_time_column_named_in_ms_us_or_ns_is_read_in_seconds(tmp_path, name, scale):
    """``time_ms`` read as seconds made a 7 Hz decay a 0.007 Hz one: no estimate and no word
    why. A unit in the time column's name converts it (both readers); 'rms' names none."""
    stamps = np.arange(4000) * 0.001 / scale
    path = tmp_path / 'a.csv'
    path.write_text(f'{name},y\n' + '\n'.join(f'{v:.17g},{i}' for i, v in enumerate(stamps)))
    layout = csv_reader.csv_layout(path)
    t = read_csv_series(path).t
    assert layout.time_scale == scale and np.allclose(t, np.arange(4000) * 0.001, rtol=1e-12)
    exact = [ti for ti, _ in csv_reader.iter_csv_rows(layout)]
    assert np.array_equal(exact, t)
    assert bool(csv_reader.time_words(layout)) == (scale != 1.0)
    assert csv_reader.time_unit('rms') == ('s', 1.0) and csv_reader.time_unit('alarms')[1] == 1


def test_pandas_to_csv_its_row_index_and_its_dates(tmp_path):
    """``DataFrame.to_csv`` writes its row index first, unnamed (``,time,accel`` / ``0,0.0,..``:
    the header was read as a data row, an error), and a time index as dates
    (``2024-08-12 21:08:55.001``): the index is left out, the dates read as seconds since the
    first, by both readers, and said."""
    t = np.arange(3000) * 0.001
    y = np.round(np.sin(2 * np.pi * 7 * t), 9)
    indexed, dated = tmp_path / 'i.csv', tmp_path / 'd.csv'
    indexed.write_text(
        ',time,accel\n' + ''.join(f'{i},{a:.17g},{b:.17g}\n' for i, (a, b) in enumerate(zip(t, y)))
    )
    dated.write_text(
        ',accel\n'
        + ''.join(
            f'2024-08-12 21:08:{55 + i // 1000:02d}.{i % 1000:03d},{b!r}\n'
            for i, b in enumerate(y.tolist())
        )
    )
    for path in (indexed, dated):
        layout = csv_reader.csv_layout(path)
        assert layout.names[1:] == ('accel',) and csv_reader.time_words(layout)
        series = read_csv_series(path)
        exact = np.array([(ti, yi) for ti, yi in csv_reader.iter_csv_rows(layout)])
        assert np.allclose(series.t, t, rtol=0, atol=1e-9) and np.array_equal(series.y, y)
        assert np.array_equal(exact, np.column_stack([series.t, series.y]))
    assert csv_reader.csv_layout(indexed).order == (1, 2)
    assert csv_reader.csv_layout(dated).origin.isoformat() == '2024-08-12T21:08:55'
    zoned = tmp_path / 'z.csv'
    zoned.write_text('t,y\n2024-08-12T21:08:55,1\n2024-08-12T21:08:56Z,2\n')
    with pytest.raises(CsvError, match='data row 3 is not numbers'):
        read_csv_series(zoned)


def test_a_row_of_units_under_the_names(tmp_path):
    """An oscilloscope's export (PicoScope: ``Time,Channel A`` / ``(ms),(V)`` / a blank line):
    the units row was data row 2, "not numbers". Now it is the columns' units, the time's read
    from it (ms), and said; a units row whose time is in seconds changes nothing."""
    t = np.arange(-500, 3000) * 0.001
    y = np.round(np.sin(2 * np.pi * 7 * t), 8)
    body = '\n'.join(f'{a * 1000:.6f},{b!r}' for a, b in zip(t.tolist(), y.tolist()))
    scope, plain = tmp_path / 'scope.csv', tmp_path / 'plain.csv'
    scope.write_text('Time,Channel A\n(ms),(V)\n\n' + body + '\n')
    plain.write_text('time,a\ns,m/s^2\n' + body + '\n')
    layout = csv_reader.csv_layout(scope)
    assert layout.units == ('(ms)', '(V)') and layout.time_scale == 1e-3
    assert 'the row of units says so' in csv_reader.time_words(layout)
    series = read_csv_series(scope)
    assert series.name == 'Channel A' and np.allclose(series.t, t, rtol=0, atol=1e-12)
    assert np.array_equal(series.y, y)
    assert csv_reader.csv_layout(plain).time_scale == 1.0  # (its times as written, in s)
    assert len(read_csv_series(plain).t) == len(t)


def test_a_time_column_named_as_one_is_the_time_wherever_it_stands(tmp_path):
    """A logger's ``ax,ay,az,millis`` (an Arduino's): ``ax`` was read as the time ("not strictly
    increasing"). The one column named as a time is the time, in its name's unit; the others are
    the signals, in their order, by both readers."""
    t = np.arange(2000) * 0.001
    a = np.round(np.sin(2 * np.pi * 7 * t), 6)
    path = tmp_path / 'log.csv'
    path.write_text(
        'ax,ay,az,millis\n'
        + '\n'.join(f'{v!r},{-v!r},9.81,{round(s * 1000)}' for v, s in zip(a.tolist(), t.tolist()))
    )
    layout = csv_reader.csv_layout(path)
    assert layout.names == ('millis', 'ax', 'ay', 'az') and layout.order == (3, 0, 1, 2)
    assert 'read as the time, by its name' in csv_reader.time_words(layout)
    times, y, names = csv_reader.read_csv_columns(path, 'all')
    assert names == ['ax', 'ay', 'az'] and np.allclose(times, t, rtol=0, atol=1e-12)
    assert np.array_equal(y, np.column_stack([a, -a, np.full_like(a, 9.81)]))
    exact = np.array([(ti, *yi) for ti, yi in csv_reader.iter_csv_column_rows(layout)])
    assert np.array_equal(exact[:, 0], times) and np.array_equal(exact[:, 1], a)
    for header in ('t,ax,millis', 'x,y,z'):  # a time first, or no name a time's: as they stand
        other = tmp_path / 'other.csv'
        other.write_text(header + '\n0,1,2\n1,2,3\n')
        assert csv_reader.csv_layout(other).order == ()


@settings(max_examples=60, deadline=None)
@given(
    n=st.integers(3, 30),
    signals=st.integers(1, 3),
    dialect=st.sampled_from([',', ';', '\t', ' ']),
    data=st.data(),
)
def test_any_dialect_header_units_and_time_position_reads_the_samples_written(
    tmp_path_factory, n, signals, dialect, data
):
    """What spreadsheets, loggers, pandas and instruments write, combined at random -- delimiter,
    decimal comma, header or none, a row of units, the time in ms, the time last, pandas' row
    index, a byte-order mark, CRLF: every sample as written, the time in seconds, the signals in
    their order (the decimal-comma traceback came from such a combination, not from random
    bytes)."""
    draw = data.draw
    header = draw(st.booleans())
    comma = dialect in (';', '\t') and draw(st.booleans())
    units = header and draw(st.booleans())
    ms = header and draw(st.booleans())
    last = header and draw(st.booleans())
    index = header and dialect in (',', ';') and draw(st.booleans())
    bom, crlf = draw(st.booleans()), draw(st.booleans())
    values = draw(
        st.lists(
            st.lists(st.floats(-1e3, 1e3, allow_nan=False), min_size=signals, max_size=signals),
            min_size=n,
            max_size=n,
        )
    )
    t = np.cumsum(draw(st.lists(st.floats(1e-3, 1.0), min_size=n, max_size=n)))
    t_text = [f'{v * (1000 if ms else 1):.6f}' for v in t]
    y_text = [[f'{v:.6f}' for v in row] for row in values]
    names = [f'sig{k}' for k in range(signals)]
    time_name = 'time_ms' if ms else 'time'

    def row(cells):
        cells = [c.replace('.', ',') for c in cells] if comma else cells
        return (' ' if dialect == ' ' else dialect).join(cells)

    def ordered(time, rest):
        return rest + [time] if last else [time] + rest

    lines = []
    if header:
        lines.append(row(([''] if index else []) + ordered(time_name, names)))
    if units:
        lines.append(row(([''] if index else []) + ordered('ms' if ms else 's', ['V'] * signals)))
    for k in range(n):
        lines.append(row(([str(k)] if index else []) + ordered(t_text[k], y_text[k])))
    text = ('\r\n' if crlf else '\n').join(lines) + '\n'
    path = tmp_path_factory.mktemp('dialect') / 'rec.csv'
    path.write_bytes((('\ufeff' if bom else '') + text).encode())
    times, y, got = csv_reader.read_csv_columns(path, 'all')
    assert got == (names if header else [str(k + 1) for k in range(signals)])
    written = np.array([float(v) for v in t_text]) * (1e-3 if ms else 1.0)
    assert np.allclose(times, written, rtol=1e-12, atol=0)
    assert np.array_equal(y, np.array([[float(v) for v in r] for r in y_text]))


def test_a_header_narrower_than_its_rows_names_the_rest_by_index(tmp_path):
    """``t`` over rows of two cells raised an IndexError (a traceback from ``analyze``)."""
    path = tmp_path / 'a.csv'
    path.write_text('t\n0,1\n0.5,2\n1,3\n')
    series = read_csv_series(path)
    assert series.name == '1' and np.array_equal(series.y, [1, 2, 3])


def test_csv_columns_name_the_row_and_columns_that_are_not_numbers(tmp_path):
    path = tmp_path / 'a.csv'
    path.write_text('t,a,b\n0,1,2\n0.1,2,x\n')
    with pytest.raises(CsvError, match=r'data row 3 is not numbers in columns 0 and 1, 2'):
        csv_reader.read_csv_columns(path, 'all')


def test_csv_error_in_a_late_block_names_the_row(tmp_path, monkeypatch):
    monkeypatch.setattr(csv_reader, 'CSV_BLOCK_BYTES', 1 << 12)
    lines = [f'{i * 0.01},{i}' for i in range(5000)]
    lines[4000] = '40.0,oops'
    path = tmp_path / 'a.csv'
    path.write_text('t,y\n' + '\n'.join(lines))
    with pytest.raises(CsvError, match='data row 4002 is not numbers'):
        list(open_signal(path).blocks())


def logger_file(path, rate='1000', samples=3000, extra=''):
    """A logger's file without a time column (the shared pendulum's layout): a header of
    settings, their values, then one sample per row."""
    values = '\n'.join(f'{np.sin(i / 50):.9g}' for i in range(samples))
    path.write_text(
        f'trigger_start_deg, sample_rate, duration_sec\n90, {rate}, 3\n{extra}{values}\n'
    )
    return path


@pytest.mark.parametrize('blocks', [1 << 12, 1 << 19])
def test_a_file_without_a_time_column_is_read_at_its_stated_rate(
    tmp_path, monkeypatch, break_extra, blocks
):
    """Its samples at i / rate, the same by pyarrow (several blocks or one), by the exact rules
    and by the streaming reader; named ``signal``, after a time column ``t``."""
    monkeypatch.setattr(csv_reader, 'CSV_BLOCK_BYTES', blocks)
    path = logger_file(tmp_path / 'swing.txt')
    series = read_csv_series(path)
    assert series.name == 'signal' and len(series.t) == 3000
    assert np.array_equal(series.t, np.arange(3000) / 1000.0)
    assert np.array_equal(
        series.y, np.array([float(f'{np.sin(i / 50):.9g}') for i in range(3000)])
    )
    streamed = [np.concatenate(c) for c in zip(*open_signal(path).blocks())]
    assert np.array_equal(streamed[0], series.t) and np.array_equal(streamed[1], series.y)
    assert csv_reader.column_names(path, 'all') == ['signal']
    break_extra('pyarrow', ImportError('not installed'))  # the exact rules
    exact = read_csv_series(path)
    assert np.array_equal(exact.t, series.t) and np.array_equal(exact.y, series.y)


def test_a_file_without_a_time_column_errors(tmp_path):
    """A rate that is not positive, and a sample that is not a number (its row counted with the
    two header rows), are ``error:`` lines; settings followed by rows of several cells are an
    ordinary CSV (the second column the signal)."""
    with pytest.raises(CsvError, match='sample rate sample_rate = 0 is not positive'):
        read_csv_series(logger_file(tmp_path / 'a.txt', rate='0'))
    bad = logger_file(tmp_path / 'b.txt', samples=10)
    bad.write_text(bad.read_text() + 'x\n')
    with pytest.raises(CsvError, match='data row 13 is not numbers'):
        read_csv_series(bad)
    plain = tmp_path / 'c.csv'
    plain.write_text('t, fs, y\n0, 100, 1\n0.01, 100, 2\n')
    assert read_csv_series(plain).y.tolist() == [100.0, 100.0]


WRENCH = 'geometry_msgs/msg/WrenchStamped'


def write_topics(path, topics):
    """A bag of 10 messages on each of ``topics`` (name: type), interleaved; value k + 1 on the
    k-th topic."""
    with BagWriter(path) as bag:
        ids = [(bag.add_topic(name, kind), kind) for name, kind in topics.items()]
        for s in (EPOCH + np.arange(10, dtype=np.int64)).tolist():
            for k, (topic, kind) in enumerate(ids):
                bag.write_message(topic, s, make_message(kind, s, 'f', k + 1.0, 0))


def test_a_bag_of_several_inputs_gives_the_topic_the_node_reads_by_default(tmp_path):
    """bags/README's example: the simulator's bag holds coupling_torque and the ground truth."""
    write_topics(
        tmp_path / 'sim',
        {'/vibration/ground_truth': 'std_msgs/msg/Float64', '/coupling_torque': WRENCH},
    )
    signal = open_signal(tmp_path / 'sim')
    assert signal.topic == '/coupling_torque' and signal.component == 'torque.z'


def test_topic_choice_and_errors(tmp_path):
    write_topics(tmp_path / 'two', {'/a': WRENCH, '/b': 'std_msgs/msg/Float64'})
    with pytest.raises(
        BagError,
        match=r'several input-type topics, choose one with --topic, '
        r'e\.g\. `vib-estimator analyze \S+ --topic /a`: '
        r'/a \(geometry_msgs/msg/WrenchStamped\)'
        r'.*/b \(std_msgs/msg/Float64\)',
    ):
        open_signal(tmp_path / 'two')
    assert open_signal(tmp_path / 'two', '/b').component == 'data'
    with pytest.raises(ValueError, match='component of std_msgs/msg/Float64'):
        open_signal(tmp_path / 'two', '/b', 'torque.z')
    shutil.copytree(tmp_path / 'two', tmp_path / 'noindex')
    (tmp_path / 'noindex' / 'metadata.yaml').unlink()
    with pytest.raises(BagError, match='vib-estimator reindex'):
        open_signal(tmp_path / 'noindex')


@pytest.mark.parametrize('name', ['mcap_wbag', 'sqlite3_wbag'])
def test_real_split_bags_list_their_topics(name):
    """Split bags of the real rosbag2 (String topics only): the error names the topics."""
    if not SHARED_BAGS.is_dir():
        pytest.skip('shared/ros2-bags is absent')
    with pytest.raises(BagError, match='no input-type topic; its topics are .*AAA'):
        open_signal(SHARED_BAGS / name)


def test_split_bag_is_read_across_its_files_in_log_time_order(tmp_path):
    """Two storage files whose times interleave (as rosbag2's wbag): merged by log time."""
    n = 400
    stamps = EPOCH + np.arange(n, dtype=np.int64) * 1_000_000
    halves = [stamps[0::2], stamps[1::2]]
    for i, part in enumerate(halves):
        write_wrench_series(tmp_path / f'p{i}', WrenchSeries(part, part * 1e-15, 'f', '/w'))
    split = tmp_path / 'split'
    split.mkdir()
    import yaml

    meta = yaml.safe_load((tmp_path / 'p0' / 'metadata.yaml').read_text())
    info = meta['rosbag2_bagfile_information']
    files = []
    for i in range(2):
        src = next((tmp_path / f'p{i}').glob('*.mcap'))
        shutil.copy(src, split / f'split_{i}.mcap')
        files.append(f'split_{i}.mcap')
    info['relative_file_paths'] = files
    info['files'] = [
        {
            'path': f,
            'starting_time': info['starting_time'],
            'duration': info['duration'],
            'message_count': n // 2,
        }
        for f in files
    ]
    info['message_count'] = n
    info['topics_with_message_count'][0]['message_count'] = n
    (split / 'metadata.yaml').write_text(yaml.safe_dump(meta))
    signal = open_signal(split)
    (t, y), _ = collect(signal)
    assert np.array_equal(y, stamps * 1e-15)


@pytest.mark.parametrize('mode', ['STORAGE', 'FILE', 'MESSAGE'])
def test_compressed_bags(tmp_path, mode):
    """zstd chunks (what rosbag2's MCAP writer does) on the fast path; whole-file and per-message
    compression through rosbags."""
    from rosbags.rosbag2 import CompressionFormat, CompressionMode, StoragePlugin, Writer

    from vib_estimator.io.bags import WRENCH_STAMPED, wrench_message

    n = 3000
    stamps = EPOCH + np.arange(n, dtype=np.int64) * 2_000_000
    values = np.cos(np.arange(n) * 0.1)
    writer = Writer(tmp_path / 'bag', version=8, storage_plugin=StoragePlugin.MCAP)
    writer.set_compression(getattr(CompressionMode, mode), CompressionFormat.ZSTD)
    with writer:
        conn = writer.add_connection('/w', WRENCH_STAMPED, typestore=TYPESTORE)
        for s, v in zip(stamps.tolist(), values.tolist()):
            writer.write(
                conn,
                s,
                TYPESTORE.serialize_cdr(wrench_message(s, 'f', 'torque.z', v), WRENCH_STAMPED),
            )
    (t, y), _ = collect(open_signal(tmp_path / 'bag'))
    assert y.tolist() == values.tolist()
    assert np.array_equal(t, (stamps - stamps[0]) * 1e-9)
    if mode == 'STORAGE':
        plan = mcap.read_plan(sorted((tmp_path / 'bag').glob('*.mcap')), '/w')
        with plan[0].path.open('rb') as handle:  # zstd chunks, read by the fast path
            assert mcap.read_chunk(handle, plan[0]).offsets.size > 0


@pytest.mark.parametrize(
    'error', [ImportError('not installed'), ImportError('pyarrow requires NumPy 2.0 or newer')]
)
def test_a_csv_reads_the_same_without_pyarrow(tmp_path, break_extra, capsys, error):
    """rosdep alone installs no pyarrow, and pyarrow 26 refuses numpy 1.26 as it loads: the exact
    reader gives the same samples, after one warning line."""
    path = tmp_path / 'a.csv'
    path.write_text('t,y\n' + '\n'.join(f'{i * 0.002},{np.sin(i / 7):.12g}' for i in range(3000)))
    with_arrow = [np.concatenate(c) for c in zip(*open_signal(path).blocks())]
    capsys.readouterr()
    break_extra('pyarrow', error)
    without = [np.concatenate(c) for c in zip(*open_signal(path).blocks())]
    assert [np.concatenate(c) for c in zip(*open_signal(path).blocks())][0].size == 3000
    warned = capsys.readouterr().err.splitlines()
    assert len(warned) == 1 and 'pyarrow unavailable' in warned[0] and str(error) in warned[0]
    without = [np.concatenate(c) for c in zip(*open_signal(path).blocks())]
    assert len(without[0]) == 3000
    assert all(np.array_equal(a, b) for a, b in zip(with_arrow, without))
