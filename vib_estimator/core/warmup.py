# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""Compile, ahead of the data, the kernels a configuration runs (numba; no rclpy).

numba compiles a kernel the first time it is called and, with ``cache=True``, keeps the machine
code in ``__pycache__`` beside the sources (or the user's cache folder when that is read-only, or
``NUMBA_CACHE_DIR``); later processes load it in a fraction of a second. :func:`warm` calls every
entry point one configuration uses -- the streaming step (``update``, the node's data path) and the
batch run (``process``: ``analyze``, ``survey``, the node's self-test) -- on a short synthetic
signal, so that the compile happens before the first real sample. ``make setup`` and
``vib-estimator warmup`` run :func:`warm_all` over :data:`CONFIGURATIONS`; the estimator node runs
:func:`warm` in a background thread while it buffers its input (:mod:`vib_estimator.nodes.stream`).

numba writes each cache file under a temporary name and renames it, so a process killed during a
compile leaves the cache as it was: the next start compiles again, nothing reads a torn file.
"""

from __future__ import annotations

import time
from typing import Callable, Dict, Hashable, Optional, Sequence, Tuple

import numpy as np

from .config import EstimatorConfig
from .factory import create_estimator

#: the synthetic signal: a lightly damped tone at 500 Hz, enough samples for several estimates
RATE_HZ = 500.0
TONE_HZ = 5.0
SAMPLES = 1500

#: the configurations ``make setup`` / ``vib-estimator warmup`` compile: the default, the paper's
#: (Section 5.3: the demo, the reproductions), the damped model, the band-pass prefilter, the
#: target-std rule, the mode tracker and the ambient identifier (its zero-phase decimation filter;
#: the set-ups the README's quick start and the benchmarks use)
CONFIGURATIONS: Dict[str, EstimatorConfig] = {
    'default': EstimatorConfig(),
    'paper': EstimatorConfig.paper(),
    'damped-sinusoid': EstimatorConfig(model='damped-sinusoid'),
    'band_hz': EstimatorConfig(band_hz=(1.0, 20.0)),
    'target_std_rel': EstimatorConfig(target_std_rel=0.01),
    'modes: 3': EstimatorConfig(modes=3),
    'excitation: ambient': EstimatorConfig(excitation='ambient'),
}

#: compile keys of the configurations warmed in this process (see :func:`compile_key`)
_warmed = set()


def compile_key(config: EstimatorConfig) -> Hashable:
    """What decides which kernels a configuration compiles. Two configurations with one key run the
    same compiled code (a conservative key: a finer split only costs a call of :func:`warm`)."""
    return (
        config.modes > 0,
        config.model,
        config.band_hz is not None,
        config.target_std_rel > 0,
        config.refine > 0,
    )


def is_warm(config: EstimatorConfig) -> bool:
    """True when :func:`warm` already ran for a configuration of this compile key in this process
    (its kernels are in memory: building an estimator of it compiles nothing)."""
    return compile_key(config) in _warmed


def signal(samples: int = SAMPLES) -> Tuple[np.ndarray, np.ndarray]:
    """(t, y) of the synthetic warm-up signal."""
    t = np.arange(samples) / RATE_HZ
    return t, np.exp(-0.05 * t) * np.sin(2 * np.pi * TONE_HZ * t) + 0.01 * np.cos(7.0 * t)


def warm(config: EstimatorConfig) -> float:
    """Compile (or load from the cache) every kernel ``config`` runs; return the seconds it
    took."""
    start = time.perf_counter()
    t, y = signal()
    streaming = create_estimator(config)
    for i in range(8):
        streaming.update(t[i], y[i])
    create_estimator(config).process(t, y)
    _warmed.add(compile_key(config))
    return time.perf_counter() - start


def warm_all(
    configurations: Optional[Dict[str, EstimatorConfig]] = None,
    report: Callable[[str], None] = print,
) -> Sequence[Tuple[str, float]]:
    """:func:`warm` each configuration (default :data:`CONFIGURATIONS`), reporting each as it ends;
    return (name, seconds) pairs."""
    times = []
    for name, config in (configurations or CONFIGURATIONS).items():
        seconds = warm(config)
        times.append((name, seconds))
        report(f'warmup: {name}: {seconds:.1f} s')
    return times
