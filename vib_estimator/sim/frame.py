# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""Multi-channel records of white-noise-driven structures (pure numpy/scipy): a shear frame.

:func:`modal_record`: channels ``y = Phi q + noise``, each modal coordinate ``q_j`` an independent
white-noise-driven SDOF of its own stationary variance (:func:`..sim.ambient.sdof_response`:
exact sampling), ``Phi`` the (channels x modes) mode shapes, plus white measurement noise on every
channel at a signal-to-noise ratio (the mean channel's modal variance over the noise's).

:func:`shear_frame`: the modes of an ``n``-storey shear frame (equal storey masses and
stiffnesses, fixed base): ``K`` tridiagonal, ``M = I``; frequencies scaled so that the first is
``f1_hz``; shapes the eigenvectors of ``K`` (mass-normalised). Five storeys with ``f1 = 0.89 Hz``
give 0.89, 2.60, 4.10, 5.26, 6.00 Hz. One channel per storey (its displacement).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from .ambient import sdof_response


def shear_frame(storeys: int = 5, f1_hz: float = 0.89) -> tuple[np.ndarray, np.ndarray]:
    """``(frequencies Hz ascending, shapes (storeys x modes), each column unit norm, largest
    entry positive)`` of a uniform ``storeys``-storey shear frame whose first mode is at
    ``f1_hz``."""
    k = 2.0 * np.eye(storeys) - np.eye(storeys, k=1) - np.eye(storeys, k=-1)
    k[-1, -1] = 1.0  # the top storey has one spring below it only
    w2, shapes = np.linalg.eigh(k)
    freqs = np.sqrt(w2) * f1_hz / math.sqrt(w2[0])
    shapes = shapes / np.linalg.norm(shapes, axis=0)
    shapes *= np.sign(shapes[np.argmax(np.abs(shapes), axis=0), np.arange(storeys)])
    return freqs, shapes


def modal_record(
    duration_s: float,
    fs: float,
    modes: Sequence[tuple[float, float, float]],
    shapes: np.ndarray,
    snr_db: float,
    seed: int = 0,
) -> tuple[np.ndarray, np.ndarray]:
    """``(t, Y)``: ``duration_s`` at ``fs`` of the channels (columns of ``Y``) of the
    white-noise-driven ``modes`` [(frequency Hz, damping ratio, modal variance)] seen through
    ``shapes`` (channels x modes), plus white noise at ``snr_db`` (see the module doc)."""
    shapes = np.asarray(shapes, dtype=np.float64)
    if shapes.ndim != 2 or shapes.shape[1] != len(modes):
        raise ValueError(f'shapes must be channels x {len(modes)} modes, got {shapes.shape}')
    rng = np.random.default_rng(seed)
    n = round(duration_s * fs)
    q = np.column_stack([sdof_response(n, fs, f, z, v, rng) for f, z, v in modes])
    y = q @ shapes.T
    signal_var = float(np.mean(shapes**2 @ np.array([v for _, _, v in modes])))
    noise_var = signal_var / 10 ** (snr_db / 10)
    y += math.sqrt(noise_var) * rng.standard_normal(y.shape)
    return np.arange(n) / fs, y


def frame_record(
    duration_s: float,
    fs: float,
    zeta: float = 0.02,
    snr_db: float = 20.0,
    seed: int = 0,
    storeys: int = 5,
    f1_hz: float = 0.89,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """``(t, Y, frequencies, shapes)``: a :func:`shear_frame` record (:func:`modal_record`,
    every mode damped ``zeta``, of unit modal variance) with its exact modes."""
    freqs, shapes = shear_frame(storeys, f1_hz)
    t, y = modal_record(duration_s, fs, [(f, zeta, 1.0) for f in freqs], shapes, snr_db, seed)
    return t, y, freqs, shapes
