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
move from rest), or more than :data:`RISE` times and sudden against the blocks before it
(:data:`SHARP`: a move while the structure still rings). A free stretch becomes **driven** when,
over the blocks since the last onset (at most the last :data:`HORIZON_BLOCKS`), the energy rises
by more than :data:`RISE` after the most energetic block, or falls by more than it before, or the
peak comes three or more blocks after the onset still rising by more than :data:`RISE` over its
last two blocks; fewer than :data:`MIN_BLOCKS` blocks since an onset, or a decay, stay free. A
driven stretch stays driven (a driven response's energy also wanders down for a while) until an
onset, or until :data:`QUIET_BLOCKS` consecutive blocks are :data:`DROP` times below its median
block: the structure rang down after the forcing stopped. A record starts free.

A free-decay estimate publishes when its sample ends in a free stretch and (``modes`` = 0) it
passes the free-decay test (:func:`is_free_decay`: the signal before it is one damped sinusoid in
white noise, where a driven mode's amplitude and phase wander), an ambient estimate when it ends
in a driven one: on a record that is a free decay throughout the output is the free estimator's
(the identifier needs a whole window and confirmations before it publishes at all), on a driven
one the identifier's (its first blocks are free until the envelope has shown it is driven, but
their free-decay estimates fail the test).

One ``mode`` scheme: every published estimate continues the mode within
:data:`~.ambient.MATCH_TOL` of its frequency (else starts one), modes are numbered by ascending
frequency, 1 = the lowest, as the mode tracker and the identifier number theirs; a mode unseen for
a window is forgotten.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Optional, Sequence, Tuple

import numpy as np

from .ambient import MATCH_TOL, AmbientEstimator
from .config import EstimatorConfig
from .estimator import Estimate, EstimateArrays, as_series

#: envelope blocks per ambient window
BLOCKS_PER_WINDOW = 30
#: shortest envelope block, s
MIN_BLOCK_S = 0.25
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
#: ... after the last block whose amplitude is more than this times the one before it (a pluck:
#: the test starts one block after it)
JUMP = 1.5
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
    after = e[p + 1 :]
    if len(after) > 1 and float(np.max(after[1:] / np.minimum.accumulate(after)[:-1])) > RISE:
        return True
    before = e[:p]
    return (
        len(before) > 1 and float(np.max(np.maximum.accumulate(before)[:-1] / before[1:])) > RISE
    )


def _blocks(t: np.ndarray, y: np.ndarray, f: float):
    """The complex amplitudes at ``f`` Hz of one-period blocks of ``(t, y)`` ending every half
    period back from ``t[-1]`` (oldest first; each block's mean removed) and the noise variance of
    each (4 x its residual's mean square / its samples); None if a block holds < 4 samples."""
    w = 2 * math.pi * f
    nb = int(math.floor((t[-1] - t[0]) * 2 * f)) - 1
    ends = t[-1] - np.arange(nb)[::-1] / (2 * f)
    a = np.searchsorted(t, ends - 1 / f, 'right')
    b = np.searchsorted(t, ends, 'right')
    if nb < 1 or np.any(b - a < 4):
        return None
    c, v = np.empty(nb, dtype=np.complex128), np.empty(nb)
    for k, (i, j) in enumerate(zip(a.tolist(), b.tolist())):
        yb = y[i:j] - np.mean(y[i:j])
        e = np.exp(-1j * w * (t[i:j] - t[-1]))
        c[k] = 2 * np.mean(yb * e)
        v[k] = 4 * np.mean((yb - np.real(c[k] * np.conj(e))) ** 2) / (j - i)
    return c, v


def decay_misfit(
    t: np.ndarray, y: np.ndarray, f: float, periods: float = TEST_PERIODS
) -> Optional[Tuple[float, float]]:
    """How far the signal ``(t, y)`` before a free estimate of ``f`` Hz (ending at its sample, the
    last :data:`TEST_PERIODS` periods) is from one damped sinusoid in white noise: the complex
    amplitudes ``c`` of its one-period blocks, half a period apart, after the last :data:`JUMP`
    (looked for one period further back), fitted by ``c[k+1] = r c[k]`` (a decay; the frequency
    refined twice from ``r``'s phase): the prediction error's mean square over the noise's and its
    RMS over the amplitude's. None when fewer than :data:`TEST_BLOCKS` blocks are left."""
    lo = np.searchsorted(t, t[-1] - (periods + 1) / f, 'left')
    t, y = t[lo:], y[lo:]
    for _ in range(3):
        got = _blocks(t, y, f) if f > 0 else None
        if got is None:
            return None
        c, v = got
        amp = np.abs(c)
        rises = np.flatnonzero(amp[:-1] * JUMP < amp[1:])
        first = max(len(c) - int(2 * periods) + 1, rises[-1] + 2 if len(rises) else 0)
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
    (:func:`decay_misfit`): not when its prediction error exceeds :data:`NOISE_RATIO` x the
    noise's and :data:`INNOVATION` of the amplitude (a driven mode's amplitude and phase wander),
    unless its last :data:`RECENT_PERIODS` are a decay within ``INNOVATION / CLEAN``; None when
    too short to tell."""
    m = decay_misfit(t, y, f)
    if m is None or m[0] <= NOISE_RATIO or m[1] <= INNOVATION:
        return None if m is None else True
    recent = decay_misfit(t, y, f, RECENT_PERIODS)
    return recent is not None and recent[1] <= INNOVATION / CLEAN


def _is_onset(energies: Sequence[float], energy: float) -> bool:
    """Whether a block of ``energy`` after the blocks ``energies`` (since the last onset) is an
    onset (see :data:`ONSET`, :data:`SHARP`)."""
    e = np.asarray(energies, dtype=np.float64)
    e = np.maximum(e, FLOOR * float(e.max()) + 1e-300)
    rise = energy / e[-1]
    if rise > ONSET:
        return True
    if rise <= RISE or len(e) < MIN_BLOCKS + 1:
        return False
    return math.log(rise) > SHARP * float(np.max(np.abs(np.diff(np.log(e)))))


class Envelope:
    """Block energies of the stream and the free/driven state after each completed block."""

    def __init__(self, block_s: float):
        self.block_s = block_s
        self.restart()

    def restart(self) -> None:
        self.state = FREE
        self._t0 = None
        self._last = -math.inf
        self._k = 0
        self._n, self._s1, self._s2 = 0, 0.0, 0.0
        self._energies: list[float] = []  # since the last onset, at most HORIZON_BLOCKS
        self._driven: list[float] = []  # the driven stretch's last BLOCKS_PER_WINDOW blocks
        self._quiet = 0  # consecutive blocks DROP below the driven stretch's median
        self.blocks = {FREE: 0, DRIVEN: 0}  # blocks closed in each state
        self.changes = {'onsets': 0, 'rang_down': 0, 'became_driven': 0}

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

    def feed(self, t: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`update` for arrays, block by block: ``(valid, driven)`` per sample (kept by
        the envelope's rule; the state after it). The same states as sample by sample: each
        block's sums are sequential (``cumsum``, from the sums carried in), as ``update``'s."""
        n = len(t)
        finite = np.isfinite(t) & np.isfinite(y)
        # valid: finite and later than every finite stamp before it (the valid ones increase)
        stamps = np.concatenate(([self._last], np.where(finite, t, -math.inf)))
        valid = finite & (t > np.maximum.accumulate(stamps)[:-1])
        driven = np.zeros(n, dtype=bool)
        idx = np.flatnonzero(valid)
        if not len(idx):
            driven[:] = self.state == DRIVEN
            return valid, driven
        tv, yv = t[idx], y[idx]
        if self._t0 is None:
            self._t0 = float(tv[0])
        self._last = float(tv[-1])
        k = ((tv - self._t0) // self.block_s).astype(np.int64)
        # the first valid sample of each new block closes the one before
        starts = np.flatnonzero(np.diff(np.concatenate(([self._k], k))) != 0)
        ends = np.concatenate((starts, [len(k)]))
        changes = [(0, self.state == DRIVEN)]
        lo = 0
        for j, hi in zip(starts.tolist() + [None], ends.tolist()):
            part = yv[lo:hi]
            if len(part):
                self._n += len(part)
                self._s1 = float(np.cumsum(np.concatenate(([self._s1], part)))[-1])
                self._s2 = float(np.cumsum(np.concatenate(([self._s2], part * part)))[-1])
            if j is None:
                break
            self._close()
            self._k = int(k[j])
            changes.append((int(idx[j]), self.state == DRIVEN))
            lo = j
        for (a, state), (b, _) in zip(changes, changes[1:] + [(n, None)]):
            driven[a:b] = state
        return valid, driven

    def _close(self) -> None:
        n = self._n
        if n < 2:  # an empty block (a gap): nothing to add
            self._n, self._s1, self._s2 = 0, 0.0, 0.0
            return
        m = self._s1 / n
        energy = max(0.0, self._s2 / n - m * m)
        self._n, self._s1, self._s2 = 0, 0.0, 0.0
        e = self._energies
        onset = bool(e) and _is_onset(e, energy)
        if onset:
            e.clear()
            self.changes['onsets'] += 1
        e.append(energy)
        del e[:-HORIZON_BLOCKS]
        if self.state == DRIVEN:
            level = float(np.median(self._driven))
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
            self.changes['became_driven'] += 1
            self._driven, self._quiet = list(e), 0
        self.blocks[self.state] += 1


class AutoEstimator:
    """The free-decay estimator and the ambient identifier, each publishing in its own stretches
    (see the module docstring)."""

    def __init__(self, config: EstimatorConfig, free):
        """``free``: the estimator of ``config`` with ``excitation = free`` (a
        :class:`~.estimator.FrequencyEstimator` or a mode tracker: ``create_estimator``)."""
        config.validate()
        self._config = config
        self._free = free
        self._ambient = AmbientEstimator(config.replace(excitation='ambient'))
        self._envelope = Envelope(max(MIN_BLOCK_S, config.ambient_window_s / BLOCKS_PER_WINDOW))
        self._modes: list[list[float]] = []  # [frequency, last t] of the known modes
        self._published = {FREE: 0, DRIVEN: 0}
        self._test = config.modes == 0  # the free-decay test of each free estimate
        self._not_free = 0  # free estimates the test held back
        self._history = np.empty((2, 2 * HISTORY))  # the last HISTORY valid samples (t, y)
        self._filled = 0

    @property
    def config(self) -> EstimatorConfig:
        return self._config

    @property
    def block_s(self) -> float:
        """The envelope's block, s."""
        return self._envelope.block_s

    @property
    def state(self) -> str:
        """``free`` or ``driven``: the stretch the last sample ends."""
        return self._envelope.state

    @property
    def counters(self) -> dict[str, int]:
        """The free-decay estimator's counters, the identifier's own (``ambient_`` + name) and
        the envelope's blocks in each state (``free_blocks``, ``driven_blocks``) and the estimates
        each published (``estimates_free``, ``estimates_driven``)."""
        c = dict(self._free.counters)
        for name, n in self._ambient.counters.items():
            if name not in c:
                c[name] = n
            elif name == 'estimates':
                c['ambient_estimates'] = n
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
        order = sorted(self._modes, key=lambda m: m[0])
        return {k: {'estimates': int(m[2])} for k, m in enumerate(order, 1)}

    def restart(self) -> None:
        self._free.restart()
        self._ambient.restart()
        self._envelope.restart()
        self._modes = []
        self._filled = 0

    def reset(self) -> None:
        self._free.reset()
        self._ambient.reset()

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
        most :data:`HISTORY` valid samples); an untestable one passes."""
        ok = not self._test or is_free_decay(t[-HISTORY:], y[-HISTORY:], f) is not False
        self._not_free += not ok
        return ok

    def update(self, t: float, y: float) -> list[Estimate]:
        """Feed one sample; the estimates it completes that belong to the current stretch."""
        self._envelope.update(float(t), float(y))
        self._remember(float(t), float(y))
        free = self._free.update(t, y)
        ambient = self._ambient.update(t, y)
        if self._envelope.state == FREE:
            chosen = [] if free is None else (free if isinstance(free, list) else [free])
            h = self._history[:, : self._filled]
            chosen = [e for e in chosen if self._passes(h[0], h[1], e.frequency_hz)]
        else:
            chosen = ambient
        state = self._envelope.state
        return [
            dataclasses.replace(e, mode=self._rank(e.frequency_hz, e.t, state)) for e in chosen
        ]

    def process(self, t: Sequence[float], y: Sequence[float]) -> EstimateArrays:
        """Feed arrays (continuing the stream); the same estimates as :meth:`update`, by time."""
        t, y = as_series(t, y)
        free = self._free.process(t, y)
        ambient = self._ambient.process(t, y)
        # the state after each sample (a sample completes at most one block's decision) and the
        # samples the history keeps (the envelope's rule)
        valid, states = self._envelope.feed(t, y)
        # the history before this call, then this call's valid samples
        ht = np.concatenate((self._history[0, : self._filled], t[valid]))
        hy = np.concatenate((self._history[1, : self._filled], y[valid]))
        upto = self._filled + np.cumsum(valid)  # valid samples so far, after each sample
        n_keep = min(HISTORY, len(ht))
        self._history[:, :n_keep] = ht[len(ht) - n_keep :], hy[len(hy) - n_keep :]
        self._filled = n_keep
        names = list(EstimateArrays.__dataclass_fields__)
        parts, driven = [], []
        for est, want in ((free, False), (ambient, True)):
            # an estimate's sample: the last one with its stamp (stamps increase where it counts)
            idx = np.clip(np.searchsorted(t, est.t, 'right') - 1, 0, max(len(t) - 1, 0))
            keep = states[idx] == want if len(t) else np.zeros(0, dtype=bool)
            if not want:
                for k in np.flatnonzero(keep).tolist():
                    n = int(upto[idx[k]])
                    lo = max(0, n - HISTORY)
                    keep[k] = self._passes(ht[lo:n], hy[lo:n], float(est.frequency_hz[k]))
            parts.append(EstimateArrays(**{n: getattr(est, n)[keep] for n in names}))
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

    def _rank(self, f: float, t: float, kind: str) -> int:
        """The mode number, in the shared scheme, of a ``kind`` estimate of ``f`` Hz at ``t``."""
        self._published[kind] += 1
        window = self._config.ambient_window_s
        self._modes = [m for m in self._modes if t - m[1] <= window]
        near = min(self._modes, key=lambda m: abs(f / m[0] - 1), default=None)
        if near is None or abs(f / near[0] - 1) > MATCH_TOL:
            near = [f, t, 0]
            self._modes.append(near)
        near[0], near[1], near[2] = f, t, near[2] + 1
        return 1 + sum(m[0] < f for m in self._modes if m is not near)
