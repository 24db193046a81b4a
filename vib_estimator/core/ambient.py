# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""Output-only (operational, ambient) identification of the modes of a driven structure, over a
sliding window of any number of channels: the streaming side.

``excitation = ambient``: the structure is driven by broadband, unmeasured forces (wind, traffic, a
robot that never rests), so there is no free decay to fit. Its modes are identified from the
correlation structure of the response over a sliding window, as operational modal analysis does.
With several channels (accelerometers, the three axes of an IMU, the joints of an arm) the modes
are identified jointly from all channels' correlations, each with its **shape** -- how much, and
in which phase, each channel moves in it (docs/channels.md). One channel is the case m = 1 (one
path, one set of fixes).

Interface (:class:`~vib_estimator.core.Estimator`): :class:`AmbientEstimator` ``(config,
channels=())`` ``.update(t, y) -> list[Estimate]``, ``.process(t, y) -> EstimateArrays`` (one
channel) or :class:`~.estimator.JointEstimates` (several named ``channels``, ``y``: samples x
channels), ``.counters``, ``.reset()``, ``.restart()``, ``.config``, ``.channels``.

Method, per analysis, once ``ambient_window_s`` of samples are in: every :data:`HOP_S` (1 s) of
input while a mode is to be confirmed, every :func:`hop_s` (a fifth of the window, 1-5 s) once
every mode tracked is published:

1. **The window's correlations** (:mod:`.correlations`): kept up to date as samples arrive at the
   input rate, and at the rates halved from it, whose unmoved middle is kept.
2. **Its modes** (:mod:`.ssi`, the mathematics with their references): covariance-driven
   stochastic subspace identification over a stabilisation diagram, the physical poles clustered
   into modes with their shapes; each mode's frequency refined to the maximum of the Whittle
   likelihood and its standard deviations the Whittle bound (:mod:`.whittle`).
3. **Calibrated standard deviations**: the bound scaled up by the factor the mode's own
   estimates from non-overlapping earlier windows show it to be too small (variance across
   windows: :meth:`_Track.calibration`).
4. **Identity over time** (stability across windows; :mod:`.identity`, the rule every estimator
   shares): each mode continues the nearest tracked mode within :data:`.identity.MATCH_TOL`
   whose last shape it matches (with one channel every shape matches); the MAC between the two
   is published with a joint estimate. A new mode publishes once seen by
   :data:`.identity.CONFIRM` consecutive analyses (beside a stronger published mode
   :data:`.identity.CONFIRM_BESIDE`, or as many as span :data:`BESIDE_SHARE` of a long window:
   :func:`beside_analyses`; ``modes_found``), a published one whenever seen; one unseen for a
   window is lost (``modes_lost``). With ``modes`` >= 1 at most that many (the strongest) publish.
   Published modes are numbered by ascending frequency, 1 = the lowest, as the mode tracker's
   ``mode`` key.

Each estimate: ``t`` = the window's last stamp, ``convergence_time`` = the window's span (the
window used), ``samples`` = its samples, ``amplitude`` = RMS of the modal response (summed in
quadrature over channels), ``fit`` = share of the window's (summed) variance the modes explain;
with several channels its ``shape``, ``shape_std`` (the spread over the stable model orders) and
``mac`` with the mode's previous shape (NaN for a mode's first window).

Bad samples never raise: a sample with a non-finite value (on any channel), duplicate and
out-of-order stamps are
skipped and counted; a gap or a backward jump longer than ``max_gap`` starts a new window
(``gap_resets``, ``time_jump_resets``); the tracked modes are kept.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from .config import EstimatorConfig
from .correlations import CorrelationCascade
from .estimator import (
    INPUT_COUNTERS,
    Estimate,
    EstimateArrays,
    Estimator,
    JointEstimates,
    accept_rows,
    accept_sample,
    as_series,
    channel_names,
    make_room,
)
from .identity import CONFIRM, CONFIRM_BESIDE, Mode, ModeRegister
from .ssi import BLOCK_ROWS, WindowModes, block_rows, identify
from .threads import single_blas_thread
from .whittle import load_kernels

#: seconds of input between two analyses (the estimates' update period) of a short window
#: (:func:`hop_s`)
HOP_S = 1.0
#: a longer window is analysed every this share of it: consecutive windows that share most of
#: their samples give nearly the same estimates, each at the cost of a whole analysis (the
#: identifier's whole cost; issue 37 asks >= 1000x real time per 500 Hz channel: a 30 s window
#: every second ran ~310x) ...
HOP_SHARE = 0.2
#: ... but at least every this many seconds (a long window on a short record still gives
#: estimates enough to confirm and calibrate its modes)
MAX_HOP_S = 5.0
#: fewest samples a window must hold to be analysed (twice the one channel's lags, and two)
MIN_WINDOW_SAMPLES = 4 * BLOCK_ROWS + 2
#: while modes are known, one analysis in this many searches the full rate for higher ones
SEARCH_EVERY = 5
#: a mode's estimates over this many windows calibrate its stds (:meth:`_Track.calibration`)
HISTORY_WINDOWS = 4

#: a mode within this (relative) of one of ``lines_hz`` is the periodic drive's line
#: (``rejected_line``): the identifier reads a line to ~1e-5, the decision refines it to ~1e-4
#: (core.choice.peak_kurtosis), and a mode 3 % from a harmonic (the arm's 1.331 Hz beside its
#: 4-s cycle's 1.375 Hz) stays apart
LINE_TOL = 0.01
#: a new mode beside a stronger published one publishes after analyses running that span at
#: least this share of the window (:func:`beside_analyses`; at least CONFIRM_BESIDE, the 8 of a
#: 30 s window): consecutive windows share most of their samples, so a statistical pole of one
#: stretch of noise lasts as many analyses as the windows hold of that stretch. A 600 s record
#: of 0.7 + 2.3 Hz at 100 Hz (171 s window: the default's) published such poles at 2.1 or
#: 2.46 Hz (5-6 estimates) on 2 of 6 seeds with 8; none with 43 (and the Heritage Court Tower,
#: 96 s window: its 6 published modes, no 6.4 Hz one)
BESIDE_SHARE = 0.25

COUNTER_NAMES = INPUT_COUNTERS + (
    'analyses',
    'analyses_idle',
    'rejected_damping',
    'rejected_unstable',
    'rejected_weak',
    'rejected_uncertain',
    'rejected_line',
    'flat_windows',
    'modes_found',
    'modes_lost',
    'estimates',
)


def beside_analyses(window_s: float) -> int:
    """Analyses running a new mode beside a stronger published one needs to publish, with a
    window of ``window_s``: :data:`.identity.CONFIRM_BESIDE`, or more: as many as span
    :data:`BESIDE_SHARE` of the window at one a second (:data:`HOP_S`, the hop while a mode is
    to be confirmed)."""
    return max(CONFIRM_BESIDE, math.ceil(BESIDE_SHARE * window_s / HOP_S))


def hop_s(window_s: float) -> float:
    """Seconds of input between two analyses of a window of ``window_s``: :data:`HOP_SHARE` of
    it, at least :data:`HOP_S` and at most :data:`MAX_HOP_S`."""
    return max(HOP_S, min(MAX_HOP_S, HOP_SHARE * window_s))


# ---- streaming ----------------------------------------------------------------------------------
class _Track(Mode):
    """A mode followed across windows (:class:`.identity.Mode`), with its recent estimates."""

    __slots__ = ('history',)

    def __init__(self, frequency: float, t: float, shape=None):
        super().__init__(frequency, t, shape)
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


class AmbientEstimator(Estimator):
    """The output-only identifier of one channel or of several named ``channels`` (at least
    :data:`.estimator.MIN_CHANNELS`; their count is the number of columns fed; see the module
    docstring): the samples' buffer (a row of values a sample), their checks and counters, the
    runs of clean samples of a batch, the window each analysis reads (:meth:`_next_window`), its
    identification (:func:`.ssi.identify`) and the modes' identity over time (:meth:`_track`)."""

    def __init__(self, config: EstimatorConfig, channels: Sequence[str] = ()):
        config.validate()
        if channels:
            hint = ' (one channel: excitation ambient, one column)'
            self.channels = channel_names(channels, 'a joint identification', hint)
        self._config = config
        self._window = config.ambient_window_s
        self._band = config.band_hz or (0.0, math.inf)
        self._c = dict.fromkeys(COUNTER_NAMES, 0)
        self._m = m = max(len(self.channels), 1)
        self._t = np.empty(1 << 14)  # the window's stamps (its values: in the cascade)
        beside = beside_analyses(self._window)
        self._register = ModeRegister(self._window, CONFIRM, beside, new=_Track)
        self._cascade = CorrelationCascade(2 * block_rows(m), m)
        load_kernels()  # (the Whittle kernels: now, not at the first analysis)
        #: samples fed one at a time since the last analysis (stamps, values): appended to the
        #: buffer at once when one is due (:meth:`_store`), not one numpy write each
        self._pending_t: list[float] = []
        self._pending_y: list = []
        self._max_gap = config.max_gap
        self._clear_window = self.reset  # (bound once: the data path's)
        self._clean = 0  # samples taken by update's fast path (counted received and used)
        self._one_gap = config.max_gap if m == 1 else -math.inf  # (the fast path: one channel)
        #: while True, a window that is due only slides (counted ``analyses_idle``): nothing is
        #: identified or published, the tracked modes wait (``excitation = auto`` in a free
        #: stretch, where the identifier's estimates would not publish)
        self.idle = False
        self.restart()

    @property
    def counters(self) -> dict[str, int]:
        c = dict(self._c)
        c['received'] += self._clean  # (the samples :meth:`update` took by its fast path)
        c['used'] += self._clean
        return c

    def restart(self) -> None:
        """Forget the signal and the tracked modes; counters are kept."""
        self._register.clear()
        self._last = -math.inf
        self._since_search = math.inf  # analyses since the last search (the first searches)
        self.reset()

    def reset(self) -> None:
        """Start a new window at the next sample (the tracked modes are kept): the next estimates
        come from samples after this call (and after a gap or a jump back)."""
        self._n = 0  # samples in the buffer
        self._start = 0  # first sample of the current window
        self._pending_t.clear()
        self._pending_y.clear()
        self._cascade.clear()
        self._next = math.inf

    def process(self, t: Sequence[float], y):
        """Feed arrays of samples (``y``: samples, or samples x channels; continuing the
        stream); the estimates by time (:class:`~.estimator.JointEstimates` of several
        channels)."""
        t, y = as_series(t, y, self.channels)
        y = y.reshape(len(t), self._m)
        out = self._feed(t, y, np.isfinite(t) & np.isfinite(y).all(axis=1))
        return JointEstimates.of(out, self.channels) if self.channels else EstimateArrays.of(out)

    def update(self, t: float, y) -> list:
        """Feed one sample (one value per channel); the estimates of an analysis it completes
        (ascending mode)."""
        last = self._last
        if y.__class__ is float and last < t <= last + self._one_gap and y - y == 0.0:
            # the data path's sample (one channel's finite float, after the last, no gap: what
            # accept_sample keeps without a restart), counted at once (``_clean``)
            self._clean += 1
            value = y
        else:
            if isinstance(y, float) and self._m == 1:  # (a float or numpy float64: no array)
                value, finite = y, math.isfinite(y)
            else:
                value = np.asarray(y, dtype=np.float64).reshape(-1).tolist()
                if len(value) != self._m:
                    raise ValueError(f'expected {self._m} channel values, got {len(value)}')
                finite = all(map(math.isfinite, value))
            t = float(t)
            # a gap or a long jump back clears the window
            if not accept_sample(self._c, last, t, finite, self._max_gap, self._clear_window):
                return []
        self._last = t
        self._pending_t.append(t)
        self._pending_y.append(value)
        if t >= self._next:
            return self._analysis()
        if self._next == math.inf:  # the window's first sample (after a reset)
            self._next = t + self._window
        return []

    def mode_counters(self) -> dict[int, dict[str, int]]:
        """Each current mode's estimates (as the mode tracker's ``mode_counters``)."""
        return self._register.counters()

    # ---- input --------------------------------------------------------------------------------
    def _store(self) -> None:
        """Append the samples fed one at a time (:meth:`update`) to the buffer."""
        if self._pending_t:
            t = np.array(self._pending_t, dtype=np.float64)
            y = np.array(self._pending_y, dtype=np.float64).reshape(len(t), self._m)
            self._pending_t.clear()
            self._pending_y.clear()
            self._append(t, y)

    def _append(self, t: np.ndarray, y: np.ndarray) -> None:
        """Append samples: stamps ``t`` and their rows ``y`` (after those fed one at a time)."""
        self._store()
        m = len(t)
        if self._n + m > len(self._t):
            self._t = make_room(self._t, self._start, self._n, m)
            self._n, self._start = self._n - self._start, 0
        self._t[self._n : self._n + m] = t
        self._cascade.push(y)
        if self._n == 0:
            self._next = float(self._t[0]) + self._window
        self._n += m

    def _due(self) -> list:
        """The analysis due now (:func:`.ssi.identify` of the window, :meth:`_track`), or,
        :attr:`idle`, only the window's slide."""
        self._store()
        if self.idle:
            self._slide()
            self._c['analyses_idle'] += 1
            return []
        window = self._next_window()
        if window is None:
            return []
        ts, cascade, fs, span, known, search = window
        modes, total = identify(
            cascade, fs, self._config.max_damping, self._band, self._c, known, search
        )
        return self._track(modes, total, float(ts[-1]), span, len(ts))

    @single_blas_thread
    def _analysis(self) -> list:
        """:meth:`_due` on one BLAS thread (:mod:`.threads`), for a sample fed alone; a batch
        (:meth:`_feed`) is on one thread throughout."""
        return self._due()

    @single_blas_thread
    def _feed(self, t: np.ndarray, y: np.ndarray, finite: np.ndarray) -> list:
        """Feed a batch (``finite``: per sample, its values are): its samples kept
        (:func:`.estimator.accept_rows`, a restart clearing the window) appended at once up to
        each analysis; the estimates of the analyses, in order."""
        out: list = []
        kept, runs, _ = accept_rows(self._c, self._last, t, finite, self._max_gap)
        t, y = t[kept], y[kept]
        for a, b, restart in runs:
            if restart:
                self.reset()
            while a < b:
                if self._next == math.inf:  # the window's first sample
                    self._next = float(t[a]) + self._window
                k = min(b, int(np.searchsorted(t[a:b], self._next, 'left')) + a + 1)
                self._append(t[a:k], y[a:k])
                self._last, a = float(t[k - 1]), k
                if self._last >= self._next:
                    out.extend(self._due())
        return out

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
        # the highest mode tracked: while a mode is published, a new one a search found above it
        # is identified at every analysis until it is confirmed or lost (not only by the next
        # search: CONFIRM_BESIDE analyses running would never see it)
        tracks = self._register.modes
        known = max((tr.frequency for tr in tracks), default=0.0)
        if not any(tr.published for tr in tracks):
            known = 0.0
        search = self._since_search >= SEARCH_EVERY - 1
        self._since_search = 0 if search else self._since_search + 1
        return ts, self._cascade, (len(ts) - 1) / span, span, known, search

    def _slide(self) -> np.ndarray:
        """Schedule the next analysis and slide the window (and the cascade) to end at the last
        sample; its samples' times."""
        t_end = self._t[self._n - 1]
        # every second while a mode is to be confirmed (CONFIRM analyses running: as soon as at
        # any window), else every hop_s of the window
        tracks = self._register.modes
        settled = bool(tracks) and all(tr.published for tr in tracks)
        hop = hop_s(self._window) if settled else HOP_S
        self._next += hop
        if self._next <= t_end:
            self._next = t_end + hop
        first = self._start + int(
            np.searchsorted(self._t[self._start : self._n], t_end - self._window, 'left')
        )
        self._start = first
        ts = self._t[first : self._n]
        self._cascade.keep_last(len(ts))
        return ts

    # ---- analysis -----------------------------------------------------------------------------
    def _off_lines(self, modes: WindowModes) -> WindowModes:
        """The window's modes less those within :data:`LINE_TOL` of a line of the drive
        (``lines_hz``; counted ``rejected_line``)."""
        lines = self._config.lines_hz
        if not lines or not len(modes):
            return modes
        ratio = modes.frequency[:, None] / np.asarray(lines, dtype=np.float64)[None, :]
        at = np.any(np.abs(ratio - 1) <= LINE_TOL, axis=1)
        self._c['rejected_line'] += int(np.count_nonzero(at))
        return modes.take(~at)

    def _track(self, modes: WindowModes, total: float, t: float, span: float, n: int) -> list:
        """Match the window's modes to the tracked ones (:class:`.identity.ModeRegister`),
        publish the confirmed ones."""
        register = self._register
        modes = self._off_lines(modes)
        match = register.match(modes.frequency.tolist(), modes.shapes)
        seen: dict = {}
        for i in range(len(modes)):
            tr = register.observe(float(modes.frequency[i]), t, modes.shapes[i], match.get(i))
            if tr is not None:
                tr.amplitude = math.sqrt(float(np.sum(modes.variances[i])))
                seen[tr] = i
        ready, found, lost = register.settle(seen, t, self._config.modes)
        self._c['modes_found'] += found
        self._c['modes_lost'] += lost
        explained = min(1.0, float(np.sum(modes.variances)) / total) if total > 0 else 0.0
        out = []
        for tr in sorted(ready, key=lambda tr: tr.frequency):
            i = seen[tr]
            f, z = float(modes.frequency[i]), float(modes.damping[i])
            fstd, zstd = float(modes.frequency_std[i]), float(modes.damping_std[i])
            scale = tr.calibration(t, f, fstd, z, zstd, self._window)
            tr.estimates += 1
            k = register.number(tr)
            shape = (modes.shapes[i], modes.shape_std[i], tr.mac) if self.channels else ()
            est = (t, f, span, n, explained, tr.amplitude, z, fstd * scale, zstd * scale, k)
            out.append(Estimate(*est, *shape))
        self._c['estimates'] += len(out)
        return out
