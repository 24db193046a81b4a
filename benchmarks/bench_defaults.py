# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""What a newcomer gets: ``vib-estimator analyze FILE`` with no option but the column(s), on the
kinds of record users bring, beside ``--excitation free`` (the default until 4 Dec 2026) and the
documented tuned options, in the same run; and ``estimator_node``'s defaults on the same record
streamed (its :class:`~vib_estimator.nodes.stream.EstimatorStream`, in process, one status a
second of the record, each ``decide_excitation`` decision applied as the node applies it).

Records: free decays (synthetic, the simulated arm's bag, the real aluminium beams and the real
flexible-link arm when ``../shared/real-data`` is there), white-noise-driven modes (one, two,
three, a close pair, a lightly damped one), the simulated arm driven without rest (a random
command, a tip disturbance), the 5-storey shear frame (5 channels) and the Heritage Court Tower
(6 channels, published modes). Per record and configuration: estimates, true modes found (an
estimate within 2 %), the share of estimates within 2 % of the nearest true mode, how many are
beyond 5 % (spurious or wrong), the median convergence in periods (free decays), the frame's
lowest MAC with the true shapes, and the CPU seconds.

    cd benchmarks && ../.venv/bin/python bench_defaults.py [--real-data ../../shared/real-data]
    cd benchmarks && ../.venv/bin/python bench_defaults.py --node-only   # the node's rows alone
"""

from __future__ import annotations

import argparse
import contextlib
import io
import json
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from vib_estimator.cli import main as cli
from vib_estimator.core import EstimatorConfig
from vib_estimator.io.csv_reader import read_csv_columns, read_csv_series
from vib_estimator.nodes.stream import EstimatorStream
from vib_estimator.sim import arm_model
from vib_estimator.sim.ambient import ambient_record
from vib_estimator.sim.frame import frame_record

ROOT = Path(__file__).resolve().parents[1]
#: Heritage Court Tower, setup 1: the published modes (SOURCE.md)
HCT_MODES = (1.23, 1.29, 1.45, 3.85, 4.26, 5.35)
#: the real beams' first modes, their own FFT (real_data.py), and their second modes, the
#: authors' (SOURCE.md: points_data.csv), which a default may report
BEAMS = {30: (16.360, 107.6), 40: (9.392, 61.54), 50: (6.054, 39.63), 60: (4.268, 27.35)}


def write_csv(folder: Path, name: str, t, y) -> Path:
    y = np.asarray(y).reshape(len(t), -1)
    path = folder / f'{name}.csv'
    header = 'time_s,' + ','.join(f'ch{i + 1}' for i in range(y.shape[1]))
    np.savetxt(
        path, np.column_stack([t, y]), delimiter=',', header=header, comments='', fmt='%.9g'
    )
    return path


def records(folder: Path, real: Path | None):
    """(name, kind, path, selection args, true frequencies, tuned args, true shapes or None)."""
    out = []
    t = np.arange(0, 10, 0.002)
    rng = np.random.default_rng(0)
    y = np.exp(-0.01 * 2 * np.pi * 5 * t) * np.sin(2 * np.pi * 5 * t)
    y += 0.01 * rng.standard_normal(len(t))
    out.append(('decay 5 Hz', 'free', write_csv(folder, 'decay5', t, y), [], [5.0], ['--paper']))
    # an IMU's rate: a 10 Hz pluck after 2 s of rest at 100 samples/s (10 samples a period)
    t = np.arange(0, 12, 0.01)
    tau = np.maximum(t - 2.0, 0)
    y = np.exp(-0.005 * 2 * np.pi * 10 * tau) * np.sin(2 * np.pi * 10 * tau + 1) * (t >= 2)
    y += 0.01 / np.sqrt(2) * np.random.default_rng(10).standard_normal(len(t))  # (rng's draws
    path = write_csv(folder, 'decay10at100', t, y)  # for the records below unchanged)
    out.append(('decay 10 Hz at 100 Hz', 'free', path, [], [10.0], ['--modes', '3']))
    for name, modes in (
        ('decay 10 / 13 Hz, 1:0.5', ((10.0, 1.0, 0.003), (13.0, 0.5, 0.003))),
        ('decay 8 / 21 / 55 Hz', ((8.0, 1.0, 0.003), (21.0, 0.3, 0.002), (55.0, 0.05, 0.002))),
    ):
        t = np.arange(0, 11, 0.001)
        tau = np.maximum(t - 1.0, 0)
        y = sum(
            a * np.exp(-z * 2 * np.pi * f * tau) * np.sin(2 * np.pi * f * tau) for f, a, z in modes
        )
        y += 0.05 / np.sqrt(2) * 10 ** (-1.5) * rng.standard_normal(len(t))
        path = write_csv(folder, name.split(',')[0].replace(' ', '').replace('/', '_'), t, y)
        out.append((name, 'free', path, [], [m[0] for m in modes], ['--modes', '3']))
    rec = arm_model.experiment_5_3(0)
    path = write_csv(folder, 'arm53', rec.t, rec.torque)
    out.append(('arm 5.3 (sim)', 'free', path, [], [1.3306], ['--paper']))
    # added 6 Dec 2026 (bench_hard_records.py): a heavily damped pluck, one beside mains hum
    for name, zeta, seconds, hum, tuned in (
        ('decay 5 Hz, zeta 5 %', 0.05, 4.2, 0.0, ['--modes', '3']),
        ('decay 5 Hz beside 3 % hum', 0.01, 40.0, 0.03, ['--band-hz', '1.58', '15.8']),
    ):
        t = np.arange(0, seconds, 0.001)
        tau = np.maximum(t - 1.0, 0)
        y = np.exp(-zeta * 2 * np.pi * 5 * tau) * np.sin(2 * np.pi * 5 * tau + 1) * (t >= 1)
        y += hum * np.sin(2 * np.pi * 50 * t)
        y += 10**-1.5 / np.sqrt(2) * np.random.default_rng(11).standard_normal(len(t))
        path = write_csv(folder, name.split(',')[0].replace(' ', '_'), t, y)
        out.append((name, 'free', path, [], [5.0], tuned))
    cases = {
        '5 Hz, zeta 1 %': [(5.0, 0.01, 1.0)],
        '5 Hz, zeta 0.2 %': [(5.0, 0.002, 1.0)],
        '5 + 17 Hz': [(5.0, 0.01, 1.0), (17.0, 0.005, 0.3)],
        '3 + 11 + 23 Hz': [(3.0, 0.02, 1.0), (11.0, 0.01, 0.5), (23.0, 0.005, 0.2)],
        '8 / 8.8 Hz': [(8.0, 0.01, 1.0), (8.8, 0.01, 1.0)],
        '2 Hz, zeta 0.2 %': [(2.0, 0.002, 1.0)],
    }
    for i, (name, modes) in enumerate(cases.items()):
        t, y, _ = ambient_record(180, 500, modes, 20, 0)
        path = write_csv(folder, f'driven{i}', t, y)
        out.append(
            (
                f'driven {name}',
                'driven',
                path,
                [],
                [m[0] for m in modes],
                ['--excitation', 'ambient'],
            )
        )
    t, y, _ = ambient_record(20, 500, cases['5 + 17 Hz'], 20, 0)  # a short record (6 Dec)
    path = write_csv(folder, 'driven_short', t, y)
    tuned = ['--excitation', 'ambient', '--ambient-window-s', '10']
    out.append(('driven 5 + 17 Hz, 20 s', 'driven', path, [], [5.0, 17.0], tuned))
    for drive, level in (('random', 0.3), ('ambient', 0.02)):
        rec = arm_model.simulate_driven(180, drive, level, seed=0)
        path = write_csv(folder, f'arm_{drive}', rec.t, rec.torque)
        out.append(
            (
                f'arm driven ({drive})',
                'driven',
                path,
                [],
                [float(rec.f_true[0])],
                ['--excitation', 'ambient'],
            )
        )
    for name, every, jitter in (
        ('moved at random times', 1.5, 0.5),
        ('moved every 0.8 s', 0.8, 0),
    ):
        rec = arm_model.back_and_forth(300, every, 0.5 if jitter else 0.3, 1.0, jitter)
        path = write_csv(folder, f'arm_moves_{every:g}', rec.t, rec.torque)
        tuned = ['--excitation', 'ambient']
        out.append((f'arm {name}', 'driven', path, [], [float(rec.f_true[0])], tuned))
    t, y, freqs, shapes = frame_record(300, 50, seed=0)
    path = write_csv(folder, 'frame', t, y)
    tuned = ['--excitation', 'ambient', '--ambient-window-s', '60']
    out.append(
        ('shear frame, 5 ch', 'frame', path, ['--columns', 'all'], list(freqs), tuned, shapes)
    )
    if real is not None:
        for length, modes in BEAMS.items():
            path = real / 'aluminium_cantilever_adxl357' / f'{length}cm_uniform_1000Hz.csv'
            out.append((f'real beam {length} cm', 'free', path, [], list(modes), ['--paper']))
        path = real / 'flexible_link_arm' / 'flex8.csv'
        out.append(('real arm flex8', 'free', path, ['--column', 'tip_deflection_m'], [1.812], []))
        path = real / 'heritage_court_tower' / 'hct_setup1.csv'
        tuned = ['--excitation', 'ambient', '--ambient-window-s', '120', '--band-hz', '0.5', '6']
        out.append(('HCT setup 1, 6 ch', 'building', path, ['--columns', 'all'], HCT_MODES, tuned))
    return [r if len(r) == 7 else (*r, None) for r in out]


def run(path: Path, args: list[str]):
    """The rows ``analyze`` prints (JSONL), its stderr, the CPU seconds."""
    out, err = io.StringIO(), io.StringIO()
    start = time.process_time()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = cli(['analyze', str(path), '--format', 'jsonl', *args])
    cpu = time.process_time() - start
    rows = [json.loads(line) for line in out.getvalue().splitlines() if line.startswith('{')]
    return code, rows, err.getvalue(), cpu


def streamed(path: Path, select: list[str]):
    """``estimator_node``'s defaults on the record streamed (module doc): exit 0, its estimates as
    ``analyze``'s rows, the decisions (excitation and window, in words), the CPU seconds."""
    if select[:1] == ['--columns']:
        t, y, names = read_csv_columns(path, select[1])
    else:
        series = read_csv_series(path, select[1] if select else None)
        t, y, names = series.t, series.y, ['y']
    start = time.process_time()
    channels = names if np.ndim(y) == 2 and len(names) > 1 else ()
    stream = EstimatorStream(EstimatorConfig(), now=0.0, channels=channels, deciding=True)
    stamps = (np.round((t - t[0]) * 1e9) + 10**18).astype(np.int64).tolist()
    values = [tuple(v) for v in y.tolist()] if channels else np.ravel(y).tolist()
    rows, decided, next_status = [], [], float(t[0]) + 1.0
    for k, (stamp, value) in enumerate(zip(stamps, values)):
        for e in stream.feed(stamp, value):
            row = {'t': e.t, 'frequency_hz': e.frequency_hz}
            row['convergence_time_s'] = e.convergence_time
            shape = getattr(e, 'shape', None)
            for i, a in enumerate(() if shape is None else shape.tolist()):
                row[f'shape_ch{i + 1:02d}'] = float(np.real(a))
            rows.append(row)
        if t[k] >= next_status:
            next_status += 1.0
            stream.status(now=float(t[k]))
            decision = stream.decision()
            if decision is not None:
                stream.configure(stream.config.replace(**decision.changes()), prime=True)
                stream.decided = True
                what = f'{decision.window_s:.0f} s'
                if decision.excitation == 'free':
                    what = (
                        f'modes {decision.modes}'
                        if decision.modes
                        else f'min_periods {decision.min_periods:g}'
                    )
                decided.append(f'{decision.excitation} {what} at {t[k]:.0f} s')
    return 0, rows, ', '.join(decided), time.process_time() - start


def mac(a: np.ndarray, b: np.ndarray) -> float:
    return float(abs(np.vdot(a, b)) ** 2 / (np.vdot(a, a).real * np.vdot(b, b).real))


def score(rows, truth, kind, shapes=None) -> str:
    if not rows:
        return '0 | 0/%d | - | - | - | -' % len(truth)
    f = np.array([r['frequency_hz'] for r in rows])
    truth = np.asarray(truth)
    rel = f[:, None] / truth[None, :] - 1
    nearest = np.argmin(np.abs(rel), axis=1)
    err = rel[np.arange(len(f)), nearest]
    found = sum(np.any((nearest == k) & (np.abs(err) <= 0.02)) for k in range(len(truth)))
    conv = '-'
    if kind == 'free':
        c = np.array([r['convergence_time_s'] for r in rows]) * truth[nearest]
        conv = f'{np.median(c):.2f}'
    low_mac = '-'
    if shapes is not None:
        macs = []
        for k in range(len(truth)):
            sel = [i for i in range(len(rows)) if nearest[i] == k and abs(err[i]) <= 0.02]
            if not sel:
                continue
            keys = sorted(key for key in rows[0] if key.startswith('shape_ch'))
            amp = np.median([[rows[i][key] for key in keys] for i in sel], axis=0)
            macs.append(mac(amp, shapes[:, k]))
        low_mac = f'{min(macs):.3f}' if macs else '-'
    within = 100 * np.mean(np.abs(err) <= 0.02)
    beyond = int(np.sum(np.abs(err) > 0.05))
    return f'{len(f)} | {found}/{len(truth)} | {within:.1f} % | {beyond} | {conv} | {low_mac}'


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--real-data', default=str(ROOT.parent / 'shared' / 'real-data'))
    parser.add_argument(
        '--node-only',
        action='store_true',
        help="only the node's defaults, streamed, with the stream time of the first estimate",
    )
    args = parser.parse_args()
    real = Path(args.real_data)
    real = real if real.is_dir() else None
    if args.node_only:
        return node_only(real)
    header('configuration', 'CPU s', 'decided')
    with tempfile.TemporaryDirectory() as tmp:
        for name, kind, path, select, truth, tuned, shapes in records(Path(tmp), real):
            for label, extra in (
                ('default (no option)', []),
                ('--excitation free', ['--excitation', 'free']),
                ('tuned: ' + (' '.join(tuned) or 'defaults'), tuned),
            ):
                if label.startswith('tuned') and not tuned:
                    continue
                code, rows, err, cpu = run(path, select + extra)
                decided = ''
                for line in err.splitlines():
                    if 'the default decides from the record' in line:
                        decided = line.split('analyze: excitation ')[1].split(' (')[0]
                        window = (
                            line.split('; window ')[1].split(' s')[0]
                            if '; window ' in line
                            else ''
                        )
                        decided += f' {window} s' if window else ''
                status = score(rows, truth, kind, shapes) if code == 0 else f'exit {code}'
                print(f'| {name} | {label} | {status} | {cpu:.1f} | {decided} |')
                sys.stdout.flush()
            code, rows, decided, cpu = streamed(path, select)
            status = score(rows, truth, kind, shapes)
            print(f'| {name} | node defaults, streamed | {status} | {cpu:.1f} | {decided} |')
            sys.stdout.flush()
        cost(Path(tmp))
    return 0


def header(before: str, after: str, last: str) -> None:
    """The table's two header lines: the record, ``before`` (if any), :func:`score`'s columns,
    then ``after`` and ``last``."""
    scored = 'estimates | modes found | within 2 % | > 5 % | median conv (periods) | lowest MAC'
    columns = ' | '.join(c for c in ('record', before, scored, after, last) if c)
    print(f'| {columns} |')
    print('|' + '---|' * (columns.count('|') + 1))


def node_only(real: Path | None) -> int:
    """The rows "node defaults, streamed" alone, with the stream time of the first estimate
    (a driven record's: the decision's time and then a window)."""
    header('', 'first estimate (s) | CPU s', 'decided')
    with tempfile.TemporaryDirectory() as tmp:
        for name, kind, path, select, truth, _, shapes in records(Path(tmp), real):
            _, rows, decided, cpu = streamed(path, select)
            first = f'{rows[0]["t"]:.1f}' if rows else '-'
            status = score(rows, truth, kind, shapes)
            print(f'| {name} | {status} | {first} | {cpu:.1f} | {decided} |')
            sys.stdout.flush()
    return 0


def cost(folder: Path) -> None:
    """The default's cost beside the estimator it chooses, through ``analyze`` (reading the CSV
    included, in both): a 2 M-sample free record and a 10-minute driven one at 500 Hz; best of 3
    CPU times."""
    t = np.arange(2_000_000) / 500.0
    y = np.sin(2 * np.pi * 1.33 * t) + 0.01 * np.random.default_rng(1).standard_normal(len(t))
    free = write_csv(folder, 'sine', t, y)
    t, y, _ = ambient_record(600, 500, [(5.0, 0.01, 1.0), (17.0, 0.005, 0.3)], 20, 1)
    driven = write_csv(folder, 'driven_cost', t, y)
    print('\n| record | configuration | CPU s (best of 3) | throughput |')
    print('|---|---|---|---|')
    for name, path, n, seconds, forced in (
        ('1.33 Hz sine, 2 M samples', free, 2_000_000, 4000.0, 'free'),
        ('5 + 17 Hz driven, 600 s', driven, 300_000, 600.0, 'ambient'),
    ):
        for label, extra in (
            ('default', []),
            (f'--excitation {forced}', ['--excitation', forced]),
        ):
            best = min(run(path, extra)[3] for _ in range(3))
            print(
                f'| {name} | {label} | {best:.2f} | {n / best / 1e6:.2f} M samples/s, '
                f'{seconds / best:.0f}x real time |'
            )
            sys.stdout.flush()


if __name__ == '__main__':
    sys.exit(main())
