# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""Streaming readers and ``vib-estimator survey``: speed and memory, each beside a baseline run
here.

    python benchmarks/bench_survey.py [--rows 5000000] [--messages 5000000] [--work DIR]

Prints:
- CSV: the streaming reader (pyarrow blocks) in M rows/s on a ``--rows`` numeric CSV (goal >= 5),
  beside ``numpy.loadtxt`` and the exact row-by-row reader (today's rules) on a tenth of it;
- MCAP: the streaming reader in M messages/s on a ``--messages`` WrenchStamped bag (goal >= 1 per
  core), beside rosbags' generic ``deserialize_cdr``, the reference ``read_wrench_series`` and the
  streaming reader decoding chunk by chunk (``MCAP_BATCH_MESSAGES`` 1, as before the batches) on
  a tenth of it;
- peak RSS of a fresh process that streams the whole CSV / bag through the estimator (goal
  <= 300 MB), beside the RSS of the same process that only imports the package (the floor);
- survey of 8 recordings (CSV, 1 M rows each): ``--jobs 2`` against ``--jobs 1`` (goal >= 1.7x;
  wall-clock, with the CPU seconds used, so that a machine busy with other work shows as wall time
  well above CPU time), and a Dask
  ``LocalCluster`` of 2 worker processes against ``--jobs 2`` (goal within 15 %; the cluster is
  started and warmed up before timing, as a long-lived cluster is). ``--jobs 1``, ``--jobs 2``
  and Dask run alternately, three rounds, so that all see the same load; ``--jobs 2`` uses the pool
  kept from the survey before (``survey.local_pool``), beside it (a fourth alternated run) a pool
  started inside the timed survey, as a one-off ``vib-estimator survey`` does;
- survey of 8 MCAP bags x 250 000 ``WrenchStamped`` messages (issue 24's fleet): M messages/s with
  ``--jobs 1`` and ``--jobs 2`` (goal >= 3 M msgs/s), and the speed-up (goal >= 1.7x).
Reader throughputs are per CPU second of the process (``time.process_time``, all threads); the
survey times are wall-clock. Each time is the best of 2 runs (the surveys: of the 3 rounds). The
generated files go to ``--work`` (default a temporary folder).
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from vib_estimator.analysis import survey as S
from vib_estimator.core import EstimatorConfig
from vib_estimator.io import streaming
from vib_estimator.io.bags import (
    TYPESTORE,
    WRENCH_STAMPED,
    BagWriter,
    read_wrench_series,
    wrench_message,
)
from vib_estimator.io.csv_reader import csv_layout, iter_csv_rows

EPOCH = 1_700_000_000 * 10**9


def best(fn, repeats=2, clock=time.perf_counter):
    times = []
    for _ in range(repeats):
        start = clock()
        fn()
        times.append(clock() - start)
    return min(times)


def cpu(fn, repeats=2):
    """Best CPU time of this process (all its threads): a per-core figure that a loaded machine
    distorts far less than the wall clock."""
    return best(fn, repeats, time.process_time)


def signal(n, f=1.33, seed=0):
    t = np.arange(n) * 0.002
    return t, np.sin(2 * np.pi * f * t) + 0.01 * np.random.default_rng(seed).standard_normal(n)


def write_csv(path: Path, n: int, seed=0) -> None:
    import pyarrow as pa
    import pyarrow.csv as pacsv

    t, y = signal(n, seed=seed)
    pacsv.write_csv(pa.table({'t': t, 'y': y}), path)


def write_bag(path: Path, n: int) -> None:
    """A WrenchStamped bag: one message serialised by rosbags, the stamps patched in its bytes."""
    t, y = signal(n)
    stamps = EPOCH + np.round(t * 1e9).astype(np.int64)
    template = bytearray(
        TYPESTORE.serialize_cdr(wrench_message(0, 'arm_base', 'torque.z', 0.0), WRENCH_STAMPED)
    )
    offset = len(template) - 8  # torque.z is the last double
    with BagWriter(path) as bag:
        conn = bag.add_topic('/coupling_torque', WRENCH_STAMPED)
        for stamp, value in zip(stamps.tolist(), y.tolist()):
            template[4:8] = (stamp // 10**9).to_bytes(4, 'little')
            template[8:12] = (stamp % 10**9).to_bytes(4, 'little')
            template[offset:] = np.float64(value).tobytes()
            bag.write(conn, stamp, bytes(template))


def drain(signal_) -> int:
    return sum(len(t) for t, _ in signal_.blocks())


def peak_rss_mb(code: str) -> float:
    """Peak resident memory of a fresh interpreter running ``code``: its ``VmHWM`` (unlike
    ``ru_maxrss``, not inherited from the forking parent)."""
    script = (
        code + '\nfrom pathlib import Path\n'
        'print(next(int(line.split()[1]) for line in Path("/proc/self/status").open() '
        'if line.startswith("VmHWM")) / 1024)'
    )
    out = subprocess.run(
        [sys.executable, '-c', script], check=True, capture_output=True, text=True
    ).stdout
    return float(out.split()[-1])


def streamed(work: Path, suffix: str, n: int, write):
    """A recording of ``n`` samples and one of a tenth of it; the streaming reader's CPU time on
    the first."""
    big, small = work / f'big{suffix}', work / f'small{suffix}'
    write(big, n)
    write(small, n // 10)
    return big, small, cpu(lambda: drain(streaming.open_signal(big)))


def report(label: str, unit: str, count: int, fast: float, refs: dict, goal: str) -> None:
    """One line: the streaming reader's rate over ``count`` items in ``fast`` s beside each
    reference's (timed on a tenth of them), M items/s, and the ratios."""
    n = count // 10
    rates = '   '.join(f'{name} {n / sec / 1e6:6.2f}' for name, sec in refs.items())
    ratios = ' / '.join(f'{sec / n * count / fast:5.1f}x' for sec in refs.values())
    print(
        f'{label:5s} streaming {count / fast / 1e6:6.2f} M {unit}/s   {rates}   ratio {ratios}'
        f'   (goal {goal})'
    )


def bench_csv(work: Path, rows: int) -> Path:
    big, small, fast = streamed(work, '.csv', rows, write_csv)
    loadtxt = cpu(lambda: np.loadtxt(small, delimiter=',', skiprows=1), 1)
    exact = cpu(lambda: sum(1 for _ in iter_csv_rows(csv_layout(small))), 1)
    refs = {'numpy.loadtxt': loadtxt, 'row-by-row reader': exact}
    report('csv', 'rows', rows, fast, refs, '>= 5 M rows/s')
    return big


def bench_bag(work: Path, messages: int) -> Path:
    big, small, fast = streamed(work, '_bag', messages, write_bag)
    from rosbags.rosbag2 import Reader

    def generic():
        with Reader(small) as reader:
            for _, _, data in reader.messages():
                TYPESTORE.deserialize_cdr(data, WRENCH_STAMPED)

    gen = cpu(generic, 1)
    ref = cpu(lambda: read_wrench_series(small), 1)
    batch, streaming.MCAP_BATCH_MESSAGES = streaming.MCAP_BATCH_MESSAGES, 1
    try:  # the streaming reader one chunk at a time (before the batches of chunks)
        one_chunk = cpu(lambda: drain(streaming.open_signal(small)), 1)
    finally:
        streaming.MCAP_BATCH_MESSAGES = batch
    refs = {
        'rosbags deserialize_cdr': gen,
        'read_wrench_series': ref,
        'chunk by chunk': one_chunk,
    }
    report('mcap', 'msg', messages, fast, refs, '>= 1 M msg/s per core')
    return big


def bench_rss(csv_path: Path, bag_path: Path) -> None:
    tiny = csv_path.with_name('tiny.csv')
    tiny.write_text('t,y\n0,1\n0.002,2\n0.004,1\n')
    run = (
        'from vib_estimator.analysis.analyze import estimate_signal\n'
        'from vib_estimator.io.streaming import open_signal\n'
        'from vib_estimator.core import EstimatorConfig\n'
        'estimate_signal(open_signal({!r}), EstimatorConfig())'
    )
    peaks = [peak_rss_mb(run.format(str(path))) for path in (csv_path, bag_path, tiny)]
    print(
        f'rss   streaming through the estimator: the CSV {peaks[0]:5.0f} MB, the bag '
        f'{peaks[1]:5.0f} MB   a 3-row CSV (imports, compiled estimator) {peaks[2]:5.0f} MB   '
        f'(goal <= 300 MB)'
    )


def bench_survey(work: Path) -> None:
    folder = work / 'fleet'
    folder.mkdir(exist_ok=True)
    for i in range(8):
        write_csv(folder / f'rec_{i}.csv', 1_000_000, seed=i)
    recordings = S.find_recordings([str(folder)])
    options = S.Options(EstimatorConfig())
    S.survey(recordings[:1], options)  # compile, warm caches
    from distributed import LocalCluster

    with LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
    ) as cluster:

        def on_dask():
            return S.survey(recordings, options, scheduler=cluster.scheduler_address)

        on_dask()  # warm every worker
        S.survey(recordings[:2], options, jobs=2)  # start the kept pool (S.local_pool)

        def started_in_survey():  # a pool started for this survey, as before the kept pool
            S.local_pool(2, fresh=True)
            return S.survey(recordings, options, jobs=2)

        # the three alternated, so that all see the same machine (other work comes and goes)
        rounds = [
            (
                with_cpu(lambda: S.survey(recordings, options, jobs=1), 1),
                with_cpu(lambda: S.survey(recordings, options, jobs=2), 1),
                best(on_dask, 1),
                best(started_in_survey, 1),
            )
            for _ in range(3)
        ]
    (one, cpu_one), (two, cpu_two) = (min(r[i] for r in rounds) for i in (0, 1))
    dask, started = (min(r[i] for r in rounds) for i in (2, 3))
    print(
        f'survey 8 recordings  --jobs 1 {one:6.2f} s ({cpu_one:5.2f} CPU s)   --jobs 2 '
        f'{two:6.2f} s ({cpu_two:5.2f} CPU s, workers included)   speed-up {one / two:5.2f}x '
        f'(goal >= 1.7)   Dask 2 workers {dask:6.2f} s   vs --jobs 2 {dask / two - 1:+6.1%} '
        f'(goal within 15 %)'
    )
    print(
        f'survey 8 recordings  --jobs 2, pool started in the survey {started:6.2f} s: speed-up '
        f'{one / started:5.2f}x (the kept pool: {two:6.2f} s)'
    )


def bench_survey_bags(work: Path, messages: int = 250_000, bags: int = 8) -> None:
    """Issue 24's fleet: ``bags`` MCAP bags of ``messages`` WrenchStamped each, surveyed with
    ``--jobs 1`` and ``--jobs 2`` (the kept pool) alternately, three rounds, best of each; M
    messages/s of the fleet, wall-clock."""
    folder = work / 'bag_fleet'
    folder.mkdir(exist_ok=True)
    for i in range(bags):
        write_bag(folder / f'bag_{i}', messages)
    recordings = S.find_recordings([str(folder)])
    options = S.Options(EstimatorConfig())
    S.survey(recordings[:1], options)  # compile, warm caches
    S.survey(recordings[:2], options, jobs=2)  # start the kept pool
    rounds = [
        (
            with_cpu(lambda: S.survey(recordings, options, jobs=1), 1),
            with_cpu(lambda: S.survey(recordings, options, jobs=2), 1),
        )
        for _ in range(3)
    ]
    (one, cpu_one), (two, cpu_two) = (min(r[i] for r in rounds) for i in (0, 1))
    total = messages * bags / 1e6
    print(
        f'survey {bags} bags x {messages} msgs  --jobs 1 {one:6.2f} s ({total / one:5.2f} M '
        f'msgs/s, {cpu_one:5.2f} CPU s)   --jobs 2 {two:6.2f} s ({total / two:5.2f} M msgs/s, '
        f'{cpu_two:5.2f} CPU s)   speed-up {one / two:5.2f}x   (goals >= 3 M msgs/s with '
        f'--jobs 2, speed-up >= 1.7)'
    )


def with_cpu(fn, repeats=2):
    """(wall s, CPU s of this process and of its children, finished or running: the kept pool's
    workers) of ``fn``, best of ``repeats``."""
    import resource

    import psutil

    def cpu_now():
        kids = resource.getrusage(resource.RUSAGE_CHILDREN)
        running = 0.0
        for child in psutil.Process().children(recursive=True):
            try:
                used = child.cpu_times()
            except psutil.Error:  # ended meanwhile: counted in RUSAGE_CHILDREN once reaped
                continue
            running += used.user + used.system
        return time.process_time() + kids.ru_utime + kids.ru_stime + running

    runs = []
    for _ in range(repeats):
        wall, used = time.perf_counter(), cpu_now()
        fn()
        runs.append((time.perf_counter() - wall, cpu_now() - used))
    return min(runs)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--rows', type=int, default=5_000_000)
    parser.add_argument('--messages', type=int, default=5_000_000)
    parser.add_argument('--work', type=Path)
    parser.add_argument('--only-bags', action='store_true', help='only the MCAP fleet survey')
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        work = args.work or Path(tmp)
        work.mkdir(parents=True, exist_ok=True)
        if args.only_bags:
            bench_survey_bags(work)
            return
        csv_path = bench_csv(work, args.rows)
        bag_path = bench_bag(work, args.messages)
        bench_rss(csv_path, bag_path)
        bench_survey(work)
        bench_survey_bags(work)


if __name__ == '__main__':
    main()
