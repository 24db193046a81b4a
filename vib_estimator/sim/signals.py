# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""Test signals of the paper (pure numpy): the Fig. 1 sine and the normalised damped
sine of Eq. 15."""

from __future__ import annotations

from typing import Tuple

import numpy as np


def fig1_signal(
    t: np.ndarray,
    seed: int = 0,
    omega: float = 10.0,
    phase: float = 1.0,
    amplitude: float = 1.0,
    noise: float = 0.01,
) -> np.ndarray:
    """Section 4's signal: ``A sin(w t + phi)`` plus piecewise-constant uniform noise in [-e, e].

    MATLAB's ``rand`` in a Simulink block holds each draw for one sample, hence one uniform draw
    per sample (seeded, so every run sees the same noise).
    """
    rng = np.random.default_rng(seed)
    return amplitude * np.sin(omega * t + phase) + rng.uniform(-noise, noise, size=len(t))


def normalised_damped_sine(t_hat: np.ndarray, zeta: float, phase: float = 0.0) -> np.ndarray:
    """Eq. 15: the damped sine in normalised time (period 1 s, unit amplitude when zeta = 0)."""
    return np.exp(-2 * np.pi * zeta / np.sqrt(1 - zeta**2) * t_hat) * np.sin(
        2 * np.pi * t_hat + phase
    )


def gappy_sine(
    seed: int, offset: float = 0.0, rate_hz: float = 500.0, f: float = 2.0
) -> Tuple[np.ndarray, np.ndarray, int]:
    """Issue 22's lost samples: a ``f`` Hz sine sampled at ``rate_hz`` for 60 s with 40 gaps of
    40-400 ms cut out (seeded, noise-free), plus ``offset``; returns (t, y, samples cut out)."""
    rng = np.random.default_rng(seed)
    t = np.arange(0, 60, 1 / rate_hz)
    keep = np.ones(len(t), bool)
    for start in rng.choice(len(t) - 300, 40, replace=False):
        keep[start : start + int(rng.uniform(0.04, 0.4) * rate_hz)] = False
    return t[keep], np.sin(2 * np.pi * f * t[keep]) + offset, int((~keep).sum())


def plucked_decays(
    seed: int,
    f: float = 5.0,
    zeta: float = 0.004,
    snr_db: float = 30.0,
    plucks: int = 3,
    every_s: float = 20.0,
    rate_hz: float = 500.0,
) -> Tuple[np.ndarray, np.ndarray]:
    """A day of free decays (issue 20's survey fleet): ``plucks`` decays of an ``f`` Hz mode of
    damping ratio ``zeta``, one every ``every_s`` s (each of random phase, amplitude 0.5-2, the
    last ones' tails still ringing), plus white noise ``snr_db`` below a unit pluck's power,
    ``plucks * every_s`` s at ``rate_hz``; returns (t, y)."""
    rng = np.random.default_rng(seed)
    t = np.arange(round(plucks * every_s * rate_hz)) / rate_hz
    w = 2 * np.pi * f
    y = np.zeros_like(t)
    for k in range(plucks):
        u = t - k * every_s
        a, phase = rng.uniform(0.5, 2.0), rng.uniform(0, 2 * np.pi)
        ring = a * np.exp(-zeta * w * u) * np.sin(w * np.sqrt(1 - zeta**2) * u + phase)
        y += np.where(u >= 0, ring, 0.0)
    noise = np.sqrt(0.5 / 10 ** (snr_db / 10))
    return t, y + noise * rng.standard_normal(len(t))
