# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""``vib-estimator survey``: rows equal per-file analyze, bad recordings, the alarm, Dask."""

import csv
import json
import math
import os
from concurrent.futures.process import BrokenProcessPool
from pathlib import Path

import numpy as np
import pytest

from vib_estimator.analysis import survey as S
from vib_estimator.analysis.interval import combine
from vib_estimator.cli import main
from vib_estimator.core import EstimatorConfig
from vib_estimator.extras import optional
from vib_estimator.io.bags import WrenchSeries, write_wrench_series

EPOCH = 1_767_225_600 * 10**9
DAY = 86_400 * 10**9


def fleet(root, freqs, seed=0):
    """One 9 s bag per day, a noisy sine of the day's frequency (>= 6 estimates of 1.25 periods)"""
    rng = np.random.default_rng(seed)
    t = np.arange(0, 9, 0.002)
    for day, f in enumerate(freqs):
        y = 0.3 * np.sin(2 * np.pi * f * t + day) + 0.003 * rng.standard_normal(len(t))
        stamps = EPOCH + day * DAY + np.round(t * 1e9).astype(np.int64)
        write_wrench_series(root / f'day_{day:02d}', WrenchSeries(stamps, y, 'arm', '/torque'))
    return sorted(root.glob('day_*'))


def jsonl(text):
    return [json.loads(line) for line in text.splitlines()]


def test_rows_equal_per_file_analyze(tmp_path, capsys):
    days = fleet(tmp_path, [1.3, 1.31, 1.32])
    np.savetxt(
        tmp_path / 'sine.csv',
        np.column_stack([np.arange(4500) * 0.002, np.sin(np.arange(4500) * 0.002 * 9)]),
        delimiter=',',
        header='t,y',
        comments='',
    )
    assert main(['survey', str(tmp_path), '--format', 'jsonl', '--jobs', '1']) == 0
    rows = jsonl(capsys.readouterr().out)
    assert [r['recording'] for r in rows] == [str(p) for p in days] + [str(tmp_path / 'sine.csv')]
    for row in rows:
        analyze = ['analyze', row['recording'], '--model', S.DEFAULT_MODEL, '--format', 'jsonl']
        analyze += ['--min-periods', '1.25']  # survey's one window for every recording
        assert main(analyze) == 0
        out = capsys.readouterr()
        estimates = jsonl(out.out)
        freqs = np.array([e['frequency_hz'] for e in estimates])
        assert row['estimates'] == len(estimates) > 5
        assert row['frequency_median_hz'] == float(np.median(freqs))
        combined = combine(
            freqs,
            np.array([e['frequency_std_hz'] for e in estimates]),
            np.array([e['t'] for e in estimates]),
            np.array([e['convergence_time_s'] for e in estimates]),
        )
        assert math.isclose(row['frequency_hz'], combined.value, rel_tol=1e-12)
        assert math.isclose(row['frequency_std_hz'], combined.std, rel_tol=1e-9)
        assert row['frequency_lo_hz'] <= row['frequency_hz'] <= row['frequency_hi_hz']
        assert f'received={row["samples"]},' in out.err
        assert f'rejected_fit={row["rejected_fit"]},' in out.err
    assert (
        rows[0]['start_utc'] == '2026-01-01T00:00:00Z'
        and rows[1]['start_utc'][:10] == '2026-01-02'
    )
    assert rows[-1]['start_utc'] == '' and rows[-1]['topic'] == ''
    assert math.isclose(rows[0]['duration_s'], 8.998)


def test_a_corrupt_recording_is_one_error_row(tmp_path, capsys):
    fleet(tmp_path, [1.3, 1.3])
    (tmp_path / 'broken.mcap').write_bytes(b'\x89MCAP0\r\n garbage')
    (tmp_path / 'bad.csv').write_text('t,y\n0,1\n0.1,x\n')
    args = ['survey', str(tmp_path), '--format', 'csv', '--jobs', '2']
    assert main(args) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[0].split(',')[:4] == ['recording', 'topic', 'component', 'mode']
    errors = [line for line in lines[1:] if not line.endswith(',False,')]
    assert len(lines) == 5 and len(errors) == 2
    assert 'not numbers' in errors[0] and 'broken.mcap' in errors[1]
    assert main(args + ['--strict']) == 1
    capsys.readouterr()


def survey_args(folder, baseline):
    """``survey`` of a folder against a baseline (recording or Hz): 2 % alarm, JSONL, one job,
    exit 3 on an alarm."""
    return [
        'survey',
        str(folder),
        '--baseline',
        str(baseline),
        '--alarm-rel',
        '0.02',
        '--format',
        'jsonl',
        '--jobs',
        '1',
        '--fail-on-alarm',
    ]


def test_alarm_on_a_seeded_drift_and_none_without(tmp_path, capsys):
    drift = fleet(tmp_path / 'drift', [1.3] * 4 + [1.3 * 0.95] * 2)
    steady = fleet(tmp_path / 'steady', [1.3] * 6, seed=1)
    out = tmp_path / 'rows.parquet'
    assert (
        main(
            [
                *survey_args(tmp_path / 'drift', drift[0]),
                '--out',
                str(out),
                '--plot',
                str(tmp_path / 'trend.png'),
            ]
        )
        == 3
    )
    rows = jsonl(capsys.readouterr().out)
    assert [r['alarm'] for r in rows] == [False] * 4 + [True] * 2
    assert all(-0.06 < r['change_rel'] < -0.04 for r in rows[4:])
    pq = optional('pyarrow.parquet')
    if pq is not None:
        assert pq.read_table(out).column('alarm').to_pylist() == [r['alarm'] for r in rows]
    else:  # a pyarrow that does not load (26 beside numpy 1.26): the rows as CSV beside
        with out.with_suffix('.csv').open() as handle:
            assert [r['alarm'] == 'True' for r in csv.DictReader(handle)] == [
                r['alarm'] for r in rows
            ]
    assert (tmp_path / 'trend.png').is_file()  # its content: the figures' own tests
    assert (
        main(
            [
                *survey_args(tmp_path / 'steady', 1.3),
            ]
        )
        == 0
    )
    rows = jsonl(capsys.readouterr().out)
    # every steady day is a row, measured against the 1.3 Hz baseline, within the band: no alarm
    assert [r['recording'] for r in rows] == [str(p) for p in steady]
    assert all(
        abs(r['change_rel']) < 0.005 and r['change_lo'] <= r['change_rel'] <= r['change_hi']
        for r in rows
    ), [r['change_rel'] for r in rows]
    assert [r['alarm'] for r in rows] == [False] * len(steady)


@pytest.mark.parametrize(
    'args, message',
    [
        (['--baseline', 'nowhere'], 'neither a frequency'),
        (['--out', 'x.xlsx'], '--out must end'),
        (['--jobs', '0'], '--jobs'),
    ],
)
def test_bad_arguments_exit_2(tmp_path, capsys, args, message):
    assert main(['survey', str(tmp_path)] + args) == 2
    err = capsys.readouterr().err
    assert message in err and len(err.strip().splitlines()) == 1


def test_median_interval():
    x = np.arange(100.0)
    f, lo, hi = S.median_interval(x)
    assert (f, lo, hi) == (49.5, 39.0, 60.0)
    assert math.isnan(S.median_interval(np.arange(5.0))[1])


def test_dask_cluster_gives_identical_rows(tmp_path):
    distributed = pytest.importorskip('distributed')
    recordings = S.find_recordings(
        [str(p) for p in fleet(tmp_path, [1.3, 1.35, 1.4])] + [str(tmp_path / 'missing.mcap')]
    )
    options = S.Options(EstimatorConfig())
    local = S.survey(recordings, options, jobs=1)
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
    ) as cluster:
        remote = S.survey(recordings, options, scheduler=cluster.scheduler_address)
    assert json.dumps(remote) == json.dumps(local)
    assert local[-1]['error'] and not local[0]['error']


def test_kept_pool_gives_identical_rows_and_outlives_a_dead_worker(tmp_path):
    recordings = S.find_recordings([str(p) for p in fleet(tmp_path, [1.3, 1.35, 1.4])])
    options = S.Options(EstimatorConfig())
    local = S.survey(recordings, options, jobs=1)
    first = S.survey(recordings, options, jobs=2)
    pool = S.local_pool(2)
    assert json.dumps(S.survey(recordings, options, jobs=2)) == json.dumps(local)
    assert S.local_pool(2) is pool and json.dumps(first) == json.dumps(local)
    with pytest.raises(BrokenProcessPool):
        pool.submit(os._exit, 1).result()  # a worker dies: the kept pool is broken for good
    assert json.dumps(S.survey(recordings, options, jobs=2)) == json.dumps(local)
    assert S.local_pool(2) is not pool


FAULTS = """
import resource, sys
from pathlib import Path
from vib_estimator.analysis import survey as S
from vib_estimator.analysis.interval import combine
from vib_estimator.core import EstimatorConfig
path, options = Path(sys.argv[1]), S.Options(EstimatorConfig())
def faults(task):
    before = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
    assert task(path, options)[0]['error'] == ''
    return resource.getrusage(resource.RUSAGE_SELF).ru_minflt - before
S.survey_recording(path, options)                       # compile, import everything
print(faults(S._recording_rows), faults(S.survey_recording))
"""


def test_a_worker_started_with_a_malloc_trim_threshold_streams_without_remapping(tmp_path):
    """Dask's nanny starts workers with MALLOC_TRIM_THRESHOLD_=65536, which also fixes glibc's
    mmap threshold at 128 KiB: without the survey task's own thresholds, every block-sized array
    is mapped and faulted in again."""
    if optional('pyarrow.csv') is None:  # e.g. pyarrow 26 beside numpy 1.26 (Ubuntu 24.04)
        pytest.skip('pyarrow unavailable: the exact CSV reader makes no block-sized arrays')
    import os
    import subprocess
    import sys

    t = np.arange(400_000) * 0.002
    np.savetxt(
        tmp_path / 'long.csv',
        np.column_stack([t, np.sin(9 * t)]),
        delimiter=',',
        header='t,y',
        comments='',
        fmt='%.6f',
    )
    env = {k: v for k, v in os.environ.items() if not k.startswith('MALLOC_')}
    env['MALLOC_TRIM_THRESHOLD_'] = '65536'
    out = subprocess.run(
        [sys.executable, '-c', FAULTS, str(tmp_path / 'long.csv')],
        env=env,
        capture_output=True,
        text=True,
        check=True,
    ).stdout
    plain, tuned = map(int, out.split())
    assert tuned < 0.5 * plain, (plain, tuned)


def test_malloc_is_left_alone_in_a_plain_process(monkeypatch):
    monkeypatch.delenv('MALLOC_TRIM_THRESHOLD_', raising=False)
    from vib_estimator.io import heap

    monkeypatch.setattr(heap.ctypes, 'CDLL', lambda *a: pytest.fail('mallopt called'))
    with S.streaming_malloc():
        pass


def test_every_entry_of_a_folder_is_accounted_for(tmp_path, capsys):
    """Corrupt, empty and non-bag entries each get an error row (or a counted skip) and a stderr
    line; a plain folder and stray files are no longer silent (issue 22, case 8)."""
    from vib_estimator.io import mcap

    (good,) = fleet(tmp_path, [1.3])
    damaged = tmp_path / 'damaged'
    fleet(damaged, [1.3])
    file = next((damaged / 'day_00').glob('*.mcap'))
    _, _, start, length, _ = mcap.read_summary(file).chunks[1]
    data = bytearray(file.read_bytes())
    data[start + length // 2] ^= 0xFF
    file.write_bytes(bytes(data))
    (tmp_path / 'empty.mcap').write_bytes(b'')
    (tmp_path / 'docs').mkdir()
    (tmp_path / 'docs' / 'notes.txt').write_text('not a recording')
    (tmp_path / 'nothing').mkdir()
    (tmp_path / 'README.md').write_text('fleet')
    args = ['survey', str(tmp_path), '--format', 'jsonl', '--jobs', '1']
    assert main(args) == 0
    out = capsys.readouterr()
    rows = {Path(r['recording']).relative_to(tmp_path).as_posix(): r for r in jsonl(out.out)}
    assert set(rows) == {'day_00', 'damaged/day_00', 'empty.mcap', 'docs', 'nothing'}
    assert rows['day_00']['error'] == '' and rows['day_00']['corrupt_records'] == 0
    hurt = rows['damaged/day_00']
    assert hurt['error'] == '' and hurt['corrupt_records'] > 0
    assert hurt['samples'] + hurt['corrupt_records'] == rows['day_00']['samples']
    for name in ('empty.mcap', 'docs', 'nothing'):
        assert rows[name]['error'], name
    assert 'not a rosbag2 bag' in rows['docs']['error']
    err = out.err.splitlines()
    assert sum('error:' in line for line in err) == 3
    assert sum('warning:' in line and 'damaged/day_00' in line for line in err) == 1
    assert any('notes.txt' in line for line in err) and any('README.md' in line for line in err)
    assert main(args + ['--strict']) == 1
    strict = {
        Path(r['recording']).relative_to(tmp_path).as_posix(): r
        for r in jsonl(capsys.readouterr().out)
    }
    assert 'damaged' in strict['damaged/day_00']['error']


def legend_texts(ax):
    return [x.get_text() for x in ax.get_legend().get_texts()]


def test_without_its_extras_survey_warns_once_each_and_falls_back(tmp_path, capsys, break_extra):
    """pyarrow, tqdm and distributed failing as they load (a wheel built for numpy 2 beside numpy
    1.26, say): the same rows, each extra one warning line; the .parquet rows as .csv beside,
    --scheduler on the local pool, no progress bar; exit 0."""
    fleet(tmp_path / 'fleet', [1.3, 1.31, 1.32])
    t = np.arange(3000) * 0.002
    signal = np.column_stack([t, np.sin(9 * t)])
    np.savetxt(tmp_path / 'fleet' / 'sine.csv', signal, delimiter=',', header='t,y', comments='')
    args = ['survey', str(tmp_path / 'fleet'), '--format', 'jsonl', '--jobs', '1']
    assert main(args) == 0
    expected = jsonl(capsys.readouterr().out)
    for package in ('pyarrow', 'tqdm', 'distributed'):
        break_extra(package, RuntimeError(f'{package} built for another ABI'))
    out = tmp_path / 'rows.parquet'
    assert main([*args, '--out', str(out), '--scheduler', 'tcp://127.0.0.1:9']) == 0
    got = capsys.readouterr()
    assert jsonl(got.out) == expected
    warned = [line for line in got.err.splitlines() if 'warning: optional package' in line]
    assert sorted(w.split()[4] for w in warned) == ['distributed', 'pyarrow', 'tqdm'], got.err
    assert 'Traceback' not in got.err and not out.exists()
    with out.with_suffix('.csv').open() as handle:
        written = [r['recording'] for r in csv.DictReader(handle)]
    assert written == [r['recording'] for r in expected]


def test_trend_plot_shows_the_baseline_and_the_alarm_band(tmp_path):
    days = fleet(tmp_path / 'fleet', [1.3] * 4 + [1.3 * 0.95] * 2)
    options = S.Options(EstimatorConfig(), (), (), None, False)
    rows = S.survey(S.find_recordings([str(tmp_path / 'fleet')]), options)
    base = S.baseline_rows(str(days[0]), options)
    S.flag(rows, base, 0.02)
    fig = S.plot_trend(rows, tmp_path / 'trend.png', base, 0.02)
    assert len(fig.axes) == 1  # no damping estimated: no damping panel
    ax = fig.axes[0]
    labels = legend_texts(ax)
    f0 = base[None][0]
    assert f'baseline {f0:.5g} Hz' in labels and 'alarm' in labels
    assert 'no-alarm band: baseline 95 % interval ±2 %' in labels
    assert ax.get_ylabel() == 'frequency (Hz)'
    baseline = [line for line in ax.get_lines() if line.get_label().startswith('baseline')][0]
    assert np.allclose(baseline.get_ydata(), f0)
    band = [p for p in ax.patches if p.get_label().startswith('no-alarm band')][0]
    lo, hi = S.alarm_band(base[None], 0.02)
    # the band's extent in data units, from its outline on the canvas: axhspan returns a Polygon
    # under matplotlib < 3.9 (Ubuntu 24.04's 3.6) and a Rectangle after
    y = ax.transData.inverted().transform(band.get_verts())[:, 1]
    assert np.isclose(y.min(), lo) and np.isclose(y.max(), hi)
    for r in rows:  # the picture's rule is flag()'s: interval wholly outside
        outside = r['frequency_hi_hz'] < lo or r['frequency_lo_hz'] > hi
        assert r['alarm'] == outside
    assert sum(r['alarm'] for r in rows) == 2
    for r in rows:
        r['damping'] = 0.01
    fig = S.plot_trend(rows, tmp_path / 'trend2.png', base, 0.02)
    assert [a.get_ylabel() for a in fig.axes] == ['frequency (Hz)', 'damping ratio']
    assert all(np.allclose(line.get_ydata(), 0.01) for line in fig.axes[1].get_lines())


def test_links_to_recordings_are_followed_and_counted(tmp_path, capsys):
    """A folder of symbolic links to bag folders and files (a cycle included) is surveyed as the
    recordings themselves, and stderr says how many were found (issue 40)."""
    store = tmp_path / 'store'
    days = fleet(store, [1.3, 1.31])
    np.savetxt(store / 'sine.csv', np.column_stack([np.arange(4500) * 0.002] * 2), delimiter=',')
    links = tmp_path / 'links'
    links.mkdir()
    for day in days:
        (links / day.name).symlink_to(day, target_is_directory=True)
    (links / 'sine.csv').symlink_to(store / 'sine.csv')
    (links / 'loop').symlink_to(links, target_is_directory=True)
    assert main(['survey', str(links), '--format', 'jsonl', '--jobs', '1']) == 0
    out = capsys.readouterr()
    rows = jsonl(out.out)
    assert [Path(r['recording']).name for r in rows] == ['day_00', 'day_01', 'sine.csv']
    assert not any(r['error'] for r in rows[:2]) and rows[0]['estimates'] > 5
    assert f'3 recording(s) found in {links}' in out.err


@pytest.mark.parametrize('make', ['empty', 'missing', 'only_text'])
def test_no_recording_found_is_one_error_line_exit_2(tmp_path, capsys, make):
    target = tmp_path / 'fleet'
    if make != 'missing':
        target.mkdir()
    if make == 'only_text':
        (target / 'sub').mkdir()
        (target / 'sub' / 'notes.txt').write_text('not a recording')
    assert main(['survey', str(target)]) == 2
    out = capsys.readouterr()
    assert out.out == ''
    assert out.err.count('\n') == 1 and 'error: no recording found in' in out.err


def test_used_counts_the_samples_used_under_every_excitation(tmp_path, capsys):
    """A mode's row carries the stream's input counters (ambient reported used 0 for 12 000
    samples used, issue 40)."""
    from vib_estimator.sim.frame import modal_record

    t, y = modal_record(80.0, 20.0, [(1.0, 0.02, 1.0)], np.ones((1, 1)), snr_db=20.0, seed=1)
    y = y.reshape(len(t))
    y[100] = np.nan
    np.savetxt(tmp_path / 'run.csv', np.column_stack([t, y]), delimiter=',', header='t,y')
    for excitation in ('free', 'ambient'):
        args = ['survey', str(tmp_path), '--format', 'jsonl', '--excitation', excitation]
        assert main(args + ['--modes', '1', '--ambient-window-s', '40']) == 0
        (row,) = jsonl(capsys.readouterr().out)
        assert row['mode'] == 1 and (row['estimates'] > 0 or excitation == 'free'), excitation
        assert row['samples'] == len(t) and row['skipped_non_finite'] == 1, excitation
        assert row['used'] == len(t) - 1, excitation


def test_trend_legend_is_beside_the_axes_each_entry_once_and_lines_break_at_gaps(tmp_path):
    """Two modes, one missing on a day: no line across that day; 'alarm' listed once."""
    rows = []
    for day in range(4):
        for mode, f in ((1, 1.3), (2, 3.1)):
            if mode == 2 and day == 2:
                continue  # not found that day
            drift = 0.95 if day == 3 else 1.0
            rows.append(
                S._row(
                    Path(f'day_{day}'),
                    '/t',
                    'torque.z',
                    mode,
                    start_utc=f'2026-01-0{day + 1}T00:00:00Z',
                    frequency_hz=f * drift,
                    frequency_lo_hz=f * drift * 0.999,
                    frequency_hi_hz=f * drift * 1.001,
                    alarm=day == 3,
                )  # fmt: skip
            )
    fig = S.plot_trend(rows, tmp_path / 'trend.png', {None: (1.3, 1.29, 1.31)}, 0.02)
    ax = fig.axes[0]
    labels = legend_texts(ax)
    assert len(labels) == len(set(labels)) and labels.count('alarm') == 1
    assert ax.get_legend().get_bbox_to_anchor().x0 > ax.get_window_extent().x1 - 1
    ys = [
        np.asarray(line.get_ydata(), float)
        for line in ax.get_lines()
        if len(line.get_ydata()) == 4
    ]
    assert any(np.isnan(y[2]) and np.isfinite(y[[0, 1, 3]]).all() for y in ys), ys


def test_survey_report_page(tmp_path, capsys):
    days = fleet(tmp_path / 'drift', [1.3] * 3 + [1.3 * 0.95] * 2)
    folder = tmp_path / 'page'
    args = [*survey_args(tmp_path / 'drift', days[0]), '--report', str(folder)]
    assert main(args) == 3
    out = capsys.readouterr()
    rows = jsonl(out.out)
    page = (folder / 'index.html').read_text()
    assert f'report written to {folder / "index.html"}' in out.err
    assert page.count('<tr class="alarm">') == sum(r['alarm'] for r in rows) == 2
    assert all(f'{r["frequency_hz"]:.5f}' in page for r in rows)
    assert '<img src="trend.png"' in page and (folder / 'trend.png').stat().st_size > 10_000
    from PIL import Image

    with Image.open(folder / 'trend.png') as im:
        im.load()


def test_a_decay_the_free_estimator_leaves_silent_is_surveyed_by_the_mode_tracker(
    tmp_path, capsys
):
    """A lightly damped 5 Hz pluck at 20 samples a period in 20 dB, after 1 s of rest: the free
    estimator (survey's one window, 1.25 periods) gives 6 estimates over the 91 periods the decay
    rings above its noise (none until 6 Dec 2026, when its segment begun in the rest stalled:
    core.kernel._stalled), under RESCUE_SHARE of the 73 its window allows; the recording is read
    again by the mode tracker (analysis.choosing.rescue), its mode 1 within 1 % of 5 Hz on 30
    estimates or more. ``--excitation free`` keeps the free estimator's few."""
    rng = np.random.default_rng(0)
    t = np.arange(0, 1 + 5 / (0.005 * 2 * np.pi * 5), 0.01)
    tau = np.clip(t - 1.0, 0, None)
    y = np.exp(-0.005 * 2 * np.pi * 5 * tau) * np.sin(2 * np.pi * 5 * tau + rng.uniform(0, 6.28))
    y = y * (t >= 1.0) + 0.1 / np.sqrt(2) * rng.standard_normal(len(t))
    np.savetxt(tmp_path / 'pluck.csv', np.column_stack([t, y]), delimiter=',', header='t,y')
    assert main(['survey', str(tmp_path), '--format', 'jsonl', '--jobs', '1']) == 0
    rows = jsonl(capsys.readouterr().out)
    assert rows[0]['mode'] == 1 and rows[0]['estimates'] >= 30
    assert abs(rows[0]['frequency_hz'] / 5 - 1) < 0.01
    args = ['survey', str(tmp_path), '--format', 'jsonl', '--jobs', '1', '--excitation', 'free']
    assert main(args) == 0
    (row,) = jsonl(capsys.readouterr().out)
    assert row['mode'] == 0 and 0 < row['estimates'] < 10


def test_a_folder_of_whitespace_tables_is_searched(tmp_path, capsys):
    """An instrument's ``.asc``/``.dat`` exports (columns aligned by spaces, the time first) are
    recordings in a folder's search, as ``.csv`` files are; a ``.txt`` there is a note."""
    t = np.arange(0, 6, 0.002)
    y = np.exp(-0.02 * 2 * np.pi * 3 * t) * np.sin(2 * np.pi * 3 * t)
    for name in ('a.asc', 'b.dat'):
        (tmp_path / name).write_text(''.join(f'{a:14.6f}{b:14.6f}\n' for a, b in zip(t, y)))
    (tmp_path / 'notes.txt').write_text('not a recording')
    assert main(['survey', str(tmp_path), '--format', 'jsonl', '--jobs', '1']) == 0
    out = capsys.readouterr()
    rows = jsonl(out.out)
    assert sorted(Path(r['recording']).name for r in rows) == ['a.asc', 'b.dat']
    assert all(not r['error'] and abs(r['frequency_hz'] / 3 - 1) < 0.01 for r in rows)
    assert any('notes.txt' in line and 'ignored' in line for line in out.err.splitlines())
