# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""What the estimator node's RSS does over a long life (docs/soak.md, "What grows (RSS)"): freed
arrays are given back (glibc's mmap threshold fixed), and a deciding stream loads the identifier
it may switch to at its start, not minutes into a run."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

from vib_estimator.core.config import EstimatorConfig
from vib_estimator.nodes import stream as S

#: arrays of 1 MB made and freed, one kept at the heap's top; RSS growth printed (MB)
_CHURN = """
import ctypes, sys
import numpy as np
from vib_estimator.io.heap import fix_allocator
if not hasattr(ctypes.CDLL(None), 'mallinfo2') or sys.argv[1] == 'fixed' and not fix_allocator():
    print('unfixable'); sys.exit()  # not glibc 2.33 or later
def rss():
    return int(open('/proc/self/status').read().split('VmRSS:')[1].split()[0]) / 1024
big = np.ones(1 << 20); del big  # 8 MB freed: glibc's dynamic threshold rises to it
before = rss()
blocks = [np.ones(1 << 17) for _ in range(40)]  # 1 MB each, touched
kept = blocks[-1]
del blocks
grown = rss() - before
class Info(ctypes.Structure):
    _fields_ = [(name, ctypes.c_size_t) for name in (
        'arena ordblks smblks hblks hblkhd usmblks fsmblks uordblks fordblks keepcost'.split())]
libc = ctypes.CDLL(None)
libc.mallinfo2.restype = Info
mapped = libc.mallinfo2().hblks
small = [np.ones(5000) for _ in range(10)]  # 40 kB each: a batch of 5000 samples
print(grown, libc.mallinfo2().hblks - mapped)
"""


def _churn(mode: str) -> tuple:
    """(RSS growth in MB, small arrays mapped for themselves) of :data:`_CHURN`."""
    # glibc's own thresholds: no MALLOC_* variable (a Dask worker's MALLOC_TRIM_THRESHOLD_ fixes
    # the mmap threshold too, and the suite's survey tests start such workers)
    env = {k: v for k, v in os.environ.items() if not k.startswith('MALLOC_')}
    out = subprocess.run(
        [sys.executable, '-c', _CHURN, mode], capture_output=True, text=True, check=True, env=env
    ).stdout.split()
    if out == ['unfixable']:
        pytest.skip("no glibc 2.33's mallopt and mallinfo2 here")
    return float(out[0]), int(out[1])


def test_freed_arrays_are_given_back_once_the_mmap_threshold_is_fixed():
    # glibc's own: after an 8-MB array was freed, 1-MB arrays come from the heap and stay
    # resident when freed below a live one (the identifier's windows, analysis after analysis)
    assert _churn('dynamic')[0] > 25.0
    grown, mapped = _churn('fixed')
    assert grown < 5.0  # each mapped for itself, unmapped when freed
    assert mapped == 0  # the data path's batches (40 kB) stay in the heap: no mapping each


def _warmed(monkeypatch, deciding: bool, config: EstimatorConfig) -> list:
    """The configurations a background stream's start warms (the warm-up made to run)."""
    warmed = []
    monkeypatch.setattr(S, 'is_warm', lambda c: False)
    monkeypatch.setattr(S, 'warm', lambda c: warmed.append(c) or 0.0)
    stream = S.EstimatorStream(config, 0.0, background=True, deciding=deciding)
    stream._build._thread.join(10.0)
    assert stream.poll() == [] and not stream.compiling
    return warmed


def test_a_deciding_stream_loads_the_identifier_at_its_start(monkeypatch):
    config = EstimatorConfig()
    warmed = _warmed(monkeypatch, True, config)
    assert warmed == [config, config.replace(excitation='auto')]
    assert _warmed(monkeypatch, False, config) == [config]  # it never switches
    ambient = EstimatorConfig(excitation='ambient')  # the user's: held, built, nothing more
    assert [c.excitation for c in _warmed(monkeypatch, True, ambient)] == ['ambient']
