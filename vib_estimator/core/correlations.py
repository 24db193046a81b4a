# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""The output correlations of a sliding window, kept up to date as samples arrive, at the input
rate and at that rate halved 1, 2, ... times: the buffers the output-only identifier
(:mod:`.ambient`) reads its subspace identification (:mod:`.ssi`) from, for any number of
channels (one is a 1 x 1 matrix).

Each buffer gives the unbiased correlation matrices ``R_k[a, b] = sum_t y_a,t+k y_b,t / (N - k)``,
k = 0 .. lags, of the window's mean-removed channels, what the direct computation from the window
gives (by FFT: ``test/core/test_ambient_incremental.py``):

- :class:`LagProducts`: the input rate's, exact, without re-reading the window;
- :class:`EditedProducts`: a halved window's, across analyses (only its ends change);
- :func:`zero_phase`: the zero-phase anti-alias filtering (:func:`decimation_filter`) before each
  halving of the rate;
- :class:`CorrelationCascade`: the levels together, as one analysis reads them.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from .estimator import make_room
from .jit import jit

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
#: block rows p of the correlation Hankel matrix of one channel (lags 1 .. 2p; core.ssi)
BLOCK_ROWS = 40
#: the decimated window holds at least this many samples (20 x the single channel's block rows)
MIN_SAMPLES = 20 * BLOCK_ROWS
#: a :class:`LagProducts` recomputes its sums from its window after this many slides (bounds the
#: rounding of the updates; the sums are otherwise exact)
REFRESH_SLIDES = 64
#: rows of a block of lag products computed at once
PRODUCT_BLOCK = 2048


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


def lag_windows(ext: np.ndarray, lags: int) -> np.ndarray:
    """``numpy.lib.stride_tricks.sliding_window_view(ext, lags + 1, axis=0)`` (rows x channels
    x lags + 1, read-only), the same view without its checks (~6 us a call)."""
    step, across = ext.strides
    shape = (len(ext) - lags, ext.shape[1], lags + 1)
    return np.lib.stride_tricks.as_strided(ext, shape, (step, across, step), writeable=False)


def summed(own: np.ndarray, view: np.ndarray) -> np.ndarray:
    """``numpy.tensordot(own, view, axes=(0, 0))`` of rows ``own`` and a :func:`lag_windows`
    ``view`` of as many rows: its own steps (one ``dot`` of ``own``'s transpose and the view's
    rows as a matrix, the same floats) without its checks of the axes."""
    m = own.shape[1]
    return np.dot(own.T, view.reshape(len(own), -1)).reshape(m, m, view.shape[2])


def lag_products(y, a, b, bound, off, sums, total, later=True, subtract=False) -> None:
    """Add to ``sums`` (lag k, channel i, channel j; k = 0 .. ``len(sums) - 1``) the products of
    the rows ``x = y - off`` that pair a row a <= t < b with another: ``later``, the products
    ``x[t] x[t - k]^T`` with the earlier rows ``bound <= t - k``; else ``x[t + k] x[t]^T`` with
    the later rows ``t + k < bound``. Add the rows a <= t < b to ``total``; subtract both instead
    with ``subtract``."""
    lags, m = len(sums) - 1, y.shape[1]
    for a0 in range(a, b, PRODUCT_BLOCK):
        b0 = min(b, a0 + PRODUCT_BLOCK)
        ext = np.zeros((b0 - a0 + lags, m))
        if later:
            lo0 = max(bound, a0 - lags)
            ext[lags - (a0 - lo0) :] = y[lo0:b0] - off
            own = ext[lags:]
            view = lag_windows(ext, lags)
            # view[i, :, q] = ext[i + q] = y[a0 + i - (lags - q)]: lag k = lags - q
            prod = summed(own, view)[:, :, ::-1].transpose(2, 0, 1)
        else:
            hi0 = min(bound, b0 + lags)
            ext[: hi0 - a0] = y[a0:hi0] - off
            own = ext[: b0 - a0]
            view = lag_windows(ext, lags)[: b0 - a0]
            # view[i, :, k] = y[a0 + i + k]
            prod = summed(own, view).transpose(2, 1, 0)
        if subtract:
            sums -= prod
            total -= own.sum(axis=0)
        else:
            sums += prod
            total += own.sum(axis=0)


def centred_correlations(sums, total, x, off) -> np.ndarray:
    """The unbiased correlation matrices of the mean-removed window ``x`` (rows) from its lag
    products ``sums`` and sum ``total`` of ``x - off`` (:func:`lag_products`): ``R_k = (sums_k -
    (total - first_k) mean^T - mean (total - last_k)^T + (n - k) mean mean^T) / (n - k)``,
    ``first_k`` and ``last_k`` the sums of ``x - off``'s first and last k rows
    (:func:`centre`)."""
    out = np.empty(sums.shape)
    centre(sums, total, x, off, out)
    return out


@jit(error_model='numpy')  # (as numpy: a division by zero gives inf or nan)
def centre(sums, total, x, off, out) -> None:
    """:func:`centred_correlations` into ``out``: numpy's arithmetic of each entry in numpy's
    order (``first`` and ``last`` running sums as ``cumsum``'s; the same floats as the array
    expression), one pass, not its ~20 array calls."""
    lags, n, m = len(sums) - 1, len(x), x.shape[1]
    first = np.zeros((lags + 1, m))
    last = np.zeros((lags + 1, m))
    for c in range(m):
        for k in range(1, lags + 1):
            a, b = x[k - 1, c] - off[c], x[n - k, c] - off[c]
            first[k, c] = a if k == 1 else first[k - 1, c] + a
            last[k, c] = b if k == 1 else last[k - 1, c] + b
    mean = total / n
    for k in range(lags + 1):
        count = float(n - k)
        for i in range(m):
            for j in range(m):
                r = sums[k, i, j] - (total[i] - first[k, i]) * mean[j]
                r = r - mean[i] * (total[j] - last[k, j])
                r = r + count * (mean[i] * mean[j])
                out[k, i, j] = r / count


class LagProducts:
    """The lag products of a sliding window over a growing buffer of samples (one row of
    ``channels`` values each), kept exactly: when the correlations are read, the products of
    the samples pushed since are added, those of the samples that left are subtracted (or, after
    :data:`REFRESH_SLIDES` such slides or a slide longer than what stays, all recomputed from the
    window). :meth:`correlations` gives the window's correlation matrices."""

    def __init__(self, lags: int, channels: int):
        self.lags, self.channels = lags, channels
        self._buf = np.empty((1 << 12, channels))
        self.clear()

    def clear(self) -> None:
        self._n = 0  # samples in the buffer
        self._want = 0  # the window's first sample
        self._start = 0  # the first sample of the stretch [start, done) the sums cover
        self._done = 0
        #: the value subtracted from the samples before their products are summed
        self.offset = np.zeros(self.channels)
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

    def mean(self) -> np.ndarray:
        """The window's mean, from the sums kept."""
        self._sync()
        return self.offset + self._total / len(self)

    def push(self, x: np.ndarray) -> None:
        """Append samples ``x`` (rows) to the window."""
        m = len(x)
        if not m:
            return
        if self._n + m > len(self._buf):
            shift = self._start
            self._buf = make_room(self._buf, shift, self._n, m)
            self._n -= shift
            self._start, self._want, self._done = 0, self._want - shift, self._done - shift
        if self._n == self._want:
            self.offset = np.array(x[0], dtype=np.float64)  # keeps the products' rounding small
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
        """Bring the sums to the window: subtract the products ``y[u + k] y[u]^T`` of the samples
        that left, add the products ``y[t] y[t - k]^T`` of those pushed with the window's."""
        args = (self.offset, self._sums, self._total)  # (updated in place)
        if self._want > self._start:
            if self._want >= self._done or self._slides >= REFRESH_SLIDES:
                self._restart()
            else:
                lag_products(self._buf, self._start, self._want, self._done, *args, False, True)
                self._start = self._want
                self._slides += 1
        if self._done < self._n:
            lag_products(self._buf, self._done, self._n, self._start, *args)
            self._done = self._n

    def correlations(self) -> np.ndarray:
        """The window's unbiased correlation matrices of its mean-removed channels, ``R_k[a, b]
        = sum_t y_a,t+k y_b,t / (N - k)``, k = 0 .. ``lags``: (lags + 1, channels, channels)."""
        self._sync()
        return centred_correlations(self._sums, self._total, self.window, self.offset)


class EditedProducts:
    """The lag products of a halved window (:class:`CorrelationCascade`'s levels from 1), kept
    across analyses: the window's middle is the previous window's (the same numbers, shifted),
    only its first and last samples differ; the products of the pairs that involve them are
    subtracted (the previous window's) and added (this one's) instead of all recomputed (all,
    after :data:`REFRESH_SLIDES` such updates, or when the middle is not the previous one's).
    :meth:`correlations` gives the window's correlation matrices."""

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
            lag_products(x, 0, n, 0, self._off, self._sums, self._total)
        else:
            # the pairs with a sample outside the middle: the previous window's out, x's in
            sums, total, off, mid = self._sums, self._total, self._off, hi + shift
            lag_products(old, mid, len(old), 0, off, sums, total, subtract=True)
            lag_products(old, 0, lo + shift, mid, off, sums, total, False, True)
            lag_products(x, 0, lo, hi, off, sums, total, False)
            lag_products(x, hi, n, 0, off, sums, total)
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


class CorrelationCascade:
    """A sliding window's correlations at the input rate and at that rate halved 1, 2, ...
    times (level j: every second sample of the window's :func:`zero_phase` filtering, j times).
    The input rate's are kept up to date as samples arrive (:class:`LagProducts`: exact,
    without re-reading the window). A halved rate's window is made when first read after the
    window moved: the zero-phase filtering of a window depends on its ends only within
    ``decimation_filter().settle`` samples of them, so its middle is kept from the previous
    analysis and only the stretches near the ends that moved are filtered again (the same
    numbers, to rounding, as the filtering of the whole window:
    ``test/core/test_ambient_incremental.py``). A halved window's correlations come from its
    lag products, kept across analyses (:class:`EditedProducts`), and the window's variance
    from the input rate's (``R_0``)."""

    def __init__(self, lags: int, channels: int):
        self.lags, self.channels = lags, channels
        self.levels = [LagProducts(lags, channels)]
        self._count = 0  # samples pushed since the last clear
        #: level -> (its input's first sample's position, step, its zero-phase filtering,
        #: the samples pushed by then)
        self._filtered: dict[int, tuple] = {}
        #: level (from 1) -> its window's lag products
        self._products: dict[int, EditedProducts] = {}
        self._moved()
        # scipy.signal imported and the zero-phase filter and the centring compiled (or loaded
        # from numba's cache) now, not at the first analysis (a window at the input rate, and a
        # halved one: every second sample)
        zero_phase(np.zeros(2 * decimation_filter().pad))
        x, zero = np.zeros((4, channels)), np.zeros(channels)
        for window in (x, x[::2]):
            centred_correlations(np.zeros((2, channels, channels)), zero, window, zero)

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
        """Level ``level``'s correlation matrices (lags 0 .. ``lags``)."""
        if level not in self._corr:
            if level == 0:
                r = self.levels[0].correlations()
            else:
                x, start, head, tail = self._level(level)
                products = self._products.setdefault(
                    level, EditedProducts(self.lags, self.channels)
                )
                r = products.correlations(x, start, 1 << level, head, tail)
            self._corr[level] = r
        return self._corr[level]

    def variance(self) -> np.ndarray:
        """Each channel's variance over the window (at the input rate), from the lag products
        kept (``R_0``), not from the window."""
        return np.diagonal(self.correlations(0)[0]).copy()

    def flat(self) -> np.ndarray:
        """Each channel's window is constant to rounding: its RMS at most :data:`FLAT_RMS_REL`
        of its mean's magnitude (exactly constant if the mean is 0). Only the channels whose
        variance from the lag products (:meth:`variance`, rounding about 1e-16 of the square of
        the samples' distance from the products' offset) lies below :data:`FLAT_SUSPECT` of that
        square are read over the window."""
        w = self.levels[0].window
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
