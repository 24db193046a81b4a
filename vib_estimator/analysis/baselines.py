# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""Baseline frequency trackers of Section 5.4, and a flight-controller-style windowed-DFT tracker.

Every tracker has the streaming/batch shape of
:class:`vib_estimator.core.estimator.FrequencyEstimator`:
``update(t, y)`` feeds one sample and returns the current estimate in Hz (a float at every sample,
``None`` while the tracker has none), ``reset()`` forgets the signal, and ``process(t, y)`` feeds
arrays and returns the per-sample estimates (NaN where ``update`` returns ``None``), the same
floats
as ``update`` gives. A sample whose value or stamp is not finite, or whose stamp does not increase,
is skipped (the current estimate is returned).

Adaptive trackers (continuous-time ODEs; the gains and initial states of Section 5.4, which the
paper used on the coupling torque in N m). Their adaptation rates scale with the signal's amplitude
squared, so the gains are tied to that unit: on a 1 N m sine they converge within ~1 s (ZK, Hou)
and ~6 s (MB), on the simulated arm's 0.05-0.4 N m ZK and MB need tens of seconds:

* :class:`ZiaraniKonrad`, Eqs. 25-26 (mu1 = 10, mu2 = 3000, mu3 = 0.1, omega(0) = 6 pi rad/s);
* :class:`Hou`, Eqs. 27-29 (alpha1 = 10, alpha2 = 5000; theta^ -> omega^2);
* :class:`MojiriBakhshai`, Eqs. 30-33 (xi1 = 0.1, xi2 = 1.25, [x, x', theta](0) = [1, 1, 6 pi];
  stable for A^2 xi2 / 2 < 1, Eq. 33).

They are integrated by :func:`_advance`: classical RK4 with ``substeps`` steps per sampling
interval, the input held first-order (linear) between samples. The gains make Ziarani-Konrad stiff
on large signals (its phase loop's fast rate is ~ mu3 mu2 A^2: ~300-600 1/s at A = 1 N m, against
500 samples/s; Hou's rates are ~ sqrt(alpha2) A, 70 1/s); the default 4 sub-steps keep RK4 well
inside its stability region, and halving the step changes the trajectories by < 1e-5 relative at
A <= 1 (``test_baselines``).

Windowed DFT (:class:`SlidingDFT`): what PX4's ``gyro_fft`` and Betaflight's dynamic notch do --
a Hann-windowed FFT of the last ``window_s`` seconds every ``hop`` samples, the largest bin in the
search band refined by two-bin interpolation.
"""

from __future__ import annotations

import math
from typing import Optional, Sequence, Tuple

import numpy as np
from numba import njit

from ..core.threads import one_blas_thread
from ..core.uncertainty import TWO_PI

ZIARANI, HOU, MOJIRI = 0, 1, 2
#: the ODE trackers' initial frequency, rad/s: the 3 Hz Section 5.5 starts all three at
OMEGA0 = 3 * TWO_PI

# ---- state array layout of the ODE trackers ------------------------------------------------
S_STARTED, S_TPREV, S_YPREV, S_X = 0, 1, 2, 3  # flag, last stamp, last value, ODE state (3)
N_STATE = S_X + 3


@njit(cache=True)
def _rhs(kind, p, x, y, dx):
    """Right-hand side of the tracker ``kind`` at state ``x`` and input ``y``; writes ``dx``.

    Ziarani-Konrad (Eqs. 25-26), x = (A, omega, gamma), p = (mu1, mu2, mu3)::

        e = y - A sin(gamma),  A' = 2 mu1 e sin(gamma),  omega' = 2 mu2 e A cos(gamma),
        gamma' = omega + mu3 omega'

    Hou (Eqs. 27-28), x = (z, eta), p = (alpha1, alpha2)::

        z' = -alpha1 z + (alpha2 y^2 / 2 - eta - alpha1^2) y,   eta' = alpha2 y (z + alpha1 y)

    Mojiri-Bakhshai (Eqs. 30-31), x = (x, x', theta), p = (xi1, xi2)::

        x'' = -2 xi1 theta x' - theta^2 x + 2 xi1 theta^2 y,
        theta' = -xi2 x (2 xi1 theta^2 y - 2 xi1 theta x')
    """
    if kind == ZIARANI:
        sg = math.sin(x[2])
        e = y - x[0] * sg
        dw = 2.0 * p[1] * e * x[0] * math.cos(x[2])
        dx[0] = 2.0 * p[0] * e * sg
        dx[1] = dw
        dx[2] = x[1] + p[2] * dw
    elif kind == HOU:
        dx[0] = -p[0] * x[0] + (0.5 * p[1] * y * y - x[1] - p[0] * p[0]) * y
        dx[1] = p[1] * y * (x[0] + p[0] * y)
        dx[2] = 0.0
    else:
        th = x[2]
        dx[0] = x[1]
        dx[1] = -2.0 * p[0] * th * x[1] - th * th * x[0] + 2.0 * p[0] * th * th * y
        dx[2] = -p[1] * x[0] * (2.0 * p[0] * th * th * y - 2.0 * p[0] * th * x[1])


@njit(cache=True)
def _frequency(kind, p, x, y):
    """The tracker's frequency estimate in Hz: omega / 2 pi (Eq. 25), sqrt(theta^) / 2 pi with
    theta^ = eta - alpha2 y^2 / 2 (Eq. 29, clipped at 0), theta / 2 pi (Eq. 32)."""
    if kind == ZIARANI:
        return x[1] / TWO_PI
    if kind == HOU:
        return math.sqrt(max(x[1] - 0.5 * p[1] * y * y, 0.0)) / TWO_PI
    return x[2] / TWO_PI


@njit(cache=True)
def _advance(kind, p, x, y0, y1, h, substeps):
    """Integrate over one sampling interval ``h`` with RK4, ``y`` linear from ``y0`` to ``y1``."""
    n = x.shape[0]
    k1 = np.empty(n)
    k2 = np.empty(n)
    k3 = np.empty(n)
    k4 = np.empty(n)
    xt = np.empty(n)
    dt = h / substeps
    dy = (y1 - y0) / substeps
    for j in range(substeps):
        ya = y0 + j * dy
        _rhs(kind, p, x, ya, k1)
        for i in range(n):
            xt[i] = x[i] + 0.5 * dt * k1[i]
        _rhs(kind, p, xt, ya + 0.5 * dy, k2)
        for i in range(n):
            xt[i] = x[i] + 0.5 * dt * k2[i]
        _rhs(kind, p, xt, ya + 0.5 * dy, k3)
        for i in range(n):
            xt[i] = x[i] + dt * k3[i]
        _rhs(kind, p, xt, ya + dy, k4)
        for i in range(n):
            x[i] += dt / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])


@njit(cache=True)
def _step(kind, p, x0, s, t, y, substeps):
    """Feed one sample to the tracker whose state is ``s``; return its estimate (NaN: none yet).

    ``x0`` is the initial ODE state; the first sample only starts the clock (and, for Hou, sets
    eta(0) so that theta^(0) = omega_i^2 whatever y(0) is).
    """
    x = s[S_X:]
    if not (math.isfinite(t) and math.isfinite(y)):
        return _frequency(kind, p, x, s[S_YPREV]) if s[S_STARTED] > 0.0 else np.nan
    if s[S_STARTED] == 0.0:
        x[:] = x0
        if kind == HOU:
            x[1] += 0.5 * p[1] * y * y
        s[S_STARTED] = 1.0
    elif t > s[S_TPREV]:
        _advance(kind, p, x, s[S_YPREV], y, t - s[S_TPREV], substeps)
    else:
        return _frequency(kind, p, x, s[S_YPREV])
    s[S_TPREV] = t
    s[S_YPREV] = y
    return _frequency(kind, p, x, y)


@njit(cache=True)
def _run(kind, p, x0, s, t, y, substeps, out):
    """Batch form of :func:`_step` over arrays (same floats)."""
    for i in range(t.shape[0]):
        out[i] = _step(kind, p, x0, s, t[i], y[i], substeps)


class _OdeTracker:
    """Streaming/batch driver of one of the ODE trackers of :func:`_rhs`."""

    kind = -1
    name = ''

    def __init__(self, params: Sequence[float], x0: Sequence[float], substeps: int = 4):
        if int(substeps) < 1:
            raise ValueError(f'substeps must be >= 1, got {substeps!r}')
        self._p = np.asarray(params, dtype=np.float64)
        self._x0 = np.zeros(3)
        self._x0[: len(x0)] = x0
        self._substeps = int(substeps)
        self._s = np.zeros(N_STATE)

    def reset(self) -> None:
        """Forget the signal: the next sample restarts from the initial state."""
        self._s[:] = 0.0

    def update(self, t: float, y: float) -> Optional[float]:
        """Feed one sample (s, signal units); return the current estimate in Hz."""
        f = _step(self.kind, self._p, self._x0, self._s, float(t), float(y), self._substeps)
        return None if math.isnan(f) else f

    def process(self, t: Sequence[float], y: Sequence[float]) -> np.ndarray:
        """Feed arrays (continuing the stream); return the per-sample estimates in Hz."""
        t, y = _as_arrays(t, y)
        out = np.empty(len(t))
        _run(self.kind, self._p, self._x0, self._s, t, y, self._substeps, out)
        return out


class ZiaraniKonrad(_OdeTracker):
    """Ziarani & Konrad's enhanced PLL (Eqs. 25-26); defaults are the gains of Section 5.4.

    States A, omega, gamma (= omega t + phi, integrated as gamma' = omega + mu3 omega'); A starts
    at 0 and gamma at 0. Units: mu1 1/s, mu2 1/(s^2 unit^2), mu3 s.
    """

    kind = ZIARANI
    name = 'Ziarani-Konrad'

    def __init__(self, mu1=10.0, mu2=3000.0, mu3=0.1, omega0=OMEGA0, substeps=4):
        super().__init__((mu1, mu2, mu3), (0.0, omega0, 0.0), substeps)


class Hou(_OdeTracker):
    """Hou's globally convergent estimator (Eqs. 27-29); defaults are the gains of Section 5.4.

    z starts at 0 and eta at omega0^2 + alpha2 y(0)^2 / 2, so that theta^ starts at omega0^2
    (the 3 Hz initial frequency Section 5.5 gives the three trackers). Units: alpha1 1/s,
    alpha2 1/(s unit^2).
    """

    kind = HOU
    name = 'Hou'

    def __init__(self, alpha1=10.0, alpha2=5000.0, omega0=OMEGA0, substeps=4):
        super().__init__((alpha1, alpha2), (0.0, omega0**2), substeps)


class MojiriBakhshai(_OdeTracker):
    """Mojiri & Bakhshai's adaptive notch filter (Eqs. 30-33); defaults are those of Section 5.4.

    Initial state [x, x', theta] = [1, 1, 6 pi]. Stable for A^2 xi2 / 2 < 1 (Eq. 33). Units: xi1
    dimensionless, xi2 1/unit^2.
    """

    kind = MOJIRI
    name = 'Mojiri-Bakhshai'

    def __init__(self, xi1=0.1, xi2=1.25, x0=(1.0, 1.0, OMEGA0), substeps=4):
        super().__init__((xi1, xi2), tuple(x0), substeps)


def _as_arrays(t, y):
    t = np.ascontiguousarray(t, dtype=np.float64)
    y = np.ascontiguousarray(y, dtype=np.float64)
    if t.shape != y.shape or t.ndim != 1:
        raise ValueError(f't and y must be 1-D arrays of one length, got {t.shape}, {y.shape}')
    return t, y


class SlidingDFT:
    """Flight-controller-style tracker: Hann-windowed DFT of the last ``window_s`` s every ``hop``
    samples, peak bin in ``band_hz`` refined by two-bin magnitude-ratio interpolation.

    This is the scheme of PX4's ``gyro_fft`` and Betaflight's dynamic notch (fixed-rate samples,
    Hann window, peak search, interpolation between bins). The interpolation is Jain, Collins &
    Davis's (1979) ratio rule with the Hann window's kernel (Grandke 1983): with ``k`` the peak
    bin,
    ``a = |X[k+1]| / |X[k]|`` (or ``|X[k-1]|``, whichever neighbour is larger), the offset is
    ``delta = +-(2a - 1) / (a + 1)`` bins, exact for a complex exponential; for a real sinusoid the
    residual bias comes from the negative-frequency image: < 0.2 % from 2.3 cycles per window on.

    Parameters: ``rate_hz`` the (fixed) sampling rate the DFT assumes; ``window_s`` the window
    (default 2 s: 2.3 cycles at the 1.15 Hz of Section 5.5, bins of 0.5 Hz); ``hop`` samples
    between two DFTs (default 10: a 50 Hz update at 500 Hz); ``band_hz`` the peak search band. The
    estimate of a DFT is reported from its last sample until the next DFT; none before the first
    full window.
    """

    name = 'Sliding DFT'

    def __init__(self, rate_hz=500.0, window_s=2.0, hop=10, band_hz=(0.5, 25.0)):
        self._n = int(round(window_s * rate_hz))
        self._hop = int(hop)
        if self._n < 8 or self._hop < 1:
            raise ValueError(
                f'window_s * rate_hz must be >= 8 samples and hop >= 1, got {self._n}, {hop!r}'
            )
        self._df = rate_hz / self._n
        nbins = self._n // 2 + 1
        self._klo = max(1, int(math.ceil(band_hz[0] / self._df)))
        self._khi = min(nbins - 2, int(math.floor(band_hz[1] / self._df)))
        if self._klo > self._khi:
            raise ValueError(f'band_hz {tuple(band_hz)} holds no interior DFT bin')
        self._window = 0.5 - 0.5 * np.cos(TWO_PI * np.arange(self._n) / self._n)  # periodic Hann
        self.reset()

    @property
    def window_samples(self) -> int:
        """Samples per DFT window."""
        return self._n

    def reset(self) -> None:
        """Forget the signal."""
        self._buf = np.empty(0)
        self._count = 0
        self._tmax = -math.inf
        self._f = math.nan

    def _peak_frequencies(self, frames: np.ndarray) -> np.ndarray:
        """Interpolated peak frequency (Hz) of each row of ``frames`` (n_frames x N)."""
        mag = np.abs(np.fft.rfft(frames * self._window, axis=1))
        rows = np.arange(len(frames))
        k = self._klo + np.argmax(mag[:, self._klo : self._khi + 1], axis=1)
        peak = mag[rows, k]
        up = mag[rows, k + 1]
        down = mag[rows, k - 1]
        side = np.where(up >= down, 1.0, -1.0)
        with np.errstate(invalid='ignore', divide='ignore'):
            a = np.maximum(up, down) / peak
        return (k + side * (2.0 * a - 1.0) / (a + 1.0)) * self._df

    def update(self, t: float, y: float) -> Optional[float]:
        """Feed one sample; return the current estimate in Hz (``None`` before the first DFT)."""
        f = self.process([t], [y])[0]
        return None if math.isnan(f) else float(f)

    def process(self, t: Sequence[float], y: Sequence[float]) -> np.ndarray:
        """Feed arrays (continuing the stream); return the per-sample estimates in Hz."""
        t, y = _as_arrays(t, y)
        finite = np.isfinite(t) & np.isfinite(y)
        tmax = np.maximum.accumulate(np.where(finite, t, -math.inf)) if len(t) else t
        prev = np.concatenate(([self._tmax], tmax[:-1]))
        accepted = finite & (t > prev)
        if len(t):
            self._tmax = max(self._tmax, float(tmax[-1]))
        data = np.concatenate((self._buf, y[accepted]))
        base = self._count - len(self._buf)  # global index of data[0]
        g = self._count + np.arange(int(accepted.sum()))  # global index of each new sample
        ends = g[(g >= self._n - 1) & ((g - (self._n - 1)) % self._hop == 0)]
        est = np.full(len(t), np.nan)
        if len(ends):
            frames = np.lib.stride_tricks.sliding_window_view(data, self._n)[
                ends - self._n + 1 - base
            ]
            est[np.flatnonzero(accepted)[ends - self._count]] = self._peak_frequencies(frames)
        out = hold_last(est, self._f)
        self._count += len(g)
        self._buf = data[max(0, len(data) - (self._n - 1)) :]
        if len(out):
            self._f = float(out[-1])
        return out


def hold_last(values: np.ndarray, initial: float = math.nan) -> np.ndarray:
    """``values`` with each NaN replaced by the last non-NaN value before it (``initial`` if none).

    This is how a published, intermittent estimate reads as a per-sample one.
    """
    idx = np.where(np.isnan(values), -1, np.arange(len(values)))
    if len(idx):
        idx = np.maximum.accumulate(idx)
    return np.where(idx >= 0, values[np.maximum(idx, 0)], initial)


def matrix_pencil(
    y: np.ndarray, ts: float, order: int = 2, max_pencil: int = 256
) -> Tuple[float, float]:
    """Matrix-pencil estimate (Hua & Sarkar 1990) of one damped mode: (natural frequency Hz, zeta).

    The damped-exponential model y_k = sum_i r_i z_i^k, fitted through the Hankel matrix of the
    window with the pencil parameter L = min(n/3, ``max_pencil``), its ``order`` dominant singular
    vectors (2 = one real damped sine; 3 adds an offset), and the poles z_i = eig(V1^+ V2). The
    pole of largest |imag| gives s = ln(z) / ts, w_n = |s|, zeta = -Re(s) / |s|. What a modal
    analyst would run on a window; NaN when the window is too short.
    """
    y = np.asarray(y, dtype=float)
    n = len(y)
    pencil = min(n // 3, max_pencil)
    if pencil < order + 1:
        return math.nan, math.nan
    hankel = np.lib.stride_tricks.sliding_window_view(y, pencil + 1)
    with one_blas_thread():  # (a busy 2-core machine: 20x slower with OpenBLAS's threads)
        _, _, vt = np.linalg.svd(hankel, full_matrices=False)
        v = vt[:order].T
        poles = np.linalg.eigvals(np.linalg.pinv(v[:-1]) @ v[1:])
    s = np.log(poles[np.argmax(np.abs(poles.imag))].astype(complex)) / ts
    return abs(s) / TWO_PI, -s.real / abs(s)


class SlidingMatrixPencil(SlidingDFT):
    """A modal analyst's tracker: :func:`matrix_pencil` over the last ``window_s`` s every ``hop``
    samples (damped-exponential model of ``order`` poles; pencil parameter at most ``max_pencil``,
    64 by default to keep a sliding run cheap). Same stream handling as :class:`SlidingDFT`."""

    name = 'Matrix pencil'

    def __init__(self, rate_hz=500.0, window_s=2.0, hop=25, order=2, max_pencil=64):
        super().__init__(rate_hz, window_s, hop)
        self._ts = 1.0 / rate_hz
        self._order = int(order)
        self._max_pencil = int(max_pencil)

    def _peak_frequencies(self, frames: np.ndarray) -> np.ndarray:
        return np.array(
            [matrix_pencil(f, self._ts, self._order, self._max_pencil)[0] for f in frames]
        )
