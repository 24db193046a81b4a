# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""Welch's spectrum and its prominent peaks, in numpy: what :mod:`.choice` took from
``scipy.signal`` (``welch``, ``find_peaks``), whose import alone cost ``analyze`` 0.8 CPU s
under scipy 1.17 (0.3 under Ubuntu 24.04's 1.11; ``docs/startup.md``), as much as the rest of a
warm ``analyze`` of a short record.

The same steps in the same order as scipy's (``scipy.signal._spectral_py``,
``_peak_finding_utils``): the periodic Hann window, half-overlapping segments each less its
mean, the one-sided density averaged over the segments; the local maxima (a plateau's middle) and
their prominences. The floats differ from scipy's by the FFT's rounding (numpy's, not
``scipy.fft``'s) at most; ``test/core/test_spectra.py`` compares both.
"""

from __future__ import annotations

import numpy as np


def welch(y: np.ndarray, fs: float, nperseg: int) -> tuple[np.ndarray, np.ndarray]:
    """``scipy.signal.welch(y, fs, nperseg=nperseg, axis=0, detrend='constant')``: the Hann
    window (periodic), ``nperseg // 2`` overlap, the one-sided density, the segments' mean;
    ``y`` samples (x channels), at least ``nperseg`` of them."""
    y = np.asarray(y, dtype=np.float64)
    fac = np.linspace(-np.pi, np.pi, nperseg + 1)
    win = np.zeros(nperseg + 1)
    win += 0.5 * np.cos(0 * fac)  # scipy's general_cosine, term by term
    win += 0.5 * np.cos(fac)
    win = win[:-1]
    scale = 1.0 / (fs * (win * win).sum())
    step = nperseg - nperseg // 2
    count = (len(y) - nperseg) // step + 1
    starts = np.arange(count) * step
    # segments x nperseg (x channels), then the samples last, as scipy arranges them
    seg = np.stack([y[s : s + nperseg] for s in starts])
    seg = np.moveaxis(seg, 1, -1)
    seg = seg - np.mean(seg, axis=-1, keepdims=True)
    spec = np.fft.rfft(win * seg, n=nperseg)
    spec = np.conjugate(spec) * spec
    spec *= scale
    if nperseg % 2:
        spec[..., 1:] *= 2
    else:
        spec[..., 1:-1] *= 2
    psd = np.moveaxis(spec.real, 0, -1).mean(axis=-1)  # (channels x) bins, mean of the segments
    return np.fft.rfftfreq(nperseg, 1 / fs), np.moveaxis(psd, -1, 0) if psd.ndim > 1 else psd


#: :func:`peaks_by_prominence` looks this far for a higher sample in Python floats, then with
#: numpy (a noisy spectrum's thousand local maxima find one within a few bins; a tall peak's
#: search runs to the ends)
SCAN = 64


def peaks_by_prominence(x: np.ndarray, minimum: float) -> np.ndarray:
    """``scipy.signal.find_peaks(x, prominence=minimum)[0]``: the indices of the local maxima
    of ``x`` (a plateau: its middle, rounded down; not the ends) whose prominence (their height
    above the higher of the lowest points between them and a higher sample on either side) is at
    least ``minimum``. Over Python floats (the same comparisons and minima as numpy's, without
    its scalars: a 5000-bin spectrum's peaks took 16 ms)."""
    x = np.asarray(x, dtype=np.float64)
    xs = x.tolist()
    n = len(xs)
    keep = []
    i = 1
    while i < n - 1:
        if xs[i - 1] < xs[i]:
            ahead = i + 1
            while ahead < n - 1 and xs[ahead] == xs[i]:
                ahead += 1
            if xs[ahead] < xs[i]:
                p = (i + ahead - 1) // 2
                if xs[p] - max(_lowest(x, xs, p, -1), _lowest(x, xs, p, 1)) >= minimum:
                    keep.append(p)
                i = ahead
        i += 1
    return np.array(keep, dtype=np.intp)


def _lowest(x: np.ndarray, xs: list, p: int, step: int) -> float:
    """The lowest sample from peak ``p`` (included) to the first higher one on its left
    (``step`` -1) or right (1), excluded, or to the end: ``xs``'s floats for :data:`SCAN`
    samples, then numpy's over the rest (a NaN between: NaN, as ``numpy.min``)."""
    top, low, j = xs[p], xs[p], p + step
    for _ in range(SCAN):
        if not 0 <= j < len(xs) or xs[j] > top:
            return low
        if not xs[j] >= low:  # lower, or NaN (which then stays)
            low = xs[j] if low == low else low
        j += step
    if step < 0:
        higher = np.flatnonzero(x[: j + 1] > top)
        rest = x[(higher[-1] + 1 if len(higher) else 0) : j + 1]
    else:
        higher = np.flatnonzero(x[j:] > top)
        rest = x[j : (j + higher[0] if len(higher) else len(x))]
    if not len(rest) or low != low:
        return low
    far = float(np.min(rest))
    return far if not far >= low else low  # (NaN there: NaN)
