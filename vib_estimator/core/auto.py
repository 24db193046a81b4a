# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""``excitation = auto``: free decay or driven, decided per stretch of signal (pure numpy).

Both estimators run on every sample: the free-decay one (the algebraic estimator, or the mode
tracker with ``modes`` >= 1, exactly as ``excitation = free``) and the output-only identifier of
:mod:`.ambient`. What publishes is decided by the **envelope**, the variance of the signal over
consecutive blocks of ``ambient_window_s / BLOCKS_PER_WINDOW`` s (at least :data:`MIN_BLOCK_S`):

- a free decay rings down from an onset: after its most energetic block the block energy never
  rises again, and before it (the rest or noise ahead of the onset) it never falls, beyond the
  jitter of a block of a few periods (:data:`RISE`); it peaks at once after the onset;
- a driven response is stationary: its energy falls and rises again, by the statistics of its
  modes' random amplitudes.

An **onset** is a block more than :data:`ONSET` times as energetic as the one before (a pluck, a
move from rest; in a free stretch also over the two before, both rises above :data:`RISE`: a
pluck straddling two blocks), or more than :data:`RISE` times and sudden against the blocks
before it (:data:`SHARP`: a move while the structure still rings), or, in a free stretch one of
whose free estimates passed the free-decay test, any rise above :data:`RISE` after blocks that
rang down (:data:`SETTLE`). While a stretch is free the block lengthens to hold
:data:`BLOCK_PERIODS` periods of its free estimates' frequency (:meth:`Envelope.follow`). A
free stretch becomes **driven** when, over the blocks since the last onset (at most the last
:data:`HORIZON_BLOCKS`), the energy rises by more than :data:`RISE` after the most energetic
block, or falls by more than it before, or the peak comes three or more blocks after the onset
still rising by more than :data:`RISE` over its last two blocks, or two blocks running each rose
by more than :data:`RISE` to the peak; fewer than :data:`MIN_BLOCKS` blocks since an onset, or a
decay, stay free. A driven stretch stays driven (a driven response's energy also wanders down
for a while) until an onset, or until :data:`QUIET_BLOCKS` consecutive blocks are :data:`DROP`
times below its median block: the structure rang down after the forcing stopped. A record
starts free.

A free-decay estimate publishes when its sample ends in a free stretch and (``modes`` = 0) it
passes the free-decay test (:func:`is_free_decay`: the signal before it is one damped sinusoid in
white noise, where a driven mode's amplitude and phase wander), an ambient estimate when it ends
in a driven one: on a record that is a free decay throughout the output is the free estimator's
(the identifier needs a whole window and confirmations before it publishes at all), on a driven
one the identifier's (its first blocks are free until the envelope has shown it is driven, but
their free-decay estimates fail the test).

One ``mode`` scheme (:mod:`.identity`, the rule every estimator shares): every published estimate
continues the mode within :data:`.identity.MATCH_TOL` of its frequency (else starts one), modes
are numbered by ascending frequency, 1 = the lowest, as the mode tracker and the identifier number
theirs; a mode unseen for a window is forgotten (and at most :data:`.identity.MAX_TRACKS` are
known, the least recent forgotten for a new one).
"""

from __future__ import annotations

import dataclasses
import math
from typing import Optional, Sequence, Tuple

import numpy as np

from .ambient import AmbientEstimator
from .config import EstimatorConfig
from .estimator import INPUT_COUNTERS, Estimate, EstimateArrays, Estimator, as_series
from .identity import ModeRegister

#: envelope blocks per ambient window
BLOCKS_PER_WINDOW = 30
#: shortest envelope block, s
MIN_BLOCK_S = 0.25
#: the block holds at least this many periods of the latest free estimate's frequency while the
#: stretch is free: a shorter block's variance depends on the phase it starts at (a 1 s block of a
#: 1.15 Hz decay jitters by more than RISE, read as driven)
BLOCK_PERIODS = 3.0
#: ... grown (or shrunk, when it holds more than twice the periods needed) to this many times the
#: block needed, so that the next estimates' scatter leaves it, and at most the ambient window
#: over this (the envelope decides within MIN_BLOCKS of them)
BLOCK_MARGIN = 1.25
MAX_BLOCK_FRACTION = 3
#: most blocks (since the last onset) the envelope test looks back over
HORIZON_BLOCKS = 10
#: fewest blocks since an onset before a stretch can be called driven
MIN_BLOCKS = 3
#: a rise of the block energy after its peak (or a fall before it) by more than this: driven
RISE = 1.5
#: a block this many times as energetic as the one before is an onset (a new free decay)
ONSET = 10.0
#: ... or more than RISE times, when its log rise is this many times the largest |log ratio| of
#: consecutive blocks before it since the last onset (at least MIN_BLOCKS of them): sudden against
#: a smooth decay (a move while the structure still rings), not a driven response's wandering
SHARP = 6.0
#: in a free stretch one of whose free estimates passed the free-decay test, a block more than
#: RISE times as energetic as the one before, after at least MIN_BLOCKS blocks since the last
#: onset that rang down from their peak (none more than this times the one before), is an onset:
#: a move while the structure still rings (a driven response's energy also falls for a few
#: blocks and rises again, but its free estimates fail the test)
SETTLE = 1.1
#: a driven stretch ends (back to free) when QUIET_BLOCKS consecutive blocks are this many times
#: less energetic than the median block of the driven stretch (its last BLOCKS_PER_WINDOW blocks):
#: the structure rang down after the forcing stopped
DROP = 10.0
#: ... for this many consecutive blocks
QUIET_BLOCKS = 6
#: block energies below this fraction of the horizon's largest count as this fraction (a signal at
#: exact rest does not make ratios of zeros)
FLOOR = 1e-6
#: the states of a stretch
FREE, DRIVEN = 'free', 'driven'
#: the free-decay test of each free estimate (``modes`` = 0): one-period blocks of the signal, half
#: a period apart, over at most this many periods before the estimate's sample
TEST_PERIODS = 8
#: ... after the last block whose amplitude is more than this times every block before it (a
#: pluck: the test starts one block after it; a driven mode's amplitude also jumps by this much
#: between blocks, seldom above all of the last periods)
JUMP = 1.5
#: ... and one block after the blocks that follow it each more than this many times as large as
#: the one before: the vibration still building up (a move's ramp)
BUILD_UP = 1.2
#: ... at least this many blocks (fewer: the estimate is published untested)
TEST_BLOCKS = 3
#: not a free decay when the one-pole prediction of the blocks' complex amplitudes errs by more
#: than NOISE_RATIO x the noise's share (mean square) and by more than INNOVATION of the amplitude
#: (RMS): a driven mode's amplitude takes a random step each half period (~sqrt(2 pi zeta) of it)
NOISE_RATIO = 4.0
INNOVATION = 0.02
#: ... or when its last RECENT_PERIODS alone are a decay within INNOVATION / CLEAN (a ringing that
#: settled into a limit cycle, where the frequency moved with the amplitude: a real arm)
RECENT_PERIODS = 2.5
CLEAN = 4.0
#: the test also fits (per block) the strongest other component of the signal at least one
#: frequency (and a main lobe) above the estimate's, when its periodogram peak is this many times
#: the periodogram's median (a white noise's ordinates: ~exponential, 30 x median ~ exp(-21)): a
#: second mode, ringing or driven, is then neither noise nor misfit
PEAK = 30.0
#: samples kept for the test (at 1 kHz: 8 periods down to 0.12 Hz)
HISTORY = 1 << 16


def is_driven(energies: Sequence[float]) -> bool:
    """The envelope test on consecutive block energies (see the module docstring)."""
    e = np.asarray(energies, dtype=np.float64)
    if len(e) < MIN_BLOCKS:
        return False
    e = np.maximum(e, FLOOR * float(e.max()) + 1e-300)
    p = int(np.argmax(e))
    if p >= 3 and e[p] > RISE * e[p - 2]:  # still rising 3 blocks after an onset: no pluck
        return True
    if p >= 2 and e[p] > RISE * e[p - 1] and e[p - 1] > RISE * e[p - 2]:  # two rises running
        return True
    after = e[p + 1 :]
    if len(after) > 1 and float(np.max(after[1:] / np.minimum.accumulate(after)[:-1])) > RISE:
        return True
    before = e[:p]
    return (
        len(before) > 1 and float(np.max(np.maximum.accumulate(before)[:-1] / before[1:])) > RISE
    )


def other_frequency(t: np.ndarray, y: np.ndarray, f: float) -> Optional[float]:
    """The frequency of the strongest component of ``(t, y)`` at least an octave (and its main
    lobe) above ``f`` Hz and below 0.45 x the rate: another mode, ringing or driven. The peak of
    the Hann-windowed periodogram (zero-padded to at least 4 x), None unless it is :data:`PEAK`
    times the periodogram's median there."""
    n = len(t)
    if n < 8:
        return None
    fs = (n - 1) / float(t[-1] - t[0])
    m = 1 << (4 * n - 1).bit_length()  # a power of two, at least 4 n
    spec = np.abs(np.fft.rfft((y - np.mean(y)) * np.hanning(n), m))
    freq = np.fft.rfftfreq(m, 1 / fs)
    allowed = (freq - f >= max(f, 2 * fs / n)) & (freq <= 0.45 * fs)  # beyond f's main lobe
    if not allowed.any():
        return None
    power = np.where(allowed, spec**2, 0.0)
    k = int(np.argmax(power))
    return float(freq[k]) if power[k] > PEAK * np.median(power[allowed]) else None


def _blocks(t: np.ndarray, y: np.ndarray, f: float, other: Optional[float] = None):
    """The complex amplitudes at ``f`` Hz of one-period blocks of ``(t, y)`` ending every half
    period back from ``t[-1]`` (oldest first) and the noise variance of each (4 x its residual's
    mean square / its samples): each block's mean removed and its projection on the sinusoid at
    ``f``, or (``other``) its least-squares fit of a constant and the sinusoids at ``f`` and at
    ``other`` Hz (the residual's mean square over its degrees of freedom); None if a block holds
    fewer than 4 samples (beyond the fit's parameters)."""
    nb = int(math.floor((t[-1] - t[0]) * 2 * f)) - 1
    if nb < 1:
        return None
    # block k spans the half-period marks k to k + 2
    cuts = np.searchsorted(t, t[-1] - np.arange(nb + 1, -1, -1) / (2 * f), 'right')
    a, b = cuts[:-2], cuts[2:]
    n = b - a
    if np.any(n < 4 + (0 if other is None else 5)):
        return None
    span = slice(cuts[0], cuts[-1])
    fit = _projected if other is None else _fitted
    return fit(t[span] - t[-1], y[span], f, cuts - cuts[0], other)


def _block_sums(x: np.ndarray, cuts: np.ndarray) -> np.ndarray:
    """The sums of each row of ``x`` over the blocks (columns), block ``k`` from ``cuts[k]`` to
    ``cuts[k + 2]``: the half blocks' sums (``np.add.reduceat``, an empty one 0) added in pairs."""
    padded = np.zeros((len(x), x.shape[1] + 1), dtype=x.dtype)  # (numpy.pad's zero, cheaper)
    padded[:, :-1] = x
    halves = np.add.reduceat(padded, cuts[:-1], axis=1)
    halves[:, cuts[:-1] == cuts[1:]] = 0.0
    return halves[:, :-1] + halves[:, 1:]


def _projected(tau, y, f, cuts, other=None):
    """:func:`_blocks` without ``other``, the blocks of ``y`` between ``cuts``
    (:func:`_block_sums`; ``tau``: time from the last sample) from sums: with ``u = y - mean`` and
    ``e = exp(-2 pi i f tau)`` over a block of ``n`` samples, ``c = 2 sum(u e) / n`` and the
    residual ``u - Re(c conj(e))`` has the sum of squares
    ``sum(u^2) - n |c|^2 / 2 + Re(c^2 conj(sum(e^2))) / 2``."""
    n = cuts[2:] - cuts[:-2]
    u = y - np.mean(y)  # the record's offset out of the sums' rounding
    e = np.exp(-2j * math.pi * f * tau)
    sums = _block_sums(np.stack((u, u * u, e, u * e, e * e)), cuts)
    mean = sums[0].real / n
    c = 2 * (sums[3] - mean * sums[2]) / n
    energy = sums[1].real - n * mean * mean
    rss = energy - n * np.abs(c) ** 2 / 2 + np.real(c * c * np.conj(sums[4])) / 2
    return c, 4 * _floored(rss, energy) / (n * n)


def _fitted(tau, y, f, cuts, other):
    """:func:`_blocks` with ``other``: each block's least squares (normal equations) of a
    constant and the sinusoids at ``f`` and ``other`` Hz on ``y`` less the block's mean, from
    sums of the columns' products; the residual's sum of squares ``sum(u^2) - beta . X'u``."""
    n = cuts[2:] - cuts[:-2]
    u = y - np.mean(y)
    w1, w2 = 2 * math.pi * f * tau, 2 * math.pi * other * tau
    x = np.stack((np.ones_like(u), np.cos(w1), -np.sin(w1), np.cos(w2), np.sin(w2)))
    i, j = np.triu_indices(5)
    sums = _block_sums(np.concatenate((x[i] * x[j], x * u, [u * u])), cuts)
    gram = np.empty((len(n), 5, 5))
    gram[:, i, j] = gram[:, j, i] = sums[: len(i)].T
    mean = sums[len(i)] / n  # x[0] u: the block's sum of u
    rhs = (sums[len(i) : len(i) + 5] - mean * sums[:5]).T  # X'(u - mean)
    beta = np.linalg.solve(gram, rhs[..., None])[..., 0]
    energy = sums[-1] - n * mean * mean
    rss = energy - np.sum(beta * rhs, axis=1)
    # y - m = A cos(w tau) - B sin(w tau) + ... = Re(c exp(i w tau)): c = A + iB
    return beta[:, 1] + 1j * beta[:, 2], 4 * _floored(rss, energy) / ((n - 5) * n)


def _floored(rss: np.ndarray, energy: np.ndarray) -> np.ndarray:
    """A residual sum of squares by difference, at least the rounding of ``energy`` (a noiseless
    block)."""
    return np.maximum(rss, np.finfo(float).eps * energy)


def _first_block(c: np.ndarray, periods: float) -> int:
    """The first block the test uses: of the last ``periods`` periods, one block after the last
    :data:`JUMP` (a pluck: a block that many times as large as every block before it) and one
    after the rise that runs on from there, if any (:data:`BUILD_UP`: the excitation still on, a
    move's ramp building the vibration up over a period or more)."""
    amp = np.abs(c)
    rises = np.flatnonzero(np.maximum.accumulate(amp)[:-1] * JUMP < amp[1:])
    first = max(len(c) - int(2 * periods) + 1, rises[-1] + 2 if len(rises) else 0)
    ends = np.flatnonzero(amp[first + 1 :] <= BUILD_UP * amp[first:-1])  # the rise's end
    if not len(ends):
        return len(c)
    run = int(ends[0])  # blocks rising from `first` to the run's peak
    return first + run + (run > 0)


def _tested_blocks(t: np.ndarray, y: np.ndarray, f: float, periods: float, other=None):
    """:func:`_blocks` at ``f`` Hz, fitting the ``other`` component too when given and the blocks
    hold enough samples for it, and the first block the test uses (:func:`_first_block`):
    ``(c, v, first)``, or None when the blocks are too short."""
    got = (other is not None and _blocks(t, y, f, other)) or _blocks(t, y, f)
    return None if got is None else (*got, _first_block(got[0], periods))


def decay_misfit(
    t: np.ndarray, y: np.ndarray, f: float, periods: float = TEST_PERIODS
) -> Optional[Tuple[float, float]]:
    """How far the signal ``(t, y)`` before a free estimate of ``f`` Hz (ending at its sample, the
    last :data:`TEST_PERIODS` periods) is from one damped sinusoid in white noise: the complex
    amplitudes ``c`` of its one-period blocks, half a period apart, after the last :data:`JUMP`
    (looked for one period further back), fitted by ``c[k+1] = r c[k]`` (a decay; the frequency
    refined twice from ``r``'s phase): the prediction error's mean square over the noise's and its
    RMS over the amplitude's. None when fewer than :data:`TEST_BLOCKS` blocks are left (or no
    samples: a stretch of a record that fell in a gap)."""
    if not f > 0 or len(t) < 2:
        return None
    lo = np.searchsorted(t, t[-1] - (periods + 1) / f, 'left')
    t, y = t[lo:], y[lo:]
    other = None
    for step in range(3):
        got = _tested_blocks(t, y, f, periods, other)
        if got is None:
            return None
        c, v, first = got
        if step == 0:  # the other component over the blocks used, from the start of the first
            start = np.searchsorted(t, t[-1] - (len(c) - first + 1) / (2 * f), 'left')
            other = other_frequency(t[start:], y[start:], f)
            if other is not None:
                c, v, first = _tested_blocks(t, y, f, periods, other)
        c, v = c[first:], v[first:]
        if len(c) < TEST_BLOCKS:
            return None
        x, z = c[:-1], c[1:]
        r = np.vdot(x, z) / np.vdot(x, x)
        f += float(np.angle(r)) * f / math.pi  # the phase per half period
    x, z = c[:-1], c[1:]
    err = float(np.mean(np.abs(z - r * x) ** 2))
    noise = float(np.median(v)) * (1 + abs(r) ** 2)
    return err / noise, math.sqrt(err / float(np.mean(np.abs(x) ** 2)))


def is_free_decay(t: np.ndarray, y: np.ndarray, f: float) -> Optional[bool]:
    """Whether the signal before a free estimate of ``f`` Hz is a free decay
    (:func:`decay_verdict`); None when too short to tell."""
    return decay_verdict(t, y, f)[0]


def decay_verdict(
    t: np.ndarray, y: np.ndarray, f: float
) -> tuple[Optional[bool], Optional[tuple]]:
    """:func:`is_free_decay`'s verdict and the misfit it read (:func:`decay_misfit` over the
    last :data:`TEST_PERIODS` periods; None when too short): not a free decay when its
    prediction error exceeds :data:`NOISE_RATIO` x the noise's and :data:`INNOVATION` of the
    amplitude (a driven mode's amplitude and phase wander), unless its last
    :data:`RECENT_PERIODS` are a decay within ``INNOVATION / CLEAN``."""
    m = decay_misfit(t, y, f)
    if m is None or m[0] <= NOISE_RATIO or m[1] <= INNOVATION:
        return (None if m is None else True), m
    recent = decay_misfit(t, y, f, RECENT_PERIODS)
    return recent is not None and recent[1] <= INNOVATION / CLEAN, m


def _is_onset(
    energies: Sequence[float], energy: float, free: bool = False, ringing: bool = False
) -> bool:
    """Whether a block of ``energy`` after the blocks ``energies`` (since the last onset) is an
    onset (see :data:`ONSET`, :data:`SHARP`); ``free``: in a free stretch, whose blocks up to the
    most energetic are its excitation (a move from rest builds up over blocks), a rise sudden
    against the blocks since that one; ``ringing``: a free estimate of the stretch passed the
    free-decay test, and then any rise by more than :data:`RISE` after a ring-down (:data:`SETTLE`)
    is an onset too (a driven response's energy also falls for a few blocks, then rises again: its
    free estimates fail the test)."""
    e = np.asarray(energies, dtype=np.float64)
    e = np.maximum(e, FLOOR * float(e.max()) + 1e-300)
    rise = energy / e[-1]
    if rise > ONSET:
        return True  # a pluck
    if free and len(e) > 1 and energy > ONSET * e[-2] and rise > RISE and e[-1] > RISE * e[-2]:
        return True  # a pluck straddling two blocks (a long one: the stretch's low frequency)
    if ringing and len(e) >= MIN_BLOCKS and _rises_after_ring_down(e, energy):
        return True
    if rise <= RISE or len(e) < MIN_BLOCKS + 1:
        return False
    if free:
        e = e[int(np.argmax(e)) :]
        if len(e) < 2:
            return False
    return math.log(rise) > SHARP * float(np.max(np.abs(np.diff(np.log(e)))))


def _rises_after_ring_down(e: np.ndarray, energy: float) -> bool:
    """Whether a block of ``energy`` rises by more than :data:`RISE` over the block before it, or
    over the one before that through a rising block (a move that straddles two blocks), after
    blocks that rang down from their peak (each at most :data:`SETTLE` x the one before)."""
    for lead in (1, 2):
        base = e[: len(e) - lead + 1]  # up to the block before the rise
        if len(base) < 2 or energy <= RISE * base[-1] or e[-1] < base[-1]:
            continue
        tail = base[int(np.argmax(base)) :]
        if len(tail) >= 2 and np.all(tail[1:] <= SETTLE * tail[:-1]):
            return True
    return False


def _median(values: list[float]) -> float:
    """``numpy.median`` of a short list of floats, none NaN (the same float: the middle one, or
    the two middle ones' sum halved), without its ~20 us of array calls (once a block)."""
    s = sorted(values)
    half = len(s) // 2
    return s[half] if len(s) % 2 else (s[half - 1] + s[half]) / 2


class Envelope:
    """Block energies of the stream and the free/driven state after each completed block.

    The block is ``block_s`` s, lengthened to :data:`BLOCK_PERIODS` periods of a lower frequency
    the stream is found to ring at (:meth:`follow`), up to ``max_block_s``."""

    def __init__(self, block_s: float, max_block_s: float = math.inf):
        self.base_s = block_s
        self.max_block_s = max(block_s, max_block_s)
        self.blocks = {FREE: 0, DRIVEN: 0}  # blocks closed in each state
        self.changes = {'onsets': 0, 'rang_down': 0, 'became_driven': 0}
        self.restart()

    def restart(self) -> None:
        """Forget the signal; the counters (:attr:`blocks`, :attr:`changes`) are kept."""
        self.block_s = self.base_s
        self.seconds = {FREE: 0.0, DRIVEN: 0.0}  # the blocks closed in each state, s
        #: the energy of the blocks closed in each state (their variance x their seconds) and the
        #: largest block variance
        self.energy = {FREE: 0.0, DRIVEN: 0.0}
        self.peak = 0.0
        self.state = FREE
        #: a free estimate of this stretch (since its last onset) passed the free-decay test
        self.ringing = False
        self._t0 = None
        self._last = -math.inf
        self._k = 0
        self._n, self._s1, self._s2 = 0, 0.0, 0.0
        self._energies: list[float] = []  # since the last onset, at most HORIZON_BLOCKS
        self.last_energy: Optional[float] = None  # the last block's
        self._driven: list[float] = []  # the driven stretch's last BLOCKS_PER_WINDOW blocks
        self._quiet = 0  # consecutive blocks DROP below the driven stretch's median

    def fitted_block(self, f: float) -> float:
        """The block for a free estimate of ``f`` Hz: :data:`BLOCK_PERIODS` of its periods at the
        least, :data:`BLOCK_MARGIN` x that when it changes (within the base and the maximum)."""
        need = BLOCK_PERIODS / f if f > 0 and math.isfinite(f) else 0.0
        if need <= self.block_s and (2 * need >= self.block_s or self.block_s == self.base_s):
            return self.block_s
        return min(max(self.base_s, BLOCK_MARGIN * need), self.max_block_s)

    def follow(self, f: float) -> None:
        """Fit the block to a free estimate of ``f`` Hz (:meth:`fitted_block`): the block under
        way goes on with the new length."""
        new = self.fitted_block(f)
        if new == self.block_s:
            return
        if self._t0 is not None:
            self._t0 += self._k * self.block_s
            self._k = 0
        self.block_s = new

    def update(self, t: float, y: float) -> None:
        """One sample (skipped unless finite and later than the last)."""
        if not (math.isfinite(t) and math.isfinite(y)) or t <= self._last:
            return
        self._last = t
        if self._t0 is None:
            self._t0 = t
        k = int((t - self._t0) // self.block_s)
        if k != self._k:
            self._close()
            self._k = k
        self._n += 1
        self._s1 += y
        self._s2 += y * y

    @property
    def last(self) -> float:
        """The stamp of the last sample kept (-inf: none since the start or a restart)."""
        return self._last

    def valid(self, t: np.ndarray, y: np.ndarray) -> np.ndarray:
        """The samples of arrays ``(t, y)`` that :meth:`update` keeps: finite and later than every
        finite stamp before them (the state unchanged)."""
        finite = np.isfinite(t) & np.isfinite(y)
        stamps = np.concatenate(([self._last], np.where(finite, t, -math.inf)))
        return finite & (t > np.maximum.accumulate(stamps)[:-1])

    def all_kept(self, t: np.ndarray, y: np.ndarray) -> bool:
        """Whether :meth:`valid` keeps every sample of arrays ``(t, y)`` (none of them empty):
        the stamps rise strictly from after the last to a finite one (so none is NaN or
        infinite) and the values are finite. A few array calls, where :meth:`valid` takes a
        dozen (the watch's batches each second: all kept)."""
        return bool(
            t[0] > self._last
            and math.isfinite(t[-1])
            and (t[1:] > t[:-1]).all()
            and np.isfinite(y).all()
        )

    def feed(
        self, t: np.ndarray, y: np.ndarray, closes: Optional[list] = None
    ) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`update` for arrays, block by block: ``(valid, driven)`` per sample (kept by
        the envelope's rule; the state after it). The same states as sample by sample: each
        block's sums are sequential (``cumsum``, from the sums carried in), as ``update``'s.
        ``closes``: a list to append, at each block closed, ``(sample, free energy, driven
        energy, onsets)`` (the sample whose arrival closed it; the totals after it)."""
        n = len(t)
        if n and self.all_kept(t, y):
            valid, idx, tv, yv = np.ones(n, dtype=bool), None, t, y
        else:
            valid = self.valid(t, y)
            idx = np.flatnonzero(valid)
            if not len(idx):
                return valid, np.full(n, self.state == DRIVEN)
            tv, yv = (t, y) if len(idx) == n else (t[idx], y[idx])
        if self._t0 is None:
            self._t0 = float(tv[0])
        self._last = float(tv[-1])
        # the first valid sample of each new block closes the one before (k does not decrease:
        # none when the last is in the block under way)
        if ((tv[-1:] - self._t0) // self.block_s).astype(np.int64)[0] == self._k:
            k, starts = None, []
        else:
            k = ((tv - self._t0) // self.block_s).astype(np.int64)
            starts = np.flatnonzero(np.diff(np.concatenate(([self._k], k))) != 0).tolist()
        changes = [(0, self.state == DRIVEN)]
        lo = 0
        for j, hi in zip(starts + [None], starts + [len(tv)]):
            self._add(yv[lo:hi])
            if j is None:
                break
            self._close()
            self._k = int(k[j])
            at = j if idx is None else int(idx[j])
            changes.append((at, self.state == DRIVEN))
            if closes is not None:
                closes.append((at, self.energy[FREE], self.energy[DRIVEN], self.changes['onsets']))
            lo = j
        driven = np.empty(n, dtype=bool)
        for (a, state), (b, _) in zip(changes, changes[1:] + [(n, None)]):
            driven[a:b] = state
        return valid, driven

    def _add(self, part: np.ndarray) -> None:
        """Add the samples ``part`` of the block under way to its sums, in sequence."""
        if len(part):
            self._n += len(part)
            sums = np.empty((2, len(part) + 1))  # the sums carried in, then the samples, squared
            sums[:, 0] = self._s1, self._s2
            sums[0, 1:] = part
            np.multiply(part, part, out=sums[1, 1:])
            self._s1, self._s2 = np.cumsum(sums, axis=1)[:, -1].tolist()  # (each row in turn)

    def _close(self) -> None:
        n = self._n
        if n < 2:  # an empty block (a gap): nothing to add
            self._n, self._s1, self._s2 = 0, 0.0, 0.0
            return
        m = self._s1 / n
        energy = max(0.0, self._s2 / n - m * m)
        self._n, self._s1, self._s2 = 0, 0.0, 0.0
        e = self._energies
        self.last_energy = energy
        onset = bool(e) and _is_onset(e, energy, self.state == FREE, self.ringing)
        if onset:
            self.ringing = False
            e.clear()
            self.changes['onsets'] += 1
        e.append(energy)
        del e[:-HORIZON_BLOCKS]
        if self.state == DRIVEN:
            level = _median(self._driven)
            self._quiet = self._quiet + 1 if energy * DROP < level else 0
            if onset or self._quiet >= QUIET_BLOCKS:
                self.changes['rang_down'] += not onset
                self.state = FREE
                self._driven = []
                e[:] = e[-1:] if onset else e[-MIN_BLOCKS:]
            else:
                self._driven = (self._driven + [energy])[-BLOCKS_PER_WINDOW:]
        elif is_driven(e):
            self.state = DRIVEN
            self.ringing = False
            self.changes['became_driven'] += 1
            self._driven, self._quiet = list(e), 0
        self.blocks[self.state] += 1
        self.seconds[self.state] += self.block_s
        self.energy[self.state] += energy * self.block_s
        self.peak = max(self.peak, energy)


class AutoEstimator(Estimator):
    """The free-decay estimator and the ambient identifier, each publishing in its own stretches
    (see the module docstring)."""

    def __init__(self, config: EstimatorConfig, free):
        """``free``: the estimator of ``config`` with ``excitation = free`` (a
        :class:`~.estimator.FrequencyEstimator` or a mode tracker: ``create_estimator``)."""
        config.validate()
        self._config = config
        self._free = free
        self._ambient = AmbientEstimator(config.replace(excitation='ambient'))
        self._envelope = Envelope(
            max(MIN_BLOCK_S, config.ambient_window_s / BLOCKS_PER_WINDOW),
            config.ambient_window_s / MAX_BLOCK_FRACTION,
        )
        self._modes = ModeRegister(config.ambient_window_s, replace=True)  # the known modes
        self._published = {FREE: 0, DRIVEN: 0}
        self._test = config.modes == 0  # the free-decay test of each free estimate
        self._not_free = 0  # free estimates the test held back
        self._history = np.empty((2, 2 * HISTORY))  # the last HISTORY valid samples (t, y)
        self._filled = 0

    @property
    def block_s(self) -> float:
        """The envelope's block, s (now)."""
        return self._envelope.block_s

    @property
    def driven_s(self) -> float:
        """The seconds of signal the envelope has read as driven (its closed blocks)."""
        return self._envelope.seconds[DRIVEN]

    @property
    def state(self) -> str:
        """``free`` or ``driven``: the stretch the last sample ends."""
        return self._envelope.state

    @property
    def counters(self) -> dict[str, int]:
        """The free-decay estimator's counters, the identifier's others (those of the same name
        as ``ambient_`` + name: ``ambient_rejected_damping``, ``ambient_estimates``) and the
        envelope's blocks in each state (``free_blocks``, ``driven_blocks``) and the estimates
        each published (``estimates_free``, ``estimates_driven``)."""
        c = dict(self._free.counters)
        for name, n in self._ambient.counters.items():
            if name not in c:
                c[name] = n
            elif name not in INPUT_COUNTERS:
                c['ambient_' + name] = n
        c.update(self._envelope.changes)
        c['free_blocks'] = self._envelope.blocks[FREE]
        c['driven_blocks'] = self._envelope.blocks[DRIVEN]
        c['not_free_decay'] = self._not_free
        c['estimates_free'] = self._published[FREE]
        c['estimates_driven'] = self._published[DRIVEN]
        c['estimates'] = self._published[FREE] + self._published[DRIVEN]
        return c

    def mode_counters(self) -> dict[int, dict[str, int]]:
        """Each known mode's estimates, by its number."""
        return self._modes.counters()

    def restart(self) -> None:
        """Forget the signal and the known modes; counters are kept (the envelope's too)."""
        for part in (self._free, self._ambient, self._envelope):
            part.restart()
        self._modes.clear()
        self._filled = 0

    def reset(self) -> None:
        self._free.reset()
        self._ambient.reset()

    def _jumped_back(self) -> None:
        """A sample's stamp jumped back beyond ``max_gap`` from the last kept (a source
        restarted, a bag looping): the envelope, the free-decay test's samples and the known
        modes start afresh, as the two estimators do by themselves
        (:func:`~.estimator.accept_sample`): else the envelope skipped every sample until the
        stamps passed the old ones (a restarted simulator: nothing published for minutes)."""
        self._envelope.restart()
        self._modes.clear()
        self._filled = 0

    # ---- streaming ----------------------------------------------------------------------------
    def _remember(self, t: float, y: float) -> None:
        """Keep a valid sample (the envelope's rule) for the free-decay test."""
        if not (math.isfinite(t) and math.isfinite(y)) or (
            self._filled and t <= self._history[0, self._filled - 1]
        ):
            return
        if self._filled == self._history.shape[1]:
            self._history[:, :HISTORY] = self._history[:, HISTORY:]
            self._filled = HISTORY
        self._history[:, self._filled] = t, y
        self._filled += 1

    def _passes(self, t: np.ndarray, y: np.ndarray, f: float) -> bool:
        """The free-decay test of a free estimate of ``f`` Hz whose sample ends ``(t, y)`` (at
        most :data:`HISTORY` valid samples); an untestable one passes. One that passes tells the
        envelope its stretch rings freely (``ringing``), as any does with the test off
        (``modes`` >= 1: the envelope alone decides)."""
        verdict = is_free_decay(t[-HISTORY:], y[-HISTORY:], f) if self._test else None
        self._envelope.ringing |= verdict is True or not self._test
        self._not_free += verdict is False
        return verdict is not False

    def update(self, t: float, y: float) -> list[Estimate]:
        """Feed one sample; the estimates it completes that belong to the current stretch."""
        tf, yf = float(t), float(y)
        if self._envelope.last - tf > self._config.max_gap:
            self._jumped_back()
        self._envelope.update(tf, yf)
        self._remember(tf, yf)
        free = self._free.update(t, y)
        self._ambient.idle = self._envelope.state == FREE
        ambient = self._ambient.update(t, y)
        if self._envelope.state == FREE:
            for e in free:
                self._envelope.follow(e.frequency_hz)
            h = self._history[:, : self._filled]
            chosen = [e for e in free if self._passes(h[0], h[1], e.frequency_hz)]
        else:
            chosen = ambient
        state = self._envelope.state
        return [
            dataclasses.replace(e, mode=self._rank(e.frequency_hz, e.t, state)) for e in chosen
        ]

    def process(self, t: Sequence[float], y: Sequence[float]) -> EstimateArrays:
        """Feed arrays (continuing the stream); the same estimates as :meth:`update`, by time
        (a batch is cut where its stamps jump back beyond ``max_gap``: :meth:`_jumped_back`)."""
        t, y = as_series(t, y)
        parts = []
        while True:
            last = self._envelope.last
            finite = np.where(np.isfinite(t) & np.isfinite(y), t, -math.inf)
            ahead = np.maximum.accumulate(np.concatenate(([last], finite)))[:-1]
            back = np.flatnonzero(ahead - t > self._config.max_gap)
            if len(back) and back[0] == 0:
                self._jumped_back()
                continue
            if not len(back):
                break
            parts.append(self._process_run(t[: back[0]], y[: back[0]]))
            t, y = t[back[0] :], y[back[0] :]
        parts.append(self._process_run(t, y))
        return parts[0] if len(parts) == 1 else EstimateArrays.concatenate(parts, by_time=False)

    def _process_run(self, t: np.ndarray, y: np.ndarray) -> EstimateArrays:
        """:meth:`process` of a batch whose stamps do not jump back beyond ``max_gap``."""
        free = self._free.process(t, y)
        # the history before this call, then this call's valid samples (the envelope's rule)
        valid = self._envelope.valid(t, y)
        ht = np.concatenate((self._history[0, : self._filled], t[valid]))
        hy = np.concatenate((self._history[1, : self._filled], y[valid]))
        upto = self._filled + np.cumsum(valid)  # valid samples so far, after each sample
        # the state after each sample (a sample completes at most one block's decision) and the
        # free estimates that pass
        states, passed = self._feed_envelope(t, y, free, (ht, hy, upto))
        ambient = self._identify(t, y, states)
        n_keep = min(HISTORY, len(ht))
        self._history[:, :n_keep] = ht[len(ht) - n_keep :], hy[len(hy) - n_keep :]
        self._filled = n_keep
        parts, driven = [], []
        for est, want in ((free, False), (ambient, True)):
            if not want:
                keep = passed
            else:
                keep = states[self._samples(t, est.t)] if len(t) else np.zeros(0, dtype=bool)
            parts.append(est.where(keep))
            driven.append(np.full(int(np.sum(keep)), want))
        # by time, stable: at one stamp the free estimate first, an analysis's modes in order
        kind = np.concatenate(driven)[
            np.argsort(np.concatenate([p.t for p in parts]), kind='stable')
        ]
        out = EstimateArrays.concatenate(parts)
        out.mode[:] = [
            self._rank(f, s, DRIVEN if k else FREE)
            for f, s, k in zip(out.frequency_hz.tolist(), out.t.tolist(), kind.tolist())
        ]
        return out

    @staticmethod
    def _samples(t: np.ndarray, stamps: np.ndarray) -> np.ndarray:
        """Each estimate's sample: the last one with its stamp (where it counts, they increase)."""
        return np.clip(np.searchsorted(t, stamps, 'right') - 1, 0, max(len(t) - 1, 0))

    def _feed_envelope(
        self, t: np.ndarray, y: np.ndarray, free: EstimateArrays, history
    ) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`Envelope.feed` of a batch, in pieces that end at its ``free`` estimates' samples,
        each of them, where the stretch is free, followed and tested (``history``: the valid
        samples ``(t, y)`` and how many end each sample of the batch), as :meth:`update` has it:
        the state after each sample and whether each free estimate publishes."""
        env = self._envelope
        ht, hy, upto = history
        passed = np.zeros(len(free), dtype=bool)
        lo, parts = 0, []
        for j, (k, f) in enumerate(
            zip(self._samples(t, free.t).tolist(), free.frequency_hz.tolist())
        ):
            parts.append(env.feed(t[lo : k + 1], y[lo : k + 1])[1])
            lo = k + 1
            if env.state == FREE:
                env.follow(f)
                kept = slice(max(0, int(upto[k]) - HISTORY), int(upto[k]))  # its history
                passed[j] = self._passes(ht[kept], hy[kept], f)
        parts.append(env.feed(t[lo:], y[lo:])[1])
        return np.concatenate(parts), passed

    def _identify(self, t: np.ndarray, y: np.ndarray, driven: np.ndarray) -> EstimateArrays:
        """The identifier's estimates of a batch whose samples end ``driven`` stretches (else
        free): it runs idle over each run of free samples, as :meth:`update` has it."""
        edges = [0, *(np.flatnonzero(np.diff(driven)) + 1).tolist(), len(t)]
        parts = []
        for a, b in zip(edges[:-1], edges[1:]):
            if b > a:
                self._ambient.idle = not driven[a]
                parts.append(self._ambient.process(t[a:b], y[a:b]))
        return EstimateArrays.concatenate(parts)

    def _rank(self, f: float, t: float, kind: str) -> int:
        """The mode number, in the shared scheme, of a ``kind`` estimate of ``f`` Hz at ``t``."""
        self._published[kind] += 1
        mode = self._modes.observe_one(f, t)
        mode.estimates += 1
        return self._modes.number(mode)
