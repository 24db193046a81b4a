# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""The header stamps' cadence of an input: what never reached the node, counted (no rclpy).

The estimator core counts what it is given (``received``, ``used``, the ``skipped_*``) and restarts
on a long step between stamps (``gaps``, ``gap_resets``, each with its ``samples_lost``). What the
node could have seen but did not take is counted here, from the stamps of every message taken, in
the order taken, with the steady time of its arrival:

* the **period** of the stamps, learnt as an exponential average of the regular steps;
* a step longer than :data:`GAP_FACTOR` periods is a **gap** in the cadence whatever its length:
  ``round(step / period) - 1`` samples are missing (``samples_missing``, in ``cadence_gaps``
  gaps). Each gap is then told apart by how the node took the :data:`DRAIN_SAMPLES` messages after
  it: faster than :data:`DRAIN_RATIO` times the live rate of the stamps (stamp seconds per steady
  second, learnt over :data:`RATE_WINDOW_S` windows without a gap) means the node was draining a
  backlog -- the queue in front of it had overflowed (the keep-last history replacing the oldest,
  or the transport's buffers while the process was stopped) and its samples are
  ``lost_in_queue``; otherwise the messages came at the live pace after the gap: the
  samples never reached the queue (not sent, or lost on the way) and are ``missing_in_gaps``. So
  ``samples_missing == lost_in_queue + missing_in_gaps`` at every moment (a gap is counted once it
  is told apart: after :data:`DRAIN_SAMPLES` messages, or :data:`DECIDE_AFTER_S` s, whichever
  comes first);
* a forward step that the steady time since the previous message cannot account for -- stamps
  advancing more than :data:`JUMP_RATIO` times faster than their live rate (or than real time,
  until the rate is known), beyond :data:`JUMP_FLOOR_S` s of steady time -- is a **jump** of the
  stamps' clock (a simulator restarted ahead, a clock set): ``stamp_jumps``, one restart of the
  estimator, no sample counted missing (it counted 2 145 170 samples lost for a jump of 4290 s);
* a step back is the core's business (a small one skipped, one beyond ``max_gap`` restarts it):
  the cadence follows the stamps from there.

The middleware's own count of samples it dropped before the queue (the DDS sample-lost status) is
``lost_in_transport``, counted by the node; those samples are among ``samples_missing`` too.
"""

from __future__ import annotations

import math
from typing import Dict, Optional

#: what :class:`Cadence` counts (the node's diagnostics carry them), and the re-creations of an
#: input subscription by the :class:`Watchdog`
CADENCE_COUNTERS = (
    'cadence_gaps',
    'samples_missing',
    'lost_in_queue',
    'missing_in_gaps',
    'stamp_jumps',
    'input_resubscribed',
)
#: a step longer than this many periods misses at least one sample (``round(step / period) - 1``)
GAP_FACTOR = 1.5
#: weight of a regular step in the running period
PERIOD_WEIGHT = 1.0 / 64.0
#: the messages after a gap that tell a drained backlog from a live stream
DRAIN_SAMPLES = 16
#: stamps taken this many times faster than their live rate after a gap: a backlog was drained
DRAIN_RATIO = 2.0
#: a gap not told apart after this long (steady s, the stream stopped) is counted as missing
DECIDE_AFTER_S = 0.5
#: steady time over which the live rate of the stamps is measured, s
RATE_WINDOW_S = 0.25
#: weight of one window in the live rate
RATE_WEIGHT = 0.25
#: stamps advancing more than this many times faster than their live rate over one step: a jump
JUMP_RATIO = 20.0
#: steady time below which a step's steady duration is taken as this (a jump right after the
#: previous message is compared with this much time), s
JUMP_FLOOR_S = 1.0


class Cadence:
    """The cadence of one stream of stamps (see the module doc); counts into ``counters``
    (:data:`CADENCE_COUNTERS` added to it when missing)."""

    def __init__(self, counters: Optional[Dict[str, int]] = None, back_ns: Optional[int] = None):
        #: a step back longer than this (ns; None: 1000 periods) is followed (the core restarts)
        self.back_ns = back_ns
        self.counters = {} if counters is None else counters
        for name in CADENCE_COUNTERS:
            self.counters.setdefault(name, 0)
        #: the running period of the stamps, ns (0 until two stamps)
        self.period = 0.0
        #: the live rate: stamp seconds per steady second (NaN until measured)
        self.rate = math.nan
        self._last: Optional[int] = None
        self._last_at = 0.0
        self._taken_at = 0.0  # steady s of the last message taken, whatever its stamp
        self._window: Optional[tuple] = None  # (steady s, stamp ns) of its start; None: a gap
        self._gap: Optional[list] = None  # [missing, stamp ns, steady s, messages since]

    def observe(self, stamp: int, now: float) -> bool:
        """A message of stamp ``stamp`` (ns) taken at ``now`` (steady s); True when its step is a
        forward jump (the caller restarts the estimator)."""
        self._taken_at = now
        last = self._last
        gap = self._gap
        if gap is not None:
            gap[3] += 1
            if gap[3] >= DRAIN_SAMPLES or now - gap[2] > DECIDE_AFTER_S:
                self._decide(stamp, now)
        if last is None:
            self._last, self._last_at, self._window = stamp, now, (now, stamp)
            return False
        h = stamp - last
        if h <= 0:  # a duplicate or a step back: the core's (the cadence follows a big one)
            if -h > (1000 * self.period if self.back_ns is None else self.back_ns):
                self._last, self._last_at, self._window = stamp, now, None
            return False
        since = now - self._last_at
        self._last, self._last_at = stamp, now
        period = self.period
        if period <= 0.0:
            self.period = float(h)
            return False
        if h <= GAP_FACTOR * period:
            self.period = period + PERIOD_WEIGHT * (h - period)
            self._measure_rate(stamp, now)
            return False
        rate = self.rate if self.rate == self.rate else 1.0  # real time until measured
        if h * 1e-9 > JUMP_RATIO * rate * max(since, JUMP_FLOOR_S):
            self.counters['stamp_jumps'] += 1
            self._window = None
            return True
        if gap is not None and self._gap is gap:  # a gap while deciding the previous one
            self._decide(stamp, now)
        self._gap = [round(h / period) - 1, stamp, now, 0]
        self._window = None
        return False

    @property
    def gap_pending(self) -> bool:
        """Whether a gap waits to be told apart (its samples not yet counted)."""
        return self._gap is not None

    @property
    def taken_at(self) -> float:
        """Steady time of the last message taken, whatever its stamp (0 before the first): a
        source restarted a little back in time, whose stamps stay behind the last one followed
        for a while, is not silent (the watchdog reads this)."""
        return self._taken_at

    @property
    def period_s(self) -> float:
        """The expected steady time between messages: the period over the live rate (NaN until
        both are known)."""
        if self.period <= 0.0 or not self.rate > 0.0:
            return math.nan
        return self.period * 1e-9 / self.rate

    def flush(self, now: float) -> None:
        """Decide a gap that waited :data:`DECIDE_AFTER_S` s (the stream stopped after it)."""
        if self._gap is not None and now - self._gap[2] > DECIDE_AFTER_S:
            self._decide(self._last, now)

    def _decide(self, stamp: int, now: float) -> None:
        """Count the pending gap: lost in the queue when the stamps after it were taken faster
        than :data:`DRAIN_RATIO` times their live rate, else missing."""
        missing, at_stamp, at, n = self._gap
        self._gap = None
        c = self.counters
        c['cadence_gaps'] += 1
        c['samples_missing'] += missing
        span = now - at
        drained = (
            n > 0
            and self.rate == self.rate
            and (stamp - at_stamp) * 1e-9 > DRAIN_RATIO * self.rate * span
        )
        c['lost_in_queue' if drained else 'missing_in_gaps'] += missing

    def _measure_rate(self, stamp: int, now: float) -> None:
        window = self._window
        if window is None or self._gap is not None:  # no window across a gap's backlog
            self._window = (now, stamp)
            return
        span = now - window[0]
        if span < RATE_WINDOW_S:
            return
        rate = (stamp - window[1]) * 1e-9 / span
        known = self.rate == self.rate
        self.rate = self.rate + RATE_WEIGHT * (rate - self.rate) if known else rate
        self._window = (now, stamp)


#: the watchdog: silence for this many expected periods of the input (or at least
#: :data:`WATCHDOG_MIN_S`) with a publisher matched re-creates the subscription
WATCHDOG_PERIODS = 1000
#: the shortest silence that re-creates the subscription, steady s (beyond the STALE status, 2 s)
WATCHDOG_MIN_S = 3.0
#: the longest wait between two re-creations while the silence lasts, steady s
WATCHDOG_MAX_S = 60.0
#: checks further apart than this (steady s; the node checks every second) mean the node itself
#: was held (a SIGSTOP, a starved CPU): the silence is measured again from then
WATCHDOG_HELD_S = 2.0


class Watchdog:
    """Never deaf: when a publisher is matched but no message was taken for
    :data:`WATCHDOG_PERIODS` expected periods (at least :data:`WATCHDOG_MIN_S` s) after input
    once flowed, :meth:`check` says to re-create the subscription; while the silence lasts it says
    so again after twice as long each time (up to :data:`WATCHDOG_MAX_S` s: a publisher that is
    only paused costs a few cheap re-creations); a message taken ends the episode."""

    def __init__(self):
        self._taken_at = 0.0  # steady s of the last message seen taken (0: none yet)
        self._since = 0.0  # steady s of that message, or of the last re-creation
        self._wait = WATCHDOG_MIN_S
        self._checked = math.inf  # steady s of the previous check
        #: re-creations in the current silence (0: data flows)
        self.episode = 0

    def check(self, now: float, taken_at: float, matched: int, period_s: float) -> bool:
        """True when the subscription should be re-created now: the last message was taken at
        ``taken_at`` (steady s; 0: none yet), ``matched`` publishers, input expected every
        ``period_s`` steady s (NaN: unknown)."""
        held, self._checked = now - self._checked > WATCHDOG_HELD_S, now
        if taken_at > self._taken_at:  # data flows: a new episode may start
            self._taken_at = self._since = taken_at
            self._wait = WATCHDOG_MIN_S
            self.episode = 0
        if held:  # the node itself was held (stopped, starved): no silence measured across it
            # (after the message taken: one taken just before the stall began is older than it)
            self._since = max(self._since, now)
        if self._taken_at <= 0.0 or matched <= 0:
            return False
        wait = self._wait
        if self.episode == 0 and period_s == period_s:
            wait = max(wait, WATCHDOG_PERIODS * period_s)
        if now - self._since < wait:
            return False
        self.episode += 1
        self._since = now
        self._wait = min(2 * wait, WATCHDOG_MAX_S)
        return True
