# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""The cost of another revision's identifiers on the same records, in the same run: its
``vib_estimator`` extracted with ``git archive`` (``bench_compile.extract``) into a temporary
directory and timed in a subprocess (``--ref REV`` of ``bench_operation`` and ``bench_channels``).

The subprocess first runs a throwaway estimator over the record's first seconds (numba's kernels
compile or load there, as they have in this process by then), then times ``process`` over the
whole record in CPU seconds (``time.process_time``), as the benchmarks time this revision's.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
from bench_compile import extract  # benchmarks/

PROBE = r"""
import json, sys, time
import numpy as np
from vib_estimator.core.config import EstimatorConfig
data = np.load(sys.argv[1])
kw = json.loads(sys.argv[2])
if kw.get('band_hz') is not None:
    kw['band_hz'] = tuple(kw['band_hz'])
config = EstimatorConfig(**kw)
t, y = data['t'], data['y']
if y.ndim == 1:
    from vib_estimator.core import create_estimator
    make = lambda: create_estimator(config)
else:
    from vib_estimator.core.ambient import AmbientEstimator
    make = lambda: AmbientEstimator(config, [f'c{i}' for i in range(y.shape[1])])
make().process(t[:2000], y[:2000])
est = make()
start = time.process_time()
est.process(t, y)
print(time.process_time() - start)
"""


class Reference:
    """Another revision's identifiers, timed on records handed to :meth:`seconds`."""

    def __init__(self, rev: str):
        self.rev = rev
        self._dir = tempfile.TemporaryDirectory(prefix='vib-ref-')
        self.src = extract(rev, Path(self._dir.name))

    def seconds(self, t: np.ndarray, y: np.ndarray, **config) -> float:
        """CPU seconds the revision's ``process`` takes over ``(t, y)`` (``y``: samples, or
        samples x channels for the joint identifier) with ``EstimatorConfig(**config)``."""
        record = Path(self._dir.name) / 'record.npz'
        np.savez(record, t=t, y=y)
        env = dict(os.environ, PYTHONPATH=str(self.src))
        out = subprocess.run(
            [sys.executable, '-c', PROBE, str(record), json.dumps(config)],
            env=env,
            cwd=self.src,
            capture_output=True,
            text=True,
            check=True,
        )
        return float(out.stdout.strip().splitlines()[-1])
