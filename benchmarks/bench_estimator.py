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
Numba compiles once before timing; each figure is the best of 3 repeats.
"""

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


def main() -> None:
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


if __name__ == '__main__':
    main()
