# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""The C heap under the numpy arrays (glibc's ``mallopt`` and ``malloc_trim``; elsewhere nothing):
one place for the node, which keeps its resident memory flat over weeks (docs/soak.md), and the
survey, whose Dask workers stream recordings (analysis/survey.py)."""

from __future__ import annotations

import ctypes

#: glibc's ``mallopt`` parameters: the trim threshold and the mmap threshold
M_TRIM_THRESHOLD, M_MMAP_THRESHOLD = -1, -3
#: the mmap threshold :func:`fix_allocator` sets (glibc's initial one)
MMAP_THRESHOLD = 128 * 1024


def glibc() -> bool:
    """Whether the C library has glibc's ``mallopt`` (what the functions below call)."""
    try:
        return hasattr(ctypes.CDLL(None), 'mallopt')
    except OSError:
        return False


def mallopt(param: int, value: int) -> bool:
    """glibc's ``mallopt(param, value)``; True when set (False elsewhere: not glibc)."""
    try:
        return ctypes.CDLL(None).mallopt(param, value) == 1
    except (OSError, AttributeError):
        return False


def fix_allocator() -> bool:
    """Fix glibc's mmap threshold at :data:`MMAP_THRESHOLD` (True when set; elsewhere nothing):
    a block at least that large is mapped for itself and unmapped when freed. glibc otherwise
    raises the threshold to the largest such block freed (32 MB at most), after which blocks of
    that size come from the heap, whose freed pages stay resident: the identifier's windows and
    self-tests (arrays of 0.1-10 MB, freed each analysis) grew the estimator's RSS by 21 MB
    over 24 simulated minutes after its start, its traced heap by 0.5 MB (tracemalloc; by 10 MB
    so, docs/soak.md)."""
    return mallopt(M_MMAP_THRESHOLD, MMAP_THRESHOLD)


def release_memory() -> None:
    """Give the C heap's free pages back to the system (glibc's ``malloc_trim``; elsewhere
    nothing). The heaps keep their peaks: the identifier's self-tests of four configurations in
    one stream left RSS about 200 MB above the start on the caller's thread, 9-20 MB each in a
    thread followed by this (docs/soak.md)."""
    try:
        ctypes.CDLL(None).malloc_trim(0)
    except (OSError, AttributeError):
        pass
