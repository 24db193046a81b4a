"""``vib-estimator analyze``: run the estimator over a recorded signal (CSV, MCAP, rosbag2).

The estimates are exactly those the estimator node publishes for the same samples: both use the
batch/streaming core with time = header stamp - first stamp (``wrench.seconds_since``).
Estimates go to stdout (jsonl, csv or a table); the sample counters go to stderr. Bad input gives
one line on stderr and exit code 2.
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

from ..io.csv_reader import CsvError, read_csv_series
from ..core import MODELS, COUNTER_NAMES, EstimatorConfig
from ..core.modes import create_estimator
from ..io.fields import COMPONENTS, seconds_since

#: CLI option -> EstimatorConfig field for the estimator's scalar parameters
_CONFIG_OPTIONS = {
    'lowpass_cutoff_hz': float, 'lowpass_damping': float, 'window': int, 'tolerance': float,
    'min_time': float, 'min_periods': float, 'max_window': float, 'min_fit': float,
    'min_amplitude': float, 'max_damping': float, 'max_gap': float, 'target_std_rel': float,
    'modes': int,
}


def add_arguments(parser: argparse.ArgumentParser) -> None:
    defaults = EstimatorConfig()
    parser.add_argument('input', help='CSV file, MCAP file, or rosbag2 directory')
    parser.add_argument('--topic', help='WrenchStamped topic of a bag (default: the only one)')
    parser.add_argument('--component', default='torque.z', choices=COMPONENTS,
                        help='field of the WrenchStamped messages (default torque.z)')
    parser.add_argument('--column', help='CSV signal column, by header name or 0-based index '
                        '(default: the second column)')
    parser.add_argument('--model', choices=MODELS, default=defaults.model)
    parser.add_argument('--band-hz', nargs=2, type=float, metavar=('LO', 'HI'),
                        help='band-pass prefilter [LO, HI] Hz (default off)')
    for name, kind in _CONFIG_OPTIONS.items():
        parser.add_argument('--' + name.replace('_', '-'), type=kind,
                            default=getattr(defaults, name), help=f'(default {getattr(defaults, name)})')
    parser.add_argument('--format', choices=('jsonl', 'csv', 'table'), default='jsonl')
    parser.add_argument('--plot', metavar='FILE.png', help='write a Fig. 5-like figure')


def _load(args):
    """(t, y, origin_ns or None, label) from the input, raising CsvError/BagError/ValueError."""
    path = Path(args.input)
    if path.suffix.lower() in ('.csv', '.txt'):
        series = read_csv_series(path, args.column)
        return series.t, series.y, None, series.name
    if not path.exists():
        raise ValueError(f'no such file or directory: {path}')
    from ..io.bags import read_wrench_series

    series = read_wrench_series(path, args.topic, args.component)
    if len(series) == 0:
        raise ValueError(f'topic {series.topic} of {path} has no messages')
    origin = int(series.stamps_ns[0])
    return (seconds_since(series.stamps_ns, origin), series.values, origin,
            f'{series.topic} {args.component}')


def _print(estimates, origin, fmt) -> None:
    rows = []
    for e in estimates.to_list():
        row = e.as_dict()
        if origin is not None:
            row['stamp_ns'] = origin + round(e.t * 1e9)
        rows.append(row)
    out = sys.stdout
    if fmt == 'jsonl':
        for row in rows:     # strict JSON: NaN (e.g. no damping estimate) becomes null
            out.write(json.dumps({k: None if v != v else v for k, v in row.items()}) + '\n')
    elif fmt == 'csv':
        keys = list(rows[0]) if rows else ['t', 'frequency_hz', 'convergence_time_s']
        out.write(','.join(keys) + '\n')
        for row in rows:
            out.write(','.join(repr(row[k]) for k in keys) + '\n')
    else:
        out.write(f'{"t (s)":>12} {"f (Hz)":>12} {"conv (s)":>9} {"samples":>8} {"fit":>6}\n')
        for row in rows:
            out.write(f'{row["t"]:12.4f} {row["frequency_hz"]:12.6f} '
                      f'{row["convergence_time_s"]:9.4f} {row["samples"]:8d} {row["fit"]:6.3f}\n')


def run(args: argparse.Namespace) -> int:
    from ..io.bags import BagError

    try:
        config = EstimatorConfig().replace(
            model=args.model, band_hz=tuple(args.band_hz) if args.band_hz else None,
            **{name: getattr(args, name) for name in _CONFIG_OPTIONS})
        t, y, origin, label = _load(args)
        if len(t) == 0:
            raise ValueError(f'{args.input} holds no samples')
        bad = np.flatnonzero(~(np.diff(t) > 0))
        if bad.size:
            i = int(bad[0]) + 1
            raise ValueError(f'{args.input}: time is not strictly increasing at sample {i} '
                             f'(t = {float(t[i - 1])!r} then {float(t[i])!r})')
    except (CsvError, BagError, ValueError) as err:
        print(f'vib-estimator analyze: error: {err}', file=sys.stderr)
        return 2
    estimator = create_estimator(config)
    estimates = estimator.process(t, y)
    _print(estimates, origin, args.format)
    counters = estimator.counters
    print('analyze: ' + ', '.join(f'{k}={counters[k]}' for k in COUNTER_NAMES),
          file=sys.stderr)
    if args.plot:
        from .plotting import plot_estimates

        Path(args.plot).parent.mkdir(parents=True, exist_ok=True)
        plot_estimates(args.plot, t, y, estimates.t, estimates.frequency_hz,
                       estimates.convergence_time, title=f'{args.input}: {label}', ylabel=label)
    return 0
