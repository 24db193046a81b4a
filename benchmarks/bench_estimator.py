# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""Speed of the estimator core: batch throughput and streaming cost, against baselines in the same
run.

Prints (one run, same machine, same signal: 2 M samples of a noisy 1.33 Hz sine at 500 Hz):
- batch: ``FrequencyEstimator.process`` in M samples/s (goal >= 10, issue 24), next to a bare
  ``numpy.cumsum`` over the same array (the cheapest whole-array pass numpy can make)
  and the ratio;
- streaming: ``FrequencyEstimator.update`` in us per sample (goal <= 0.5), next to an empty Python
  function call with the same arguments (the floor of any per-sample Python API) and the ratio;
- batch cost of other configurations against the default: the paper's estimator (``refine`` = 0)
  long windows (``min_periods`` = 5, 20; ``target_std_rel`` = 1e-4) and the band prefilter
  (``band_hz`` = [f/2, 2f]: its std is a sandwich over the prefilter's noise covariance) and the
  mode tracker (``modes`` = 3, over a quarter of the samples; goal >= 2 M samples/s);
- streaming through the compiled entry (``core.jit.entry`` of ``core.kernel.feed``: two arrays
  to unbox, today's ``update``) beside the same kernel called through numba's dispatcher with
  seven array arguments (``update`` before issue 24), alternately;
- the previous kernel (``PREVIOUS``, before the split into per-equation functions and before
  refinement; loaded at run time with ``git show`` into a temporary package, "skipped" without git)
  on the same signal, ``EstimatorConfig.paper(refine=0)`` (it also computes each estimate's std)
  and ``EstimatorConfig.paper()`` against it (the paper's configuration: the previous kernel's
  defaults), timed alternately (the ratios hold when the machine is loaded; the rates do not;
  goal for ``refine`` = 0: today/previous >= 1.0).
- the kernel of ``SPLIT`` (before issues 19 and 24: the compile-time and speed restructuring),
  loaded the same way, beside this one for each configuration, ``modes`` = 3 and streaming,
  timed alternately: rates and this/then ratios (the outputs are bit-identical,
  test/core/test_kernel_reference.py).
- the default's cost (issue 37, item 7: :func:`default_cost`), beside ``free`` (and ``ambient``
  on the driven record) in the same run: batch through ``analyze``'s own path (the decision,
  ``analysis.choosing.prepare``, then ``analysis.analyze.estimate_signal``; the CSV parsing
  excluded), streaming through the node's (``EstimatorStream.feed``, with the status and the
  decision it asks each second), and cold compile (``vib-estimator analyze`` in a fresh process
  with an empty ``NUMBA_CACHE_DIR``: ``bench_startup.analyze_seconds``), each beside its goal.
Numba compiles once before timing; each figure is the best of 3 repeats.

    python benchmarks/bench_estimator.py                  # everything (a few minutes)
    python benchmarks/bench_estimator.py --default-only   # the default's cost alone
"""

import argparse
import atexit
import importlib
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from vib_estimator.core import EstimatorConfig, FrequencyEstimator, create_estimator

VARIANTS = {
    'refine=0 (paper)': dict(refine=0),
    'min_periods=5': dict(min_periods=5.0),
    'min_periods=20': dict(min_periods=20.0),
    'target_std_rel=1e-4': dict(target_std_rel=1e-4, min_periods=0.0),
    'band_hz=[f/2, 2f]': dict(band_hz=(0.665, 2.66)),
    'modes=3': dict(modes=3),
}


#: the commit whose kernel (one 169-line step, no refinement) is the speed baseline of issue 14
PREVIOUS = '627a108'
#: the kernel before the compile-time and speed work of issues 19 and 24
#: (the bit-identity reference)
SPLIT = '7374e6d'


def load_core(commit, package, names=None):
    """vib_estimator/core of ``commit`` as the package ``package`` (a temporary copy), or None
    without git; ``names``: only these modules (default: all of them)."""
    root = Path(__file__).resolve().parents[1]
    folder = Path(tempfile.mkdtemp(prefix=f'{package}_')) / package
    atexit.register(shutil.rmtree, folder.parent, True)
    folder.mkdir()
    (folder / '__init__.py').write_text('')
    try:
        if names is None:
            names = [
                Path(f).stem
                for f in subprocess.run(
                    ['git', 'ls-tree', '--name-only', f'{commit}:vib_estimator/core'],
                    cwd=root,
                    capture_output=True,
                    text=True,
                    check=True,
                ).stdout.split()
                if f.endswith('.py') and f != '__init__.py'
            ]
        for name in names:
            text = subprocess.run(
                ['git', 'show', f'{commit}:vib_estimator/core/{name}.py'],
                cwd=root,
                capture_output=True,
                text=True,
                check=True,
            ).stdout
            (folder / f'{name}.py').write_text(text)
    except (OSError, subprocess.CalledProcessError):
        return None
    sys.path.insert(0, str(folder.parent))
    return package


def load_previous():
    """The previous kernel's FrequencyEstimator and EstimatorConfig, or None without git."""
    if load_core(PREVIOUS, 'vib_previous', ('kernel', 'estimator', 'config')) is None:
        return None
    return (
        importlib.import_module('vib_previous.estimator').FrequencyEstimator,
        importlib.import_module('vib_previous.config').EstimatorConfig,
    )


def compare_split(t, y):
    """This kernel beside SPLIT's, per configuration (batch), ``modes`` = 3 and streaming,
    alternating, best of 3."""
    if load_core(SPLIT, 'vib_split') is None:
        print(f'kernel of {SPLIT}   skipped (git or the commit is not available)')
        return
    then_config = importlib.import_module('vib_split.config').EstimatorConfig
    then_create = importlib.import_module('vib_split.modes').create_estimator
    n = len(t)
    print(
        f"\nthis kernel beside {SPLIT}'s (batch M samples/s; streaming us/sample; each row's"
        f" configuration applied to EstimatorConfig.paper(), {SPLIT}'s defaults)"
    )
    rows = [('default', {}), *VARIANTS.items()]
    for name, changes in rows:
        name = 'paper()' if name == 'default' else name
        m = n // 4 if 'modes' in changes else n
        now_cfg, then_cfg = EstimatorConfig.paper(**changes), then_config(**changes)
        create_estimator(now_cfg).process(t[:5000], y[:5000])
        then_create(then_cfg).process(t[:5000], y[:5000])
        now, then = [], []
        for _ in range(3):
            now.append(best(lambda c=now_cfg, k=m: create_estimator(c).process(t[:k], y[:k]), 1))
            then.append(best(lambda c=then_cfg, k=m: then_create(c).process(t[:k], y[:k]), 1))
        print(
            f'batch {name:>20} {m / min(now) / 1e6:8.2f} this {m / min(then) / 1e6:8.2f} '
            f'{SPLIT}   this/then {min(then) / min(now):5.2f}'
        )
    m = STREAMED
    stream = streamer(t, y)

    now, then = [], []
    for _ in range(3):
        now.append(best(lambda: stream(create_estimator(EstimatorConfig.paper()).update), 1))
        then.append(best(lambda: stream(then_create(then_config()).update), 1))
    print(
        f'streaming {"paper()":>16} {min(now) / m * 1e6:8.3f} this {min(then) / m * 1e6:8.3f} '
        f'{SPLIT}   this/then {min(then) / min(now):5.2f}'
    )


#: samples of the streaming comparisons
STREAMED = 200_000


def streamer(t, y):
    """A function feeding the first STREAMED samples, as Python floats, to an ``update``."""
    tl, yl = t[:STREAMED].tolist(), y[:STREAMED].tolist()

    def stream(update):
        for a, b in zip(tl, yl):
            update(a, b)

    return stream


def compare_dispatch(t, y):
    """Streaming through the compiled entry (``update`` today) beside the same kernel called
    through numba's dispatcher with numpy item assignment (``update`` before), alternating, best
    of 5."""
    from vib_estimator.core import kernel as K

    def dispatched(e):
        t1, y1 = np.zeros(1), np.zeros(1)

        def update(a, b):
            t1[0] = a
            y1[0] = b
            return K.run(e._p, e._s, e._c, e._seg, t1, y1, e._row, 0, e._optional)[0]

        return update

    m = STREAMED
    stream = streamer(t, y)

    now, then = [], []
    for _ in range(5):
        now.append(best(lambda: stream(FrequencyEstimator().update), 1))
        then.append(best(lambda: stream(dispatched(FrequencyEstimator())), 1))
    print(
        f'streaming {min(now) / m * 1e6:8.3f} us/sample (compiled entry)   through the dispatcher '
        f'{min(then) / m * 1e6:8.3f} us/sample   dispatcher/entry {min(then) / min(now):5.2f}'
    )


def compare_previous(t, y):
    """Batch rate of the previous kernel beside today's refine = 0 and default, alternating, best
    of 3 (the ratios hold on a loaded machine, where the absolute rates do not)."""
    previous = load_previous()
    if previous is None:
        print(f'previous kernel ({PREVIOUS})   skipped (git or the commit is not available)')
        return
    old_estimator, old_config = previous
    paper = EstimatorConfig.paper(refine=0)  # the previous kernel's defaults, no refinement
    old_estimator(old_config()).process(t[:5000], y[:5000])
    now, default, old = [], [], []
    for _ in range(3):
        now.append(best(lambda: FrequencyEstimator(paper).process(t, y), 1))
        default.append(best(lambda: FrequencyEstimator(EstimatorConfig.paper()).process(t, y), 1))
        old.append(best(lambda: old_estimator(old_config()).process(t, y), 1))
    n = len(t)
    print(
        f'previous kernel ({PREVIOUS}) {n / min(old) / 1e6:8.2f} M samples/s   refine=0 today '
        f'{n / min(now) / 1e6:8.2f} M samples/s   today/previous {min(old) / min(now):5.2f}'
    )
    print(
        f'{"":27}{"":22}   paper() today  {n / min(default) / 1e6:8.2f} M samples/s   '
        f'today/previous {min(old) / min(default):5.2f}'
    )


def best(fn, repeats=3):
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        fn()
        times.append(time.perf_counter() - start)
    return min(times)


#: issue 37's goals for the default (item 7)
GOAL_FREE_MSPS = 2.0  # batch, a one-channel free decay, M samples/s
GOAL_DRIVEN_X = 1000.0  # batch, a 500 Hz driven channel, x real time
GOAL_STREAM_US = 2.0  # streaming, mean us per sample
GOAL_COLD_S = 5.0  # cold compile: at most this many CPU s over ``free``'s


def plucked(n: int, fs: float = 500.0, seed: int = 1):
    """``n`` samples at ``fs`` of a 1.33 Hz mode at zeta 1 % plucked every 30 s (a free decay
    throughout, as the shared arm's), noise 1 % of the pluck."""
    t = np.arange(n) / fs
    tau = np.mod(t, 30.0)
    y = np.exp(-0.01 * 2 * np.pi * 1.33 * tau) * np.sin(2 * np.pi * 1.33 * tau)
    return t, y + 0.01 * np.random.default_rng(seed).standard_normal(n)


def driven_record():
    """bench_defaults.cost's driven record: 600 s at 500 Hz of a 5 and a 17 Hz mode driven by
    white noise, 20 dB."""
    from vib_estimator.sim.ambient import ambient_record

    t, y, _ = ambient_record(600, 500, [(5.0, 0.01, 1.0), (17.0, 0.005, 0.3)], 20, 1)
    return t, y


def analyzed(t, y, excitation=None) -> float:
    """CPU s of ``analyze``'s path on ``(t, y)`` with ``--excitation excitation`` (None: the
    default, decided from the record), the CSV parsing excluded: the decision
    (``choosing.prepare``, which ``analyze`` runs whatever the options: a forced excitation is
    checked against the record) and ``estimate_signal`` over the record as one block."""
    from types import SimpleNamespace

    from vib_estimator.analysis.analyze import estimate_signal
    from vib_estimator.analysis.choosing import prepare

    args = SimpleNamespace(excitation=excitation, paper=False)
    config = EstimatorConfig() if excitation is None else EstimatorConfig(excitation=excitation)
    start = time.process_time()
    config, _, _ = prepare(args, config, t, y, 1, 'analyze')
    estimate_signal(SimpleNamespace(path='record', topic=''), config, False, [(t, y)])
    return time.process_time() - start


def streamed_cost(t, y, deciding=None, config=None) -> float:
    """Mean CPU us per sample of ``EstimatorStream(EstimatorConfig(), deciding=...).feed`` over
    ``(t, y)`` as the node feeds it (integer ns stamps, Python floats), with the ``status`` it
    asks each second of the record and (``deciding``) the ``decision``, applied as the node
    applies it; ``deciding`` None: the bare estimator's ``update`` (no stream) of ``config``
    (default: ``EstimatorConfig()``)."""
    from vib_estimator.nodes.stream import EstimatorStream

    stamps = (np.round(t * 1e9).astype(np.int64) + 10**18).tolist()
    values, seconds = y.tolist(), t.tolist()
    if deciding is None:
        update = create_estimator(config or EstimatorConfig()).update
        start = time.process_time()
        for a, b in zip(seconds, values):
            update(a, b)
        return (time.process_time() - start) / len(t) * 1e6
    stream = EstimatorStream(EstimatorConfig(), now=0.0, deciding=deciding)
    feed, due = stream.feed, 1.0
    start = time.process_time()
    for stamp, value, now in zip(stamps, values, seconds):
        feed(stamp, value)
        if now >= due:  # the node's 1-s timer
            due += 1.0
            stream.status(now)
            decision = stream.decision() if deciding else None
            if decision is not None:
                stream.configure(stream.config.replace(**decision.changes()), prime=True)
                stream.decided = True
    return (time.process_time() - start) / len(t) * 1e6


def verdict(met: bool) -> str:
    return 'met' if met else '**not met**'


def default_cost(cold: bool = True) -> None:
    """The default's cost beside ``free`` (and ``ambient``), in the same run, alternating
    (module doc; issue 37, item 7)."""
    n = 2_000_000
    tf, yf = plucked(n)
    td, yd = driven_record()
    print(
        '\nthe default (no option) beside the forced excitation, same run; CPU s, best of 3, '
        'alternating'
    )
    analyzed(tf[:20000], yf[:20000])  # compile
    analyzed(td[:30000], yd[:30000])
    for name, (t, y), forced in (
        ('free decay (1.33 Hz plucked every 30 s), 2 M samples', (tf, yf), ('free',)),
        ('5 + 17 Hz driven, 600 s at 500 Hz', (td, yd), ('free', 'ambient')),
    ):
        times = {e: [] for e in (None, *forced)}
        for _ in range(3):
            for e in times:
                times[e].append(analyzed(t, y, e))
        span = float(t[-1] - t[0])
        for e, cpu in times.items():
            best_s = min(cpu)
            label = 'default' if e is None else f'--excitation {e}'
            line = (
                f'batch {name:52s} {label:22s} {best_s:6.2f} s {len(t) / best_s / 1e6:6.2f} M '
                f'samples/s {span / best_s:7.0f}x real time'
            )
            if e is None and 'driven' in name:
                met = span / best_s >= GOAL_DRIVEN_X
                line += f'   goal >= {GOAL_DRIVEN_X:.0f}x: {verdict(met)}'
            elif e is None:
                met = len(t) / best_s / 1e6 >= GOAL_FREE_MSPS
                line += f'   goal >= {GOAL_FREE_MSPS:g} M samples/s: {verdict(met)}'
            print(line, flush=True)
    m = 200_000  # 400 s of the free decay; the driven record's 600 s
    streamed_cost(tf[:5000], yf[:5000], True)  # compile
    for name, (t, y) in (
        ('free decay, 400 s at 500 Hz', (tf[:m], yf[:m])),
        ('5 + 17 Hz driven, 600 s at 500 Hz', (td, yd)),
    ):
        ambient = EstimatorConfig(excitation='ambient')
        cost = {k: [] for k in ('deciding', 'not deciding', 'bare update', 'ambient update')}
        for _ in range(3):
            for k, deciding in zip(cost, (True, False, None, None)):
                config = ambient if k == 'ambient update' else None
                cost[k].append(streamed_cost(t, y, deciding, config))
        us = {k: min(v) for k, v in cost.items()}
        print(
            f'streaming {name:34s} default (deciding) {us["deciding"]:6.2f} us/sample   '
            f'deciding=False {us["not deciding"]:6.2f}   bare update: free '
            f'{us["bare update"]:5.2f}, ambient {us["ambient update"]:5.2f}   '
            f'goal <= {GOAL_STREAM_US:g}: {verdict(us["deciding"] <= GOAL_STREAM_US)}',
            flush=True,
        )
    if cold:
        cold_compile(tf, yf, td, yd)


def cold_compile(tf, yf, td, yd) -> None:
    """``vib-estimator analyze`` of a 120 s free decay and a 120 s driven record (60000 samples:
    beyond ``core.estimator.UNCOMPILED_SAMPLES``, where ``analyze`` compiles the algebraic
    estimator's kernels), each in a fresh process with an empty ``NUMBA_CACHE_DIR``
    (``bench_startup.analyze_seconds``), the default beside ``--excitation free`` (the default
    until 4 Dec 2026) and, driven, ``ambient``."""
    from bench_startup import analyze_seconds, environment, write_csv  # benchmarks/

    root = Path(__file__).resolve().parents[1]
    print('\ncold analyze (empty NUMBA_CACHE_DIR, one process each): CPU s / wall s')
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        free = write_csv(tmp / 'free.csv', tf[:60000], yf[:60000])
        driven = write_csv(tmp / 'driven.csv', td[:60000], yd[:60000])
        got = {}
        for name, csv, forced in (
            ('free decay, 120 s', free, ('free',)),
            ('driven, 120 s', driven, ('free', 'ambient')),
        ):
            for e in (None, *forced):
                with tempfile.TemporaryDirectory(dir=tmp) as cache:
                    extra = () if e is None else ('--excitation', e)
                    wall, cpu = analyze_seconds(root, environment(root, cache), csv, extra)
                got[name, e] = cpu
                label = 'default' if e is None else f'--excitation {e}'
                line = f'cold {name:18s} {label:22s} {cpu:6.1f} / {wall:6.1f} s'
                if e is None:
                    print(line, flush=True)
                    continue
                over = got[name, None] - cpu
                line += f'   default - this {over:+5.1f} CPU s'
                if e == 'free':
                    line += f' (goal <= +{GOAL_COLD_S:g}: {verdict(over <= GOAL_COLD_S)})'
                print(line, flush=True)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--default-only', action='store_true', help="only the default's cost")
    parser.add_argument('--no-cold', action='store_true', help='without the cold compiles')
    args = parser.parse_args()
    if args.default_only:
        default_cost(not args.no_cold)
        return
    rng = np.random.default_rng(0)
    n = 2_000_000
    t = np.arange(n) * 0.002
    y = np.sin(2 * np.pi * 1.33 * t) + 0.01 * rng.standard_normal(n)
    FrequencyEstimator().process(t[:5000], y[:5000])  # compile

    batch = best(lambda: FrequencyEstimator().process(t, y))
    base = best(lambda: np.cumsum(y))
    print(
        f'batch     {n / batch / 1e6:8.2f} M samples/s   numpy.cumsum {n / base / 1e6:8.1f} '
        f'M samples/s   ratio {base / batch:6.3f}   (goal >= 10 M samples/s)'
    )

    m = 200_000
    tl, yl = t[:m].tolist(), y[:m].tolist()

    def stream():
        update = FrequencyEstimator().update
        for a, b in zip(tl, yl):
            update(a, b)

    def empty(a, b):
        return None

    def floor():
        for a, b in zip(tl, yl):
            empty(a, b)

    s = best(stream) / m * 1e6
    f = best(floor) / m * 1e6
    print(
        f'streaming {s:8.3f} us/sample        empty Python call {f:8.3f} us/sample   '
        f'ratio {s / f:6.1f}   (goal <= 0.5 us/sample)'
    )
    for name, changes in VARIANTS.items():
        cfg = EstimatorConfig(**changes)
        k = n // 4 if 'modes' in changes else n
        create_estimator(cfg).process(t[:5000], y[:5000])
        v = best(lambda: create_estimator(cfg).process(t[:k], y[:k])) * n / k
        print(
            f'batch {name:>20} {n / v / 1e6:8.2f} M samples/s   ratio to default {batch / v:6.2f}'
        )
    compare_dispatch(t, y)
    compare_previous(t, y)
    compare_split(t, y)
    default_cost(not args.no_cold)


if __name__ == '__main__':
    main()
