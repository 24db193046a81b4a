# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""What a record needs, decided from the record itself: the default of ``vib-estimator analyze``
(no ``--excitation``, no ``--paper``), where the whole record is at hand (pure numpy/scipy).

A newcomer passes no option; a plucked beam, a machine driven without rest and a building under
wind each need another estimator and, when driven, a window sized to the structure. From the
first :data:`DECIDE_S` seconds of the record (all channels):

1. **The spectrum** (Welch, segments of :data:`SEGMENT_S` s): its peaks standing
   :data:`PEAK_DB` above their surroundings (prominence) and holding at least
   :data:`PEAK_SHARE` of the strongest one's power; the strongest is the **dominant** frequency,
   the lowest the **fundamental**.
2. **Free or driven**, by the envelope of :mod:`.auto` (:class:`.auto.Envelope`) over the record's
   first principal component (one channel: the signal), its block :data:`.auto.BLOCK_PERIODS`
   x :data:`.auto.BLOCK_MARGIN` periods of the dominant frequency (a 1 s block of a 0.8 Hz
   decay jitters by more than the envelope tests): the share of the record's energy in what it
   reads as driven (the envelope starts free and needs a few blocks to tell: a record driven
   throughout shows 80-98 %; the noise a decay rings down into weighs nothing).
   Below :data:`FREE_BELOW`: ``free`` (the algebraic estimator, exactly as ``--excitation free``);
   above :data:`DRIVEN_ABOVE`: ``ambient`` (output-only identification); between, one channel:
   ``auto`` (per stretch), several: the larger share's (the joint estimators take free or
   ambient).
3. **The window** of a driven record: :data:`WINDOW_PERIODS` periods of the fundamental
   (about 15 correlation times ``1 / (2 pi zeta f)`` of a mode at zeta = 2 %: the frequency of a
   lightly damped mode scatters by more than 2 % across windows of a few correlation times, and
   the identifier drops it), at least the configured ``ambient_window_s`` and at most
   :data:`MAX_WINDOW_S`, and no longer than the record allows :data:`MIN_ANALYSES` analyses of.

Each decision carries its reasons in words (:attr:`Decision.reason`), which ``analyze`` prints.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .auto import BLOCK_MARGIN, BLOCK_PERIODS, MIN_BLOCK_S, Envelope

#: the first seconds of a record the decision reads
DECIDE_S = 600.0
#: samples stamped beyond this many seconds are not read (an absurd stamp)
MAX_STAMP_S = 1e12
#: ... nor values farther from the median than this many median absolute deviations (a pluck of
#: 1 in a long record of 1e-4 noise stands at ~1e4)
ABSURD = 1e6
#: Welch segment, s (0.05 Hz resolution: a 1.2 Hz building mode's peak stands apart)
SEGMENT_S = 20.0
#: a spectral peak's prominence over its surroundings, dB
PEAK_DB = 10.0
#: ... and its power at least this share of the strongest peak's
PEAK_SHARE = 1e-3
#: a record whose envelope reads driven for less than this share of its time is a free decay
FREE_BELOW = 0.1
#: ... and one read driven for more than this share is driven throughout (the envelope's first
#: blocks of a driven record read free: 80-98 % measured, a 1.2 Hz mode's 3 s blocks the least)
DRIVEN_ABOVE = 0.7
#: a driven record's window, in periods of its fundamental (~15 correlation times at zeta 2 %)
WINDOW_PERIODS = 120.0
#: the longest window the decision chooses, s
MAX_WINDOW_S = 300.0
#: the window leaves the record room for at least this many analyses (one per second)
MIN_ANALYSES = 60


@dataclass(frozen=True)
class Decision:
    """The excitation a record needs, the ambient window (s) for a driven one, what the decision
    saw and why, in words."""

    excitation: str
    window_s: float
    driven_share: float
    dominant_hz: float
    fundamental_hz: float
    peaks_hz: tuple = field(default=())
    reason: str = ''
    #: the seconds and the mean sampling rate of what was read
    span_s: float = math.nan
    rate_hz: float = math.nan


def principal_component(y: np.ndarray) -> np.ndarray:
    """One signal from ``y`` (samples, or samples x channels): the projection of the centred
    channels on their covariance's leading eigenvector (one channel: the signal centred)."""
    y = np.asarray(y, dtype=np.float64)
    y = y - np.mean(y, axis=0)
    if y.ndim == 1 or y.shape[1] == 1:
        return y.reshape(-1)
    _, vectors = np.linalg.eigh(y.T @ y)
    return y @ vectors[:, -1]


def spectral_peaks(t: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(frequencies, powers)`` of the spectrum's peaks (module docstring, 1), strongest first,
    summed over the channels of ``y``."""
    from scipy.signal import find_peaks, welch

    fs = (len(t) - 1) / float(t[-1] - t[0])
    y = np.asarray(y, dtype=np.float64).reshape(len(t), -1)
    nper = int(min(len(t), max(64, round(SEGMENT_S * fs))))
    freq, psd = welch(y, fs, nperseg=nper, axis=0, detrend='constant')
    psd = np.sum(psd, axis=1)
    level = 10 * np.log10(np.maximum(psd, 1e-300 + 1e-12 * float(np.max(psd))))
    idx, _ = find_peaks(level, prominence=PEAK_DB)
    idx = idx[freq[idx] > 2 * fs / nper]  # above the segment's own lowest bins (a drift)
    if not len(idx):
        return np.empty(0), np.empty(0)
    order = idx[np.argsort(psd[idx])[::-1]]
    order = order[psd[order] >= PEAK_SHARE * psd[order[0]]]
    return freq[order], psd[order]


def driven_share(t: np.ndarray, signal: np.ndarray, dominant_hz: float) -> float:
    """The share of the record's energy (``signal`` centred, squared) in the samples the envelope
    (:class:`.auto.Envelope`, its block fitted to ``dominant_hz``) reads as driven: the noise a
    free decay rings down into (a stationary tail the envelope reads as driven) weighs nothing
    beside the decay."""
    block = MIN_BLOCK_S
    if dominant_hz > 0:
        block = max(MIN_BLOCK_S, BLOCK_MARGIN * BLOCK_PERIODS / dominant_hz)
    valid, driven = Envelope(block).feed(t, signal)
    energy = np.where(valid, (signal - np.mean(signal[valid])) ** 2, 0.0)
    total = float(np.sum(energy))
    return float(np.sum(energy[driven])) / total if total > 0 else 0.0


def decide(t, y, channels: int = 1, window_s: float = 30.0) -> Decision:
    """The :class:`Decision` for the record ``(t, y)`` (its first :data:`DECIDE_S` s are read;
    ``y`` samples or samples x ``channels``), ``window_s`` the shortest window (the configured
    one)."""
    t = np.asarray(t, dtype=np.float64)
    y = np.asarray(y, dtype=np.float64)
    # finite samples at sane times (an absurd stamp, 1e300 s, would overflow the block index)
    keep = (np.abs(t) < MAX_STAMP_S) & np.all(np.isfinite(y.reshape(len(t), -1)), axis=1)
    t, y = t[keep], y[keep]
    if len(t):  # an absurd value (1e300: the estimator skips it as an outlier) is not read
        dev = np.abs(y - np.median(y, axis=0)).reshape(len(t), -1)
        mad = np.median(dev, axis=0)
        keep = np.all(dev <= ABSURD * np.maximum(mad, np.max(mad) + 1e-300), axis=1)
        t, y = t[keep], y[keep]
    if len(t) > 1:
        n = int(np.searchsorted(t, t[0] + DECIDE_S, 'right'))
        t, y = t[:n], y[:n]
    if len(t) < 64 or not t[-1] > t[0]:
        return Decision('free', window_s, 0.0, math.nan, math.nan, (), 'too short to tell: free')
    peaks, _ = spectral_peaks(t, y)
    dominant = float(peaks[0]) if len(peaks) else math.nan
    fundamental = float(np.min(peaks)) if len(peaks) else math.nan
    share = driven_share(t, principal_component(y), dominant if len(peaks) else 0.0)
    span = float(t[-1] - t[0])
    seen = (
        f'{100 * share:.0f} % of the energy of {span:.0f} s read driven by the envelope; spectral '
        'peaks at '
        + (', '.join(f'{f:.3g}' for f in sorted(peaks[:8])) + ' Hz' if len(peaks) else 'none')
    )
    if share < FREE_BELOW:
        excitation = 'free'
    elif share > DRIVEN_ABOVE or channels > 1:
        excitation = 'ambient' if share >= 0.5 else 'free'
    else:
        excitation = 'auto'
    window = window_s
    if excitation != 'free' and math.isfinite(fundamental):
        room = max(window_s, span - MIN_ANALYSES)
        window = min(max(window_s, WINDOW_PERIODS / fundamental), MAX_WINDOW_S, room)
        seen += (
            f'; window {window:.0f} s ({window * fundamental:.0f} periods of {fundamental:.3g} Hz)'
        )
    rate = (len(t) - 1) / span
    return Decision(
        excitation, window, share, dominant, fundamental, tuple(peaks), seen, span, rate
    )
