# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""One BLAS thread for the core's small dense linear algebra.

The identifiers' matrices are small (a Hankel matrix of a few dozen rows, state matrices of order
≤ 40, a pencil of ≤ 256 columns). OpenBLAS runs each call on all cores by default: on a 2-core
machine that gained no wall time and spent twice the CPU time (the second thread spins while it
waits; ``excitation: ambient`` cost 180-214x real time per 500 Hz channel with two threads and
400-480x with one, the same wall time), and on a machine busy with other work it made a sliding
matrix pencil 20x slower (88 s instead of 0.9 s for one 10 s record). Inside
:func:`one_blas_thread` every BLAS library loaded runs on one thread; the caller's setting is
restored after. Without threadpoolctl (it is in requirements.txt; a system install may lack it, or
have one that does not load) nothing is limited (:func:`..extras.optional`).
"""

from __future__ import annotations

import contextlib
import functools

from ..extras import optional


@functools.lru_cache(maxsize=None)
def blas_controller():
    """threadpoolctl's controller of numpy's and scipy's BLAS libraries (each wheel bundles its
    own OpenBLAS), or None without threadpoolctl. It knows only the libraries loaded when it is
    made, so scipy's is loaded first."""
    threadpoolctl = optional('threadpoolctl')
    if threadpoolctl is None:
        return None
    import scipy.linalg  # noqa: F401 -- loads scipy's OpenBLAS before the controller looks

    return threadpoolctl.ThreadpoolController()


def one_blas_thread():
    """A context in which BLAS calls run on one thread (about 4 µs to enter and leave)."""
    controller = blas_controller()
    if controller is None:
        return contextlib.nullcontext()
    return controller.limit(limits=1, user_api='blas')


def single_blas_thread(fn):
    """``fn`` run inside :func:`one_blas_thread` (a decorator)."""

    @functools.wraps(fn)
    def wrapped(*args, **kwargs):
        with one_blas_thread():
            return fn(*args, **kwargs)

    return wrapped
