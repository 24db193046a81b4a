# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""Records of structures under ambient excitation (pure numpy/scipy): white-noise-driven modes.

Each mode is an SDOF ``x'' + 2 zeta wn x' + wn^2 x = w(t)``, ``w`` continuous white noise, sampled
exactly (the discrete model of the sampled process: ``x_k+1 = Ad x_k + e_k`` with
``e_k ~ N(0, Qd)``, Van Loan's matrix exponential), scaled to its stationary variance and started
from its stationary distribution; the record is the sum of the modes' displacements plus white
measurement noise at a signal-to-noise ratio (total modal variance over noise variance).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from scipy.linalg import expm, solve_discrete_lyapunov
from scipy.signal import lfilter


def sdof_response(
    n: int, fs: float, frequency_hz: float, zeta: float, variance: float, rng: np.random.Generator
) -> np.ndarray:
    """``n`` samples at ``fs`` of a white-noise-driven SDOF's displacement of stationary
    ``variance`` (see the module doc)."""
    w = 2 * math.pi * frequency_hz
    a = np.array([[0.0, 1.0], [-w * w, -2 * zeta * w]])
    van_loan = expm(np.block([[-a, np.diag([0.0, 1.0])], [np.zeros((2, 2)), a.T]]) / fs)
    ad = van_loan[2:, 2:].T
    qd = ad @ van_loan[:2, 2:]
    qd = 0.5 * (qd + qd.T)
    p = solve_discrete_lyapunov(ad, qd)
    scale = math.sqrt(variance / p[0, 0])
    e = rng.standard_normal((n, 2)) @ np.linalg.cholesky(qd).T
    x0 = np.linalg.cholesky(p) @ rng.standard_normal(2)
    # x_k+1 = Ad x_k + e_k, state by state: two first-order recursions through lfilter would
    # not couple; run the 2-state recursion as a vector IIR on the modal (complex) coordinate
    lam, vec = np.linalg.eig(ad)
    inv = np.linalg.inv(vec)
    q = e @ inv.T  # modal noise, complex
    z = np.empty((n, 2), dtype=complex)
    z0 = inv @ x0
    for i in range(2):
        zi, _ = lfilter([1.0], [1.0, -lam[i]], q[:, i], zi=[lam[i] * z0[i]])
        z[:, i] = zi
    x = (z @ vec.T).real
    return scale * x[:, 0]


def ambient_record(
    duration_s: float,
    fs: float,
    modes: Sequence[tuple[float, float, float]],
    snr_db: float,
    seed: int = 0,
) -> tuple[np.ndarray, np.ndarray, float]:
    """``(t, y, noise variance)``: ``duration_s`` at ``fs`` of the white-noise-driven ``modes``
    [(frequency Hz, damping ratio, variance)] plus white noise at ``snr_db`` (total modal
    variance over noise variance)."""
    rng = np.random.default_rng(seed)
    n = round(duration_s * fs)
    y = np.zeros(n)
    for f, z, v in modes:
        y += sdof_response(n, fs, f, z, v, rng)
    noise_var = sum(v for _, _, v in modes) / 10 ** (snr_db / 10)
    y += math.sqrt(noise_var) * rng.standard_normal(n)
    return np.arange(n) / fs, y, noise_var
