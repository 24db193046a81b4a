# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""Diagnostics bookkeeping of ``estimator_node``, with no rclpy (tested alone).

:class:`Health` keeps what ``/diagnostics`` reports: the counters since the node started (the
core's, summed across the estimators that parameter changes replaced, and the node's own
:data:`NODE_COUNTERS`), the last estimate of ``vibration/frequency`` and of each mode with the
time it was published, the input and sampling rates, and the status level. The node calls
:meth:`Health.record` on each published estimate and :meth:`Health.status` once per diagnostics
period, and converts the returned :class:`Status` to a ``diagnostic_msgs/DiagnosticStatus``.

Times ``now`` are seconds of a monotonic clock (the node passes ``time.monotonic()``); ``last_t``
is the time base of the estimator (seconds since the first stamp).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Dict, Mapping, Optional, Sequence, Tuple

from .cadence import CADENCE_COUNTERS

#: levels, equal to ``diagnostic_msgs/DiagnosticStatus``'s
OK, WARN, ERROR, STALE = 0, 1, 2, 3
#: period of /diagnostics of every node, s
DIAGNOSTICS_PERIOD = 1.0
#: the status goes STALE when no input arrived for this long, s
STALE_AFTER = 2.0
#: core counters that grow when the quality gate holds a converged estimate back, or none forms,
#: and why, in words, with the parameter that changes it (issue 37: counters alone are no
#: explanation)
WHY_HELD = {
    'rejected_at_rest': 'no vibration above min_amplitude',
    'rejected_fit': 'the model fits the segment under min_fit',
    'rejected_nyquist': 'above half the sample rate: a faster sensor, or band_hz below it',
    'rejected_damping': 'damped beyond max_damping: a transient',
    'rejected_inconsistent': (
        'each farther than consistency from the one before: a frequency that moves from one '
        'segment to the next; consistency:=0.0 follows it'
    ),
    'max_window_resets': 'no convergence within max_window',
    'not_free_decay': (
        'the signal before each is no free decay, a driven response or an oscillation whose '
        'phase wanders (read for 20-60 s: a driven one goes to the identifier; a minute: a '
        'steady one to the mode tracker); decide_excitation:=false publishes them'
    ),
}
HELD_BACK = tuple(WHY_HELD)
#: counters of bad input: their growth since the previous status makes it WARN (and is logged
#: once per episode): the core's (its short gaps, long ones and the samples they lost, outliers)
#: and the stamps' cadence's (:mod:`.cadence`)
BAD_INPUT = (
    'gaps',
    'samples_lost',
    'skipped_outlier',
    'gap_resets',
    'cadence_gaps',
    'samples_missing',
    'lost_in_queue',
    'missing_in_gaps',
    'stamp_jumps',
)
#: the counters whose growth between two statuses makes the samples used over the span of their
#: stamps no sampling rate (:meth:`Health._update_sample_rate`)
RATE_UPSETS = (
    'gaps',
    'samples_lost',
    'gap_resets',
    'samples_missing',
    'stamp_jumps',
    'skipped_out_of_order',
    'skipped_duplicate',
    'time_jump_resets',
    'skipped_non_finite',
    'dropped_warmup',
    'lost_in_transport',
)
#: the node's own counters: zero header stamps replaced by the receipt time; JointState messages
#: without the configured joint (skipped); samples received while ``band_hz`` reached above the
#: Nyquist frequency of the input's sampling rate; samples dropped while the kernels compiled (the
#: oldest beyond the warm-up buffer of :mod:`.stream`); free estimates held back by the free-decay
#: test while the node decides its excitation (added to ``auto``'s counter of the same name)
NODE_COUNTERS = (
    (
        'zero_stamps_replaced',
        'skipped_joint_missing',
        'band_above_nyquist',
        'dropped_warmup',
        'not_free_decay',
    )
    + CADENCE_COUNTERS
    + ('lost_in_transport',)
)


#: what each sample the core received became
RECEIVED_AS = (
    'used',
    'skipped_non_finite',
    'skipped_duplicate',
    'skipped_out_of_order',
    'skipped_outlier',
)


def identities(counters: Mapping[str, int]) -> Dict[str, bool]:
    """The identities the counters satisfy (docs/nodes.md#what-the-counters-count), by name:
    whether each holds."""
    c = counters
    return {
        'received = used + skipped': c.get('received', 0)
        == sum(c.get(name, 0) for name in RECEIVED_AS),
        'samples_missing = lost_in_queue + missing_in_gaps': c.get('samples_missing', 0)
        == c.get('lost_in_queue', 0) + c.get('missing_in_gaps', 0),
    }


@dataclass(frozen=True)
class Status:
    """One diagnostics status: level (:data:`OK` ...), message, ordered key/values, and a
    warning to log (once per condition; None when there is nothing new to say)."""

    level: int
    message: str
    values: Dict[str, object]
    log: Optional[str] = None


@dataclass
class _Tick:
    """The state at the previous :meth:`Health.status` call."""

    at: float
    messages: int = 0  # received by the core + skipped by the node
    joint_missing: int = 0
    used: int = 0
    last_t: Optional[float] = None
    bad: Optional[Dict[str, int]] = None  # the BAD_INPUT counters
    upsets: Optional[Tuple[int, ...]] = None  # the RATE_UPSETS counters


@dataclass
class _Last:
    """An estimate and the monotonic time it was published."""

    estimate: object
    at: float


#: the aligner's counters whose growth since the previous status is a problem (see
#: :func:`alignment_status`)
ALIGN_PROBLEMS = ('dropped_unaligned', 'dropped_stalled')


def alignment_status(
    status: Status,
    lagging: Sequence[str],
    pending: int,
    counters: Mapping[str, int],
    before: Mapping[str, int],
) -> Status:
    """``status`` of a node reading several input topics (``io.align.StampAligner``): with the
    samples ``pending`` (waiting for a partner) and the ``lagging`` topics (behind the others by
    more than :data:`STALE_AFTER` s of stamps) among its values; WARN (or, STALE, the reason) when
    a topic lags or the :data:`ALIGN_PROBLEMS` counters grew since ``before``."""
    values = {**status.values, 'pending_aligned': pending, 'lagging_topics': ','.join(lagging)}
    problems = []
    if lagging:
        problems.append(
            f'{", ".join(lagging)} behind the other input topics by more than {STALE_AFTER:g} s: '
            'no joint sample until they resume (the others wait, then their oldest are dropped)'
        )
    grown = {name: counters.get(name, 0) - before.get(name, 0) for name in ALIGN_PROBLEMS}
    if grown['dropped_unaligned']:
        problems.append(
            f'{grown["dropped_unaligned"]} samples without a partner within sync_tolerance_s on '
            'every input topic dropped'
        )
    if grown['dropped_stalled']:
        problems.append(f'{grown["dropped_stalled"]} samples dropped waiting for a stalled topic')
    if not problems:
        return replace(status, values=values)
    text = '; '.join(problems)
    message = text if status.level == OK else f'{status.message}; {text}'
    return replace(status, level=max(status.level, WARN), message=message, values=values)


def format_value(value) -> str:
    """A diagnostics value: integers exactly, floats to 9 significant digits, text as it is."""
    return str(value) if isinstance(value, (int, str)) else f'{value:.9g}'


class Health:
    """Counters, last estimates, rates and status of the estimator node (see the module doc).

    ``now``: the monotonic time at start (the first input rate is measured from it).
    """

    def __init__(self, now: float, stale_after: float = STALE_AFTER):
        self.stale_after = stale_after
        self.node_counters: Dict[str, int] = dict.fromkeys(NODE_COUNTERS, 0)
        #: sampling rate of the input from its stamps (NaN until known), Hz
        self.sample_rate_hz = math.nan
        self._base: Dict[str, int] = {}  # core counters of the replaced estimators
        self._last: Optional[_Last] = None  # what vibration/frequency carried last
        self._modes: Dict[int, _Last] = {}
        self._held_at: Dict[str, int] = dict.fromkeys(HELD_BACK, 0)
        self._tick = _Tick(now)
        self._input_at: Optional[float] = None
        self._band_warned: Optional[tuple] = None
        self._bad_warned = False
        self._hinted: Optional[str] = None
        self._upset_before = False  # a RATE_UPSETS counter grew at the previous status
        self._hold = False  # keep the rate over the next status (hold_rate)

    # ---- counters ----------------------------------------------------------------------------
    def count(self, name: str, n: int = 1) -> int:
        """Add ``n`` to one of :data:`NODE_COUNTERS`; return its new value."""
        self.node_counters[name] += n
        return self.node_counters[name]

    def hold_rate(self) -> None:
        """Keep the sampling rate over the next status: samples were lost that no counter shows
        yet (a gap in the stamps not yet told apart, :class:`.cadence.Cadence`: counted a status
        late, and the status before it read 339 Hz for 500 in a suite soak on the Jazzy set)."""
        self._hold = True

    def absorb(self, core_counters: Mapping[str, int]) -> None:
        """Keep the counters of an estimator about to be replaced (they go on adding up)."""
        self.hold_rate()  # (the samples used across it are no rate: _update_sample_rate)
        for name, value in core_counters.items():
            self._base[name] = self._base.get(name, 0) + value

    def totals(self, core_counters: Mapping[str, int]) -> Dict[str, int]:
        """The counters since start: the core's (live estimator + replaced ones), then the
        node's."""
        totals = dict(self._base)
        for counters in (core_counters, self.node_counters):  # one name in both: added
            for name, value in counters.items():
                totals[name] = totals.get(name, 0) + value
        return totals

    @property
    def input_at(self) -> float:
        """The monotonic time of the status that first saw the last input (0 before any)."""
        return self._input_at or 0.0

    # ---- estimates ---------------------------------------------------------------------------
    def record(self, estimate, now: float, totals: Mapping[str, int]) -> None:
        """An estimate was published at ``now``: mode 0 or 1 is the one of ``vibration/frequency``;
        ``totals`` (:meth:`totals`) gives the held-back counters' values at that moment (an
        estimate of any mode clears the WARN of estimates held back)."""
        last = _Last(estimate, now)
        if estimate.mode >= 1:
            self._modes[estimate.mode] = last
        if estimate.mode <= 1:
            self._last = last
        self.count_holds_from(totals)

    def count_holds_from(self, totals: Mapping[str, int]) -> None:
        """The held-back counters count from ``totals`` (:meth:`totals`): at an estimate, and
        when a new configuration runs (what held the one it replaced back no longer says why it
        is silent)."""
        self._held_at = {name: totals.get(name, 0) for name in HELD_BACK}

    @property
    def last_estimate(self):
        """The last estimate of ``vibration/frequency`` (None before the first)."""
        return self._last.estimate if self._last else None

    def forget_modes(self, modes: int) -> None:
        """Drop the records of modes above ``modes`` (after a change of the parameter)."""
        self._modes = {k: v for k, v in self._modes.items() if k <= modes}

    # ---- status ------------------------------------------------------------------------------
    def status(
        self,
        now: float,
        totals: Mapping[str, int],
        last_t: Optional[float],
        band_hz: Optional[Sequence[float]] = None,
        modes: int = 0,
        hint: Optional[str] = None,
        waiting: Optional[str] = None,
    ) -> Status:
        """The status at ``now``; updates the rates and the ``band_above_nyquist`` counter.

        STALE without input for :attr:`stale_after` s; WARN when a :data:`HELD_BACK` counter grew
        since the last estimate (or configuration, :meth:`count_holds_from`), when JointState
        messages lacked the joint since the last call, when ``band_hz`` reaches the Nyquist
        frequency of the input, or with a ``hint`` (what the input shows that the configuration
        does not fit; logged when it starts); OK otherwise, its message ``waiting`` when given
        (what the estimator waits for).
        """
        tick = self._tick
        counted = dict(self.node_counters)  # what this call adds goes into the values too
        messages = totals.get('received', 0) + totals['skipped_joint_missing']
        if messages > tick.messages:
            self._input_at = now
        input_rate = (messages - tick.messages) / (now - tick.at) if now > tick.at else math.nan
        self._update_sample_rate(totals, last_t)
        nyquist, log = self._check_band(band_hz, messages - tick.messages)
        missing = totals['skipped_joint_missing'] - tick.joint_missing
        held = {name: totals.get(name, 0) - self._held_at[name] for name in HELD_BACK}
        problems = []
        if any(held.values()):
            problems.append(
                'held back since the last estimate: '
                + ', '.join(f'{name} {n} ({WHY_HELD[name]})' for name, n in held.items() if n)
            )
        if missing:
            problems.append(f'{missing} messages without the joint')
        if nyquist:
            problems.append(nyquist)
        bad, bad_log = self._check_bad_input(totals)
        if bad:
            problems.append(bad)
        hint_log = hint if hint and not self._hinted else None  # logged when it starts
        self._hinted = hint
        if hint:
            problems.append(hint)
        log = '; '.join(text for text in (log, bad_log, hint_log) if text) or None
        if self._input_at is None or now - self._input_at > self.stale_after:
            level, message = STALE, 'no input'
        elif problems:
            level, message = WARN, '; '.join(problems)
        elif waiting:
            level, message = OK, waiting
        elif self._last is None:
            level, message = OK, 'waiting for a first estimate'
        else:
            level, message = OK, 'estimating'
        self._tick = _Tick(
            now,
            messages,
            totals['skipped_joint_missing'],
            totals.get('used', 0),
            last_t,
            {name: totals.get(name, 0) for name in BAD_INPUT},
            tuple(totals.get(name, 0) for name in RATE_UPSETS),
        )
        values = {
            **self._estimate_values(now),
            'input_rate_hz': input_rate,
            'sample_rate_hz': self.sample_rate_hz,
            **self._mode_values(now, modes),
            **{
                name: n + self.node_counters.get(name, 0) - counted.get(name, 0)
                for name, n in totals.items()
            },
        }
        return Status(level, message, values, log)

    def _check_bad_input(self, totals: Mapping[str, int]):
        """(problem text or None, warning to log or None): gaps and outliers since the previous
        status; the warning is logged when such an episode starts."""
        before = self._tick.bad or dict.fromkeys(BAD_INPUT, 0)
        grown = {name: totals.get(name, 0) - before[name] for name in BAD_INPUT}
        if not any(grown.values()):
            self._bad_warned = False
            return None, None
        parts = []
        if grown['cadence_gaps'] or grown['stamp_jumps']:  # the stamps' cadence (.cadence)
            parts.append(
                f'{grown["cadence_gaps"]} gaps in the stamps ({grown["samples_missing"]} samples '
                f'missing: {grown["lost_in_queue"]} lost in the input queue, the node fell '
                f'behind; {grown["missing_in_gaps"]} never received)'
            )
            if grown['stamp_jumps']:
                parts.append(f'{grown["stamp_jumps"]} forward jumps of the stamps')
        else:  # the core's view (input without a header, or a gap not told apart yet)
            parts.append(
                f'{grown["gaps"] + grown["gap_resets"]} gaps ({grown["samples_lost"]} samples '
                'lost; each restarts the estimate)'
            )
        parts.append(f'{grown["skipped_outlier"]} outliers skipped')
        text = 'input since the last status: ' + ', '.join(parts)
        hint = ': check the sensor and its stamps (a lasting change of rate costs one gap)'
        log = None if self._bad_warned else text + hint
        self._bad_warned = True
        return text, log

    def _update_sample_rate(self, totals: Mapping[str, int], last_t: Optional[float]) -> None:
        """The input's sampling rate from its stamps: samples used over the time they span since
        the previous call (since the first stamp, t = 0, at the first call with input) -- kept
        from before over a call in which, or after one in which, a :data:`RATE_UPSETS` counter
        grew or an estimator was replaced (:meth:`absorb`: a new configuration; its samples
        held while it builds) -- a gap's lost samples, a burst, stamps going back: a stop of 2 s
        read 8.6 Hz for a 500 Hz input, a burst 2190 Hz, and the self-test and the band's
        Nyquist check used them; with the counters alone, one status of the suite's soak
        (restart, stop, storm of parameter sets, burst) still read 365 Hz --, unless none is
        known yet."""
        tick, used = self._tick, totals.get('used', 0)
        upsets = tuple(totals.get(name, 0) for name in RATE_UPSETS)
        upset = (tick.upsets is not None and upsets != tick.upsets) or self._hold
        self._hold = False
        self._upset_before, upset = upset, upset or self._upset_before
        if last_t is None or (upset and math.isfinite(self.sample_rate_hz)):
            return
        if tick.last_t is None:
            n, span = used - 1, last_t
        else:
            n, span = used - tick.used, last_t - tick.last_t
        if n > 0 and span > 0:
            self.sample_rate_hz = n / span

    def _check_band(self, band_hz, received: int):
        """(problem text or None, warning to log or None) for ``band_hz`` against the Nyquist
        frequency; counts the samples received while the band reaches above it. The warning is
        logged once per band, again when the band changes to another one above Nyquist."""
        if band_hz is None or not len(band_hz) or math.isnan(self.sample_rate_hz):
            return None, None
        nyquist = self.sample_rate_hz / 2
        if band_hz[1] < nyquist:
            self._band_warned = None
            return None, None
        self.count('band_above_nyquist', received)
        text = (
            f'band_hz upper edge {band_hz[1]:g} Hz is at or above the Nyquist frequency '
            f'{nyquist:.6g} Hz of the input (sampled at {self.sample_rate_hz:.6g} Hz): '
            'no estimate can form'
        )
        key = tuple(band_hz)
        log = None if self._band_warned == key else text
        self._band_warned = key
        return text, log

    def _estimate_values(self, now: float) -> Dict[str, float]:
        """The last estimate of ``vibration/frequency`` (NaN before the first)."""
        e = self.last_estimate
        nan = math.nan
        return {
            'last_frequency_hz': e.frequency_hz if e else nan,
            'last_frequency_std_hz': e.frequency_std_hz if e else nan,
            'last_convergence_time_s': e.convergence_time if e else nan,
            'last_damping_ratio': e.damping if e else nan,
            'last_damping_std': e.damping_std if e else nan,
            'last_amplitude': e.amplitude if e else nan,
            'last_estimate_age_s': now - self._last.at if e else nan,
        }

    def _mode_values(self, now: float, modes: int) -> Dict[str, float]:
        """``mode<k>_frequency_hz``, ``mode<k>_frequency_std_hz``, ``mode<k>_age_s`` for
        k = 1..modes (NaN for a mode not published yet)."""
        values = {}
        for k in range(1, modes + 1):
            last = self._modes.get(k)
            e = last.estimate if last else None
            values[f'mode{k}_frequency_hz'] = e.frequency_hz if e else math.nan
            values[f'mode{k}_frequency_std_hz'] = e.frequency_std_hz if e else math.nan
            values[f'mode{k}_age_s'] = now - last.at if e else math.nan
        return values
