# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""The Whittle likelihood of noise-driven modes: the model density, the refinement of a mode's
frequency to the likelihood's maximum, and the bound (the likelihood's Fisher information).

The output-only identifier's model of a window of one channel (:mod:`.ssi`, :mod:`.ambient`): a sum
of white-noise-driven single-degree-of-freedom modes (frequency, damping ratio, variance) plus
white measurement noise. For a stationary Gaussian series of ``N`` samples, the Whittle
log-likelihood over the Fourier frequencies ``w_j = 2 pi j / N`` is
``-sum_j (ln S(w_j) + I(w_j) / S(w_j))`` (``I`` the periodogram, ``S`` the model density; P.
Whittle, "Estimation and information in stationary time series", Arkiv for Matematik 2 (1953)
423-434); its maximum is asymptotically efficient, and its Fisher information
``F_ij = sum_j d_i ln S(w_j) d_j ln S(w_j)`` is the asymptotic Cramer-Rao bound of the parameters
(P. J. Brockwell, R. A. Davis, *Time Series: Theory and Methods*, 2nd ed., Springer 1991,
section 10.8).

In this module's order:

1. **The model density**: :func:`sdof_density`, each mode's in closed form; :func:`peak_ratio`, a
   mode's peak over the noise.
2. **The frequency refinement** (:func:`whittle_frequencies`): each identified mode's frequency
   moved to the likelihood's maximum near it, the other parameters kept (SSI-cov's frequencies are
   consistent but not efficient: 1.1-1.9x the bound, the refined ones 1.0-1.4x;
   ``benchmarks/bench_operation.py``).
3. **The bound** (:func:`whittle_fisher`, :func:`whittle_std`): the standard deviations of each
   mode's frequency and damping ratio over a window's samples.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Sequence

import numpy as np

from .jit import jit

#: the Whittle refinement of a mode's frequency (:func:`whittle_frequencies`) reads the
#: periodogram within this many half-power half-widths (``zeta f``) of it ...
WHITTLE_SPAN = 15.0
#: ... and at most this fraction of the way to the nearest other mode (measured,
#: bench_operation's records, 6 seeds, RMS error / Whittle bound: 3 half-widths 1.10-1.60,
#: 8 1.12-1.49, 15 1.07-1.71 (the close pair's 8 Hz: the neighbour's peak inside), 15 and half
#: the gap 1.02-1.43; the SSI frequencies alone 1.11-1.91)
WHITTLE_GAP = 0.5
#: ... and only when its half-power half-width spans at least this many Fourier bins of the
#: window (``zeta f T``): a narrower peak is shaped by the window's leakage (the bins are not
#: independent there), and the refinement moved the driven arm's 1.33 Hz (zeta ~0.6 %, 20-30 s
#: windows: 0.2-0.25 bins) by 0.3 % (median error 0.30 -> 0.60 %, 10 seeds)
WHITTLE_MIN_BINS = 0.5
#: ... moving it by at most this many of its (Whittle) stds: a mode whose SSI damping is too
#: high reads a wide band, where a coloured excitation (the randomly driven arm's motor command)
#: shapes the density; unbounded, 3 of its 1371 estimates moved beyond 5 %
WHITTLE_REACH = 4.0
#: ... and only for a mode whose SSI damping ratio is at most this: the randomly driven arm's
#: 1.33 Hz mode (zeta ~0.6 %) reads 2.5-6 % in a few windows, whose density over the wide band
#: is the coloured excitation's more than an SDOF's; refined, they moved up by 1-5 % (1 of
#: 1367 estimates beyond 5 %, 97.2 % within 2 % against 98.4 % unrefined)
WHITTLE_MAX_DAMPING = 0.025
#: a frequency bin counts in the Fisher information of the modes where their density exceeds this
#: fraction of the noise's
ACTIVE = 1e-2


# ---- 1. the model density -----------------------------------------------------------------------
def sdof_density(
    c: np.ndarray, frequency_hz: float, zeta: float, variance: float, dt: float
) -> np.ndarray:
    """Spectral density at ``w`` (rad/sample; normalised so that its mean over a period is the
    variance), given as ``c = cos w``, of a white-noise-driven SDOF's response sampled every
    ``dt``: the DTFT of its autocovariance ``c_k = variance e^(-zeta wn |k| dt) (cos wd k dt +
    zeta / sqrt(1 - zeta^2) sin wd |k| dt)``, summed in closed form (``c_k = Re(a z^|k|)``, ``z =
    e^((-zeta wn + i wd) dt)``: ``Re(a (1 - z^2) / (1 - 2 z cos w + z^2))``), in real
    arithmetic (:func:`density_at`, compiled)."""
    c = np.asarray(c, dtype=np.float64)
    out = np.empty(c.shape)
    terms = _density_terms(frequency_hz, zeta, variance, dt)
    density_row(np.ascontiguousarray(c.reshape(-1)), terms, out.reshape(-1))  # (one layout)
    return out


def _density_terms(frequency_hz: float, zeta: float, variance: float, dt: float) -> tuple:
    """:func:`sdof_density`'s six scalars: with ``z`` and ``a (1 - z^2)`` as there, the real
    parts of ``1 + z^2`` and of ``2 z``, their imaginary parts, and those of ``a (1 - z^2)``."""
    wn = 2 * math.pi * frequency_hz * dt
    root = math.sqrt(max(1.0 - zeta * zeta, 1e-12))
    decay = math.exp(-zeta * wn)
    z = complex(decay * math.cos(wn * root), decay * math.sin(wn * root))
    num = variance * complex(1.0, -zeta / root) * (1.0 - z * z)
    zz = 1.0 + z * z
    return zz.real, 2.0 * z.real, zz.imag, 2.0 * z.imag, num.real, num.imag


@jit(inline='always')
def density_at(c, terms):
    """:func:`sdof_density` at one ``c = cos w`` from its :func:`_density_terms` ``terms``:
    ``Re(a (1 - z^2) / (1 + z^2 - 2 z c))`` in real arithmetic, the one place of its
    arithmetic (compiled without ``fastmath``: IEEE operations in this order, the floats of
    the same expression over numpy arrays)."""
    zz_re, z2_re, zz_im, z2_im, num_re, num_im = terms
    dr = zz_re - z2_re * c
    di = zz_im - z2_im * c
    return (num_re * dr + num_im * di) / (dr * dr + di * di)


@jit(error_model='numpy')  # (a division by zero gives numpy's inf or nan, not an error)
def density_row(c, terms, out) -> None:
    """:func:`density_at` of each entry of ``c`` into ``out``."""
    for i in range(len(c)):
        out[i] = density_at(c[i], terms)


def peak_ratio(
    frequency_hz: float, zeta: float, variance: float, noise_var: float, dt: float
) -> float:
    """A mode's spectral density at its frequency over the white noise's (:func:`sdof_density`)."""
    c = np.cos(np.array([2 * math.pi * frequency_hz * dt]))
    return float(sdof_density(c, frequency_hz, zeta, variance, dt)[0]) / noise_var


# ---- 2. the frequency refinement ---------------------------------------------------------------
def _rank_one(c, spec, modes, shapes, noise, k, dt, n) -> tuple[np.ndarray, np.ndarray]:
    """For mode ``k`` at the bins ``c = cos w`` (``spec``: their Fourier coefficients, bins x
    channels; ``n``: the window's samples): ``a = phi^T R^-1 phi`` and ``b = |(R^-1 phi)^T X|^2 /
    n`` of :func:`whittle_frequencies`, ``R`` the noise's diagonal and the other modes' terms."""
    n_bins, m = spec.shape
    rest = np.zeros((n_bins, m, m))
    rest[:, np.arange(m), np.arange(m)] = noise
    for j, (fj, zj, vj) in enumerate(modes[:, :3]):
        if j != k:
            psi = sdof_density(c, fj, zj, max(vj, 1e-300), dt)
            rest += psi[:, None, None] * np.outer(shapes[j], shapes[j])[None]
    phi = shapes[k]
    if m == 1:  # (R^-1 phi without a LAPACK call)
        u = phi / rest[:, 0]
    else:
        u = np.linalg.solve(rest, np.broadcast_to(phi, (n_bins, m))[..., None])[..., 0]
    proj = np.sum(u * spec, axis=1)
    return u @ phi, (proj.real**2 + proj.imag**2) / n


@jit(error_model='numpy')  # (a division by zero gives numpy's inf or nan, not an error)
def likelihood_terms(c, terms, a, b, gain, rest) -> None:
    """The terms of :func:`whittle_frequencies`' likelihood at the bins ``c`` of a mode's
    density of :func:`_density_terms` ``terms``: ``gain = 1 + psi a`` and ``rest = b / (a
    gain)`` (their logarithm and sum left to numpy), in one pass: numpy's arithmetic of each
    bin in numpy's order, the same floats (the search calls it ~10 times a mode)."""
    for i in range(len(c)):
        g = 1.0 + density_at(c[i], terms) * a[i]
        gain[i] = g
        rest[i] = b[i] / (a[i] * g)


def whittle_frequencies(
    x: np.ndarray,
    fs: float,
    modes: np.ndarray,
    noise,
    stds: np.ndarray,
    shapes: np.ndarray | None = None,
) -> np.ndarray:
    """Each mode's frequency refined to the maximum of the Whittle likelihood of the window
    ``x`` (samples, or samples x channels, at ``fs``) near it, the other parameters kept
    (``modes``: rows of frequency, damping ratio, variance of the modal coordinate; ``noise``:
    each channel's white noise density at ``fs``, its variance there; ``stds``: the
    frequencies' stds, Hz; ``shapes``: each mode's real unit shape, modes x channels, one channel:
    1).

    The Whittle log-likelihood of a stationary Gaussian vector series over the Fourier frequencies
    ``w_j = 2 pi j / N`` is ``-sum_j (ln det S(w_j) + tr(S(w_j)^-1 I(w_j)))``, ``I`` the
    periodogram matrix ``X_j X_j^H / N`` (``X_j = sum_t (x_t - mean) e^(-i w_j t)``) and ``S`` the
    model's spectral matrix: each mode's SDOF density (:func:`sdof_density`) times ``phi phi^T``,
    plus the noise's diagonal (one channel: ``-sum_j (ln S + I / S)``). Maximised over one mode's
    frequency at a time, the bins within :data:`WHITTLE_SPAN` half-power half-widths (``zeta f``)
    of it and at most :data:`WHITTLE_GAP` of the way to the nearest other mode, the others at their
    SSI values, within :data:`WHITTLE_REACH` of the mode's std of the SSI frequency. With ``R`` the
    rest of ``S`` and ``psi`` the mode's density, ``S = R + psi phi phi^T`` is a rank-one update:
    ``ln det S = ln det R + ln(1 + psi a)`` and ``tr(S^-1 I) = tr(R^-1 I) - psi b / (1 + psi a)``
    (``a = phi^T R^-1 phi``, ``b = |(R^-1 phi)^T X|^2 / N``), so the search costs per bin what one
    channel's does.
    SSI-cov's frequencies are consistent but not efficient (1.1-1.9x the Whittle bound,
    ``benchmarks/bench_operation.py``); the likelihood's maximum is (asymptotically) at the
    bound. The damping is left to SSI: the periodogram's leakage (the window's Fejer kernel)
    widens the peak, which biases a likelihood estimate of the damping up but, being
    symmetric, not the frequency."""
    from scipy.optimize import minimize_scalar

    x = np.asarray(x, dtype=np.float64).reshape(len(x), -1)
    n, m = x.shape
    shapes = np.ones((len(modes), m)) if shapes is None else np.asarray(shapes, dtype=np.float64)
    noise = np.broadcast_to(np.asarray(noise, dtype=np.float64), (m,))
    spectrum = np.fft.rfft(x - x.mean(axis=0), axis=0)  # bins x channels
    w = 2 * math.pi * np.arange(len(spectrum)) / n
    hz = w * fs / (2 * math.pi)
    dt = 1.0 / fs
    out = modes[:, 0].copy()
    for k in range(len(modes)):
        f, zeta, variance = modes[k, :3]
        if zeta * f * n / fs < WHITTLE_MIN_BINS or zeta > WHITTLE_MAX_DAMPING:
            continue  # a peak narrower than the bins (their leakage shapes it), or a wide one
        others = np.delete(modes[:, 0], k)
        gap = float(np.min(np.abs(others - f))) if len(others) else math.inf
        half = max(min(WHITTLE_SPAN * zeta * f, WHITTLE_GAP * gap), 2 * fs / n)
        near = np.abs(hz - f) <= half
        reach = min(half / 2, WHITTLE_REACH * float(stds[k]))
        if np.count_nonzero(near) < 3:
            continue
        c = np.cos(w[near])
        a, b = _rank_one(c, spectrum[near], modes, shapes, noise, k, dt, n)
        gain, rest = np.empty(len(c)), np.empty(len(c))

        def negative_log_likelihood(fk, zeta=zeta, variance=max(variance, 1e-300)):
            terms = _density_terms(fk, zeta, variance, dt)
            likelihood_terms(c, terms, a, b, gain, rest)
            return float(np.sum(np.log(gain) + rest))

        best = minimize_scalar(
            negative_log_likelihood,
            bounds=(f - reach, f + reach),
            method='bounded',
            options={'xatol': 1e-7 * f},
        )
        if np.isfinite(best.x):
            out[k] = float(best.x)
    return out


# ---- 3. the bound ------------------------------------------------------------------------------
def _active_bins(modes, noise_var: float, dt: float, n: int) -> np.ndarray:
    """The Fourier bins 0 < k < n/2 near enough a mode for its density to exceed :data:`ACTIVE`
    of the noise's (a Lorentzian of the mode's peak and half-width bounds the distance)."""
    keep = np.zeros((n + 1) // 2, dtype=bool)
    for f, z, v in modes:
        centre = f * dt * n
        peak = peak_ratio(f, z, v, noise_var, dt)
        half = z * f * dt * n * math.sqrt(max(peak / ACTIVE, 1.0)) + 2.0
        keep[max(1, int(centre - half)) : max(1, min(len(keep), int(centre + half) + 2))] = True
    keep[0] = False
    return np.flatnonzero(keep)


def _log_density_gradient(c: np.ndarray, modes, noise_var: float, dt: float):
    """The model's density ``S`` at ``c = cos w`` and the gradient of ``ln S`` with respect
    to (f, zeta, variance of each mode, the noise variance), one row each: f's and zeta's as
    central differences (steps of 1e-6 of each), computed by :func:`gradient_rows`."""
    terms, steps = [], []
    for f, z, v in modes:
        terms.append(_density_terms(f, z, v, dt))
        for i, x in enumerate((f, z)):
            h = 1e-6 * x
            hi = [f, z, v]
            lo = [f, z, v]
            hi[i] += h
            lo[i] -= h
            terms += [_density_terms(*hi, dt), _density_terms(*lo, dt)]
            steps.append(2 * h)
    grads = np.empty((3 * len(modes) + 1, len(c)))
    total = np.empty(len(c))
    variances = np.array([float(v) for _, _, v in modes])
    terms = np.array(terms).reshape(-1, 6)
    gradient_rows(c, terms, np.array(steps), variances, float(noise_var), grads, total)
    return total, grads


@jit(error_model='numpy')  # (a division by zero gives numpy's inf or nan, not an error)
def gradient_rows(c, terms, steps, variances, noise_var, grads, total) -> None:
    """:func:`_log_density_gradient`'s rows into ``grads`` and ``S`` into ``total``, from the
    :func:`_density_terms` of each mode and of its four steps (``terms``: five rows a mode: the
    mode, f up, f down, zeta up, zeta down; ``steps``: each mode's two central differences'
    widths): numpy's arithmetic of each bin in numpy's order (the same floats as
    :func:`sdof_density` and the differences in array operations), without their passes over
    the bins (two thirds of the bound's time)."""
    n, k = len(c), len(variances)
    dens = np.empty((5 * k, n))
    for r in range(5 * k):
        density_row(c, terms[r], dens[r])
    for i in range(n):
        s = 0.0 if k == 0 else dens[0, i]
        for j in range(1, k):
            s = s + dens[5 * j, i]
        total[i] = noise_var + s
    for j in range(k):
        d = dens[5 * j : 5 * j + 5]
        for i in range(n):
            grads[3 * j, i] = (d[1, i] - d[2, i]) / steps[2 * j] / total[i]
            grads[3 * j + 1, i] = (d[3, i] - d[4, i]) / steps[2 * j + 1] / total[i]
            grads[3 * j + 2, i] = d[0, i] / variances[j] / total[i]
    for i in range(n):
        grads[3 * k, i] = 1.0 / total[i]


def load_kernels() -> None:
    """:func:`sdof_density`'s kernel, :func:`gradient_rows` and :func:`likelihood_terms`
    compiled (or loaded from numba's cache) now: an identifier built ahead of its first
    analysis pays it there, as :class:`.correlations.CorrelationCascade` its filter's."""
    _log_density_gradient(np.zeros(1), [(1.0, 0.01, 1.0)], 1.0, 0.01)
    sdof_density(np.zeros(1), 1.0, 0.01, 1.0, 0.01)
    one = np.ones(1)
    likelihood_terms(one, _density_terms(1.0, 0.01, 1.0, 0.01), one, one, one.copy(), one.copy())


@functools.lru_cache(maxsize=16)
def fourier_cosines(n: int) -> np.ndarray:
    """``cos w_k`` of the Fourier frequencies ``w_k = 2 pi k / n``, 0 <= k < (n + 1) / 2, of
    ``n`` samples (the windows' counts repeat from one analysis to the next)."""
    out = np.cos(2 * math.pi * np.arange((n + 1) // 2) / n)
    out.flags.writeable = False
    return out


def whittle_fisher(
    modes: Sequence[tuple[float, float, float]], noise_var: float, fs: float, n: int
) -> np.ndarray:
    """Fisher information of the Whittle likelihood of ``n`` samples at ``fs`` of a sum of
    noise-driven SDOFs ``modes`` = [(frequency Hz, damping ratio, variance)] plus white noise of
    variance ``noise_var``: ``F_ij = sum_k d_i ln S(w_k) d_j ln S(w_k)`` over the Fourier
    frequencies 0 < w_k < pi (parameters: f, zeta, variance of each mode, then the noise's).

    Bins where the modes' density is below :data:`ACTIVE` of the noise's carry (to that
    precision) information on the noise level only, and are counted as such."""
    dt = 1.0 / fs
    bins = _active_bins(modes, noise_var, dt, n)
    _, d = _log_density_gradient(fourier_cosines(n)[bins], modes, noise_var, dt)
    fisher = d @ d.T
    fisher[-1, -1] += ((n + 1) // 2 - 1 - len(bins)) / noise_var**2
    return fisher


def whittle_std(
    modes: Sequence[tuple[float, float, float]], noise_var: float, fs: float, n: int
) -> list[tuple[float, float]]:
    """The Whittle (asymptotic Cramer-Rao) bound of each mode's frequency (Hz) and damping ratio,
    as standard deviations, over ``n`` samples (see :func:`whittle_fisher`); NaN if singular."""
    if not modes:
        return []
    fisher = whittle_fisher(modes, noise_var, fs, n)
    try:
        cov = np.linalg.inv(fisher)
    except np.linalg.LinAlgError:
        return [(math.nan, math.nan)] * len(modes)
    var = np.diag(cov)
    return [
        (
            math.sqrt(var[3 * j]) if var[3 * j] > 0 else math.nan,
            math.sqrt(var[3 * j + 1]) if var[3 * j + 1] > 0 else math.nan,
        )
        for j in range(len(modes))
    ]
