# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""The identifiers' incremental window arithmetic equals the batch computation it replaces."""

import math

import numpy as np
import pytest
from scipy.signal import sosfiltfilt

from vib_estimator.core.correlations import CorrelationCascade, decimation_filter, zero_phase
from vib_estimator.core.ssi import ORDERS, hankel_svd, state_matrices
from vib_estimator.core.whittle import sdof_density


# ---- the direct computations the buffers are checked against
def correlation_matrices(y: np.ndarray, lags: int) -> np.ndarray:
    """Unbiased correlation matrices ``R_k[a, b] = sum_t y_a,t+k y_b,t / (N - k)``, k = 0 ..
    ``lags``, of the mean-removed columns of ``y`` (samples x channels), by FFT: (lags + 1,
    channels, channels)."""
    n = len(y)
    y = y - y.mean(axis=0)
    size = 1 << math.ceil(math.log2(n + lags + 1))
    spec = np.fft.rfft(y, size, axis=0).T  # channels x bins
    m = y.shape[1]
    a, b = np.triu_indices(m)
    # one inverse transform per pair a <= b: its start holds R_k[a, b], its end R_k[b, a]
    circ = np.fft.irfft(spec[a] * np.conj(spec[b]), size, axis=-1)
    r = np.empty((lags + 1, m, m))
    r[:, a, b] = circ[:, : lags + 1].T
    r[0, b, a] = circ[:, 0]
    r[1:, b, a] = circ[:, : -lags - 1 : -1].T
    return r / np.arange(n, n - lags - 1, -1)[:, None, None]


def halve(y: np.ndarray) -> np.ndarray:
    """``y`` (samples, or samples x channels) at half its rate: every second sample of its
    zero-phase (forwards and backwards) anti-alias filtering by ``decimation_filter``
    (``zero_phase``)."""
    return zero_phase(y)[::2]


@pytest.mark.parametrize('channels', [1, 3])
def test_sliding_lag_products_equal_the_batch_correlations(channels):
    # blocks of random length pushed, the window slid by random amounts (longer than what
    # stays, too), read at random: every read equals the FFT of the window
    rng = np.random.default_rng(channels)
    y = rng.standard_normal((40000, channels)) + 7.0  # an offset: the centring is exercised
    cascade = CorrelationCascade(40, channels)
    pos, reads = 0, 0
    for _ in range(150):
        k = int(rng.integers(1, 1500))
        cascade.push(y[pos : pos + k])
        pos += k
        cascade.keep_last(int(rng.integers(200, 7000)))
        if len(cascade.window(0)) > 41 and rng.random() < 0.4:
            ref = correlation_matrices(cascade.window(0), 40)
            got = cascade.correlations(0)
            np.testing.assert_allclose(got, ref, rtol=0, atol=1e-10 * np.abs(ref).max())
            reads += 1
    assert reads > 30
    one = CorrelationCascade.of(y[:5000, 0], 80)
    np.testing.assert_allclose(one.correlations(0), correlation_matrices(y[:5000, :1], 80))


def test_halved_levels_are_the_zero_phase_decimation():
    rng = np.random.default_rng(5)
    y = rng.standard_normal((9001, 2))
    sos = decimation_filter().sos
    assert np.array_equal(halve(y), sosfiltfilt(sos, y, axis=0)[::2])
    assert np.array_equal(halve(y[:, 0]), sosfiltfilt(sos, y[:, 0])[::2])
    cascade = CorrelationCascade.of(y, 10)
    twice = sosfiltfilt(sos, sosfiltfilt(sos, y, axis=0)[::2], axis=0)[::2]
    np.testing.assert_array_equal(cascade.window(2), twice)
    np.testing.assert_allclose(cascade.correlations(2), correlation_matrices(twice, 10))
    assert [cascade.samples(j) for j in range(4)] == [9001, 4501, 2251, 1126]
    assert cascade.can_halve(2) and not cascade.can_halve(3)  # MIN_SAMPLES = 800


@pytest.mark.parametrize('m', [1, 6])
def test_state_matrices_and_svd_equal_least_squares_and_lapack(m):
    rng = np.random.default_rng(m)
    size = 40 if m == 1 else 96
    h = rng.standard_normal((size, size))
    h = h @ np.diag(np.logspace(0, -3, size)) @ rng.standard_normal((size, size))
    u, s, vt = hankel_svd(h, max(ORDERS), m)
    u0, s0, vt0 = np.linalg.svd(h)
    np.testing.assert_allclose(s, s0[: len(s)], rtol=1e-8)
    sign = np.sign(np.sum(u * u0[:, : len(s)], axis=0))
    np.testing.assert_allclose(u * sign, u0[:, : len(s)], atol=1e-7)
    np.testing.assert_allclose(vt * sign[:, None], vt0[: len(s), :m], atol=1e-7)
    for order, a in zip(ORDERS, state_matrices(u0, s0, m, ORDERS)):
        obs = u0[:, :order] * np.sqrt(s0[:order])
        ref = np.linalg.lstsq(obs[:-m], obs[m:], rcond=None)[0]
        np.testing.assert_allclose(a, ref, atol=1e-10 * np.abs(ref).max())


def test_sdof_density_in_real_arithmetic_is_the_complex_closed_form():
    w = np.linspace(1e-3, math.pi, 2001)
    for f, zeta, var, dt in ((5.0, 0.01, 1.0, 1 / 500), (23.0, 0.005, 0.2, 1 / 62.5)):
        wn = 2 * math.pi * f * dt
        root = math.sqrt(1 - zeta**2)
        z = math.exp(-zeta * wn) * complex(math.cos(wn * root), math.sin(wn * root))
        a = var * complex(1.0, -zeta / root)
        e = np.exp(-1j * w)
        total = a * (1 / (1 - z * e) + 1 / (1 - z / e) - 1)
        total += a.conjugate() * (1 / (1 - z.conjugate() * e) + 1 / (1 - z.conjugate() / e) - 1)
        np.testing.assert_allclose(
            sdof_density(np.cos(w), f, zeta, var, dt), 0.5 * total.real, rtol=1e-7
        )


@pytest.mark.parametrize('channels', [1, 2])
def test_halved_windows_kept_across_analyses_equal_the_whole_windows(channels):
    # pushes of a second or so (odd counts too: the halved grids move), slides, reads of every
    # level: each equals halve() applied to the window from scratch, to rounding, and so do its
    # correlations (several channels: from the lag products updated at the moved ends)
    rng = np.random.default_rng(10 + channels)
    y = rng.standard_normal((60000, channels)) + 3.0
    cascade = CorrelationCascade(16, channels)
    pos, reads = 0, 0
    for step in range(60):
        k = int(rng.integers(1, 700)) if step % 7 == 3 else 500
        cascade.push(y[pos : pos + k])
        pos += k
        cascade.keep_last(12000)
        ref = cascade.window(0)
        for level in range(1, 5):
            ref = halve(ref)
            if rng.random() < 0.7:
                np.testing.assert_allclose(
                    cascade.window(level), ref, rtol=0, atol=1e-12 * np.abs(ref).max()
                )
                r = correlation_matrices(ref, 16)
                np.testing.assert_allclose(
                    cascade.correlations(level), r, rtol=0, atol=1e-11 * np.abs(r).max()
                )
                reads += 1
    assert reads > 100


def test_flat_channels_of_several_from_the_lag_products():
    # a channel constant over the window after a step (far from the products' offset), one at
    # 0, one of gravity plus rounding-sized noise, one moving: the window's own test
    rng = np.random.default_rng(4)
    n = 6000
    y = np.column_stack(
        (
            np.r_[np.full(n, 100.0), np.full(n, 3.0)],
            np.zeros(2 * n),
            9.81 + 1e-14 * rng.standard_normal(2 * n),
            rng.standard_normal(2 * n),
        )
    )
    cascade = CorrelationCascade(10, 4)
    for i in range(0, 2 * n, 500):
        cascade.push(y[i : i + 500])
        cascade.keep_last(4000)
    w = cascade.window(0)
    expect = np.var(w, axis=0) <= (1e-12 * np.mean(w, axis=0)) ** 2
    assert expect.tolist() == [True, True, True, False]
    assert cascade.flat().tolist() == expect.tolist()
    np.testing.assert_allclose(cascade.variance(), np.var(w, axis=0), rtol=1e-9, atol=1e-20)
