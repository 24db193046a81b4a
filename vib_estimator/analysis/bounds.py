# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""Cramer-Rao lower bounds on the frequency (and damping) of the estimator's signal models.

For ``N`` samples ``y_n = A sin(w n Ts + phi) + e_n``, ``e_n ~ N(0, sigma^2)``, with A, w and phi
unknown, the bound on any unbiased estimator of w is (Rife & Boorstyn 1974; Kay 1993, Ex. 3.14)::

    var(w^) >= 24 sigma^2 / (A^2 Ts^2 N (N^2 - 1))        (rad/s)^2

which is asymptotic (it drops terms of relative order 1/N and assumes the frequency is not near 0
or Nyquist). :func:`fisher_frequency_std` computes the exact bound for given parameters from the
Fisher information matrix, to check it; :func:`model_crb` is the exact bound of each of the
estimator's models (sinusoid; with an offset; damped, bounding the natural frequency and the
damping ratio) over the samples an estimate used.
"""

from __future__ import annotations

import math
from typing import Tuple

import numpy as np


def crlb_frequency_std(amplitude: float, noise_std: float, ts: float, n: int) -> float:
    """Asymptotic CRLB on the standard deviation of a frequency estimate, Hz.

    ``amplitude`` and ``noise_std`` in signal units, ``ts`` the sampling period (s), ``n`` the
    number of samples; ``sqrt(24 sigma^2 / (A^2 Ts^2 N (N^2 - 1))) / (2 pi)``. Infinite for
    ``n < 2`` or a zero amplitude.
    """
    if n < 2 or amplitude == 0:
        return math.inf
    var_w = 24.0 * noise_std**2 / (amplitude**2 * ts**2 * n * (n * n - 1.0))
    return math.sqrt(var_w) / (2 * math.pi)


def fisher_frequency_std(
    amplitude: float,
    frequency_hz: float,
    phase: float,
    noise_std: float,
    ts: float,
    n: int,
    rel_step: float = 1e-6,
) -> float:
    """Exact CRLB on the frequency's standard deviation (Hz) from the Fisher information.

    The Jacobian of ``s(theta) = A sin(w t + phi)``, ``t = k Ts``, with respect to
    ``theta = (A, w, phi)`` is taken by central differences; ``FIM = J^T J / sigma^2`` and the
    bound
    is ``sqrt([FIM^-1]_ww) / (2 pi)``.
    """
    t = np.arange(n) * ts
    theta = np.array([amplitude, 2 * math.pi * frequency_hz, phase], dtype=float)

    def model(p):
        return p[0] * np.sin(p[1] * t + p[2])

    jac = np.empty((n, 3))
    for i in range(3):
        step = rel_step * max(abs(theta[i]), 1.0)
        up, down = theta.copy(), theta.copy()
        up[i] += step
        down[i] -= step
        jac[:, i] = (model(up) - model(down)) / (2 * step)
    fim = jac.T @ jac / noise_std**2
    return math.sqrt(np.linalg.inv(fim)[1, 1]) / (2 * math.pi)


def window_crlb_std(y: np.ndarray, ts: float, frequency_hz: float, noise_std: float) -> float:
    """Exact CRLB (Hz) for the data window ``y`` (uniform samples ``ts`` apart) at its frequency.

    The amplitude and phase the bound needs are those of the least-squares fit of
    ``a sin(w t) + b cos(w t) + c`` at ``w = 2 pi frequency_hz`` to the window (the offset ``c``
    only keeps a slow drift out of the amplitude); the bound is :func:`fisher_frequency_std`,
    since for windows shorter than about one period the asymptotic :func:`crlb_frequency_std` is
    off by a phase-dependent factor (0.9-3.3 over half a period).
    """
    n = len(y)
    if n < 4:
        return math.inf
    w = 2 * math.pi * frequency_hz
    t = np.arange(n) * ts
    basis = np.column_stack((np.sin(w * t), np.cos(w * t), np.ones(n)))
    (a, b, _), *_ = np.linalg.lstsq(basis, y, rcond=None)
    return fisher_frequency_std(math.hypot(a, b), frequency_hz, math.atan2(b, a), noise_std, ts, n)


def model_crb(
    model: str,
    t: np.ndarray,
    amplitude: float,
    frequency_hz: float,
    phase: float,
    noise_std: float,
    damping: float = 0.0,
) -> Tuple[float, float]:
    """Exact CRB (std of the natural frequency in Hz, std of the damping ratio) for one window.

    The signal is the model's, at its true parameters, on the sample times ``t`` (the samples the
    estimate used)::

        sinusoid:         A sin(w t + phi)                                  (A, phi, w)
        biased-sinusoid:  A sin(w t + phi) + B                              (A, phi, w, B)
        damped-sinusoid:  A exp(-zeta w_n t) sin(w_d t + phi), w_d = w_n sqrt(1 - zeta^2)
                                                                            (A, phi, w_d, sigma)

    with white Gaussian noise of std ``noise_std``; every parameter unknown (the offset's value
    does not enter the bound). ``FIM = J^T J / noise_std^2`` from the analytic Jacobian, on
    centred time (amplitude and phase moved to the window's centre, which leaves the bound
    unchanged and the matrix well conditioned); for the damped model the bounds on
    w_n = sqrt(w_d^2 + sigma^2) and zeta = sigma / w_n follow from the (w_d, sigma) block.
    The damping-ratio bound is NaN for the models without damping.
    """
    t = np.asarray(t, dtype=float)
    wn = 2 * math.pi * frequency_hz
    sigma = damping * wn if model == 'damped-sinusoid' else 0.0
    wd = math.sqrt(wn * wn - sigma * sigma)
    tm = 0.5 * (t[0] + t[-1])
    u = t - tm
    amp = amplitude * math.exp(-sigma * tm)
    env = amp * np.exp(-sigma * u)
    arg = wd * u + phase + wd * tm
    cols = [env / amp * np.sin(arg), env * np.cos(arg), u * env * np.cos(arg)]
    if model == 'biased-sinusoid':
        cols.append(np.ones_like(u))
    elif model == 'damped-sinusoid':
        cols.append(-u * env * np.sin(arg))
    jac = np.column_stack(cols)
    scale = 1.0 / np.sqrt(np.sum(jac * jac, axis=0))
    cov = np.linalg.inv((jac * scale).T @ (jac * scale)) * np.outer(scale, scale) * noise_std**2
    if model != 'damped-sinusoid':
        return math.sqrt(cov[2, 2]) / (2 * math.pi), math.nan
    g_w = np.array([wd / wn, sigma / wn])
    g_z = np.array([-sigma * wd / wn**3, wd * wd / wn**3])
    block = cov[2:4, 2:4]
    return (math.sqrt(g_w @ block @ g_w) / (2 * math.pi), math.sqrt(g_z @ block @ g_z))
