# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""``vib-estimator analyze``: run the estimator over a recorded signal (CSV, MCAP, rosbag2).

The estimates are exactly those the estimator node publishes for the same samples: both use the
streaming core with time = header stamp - first stamp (``fields.seconds_since``; ``Float64``, which
has no header: the log time). The recording is read block by block (:mod:`..io.streaming`), so
memory does not grow with its length. A bag's topic may be of any input type of
:mod:`..io.fields`; ``--component`` is checked against it. Estimates go to stdout (jsonl, csv or a
table); the sample counters go to stderr, then a summary (:mod:`.summary`: the modes found and
the ``shaper_node`` command of the input shaper to use). Bad input gives one line on stderr and
exit code 2.

Damaged bag records (an MCAP chunk whose checksum fails, an index entry that points at no message,
a payload that does not decode as its type) are skipped: one ``warning:`` line on stderr says how
many and what the first was, the counters line ends with ``corrupt_records=N``, and the exit code
stays 0. With ``--strict`` the first one is an error instead (one ``error:`` line, exit code 2).
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from dataclasses import dataclass
from typing import Optional, Tuple

import numpy as np

from ..core import MODELS, EstimateArrays, EstimatorConfig
from ..core.config import EXCITATIONS, PAPER
from ..core.estimator import run_batch
from ..core.factory import batch_estimator, kind_of
from ..errors import VibEstimatorError, report
from ..io.align import ALIGN_TOLERANCE_S
from ..io.csv_reader import NO_TIME, csv_layout, time_words
from ..io.fields import INPUT_TYPES, signal_unit
from ..io.streaming import Signal, is_csv, open_signal
from .channels import channel_names, component_names, need_joint, run_joint, topic_list
from .choosing import (
    decides,
    dominant_reading,
    explain_no_estimate,
    model_given,
    peaks_without_mode,
    periods_given,
    prepare,
    read_ahead,
    rescue,
    with_dominant,
)
from .outputs import check_output
from .summary import summarise_modes, summary_lines

#: CLI option -> EstimatorConfig field for the estimator's scalar parameters
_CONFIG_OPTIONS = {
    'lowpass_cutoff_hz': float,
    'lowpass_damping': float,
    'window': int,
    'tolerance': float,
    'min_time': float,
    'min_periods': float,
    'max_window': float,
    'min_fit': float,
    'min_amplitude': float,
    'max_damping': float,
    'max_gap': float,
    'target_std_rel': float,
    'early_std_rel': float,
    'gap_intervals': float,
    'outlier_ratio': float,
    'modes': int,
    'refine': int,
    'consistency': float,
    'ambient_window_s': float,
}


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument('input', help='CSV file, MCAP file, or rosbag2 directory')
    parser.add_argument(
        '--topic',
        help='topic of a bag (default: its only topic of a supported '
        f'type: {", ".join(t.split("/")[-1] for t in INPUT_TYPES)})',
    )
    parser.add_argument(
        '--component',
        help="field of the messages, as the node's component "
        "parameter (default: the type's, e.g. torque.z of a WrenchStamped, "
        'linear_acceleration.z of an Imu)',
    )
    parser.add_argument(
        '--topics',
        help='several topics of a bag, comma-separated: the --component (or --components) of '
        "each, their samples aligned by header stamp as the node's input_topics, one set of "
        'modes with their shapes (channels topic:field; docs/channels.md)',
    )
    parser.add_argument(
        '--sync-tolerance-s',
        type=float,
        default=ALIGN_TOLERANCE_S,
        help='--topics: samples whose stamps lie within this of each other are one joint sample '
        f"(default {ALIGN_TOLERANCE_S:g} s, as the node's sync_tolerance_s)",
    )
    parser.add_argument(
        '--components',
        help='several fields of the bag topic, comma-separated (e.g. linear_acceleration.x,'
        'linear_acceleration.y,linear_acceleration.z): one set of modes with their shapes '
        '(free decays or --excitation ambient; docs/channels.md)',
    )
    parser.add_argument(
        '--column',
        help='CSV signal column, by header name or 0-based index (default: the second column)',
    )
    parser.add_argument(
        '--columns',
        help='several CSV signal columns, comma-separated names or indices, or all: one set of '
        'modes with their shapes (free decays or --excitation ambient; docs/channels.md)',
    )
    add_config_arguments(parser)
    parser.add_argument('--format', choices=('jsonl', 'csv', 'table'), default='jsonl')
    parser.add_argument('--plot', metavar='FILE.png', help='write a Fig. 5-like figure')
    parser.add_argument(
        '--report',
        metavar='DIR',
        help='write DIR/index.html, a self-contained page (images beside it): the modes, '
        'spectrum, stabilisation diagram, estimates over time, mode shapes, MAC, shaper '
        '(docs/report.md)',
    )
    parser.add_argument(
        '--geometry',
        metavar='FILE.yaml',
        help="--report: draw each mode's shape on the structure (points, channels, lines: "
        'docs/geometry.md; examples in config/geometry/)',
    )
    parser.add_argument(
        '--strict',
        action='store_true',
        help='a damaged bag record is an error (exit 2) instead of a counted skip',
    )


def add_config_arguments(parser: argparse.ArgumentParser, model: Optional[str] = None) -> None:
    """The estimator options (``--paper``, ``--model``, ``--band-hz``, one per scalar config
    field); an option not given keeps the default (or with ``--paper`` the paper's) value, the
    help of ``--model`` says ``model`` if the command has its own default."""
    defaults, paper = (
        EstimatorConfig(model=model or EstimatorConfig.model),
        EstimatorConfig.paper(),
    )
    parser.add_argument(
        '--paper',
        action='store_true',
        help="start from the paper's configuration ("
        + ', '.join(f'{k} {v}' for k, v in PAPER.items())
        + ') instead of the defaults',
    )
    parser.add_argument(
        '--model',
        choices=MODELS,
        default=None,
        help=f'(default {defaults.model}; --paper: {paper.model})',
    )
    parser.add_argument(
        '--excitation',
        choices=EXCITATIONS,
        default=None,
        help=EstimatorConfig.describe('excitation')[0] + f' (default {defaults.excitation})',
    )
    parser.add_argument(
        '--band-hz',
        nargs=2,
        type=float,
        metavar=('LO', 'HI'),
        help='band-pass prefilter [LO, HI] Hz (default off)',
    )
    parser.add_argument(
        '--lines-hz',
        nargs='+',
        type=float,
        metavar='F',
        help="a periodic drive's lines, Hz: the identifier drops its modes within 1 %% of one "
        '(default: those the record shows, where the default reads a periodic drive)',
    )
    for name, kind in _CONFIG_OPTIONS.items():
        value, paper_value = getattr(defaults, name), getattr(paper, name)
        parser.add_argument(
            '--' + name.replace('_', '-'),
            type=kind,
            default=None,
            help=f'(default {value}'
            + (f'; --paper: {paper_value})' if paper_value != value else ')'),
        )


def make_config(args: argparse.Namespace) -> EstimatorConfig:
    """The estimator configuration of the command line (ValueError if out of range)."""
    base = EstimatorConfig.paper() if args.paper else EstimatorConfig()
    given = {
        name: getattr(args, name)
        for name in ('model', 'excitation', *_CONFIG_OPTIONS)
        if getattr(args, name) is not None
    }
    lines = getattr(args, 'lines_hz', None)
    return base.replace(
        band_hz=tuple(args.band_hz) if args.band_hz else None, lines_hz=lines or None, **given
    )


def _check_times(t: np.ndarray, previous: float, count: int, name: str) -> None:
    """ValueError unless ``t`` (after ``previous``, samples ``count`` on) strictly increases."""
    bad = np.flatnonzero(~(np.diff(np.concatenate(([previous], t)) if count else t) > 0))
    if bad.size:
        i = int(bad[0]) + (0 if count else 1)
        before = previous if i == 0 else t[i - 1]
        raise ValueError(
            f'{name}: time is not strictly increasing at sample {count + i} '
            f'(t = {float(before)!r} then {float(t[i])!r})'
            + (f'; {NO_TIME}' if is_csv(name) else '')
        )


def _check_nyquist(config: EstimatorConfig, t: np.ndarray, name: str) -> None:
    """ValueError if the band-pass reaches above the Nyquist frequency of the samples ``t``."""
    if config.band_hz is None or len(t) < 2:
        return
    nyquist = 0.5 / float(np.median(np.diff(t[:10_000])))
    if config.band_hz[1] > nyquist:
        raise ValueError(
            f'--band-hz upper edge {config.band_hz[1]:g} Hz is above the Nyquist '
            f'frequency {nyquist:g} Hz of {name} (sampled at {2 * nyquist:g} Hz)'
        )


@dataclass
class Run:
    """The result of :func:`estimate_signal`: the estimator (its counters), the estimates, the
    first and last sample times, and (``keep_samples``) every ``(t, y)``."""

    estimator: object
    estimates: EstimateArrays
    first_t: float
    last_t: float
    samples: Optional[Tuple[np.ndarray, np.ndarray]]


def estimate_signal(
    signal: Signal,
    config: EstimatorConfig,
    keep_samples: bool = False,
    blocks=None,
    offset: float = 0.0,
) -> Run:
    """Stream ``signal`` (or its ``blocks``, when some were read ahead) through a fresh estimator
    of ``config``, block by block, less ``offset`` (the samples kept as read).

    Raises ValueError (no samples, time not increasing, band above Nyquist) and the readers'
    CsvError/BagError.
    """
    estimator = batch_estimator(config)  # uncompiled at first when not compiled yet
    parts, kept = [], []
    count, previous, first_t, nyquist_checked = 0, 0.0, None, False
    for t, y in signal.blocks() if blocks is None else blocks:
        if len(t) == 0:
            continue
        _check_times(t, previous, count, str(signal.path))
        if not nyquist_checked and count + len(t) >= 2:
            _check_nyquist(
                config, np.concatenate(([previous], t)) if count else t, str(signal.path)
            )
            nyquist_checked = True
        first_t = float(t[0]) if first_t is None else first_t
        parts.append(run_batch(estimator, t, y - offset if offset else y))
        count, previous = count + len(t), float(t[-1])
        if keep_samples:
            kept.append((t, y))
    if count == 0:
        raise ValueError(
            f'{signal.path} holds no samples'
            if not signal.topic
            else f'topic {signal.topic} of {signal.path} has no messages'
        )
    samples = tuple(np.concatenate(p) for p in zip(*kept)) if keep_samples else None
    return Run(estimator, EstimateArrays.concatenate(parts), first_t, previous, samples)


def json_row(row: dict) -> dict:
    """``row`` with every non-finite float as None, so strict JSON can hold it (null)."""
    return {
        k: None if isinstance(v, float) and not math.isfinite(v) else v for k, v in row.items()
    }


def _print(estimates, origin, fmt, modes: int = 0) -> None:
    rows = []
    for e in estimates.to_list():
        row = e.as_dict()
        if origin is not None:
            row['stamp_ns'] = origin + round(e.t * 1e9)
        rows.append(row)
    out = sys.stdout
    if fmt == 'jsonl':
        for row in rows:  # strict JSON: NaN or inf (unknown, e.g. no damping) becomes null
            out.write(json.dumps(json_row(row), allow_nan=False) + '\n')
    elif fmt == 'csv':
        keys = list(rows[0]) if rows else ['t', 'frequency_hz', 'convergence_time_s']
        out.write(','.join(keys) + '\n')
        for row in rows:
            out.write(','.join(repr(row[k]) for k in keys) + '\n')
    else:
        mode = f'{"mode":>5} ' if modes else ''
        out.write(
            f'{"t (s)":>12} {mode}{"f (Hz)":>12} {"f std (Hz)":>10} {"zeta":>8} '
            f'{"conv (s)":>9} {"samples":>8} {"fit":>6}\n'
        )
        for row in rows:
            mode = f'{row["mode"]:5d} ' if modes else ''
            out.write(
                f'{row["t"]:12.4f} {mode}{row["frequency_hz"]:12.6f} '
                f'{row["frequency_std_hz"]:10.3g} {row["damping"]:8.5f} '
                f'{row["convergence_time_s"]:9.4f} {row["samples"]:8d} {row["fit"]:6.3f}\n'
            )


def default_column(args) -> Optional[list[str]]:
    """For a CSV input read without ``--column``: the file's signal columns, the one read (the
    first after the time) first; else None. Says the time column's unit when its name gives
    one (:func:`..io.csv_reader.time_words`)."""
    if not is_csv(args.input):
        return None
    layout = csv_layout(args.input)
    words = time_words(layout)
    if words:
        print(f'analyze: {words}', file=sys.stderr)
    return None if args.column is not None else list(layout.names[1:])


def damage_warning(signal: Signal, prog: str) -> None:
    """The one ``warning:`` line on stderr for the damaged records a read skipped, if any."""
    if signal.corrupt:
        print(
            f'{prog}: warning: skipped {signal.corrupt} damaged record(s) of {signal.topic} in '
            f'{signal.path} (first: {signal.damage}); --strict makes this an error',
            file=sys.stderr,
        )


def rescues(args) -> bool:
    """Whether a free decay the free estimator gives nothing of may be read again by the mode
    tracker (:func:`.choosing.rescue`), and the strongest of a free decay's modes by the free
    estimator (:func:`.choosing.dominant_reading`): decided from the record, no ``--model``,
    ``--min-periods`` or ``--modes`` (which keep the estimator as chosen)."""
    chosen = model_given(args) or periods_given(args) or getattr(args, 'modes', None) is not None
    return decides(args) and not chosen


def estimate_rescued(
    signal: Signal, config, decision, allowed: bool, prog: str, keep=False, blocks=None, offset=0.0
):
    """``(config, run, line)``: :func:`estimate_signal`, and a free decay it gave (almost) no
    estimate of read again by the mode tracker when ``allowed`` (:func:`.choosing.rescue`; the
    record's counts started afresh) and kept where the tracker gives more, with the line that
    says so ('' otherwise)."""
    result = estimate_signal(signal, config, keep, blocks, offset)
    lowest = dominant_reading(config, decision, allowed)
    if lowest is not None:  # the strongest of several modes: the free estimator's
        skipped, corrupt = signal.skipped, signal.corrupt
        free = estimate_signal(signal, lowest[0], offset=lowest[1]).estimates
        signal.skipped, signal.corrupt = skipped, corrupt  # (counted once)
        result.estimates, words = with_dominant(result.estimates, free)
        return config, result, f'{prog}: {words}' if words else ''
    again = rescue(config, decision, allowed, len(result.estimates), prog)
    if again is None:
        return config, result, ''
    skipped, corrupt = signal.skipped, signal.corrupt
    signal.skipped = signal.corrupt = 0  # counted again
    tracked = estimate_signal(signal, again[0], keep)
    if len(tracked.estimates) <= len(result.estimates):  # the free estimates, as they were
        signal.skipped, signal.corrupt = skipped, corrupt
        return config, result, ''
    return again[0], tracked, again[1]


def say_column(columns: Optional[list]) -> list:
    """Say which column the default took (``columns``: the CSV's, when no ``--column`` named one;
    None otherwise) and return the others."""
    others = columns[1:] if columns else []
    if columns:
        print(
            f'analyze: column {columns[0]} (the first after the time, the default'
            + (f'; the others: {", ".join(others)}: --column NAME' if others else '')
            + ')',
            file=sys.stderr,
        )
    return others


def run(args: argparse.Namespace) -> int:
    try:
        config = make_config(args)
        check_output(args.plot, '--plot')
        geometry = args.loaded_geometry = report_geometry(args)
        if getattr(args, 'columns', None) is not None:
            names = channel_names(args)
            if len(names) > 1:
                return run_joint(args, config, names, json_row, 'analyze')
            args.column = names[0]  # one column: exactly --column
        if getattr(args, 'topics', None) is not None:
            args.topics_list = topic_list(args)
            if len(args.topics_list) > 1:
                names = component_names(args) if args.components is not None else []
                need_joint(f'{len(args.topics_list)} topics', config)
                return run_joint(args, config, names, json_row, 'analyze', damage_warning)
            args.topic = args.topics_list[0]  # one topic: exactly --topic
        if getattr(args, 'components', None) is not None:
            names = component_names(args)
            if len(names) > 1:
                return run_joint(args, config, names, json_row, 'analyze', damage_warning)
            args.component = names[0]  # one component: exactly --component
        signal = open_signal(
            args.input,
            args.topic,
            args.component,
            args.column,
            strict=getattr(args, 'strict', False),
        )
        if geometry is not None:
            geometry.check_channels((signal.component or signal.label,))
        columns = default_column(args)
        ahead, blocks = read_ahead(signal.blocks())
        decision, notes = None, []
        if ahead is not None:
            config, decision, notes = prepare(args, config, *ahead, 1, 'analyze')
        offset = decision.offset if decision is not None and math.isfinite(decision.offset) else 0
        keep = bool(args.plot or args.report)
        config, result, rescued = estimate_rescued(
            signal, config, decision, rescues(args), 'analyze', keep, blocks, offset
        )
    except (VibEstimatorError, ValueError) as err:
        return report(err, 'vib-estimator analyze')
    damage_warning(signal, 'vib-estimator analyze')
    for line in filter(None, [*notes, rescued]):
        print(line, file=sys.stderr)
    others = say_column(columns)
    estimates = result.estimates
    numbered = kind_of(config).numbered
    _print(estimates, signal.origin_ns, args.format, numbered)
    counters = result.estimator.counters
    extra = f', messages_without_component={signal.skipped}' if signal.skipped else ''
    extra += f', corrupt_records={signal.corrupt}' if signal.topic else ''
    open_samples = result.estimator.segment_samples
    if open_samples is not None:
        extra += f', open_segment_samples={open_samples}'
    print(
        'analyze: ' + ', '.join(f'{k}={v}' for k, v in counters.items()) + extra, file=sys.stderr
    )
    mode = estimates.mode if numbered else None
    why = '' if len(estimates) else explain_no_estimate(counters, open_samples, config, decision)
    if len(estimates) == 0:
        print('analyze: no estimate: ' + why, file=sys.stderr)
        if others:
            print(
                f"analyze: column {signal.label} gave no estimate; the file's other columns: "
                + ', '.join(others)
                + ' (--column NAME, or --columns all for a joint estimation)',
                file=sys.stderr,
            )
    modes = summarise_modes(estimates.frequency_hz, estimates.damping, mode, estimates.t)
    for line in summary_lines(modes, config.excitation != 'free'):
        print('analyze: ' + line, file=sys.stderr)
    missing = peaks_without_mode(config, decision, [m.frequency_hz for m in modes])
    if missing:
        print('analyze: ' + missing, file=sys.stderr)
    pictures(args, config, signal, result, mode, geometry, why)
    return 0


def pictures(args, config, signal: Signal, run: Run, mode, geometry, why: str) -> None:
    """``--plot`` and ``--report`` of a one-channel run (its samples kept)."""
    if args.plot:
        plot_run(args.plot, args.input, signal, run, mode, config, why)
    if getattr(args, 'report', None):
        write_run_report(args, config, signal, run, geometry, why)


def report_geometry(args):
    """Check ``--report`` (a writable folder) and load ``--geometry`` (GeometryError, ValueError
    if bad; --geometry without --report is a ValueError)."""
    report_dir, path = getattr(args, 'report', None), getattr(args, 'geometry', None)
    check_output(report_dir, '--report', directory=True)
    if path and not report_dir:
        raise ValueError('--geometry draws the shapes of --report DIR: give --report too')
    if not path:
        return None
    from ..io.geometry import load_geometry

    return load_geometry(path)


def write_run_report(args, config, signal: Signal, run: Run, geometry, why: str) -> None:
    """``--report`` of a one-channel run (its samples kept)."""
    from .report import Record, command_line, write_report

    name = signal.component or signal.label
    record = Record(
        str(args.input),
        command_line(args),
        (name,),
        run.samples[0],
        run.samples[1],
        run.estimates,
        config,
        dict(run.estimator.counters),
        unit=signal_unit(name),
        why=why,
    )
    path = write_report(args.report, record, geometry)
    print(f'analyze: report written to {path}', file=sys.stderr)


#: what ``--plot`` calls the estimates of each excitation
ESTIMATE_LABELS = {
    'free': 'algebraic estimates',
    'ambient': 'SSI-cov estimates (ambient)',
    'auto': 'estimates (decays: algebraic; driven: SSI-cov)',
}


def plot_run(path: str, name: str, signal: Signal, run: Run, mode=None, config=None, why=''):
    """``--plot``: the estimates and spectrum figure of a run (``keep_samples``) of ``signal``,
    its signal axis in the unit of the component or column (:func:`..io.fields.signal_unit`);
    the estimates labelled by what made them (``config``'s excitation; ambient: coloured by
    mode, the third panel their frequency std: every estimate spans the same window); ``why``
    written on the empty panels of a run without an estimate; returns the Figure."""
    from .plotting import plot_estimates

    e = run.estimates
    excitation = config.excitation if config is not None else 'free'
    ambient = excitation == 'ambient'
    if ambient and mode is None:
        mode = e.mode
    return plot_estimates(
        path,
        *run.samples,
        e.t,
        e.frequency_hz,
        e.convergence_time,
        title=f'{name}: {signal.label}',
        ylabel=signal.label,
        mode=mode,
        unit=signal_unit(signal.component or signal.label),
        label=ESTIMATE_LABELS.get(excitation, 'estimates'),
        panel3=('frequency std (Hz)', e.frequency_std_hz) if ambient else None,
        note=why,
    )
