# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""``vib-estimator survey``: many recordings at once, one summary row each, and a health alarm.

Inputs are files, directories (searched recursively: a directory with ``metadata.yaml`` is one
rosbag2 bag; ``.mcap``, ``.db3`` and ``.csv`` files elsewhere are recordings) and globs. Each
recording is streamed (:mod:`..io.streaming`) through the same estimator as ``analyze``; a row is
written per recording x topic x component (x mode with ``--modes``): first stamp (ISO 8601 UTC),
duration, samples, estimates, the frequency and damping ratio with their 95 % intervals (by
default the weighted mean of the estimates, the interval from their stds and their scatter,
correlated estimates counted as such: :mod:`.interval`; ``--summary median``: the median and its
distribution-free interval), the median amplitude, and the estimator's counters. Several
channels (``--columns a,b,c|all`` of a CSV recording, ``--components x,y,z`` of a bag topic;
``excitation`` free or ambient): one joint estimation per recording (:mod:`.channels`), its rows
per mode with each channel's median shape, the median MAC and, against a baseline,
``mac_to_baseline``.

Health monitoring: against ``--baseline`` (a recording, whose rows are matched by topic,
component and mode, or a frequency in Hz), a row is flagged (``alarm``) when the relative change
of its frequency is beyond ``--alarm-rel`` with 95 % confidence, i.e. the whole interval
of the change (both frequencies' intervals combined) lies outside [-R, R].

Recordings are independent tasks: ``--jobs N`` runs them on a local process pool
(``concurrent.futures``), ``--scheduler ADDRESS`` on a Dask distributed cluster
(``dask scheduler``,
``dask worker ADDRESS``; every worker must have this package and see the files). Rows come back in
the order of the sorted recordings, whatever finished first, so every engine gives the same rows.
A recording that fails is one row with ``error`` set, and one line on stderr. Every entry of a
searched directory is accounted for: a recording gives rows, a folder holding no recording (not a
bag, nothing in it) an error row, and files that are not recordings are listed on stderr, one line
per folder. Damaged bag records are skipped and counted (column ``corrupt_records``, one
``warning:`` line on stderr per recording); with ``--strict`` they make the recording an error row.
Exit status: 0; 3 when ``--fail-on-alarm`` and a row is flagged; 1 when ``--strict`` and a row has
an error; 2 for bad arguments.
"""

from __future__ import annotations

import argparse
import atexit
import contextlib
import glob
import json
import math
import os
import sys
import threading
from concurrent.futures import ProcessPoolExecutor, as_completed
from concurrent.futures.process import BrokenProcessPool
from dataclasses import dataclass
from datetime import datetime, timezone
from pathlib import Path
from typing import Dict, Iterable, List, Optional, Sequence, Tuple

import numpy as np

from ..core import COUNTER_NAMES, EstimatorConfig
from ..core.choice import decide
from ..core.estimator import INPUT_COUNTERS
from ..core.shapes import mac
from ..errors import VibEstimatorError, report
from ..extras import optional
from ..io.csv_reader import CSV_SUFFIXES, column_names
from ..io.fields import DEFAULT_COMPONENT, check_component
from ..io.heap import M_MMAP_THRESHOLD, M_TRIM_THRESHOLD, MMAP_THRESHOLD, glibc, mallopt
from ..io.streaming import BagInfo, bag_info, is_csv, open_signal, supported_topics
from . import health
from .analyze import Run, add_config_arguments, estimate_rescued, make_config, rescues
from .channels import channel_list, joint_run, mode_shapes, need_joint, read_channels
from .choosing import damping_given, decided_config, decides, read_ahead, window_given
from .interval import combine
from .outputs import check_output, progress

_STATS = (
    'start_utc',
    'duration_s',
    'samples',
    'estimates',
    'frequency_hz',
    'frequency_lo_hz',
    'frequency_hi_hz',
    'damping',
    'amplitude',
)
#: columns of the weighted summary (:mod:`.interval`), after the counters
_INTERVAL_STATS = (
    'frequency_std_hz',
    'frequency_median_hz',
    'damping_lo',
    'damping_hi',
    'damping_std',
    'effective_estimates',
    'frequency_birge',
)
#: ``--summary``: the weighted mean of the estimates and its interval from their stds and
#: scatter (:func:`.interval.combine`), or their median and its order-statistic interval
SUMMARIES = ('weighted', 'median')
#: survey's model when neither ``--model`` nor ``--paper`` is given: the damped sinusoid, whose
#: natural frequency carries no bias on decaying records and which estimates the damping trended
DEFAULT_MODEL = 'damped-sinusoid'
_COUNTERS = tuple(c for c in COUNTER_NAMES if c not in ('received', 'estimates'))
#: the counters of the input stream, the same in every mode's row
_INPUT_COUNTERS = tuple(c for c in INPUT_COUNTERS if c in _COUNTERS) + (
    'gaps',
    'samples_lost',
    'skipped_outlier',
)
#: the columns of a row, in order
COLUMNS = (
    ('recording', 'topic', 'component', 'mode')
    + _STATS
    + _COUNTERS
    + (
        'messages_without_component',
        'corrupt_records',
    )
    + _INTERVAL_STATS
    + (
        'change_rel',
        'change_lo',
        'change_hi',
        'alarm',
        'error',
    )
)
_OUT_SUFFIXES = ('.csv', '.parquet', '.jsonl')
_UNIX_2000 = 946_684_800.0  # a CSV time column at least this large is taken as Unix time


@dataclass(frozen=True)
class Options:
    """What to read from each recording and how to estimate (picklable: sent to the workers)."""

    config: EstimatorConfig
    topics: Tuple[str, ...] = ()
    components: Tuple[str, ...] = ()
    column: Optional[str] = None
    #: a damaged bag record makes the recording an error row (instead of a counted skip)
    strict: bool = False
    #: how a recording's estimates are summarised (:data:`SUMMARIES`)
    summary: str = SUMMARIES[0]
    #: ``--columns``: a CSV recording's channels (names or indices, comma-separated, or
    #: ``all``), identified jointly when two or more
    columns: Optional[str] = None
    #: ``--components``: two or more fields of a bag topic, identified jointly
    joint_components: Tuple[str, ...] = ()
    #: no ``--excitation``: each recording's excitation (and ambient window, unless
    #: ``keep_window``) is decided from it (:mod:`.choosing`)
    decide: bool = False
    keep_window: bool = False
    #: ``--max-damping`` given: a steady oscillation's is not applied
    keep_damping: bool = False
    #: ``--covariates``: each recording's mean of these (:mod:`..io.covariates`) in its rows
    covariates: Tuple[str, ...] = ()
    #: a free decay of one mode that the free estimator gave no estimate of is read again by the
    #: mode tracker (:func:`.choosing.rescue`; decided, and no ``--model`` or ``--min-periods``)
    rescues: bool = False

    def kept(self) -> Tuple[bool, bool, bool]:
        """(keep_window, keep_periods, keep_damping) of :func:`.choosing.decided_config`: the
        free-decay window is never decided per recording -- a survey compares recordings, and a
        window that changed with a recording's noise would move its estimates' small model bias
        (0.1 % between 0.9 and 1.25 periods of a damped mode) like a drift."""
        return self.keep_window, True, self.keep_damping


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        'inputs',
        nargs='+',
        metavar='INPUT',
        help='recordings: files, directories (searched recursively), globs',
    )
    parser.add_argument(
        '--topic',
        action='append',
        default=[],
        help='topic to read (repeatable; default: every topic of a supported type)',
    )
    parser.add_argument(
        '--component',
        action='append',
        default=[],
        help='component to read (repeatable; each topic takes those valid for its '
        "type; default: the type's default)",
    )
    parser.add_argument(
        '--components',
        help='several fields of each bag topic, comma-separated: one set of modes with their '
        'shapes per recording (free decays or --excitation ambient; docs/survey.md)',
    )
    parser.add_argument('--column', help='CSV signal column (default: the second)')
    parser.add_argument(
        '--columns',
        help='several CSV signal columns, comma-separated names or indices, or all: one set of '
        'modes with their shapes per recording (free decays or --excitation ambient; '
        'docs/survey.md)',
    )
    add_config_arguments(parser, DEFAULT_MODEL)
    _add_output_arguments(parser)
    health.add_arguments(parser)
    parser.add_argument(
        '--strict',
        action='store_true',
        help='a damaged bag record fails its recording; exit 1 if any recording failed',
    )
    parser.add_argument(
        '--jobs',
        type=int,
        default=os.cpu_count() or 1,
        help='local worker processes (default: the number of cores)',
    )
    parser.add_argument(
        '--scheduler',
        metavar='ADDRESS',
        help='run on this Dask distributed scheduler (e.g. tcp://host:8786)',
    )


def _add_output_arguments(parser: argparse.ArgumentParser) -> None:
    """The options of what survey writes: the rows' summary and format, files, the baseline and
    the alarm."""
    parser.add_argument(
        '--summary',
        choices=SUMMARIES,
        default=SUMMARIES[0],
        help="a recording's frequency and damping: the weighted mean of the estimates with an "
        'interval from their stds and scatter (default), or their median with an order-statistic '
        'interval (the former default)',
    )
    parser.add_argument('--format', choices=('table', 'csv', 'jsonl'), default='table')
    parser.add_argument(
        '--out', metavar='FILE', help='also write the rows to FILE (.csv, .parquet, .jsonl)'
    )
    parser.add_argument(
        '--plot', metavar='FILE.png', help='frequency and damping vs recording time'
    )
    parser.add_argument(
        '--report',
        metavar='DIR',
        help='write DIR/index.html: the trend with the baseline and the alarm band, one row per '
        'recording (docs/report.md)',
    )
    parser.add_argument(
        '--baseline',
        help='a recording, or a frequency in Hz, to compare against; or a saved learned '
        'baseline (FILE.yaml, --save-baseline)',
    )
    parser.add_argument(
        '--alarm-rel',
        type=float,
        default=0.01,
        help='relative frequency change that raises the alarm (default 0.01)',
    )
    parser.add_argument(
        '--fail-on-alarm', action='store_true', help='exit 3 if any row is flagged'
    )


# ------------------------------------------------------------------------------ finding recordings


def _is_bag_dir(path: Path) -> bool:
    return (path / 'metadata.yaml').is_file()


#: the files a folder's search takes for recordings: the bags' storage files and the CSV tables
#: (:data:`..io.csv_reader.CSV_SUFFIXES`) but ``.txt`` (a folder's notes; named, one is read)
_RECORDING_SUFFIXES = ('.mcap', '.db3') + tuple(s for s in CSV_SUFFIXES if s != '.txt')


def _in_directory(root: Path, ignored: List[Path]) -> Iterable[Path]:
    """The recordings under ``root``; a folder without any (no recording file, no subfolder) is
    yielded itself (its row says it is not a bag), other files are appended to ``ignored``.
    Symbolic links to folders and files are followed (a folder reached twice, e.g. by a link
    cycle, is searched once)."""
    seen = set()
    for folder, dirs, files in os.walk(root, followlinks=True):
        here = Path(folder)
        real = os.path.realpath(here)
        if real in seen:
            dirs.clear()
            continue
        seen.add(real)
        if _is_bag_dir(here):
            dirs.clear()
            yield here
            continue
        dirs.sort()
        recordings = [
            here / n for n in sorted(files) if Path(n).suffix.lower() in _RECORDING_SUFFIXES
        ]
        ignored.extend(
            here / n for n in sorted(files) if Path(n).suffix.lower() not in _RECORDING_SUFFIXES
        )
        if not recordings and not dirs:
            yield here
        yield from recordings


def find_recordings(inputs: Sequence[str], ignored: Optional[List[Path]] = None) -> List[Path]:
    """Every recording named by ``inputs``, sorted, once each; a name matching nothing, and a
    folder holding no recording, is kept (its row will say so). Files of searched folders that
    are not recordings are appended to ``ignored``."""
    found = set()
    ignored = [] if ignored is None else ignored
    for name in inputs:
        matches = sorted(glob.glob(name, recursive=True)) if glob.has_magic(name) else [name]
        for match in (Path(m) for m in matches or [name]):
            if match.is_dir() and not _is_bag_dir(match):
                found.update(_in_directory(match, ignored))
            else:
                found.add(match)
    return sorted(found)


def is_recording(path: Path) -> bool:
    """True for what :func:`find_recordings` returns that is a recording (a bag folder, an
    existing file), False for a name matching nothing or a folder without any."""
    return _is_bag_dir(path) or path.is_file()


# ---------------------------------------------------------------------------------- one recording


def median_interval(values: np.ndarray) -> Tuple[float, float, float]:
    """Median of the finite values and its distribution-free 95 % interval (order statistics of
    the binomial(n, 1/2) quantiles); the interval is NaN below 6 values, where none exists."""
    from scipy.stats import binom

    x = np.sort(values[np.isfinite(values)])
    n = len(x)
    if n == 0:
        return math.nan, math.nan, math.nan
    if n < 6:
        return float(np.median(x)), math.nan, math.nan
    j = int(binom.ppf(0.025, n, 0.5))
    return float(np.median(x)), float(x[max(j - 1, 0)]), float(x[min(n - j, n - 1)])


def _iso(seconds: Optional[float]) -> str:
    if seconds is None or not seconds >= _UNIX_2000:
        return ''
    return datetime.fromtimestamp(seconds, timezone.utc).isoformat().replace('+00:00', 'Z')


def _row(recording: Path, topic: str, component: str, mode: int, **fields) -> Dict:
    row = dict.fromkeys(COLUMNS, math.nan)
    row.update(
        recording=str(recording),
        topic=topic,
        component=component,
        mode=mode,
        start_utc='',
        alarm=False,
        error='',
    )
    row.update(fields)
    return row


def summarise(est, take: np.ndarray, summary: str = SUMMARIES[0]) -> Dict:
    """The frequency, damping and amplitude fields of the estimates ``est[take]`` (an
    :class:`~vib_estimator.core.EstimateArrays` and a mask), by ``summary`` (:data:`SUMMARIES`)."""
    f_median, f_lo, f_hi = median_interval(est.frequency_hz[take])
    fields = dict(
        frequency_hz=f_median,
        frequency_lo_hz=f_lo,
        frequency_hi_hz=f_hi,
        frequency_median_hz=f_median,
        damping=median_interval(est.damping[take])[0],
        amplitude=median_interval(est.amplitude[take])[0],
    )
    if summary == 'median':
        return fields
    t, span = est.t[take], est.convergence_time[take]
    f = combine(est.frequency_hz[take], est.frequency_std_hz[take], t, span)
    fields.update(
        frequency_hz=f.value,
        frequency_lo_hz=f.lo,
        frequency_hi_hz=f.hi,
        frequency_std_hz=f.std,
        effective_estimates=f.n_eff,
        frequency_birge=f.birge,
    )
    if np.isfinite(est.damping[take]).any():
        d = combine(est.damping[take], est.damping_std[take], t, span)
        fields.update(damping=d.value, damping_lo=d.lo, damping_hi=d.hi, damping_std=d.std)
    return fields


def _stat_rows(
    recording: Path, signal, result, modes: int, summary: str, joint=None, component=None
) -> List[Dict]:
    """The rows of one streamed signal: one, or one per mode. ``joint``: the
    :class:`..core.estimator.JointEstimates` of a joint run (``signal`` None for CSV
    columns), whose rows gain the shape fields (:func:`mode_shape_fields`) and are named
    ``component`` (the channels, comma-separated)."""
    est = result.estimates
    origin = None if signal is None else signal.origin_ns
    start = origin * 1e-9 if origin is not None else result.first_t
    shapes = {} if joint is None else mode_shapes(joint)
    rows = []
    modes = modes or int(est.mode.max(initial=0))  # a joint estimator numbers its modes
    for mode in range(1, modes + 1) if modes else [0]:
        take = est.mode == mode
        # the input counters (samples used, skipped, gaps) are the stream's, under every mode and
        # excitation; a mode's own counters (its estimates, rejections) where the estimator keeps
        # them (a joint run: the mode's estimates only)
        stream = result.estimator.counters
        counters = {c: stream.get(c, 0) for c in _INPUT_COUNTERS}
        if not modes:
            counters = stream
        else:
            counters.update(result.estimator.mode_counters().get(mode, {}))
        rows.append(
            _row(
                recording,
                '' if signal is None else signal.topic,
                component or signal.component or signal.label,
                mode,
                start_utc=_iso(start),
                duration_s=result.last_t - result.first_t,
                samples=result.estimator.counters['received'],
                estimates=int(take.sum()),
                messages_without_component=0 if signal is None else signal.skipped,
                corrupt_records=0 if signal is None else signal.corrupt,
                **summarise(est, take, summary),
                **{c: counters.get(c, 0) for c in _COUNTERS},
                **({} if joint is None else mode_shape_fields(joint, take, shapes.get(mode))),
            )
        )
    return rows


def mode_shape_fields(joint, take: np.ndarray, shape) -> Dict:
    """A joint run's mode fields: per channel ``<name>``, ``shape_<name>`` and
    ``shape_std_<name>`` (the medians over the mode's estimates ``take``, as ``analyze``'s
    :func:`.channels.mode_shapes`), and ``mac``, the median MAC of consecutive estimates (NaN
    for a mode without any, or estimated once)."""
    amp, std = (np.full(len(joint.channels), math.nan),) * 2 if shape is None else shape[1:]
    macs = joint.mac[take]
    macs = macs[np.isfinite(macs)]
    fields = {f'shape_{n}': float(a) for n, a in zip(joint.channels, amp)}
    fields.update({f'shape_std_{n}': float(s) for n, s in zip(joint.channels, std)})
    fields['mac'] = float(np.median(macs)) if macs.size else math.nan
    return fields


def row_shape(row: Dict) -> Optional[np.ndarray]:
    """The median shape of a joint run's row (:func:`mode_shape_fields`), None for other rows."""
    names = row['component'].split(',')
    keys = [f'shape_{n}' for n in names]
    if len(names) < 2 or not all(k in row for k in keys):
        return None
    shape = np.array([row[k] for k in keys], dtype=np.float64)
    return shape if np.isfinite(shape).all() else None


Target = Tuple[Optional[str], Optional[str], Tuple[str, ...]]


def _targets(path: Path, options: Options) -> Tuple[List[Target], Optional[BagInfo]]:
    """(topic, component, channels) to read from a recording (``channels``: two or more, read
    jointly; a CSV file's one ``--columns`` column; else none), and the bag's metadata (read
    once)."""
    if is_csv(path):
        names = () if options.columns is None else tuple(column_names(path, options.columns))
        return [(None, None, names)], None
    info = bag_info(path)
    topics = info.topics
    chosen = (
        {t: topics.get(t, '') for t in options.topics}
        if options.topics
        else supported_topics(topics)
    )
    if not chosen:
        open_signal(path, info=info)  # raises the error naming the bag's topics
    if options.joint_components:
        return _joint_targets(path, chosen, options), info
    pairs = []
    for topic, kind in sorted(chosen.items()):
        valid = [c for c in options.components if _valid(c, kind)]
        if options.components and not valid and not options.topics:
            continue
        for component in valid or [
            options.components[0] if options.components else DEFAULT_COMPONENT.get(kind)
        ]:
            pairs.append((topic, component, ()))
    return pairs, info


def _joint_targets(path: Path, chosen: Dict[str, str], options: Options) -> List[Target]:
    """The topics whose type has every ``--components`` field (with ``--topic``: those
    topics, an invalid field being their error row); ValueError if none has."""
    names = options.joint_components
    targets = [
        (topic, None, names)
        for topic, kind in sorted(chosen.items())
        if options.topics or all(_valid(c, kind) for c in names)
    ]
    if not targets:
        raise ValueError(
            f'no topic of {path} has the fields {",".join(names)} (topics: '
            f'{", ".join(f"{t} ({k})" for t, k in sorted(chosen.items()))})'
        )
    return targets


def _valid(component: str, kind: str) -> bool:
    try:
        check_component(component, kind)
        return True
    except ValueError:
        return False


_tuned_tasks = 0  # survey tasks running with raised thresholds
_tuned_lock = threading.Lock()


@contextlib.contextmanager
def streaming_malloc():
    """Let glibc keep freed blocks for the next one while a recording streams, in a process
    started with ``MALLOC_TRIM_THRESHOLD_`` (a Dask nanny's workers: 65536). That setting also
    fixes the mmap threshold at 128 KiB, so every block-sized array is mapped, faulted in and
    unmapped again: a survey task ran ~25 % more CPU than in a plain process. Thresholds are
    raised (32 MiB mmap, 64 MiB trim) for the task and put back to the environment's values when
    the worker's last running task ends; elsewhere (not glibc, or no such variable) a no-op."""
    trim = os.environ.get('MALLOC_TRIM_THRESHOLD_')
    if trim is None or not trim.isdigit() or not glibc():
        yield
        return
    global _tuned_tasks
    with _tuned_lock:
        _tuned_tasks += 1
        mallopt(M_MMAP_THRESHOLD, 32 << 20)
        mallopt(M_TRIM_THRESHOLD, 64 << 20)
    try:
        yield
    finally:
        with _tuned_lock:
            _tuned_tasks -= 1
            if _tuned_tasks == 0:
                mallopt(
                    M_MMAP_THRESHOLD,
                    int(os.environ.get('MALLOC_MMAP_THRESHOLD_', MMAP_THRESHOLD)),
                )
                mallopt(M_TRIM_THRESHOLD, int(trim))


def survey_recording(path: Path, options: Options) -> List[Dict]:
    """The rows of one recording; any failure is one row with ``error`` set (never raises)."""
    with streaming_malloc():
        rows = _recording_rows(path, options)
    if options.covariates:
        health.add_covariates(path, rows, options.covariates)
    return rows


def _recording_rows(path: Path, options: Options) -> List[Dict]:
    try:
        targets, info = _targets(path, options)
    except Exception as err:  # noqa: BLE001 -- a bad recording is a row, not the end of the survey
        return [_error_row(path, '', '', err)]
    rows: List[Dict] = []
    for topic, component, channels in targets:
        try:
            if len(channels) > 1:
                rows.extend(_joint_recording_rows(path, topic, channels, options, info))
                continue
            column = channels[0] if channels else options.column
            signal = open_signal(path, topic, component, column, options.strict, info=info)
            config, blocks, d = options.config, None, None
            if options.decide:
                ahead, blocks = read_ahead(signal.blocks())
                if ahead is not None:
                    d = decide(*ahead, 1, config.ambient_window_s, given=config.lines_hz or ())
                    config = decided_config(config, d, 'survey', *options.kept())[0]
            config, result, _ = estimate_rescued(
                signal, config, d, options.rescues, 'survey', blocks=blocks
            )
            rows.extend(_stat_rows(path, signal, result, config.modes, options.summary))
        except Exception as err:  # noqa: BLE001 -- as above
            rows.append(_error_row(path, topic or '', component or ','.join(channels), err))
    return rows


def _joint_recording_rows(path, topic, names, options: Options, info) -> List[Dict]:
    """The rows of a joint identification of the channels ``names`` of one recording."""
    t, y, names, signal = read_channels(path, topic, names, options.strict, info)
    if not len(t):
        raise ValueError(f'{path} holds no samples')
    config = options.config
    if options.decide:
        d = decide(t, y, len(names), config.ambient_window_s, given=config.lines_hz or ())
        config = decided_config(config, d, 'survey', *options.kept())[0]
    estimator, joint = joint_run(t, y, names, config)
    result = Run(estimator, joint.estimates, float(t[0]), float(t[-1]), None)
    modes = options.config.modes
    return _stat_rows(path, signal, result, modes, options.summary, joint, ','.join(names))


def _error_row(path: Path, topic: str, component: str, err: BaseException) -> Dict:
    detail = (str(err).strip() or type(err).__name__).splitlines()[0]
    return _row(path, topic, component, 0, error=detail)


# ------------------------------------------------------------------------------- running them all


def _progress(total: int):
    return progress(total, 'recording')


def survey(
    recordings: Sequence[Path], options: Options, jobs: int = 1, scheduler: Optional[str] = None
) -> List[Dict]:
    """The rows of every recording, in the order of ``recordings``: in this process
    (``jobs`` 1), on a local process pool, or on the Dask scheduler at ``scheduler``."""
    bar = _progress(len(recordings))
    try:
        if scheduler is None and jobs <= 1:
            parts = []
            for path in recordings:
                parts.append(survey_recording(path, options))
                bar.update()
        else:
            parts = _on_executor(recordings, options, jobs, scheduler, bar)
    finally:
        bar.close()
    return [row for part in parts for row in part]


_local_pools: Dict[int, ProcessPoolExecutor] = {}  # jobs -> the pool kept for later surveys


def local_pool(jobs: int, fresh: bool = False) -> ProcessPoolExecutor:
    """The process pool of ``jobs`` workers: started by the first survey that asks for it and kept
    for the later ones of this process (shut down at exit), so a process that surveys repeatedly
    (a monitoring loop, the benchmark) starts its workers, and loads the kernels in them, once.
    ``fresh``: replace the kept pool (one whose worker died is broken for good)."""
    pool = _local_pools.get(jobs)
    if pool is None or fresh:
        if pool is not None:
            pool.shutdown(wait=False, cancel_futures=True)
        pool = _local_pools[jobs] = ProcessPoolExecutor(max_workers=jobs)
        atexit.register(pool.shutdown)
    return pool


def _on_executor(recordings, options, jobs, scheduler, bar) -> List[List[Dict]]:
    client = None
    distributed = None if scheduler is None else optional('distributed')
    if distributed is not None:
        client = distributed.Client(scheduler)
        executor = client.get_executor(pure=False)
    else:
        executor = local_pool(jobs)
    try:
        try:
            futures = [executor.submit(survey_recording, path, options) for path in recordings]
        except BrokenProcessPool:  # a worker of the kept pool died in an earlier survey
            executor = local_pool(jobs, fresh=True)
            futures = [executor.submit(survey_recording, path, options) for path in recordings]
        for _ in as_completed(futures):
            bar.update()
        return [_result(future, path) for future, path in zip(futures, recordings)]
    finally:
        if client is not None:
            executor.shutdown()
            client.close()


def _result(future, path: Path) -> List[Dict]:
    try:
        return future.result()
    except Exception as err:  # noqa: BLE001 -- a worker that died: one error row
        return [_error_row(path, '', '', err)]


# ------------------------------------------------------------------------------ health monitoring


def _key(row: Dict) -> Tuple[str, str, int]:
    return row['topic'], row['component'], row['mode']


def baseline_rows(baseline: str, options: Options) -> Dict[Tuple, Tuple]:
    """{(topic, component, mode) or None: (median, lo, hi, shape)} of ``--baseline`` (``shape``:
    a joint run's median mode shape, :func:`row_shape`, else None); a number is one exact
    frequency for every row. ValueError if the baseline gives no frequency."""
    try:
        hz = float(baseline)
    except ValueError:
        hz = None
    if hz is not None:
        if not hz > 0:
            raise ValueError(f'--baseline frequency must be > 0 Hz, got {baseline}')
        return {None: (hz, hz, hz, None)}
    if not Path(baseline).exists():
        raise ValueError(f'--baseline {baseline!r} is neither a frequency (Hz) nor a recording')
    rows = [
        r
        for r in survey_recording(Path(baseline), options)
        if not r['error'] and np.isfinite(r['frequency_hz'])
    ]
    if not rows:
        raise ValueError(f'baseline {baseline} gives no frequency estimate')
    table = {
        _key(r): (r['frequency_hz'], r['frequency_lo_hz'], r['frequency_hi_hz'], row_shape(r))
        for r in rows
    }
    if len(rows) == 1:
        table[None] = next(iter(table.values()))
    return table


def flag(rows: List[Dict], base: Dict, alarm_rel: float) -> None:
    """Set the change columns and ``alarm`` of every row against the baseline ``base``; a
    joint run's row matched to a baseline row with a shape also ``mac_to_baseline`` (the MAC of
    the two median shapes; no alarm)."""
    for row in rows:
        ref = base.get(_key(row), base.get(None))
        if ref is None or row['error']:
            continue
        f0, lo0, hi0, shape0 = ref
        shape = row_shape(row)
        if shape0 is not None and 'mac' in row and _key(row) in base:  # the same channels
            row['mac_to_baseline'] = math.nan if shape is None else mac(shape, shape0)
        row['change_rel'] = row['frequency_hz'] / f0 - 1
        row['change_lo'] = row['frequency_lo_hz'] / hi0 - 1
        row['change_hi'] = row['frequency_hi_hz'] / lo0 - 1
        row['alarm'] = bool(row['change_hi'] < -alarm_rel or row['change_lo'] > alarm_rel)


# ------------------------------------------------------------------------------------- output


def _plain(value):
    """JSON/CSV-friendly scalar: NaN as None, numpy scalars as Python ones."""
    if isinstance(value, (float, np.floating)):
        return None if value != value else float(value)
    return value.item() if isinstance(value, np.generic) else value


def row_columns(rows: List[Dict]) -> Tuple[str, ...]:
    """:data:`COLUMNS`, then the fields only some rows have (a joint run's shapes, ``mac``,
    ``mac_to_baseline``) in the order they first appear."""
    extra = dict.fromkeys(k for row in rows for k in row if k not in COLUMNS)
    return COLUMNS + tuple(extra)


def write_rows(rows: List[Dict], fmt: str, out) -> None:
    """Rows as ``table``, ``csv`` or ``jsonl`` text on the stream ``out``."""
    if fmt == 'jsonl':
        for row in rows:
            out.write(json.dumps({k: _plain(v) for k, v in row.items()}) + '\n')
    elif fmt == 'csv':
        import csv

        columns = row_columns(rows)
        writer = csv.writer(out, lineterminator='\n')
        writer.writerow(columns)
        for row in rows:
            row = {**dict.fromkeys(columns, math.nan), **row}
            writer.writerow(
                [
                    ''
                    if _plain(row[k]) is None
                    else repr(_plain(row[k]))
                    if isinstance(row[k], float)
                    else row[k]
                    for k in columns
                ]
            )
    else:
        out.write(
            f'{"recording":<28} {"topic":<18} {"component":<22} {"mode":>4} '
            f'{"start (UTC)":<20} {"dur (s)":>8} {"samples":>9} {"est":>5} '
            f'{"f (Hz)":>10} {"95% interval":>21} {"damping":>8} {"change":>8} alarm\n'
        )
        for r in rows:
            if r['error']:
                out.write(f'{_short(r["recording"]):<28} {r["topic"]:<18} error: {r["error"]}\n')
                continue
            out.write(
                f'{_short(r["recording"]):<28} {r["topic"]:<18} {r["component"]:<22} '
                f'{r["mode"]:>4} {r["start_utc"][:19]:<20} {r["duration_s"]:8.1f} '
                f'{r["samples"]:9d} {r["estimates"]:5d} {r["frequency_hz"]:10.5f} '
                f'[{r["frequency_lo_hz"]:9.5f},{r["frequency_hi_hz"]:9.5f}] '
                f'{r["damping"]:8.5f} {r["change_rel"]:+8.2%} '
                f'{"ALARM" if r["alarm"] else ""}{_shape_text(r)}\n'
            )


def _shape_text(row: Dict) -> str:
    """A joint run's row in the table: its median MAC (and to the baseline) and shape."""
    if 'mac' not in row:
        return ''
    names = row['component'].split(',')
    shape = ' '.join(f'{row[f"shape_{n}"]:+.2f}' for n in names)
    base = f' base {row["mac_to_baseline"]:.3f}' if 'mac_to_baseline' in row else ''
    return f' MAC {row["mac"]:.3f}{base} shape {shape}'


def _short(name: str, width: int = 28) -> str:
    return name if len(name) <= width else '...' + name[-(width - 3) :]


def write_file(rows: List[Dict], path: Path) -> None:
    """``--out``: the rows as .csv, .jsonl, or .parquet (pyarrow; without it, the .csv beside)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    if path.suffix == '.parquet':
        pa, pq = optional('pyarrow'), optional('pyarrow.parquet')
        if pa is not None and pq is not None:
            columns = row_columns(rows)
            full = [{**dict.fromkeys(columns, math.nan), **row} for row in rows]
            pq.write_table(pa.Table.from_pylist(full), path)
            return
        path = path.with_suffix('.csv')  # without pyarrow (its warning line says so)
    with path.open('w', newline='') as handle:
        write_rows(rows, 'csv' if path.suffix == '.csv' else 'jsonl', handle)


def alarm_band(ref: Tuple[float, float, float], alarm_rel: float) -> Tuple[float, float]:
    """The frequencies (Hz) a recording's 95 % interval must leave wholly to alarm (:func:`flag`):
    the baseline's interval ``ref`` = (median, lo, hi) widened by ``alarm_rel`` each side."""
    return ref[1] * (1 - alarm_rel), ref[2] * (1 + alarm_rel)


def with_gaps(good: List[Dict], key) -> List[Dict]:
    """The rows of ``key`` (topic, component, mode) over every recording of ``good``, by start
    time: a recording where that mode was not found gets a row of NaNs, so that its line breaks
    there instead of joining the recordings either side."""
    start = {r['recording']: r['start_utc'] for r in good}
    mine = {r['recording']: r for r in good if _key(r) == key}
    order = sorted(start, key=lambda rec: (start[rec], rec))
    return [mine.get(rec) or _row(Path(rec), *key, start_utc=start[rec]) for rec in order]


def _bars(ax, x, line: List[Dict], name: str, colour: str, label: str) -> np.ndarray:
    """Plot the rows' ``name`` (frequency or damping) with their 95 % intervals as bars."""
    value = np.array([r[name + '_hz' if name == 'frequency' else name] for r in line])
    ends = ('_lo_hz', '_hi_hz') if name == 'frequency' else ('_lo', '_hi')
    err = np.abs(np.array([[r[name + end] for r in line] for end in ends]) - value)
    ax.errorbar(
        x, value, yerr=np.nan_to_num(err), marker='o', ms=3, capsize=2, color=colour, label=label
    )
    return value


def plot_trend(
    rows: List[Dict], path: Path, base: Optional[Dict] = None, alarm_rel: Optional[float] = None
):
    """Frequency (and damping, when estimated) against recording time, one line per
    topic/component/mode, with the 95 % intervals as bars and the flagged recordings marked; with
    the baseline ``base`` (:func:`baseline_rows`) its median and the alarm band
    (:func:`alarm_band`) of ``alarm_rel``. Returns the Figure."""
    from .plotting import pyplot

    plt = pyplot()
    good = [r for r in rows if not r['error'] and np.isfinite(r['frequency_hz'])]
    damped = any(np.isfinite(r['damping']) for r in good)
    fig, axes = plt.subplots(
        2 if damped else 1, 1, sharex=True, figsize=(12, 6 if damped else 4), squeeze=False
    )
    ax_f = axes[0, 0]
    for n, key in enumerate(sorted({_key(r) for r in good})):
        colour = f'C{n % 10}'
        line = with_gaps(good, key)
        x = [
            datetime.fromisoformat(r['start_utc'].replace('Z', '+00:00')) if r['start_utc'] else i
            for i, r in enumerate(line)
        ]
        label = ' '.join(str(k) for k in key if k not in ('', 0))
        f = _bars(ax_f, x, line, 'frequency', colour, f'{label}: frequency, 95 % interval')
        alarmed = [i for i, r in enumerate(line) if r['alarm']]
        ax_f.plot(
            [x[i] for i in alarmed], f[alarmed], 'rx', ms=9, label='alarm' if alarmed else None
        )
        ref = None if base is None else base.get(key, base.get(None))
        if ref is not None:
            ax_f.axhline(ref[0], color=colour, ls='--', lw=1.0, label=f'baseline {ref[0]:.5g} Hz')
            if alarm_rel is not None:
                lo, hi = alarm_band(ref, alarm_rel)
                ax_f.axhspan(
                    lo,
                    hi,
                    color=colour,
                    alpha=0.12,
                    label=f'no-alarm band: baseline 95 % interval ±{100 * alarm_rel:g} %',
                )
        if damped:
            _bars(axes[1, 0], x, line, 'damping', colour, label)
    ax_f.set_ylabel('frequency (Hz)')
    explain = ': a recording alarms when its 95 % interval lies wholly outside the band'
    ax_f.set_title('frequency trend' + ('' if base is None else explain), fontsize=10)
    if damped:
        axes[1, 0].set_ylabel('damping ratio')
    axes[-1, 0].set_xlabel('recording start (UTC)')
    unique: Dict[str, object] = {}
    for handle, text in zip(*ax_f.get_legend_handles_labels()):
        unique.setdefault(text, handle)  # a label once: its first line
    ax_f.legend(
        unique.values(), unique.keys(), fontsize=8, loc='upper left', bbox_to_anchor=(1.01, 1.0)
    )  # beside the axes: the alarms stay visible
    for ax in axes[:, 0]:
        ax.grid(alpha=0.3)
    fig.autofmt_xdate()
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return fig


def write_survey_page(args: argparse.Namespace, rows: List[Dict], base) -> None:
    """``--report DIR``: the trend (:func:`plot_trend`) and a page with a row per recording."""
    from .report import command_line, write_survey_report

    folder = Path(args.report)
    good = [r for r in rows if not r['error'] and np.isfinite(r['frequency_hz'])]
    if good:
        plot_trend(rows, folder / 'trend.png', base, args.alarm_rel)
    baseline = None
    if base is not None:
        baseline = f'{args.baseline}, alarm beyond ±{100 * args.alarm_rel:g} % (--alarm-rel)'
    path = write_survey_report(folder, rows, command_line(args), baseline, bool(good))
    print(f'vib-estimator survey: report written to {path}', file=sys.stderr)


def report_entries(rows: List[Dict], ignored: Sequence[Path], out) -> None:
    """One stderr line per failed recording, per recording with damaged records skipped, and per
    folder with files that are not recordings."""
    prog = 'vib-estimator survey'
    for row in rows:
        if row['error']:
            out.write(f'{prog}: error: {row["recording"]}: {row["error"]}\n')
        elif row['corrupt_records']:
            out.write(
                f'{prog}: warning: {row["recording"]}: skipped {row["corrupt_records"]} '
                f'damaged record(s) of {row["topic"]} (`vib-estimator analyze` says '
                f'which); --strict makes this an error\n'
            )
    folders: Dict[Path, List[str]] = {}
    for path in ignored:
        folders.setdefault(path.parent, []).append(path.name)
    for folder, names in sorted(folders.items()):
        out.write(
            f'{prog}: {folder}: {len(names)} file(s) not a recording (not '
            f'{", ".join(_RECORDING_SUFFIXES)}), ignored: {", ".join(names)}\n'
        )


def _options(args: argparse.Namespace) -> Options:
    if args.out and Path(args.out).suffix not in _OUT_SUFFIXES:
        raise ValueError(f'--out must end in {", ".join(_OUT_SUFFIXES)}, got {args.out}')
    check_output(args.out, '--out')
    check_output(args.plot, '--plot')
    check_output(getattr(args, 'report', None), '--report', directory=True)
    if args.jobs < 1:
        raise ValueError(f'--jobs must be >= 1, got {args.jobs}')
    if not args.alarm_rel >= 0:
        raise ValueError(f'--alarm-rel must be >= 0, got {args.alarm_rel}')
    config = make_config(args)
    if args.model is None and not args.paper:
        config = config.replace(model=DEFAULT_MODEL)
    column, columns = args.column, args.columns
    if columns is not None:
        if column is not None:
            raise ValueError('give --column or --columns, not both')
        items = channel_list('--columns', columns)
        if len(items) == 1 and items[0] != 'all':
            column, columns = items[0], None  # one column: exactly --column
        else:
            need_joint(f'--columns {columns}', config)
    covariates, _ = health.check_arguments(args)
    components, joint = tuple(args.component), ()
    if args.components is not None:
        if components:
            raise ValueError('give --component or --components, not both')
        joint = channel_list('--components', args.components)
        if len(joint) == 1:
            components, joint = joint, ()  # one component: exactly --component
        else:
            need_joint(f'{len(joint)} components', config)
    return Options(
        config,
        tuple(args.topic),
        components,
        column,
        args.strict,
        args.summary,
        columns,
        joint,
        decides(args),
        window_given(args),
        damping_given(args),
        covariates,
        rescues(args),
    )


def run(args: argparse.Namespace) -> int:
    try:
        options = _options(args)
        learned = health.check_arguments(args)[1]
        base = baseline_rows(args.baseline, options) if args.baseline and not learned else None
    except (ValueError, VibEstimatorError) as err:
        return report(err, 'vib-estimator survey')
    ignored: List[Path] = []
    recordings = find_recordings(args.inputs, ignored)
    found = sum(map(is_recording, recordings))
    if not found:
        where = ', '.join(args.inputs)
        return report(
            ValueError(
                f'no recording found in {where} (rosbag2 bag folders, '
                f'{", ".join(_RECORDING_SUFFIXES)} files, searched recursively, links followed)'
            ),
            'vib-estimator survey',
        )
    if any(glob.has_magic(name) or Path(name).is_dir() for name in args.inputs):  # searched
        print(
            f'vib-estimator survey: {found} recording(s) found in {", ".join(args.inputs)}',
            file=sys.stderr,
        )
    rows = survey(recordings, options, args.jobs, args.scheduler)
    report_entries(rows, ignored, sys.stderr)
    if base is not None:
        flag(rows, base, args.alarm_rel)
    try:
        learned = health.judge(rows, args, options.covariates, learned, row_shape)
    except ValueError as err:
        return report(err, 'vib-estimator survey')
    write_rows(rows, args.format, sys.stdout)
    if args.out:
        write_file(rows, Path(args.out))
    if args.plot and learned is not None:
        health.plot_health(rows, Path(args.plot), learned)
    elif args.plot:
        plot_trend(rows, Path(args.plot), base, args.alarm_rel)
    if getattr(args, 'report', None):
        write_survey_page(args, rows, base)
    if args.fail_on_alarm and any(r['alarm'] for r in rows):
        return 3
    return 1 if args.strict and any(r['error'] for r in rows) else 0
