# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""Test signals (pure numpy): the paper's Fig. 1 sine and normalised damped sine of Eq. 15,
gappy and repeatedly plucked decays, a pluck beside a machine's lines, and a closed loop's limit
cycle."""

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
    seed,
    f=5.0,
    zeta=0.004,
    snr_db=30.0,
    plucks=3,
    every_s=20.0,
    rate_hz=500.0,
    impacts=False,
    start_s=0.0,
):
    """A day of free decays (issue 20's survey fleet): ``plucks`` decays of an ``f`` Hz mode of
    damping ratio ``zeta``, one every ``every_s`` s from ``start_s`` (each of random phase,
    amplitude 0.5-2, the last ones' tails still ringing; ``impacts``: each a unit impact, phase
    0, as a hammer's), plus white noise ``snr_db`` below a unit pluck's power,
    ``start_s + plucks * every_s`` s at ``rate_hz``; returns (t, y)."""
    rng = np.random.default_rng(seed)
    t = np.arange(round((start_s + plucks * every_s) * rate_hz)) / rate_hz
    w = 2 * np.pi * f
    y = np.zeros_like(t)
    for k in range(plucks):
        u = t - start_s - k * every_s
        a, phase = (1.0, 0.0) if impacts else (rng.uniform(0.5, 2.0), rng.uniform(0, 2 * np.pi))
        ring = a * np.exp(-zeta * w * u) * np.sin(w * np.sqrt(1 - zeta**2) * u + phase)
        y += np.where(u >= 0, ring, 0.0)
    noise = np.sqrt(0.5 / 10 ** (snr_db / 10))
    return t, y + noise * rng.standard_normal(len(t))


def beside_lines(mode, zeta, lines, seconds, rate_hz, start_s=1.0, seed=0):
    """A pluck of a ``mode`` Hz mode of damping ratio ``zeta`` at ``start_s`` (a unit impact,
    :func:`plucked_decays`, in white noise of 0.005: 43 dB below its power) beside steady
    ``lines`` ((Hz, amplitude), ...: a machine running nearby, the k-th at phase k), ``seconds``
    at ``rate_hz``; returns (t, y)."""
    t, y = plucked_decays(seed, mode, zeta, 43.0, 1, seconds - start_s, rate_hz, True, start_s)
    for k, (f, a) in enumerate(lines):
        y = y + a * np.sin(2 * np.pi * f * t + k)
    return t, y


def limit_cycle(
    seconds, rate_hz, seed=0, wander=0.05, diffusion=0.02, step=1e-3, scale=1.0, noise=2e-4
):
    """A closed loop's limit cycle of the real flexible-link arm's kind (``flex8``'s fit,
    ``benchmarks/real_arm.py``: -4.8 mm offset, 10.1 mm at 1.8116 Hz, 2nd and 3rd harmonics 0.19
    and 0.05 mm; m; all but the offset x ``scale``: ``flex1``'s ~5 mm at 0.5): its amplitude
    wandering by ``wander`` (at 0.37 Hz), its phase diffusing by ``diffusion`` x 2 pi rad in a
    second's square root (0.13 rad in a second: its frequency wanders by ~1 % over a second), in
    ``noise`` m of white noise (0.2 mm), read in steps of ``step`` m (the rig's 1 mm; 0: not
    quantised; flex1 moves in clean 1 mm steps, undithered). ``(t, y)``."""
    rng = np.random.default_rng(seed)
    t = np.arange(0, seconds, 1 / rate_hz)
    drift = np.cumsum(diffusion * 2 * np.pi * rng.standard_normal(len(t))) / np.sqrt(rate_hz)
    w = 2 * np.pi * 1.8116 * t + rng.uniform(0, 2 * np.pi) + drift
    a = 10.1e-3 * (1 + wander * np.sin(2 * np.pi * 0.37 * t + 1))
    y = a * np.sin(w) + 0.19e-3 * np.sin(2 * w + 1) + 0.05e-3 * np.sin(3 * w + 2)
    y = -4.8e-3 + scale * y
    y = y + noise * rng.standard_normal(len(t))
    return t, (np.round(y / step) * step if step else y)


def step_into_limit_cycle(seconds, rate_hz, seed=0):
    """:func:`limit_cycle` with a reference step's ringing on it from 2 s, as the real arm rings
    before its cycle (flex8: 1.55-1.74 Hz, damped 5-8 %): 30 mm at 1.6 Hz, zeta 6 %, read in 1 mm
    steps of its own. ``(t, y)``."""
    t, y = limit_cycle(seconds, rate_hz, seed)
    tau = t[t >= 2.0] - 2.0
    ring = np.exp(-0.06 * 2 * np.pi * 1.6 * tau) * np.sin(2 * np.pi * 1.6 * tau)
    y[t >= 2.0] += np.round(30 * ring) * 1e-3
    return t, y


def two_plucks(per_period, zeta, second, seed=0, f=10.0):
    """Two plucks of ``f`` Hz in 37 dB of white noise: at 1 s (damping ratio ``zeta``) and, half
    as strong (zeta 0.02), at ``second`` s, once the first rang down; ``per_period`` samples a
    period, 5 s after the second; returns (t, y)."""
    t = np.arange(0, second + 5, 1 / (per_period * f))
    y = 0.01 / np.sqrt(2) * np.random.default_rng(seed).standard_normal(len(t))
    for start, amplitude, z in ((1.0, 1.0, zeta), (second, 0.5, 0.02)):
        tau = np.maximum(t - start, 0.0)
        wave = np.exp(-z * 2 * np.pi * f * tau) * np.sin(2 * np.pi * f * tau + 1.0)
        y += amplitude * wave * (t >= start)
    return t, y


def pulled_pluck(rest, pull, seed=0, f=9.4, rate_hz=1000.0, noise=1e-3):
    """A pluck as a hand gives it: ``rest`` s of rest, the beam pulled to -1 over ``pull`` s (a
    half cosine), then let go: ``f`` Hz at damping ratio 0.004 for 10 s, plus white ``noise``
    (its std), at ``rate_hz``; returns (t, y)."""
    t = np.arange(0, rest + pull + 10, 1 / rate_hz)
    y = np.zeros_like(t)
    ramp = (t >= rest) & (t < rest + pull)
    y[ramp] = -0.5 * (1 - np.cos(np.pi * (t[ramp] - rest) / pull))
    tau = t - rest - pull
    on = tau >= 0
    y[on] = -np.exp(-0.004 * 2 * np.pi * f * tau[on]) * np.cos(2 * np.pi * f * tau[on])
    return t, y + noise * np.random.default_rng(seed).standard_normal(len(t))
