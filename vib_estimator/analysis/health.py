# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""``survey``'s learned health baseline: covariates in the rows, training, compensated changes,
alarms with a known false-alarm rate, and their plot (the model: :mod:`..core.health_model`;
docs/health.md).

Options: ``--covariates TOPIC:FIELD[,...]`` (each recording's mean of each, column
``covariate_<spec>``), ``--baseline-records N`` or ``--baseline-until DATE`` (learn from the first
N recordings by start time, or those starting up to DATE), ``--baseline FILE.yaml`` (a saved one),
``--save-baseline FILE.yaml``, ``--false-alarm P``, ``--sequential cusum|none``. Every row of a
baseline mode gains ``baseline_mode``, ``predicted_hz``, ``residual_z``, ``alarm_limit_rel``,
``extrapolated``, ``alarm_since`` (and ``cusum``), and its ``change_rel``/``change_lo``/
``change_hi``/``alarm`` are the compensated ones.
"""

from __future__ import annotations

import argparse
import math
from datetime import datetime, timedelta, timezone
from pathlib import Path
from typing import Callable, Dict, List, Optional, Sequence, Tuple

import numpy as np

from ..core import health_model as hm
from ..core.shapes import mac
from ..io.covariates import covariate_means, parse_covariates

#: ``--sequential``: the sequential test beside the per-recording one (default first)
SEQUENTIAL = ('cusum', 'none')
#: a row's covariate column is this prefix and the covariate's spec
COVARIATE_PREFIX = 'covariate_'
#: fields a row of a baseline mode gains (after ``change_*`` and ``alarm``)
HEALTH_FIELDS = (
    'baseline_mode',
    'predicted_hz',
    'residual_z',
    'alarm_limit_rel',
    'extrapolated',
    'alarm_since',
)


def covariate_column(spec: str) -> str:
    return COVARIATE_PREFIX + spec


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        '--covariates',
        metavar='TOPIC:FIELD[,...]',
        help='environmental covariates (bag TOPIC:FIELD, CSV column names), comma-separated: '
        "each recording's mean in its rows, and what a learned baseline compensates "
        '(docs/health.md)',
    )
    learn = parser.add_mutually_exclusive_group()
    learn.add_argument(
        '--baseline-records',
        type=int,
        metavar='N',
        help='learn the baseline (frequency ~ covariates, per mode) from the first N recordings '
        'by start time',
    )
    learn.add_argument(
        '--baseline-until',
        metavar='DATE',
        help='learn the baseline from the recordings starting up to DATE (ISO 8601, UTC)',
    )
    parser.add_argument(
        '--save-baseline', metavar='FILE.yaml', help='write the learned baseline to FILE.yaml'
    )
    parser.add_argument(
        '--false-alarm',
        type=float,
        metavar='P',
        help='with a learned baseline: false-alarm probability per recording per mode '
        f"(default {hm.DEFAULT_FALSE_ALARM}, or the saved baseline's)",
    )
    parser.add_argument(
        '--sequential',
        choices=SEQUENTIAL,
        default=SEQUENTIAL[0],
        help='with a learned baseline: cusum (default) also alarms while a two-sided CUSUM of the '
        f'standardised changes (k {hm.CUSUM_K}) is beyond the threshold whose in-control run '
        'length is 1/P recordings; none: the per-recording test alone',
    )


def check_arguments(args: argparse.Namespace) -> Tuple[Tuple[str, ...], Optional[hm.Baseline]]:
    """The covariates to read and the saved baseline ``--baseline`` names, if it is one;
    ValueError for a bad combination."""
    covariates = tuple(parse_covariates(args.covariates)) if args.covariates else ()
    learning = args.baseline_records is not None or args.baseline_until is not None
    saved = None
    if args.baseline and hm.is_baseline_file(args.baseline):
        saved = hm.load(args.baseline)
        if covariates and tuple(saved.covariates) != covariates:
            raise ValueError(
                f"--covariates {','.join(covariates)} differ from the baseline's "
                f'({",".join(saved.covariates) or "none"}); give the same or none'
            )
        covariates = tuple(saved.covariates)
    if learning and args.baseline:
        raise ValueError('give --baseline or --baseline-records/--baseline-until, not both')
    if args.baseline_records is not None and args.baseline_records < 2:
        raise ValueError(f'--baseline-records must be >= 2, got {args.baseline_records}')
    if args.baseline_until is not None:
        until_time(args.baseline_until)
    if args.save_baseline and not (learning or saved):
        raise ValueError('--save-baseline needs --baseline-records or --baseline-until')
    if args.save_baseline and Path(args.save_baseline).suffix.lower() not in ('.yaml', '.yml'):
        raise ValueError(f'--save-baseline must end in .yaml, got {args.save_baseline}')
    if args.false_alarm is not None:
        if not 0 < args.false_alarm < 1:
            raise ValueError(f'--false-alarm must be in (0, 1), got {args.false_alarm}')
        if not (learning or saved):
            raise ValueError('--false-alarm needs a learned baseline (--baseline-records, ...)')
    return covariates, saved


def until_time(text: str) -> datetime:
    """The end (exclusive) of ``--baseline-until``: a date means the end of that day (UTC)."""
    try:
        when = datetime.fromisoformat(text.replace('Z', '+00:00'))
    except ValueError:
        raise ValueError(f'--baseline-until must be an ISO 8601 date, got {text!r}') from None
    if when.tzinfo is None:
        when = when.replace(tzinfo=timezone.utc)
    return when + timedelta(days=1) if len(text) == 10 else when


def add_covariates(path, rows: List[Dict], specs: Sequence[str]) -> None:
    """Each row gains ``covariate_<spec>`` = the recording's mean; a covariate that cannot be
    read makes the recording's rows error rows (they keep their frequencies)."""
    try:
        means = covariate_means(path, specs)
    except Exception as err:  # noqa: BLE001 -- a bad recording is a row, not the end of the survey
        means = [math.nan] * len(specs)
        detail = (str(err).strip() or type(err).__name__).splitlines()[0]
        for row in rows:
            row['error'] = row['error'] or f'covariate: {detail}'
    for row in rows:
        row.update({covariate_column(s): m for s, m in zip(specs, means)})


def _start(row: Dict) -> Optional[datetime]:
    return (
        datetime.fromisoformat(row['start_utc'].replace('Z', '+00:00'))
        if row['start_utc']
        else None
    )


def in_time_order(rows: Sequence[Dict]) -> List[str]:
    """The recordings of ``rows`` by start time (those without one last, by name)."""
    first: Dict[str, str] = {}
    for row in rows:
        first.setdefault(row['recording'], row['start_utc'])
    return sorted(first, key=lambda r: (not first[r], first[r], r))


def training(rows: Sequence[Dict], records: Optional[int], until: Optional[str]) -> List[Dict]:
    """The rows of the training recordings (the first ``records`` by start time, or those
    starting up to ``until``), errors left out."""
    order = in_time_order([r for r in rows if not r['error']])
    if records is not None:
        if records > len(order):
            raise ValueError(
                f'--baseline-records {records}: only {len(order)} recording(s) gave rows'
            )
        chosen = set(order[:records])
    else:
        end = until_time(until)
        chosen = {r['recording'] for r in rows if _start(r) is not None and _start(r) < end}
    return [r for r in rows if r['recording'] in chosen and not r['error']]


def learn_rows(
    rows: Sequence[Dict],
    covariates: Sequence[str],
    records: Optional[int],
    until: Optional[str],
    shape_of: Callable,
    false_alarm: Optional[float],
) -> hm.Baseline:
    """The baseline learned from the training recordings of ``rows`` (ValueError if none)."""
    train = training(rows, records, until)
    names = in_time_order(train)
    if not names:
        raise ValueError('no recording in the training period gave a frequency')
    starts = [r['start_utc'] for r in train if r['start_utc']]
    span = f', {min(starts)} .. {max(starts)}' if starts else ''
    return hm.learn(
        train,
        covariates,
        lambda r: [r.get(covariate_column(s), math.nan) for s in covariates],
        shape_of,
        hm.DEFAULT_FALSE_ALARM if false_alarm is None else false_alarm,
        f'{len(names)} recordings{span}',
    )


def judge(
    rows: List[Dict],
    args: argparse.Namespace,
    covariates: Sequence[str],
    saved: Optional[hm.Baseline],
    shape_of: Callable,
) -> Optional[hm.Baseline]:
    """``survey``'s health step: the baseline learned from ``rows`` (``--baseline-records``,
    ``--baseline-until``) or ``saved``, every row judged against it (:func:`flag_learned`), and
    saved (``--save-baseline``); None without one. ValueError if it cannot be learned."""
    baseline = saved
    if args.baseline_records is not None or args.baseline_until is not None:
        baseline = learn_rows(
            rows,
            covariates,
            args.baseline_records,
            args.baseline_until,
            shape_of,
            args.false_alarm,
        )
    if baseline is None:
        return None
    flag_learned(rows, baseline, shape_of, args.false_alarm, args.sequential == SEQUENTIAL[0])
    if args.save_baseline:
        hm.save(baseline, Path(args.save_baseline))
    return baseline


def flag_learned(
    rows: List[Dict],
    baseline: hm.Baseline,
    shape_of: Callable,
    false_alarm: Optional[float] = None,
    cusum: bool = True,
) -> None:
    """Match each row to a baseline mode (:meth:`~..core.health_model.Baseline.match`; one row
    per mode and recording, the nearest) and set its compensated change, alarm and since when
    (in recording time order; ``cusum``: also while the CUSUM is beyond its threshold). Since
    when: the first recording of the current run of alarmed recordings."""
    if false_alarm is not None:
        baseline.false_alarm = false_alarm

    def x_of(row):
        return [row.get(covariate_column(s), math.nan) for s in baseline.covariates]

    good = [r for r in rows if not r['error'] and np.isfinite(r['frequency_hz'])]
    chosen: Dict[Tuple[str, int], Tuple[float, Dict]] = {}
    for row in good:
        row.update(baseline_mode=0, alarm=False)
        x = x_of(row)
        if not np.all(np.isfinite(x)):
            continue
        mode = baseline.match(
            row['topic'], row['component'], row['frequency_hz'], x, shape_of(row)
        )
        if mode is None:
            continue
        d = abs(math.log(row['frequency_hz'] / mode.predict(x)[0]))
        key = (row['recording'], baseline.modes.index(mode))
        if key not in chosen or d < chosen[key][0]:
            chosen[key] = (d, row)
    order = {name: i for i, name in enumerate(in_time_order(rows))}
    for index, mode in enumerate(baseline.modes):
        mine = sorted(
            (row for (_, i), (_, row) in chosen.items() if i == index),
            key=lambda r: order[r['recording']],
        )
        sequential = hm.Cusum(baseline.cusum_h()) if cusum else None
        since = ''
        for row in mine:
            change = baseline.change(mode, row['frequency_hz'], x_of(row))
            alarm = change.alarm
            if sequential is not None:
                sequential.update(change.z, change.shared)
                row['cusum'] = sequential.value
            alarm = alarm or (sequential is not None and sequential.alarm)
            since = (since or row['start_utc'] or row['recording']) if alarm else ''
            row.update(
                baseline_mode=mode.mode,
                predicted_hz=change.predicted_hz,
                change_rel=change.change_rel,
                change_lo=change.change_lo,
                change_hi=change.change_hi,
                residual_z=change.z,
                alarm_limit_rel=change.limit_rel,
                extrapolated=change.extrapolated,
                alarm=alarm,
                alarm_since=since,
            )
            shape = shape_of(row)
            if shape is not None and len(mode.shape) == len(shape):
                row['mac_to_baseline'] = mac(shape, mode.shape)


def plot_health(rows: List[Dict], path: Path, baseline: hm.Baseline):
    """Per baseline mode: raw and predicted frequency against time, the compensated change with
    its alarm band and the alarms against time, and the raw frequency against the first covariate
    (training recordings marked, the regression line). Returns the Figure."""
    from .plotting import pyplot

    plt = pyplot()
    modes = baseline.modes
    fig, axes = plt.subplots(
        len(modes), 3, figsize=(14, 3.4 * len(modes)), squeeze=False, constrained_layout=True
    )
    name = baseline.covariates[0] if baseline.covariates else None
    for ax_row, mode in zip(axes, modes):
        mine = [
            r
            for r in rows
            if r.get('baseline_mode') == mode.mode
            and (r['topic'], r['component']) == (mode.topic, mode.component)
        ]
        x = [_start(r) or i for i, r in enumerate(mine)]
        f = np.array([r['frequency_hz'] for r in mine])
        pred = np.array([r['predicted_hz'] for r in mine])
        change = 100 * np.array([r['change_rel'] for r in mine])
        limit = 100 * np.array([r['alarm_limit_rel'] for r in mine])
        alarmed = np.array([bool(r['alarm']) for r in mine], dtype=bool)
        title = f'mode {mode.mode} ({mode.frequency_hz:.4g} Hz)'
        ax = ax_row[0]
        ax.plot(x, f, 'o', ms=3, label='measured')
        ax.plot(x, pred, '-', lw=1, label='baseline prediction (covariates)')
        ax.plot([x[i] for i in np.flatnonzero(alarmed)], f[alarmed], 'rx', ms=8, label='alarm')
        ax.set_ylabel('frequency (Hz)')
        ax.set_title(title + ': raw', fontsize=9)
        ax = ax_row[1]
        ax.plot(x, change, 'o', ms=3, label='compensated change')
        ax.fill_between(
            x, -limit, limit, alpha=0.15, label=f'no-alarm band (P={baseline.false_alarm:g})'
        )
        ax.plot(
            [x[i] for i in np.flatnonzero(alarmed)], change[alarmed], 'rx', ms=8, label='alarm'
        )
        ax.axhline(0, color='k', lw=0.6)
        ax.set_ylabel('change (%)')
        ax.set_title(title + ': compensated', fontsize=9)
        ax = ax_row[2]
        if name is not None:
            c = np.array([r[covariate_column(name)] for r in mine])
            k = baseline.covariates.index(name)
            lo, hi = np.nanmin(c), np.nanmax(c)
            grid = np.linspace(lo, hi, 50)
            others = list(mode.x_mean)
            line = [mode.predict(others[:k] + [g] + others[k + 1 :])[0] for g in grid]
            ax.plot(c, f, 'o', ms=3, color='0.6', label='recordings')
            train = np.array([not r['extrapolated'] for r in mine], dtype=bool)
            ax.plot(c[train], f[train], 'o', ms=3, color='C0', label='training range')
            ax.plot(c[alarmed], f[alarmed], 'rx', ms=8, label='alarm')
            ax.plot(grid, line, '-', color='C1', lw=1, label='baseline (others at mean)')
            ax.set_xlabel(name)
        ax.set_ylabel('frequency (Hz)')
        ax.set_title(title + ': against the covariate', fontsize=9)
        for a in ax_row:
            a.grid(alpha=0.3)
            a.legend(fontsize=7, loc='best')
    fig.suptitle(
        f'{", ".join(sorted({f"{m.topic} {m.component}".strip() for m in modes}))}: learned '
        f'baseline of {baseline.trained_on}, P = {baseline.false_alarm:g} per recording per mode',
        fontsize=10,
    )
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return fig
