# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""Output-only (operational, ambient) identification of the modes of a driven structure.

``excitation = ambient``: the structure is driven by broadband, unmeasured forces (wind, traffic, a
robot that never rests), so there is no free decay to fit. Its modes are identified from the
correlation structure of the response over a sliding window, as operational modal analysis does.

Interface (that of :class:`~vib_estimator.core.FrequencyEstimator` and the mode tracker, which the
node stream and ``analyze`` use): :class:`AmbientEstimator` ``.update(t, y) -> List[Estimate]``,
``.process(t, y) -> EstimateArrays``, ``.counters``, ``.reset()``, ``.restart()``, ``.config``.

Method, per analysis (every :data:`HOP_S` of input once ``ambient_window_s`` of samples are in):

1. **Covariance-driven stochastic subspace identification** (SSI-cov; Peeters & De Roeck 1999) of
   the last ``ambient_window_s`` seconds: the output correlations ``R_k`` (k = 0 .. 2 p,
   unbiased; at the input rate kept up to date as samples arrive, at a halved rate from the
   window's halving, whose unmoved middle is kept, with several channels its lag products too:
   :class:`CorrelationCascade`, :class:`EditedProducts`), their block
   Hankel matrix ``H = [R_{i+j+1}]`` (p = :data:`BLOCK_ROWS` rows), its
   SVD ``H = U S V^T``; at each model order n = :data:`ORDERS` the observability matrix
   ``O = U_n S_n^1/2``, the state matrix ``A = O_up^+ O_down`` and the output/next-state
   covariance ``G`` (first column of ``S_n^1/2 V_n^T``). Each eigenvalue ``lambda`` of ``A`` gives
   a pole ``s = ln(lambda) fs``: frequency ``|s| / 2 pi``, damping ratio ``-Re s / |s|``, and, from
   the modal decomposition ``R_k = sum_m c_m g_m lambda_m^(k-1)``, the mode's share of the
   variance.
2. **Physical or spurious** (automated OMA): poles with a damping ratio outside
   (0, ``max_damping``], or above 0.45 fs (or outside ``band_hz`` when set), are dropped
   (``rejected_damping``); the others are clustered in frequency (neighbours within
   :data:`CLUSTER_TOL`, a cluster no wider than :data:`CLUSTER_SPAN`); a cluster is a mode when it
   holds a pole at :data:`MIN_SUPPORT` of the orders (stable across model orders; else
   ``rejected_unstable``). Its frequency, damping and variance are the medians over its poles;
   the frequency is then refined to the maximum of the Whittle likelihood of the window's
   periodogram near the mode, the other parameters kept (:func:`whittle_frequencies`: SSI-cov's
   frequencies are 1.1-1.9x the bound, the refined ones 1.0-1.4x).
3. **Standard deviations** from the window's own statistics: the inverse Fisher information of the
   Whittle likelihood (:func:`whittle_std`) of the identified model -- every mode a noise-driven
   SDOF with the estimated frequency, damping and variance, plus white measurement noise of the
   variance left over (``R_0`` minus the modes') -- over the window's samples, scaled up by the
   factor the mode's own estimates from non-overlapping earlier windows show it to be too small
   (variance across windows: :meth:`_Track.calibration`). SSI-cov attains this
   bound within the measured factor of ``benchmarks/bench_operation.py``; a mode whose relative
   frequency std exceeds :data:`MAX_STD_REL` is too weak to tell (``rejected_uncertain``). A
   window constant to rounding (:meth:`CorrelationCascade.flat`) holds no vibration: it is not
   identified (``flat_windows``); its halvings would hold only the filter's rounding.
4. **Identity over time** (stability across windows): each mode is matched to the nearest tracked
   mode within :data:`MATCH_TOL`; a new one publishes once seen by :data:`CONFIRM` consecutive
   analyses (:data:`CONFIRM_BESIDE` beside published modes; ``modes_found``), a published one
   whenever seen; one unseen for a window is lost (``modes_lost``). With
   ``modes`` >= 1 at most that many (the strongest) publish. Published modes are numbered by
   ascending frequency, 1 = the lowest, as the mode tracker's ``mode`` key.

Each estimate: ``t`` = the window's last stamp, ``convergence_time`` = the window's span (the
window used), ``samples`` = its samples, ``amplitude`` = RMS of the modal response, ``fit`` = share
of the window's variance the modes explain.

Bad samples never raise: non-finite values, duplicate and out-of-order stamps are skipped and
counted; a gap or a backward jump longer than ``max_gap`` starts a new window (``gap_resets``,
``time_jump_resets``); the tracked modes are kept.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from .config import EstimatorConfig
from .estimator import INPUT_COUNTERS, Estimate, EstimateArrays, Estimator, as_series
from .jit import jit
from .threads import single_blas_thread

#: seconds of input between two analyses (the estimates' update period)
HOP_S = 1.0
#: block rows p of the correlation Hankel matrix (lags 1 .. 2p)
BLOCK_ROWS = 40
#: fewest samples a window must hold to be analysed (twice the lags, and two)
MIN_WINDOW_SAMPLES = 4 * BLOCK_ROWS + 2
#: model orders of the stabilisation diagram
ORDERS = tuple(range(4, 31, 4))
#: neighbouring poles within this relative frequency join one cluster
CLUSTER_TOL = 0.004
#: a cluster spans at most this relative frequency range
CLUSTER_SPAN = 0.02
#: fraction of the model orders at which a cluster must hold a pole to be a mode
MIN_SUPPORT = 0.5
#: a mode's spectral peak must stand this far above the noise's density (else ``rejected_weak``)
MIN_PEAK_RATIO = 4.0
#: a mode whose predicted relative frequency std exceeds this is not published
MAX_STD_REL = 0.02
#: a window's mode continues a tracked mode within this relative frequency
MATCH_TOL = 0.03
#: while modes are known, one analysis in this many searches the full rate for higher ones
SEARCH_EVERY = 5
#: a mode's estimates over this many windows calibrate its stds (:meth:`_Track.calibration`)
HISTORY_WINDOWS = 4
#: consecutive analyses that must see a new mode before it publishes, while none is published
CONFIRM = 3
#: ... and beside published modes: a coloured excitation's continuum (a randomly commanded arm's)
#: gives statistical poles beside a strong mode that last 1-8 analyses; a mode persists
CONFIRM_BESIDE = 8
#: most modes tracked at once
MAX_TRACKS = 8
#: a frequency bin counts in the Fisher information of the modes where their density exceeds this
#: fraction of the noise's
ACTIVE = 1e-2
#: highest pole frequency kept, in units of the sampling rate
NU_MAX = 0.45
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
#: the second pass's rate puts the highest mode of the first at or below this fraction of it
TOP_NU = 0.4
#: the decimated window holds at least this many samples
MIN_SAMPLES = 20 * BLOCK_ROWS
#: two clusters closer than this (relative) are one mode
MERGE_TOL = 0.02
#: a window whose RMS is at most this fraction of its mean's magnitude is constant to rounding
#: (float64 sums and filters of it carry ~1e-13 relative; a 24-bit ADC resolves 6e-8)
FLAT_RMS_REL = 1e-12
#: anti-alias filter of each halving of the rate: 8th order Butterworth at 0.45 of the Nyquist
#: frequency (run forwards and backwards: no phase, gain 0.96 at the owned band's top edge;
#: :func:`decimation_filter`)
DECIMATE_ORDER, DECIMATE_CUTOFF = 8, 0.45
#: a channel whose variance from the lag products is at most this fraction of its samples'
#: squared distance from zero or the products' offset may be flat: its window is read
#: (:meth:`CorrelationCascade.flat`; far above those products' rounding)
FLAT_SUSPECT = 1e-6

COUNTER_NAMES = INPUT_COUNTERS + (
    'analyses',
    'analyses_idle',
    'rejected_damping',
    'rejected_unstable',
    'rejected_weak',
    'rejected_uncertain',
    'flat_windows',
    'modes_found',
    'modes_lost',
    'estimates',
)


# ---- the bound and the standard deviations ------------------------------------------------------
def sdof_psd(
    w: np.ndarray, frequency_hz: float, zeta: float, variance: float, dt: float
) -> np.ndarray:
    """Spectral density at ``w`` (rad/sample; normalised so that its mean over a period is the
    variance) of a white-noise-driven SDOF's response sampled every ``dt``: the DTFT of its
    autocovariance ``c_k = variance e^(-zeta wn |k| dt) (cos wd k dt + zeta / sqrt(1 - zeta^2)
    sin wd |k| dt)``, summed in closed form (``c_k = Re(a z^|k|)``, ``z = e^((-zeta wn + i wd)
    dt)``: ``Re(a (1 - z^2) / (1 - 2 z cos w + z^2))``)."""
    return _sdof_psd(np.cos(np.asarray(w, dtype=np.float64)), frequency_hz, zeta, variance, dt)


def _sdof_psd(
    c: np.ndarray, frequency_hz: float, zeta: float, variance: float, dt: float
) -> np.ndarray:
    """:func:`sdof_psd` at ``c = cos w``, in real arithmetic."""
    wn = 2 * math.pi * frequency_hz * dt
    root = math.sqrt(max(1.0 - zeta * zeta, 1e-12))
    decay = math.exp(-zeta * wn)
    z = complex(decay * math.cos(wn * root), decay * math.sin(wn * root))
    num = variance * complex(1.0, -zeta / root) * (1.0 - z * z)
    zz = 1.0 + z * z
    dr = zz.real - 2.0 * z.real * c
    di = zz.imag - 2.0 * z.imag * c
    return (num.real * dr + num.imag * di) / (dr * dr + di * di)


def peak_ratio(
    frequency_hz: float, zeta: float, variance: float, noise_var: float, dt: float
) -> float:
    """A mode's spectral density at its frequency over the white noise's (:func:`sdof_psd`)."""
    w = 2 * math.pi * frequency_hz * dt
    return float(sdof_psd(np.array([w]), frequency_hz, zeta, variance, dt)[0]) / noise_var


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
    to (f, zeta, variance of each mode, the noise variance), one row each."""
    density = _sdof_psd
    parts = [density(c, f, z, v, dt) for f, z, v in modes]
    total = noise_var + (np.sum(parts, axis=0) if parts else 0.0)
    grads = []
    for (f, z, v), part in zip(modes, parts):
        for i, x in enumerate((f, z)):
            h = 1e-6 * x
            hi = [f, z, v]
            lo = [f, z, v]
            hi[i] += h
            lo[i] -= h
            grads.append((density(c, *hi, dt) - density(c, *lo, dt)) / (2 * h))
        grads.append(part / v)
    grads.append(np.ones(len(c)))
    return total, np.array(grads) / total


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


# ---- one window ---------------------------------------------------------------------------------
def correlations(y: np.ndarray, lags: int) -> np.ndarray:
    """Unbiased output correlations ``R_k = sum_t y_t+k y_t / (N - k)``, k = 0 .. ``lags``, of the
    mean-removed ``y`` (by FFT)."""
    n = len(y)
    y = y - y.mean()
    size = 1 << math.ceil(math.log2(n + lags + 1))
    spec = np.fft.rfft(y, size)
    r = np.fft.irfft(spec * np.conj(spec), size)[: lags + 1]
    return r / np.arange(n, n - lags - 1, -1)


@dataclass(frozen=True)
class DecimationFilter:
    """The anti-alias filter of each halving of the rate (:data:`DECIMATE_ORDER`,
    :data:`DECIMATE_CUTOFF`) as second-order sections ``sos``; ``zi``: its steady state for a unit
    input; ``pad``: the samples a zero-phase pass extends the signal by at each end (odd
    extension), those of ``scipy.signal.sosfiltfilt``; ``settle``: the samples over which its
    response has decayed below 1e-20 of its start (its slowest pole's radius r: r^n < 1e-20),
    plus ``pad``."""

    sos: np.ndarray
    zi: np.ndarray
    pad: int
    settle: int


@functools.lru_cache(maxsize=None)
def decimation_filter() -> DecimationFilter:
    """The :class:`DecimationFilter`, designed on first use: ``scipy.signal`` takes a second or
    more to import, which a node or a command that never runs this identifier should not pay at
    its start."""
    from scipy.signal import butter, sos2zpk, sosfilt_zi

    sos = butter(DECIMATE_ORDER, DECIMATE_CUTOFF, output='sos')
    pad = 3 * (2 * len(sos) + 1 - min(int(np.sum(sos[:, 2] == 0)), int(np.sum(sos[:, 5] == 0))))
    radius = float(np.max(np.abs(sos2zpk(sos)[1])))
    settle = math.ceil(-20.0 / math.log10(radius)) + pad
    return DecimationFilter(sos, sosfilt_zi(sos), pad, settle)


#: a :class:`LagProducts` recomputes its sums from its window after this many slides (bounds the
#: rounding of the updates; the sums are otherwise exact)
REFRESH_SLIDES = 64
#: rows of a block of lag products computed at once
PRODUCT_BLOCK = 2048


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


def later_products(y, a, b, lo, off, sums, total, subtract=False) -> None:
    """Add to ``sums`` (lag k, channel a, channel b) the products ``x[t] x[t - k]^T`` of the
    rows ``x = y - off`` for a <= t < b and lo <= t - k (k = 0 .. ``len(sums) - 1``), to
    ``total`` the rows a <= t < b (both subtracted instead with ``subtract``)."""
    lags, m = len(sums) - 1, y.shape[1]
    for a0 in range(a, b, PRODUCT_BLOCK):
        b0 = min(b, a0 + PRODUCT_BLOCK)
        lo0 = max(lo, a0 - lags)
        ext = np.zeros((b0 - a0 + lags, m))
        ext[lags - (a0 - lo0) :] = y[lo0:b0] - off
        new = ext[lags:]
        view = np.lib.stride_tricks.sliding_window_view(ext, lags + 1, axis=0)
        # view[i, :, q] = ext[i + q] = y[a0 + i - (lags - q)]: lag k = lags - q
        prod = np.tensordot(new, view, axes=(0, 0))  # (a, b, q)
        if subtract:
            sums -= prod[:, :, ::-1].transpose(2, 0, 1)
            total -= new.sum(axis=0)
        else:
            sums += prod[:, :, ::-1].transpose(2, 0, 1)
            total += new.sum(axis=0)


def earlier_products(y, c, d, hi, off, sums, total, subtract=False) -> None:
    """Add to ``sums`` the products ``x[u + k] x[u]^T`` of the rows ``x = y - off`` for
    c <= u < d and u + k < hi, to ``total`` the rows c <= u < d (subtracted with
    ``subtract``)."""
    lags, m = len(sums) - 1, y.shape[1]
    for c0 in range(c, d, PRODUCT_BLOCK):
        d0 = min(d, c0 + PRODUCT_BLOCK)
        hi0 = min(hi, d0 + lags)
        ext = np.zeros((d0 - c0 + lags, m))
        ext[: hi0 - c0] = y[c0:hi0] - off
        old = ext[: d0 - c0]
        view = np.lib.stride_tricks.sliding_window_view(ext, lags + 1, axis=0)[: d0 - c0]
        # view[i, :, k] = y[c0 + i + k]
        prod = np.tensordot(old, view, axes=(0, 0))  # (b, a, k)
        if subtract:
            sums -= prod.transpose(2, 1, 0)
            total -= old.sum(axis=0)
        else:
            sums += prod.transpose(2, 1, 0)
            total += old.sum(axis=0)


def centred_correlations(sums, total, x, off) -> np.ndarray:
    """The unbiased correlation matrices of the mean-removed window ``x`` (rows) from its lag
    products ``sums`` and sum ``total`` of ``x - off`` (:func:`later_products`)."""
    lags, n, m = len(sums) - 1, len(x), x.shape[1]
    first = np.concatenate((np.zeros((1, m)), np.cumsum(x[:lags] - off, 0)))
    last = np.concatenate((np.zeros((1, m)), np.cumsum(x[: -lags - 1 : -1] - off, 0)))
    mean = total / n
    count = np.arange(n, n - lags - 1, -1, dtype=np.float64)
    r = (
        sums
        - (total - first)[:, :, None] * mean[None, None, :]
        - mean[None, :, None] * (total - last)[:, None, :]
        + count[:, None, None] * np.outer(mean, mean)[None]
    )
    return r / count[:, None, None]


class LagProducts:
    """The lag products of a sliding window over a growing buffer of samples (one row of
    ``channels`` values each), kept exactly: when the correlations are read, the products of
    the samples pushed since are added, those of the samples that left are subtracted (or, after
    :data:`REFRESH_SLIDES` such slides or a slide longer than what stays, all recomputed from the
    window). :meth:`correlations` gives what :func:`correlation_matrices` computes from the
    window."""

    def __init__(self, lags: int, channels: int):
        self.lags, self.channels = lags, channels
        self._buf = np.empty((1 << 12, channels))
        self.clear()

    def clear(self) -> None:
        self._n = 0  # samples in the buffer
        self._want = 0  # the window's first sample
        self._start = 0  # the first sample of the stretch [start, done) the sums cover
        self._done = 0
        self._offset = np.zeros(self.channels)
        self._sums = np.zeros((self.lags + 1, self.channels, self.channels))
        self._total = np.zeros(self.channels)
        self._slides = 0

    def __len__(self) -> int:
        """The window's samples."""
        return self._n - self._want

    @property
    def window(self) -> np.ndarray:
        """The window's samples (a view)."""
        return self._buf[self._want : self._n]

    @property
    def offset(self) -> np.ndarray:
        """The value subtracted from the samples before their products are summed."""
        return self._offset

    def mean(self) -> np.ndarray:
        """The window's mean, from the sums kept."""
        self._sync()
        return self._offset + self._total / len(self)

    def push(self, x: np.ndarray) -> None:
        """Append samples ``x`` (rows) to the window."""
        m = len(x)
        if not m:
            return
        if self._n + m > len(self._buf):
            keep = self._n - self._start
            size = max(len(self._buf), 1 << math.ceil(math.log2(2 * (keep + m))))
            buf = np.empty((size, self.channels)) if size > len(self._buf) else self._buf
            buf[:keep] = self._buf[self._start : self._n]
            shift = self._start
            self._buf, self._n = buf, keep
            self._start, self._want, self._done = 0, self._want - shift, self._done - shift
        if self._n == self._want:
            self._offset = np.array(x[0], dtype=np.float64)  # keeps the products' rounding small
            self._restart()
        self._buf[self._n : self._n + m] = x
        self._n += m

    def keep_last(self, count: int) -> None:
        """Slide the window's start so that it holds the last ``count`` samples."""
        self._want = max(self._want, self._n - count)
        if self._want - self._start > self._n - self._want:
            self._restart()  # (bounds the buffer of a level seldom read)

    def _restart(self) -> None:
        """Drop the sums: the next read recomputes them from the window."""
        self._start = self._done = self._want
        self._sums[:] = 0.0
        self._total[:] = 0.0
        self._slides = 0

    def _sync(self) -> None:
        """Bring the sums to the window."""
        if self._want > self._start:
            if self._want >= self._done or self._slides >= REFRESH_SLIDES:
                self._restart()
            else:
                self._sub(self._start, self._want)
                self._start = self._want
                self._slides += 1
        if self._done < self._n:
            self._add(self._done, self._n)
            self._done = self._n

    def _add(self, a: int, b: int) -> None:
        """Add the products ``y[t] y[t - k]^T`` of the samples a <= t < b with the window's."""
        later_products(self._buf, a, b, self._start, self._offset, self._sums, self._total)

    def _sub(self, c: int, d: int) -> None:
        """Subtract the products ``y[u + k] y[u]^T`` of the samples c <= u < d leaving."""
        earlier_products(
            self._buf, c, d, self._done, self._offset, self._sums, self._total, subtract=True
        )

    def correlations(self) -> np.ndarray:
        """The window's unbiased correlation matrices of its mean-removed channels, ``R_k[a, b]
        = sum_t y_a,t+k y_b,t / (N - k)``, k = 0 .. ``lags``: (lags + 1, channels, channels)."""
        self._sync()
        return centred_correlations(self._sums, self._total, self.window, self._offset)


class EditedProducts:
    """The lag products of a halved window (:class:`CorrelationCascade`'s levels from 1), kept
    across analyses: the window's middle is the previous window's (the same numbers, shifted),
    only its first and last samples differ; the products of the pairs that involve them are
    subtracted (the previous window's) and added (this one's) instead of all recomputed (all,
    after :data:`REFRESH_SLIDES` such updates, or when the middle is not the previous one's).
    :meth:`correlations` gives what :func:`correlation_matrices` computes from the window."""

    def __init__(self, lags: int, channels: int):
        self._sums = np.zeros((lags + 1, channels, channels))
        self._total = np.zeros(channels)
        self._x: np.ndarray | None = None  # the window the sums are of
        self._pos = 0
        self._off = np.zeros(channels)
        self._updates = 0

    def correlations(self, x: np.ndarray, pos: int, step: int, head: int, tail: int):
        """The correlation matrices of window ``x`` (rows; its first sample at ``pos``, one
        every ``step``, input samples) whose first ``head`` and last ``tail`` samples may
        differ from the previous window's."""
        old, n = self._x, len(x)
        lo, hi = head, n - tail  # the middle of x, the previous window's
        shift = (pos - self._pos) // step
        if not (
            old is not None
            and self._updates < REFRESH_SLIDES
            and (pos - self._pos) % step == 0
            and 0 <= shift
            and lo < hi
            and hi + shift <= len(old)
            and np.array_equal(x[lo:hi], old[lo + shift : hi + shift])
        ):
            self._off = np.array(x[0], dtype=np.float64)
            self._sums[:] = 0.0
            self._total[:] = 0.0
            self._updates = 0
            later_products(x, 0, n, 0, self._off, self._sums, self._total)
        else:
            # the pairs with a sample outside the middle: the previous window's out, x's in
            sums, total, off, mid = self._sums, self._total, self._off, hi + shift
            later_products(old, mid, len(old), 0, off, sums, total, subtract=True)
            earlier_products(old, 0, lo + shift, mid, off, sums, total, subtract=True)
            earlier_products(x, 0, lo, hi, off, sums, total)
            later_products(x, hi, n, 0, off, sums, total)
            self._updates += 1
        self._x, self._pos = x, pos
        return centred_correlations(self._sums, self._total, x, self._off)


@jit
def sos_pass(sos: np.ndarray, x: np.ndarray, zi: np.ndarray) -> None:
    """``scipy.signal.sosfilt(sos, x, axis=0, zi=zi * x[0])`` in place on ``x`` (samples x
    channels; ``zi``: sections x 2, the steady state of a unit step): the cascade of second-order
    sections in direct form II transposed, scipy's arithmetic in scipy's order (the same floats;
    scipy's per-call checks and axis moves were a fifth of the identifier's time, 14 calls an
    analysis)."""
    n_sections = sos.shape[0]
    state = np.empty((n_sections, 2))
    for c in range(x.shape[1]):
        x0 = x[0, c]
        for k in range(n_sections):
            state[k, 0] = zi[k, 0] * x0
            state[k, 1] = zi[k, 1] * x0
        for i in range(x.shape[0]):
            cur = x[i, c]
            for k in range(n_sections):
                new = sos[k, 0] * cur + state[k, 0]
                state[k, 0] = sos[k, 1] * cur - sos[k, 4] * new + state[k, 1]
                state[k, 1] = sos[k, 2] * cur - sos[k, 5] * new
                cur = new
            x[i, c] = cur


def zero_phase(x: np.ndarray) -> np.ndarray:
    """``scipy.signal.sosfiltfilt(decimation_filter().sos, x, axis=0)``, its initial conditions
    computed once (:func:`sos_pass` forwards, then backwards)."""
    f = decimation_filter()
    pad = f.pad
    ext = np.concatenate((2 * x[0] - x[pad:0:-1], x, 2 * x[-1] - x[-2 : -pad - 2 : -1]))
    work = np.ascontiguousarray(ext.reshape(len(ext), -1))
    sos_pass(f.sos, work, f.zi)
    work = np.ascontiguousarray(work[::-1])
    sos_pass(f.sos, work, f.zi)
    return work[::-1][pad:-pad].reshape((-1,) + x.shape[1:])


def halve(y: np.ndarray) -> np.ndarray:
    """``y`` (samples, or samples x channels) at half its rate: every second sample of its
    zero-phase (forwards and backwards) anti-alias filtering by :func:`decimation_filter`
    (:func:`zero_phase`)."""
    return zero_phase(y)[::2]


class CorrelationCascade:
    """A sliding window's correlations at the input rate and at that rate halved 1, 2, ...
    times (level j: :func:`halve` applied j times to the window). The input rate's are kept up to
    date as samples arrive (:class:`LagProducts`: exact, without re-reading the window). A
    halved rate's window is made when first read after the window moved: the zero-phase
    filtering of a window depends on its ends only within ``decimation_filter().settle``
    samples of them, so
    its middle is kept from the previous analysis and only the stretches near the ends that
    moved are filtered again (the same numbers, to rounding, as :func:`halve` of the whole
    window: ``test/core/test_ambient_incremental.py``). With several channels a halved window's
    correlations come from its lag products, kept across analyses (:class:`EditedProducts`),
    and the window's variance from the input rate's (``R_0``); with one, from the FFT of the
    window and from the window (as before, bit for bit)."""

    def __init__(self, lags: int, channels: int):
        self.lags, self.channels = lags, channels
        self.levels = [LagProducts(lags, channels)]
        self._count = 0  # samples pushed since the last clear
        #: level -> (its input's first sample's position, step, its zero-phase filtering,
        #: the samples pushed by then)
        self._filtered: dict[int, tuple] = {}
        #: level (from 1, several channels) -> its window's lag products
        self._products: dict[int, EditedProducts] = {}
        self._moved()
        # scipy.signal imported and the zero-phase filter compiled (or loaded from numba's cache)
        # now, not at the first analysis
        zero_phase(np.zeros(2 * decimation_filter().pad))

    @classmethod
    def of(cls, y: np.ndarray, lags: int) -> 'CorrelationCascade':
        """The cascade of one window ``y`` (samples, or samples x channels)."""
        y = np.asarray(y, dtype=np.float64)
        out = cls(lags, 1 if y.ndim == 1 else y.shape[1])
        out.push(y.reshape(len(y), -1))
        return out

    def clear(self) -> None:
        self.levels[0].clear()
        self._count = 0
        self._filtered = {}
        self._products = {}
        self._moved()

    def _moved(self) -> None:
        # per level from 1: the window, the position (input samples) of its first sample, and
        # how many of its first and last samples may differ from the previous analysis's
        self._halved: list[tuple[np.ndarray, int, int, int]] = []
        self._corr: dict[int, np.ndarray] = {}

    def push(self, x: np.ndarray) -> None:
        """Append samples ``x`` (rows) at the input rate."""
        if len(x):
            self.levels[0].push(x)
            self._count += len(x)
            self._moved()

    def keep_last(self, count: int) -> None:
        """Slide the window: it holds the last ``count`` samples."""
        if count < len(self.levels[0]):
            self.levels[0].keep_last(count)
            self._moved()

    def _level(self, level: int) -> tuple[np.ndarray, int, int, int]:
        """Level ``level``'s (window, its first sample's position, samples at its start and at
        its end that may differ from the previous analysis's)."""
        if level == 0:
            x = self.levels[0].window
            prev = self._filtered.get(1)  # (the samples since level 1 was last made are new)
            new = len(x) if prev is None else min(len(x), self._count - prev[3])
            return x, self._count - len(x), 0, new
        while len(self._halved) < level:
            j = len(self._halved) + 1
            x, start, head, tail = self._level(j - 1)
            step = 1 << (j - 1)
            z, head, tail = self._filter(j, x, start, step, head, tail)
            self._halved.append((z[::2], start, (head + 1) // 2 + 1, (tail + 1) // 2 + 1))
        return self._halved[level - 1]

    def _filter(self, j, x, start, step, head, tail):
        """:func:`zero_phase` of level j - 1's window ``x``, its middle kept from the previous
        analysis where that is exact to rounding; with the counts of its first and last samples
        that may differ from that analysis's."""
        n, k = len(x), decimation_filter().settle
        prev = self._filtered.get(j)
        z = None
        if prev is not None and prev[1] == step and (start - prev[0]) % step == 0:
            shift = (start - prev[0]) // step
            old = prev[2]
            lo, hi = head + k, n - tail - k  # the middle [lo, hi) of x kept
            if shift >= 0 and lo + 2 * k <= hi and hi + shift <= len(old) - k:
                z = np.empty_like(x)
                z[:lo] = zero_phase(x[: lo + 2 * k])[:lo]
                z[lo:hi] = old[lo + shift : hi + shift]
                z[hi:] = zero_phase(x[hi - 2 * k :])[2 * k :]
                head, tail = lo, n - hi
        if z is None:
            z = zero_phase(x)
            head, tail = n, n
        self._filtered[j] = (start, step, z, self._count)
        return z, head, tail

    def window(self, level: int) -> np.ndarray:
        """The window at level ``level`` (samples x channels)."""
        return self._level(level)[0]

    def correlations(self, level: int) -> np.ndarray:
        """Level ``level``'s correlation matrices (as :func:`correlation_matrices`)."""
        if level not in self._corr:
            if level == 0:
                r = self.levels[0].correlations()
            elif self.channels == 1:
                r = correlations(self.window(level)[:, 0], self.lags)[:, None, None]
            else:  # (several channels: the lag products kept, not the FFT of the window)
                x, start, head, tail = self._level(level)
                products = self._products.setdefault(
                    level, EditedProducts(self.lags, self.channels)
                )
                r = products.correlations(x, start, 1 << level, head, tail)
            self._corr[level] = r
        return self._corr[level]

    def variance(self) -> np.ndarray:
        """Each channel's variance over the window (at the input rate): with several channels,
        from the lag products kept (``R_0``), not from the window."""
        if self.channels == 1:
            return np.var(self.levels[0].window, axis=0)
        return np.diagonal(self.correlations(0)[0]).copy()

    def flat(self) -> np.ndarray:
        """Each channel's window is constant to rounding: its RMS at most :data:`FLAT_RMS_REL`
        of its mean's magnitude (exactly constant if the mean is 0). With several channels, only
        those whose variance from the lag products (:meth:`variance`, rounding about 1e-16 of
        the square of the samples' distance from the products' offset) lies below
        :data:`FLAT_SUSPECT` of that square are read over the window."""
        w = self.levels[0].window
        if self.channels == 1:
            return np.var(w, axis=0) <= (FLAT_RMS_REL * np.mean(w, axis=0)) ** 2
        var = self.variance()
        mean, off = self.levels[0].mean(), self.levels[0].offset
        out = np.zeros(self.channels, dtype=bool)
        suspect = np.flatnonzero(var <= FLAT_SUSPECT * (mean**2 + (mean - off) ** 2))
        if len(suspect):
            x = w[:, suspect]
            out[suspect] = np.var(x, axis=0) <= (FLAT_RMS_REL * np.mean(x, axis=0)) ** 2
        return out

    def samples(self, level: int) -> int:
        """Level ``level``'s window samples."""
        n = len(self.levels[0])
        for _ in range(level):
            n = (n + 1) // 2
        return n

    def can_halve(self, level: int) -> bool:
        """Whether level ``level + 1`` keeps :data:`MIN_SAMPLES` in the window."""
        return self.samples(level) // 2 >= MIN_SAMPLES


def decimation_level(cascade: CorrelationCascade, fs: float, top_hz: float) -> int:
    """The level of the lowest rate fs / 2^j that keeps ``top_hz`` at or below :data:`TOP_NU`
    of it and :data:`MIN_SAMPLES` samples in the window."""
    j = 0
    while top_hz <= 0.5 * TOP_NU * fs / 2**j and cascade.can_halve(j):
        j += 1
    return j


def hankel_svd(h: np.ndarray, top: int, m: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The leading ``top`` singular values ``s`` of a (square) block Hankel matrix ``h``, their
    left singular vectors ``u`` and the first ``m`` columns of the right ones ``vt``, from the
    eigendecomposition of ``h h^T`` (a third of the cost of an SVD; the signal's singular values
    lie decades above the rounding of the squares)."""
    lam, vec = np.linalg.eigh(h @ h.T)
    lam, u = lam[::-1][:top], vec[:, ::-1][:, :top]
    s = np.sqrt(np.maximum(lam, 1e-30 * max(lam[0], 1e-300)))
    return u, s, (u.T @ h[:, :m]) / s[:, None]


def state_matrices(u: np.ndarray, s: np.ndarray, m: int, orders: Sequence[int]) -> list:
    """The state matrices ``A = O_up^+ O_down`` of each model order from the SVD ``u``, ``s`` of
    a block Hankel matrix of ``m`` rows a block (``O = U_n S_n^1/2``): with ``U``'s columns
    orthonormal, ``O_up^T O_up = S^1/2 (I - W^T W) S^1/2`` (``W``: the last block row of
    ``U_n``), so ``A = S^-1/2 (I + W^T (I - W W^T)^-1 W) U_up^T U_down S^1/2`` (Woodbury): one
    ``m x m`` solve per order. None for an order where that is singular."""
    top = max(orders)
    shift = u[:-m, :top].T @ u[m:, :top]
    eye = np.eye(m)
    out = []
    for order in orders:
        w = u[-m:, :order]
        b = shift[:order, :order]
        wb = w @ b
        if m == 1:  # (a scalar: no LAPACK call)
            gap = 1.0 - float(w[0] @ w[0])
            if gap <= 0.0:
                out.append(None)
                continue
            b = b + w.T @ (wb / gap)
        else:
            try:
                b = b + w.T @ np.linalg.solve(eye - w @ w.T, wb)
            except np.linalg.LinAlgError:
                out.append(None)
                continue
        root = np.sqrt(s[:order])
        out.append(b * (root[None, :] / root[:, None]))
    return out


def ssi_poles(
    r: np.ndarray, fs: float, rows: int = BLOCK_ROWS, orders: Sequence[int] = ORDERS
) -> list[np.ndarray]:
    """SSI-cov poles of correlations ``r`` at each model order: one array per order with a row
    (frequency Hz, damping ratio, variance of the mode) per complex pair (upper half plane)."""
    hankel = r[1 + np.add.outer(np.arange(rows), np.arange(rows))]
    u, s, vt = hankel_svd(hankel, max(orders), 1)
    out = []
    for order, a in zip(orders, state_matrices(u, s, 1, orders)):
        root = np.sqrt(s[:order])
        try:
            if a is None:
                raise np.linalg.LinAlgError
            lam, vec = np.linalg.eig(a)
        except np.linalg.LinAlgError:
            out.append(np.empty((0, 3)))
            continue
        keep = lam.imag > 1e-12
        if not np.any(keep):
            out.append(np.empty((0, 3)))
            continue
        c_modal = (u[0, :order] * root) @ vec
        try:
            g_modal = np.linalg.solve(vec, root * vt[:order, 0])
        except np.linalg.LinAlgError:
            out.append(np.empty((0, 3)))
            continue
        lam_k, amp = lam[keep], (c_modal * g_modal)[keep]
        pole = np.log(lam_k) * fs
        freq = np.abs(pole) / (2 * math.pi)
        zeta = -pole.real / np.abs(pole)
        variance = 2.0 * (amp / lam_k).real  # the pair's share of R_0
        out.append(np.column_stack((freq, zeta, variance)))
    return out


def order_support(group: np.ndarray) -> int:
    """The model orders at which a cluster of :func:`stable_clusters` holds a pole."""
    return len(set(group[:, -2].tolist()))


def stable_clusters(
    poles: list[np.ndarray],
    fs: float,
    max_damping: float,
    band: tuple[float, float],
    counts: dict[str, int],
) -> list[np.ndarray]:
    """The stable clusters of a stabilisation diagram ``poles`` (one array per model order whose
    first three columns are frequency, damping, variance; further columns ride along): poles with
    a damping ratio in (0, ``max_damping``], below :data:`NU_MAX` fs and in ``band``, grouped in
    frequency (neighbours within :data:`CLUSTER_TOL`, a group no wider than :data:`CLUSTER_SPAN`);
    a group is kept when it holds a pole at :data:`MIN_SUPPORT` of the orders. Each cluster: its
    poles' rows with two columns appended, the order's index and the row's index in that order;
    ascending frequency. Counts the rejected poles/clusters."""
    rows = []
    for k, p in enumerate(poles):
        ok = (
            (p[:, 1] > 0)
            & (p[:, 1] <= max_damping)
            & (p[:, 0] < NU_MAX * fs)
            & (p[:, 0] >= band[0])
            & (p[:, 0] <= band[1])
        )
        counts['rejected_damping'] += int(np.count_nonzero(~ok))
        rows.append(np.column_stack((p[ok], np.full(np.count_nonzero(ok), k), np.flatnonzero(ok))))
    width = (poles[0].shape[1] if poles else 3) + 2
    allp = np.concatenate(rows) if rows else np.empty((0, width))
    allp = allp[np.argsort(allp[:, 0])]
    clusters = []
    start = 0
    n_orders = len(poles)
    for i in range(1, len(allp) + 1):
        if (
            i < len(allp)
            and allp[i, 0] <= allp[i - 1, 0] * (1 + CLUSTER_TOL)
            and allp[i, 0] <= allp[start, 0] * (1 + CLUSTER_SPAN)
        ):
            continue
        group = allp[start:i]
        start = i
        if order_support(group) / n_orders < MIN_SUPPORT:
            counts['rejected_unstable'] += 1
            continue
        clusters.append(group)
    return clusters


def cluster_modes(poles, fs, max_damping, band, counts) -> np.ndarray:
    """The physical modes of a stabilisation diagram ``poles`` (:func:`ssi_poles`): rows
    (frequency, damping, variance, support), ascending; counts the rejected poles/clusters
    (:func:`stable_clusters`)."""
    modes = []
    for group in stable_clusters(poles, fs, max_damping, band, counts):
        f, z, v = np.median(group[:, :3], axis=0)
        modes.append((f, z, max(v, 0.0), order_support(group) / len(poles)))
    return np.array(modes).reshape(-1, 4)


def _modes_at(
    r: np.ndarray, fs: float, max_damping: float, band: tuple[float, float], counts: dict[str, int]
) -> np.ndarray:
    """The clustered modes (:func:`cluster_modes`) of correlations ``r`` at ``fs``, poles up to
    :data:`NU_MAX` fs in ``band``; clusters closer than :data:`MERGE_TOL` are one mode (the one
    with the larger support)."""
    modes = cluster_modes(
        ssi_poles(r, fs),
        fs,
        max_damping,
        (band[0], min(band[1], NU_MAX * fs)),
        counts,
    )
    keep = []
    for row in modes:
        if keep and row[0] <= keep[-1][0] * (1 + MERGE_TOL):
            if row[3] > keep[-1][3]:
                keep[-1] = row
            continue
        keep.append(row)
    return np.array(keep).reshape(-1, 4)


def _strong(modes: np.ndarray, total: float, fs: float, counts: dict[str, int]):
    """The ``modes`` whose peak stands :data:`MIN_PEAK_RATIO` above the density of everything
    else at its frequency (the white noise -- the variance ``total`` less the modes' -- and the
    other modes' skirts), and that noise variance."""
    dt = 1.0 / fs
    while True:
        noise = max(total - float(np.sum(modes[:, 2])), 1e-3 * total)
        w = 2 * math.pi * modes[:, 0] * dt
        c = np.cos(w)
        dens = np.array([_sdof_psd(c, f, z, max(v, 1e-300), dt) for f, z, v, _ in modes])
        own = np.diag(dens) if len(modes) else np.empty(0)
        ratio = own / (noise + dens.sum(axis=0) - own) if len(modes) else own
        weak = ratio < MIN_PEAK_RATIO
        if not np.any(weak):
            return modes, noise
        worst = int(np.argmin(ratio))  # drop the weakest, then judge the others again
        counts['rejected_weak'] += 1
        modes = np.delete(modes, worst, axis=0)


def whittle_frequencies(
    x: np.ndarray, fs: float, modes: np.ndarray, noise: float, stds: np.ndarray
) -> np.ndarray:
    """Each mode's frequency refined to the maximum of the Whittle likelihood of the window
    ``x`` (one channel, at ``fs``) near it, the other parameters kept (``modes``: rows of
    frequency, damping ratio, variance; ``noise``: the white noise's density at ``fs``, its
    variance there; ``stds``: the frequencies' stds, Hz).

    The Whittle log-likelihood of a stationary Gaussian series over the Fourier frequencies
    ``w_j = 2 pi j / N`` is ``-sum_j (log S(w_j) + I(w_j) / S(w_j))``, ``I`` the periodogram
    ``|sum_t (x_t - mean) e^(-i w_j t)|^2 / N`` and ``S`` the model density (:func:`sdof_psd` of
    every mode plus the noise). Maximised over one mode's frequency at a time, the bins within
    :data:`WHITTLE_SPAN` half-power half-widths (``zeta f``) of it and at most
    :data:`WHITTLE_GAP` of the way to the nearest other mode, the others at their SSI values,
    within :data:`WHITTLE_REACH` of the mode's std of the SSI frequency.
    SSI-cov's frequencies are consistent but not efficient (1.1-1.9x the Whittle bound,
    ``benchmarks/bench_operation.py``); the likelihood's maximum is (asymptotically) at the
    bound. The damping is left to SSI: the periodogram's leakage (the window's Fejer kernel)
    widens the peak, which biases a likelihood estimate of the damping up but, being
    symmetric, not the frequency."""
    from scipy.optimize import minimize_scalar

    n = len(x)
    spectrum = np.fft.rfft(x - np.mean(x))
    periodogram = (spectrum.real**2 + spectrum.imag**2) / n
    w = 2 * math.pi * np.arange(len(periodogram)) / n
    hz = w * fs / (2 * math.pi)
    dt = 1.0 / fs
    out = modes[:, 0].copy()
    for k, (f, zeta, variance) in enumerate(modes[:, :3]):
        if zeta * f * n / fs < WHITTLE_MIN_BINS or zeta > WHITTLE_MAX_DAMPING:
            continue  # a peak narrower than the bins (their leakage shapes it), or a wide one
        others = np.delete(modes[:, 0], k)
        gap = float(np.min(np.abs(others - f))) if len(others) else math.inf
        half = max(min(WHITTLE_SPAN * zeta * f, WHITTLE_GAP * gap), 2 * fs / n)
        near = np.abs(hz - f) <= half
        reach = min(half / 2, WHITTLE_REACH * float(stds[k]))
        if np.count_nonzero(near) < 3:
            continue
        c, power = np.cos(w[near]), periodogram[near]
        rest = noise + sum(
            _sdof_psd(c, fj, zj, max(vj, 1e-300), dt)
            for j, (fj, zj, vj) in enumerate(modes[:, :3])
            if j != k
        )

        def negative_log_likelihood(fk, zeta=zeta, variance=max(variance, 1e-300)):
            density = rest + _sdof_psd(c, fk, zeta, variance, dt)
            return float(np.sum(np.log(density) + power / density))

        best = minimize_scalar(
            negative_log_likelihood,
            bounds=(f - reach, f + reach),
            method='bounded',
            options={'xatol': 1e-7 * f},
        )
        if np.isfinite(best.x):
            out[k] = float(best.x)
    return out


def identify(
    cascade, fs, max_damping=0.1, band=(0.0, math.inf), counts=None, top_hz=0.0, search=True
):
    """Modes of one window (its :class:`CorrelationCascade`, one channel; ``fs`` the input
    rate): (rows of frequency, damping, variance, frequency std, damping std, ascending; the
    white noise variance left over; the window's variance). A first pass at ``fs`` (or, if it
    finds none, at the first of the rates halved in turn that does) finds the highest mode (or
    ``top_hz``, the highest mode known, if higher; with ``search`` false and ``top_hz`` given, no
    first pass); when it lies low enough, the modes come from a second pass at the rate
    :func:`decimation_level` gives, over whose lags (``BLOCK_ROWS`` samples) close modes are
    resolved."""
    counts = dict.fromkeys(COUNTER_NAMES, 0) if counts is None else counts

    def modes_at(level):
        r = cascade.correlations(level)[:, 0, 0]
        return _strong(_modes_at(r, fs / 2**level, max_damping, band, counts), total, fs, counts)

    n = cascade.samples(0)
    total = float(cascade.variance()[0])
    if cascade.flat()[0]:
        counts['flat_windows'] += 1
        return np.empty((0, 5)), total, total
    modes, noise, at = np.empty((0, 4)), total, 0
    if search or top_hz <= 0:
        # the search: from the full rate down by halvings until a level finds a mode (a low
        # mode spans too few periods of the full rate's lags to be stable there)
        level = 0
        while True:
            modes, noise, at = *modes_at(level), level
            if len(modes) or not cascade.can_halve(level):
                break
            level += 1
    top = max(float(np.max(modes[:, 0])) if len(modes) else 0.0, top_hz)
    if top > 0:
        level = decimation_level(cascade, fs, top)
        if level > 0 or not (search or top_hz <= 0):  # (no search pass ran at fs)
            modes, noise, at = *modes_at(level), level
    triples = [(f, z, v) for f, z, v, _ in modes]
    stds = np.array(whittle_std(triples, noise, fs, n)).reshape(-1, 2)
    if len(modes):
        modes = modes.copy()
        modes[:, 0] = whittle_frequencies(
            cascade.window(at)[:, 0], fs / 2**at, modes, noise / 2**at, stds[:, 0]
        )
    out = np.column_stack((modes[:, :3], stds)) if len(modes) else np.empty((0, 5))
    weak = ~(out[:, 3] <= MAX_STD_REL * out[:, 0])
    counts['rejected_uncertain'] += int(np.count_nonzero(weak))
    return out[~weak], noise, total


# ---- streaming ----------------------------------------------------------------------------------
class _Track:
    """A mode followed across windows."""

    __slots__ = ('amplitude', 'estimates', 'frequency', 'history', 'last_t', 'published', 'seen')

    def __init__(self, frequency: float, t: float):
        self.frequency, self.seen, self.last_t, self.published = frequency, 1, t, False
        self.amplitude = 0.0
        self.estimates = 0
        self.history: list[tuple[float, float, float, float, float]] = []

    def calibration(
        self, t: float, f: float, f_std: float, z: float, z_std: float, window: float
    ) -> float:
        """The factor (>= 1) by which the Whittle stds are too small, from this mode's own
        estimates: the RMS of ``(f - f_j) / sqrt(std^2 + std_j^2)`` (and of the damping's) over
        its estimates ``f_j`` of windows that do not overlap this one (at least ``window`` s
        earlier, within :data:`HISTORY_WINDOWS` windows); 1 until there are such. Records
        ``(t, f, f_std, z, z_std)`` for the next ones."""
        hist = [h for h in self.history if h[0] >= t - HISTORY_WINDOWS * window]
        self.history = hist + [(t, f, f_std, z, z_std)]
        old = np.array([h for h in hist if h[0] <= t - window]).reshape(-1, 5)
        if not len(old):
            return 1.0
        d = np.concatenate(
            (
                (f - old[:, 1]) / np.hypot(f_std, old[:, 2]),
                (z - old[:, 3]) / np.hypot(z_std, old[:, 4]),
            )
        )
        return max(1.0, math.sqrt(float(np.mean(d * d))))


class SlidingWindowIdentifier(Estimator):
    """The sliding window both output-only identifiers share (this module's, one channel, and
    :class:`vib_estimator.core.multichannel.JointAmbientEstimator`): the samples' buffer (``y``:
    one value or one row of ``channels`` values a sample), their checks and counters, the runs of
    clean samples of a batch, and the window each analysis reads. A subclass analyses a window
    (``_analyse``) and tracks its modes."""

    def __init__(self, config: EstimatorConfig, channels: int = 0, lags: int = 2 * BLOCK_ROWS):
        config.validate()
        self._config = config
        self._window = config.ambient_window_s
        self._band = config.band_hz or (0.0, math.inf)
        self._c = dict.fromkeys(COUNTER_NAMES, 0)
        self._row = (channels,) if channels else ()  # the shape of one sample's values
        self._t = np.empty(1 << 14)
        self._y = np.empty((1 << 14, *self._row))
        self._tracks: list = []
        self._cascade = CorrelationCascade(lags, max(channels, 1))
        #: while True, a window that is due only slides (counted ``analyses_idle``): nothing is
        #: identified or published, the tracked modes wait (``excitation = auto`` in a free
        #: stretch, where the identifier's estimates would not publish)
        self.idle = False
        self.restart()

    @property
    def config(self) -> EstimatorConfig:
        return self._config

    @property
    def counters(self) -> dict[str, int]:
        return dict(self._c)

    def restart(self) -> None:
        """Forget the signal and the tracked modes; counters are kept."""
        self._tracks = []
        self._last = -math.inf
        self._clear()

    def reset(self) -> None:
        """Start a new window at the next sample (the tracked modes are kept): the next estimates
        come from samples after this call."""
        self._clear()

    def _clear(self) -> None:
        self._n = 0  # samples in the buffer
        self._start = 0  # first sample of the current window
        self._fed = 0  # samples of the buffer in the cascade
        self._cascade.clear()
        self._next = math.inf

    # ---- input --------------------------------------------------------------------------------
    def _append(self, t: np.ndarray, y: np.ndarray) -> None:
        m = len(t)
        if self._n + m > len(self._t):
            keep = self._n - self._start
            if keep + m > len(self._t) // 2:  # grow
                size = 1 << math.ceil(math.log2(2 * (keep + m)))
                self._t = np.concatenate((self._t[self._start : self._n], np.empty(size - keep)))
                self._y = np.concatenate(
                    (self._y[self._start : self._n], np.empty((size - keep, *self._row)))
                )
            else:  # compact
                self._t[:keep] = self._t[self._start : self._n]
                self._y[:keep] = self._y[self._start : self._n]
            self._fed -= self._start
            self._n, self._start = keep, 0
        self._t[self._n : self._n + m] = t
        self._y[self._n : self._n + m] = y
        if self._n == 0:
            self._next = float(t[0]) + self._window
        self._n += m

    def _accept(self, t: float, finite: bool) -> bool:
        """Count one sample (``finite``: its values are); False if skipped. A gap or a long jump
        back clears the window."""
        c = self._c
        c['received'] += 1
        if not (finite and math.isfinite(t)):
            c['skipped_non_finite'] += 1
            return False
        last = self._last
        if t <= last:
            if last - t > self._config.max_gap:
                c['time_jump_resets'] += 1
                self._clear()
            else:
                c['skipped_duplicate' if t == last else 'skipped_out_of_order'] += 1
                return False
        elif t - last > self._config.max_gap and self._n:
            c['gap_resets'] += 1
            self._clear()
        self._last = t
        c['used'] += 1
        return True

    def _due(self) -> list:
        """The analysis due now (:meth:`_analyse`), or, :attr:`idle`, only the window's slide."""
        if not self.idle:
            return self._analyse()
        self._slide()
        self._c['analyses_idle'] += 1
        return []

    @single_blas_thread
    def _analysis(self) -> list:
        """:meth:`_due` on one BLAS thread (:mod:`.threads`), for a sample fed alone; a batch
        (:meth:`_feed`) is on one thread throughout."""
        return self._due()

    @single_blas_thread
    def _feed(self, t: np.ndarray, y: np.ndarray, finite: np.ndarray) -> list:
        """Feed a batch (``finite``: per sample, its values are): each clean run (finite,
        increasing, no gap) at once up to the next analysis, any other sample through
        ``update``; the estimates of the analyses, in order."""
        out: list = []
        gap = self._config.max_gap
        i, n = 0, len(t)
        while i < n:
            j = i
            if finite[i] and t[i] > self._last and (t[i] - self._last <= gap or not self._n):
                d = np.diff(t[i : min(n, i + 65536)])
                bad = ~((d > 0) & (d <= gap)) | ~finite[i + 1 : i + 1 + len(d)]
                j = i + 1 + (int(np.argmax(bad)) if bad.any() else len(d))
            if j == i:
                out.extend(self.update(t[i], y[i]))
                i += 1
                continue
            while i < j:
                if not self._n:
                    self._next = float(t[i]) + self._window
                k = min(j, int(np.searchsorted(t[i:j], self._next, 'left')) + i + 1)
                self._c['received'] += k - i
                self._c['used'] += k - i
                self._append(t[i:k], y[i:k])
                self._last = float(t[k - 1])
                i = k
                if self._last >= self._next:
                    out.extend(self._due())
        return out

    def _confirm(self, seen: dict, t: float) -> tuple[list, list]:
        """After an analysis at ``t`` (``seen``: the tracks it saw, by id): forget the unseen
        unpublished tracks and the published ones unseen for a window, publish those seen
        ``CONFIRM`` analyses running (``CONFIRM_BESIDE`` once a mode is published) and the
        published ones seen again (the ``modes`` strongest if set); ``(the tracks to publish
        now, every published track by ascending frequency: the mode numbers)``."""
        tracks = self._tracks
        for tr in list(tracks):
            if id(tr) not in seen:
                tr.seen = 0
                if not tr.published or t - tr.last_t > self._window:
                    tracks.remove(tr)
                    self._c['modes_lost'] += tr.published
        need = CONFIRM_BESIDE if any(tr.published for tr in tracks) else CONFIRM
        ready = [tr for tr in tracks if id(tr) in seen and (tr.published or tr.seen >= need)]
        if self._config.modes:
            ready = sorted(ready, key=lambda tr: -tr.amplitude)[: self._config.modes]
        for tr in ready:
            if not tr.published:
                tr.published = True
                self._c['modes_found'] += 1
        numbered = sorted((tr for tr in tracks if tr.published), key=lambda tr: tr.frequency)
        return ready, numbered

    def _next_window(self):
        """Advance to the next analysis; ``(samples' times, their correlations (the
        :class:`CorrelationCascade`, brought up to the last sample), rate, span, the highest
        published mode's frequency (0: none), whether to search the whole band)`` of the window
        it reads, or None when the window is too short."""
        ts = self._slide()
        if len(ts) < MIN_WINDOW_SAMPLES:
            return None
        span = float(ts[-1] - ts[0])
        self._c['analyses'] += 1
        known = max((tr.frequency for tr in self._tracks if tr.published), default=0.0)
        search = self._c['analyses'] % SEARCH_EVERY == 1
        return ts, self._cascade, (len(ts) - 1) / span, span, known, search

    def _slide(self) -> np.ndarray:
        """Schedule the next analysis and slide the window (and the cascade) to end at the last
        sample; its samples' times."""
        t_end = self._t[self._n - 1]
        self._next += HOP_S
        if self._next <= t_end:
            self._next = t_end + HOP_S
        first = self._start + int(
            np.searchsorted(self._t[self._start : self._n], t_end - self._window, 'left')
        )
        self._start = first
        ts = self._t[first : self._n]
        new = self._y[self._fed : self._n]
        self._cascade.push(new.reshape(len(new), -1))
        self._fed = self._n
        self._cascade.keep_last(len(ts))
        return ts


class AmbientEstimator(SlidingWindowIdentifier):
    """Sliding-window output-only mode identification; see the module docstring."""

    def mode_counters(self) -> dict[int, dict[str, int]]:
        """Each current mode's estimates (as the mode tracker's ``mode_counters``)."""
        published = sorted(
            (tr for tr in self._tracks if tr.published), key=lambda tr: tr.frequency
        )
        return {k: {'estimates': tr.estimates} for k, tr in enumerate(published, 1)}

    def update(self, t: float, y: float) -> list[Estimate]:
        """Feed one sample; the estimates of an analysis it completes (ascending mode)."""
        t, y = float(t), float(y)
        if not self._accept(t, math.isfinite(y)):
            return []
        self._append(np.array((t,)), np.array((y,)))
        if t >= self._next:
            return self._analysis()
        return []

    def process(self, t: Sequence[float], y: Sequence[float]) -> EstimateArrays:
        """Feed arrays of samples (continuing the stream); the estimates as columns, by time."""
        t, y = as_series(t, y)
        return _columns(self._feed(t, y, np.isfinite(t) & np.isfinite(y)))

    # ---- analysis -----------------------------------------------------------------------------
    def _analyse(self) -> list[Estimate]:
        window = self._next_window()
        if window is None:
            return []
        ts, cascade, fs, span, known, search = window
        modes, _noise, total = identify(
            cascade, fs, self._config.max_damping, self._band, self._c, known, search
        )
        return self._track(modes, total, float(ts[-1]), span, len(ts))

    def _track(
        self, modes: np.ndarray, total: float, t: float, span: float, n: int
    ) -> list[Estimate]:
        """Match the window's modes to the tracked ones, publish the confirmed ones."""
        tracks = self._tracks
        pairs = sorted(
            (abs(m[0] / tr.frequency - 1), i, j)
            for i, m in enumerate(modes)
            for j, tr in enumerate(tracks)
        )
        match: dict[int, int] = {}
        used = set()
        pairs.sort(key=lambda p: (not tracks[p[2]].published, p[0]))  # published ones first
        for dist, i, j in pairs:
            if dist <= MATCH_TOL and i not in match and j not in used:
                match[i] = j
                used.add(j)
        seen = {}
        for i, m in enumerate(modes):
            if i in match:
                tr = tracks[match[i]]
                tr.seen += 1
            elif len(tracks) < MAX_TRACKS:
                tr = _Track(m[0], t)
                tracks.append(tr)
            else:
                continue
            tr.frequency, tr.last_t, tr.amplitude = m[0], t, math.sqrt(m[2])
            seen[id(tr)] = m
        ready, numbered = self._confirm(seen, t)
        explained = min(1.0, float(np.sum(modes[:, 2])) / total) if total > 0 else 0.0
        out = []
        for k, tr in enumerate(numbered, 1):
            if tr in ready:
                f, z, v, fstd, zstd = seen[id(tr)]
                scale = tr.calibration(t, f, fstd, z, zstd, self._window)
                fstd, zstd = fstd * scale, zstd * scale
                tr.estimates += 1
                out.append(
                    Estimate(
                        t,
                        float(f),
                        span,
                        n,
                        explained,
                        math.sqrt(v),
                        float(z),
                        float(fstd),
                        float(zstd),
                        k,
                    )
                )
        self._c['estimates'] += len(out)
        return out


def _columns(estimates: list[Estimate]) -> EstimateArrays:
    """Estimates as the columns of :class:`EstimateArrays`."""
    names = list(EstimateArrays.__dataclass_fields__)
    ints = ('samples', 'mode')
    return EstimateArrays(
        **{
            name: np.array(
                [getattr(e, name) for e in estimates],
                dtype=np.int64 if name in ints else np.float64,
            )
            for name in names
        }
    )


#: a mode followed across windows (public for the multi-channel identifier,
#: :mod:`vib_estimator.core.multichannel`)
ModeTrack = _Track
#: estimates as the columns of :class:`EstimateArrays` (public for the multi-channel identifier)
estimate_columns = _columns
