# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""``vib-estimator warmup``: compile the estimator's kernels now (``make setup`` runs it).

A fresh install has no numba cache: the first process that runs an estimator compiles its kernels
(:mod:`vib_estimator.core.warmup`). This command pays that cost once, ahead of the first node or
analysis, for the configurations of :data:`~vib_estimator.core.warmup.CONFIGURATIONS`.

It is also an executable of its own, ``warmup`` (:func:`main`), where ``ros2 run`` looks: on a
colcon-built install, ``ros2 run vib_estimator warmup`` once after the build (docs/startup.md).
"""

from __future__ import annotations

import argparse
import sys
import time
from typing import Optional, Sequence

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


def main(argv: Optional[Sequence[str]] = None) -> int:
    """The ``warmup`` executable (``ros2 run vib_estimator warmup``): ``vib-estimator warmup``;
    a ``--ros-args`` section (which ``ros2 run`` may add) is ignored."""
    argv = list(sys.argv[1:] if argv is None else argv)
    if '--ros-args' in argv:
        argv = argv[: argv.index('--ros-args')]
    parser = argparse.ArgumentParser(prog='warmup', description=__doc__.splitlines()[0])
    add_arguments(parser)
    return run(parser.parse_args(argv))
