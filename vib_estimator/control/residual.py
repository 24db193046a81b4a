# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""The residual vibration a move adds to a mode that is still ringing (pure numpy/scipy).

A lightly damped structure keeps ringing from its previous moves (zeta = 0.004 decays with a
~30 s time constant at 1.3 Hz), so the vibration after a move is the old one continued plus what
the move added. Both are free vibrations of the same mode, so one joint least-squares fit
separates them: on a window before the move and one after it has settled::

    y(t) = c_before [t < t_move] + c_after [t >= t_settled]
           + D(t) (a cos wd s + b sin wd s)                        the old vibration, continued
           + [t >= t_settled] D(t) (p cos wd s + q sin wd s)       what the move added

with ``s = t - t_move`` and ``D(t) = exp(-zeta w s)``. The window before pins ``(a, b)``; after the
move only ``(a + p, b + q)`` is seen. It is linear in the six coefficients; the mode's frequency
and damping are fitted too (variable projection: Nelder-Mead over (f, zeta), least squares
inside), starting from a guess.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class AddedVibration:
    """Amplitudes at ``t_settled`` (signal units) of the vibration the move added and of the one
    continued from before it; the fitted mode; the rms residual of the fit; the move's time and
    the six coefficients of the model (for :meth:`continued`)."""

    added: float
    previous: float
    frequency_hz: float
    damping: float
    rms_residual: float
    t_move: float = 0.0
    coefficients: tuple = (0.0,) * 6

    def continued(self, t) -> np.ndarray:
        """The vibration from before the move, continued to times ``t`` (no offset)."""
        s = np.asarray(t, dtype=float) - self.t_move
        m = _design(s, np.zeros(len(s), dtype=bool), self.frequency_hz, self.damping)
        return m[:, 2:4] @ np.asarray(self.coefficients[2:4])


def _design(s: np.ndarray, after: np.ndarray, frequency_hz: float, damping: float) -> np.ndarray:
    w = 2 * math.pi * frequency_hz
    decay = np.exp(-damping * w * s)
    phase = w * math.sqrt(max(1 - damping**2, 0.0)) * s
    c, d = decay * np.cos(phase), decay * np.sin(phase)
    return np.column_stack([~after, after, c, d, c * after, d * after]).astype(float)


def added_vibration(
    t,
    y,
    t_move: float,
    t_settled: float,
    before_s: float,
    after_s: float,
    frequency_hz: float,
    damping: float = 0.0,
) -> AddedVibration:
    """Fit the model above on ``[t_move - before_s, t_move)`` and ``[t_settled, t_settled +
    after_s)``; ``frequency_hz`` and ``damping`` are the starting guess of the mode."""
    from scipy.optimize import minimize

    t = np.asarray(t, dtype=float)
    y = np.asarray(y, dtype=float)
    before = (t >= t_move - before_s) & (t < t_move)
    after = (t >= t_settled) & (t < t_settled + after_s)
    if before.sum() < 10 or after.sum() < 10:
        raise ValueError('too few samples before or after the move to fit the vibration')
    keep = before | after
    s, yk, ak = t[keep] - t_move, y[keep], after[keep]

    def solve(x):
        m = _design(s, ak, x[0], x[1])
        coef = np.linalg.lstsq(m, yk, rcond=None)[0]
        return coef, float(np.sum((yk - m @ coef) ** 2))

    start = np.array([frequency_hz, damping])
    simplex = np.array([start, start + [2e-3 * frequency_hz, 0], start + [0, 2e-3]])
    best = minimize(
        lambda x: solve(x)[1],
        start,
        method='Nelder-Mead',
        options={'initial_simplex': simplex, 'xatol': 1e-8, 'fatol': 1e-12, 'maxiter': 400},
    )
    f, zeta = best.x
    coef, rss = solve(best.x)
    decay = math.exp(-zeta * 2 * math.pi * f * (t_settled - t_move))
    return AddedVibration(
        added=math.hypot(coef[4], coef[5]) * decay,
        previous=math.hypot(coef[2], coef[3]) * decay,
        frequency_hz=float(f),
        damping=float(zeta),
        rms_residual=math.sqrt(rss / len(yk)),
        t_move=t_move,
        coefficients=tuple(float(c) for c in coef),
    )


def move_onset(
    t,
    y,
    t_command: float,
    frequency_hz: float,
    damping: float = 0.0,
    window_s: float = 1.0,
    horizon_s: float = 2.0,
    threshold: float = 10.0,
) -> float:
    """When a move commanded at ``t_command`` shows in the signal: the first sample after it that
    leaves the free vibration fitted on the ``window_s`` before it (offset plus a decaying
    sinusoid of the given mode) by more than ``threshold`` times the fit's rms residual; NaN if
    none within ``horizon_s``. A command reaches the arm with a latency; this is the time the
    arm saw it."""
    t = np.asarray(t, dtype=float)
    y = np.asarray(y, dtype=float)
    before = (t >= t_command - window_s) & (t < t_command)
    later = np.flatnonzero((t >= t_command) & (t < t_command + horizon_s))
    if before.sum() < 10 or not len(later):
        raise ValueError('too few samples around the move to find its onset')
    m = _design(t - t_command, np.zeros(len(t), dtype=bool), frequency_hz, damping)[:, [0, 2, 3]]
    coef = np.linalg.lstsq(m[before], y[before], rcond=None)[0]
    sigma = math.sqrt(np.mean((y[before] - m[before] @ coef) ** 2))
    out = np.abs(y[later] - m[later] @ coef) > threshold * max(sigma, 1e-12)
    return float(t[later[np.argmax(out)]]) if out.any() else math.nan
