# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""``vib-estimator compare``: the algebraic estimator against the trackers of Section 5.4.

Every method -- the paper's algebraic estimator (``refine`` = 0) with the sinusoid model and with
the ``damped-sinusoid`` model (``Algebraic-damped``), this package's default configuration (the
same estimates refined by maximum likelihood over their segments, ``Algebraic-ML``),
Ziarani-Konrad (Eqs. 25-26), Hou (Eqs. 27-29), Mojiri-Bakhshai (Eqs. 30-33), all with the paper's
gains and again (``-A`` rows) with the gains tuned for the signal's amplitude
(:func:`tuned_gains`),
the flight-controller-style :class:`SlidingDFT` and a sliding matrix pencil
(:class:`SlidingMatrixPencil`, 2 s windows) -- runs on the same signals:

* ``5.3``: the simulated arm of Section 5.3 (Figs. 5-6, 45.55 g, ramp to 1 rad, 10 s);
* ``5.5``: the three tip masses of Section 5.5 (Fig. 7, 30 -> 45.55 -> 61.17 g, 6 s each);
* ``fig1``: Section 4's sine (A = 1, w = 10 rad/s, uniform noise in [-0.01, 0.01]), 10 s at 2 ms;

with ``--seeds`` independent noise draws each (a Monte Carlo over the measurement noise). Each
stretch of constant true frequency is a *segment*. Definitions (per method, case and segment):

* estimates that enter the statistics: the algebraic method's published estimates whose data
  window (``t - convergence_time`` to ``t``) lies inside the segment; for the continuous trackers,
  their per-sample estimate over the last half of the segment (when they have had the longest to
  converge: generous to them). Pooled over seeds: bias = mean - f, variance (population), MSE =
  bias^2 + variance, as in Table 2; and, since a few wild estimates can dominate the variance, the
  median error and the fraction ``>5%`` of estimates more than 5 % off;
* ``first``: time from the segment's start to the first estimate within 2 % of the truth (the
  algebraic method's first published one; a tracker's first sample, which may be a crossing);
* ``tracked``: time from the segment's start to the first instant from which the method's output
  stays within 2 % for one true period. The output is what a user reads at each sample: a tracker's
  current value, the algebraic method's latest published estimate (held). Median over the seeds
  where it happens; ``ok`` is the fraction of seeds where it does within the segment;
* ``CRLB``: the Cramer-Rao bound on the std for the data each method used, from the exact Fisher
  information (:func:`vib_estimator.analysis.bounds.window_crlb_std`): for the algebraic method the
  samples of each estimate's segment (RMS of the per-estimate bounds, the bound on the pooled
  variance); for a tracker, the samples from the segment's start to its ``tracked`` instant (the
  data it needed to converge; NaN when it never does). ``std/CRLB`` is the measured std over that;
* ``us/sample``: wall time of ``process()`` over all the case's records divided by their samples
  (compiled code warmed up first).

Plots like Figs. 6-7 (signal; every method's estimate; truth dashed; zoom) go to ``--out``.
"""

from __future__ import annotations

import argparse
import functools
import inspect
import math
import os
import sys
import time
from dataclasses import dataclass
from typing import Callable, Dict, List, Optional, Sequence, Tuple

import numpy as np

from ..core import EstimatorConfig, FrequencyEstimator
from ..sim import arm_model
from ..sim.signals import fig1_signal
from .baselines import (
    Hou,
    MojiriBakhshai,
    SlidingDFT,
    SlidingMatrixPencil,
    ZiaraniKonrad,
    hold_last,
)
from .bounds import window_crlb_std
from .outputs import check_output, progress

TOLERANCE = 0.02
OUTLIER = 0.05
#: Table 2 of the paper (algebraic method, Section 5.5): f (Hz) -> (bias Hz, variance Hz^2)
PAPER_TABLE_2 = {1.64: (7.0e-2, 1.2e-4), 1.33: (3.0e-2, 3.1e-5), 1.15: (1.5e-2, 7.1e-5)}
ALGEBRAIC = 'Algebraic'
#: the paper's algebraic estimator (refine = 0; the sinusoid model and the damped model) and its
#: maximum-likelihood refinement over the same segments (the paper's configuration,
#: ``EstimatorConfig.paper``: the comparison of Section 5.4 is the paper's)
ALGEBRAIC_CONFIGS = {
    ALGEBRAIC: EstimatorConfig.paper(refine=0),
    'Algebraic-damped': EstimatorConfig.paper(model='damped-sinusoid', refine=0),
    'Algebraic-ML': EstimatorConfig.paper(),
}
TRACKERS = (ZiaraniKonrad, Hou, MojiriBakhshai, SlidingDFT, SlidingMatrixPencil)
#: the adaptive trackers with amplitude-tuned gains: name -> (tracker, the gain that multiplies
#: the signal's amplitude squared in its frequency adaptation law)
AMPLITUDE_TUNED = {
    f'{cls.name}-A': (cls, gain)
    for cls, gain in ((ZiaraniKonrad, 'mu2'), (Hou, 'alpha2'), (MojiriBakhshai, 'xi2'))
}
#: noise seeds the tuning measures the amplitude on (never used for scoring: those are 0, 1, ...)
TUNING_SEEDS = (1000, 1001)
#: the grid of the tuned gain, as factors of the paper's
GAIN_FACTORS = (0.25, 0.5, 1.0, 2.0, 4.0, 8.0, 16.0, 32.0, 64.0)
METHODS = tuple(ALGEBRAIC_CONFIGS) + tuple(cls.name for cls in TRACKERS) + tuple(AMPLITUDE_TUNED)


#: a record: sample times (s), signal, true frequency of each sample (Hz)
Record = Tuple[np.ndarray, np.ndarray, np.ndarray]


@dataclass(frozen=True)
class Case:
    """A test signal: ``record(seed) -> Record``, its noise std and the unit of its samples."""

    key: str
    title: str
    record: Callable[[int], Record]
    noise_std: float
    unit: str = 'N·m'


def _arm(experiment):
    def record(seed):
        rec = experiment(seed)
        return rec.t, rec.torque, rec.f_true

    return record


def _fig1(seed):
    t = np.arange(5000) * 2e-3
    return t, fig1_signal(t, seed), np.full(len(t), 10.0 / (2 * math.pi))


_ARM_NOISE = math.hypot(arm_model.DEFAULT_NOISE_STD, arm_model.DEFAULT_QUANTUM / math.sqrt(12))
CASES = (
    Case(
        '5.3',
        'Section 5.3 / Fig. 6: 45.55 g, ramp to 1 rad',
        _arm(arm_model.experiment_5_3),
        _ARM_NOISE,
    ),
    Case(
        '5.5',
        'Section 5.5 / Fig. 7: 30 -> 45.55 -> 61.17 g',
        _arm(arm_model.experiment_5_5),
        _ARM_NOISE,
    ),
    Case(
        'fig1',
        'Section 4 / Fig. 1: sin(10 t + 1) + U(-0.01, 0.01)',
        _fig1,
        0.01 / math.sqrt(3),
        'dimensionless',
    ),
)


@dataclass
class Run:
    """One method on one record: per-sample output and, for the algebraic method, its estimates."""

    output: np.ndarray
    est_index: np.ndarray  # sample index of each published estimate (algebraic only)
    est_f: np.ndarray
    est_samples: np.ndarray
    est_start: np.ndarray  # t - convergence_time of each estimate
    seconds: float


@functools.lru_cache(maxsize=None)
def tuned_gains(case: 'Case') -> Dict[str, Dict[str, float]]:
    """Gains of the ``-A`` rows for ``case``, chosen on the records of :data:`TUNING_SEEDS`.

    The paper's gains are for a ~1 N m signal (Section 5.4). In each adaptation law the frequency
    update scales with the amplitude squared (omega' ~ mu2 A^2, eta' ~ alpha2 A^2,
    theta' ~ xi2 A^2; the other gains set rates independent of A), so that gain is the one to
    tune: it is the paper's times the factor of :data:`GAIN_FACTORS` (1/A^2 is ~15-25 on the
    arm's 0.2-0.3 N m) with the least mean squared error of the per-sample estimate over the last
    half of each segment (the statistic the table scores), summed over the tuning records.
    """
    records = [case.record(seed) for seed in TUNING_SEEDS]
    best = {}
    for name, (cls, gain) in AMPLITUDE_TUNED.items():
        paper = inspect.signature(cls).parameters[gain].default
        scores = [
            sum(_tuning_error(name, {gain: paper * k}, rec) for rec in records)
            for k in GAIN_FACTORS
        ]
        best[name] = {gain: paper * GAIN_FACTORS[int(np.argmin(scores))]}
    return best


def _tuning_error(name: str, gains: Dict[str, float], record: Record) -> float:
    t, y, f_true = record
    out = run_method(name, t, y, gains).output
    err = 0.0
    for i0, i1, f in segments(f_true):
        tail = out[(i0 + i1) // 2 : i1]
        err += float(np.mean(np.square(tail - f))) if np.isfinite(tail).all() else math.inf
    return err


def run_method(
    name: str, t: np.ndarray, y: np.ndarray, gains: Optional[Dict[str, float]] = None
) -> Run:
    """Run method ``name`` (one of :data:`METHODS`) fresh over a record; ``gains``: keyword
    arguments of an ``-A`` tracker (:func:`tuned_gains`; default the paper's gains)."""
    empty = np.empty(0)
    if name in ALGEBRAIC_CONFIGS:
        est = FrequencyEstimator(ALGEBRAIC_CONFIGS[name])
        t0 = time.perf_counter()
        e = est.process(t, y)
        seconds = time.perf_counter() - t0
        idx = np.searchsorted(t, e.t)
        marks = np.full(len(t), np.nan)
        marks[idx] = e.frequency_hz
        return Run(
            hold_last(marks), idx, e.frequency_hz, e.samples, e.t - e.convergence_time, seconds
        )
    if name in AMPLITUDE_TUNED:
        tracker = AMPLITUDE_TUNED[name][0](**(gains or {}))
    else:
        cls = next(c for c in TRACKERS if c.name == name)
        tracker = (
            cls(rate_hz=1.0 / np.median(np.diff(t))) if issubclass(cls, SlidingDFT) else cls()
        )
    t0 = time.perf_counter()
    out = tracker.process(t, y)
    return Run(out, empty.astype(int), empty, empty.astype(int), empty, time.perf_counter() - t0)


def segments(f_true: np.ndarray) -> List[Tuple[int, int, float]]:
    """(first index, end index, frequency) of each stretch of constant true frequency."""
    cuts = np.flatnonzero(np.diff(f_true) != 0) + 1
    bounds = np.concatenate(([0], cuts, [len(f_true)]))
    return [(int(a), int(b), float(f_true[a])) for a, b in zip(bounds[:-1], bounds[1:])]


def tracked_index(output: np.ndarray, f: float, i0: int, i1: int, period: int) -> Optional[int]:
    """First index in [i0, i1) from which ``output`` stays within 2 % of ``f`` for ``period``
    samples (inside the segment), or None."""
    with np.errstate(invalid='ignore'):
        ok = np.abs(output[i0:i1] / f - 1.0) <= TOLERANCE
    n = len(ok)
    # index of the next bad sample at or after each index
    nxt = np.minimum.accumulate(np.where(ok, n, np.arange(n))[::-1])[::-1]
    good = ok & (nxt - np.arange(n) >= period) & (np.arange(n) + period <= n)
    hits = np.flatnonzero(good)
    return i0 + int(hits[0]) if len(hits) else None


@dataclass
class SegmentResult:
    """What one run contributes to the statistics of one segment."""

    values: np.ndarray
    first: float
    tracked: float
    crlb_sq: np.ndarray


def evaluate(
    run: Run,
    t: np.ndarray,
    y: np.ndarray,
    seg: Tuple[int, int, float],
    noise_std: float,
    algebraic: bool,
) -> SegmentResult:
    """Statistics of one run over one segment (see the module docstring for the definitions)."""
    i0, i1, f = seg
    ts = float(np.median(np.diff(t)))
    period = int(round(1.0 / (f * ts)))
    ti = tracked_index(run.output, f, i0, i1, period)
    tracked = t[ti] - t[i0] if ti is not None else math.nan
    if algebraic:
        inside = (run.est_index >= i0) & (run.est_index < i1)
        within = inside & (np.abs(run.est_f / f - 1.0) <= TOLERANCE)
        first = t[run.est_index[within][0]] - t[i0] if within.any() else math.nan
        use = inside & (run.est_start >= t[i0] - 0.5 * ts)
        values = run.est_f[use]
        crlb = [
            window_crlb_std(y[k - n + 1 : k + 1], ts, f, noise_std)
            for k, n in zip(run.est_index[use], run.est_samples[use])
        ]
    else:
        with np.errstate(invalid='ignore'):
            within = np.flatnonzero(np.abs(run.output[i0:i1] / f - 1.0) <= TOLERANCE)
        first = t[i0 + within[0]] - t[i0] if len(within) else math.nan
        values = run.output[(i0 + i1) // 2 : i1]
        values = values[np.isfinite(values)]
        crlb = [window_crlb_std(y[i0 : ti + 1], ts, f, noise_std)] if ti is not None else []
    return SegmentResult(values, first, tracked, np.square(crlb))


@dataclass
class Row:
    """A line of the comparison table: one method on one segment of one case, over all seeds."""

    case: str
    method: str
    f_true: float
    n: int
    bias: float
    variance: float
    mse: float
    median_error: float
    outliers: float
    first: float
    tracked: float
    tracked_fraction: float
    crlb: float
    us_per_sample: float

    @property
    def std_over_crlb(self) -> float:
        return math.sqrt(self.variance) / self.crlb if self.crlb > 0 else math.nan


def _nanmedian(v: Sequence[float]) -> float:
    v = np.asarray(v, dtype=float)
    return float(np.median(v[np.isfinite(v)])) if np.isfinite(v).any() else math.nan


def compare(
    seeds: int,
    cases: Sequence[Case] = CASES,
    keep: Optional[Dict[str, Tuple[Record, Dict[str, Run]]]] = None,
) -> List[Row]:
    """Run the Monte Carlo; return the table rows. ``keep`` receives, per case, seed 0's record
    and runs (for the plots)."""
    for name in METHODS:  # compile and warm up before timing
        run_method(name, *CASES[-1].record(0)[:2])
    rows = []
    bar = progress(len(cases) * seeds, 'record', f'{len(METHODS)} methods')
    for case in cases:
        acc: Dict[Tuple[str, int], List[SegmentResult]] = {}
        seconds = dict.fromkeys(METHODS, 0.0)
        samples = 0
        segs = None
        gains = tuned_gains(case)
        for seed in range(seeds):
            t, y, f_true = case.record(seed)
            segs = segments(f_true)
            samples += len(t)
            for name in METHODS:
                run = run_method(name, t, y, gains.get(name))
                seconds[name] += run.seconds
                if seed == 0 and keep is not None:
                    keep.setdefault(case.key, ((t, y, f_true), {}))[1][name] = run
                for k, seg in enumerate(segs):
                    acc.setdefault((name, k), []).append(
                        evaluate(run, t, y, seg, case.noise_std, name in ALGEBRAIC_CONFIGS)
                    )
            bar.update()
        for name in METHODS:
            for k, (_, _, f) in enumerate(segs):
                res = acc[(name, k)]
                values = np.concatenate([r.values for r in res])
                crlb_sq = np.concatenate([r.crlb_sq for r in res])
                bias = float(values.mean() - f) if len(values) else math.nan
                var = float(values.var()) if len(values) else math.nan
                median = float(np.median(values) - f) if len(values) else math.nan
                outliers = (
                    float(np.mean(np.abs(values / f - 1) > OUTLIER)) if len(values) else math.nan
                )
                tracked = [r.tracked for r in res]
                rows.append(
                    Row(
                        case.key,
                        name,
                        f,
                        len(values),
                        bias,
                        var,
                        bias * bias + var,
                        median,
                        outliers,
                        _nanmedian([r.first for r in res]),
                        _nanmedian(tracked),
                        float(np.mean(np.isfinite(tracked))),
                        float(np.sqrt(crlb_sq.mean())) if len(crlb_sq) else math.nan,
                        1e6 * seconds[name] / samples,
                    )
                )
    bar.close()
    return rows


def _fmt(v: float, spec: str = '.2e') -> str:
    return '-' if not math.isfinite(v) else format(v, spec)


def _duration(seconds: float, f: float) -> str:
    return f'{seconds:.3f} ({seconds * f:.2f})' if math.isfinite(seconds) else '-'


HEADER = (
    'case',
    'f (Hz)',
    'method',
    'n',
    'bias (Hz)',
    'var (Hz²)',
    'MSE (Hz²)',
    'median err',
    '>5%',
    'first s (periods)',
    'tracked s (periods)',
    'ok',
    'CRLB (Hz)',
    'std/CRLB',
    'us/sample',
)


def table_cells(rows: Sequence[Row]) -> List[Tuple[str, ...]]:
    """The table's cells as strings, one tuple per row, in :data:`HEADER` order."""
    return [
        (
            r.case,
            f'{r.f_true:.3f}',
            r.method,
            str(r.n),
            _fmt(r.bias, '+.2e'),
            _fmt(r.variance),
            _fmt(r.mse),
            _fmt(r.median_error, '+.1e'),
            _fmt(100 * r.outliers, '.1f') + '%',
            _duration(r.first, r.f_true),
            _duration(r.tracked, r.f_true),
            f'{100 * r.tracked_fraction:.0f}%',
            _fmt(r.crlb),
            _fmt(r.std_over_crlb, '.1f'),
            _fmt(r.us_per_sample, '.3f'),
        )
        for r in rows
    ]


#: the text table's widest line, characters
TABLE_WIDTH = 100
#: the columns of :data:`HEADER` every block of the text table repeats (case, f, method)
KEY_COLUMNS = 3
#: the text table's blocks after the key columns: the accuracy, then the speed and the bound
TEXT_BLOCKS = (
    ('n', 'bias (Hz)', 'var (Hz²)', 'MSE (Hz²)', 'median err', '>5%', 'std/CRLB'),
    ('first s (periods)', 'tracked s (periods)', 'ok', 'CRLB (Hz)', 'us/sample'),
)


def format_table(rows: Sequence[Row]) -> str:
    """Fixed-width text table in the :data:`TEXT_BLOCKS` (separated by a blank line), each
    starting with the :data:`KEY_COLUMNS`, so that no line is wider than :data:`TABLE_WIDTH`."""
    cells = [HEADER] + table_cells(rows)
    widths = [max(len(c[i]) for c in cells) for i in range(len(HEADER))]
    blocks = [
        list(range(KEY_COLUMNS)) + [HEADER.index(name) for name in block] for block in TEXT_BLOCKS
    ]
    return '\n\n'.join(
        '\n'.join('  '.join(line[j].rjust(widths[j]) for j in b) for line in cells) for b in blocks
    )


def format_markdown(rows: Sequence[Row], seeds: int) -> str:
    """Markdown: Section 5.5's bias and variance next to Table 2, then the full table."""
    lines = [
        f'Section 5.5 (simulated arm, {seeds} noise seeds): bias / variance of each method '
        'against Table 2 of the paper (algebraic method on the real arm).',
        '',
        '| f (Hz) | paper bias | paper var | '
        + ' | '.join(f'{m} bias | {m} var' for m in METHODS)
        + ' |',
        '|---' * (3 + 2 * len(METHODS)) + '|',
    ]
    for f_paper, (b, v) in PAPER_TABLE_2.items():
        seg = [r for r in rows if r.case == '5.5' and abs(r.f_true - f_paper) < 0.01]
        by_method = {r.method: r for r in seg}
        cells = [f'{f_paper:.2f}', f'{b:.1e}', f'{v:.1e}']
        for m in METHODS:
            r = by_method.get(m)
            cells += [_fmt(r.bias, '+.1e'), _fmt(r.variance, '.1e')] if r else ['-', '-']
        lines.append('| ' + ' | '.join(cells) + ' |')
    lines += [
        '',
        'All cases (definitions in `vib_estimator/compare.py`):',
        '',
        '| ' + ' | '.join(HEADER) + ' |',
        '|---' * len(HEADER) + '|',
    ]
    lines += ['| ' + ' | '.join(c) + ' |' for c in table_cells(rows)]
    return '\n'.join(lines) + '\n'


def format_gains(cases: Sequence[Case] = CASES) -> str:
    """One line per case: the gains of the ``-A`` rows (:func:`tuned_gains`)."""
    lines = [
        f'amplitude-tuned gains (least MSE on seeds {TUNING_SEEDS[0]}-{TUNING_SEEDS[-1]}, '
        'the paper gain x ' + '/'.join(f'{k:g}' for k in GAIN_FACTORS) + '):'
    ]
    for case in cases:
        gains = tuned_gains(case)
        lines.append(
            f'  {case.key}: '
            + ', '.join(
                f'{name} {k} = {v:.4g}' for name, kw in gains.items() for k, v in kw.items()
            )
        )
    return '\n'.join(lines) + '\n'


#: markers of the algebraic estimates, line styles of the trackers (with colours C0-C9: after ten
#: methods a style repeats with another colour, so no two methods look alike)
ALGEBRAIC_MARKERS = ('*', 'P', 'X', 'D')
TRACKER_STYLES = ('-', '--', '-.', ':')


def method_styles(count: int) -> List[Tuple[str, str]]:
    """(colour, marker or line style) of each of ``count`` methods in :data:`METHODS` order, no
    two alike: the algebraic ones (first) get markers, the trackers line styles."""
    return [
        (
            f'C{i % 10}',
            ALGEBRAIC_MARKERS[i % len(ALGEBRAIC_MARKERS)]
            if name in ALGEBRAIC_CONFIGS
            else TRACKER_STYLES[(i // 10) % len(TRACKER_STYLES)],
        )
        for i, name in enumerate(METHODS[:count])
    ]


def plot_case(path: str, case: Case, record: Record, runs: Dict[str, Run]):
    """Figs. 6-7 layout: signal; every method's estimate with the truth dashed; a +-10 % zoom.
    The algebraic estimates are markers drawn over the trackers' lines. Returns the Figure."""
    from .plotting import pyplot

    plt = pyplot()
    t, y, f_true = record
    fig, axes = plt.subplots(3, 1, figsize=(9, 9), sharex=True)
    axes[0].plot(t, y, lw=0.6)
    axes[0].set_ylabel(f'signal ({case.unit})')
    axes[0].set_title(case.title)
    for ax in axes[1:]:
        for i, (a, b, f) in enumerate(segments(f_true)):
            ax.hlines(
                f,
                t[a],
                t[b - 1],
                colors='k',
                linestyles='--',
                zorder=4,
                label='true f' if i == 0 else None,
            )
        for i, (name, (colour, style)) in enumerate(zip(METHODS, method_styles(len(METHODS)))):
            run = runs[name]
            if name in ALGEBRAIC_CONFIGS:  # on top of the trackers, smaller ones nested
                ax.plot(
                    t[run.est_index],
                    run.est_f,
                    style,
                    ms=11 - 2 * i,
                    mec='k',
                    mew=0.5,
                    color=colour,
                    ls='none',
                    zorder=6,
                    label=name,
                )
            else:
                ax.plot(
                    t, run.output, lw=0.8, alpha=0.7, color=colour, ls=style, zorder=2, label=name
                )
        ax.set_ylabel('frequency (Hz)')
        ax.grid(alpha=0.3)
    axes[1].set_ylim(0, 3.5)
    axes[2].set_ylim(0.9 * f_true.min(), 1.1 * f_true.max())
    axes[2].set_title('zoom: +-10 % around the true frequencies', fontsize=9)
    axes[1].legend(loc='upper right', fontsize=8, ncol=3)
    axes[2].set_xlabel('time (s)')
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return fig


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        '--seeds',
        type=int,
        default=None,
        help='noise seeds per case (default 100; 10 with --quick)',
    )
    parser.add_argument('--quick', action='store_true', help='10 seeds (smoke test)')
    parser.add_argument('--out', default='out', help='directory for the PNG plots (default out/)')
    parser.add_argument('--markdown', metavar='FILE', help='also write the tables as markdown')


def run(args: argparse.Namespace) -> int:
    seeds = args.seeds if args.seeds is not None else (10 if args.quick else 100)
    try:
        if seeds < 1:
            raise ValueError(f'--seeds must be >= 1, got {seeds}')
        check_output(args.out, '--out', directory=True)
    except ValueError as err:
        print(f'vib-estimator compare: error: {err}', file=sys.stderr)
        return 2
    start = time.perf_counter()
    keep: Dict[str, Tuple[Record, Dict[str, Run]]] = {}
    rows = compare(seeds, keep=keep)
    print(
        f'{seeds} noise seeds per case; estimates within {100 * TOLERANCE:.0f} % count as '
        'converged\n(definitions: vib_estimator/analysis/compare.py)'
    )
    print(format_table(rows))
    print(format_gains(), end='')
    os.makedirs(args.out, exist_ok=True)
    for case in CASES:
        path = os.path.join(args.out, f'compare_{case.key.replace(".", "_")}.png')
        plot_case(path, case, *keep[case.key])
        print(f'wrote {path}')
    if args.markdown:
        with open(args.markdown, 'w') as fh:
            fh.write(format_markdown(rows, seeds) + '\n' + format_gains())
        print(f'wrote {args.markdown}')
    print(f'wall time {time.perf_counter() - start:.1f} s')
    return 0
