# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""The same seeded cases on two library sets (issue 39, item 4): how far apart are the floats?

    .venv/bin/python benchmarks/bench_sets.py --other .venv-jazzy/bin/python

Prints, for each case, the estimates' count on each set, whether their stamps, sample counts and
modes are identical, and the largest relative difference of each float column (per value, and
relative to the column's largest value for values near 0 such as a damping ratio), then the
worst of all. Asserts nothing (a minute or two; each set compiles its kernels once, into its own
``NUMBA_CACHE_DIR`` as ``make test-jazzy`` does, unless one is set).

The inputs are made once, by this process (``vib_estimator.sim`` and numpy's seeded generator),
and the same arrays are fed to both sets: a difference is the estimator's, not the simulator's.
Each set runs in a child process (``--dump``: the cases' outputs into an ``.npz``).

Cases: the free-decay default, the paper's configuration, the damped model, ``band_hz``, the mode
tracker (``modes: 3``) on a two-mode decay, the ambient estimator on one channel and the joint
ambient estimator on a five-storey frame's five channels.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
FS = 500.0

#: (name, input, configuration changes) - the inputs are made by :func:`inputs`
CASES = [
    ('free decay, default', 'decay', {}),
    ('free decay, paper', 'decay', 'paper'),
    ('free decay, damped model', 'decay', {'model': 'damped-sinusoid'}),
    ('free decay, band_hz', 'decay', {'band_hz': (1.0, 10.0)}),
    ('modes: 3', 'two-modes', {'modes': 3}),
    ('ambient, one channel', 'ambient', {'excitation': 'ambient', 'ambient_window_s': 20.0}),
    ('ambient, joint (5 channels)', 'frame', {'excitation': 'ambient', 'ambient_window_s': 60.0}),
]


def inputs() -> dict:
    """The seeded inputs, as arrays: (t, y) of each kind."""
    from vib_estimator.sim.ambient import ambient_record
    from vib_estimator.sim.frame import frame_record

    rng = np.random.default_rng(39)
    n = 15000
    t = np.arange(n) / FS
    tr = t % 6.0  # a lightly damped 3.1 Hz mode plucked every 6 s
    decay = np.exp(-2 * np.pi * 3.1 * 0.01 * tr) * np.sin(2 * np.pi * 3.1 * tr + 0.4)
    two = np.exp(-0.05 * t) * np.sin(2 * np.pi * 2.3 * t + 0.3) + 0.6 * np.exp(-0.1 * t) * np.sin(
        2 * np.pi * 7.9 * t + 1.1
    )
    ta, ya, _ = ambient_record(60.0, FS, [(5.0, 0.01, 1.0), (8.0, 0.02, 0.5)], 26.0, 39)
    tf, yf, _, _ = frame_record(300.0, 20.0, zeta=0.02, snr_db=20.0, seed=39)
    return {
        'decay/t': t,
        'decay/y': decay + 0.02 * rng.standard_normal(n),
        'two-modes/t': t,
        'two-modes/y': two + 0.02 * rng.standard_normal(n),
        'ambient/t': ta,
        'ambient/y': ya,
        'frame/t': tf,
        'frame/y': yf,
    }


def nudged(data: dict) -> dict:
    """The inputs with every sample of y moved by one ulp, up or down (seeded): how far the
    outputs move for a change of the input at the last bit, the floor of any comparison."""
    rng = np.random.default_rng(1)
    out = dict(data)
    for key, y in data.items():
        if key.endswith('/y'):
            out[key] = np.nextafter(y, np.where(rng.random(y.shape) < 0.5, -np.inf, np.inf))
    return out


def _columns(result) -> dict:
    """The float and integer arrays of a batch result (joint: the shapes too)."""
    from vib_estimator.core.estimator import EstimateArrays

    est = result if isinstance(result, EstimateArrays) else result.estimates
    out = {k: np.asarray(getattr(est, k)) for k in EstimateArrays.__dataclass_fields__}
    if est is not result:
        shapes = np.asarray(result.shapes)
        out['shape (abs)'] = np.abs(shapes)
        out['shape_std'] = np.asarray(result.shape_std, dtype=float)
        out['mac'] = np.asarray(result.mac, dtype=float)
    return out


def dump(data: Path, out: Path) -> None:
    """Run every case on this process's libraries and save the outputs into ``out``."""
    import numba
    import scipy

    from vib_estimator.core import EstimatorConfig, create_estimator

    with np.load(data) as d:
        arrays = {k: d[k] for k in d.files}
    store = {
        'versions': np.array(
            f'numpy {np.__version__}, scipy {scipy.__version__}, numba {numba.__version__}'
        )
    }
    for name, kind, changes in CASES:
        config = EstimatorConfig.paper() if changes == 'paper' else EstimatorConfig(**changes)
        t, y = arrays[f'{kind}/t'], arrays[f'{kind}/y']
        channels = [f'storey{i}' for i in range(1, y.shape[1] + 1)] if y.ndim == 2 else ()
        start = time.monotonic()
        result = create_estimator(config, channels).process(t, y)
        for col, v in _columns(result).items():
            store[f'{name}/{col}'] = v
        print(
            f'  {name:30s} {len(result):5d} estimates, {time.monotonic() - start:5.1f} s',
            file=sys.stderr,
            flush=True,
        )
    np.savez(out, **store)


EXACT = ('t', 'samples', 'mode')


FLOATS = (
    'frequency_hz',
    'damping',
    'amplitude',
    'fit',
    'convergence_time',
    'frequency_std_hz',
    'damping_std',
    'shape (abs)',
    'shape_std',
    'mac',
)


def differences(x: np.ndarray, y: np.ndarray) -> tuple:
    """(largest |x - y| / |y|, largest |x - y| / max |y|) of two float columns (inf when their
    NaNs differ)."""
    x, y = x.astype(float), y.astype(float)
    if x.shape != y.shape or not np.array_equal(np.isnan(x), np.isnan(y)):
        return np.inf, np.inf
    ok = ~np.isnan(y)
    x, y = x[ok], y[ok]
    if not len(y):
        return 0.0, 0.0
    d = np.abs(x - y)
    scale = float(np.max(np.abs(y)))
    return float(np.max(d / np.maximum(np.abs(y), 1e-300))), (
        float(d.max()) / scale if scale else 0.0
    )


def compare(a: dict, b: dict) -> dict:
    """Print the per-case table; return {case: {column: (per value, per column scale)}}."""
    print(f'a: {a["versions"]}\nb: {b["versions"]}\n')
    head = [c for c in FLOATS]
    print(
        'largest relative difference per column: |a - b| / |b| per value; |a - b| / max |b| '
        "(the column's scale) in brackets\n"
    )
    print('| case | estimates a / b | stamps, samples, modes | ' + ' | '.join(head) + ' |')
    print('|---|---|---|' + '---|' * len(head))
    table = {}
    for name, _, _ in CASES:
        na, nb = len(a[f'{name}/t']), len(b[f'{name}/t'])
        same = na == nb and all(np.array_equal(a[f'{name}/{c}'], b[f'{name}/{c}']) for c in EXACT)
        row = {}
        for c in head:
            if f'{name}/{c}' in a:
                row[c] = differences(a[f'{name}/{c}'], b[f'{name}/{c}']) if same else (np.inf,) * 2
        table[name] = row
        cells = [f'{row[c][0]:.0e} ({row[c][1]:.0e})' if c in row else '' for c in head]
        print(
            f'| {name} | {na} / {nb} | {"identical" if same else "DIFFERENT"} | '
            + ' | '.join(cells)
            + ' |'
        )
    return table


def run_set(python: str, data: Path, out: Path, cache: str | None) -> None:
    env = dict(os.environ)
    env['PYTHONPATH'] = os.pathsep.join([str(ROOT)] + [p for p in [env.get('PYTHONPATH')] if p])
    if cache:
        env['NUMBA_CACHE_DIR'] = cache
    cmd = [python, '-P', str(Path(__file__).resolve()), '--dump', str(data), str(out)]
    print(f'{python}:', file=sys.stderr, flush=True)
    subprocess.run(cmd, env=env, check=True)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--other', help="the other set's Python (default .venv-jazzy/bin/python)")
    parser.add_argument(
        '--no-nudge', action='store_true', help='leave out the run on inputs 1 ulp off'
    )
    parser.add_argument('--dump', nargs=2, metavar=('INPUTS', 'OUT'), help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.dump:
        dump(Path(args.dump[0]), Path(args.dump[1]))
        return 0
    other = args.other or str(ROOT / '.venv-jazzy' / 'bin' / 'python')
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        data = inputs()
        np.savez(tmp / 'inputs.npz', **data)
        np.savez(tmp / 'nudged.npz', **nudged(data))
        results = {}
        runs = (('a', sys.executable, 'inputs'), ('b', other, 'inputs'))
        runs += () if args.no_nudge else (('a nudged', sys.executable, 'nudged'),)
        for label, python, kind in runs:
            out = tmp / f'{label}.npz'
            # each numba its own cache (two versions on one folder recompile each other's)
            cache = os.environ.get('NUMBA_CACHE_DIR')
            if cache is None and python == other and other != sys.executable:
                cache = str(Path(other).absolute().parents[1] / 'numba-cache')
            run_set(python, tmp / f'{kind}.npz', out, cache)
            with np.load(out) as d:
                results[label] = {k: d[k] for k in d.files}
    print('## The two sets, the same inputs\n')
    table = compare(results['a'], results['b'])
    worst = max(v[1] for row in table.values() for v in row.values())
    print(f"\nworst relative difference (to the column's largest value): {worst:.1e}")
    if not args.no_nudge:
        print("\n## One set, each input sample 1 ulp off (the outputs' own sensitivity)\n")
        compare(results['a nudged'], results['a'])
    return 0


if __name__ == '__main__':
    sys.exit(main())
