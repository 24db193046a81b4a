# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""``vib-estimator warmup``: compile the estimator's kernels now (``make setup`` runs it).

A fresh install has no numba cache: the first process that runs an estimator compiles its kernels
(:mod:`vib_estimator.core.warmup`). This command pays that cost once, ahead of the first node or
analysis, for the configurations of :data:`~vib_estimator.core.warmup.CONFIGURATIONS`.
"""

from __future__ import annotations

import argparse
import time

from ..core.warmup import CONFIGURATIONS, warm_all


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        '--only',
        action='append',
        choices=sorted(CONFIGURATIONS),
        default=None,
        help='compile only this configuration (repeatable; default: all)',
    )


def run(args: argparse.Namespace) -> int:
    chosen = {name: CONFIGURATIONS[name] for name in (args.only or CONFIGURATIONS)}
    start = time.perf_counter()
    print(
        f'warmup: compiling the estimator kernels of {len(chosen)} configuration(s) '
        '(first run after an install; later runs load them from the cache)',
        flush=True,
    )
    warm_all(chosen, lambda line: print(line, flush=True))
    print(f'warmup: done in {time.perf_counter() - start:.1f} s')
    return 0
