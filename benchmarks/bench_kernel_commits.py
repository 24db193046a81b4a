# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""Batch rate of the kernel at several commits on the paper's configuration, alternating, same run.

    python benchmarks/bench_kernel_commits.py 627a108 34f135f 7374e6d HEAD

Each commit's vib_estimator/core is loaded into a temporary package (``bench_estimator.load_core``)
and runs ``refine`` = 0 with the paper's model and window (the fields a commit does not have are
left out) over 400 000 samples of a noisy 1.33 Hz sine at 500 Hz; three alternated rounds, the
best of each; the rate relative to the first commit. For finding where the batch time was lost.
"""

import importlib
import sys

import numpy as np
from bench_estimator import best, load_core

PAPER_REFINE_0 = dict(refine=0, model='sinusoid', min_periods=0.5, consistency=0.0)


def main(commits) -> None:
    n = 400_000
    t = np.arange(n) * 0.002
    y = np.sin(2 * np.pi * 1.33 * t) + 0.01 * np.random.default_rng(0).standard_normal(n)
    kernels = []
    for i, commit in enumerate(commits):
        package = load_core(commit, f'vib_commit_{i}')
        if package is None:
            print(f'{commit}: skipped (git or the commit is not available)')
            continue
        estimator = importlib.import_module(f'{package}.estimator').FrequencyEstimator
        config = importlib.import_module(f'{package}.config').EstimatorConfig
        known = set(config.__dataclass_fields__)
        cfg = config(**{k: v for k, v in PAPER_REFINE_0.items() if k in known})
        estimator(cfg).process(t[:5000], y[:5000])  # compile
        kernels.append((commit, estimator, cfg))
    times = {commit: [] for commit, _, _ in kernels}
    for _ in range(3):
        for commit, estimator, cfg in kernels:
            times[commit].append(best(lambda e=estimator, c=cfg: e(c).process(t, y), 1))
    if not kernels:
        return
    first = min(times[kernels[0][0]])
    for commit, _, _ in kernels:
        rate = n / min(times[commit]) / 1e6
        print(f'{commit:>10} {rate:6.2f} M samples/s   relative {first / min(times[commit]):5.2f}')


if __name__ == '__main__':
    main(sys.argv[1:] or ['627a108', '7374e6d', 'HEAD'])
