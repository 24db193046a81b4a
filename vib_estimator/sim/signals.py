# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""Test signals of the paper (pure numpy): the Fig. 1 sine and the normalised damped
sine of Eq. 15."""

from __future__ import annotations

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
