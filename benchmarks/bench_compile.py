# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""Cold compile time of the compiled core per configuration, beside a previous commit's, same run.

Each figure is one fresh Python process with an empty ``NUMBA_CACHE_DIR``: ``create_estimator``,
the first ``update`` (the streaming entry point) and the first ``process`` (the batch one) over a
short synthetic signal; CPU seconds beside wall seconds (the machine is shared: CPU time is the
steadier figure). The previous commit's ``vib_estimator`` is extracted with ``git archive`` into a
temporary directory and run the same way. ``--warm`` adds a second run on the filled cache.
``--profile CONFIG`` prints the compile time of each compiled function (numba's event recorder;
self time = inclusive minus the functions compiled inside it, split into front end and LLVM).

    python benchmarks/bench_compile.py                 # against 7374e6d
    python benchmarks/bench_compile.py --ref HEAD~1 --warm
    python benchmarks/bench_compile.py --profile "{'modes': 3}"
"""

from __future__ import annotations

import argparse
import ast
import json
import os
import pathlib
import subprocess
import sys
import tempfile

ROOT = pathlib.Path(__file__).resolve().parents[1]
CONFIGS = {'default': {}, 'modes: 3': {'modes': 3}, 'band_hz': {'band_hz': (1.0, 10.0)}}

PROBE = r"""
import json, sys, time
c0, w0 = time.process_time(), time.perf_counter()
import numpy as np
from vib_estimator.core.config import EstimatorConfig
from vib_estimator.core import create_estimator
est = create_estimator(EstimatorConfig().replace(**json.loads(sys.argv[1])))
t = np.arange(2000) / 500.0
y = np.sin(2 * np.pi * 2.0 * t) + 0.01 * np.cos(2 * np.pi * 37.0 * t)
c1, w1 = time.process_time(), time.perf_counter()
est.update(t[0], y[0])
c2, w2 = time.process_time(), time.perf_counter()
est.process(t[1:], y[1:])
c3, w3 = time.process_time(), time.perf_counter()
print(json.dumps({'import': [c1 - c0, w1 - w0], 'update': [c2 - c1, w2 - w1],
                  'process': [c3 - c2, w3 - w2], 'total': [c3 - c0, w3 - w0]}))
"""


def probe(src: pathlib.Path, config: dict, cache: str) -> dict:
    env = dict(os.environ, NUMBA_CACHE_DIR=cache, PYTHONPATH=str(src))
    out = subprocess.run(
        [sys.executable, '-c', PROBE, json.dumps(config)],
        env=env,
        cwd=src,
        capture_output=True,
        text=True,
        check=True,
    )
    return json.loads(out.stdout.strip().splitlines()[-1])


def extract(ref: str, into: pathlib.Path) -> pathlib.Path:
    archive = subprocess.run(
        ['git', 'archive', ref, 'vib_estimator'], cwd=ROOT, capture_output=True, check=True
    ).stdout
    subprocess.run(['tar', '-x', '-C', str(into)], input=archive, check=True)
    return into


def profile(config: dict) -> None:
    """Compile time per compiled function of one configuration (fresh cache in this process)."""
    import time

    import numpy as np
    from numba.core import event

    from vib_estimator.core import create_estimator
    from vib_estimator.core.config import EstimatorConfig

    marks = []

    class Listener(event.Listener):
        def on_start(self, ev):
            marks.append((time.process_time(), ev))

        def on_end(self, ev):
            marks.append((time.process_time(), ev))

    listener = Listener()
    event.register('numba:compile', listener)
    event.register('numba:llvm_lock', listener)
    est = create_estimator(EstimatorConfig().replace(**config))
    t = np.arange(2000) / 500.0
    est.update(t[0], 0.0)
    est.process(t[1:], np.sin(2 * np.pi * 2.0 * t[1:]))
    stack, front, llvm, count, lock = [], {}, {}, {}, []
    for ts, ev in marks:
        if ev.kind == 'numba:compile':
            fn = ev.data['dispatcher'].py_func
            name = f'{fn.__module__.split(".")[-1]}.{fn.__name__}'
            if ev.is_start:
                stack.append([name, ts, 0.0, 0.0])
                continue
            name, t0, children, in_llvm = stack.pop()
            front[name] = front.get(name, 0.0) + ts - t0 - children - in_llvm
            llvm[name] = llvm.get(name, 0.0) + in_llvm
            count[name] = count.get(name, 0) + 1
            if stack:
                stack[-1][2] += ts - t0
        elif ev.is_start:
            lock.append(ts)
        else:
            t0 = lock.pop()
            if not lock and stack:
                stack[-1][3] += ts - t0
    print(f'{"front end":>9s} {"LLVM":>6s} {"n":>3s}  function (CPU s, self)')
    for name in sorted(front, key=lambda n: -(front[n] + llvm[n])):
        print(f'{front[name]:9.2f} {llvm[name]:6.2f} {count[name]:3d}  {name}')
    print(f'{sum(front.values()):9.2f} {sum(llvm.values()):6.2f}       total')


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument('--ref', default='7374e6d', help='previous commit to compare with')
    ap.add_argument('--warm', action='store_true', help='also a second run on the filled cache')
    every = 'configurations to measure (default: all)'
    ap.add_argument('--config', action='append', choices=sorted(CONFIGS), help=every)
    ap.add_argument(
        '--profile',
        metavar='CONFIG',
        help='per-function compile time of a '
        'configuration given as a Python dict, e.g. "{\'modes\': 3}"',
    )
    args = ap.parse_args()
    if args.profile is not None:
        os.environ.setdefault('NUMBA_CACHE_DIR', tempfile.mkdtemp())
        profile(ast.literal_eval(args.profile))
        return
    with tempfile.TemporaryDirectory() as tmp:
        previous = extract(args.ref, pathlib.Path(tmp))
        print(f'cold start (empty NUMBA_CACHE_DIR), CPU s / wall s; previous = {args.ref}')
        print(
            f'{"configuration":14s} {"kernel":8s} {"update":>13s} {"process":>13s} '
            f'{"total":>13s}' + (f' {"warm total":>13s}' if args.warm else '')
        )
        for label in args.config or CONFIGS:
            for kernel, src in (('previous', previous), ('this', ROOT)):
                with tempfile.TemporaryDirectory() as cache:
                    r = probe(src, CONFIGS[label], cache)
                    warm = probe(src, CONFIGS[label], cache)['total'] if args.warm else None
                cells = [
                    f'{r[k][0]:5.1f} / {r[k][1]:5.1f}' for k in ('update', 'process', 'total')
                ]
                if warm:
                    cells.append(f'{warm[0]:5.2f} / {warm[1]:5.2f}')
                print(
                    f'{label:14s} {kernel:8s} ' + ' '.join(f'{c:>13s}' for c in cells), flush=True
                )


if __name__ == '__main__':
    main()
