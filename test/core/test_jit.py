# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""core.jit.borrowed: a view of the caller's array without its reference count."""

from __future__ import annotations

import sys

import numpy as np
from numba import njit

from vib_estimator.core.jit import borrowed


@njit
def _fill_through_views(a, b):
    """Writes through borrowed views of ``a`` and of a view of it, reads ``b`` through one."""
    a = borrowed(a)
    head = a[:2]
    head[0] = 1.5
    a.reshape((2, 2))[1, 1] = 2.5
    b = borrowed(b)
    return b[0] + b[1]


def test_a_borrowed_view_reads_and_writes_the_callers_memory():
    a = np.zeros(4)
    b = np.array([3.0, 4.0])
    assert _fill_through_views(a, b) == 7.0
    np.testing.assert_array_equal(a, [1.5, 0.0, 0.0, 2.5])


def test_borrowing_leaves_the_reference_counts_as_they_were():
    a = np.zeros(4)
    b = np.ones(2)
    _fill_through_views(a, b)  # compiled
    before = sys.getrefcount(a), sys.getrefcount(b)
    for _ in range(1000):
        _fill_through_views(a, b)
    assert (sys.getrefcount(a), sys.getrefcount(b)) == before


# ---- available: compiled code in memory or numba's cache, never a compile ---------------------
@njit
def _twice(x):
    return 2.0 * x


def test_available_says_whether_a_call_would_compile_and_never_compiles():
    from vib_estimator.core.jit import available

    assert not available(_twice, (1.0,)) and not _twice.signatures  # nothing compiled
    assert _twice(1.0) == 2.0
    assert available(_twice, (1.0,)) and not available(_twice, (np.zeros(2),))
    assert len(_twice.signatures) == 1


# ---- NUMBA_DISABLE_JIT=1: numba's switch for debugging, the kernels as plain Python -------------
def test_the_estimators_run_as_python_under_numba_disable_jit(tmp_path):
    """A developer who sets numba's NUMBA_DISABLE_JIT=1 (to step through a kernel) gets the same
    answer, not an AttributeError at import (njit then returns the plain function: no
    ``py_func``, no ``compile``, ``borrowed`` unusable)."""
    import os
    import subprocess

    t = np.arange(0.0, 4.0, 0.002)
    y = np.exp(-0.05 * t) * np.sin(2 * np.pi * 3.0 * t) * (t >= 0.5)
    y += 1e-3 * np.random.default_rng(0).standard_normal(len(t))
    path = tmp_path / 'decay.csv'
    np.savetxt(path, np.column_stack([t, y]), delimiter=',', header='t,y', comments='')
    out = {}
    for flag in ('0', '1'):
        env = dict(os.environ, NUMBA_DISABLE_JIT=flag)
        run = subprocess.run(
            [sys.executable, '-m', 'vib_estimator.cli', 'analyze', str(path), '--format', 'jsonl'],
            capture_output=True,
            text=True,
            env=env,
            timeout=300,
        )
        assert run.returncode == 0, run.stderr[-2000:]
        out[flag] = [line for line in run.stdout.splitlines() if line.startswith('{')]
    assert out['0'] and out['1'] == out['0']
