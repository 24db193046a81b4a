# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""Algebraic on-line frequency estimator of Trapero, Sira-Ramirez & Feliu (pure numpy/numba core).

Streaming: ``FrequencyEstimator.update(t, y)`` takes one timestamped sample and returns an
:class:`Estimate` (in a sequence of one, else an empty one) when the convergence test (Eqs. 16-17)
fires; the estimator then resets and
starts again, giving the consecutive estimates of Section 5.3. Batch:
``FrequencyEstimator.process(t, y)`` runs the same compiled step over arrays and returns the same
floats.

The arithmetic lives in :mod:`vib_estimator.core.kernel` (its docstring derives Eqs. 7-12 and the
corrected sign of Eq. 8). The configuration and its validation are in
:mod:`vib_estimator.core.config`; this module holds the Python API, and what every estimator
shares: the :class:`Estimator` interface, :class:`Estimate`, :class:`EstimateArrays`,
:class:`JointEstimates`, the input policy (:func:`accept_sample`, :func:`accept_rows`) and sample
buffer (:func:`make_room`) of those written in Python.

Error budget behind the defaults (the integration rule and eps). The numerator ``n`` is a
difference of terms of order A t^2 that cancel to w^2 A t^4 / 12, so an integration error e in the
moments becomes a relative error ~ e / (w^2 A t^4) in the estimate: largest early in a segment and
when the segment starts near a zero crossing (d small). With a rule exact for polynomials of
degree q-1 the relative error after k samples scales like (w h)^(q-2) / k^2: percent-level for the
trapezoid (q = 2), 1e-3 for a cubic (q = 4) at fs/f = 100 (``benchmarks/bench_accuracy.py``
measures 1.6e-2 and 1.4e-3), below 1e-8 at fs/f = 100 and 2e-5 at fs/f = 20 for the default
degree-7 rule (q = 8). The first segment after a (re)start begins only once NH samples are in the
stencil, so every interval uses the full rule. ``min_samples`` = 16 and ``min_periods`` = 0.5 keep
early, poorly determined ratios out of the convergence test; ``min_time`` (eps of Eq. 12) adds a
floor in seconds for noisy signals, where the first milliseconds of ``n_f / d_f`` are dominated by
noise (d ~ t^4).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import partial
from typing import Callable, Dict, List, Optional, Protocol, Sequence, Tuple

import numpy as np

from . import kernel as K
from .config import EstimatorConfig
from .jit import available, entry, interpreted, python_of

#: the input counters every estimator keeps (the first of the kernel's counter array, in order)
INPUT_COUNTERS = (
    'received',
    'used',
    'skipped_non_finite',
    'skipped_duplicate',
    'skipped_out_of_order',
    'time_jump_resets',
    'gap_resets',
)


def accept_sample(
    c: Dict[str, int],
    last: float,
    t: float,
    finite: bool,
    max_gap: float,
    restart: Callable[[], None],
) -> bool:
    """The input policy of the estimators written in Python (the kernel's ``_accept_time`` is
    the same rule compiled): count a sample of stamp ``t`` in ``c`` (the :data:`INPUT_COUNTERS`)
    after the last kept stamp ``last`` (-inf: none); True if it is kept. Non-finite (stamp or a
    value): skipped. A repeated stamp or a step back within ``max_gap``: skipped
    (``skipped_duplicate``, ``skipped_out_of_order``). A jump back beyond it (a restarted
    source, a bag looping) or a step forward beyond it (a gap): ``restart()`` is called
    (``time_jump_resets``, ``gap_resets``: the caller forgets its signal) and the sample kept,
    so a stream whose time went back is followed, never skipped for good."""
    c['received'] += 1
    if not (finite and math.isfinite(t)):
        c['skipped_non_finite'] += 1
        return False
    if t <= last and last - t <= max_gap:
        c['skipped_duplicate' if t == last else 'skipped_out_of_order'] += 1
        return False
    c['used'] += 1
    if t <= last or (t - last > max_gap and math.isfinite(last)):
        c['time_jump_resets' if t <= last else 'gap_resets'] += 1
        restart()
    return True


def accept_rows(
    c: Dict[str, int], last: float, t: np.ndarray, finite: np.ndarray, max_gap: float
) -> Tuple[np.ndarray, List[Tuple[int, int, bool]], float]:
    """:func:`accept_sample` over a batch of stamps ``t`` (``finite``: per sample, its values
    are): ``(kept: per sample, whether it is kept; the kept samples' runs [a, b) between
    restarts (a gap or a jump back), with whether each begins with one; the last kept stamp)``.
    A run of clean samples (finite, increasing, no gap) is counted at once, any other sample by
    :func:`accept_sample`."""
    n = len(t)
    kept, restarts, restarted = np.zeros(n, bool), np.zeros(n, bool), []
    mark = partial(restarted.append, True)  # accept_sample's restart
    i = 0
    while i < n:
        if finite[i] and t[i] > last and t[i] - last <= max_gap:
            d = np.diff(t[i : min(n, i + 65536)])
            bad = ~((d > 0) & (d <= max_gap)) | ~finite[i + 1 : i + 1 + len(d)]
            j = i + 1 + (int(np.argmax(bad)) if bad.any() else len(d))
            c['received'] += j - i
            c['used'] += j - i
            kept[i:j], last, i = True, float(t[j - 1]), j
            continue
        restarted.clear()
        if accept_sample(c, last, float(t[i]), bool(finite[i]), max_gap, mark):
            kept[i], restarts[i], last = True, bool(restarted), float(t[i])
        i += 1
    restarts = restarts[kept]
    cuts = [0, *np.flatnonzero(restarts).tolist(), len(restarts)]
    runs = [(a, b, bool(restarts[a])) for a, b in zip(cuts[:-1], cuts[1:]) if a < b]
    return kept, runs, last


def make_room(buf: np.ndarray, start: int, n: int, more: int) -> np.ndarray:
    """``buf`` (a buffer of rows) with its rows ``start .. n`` moved to its front and room after
    them for ``more`` rows: in place, or in a new buffer of twice their count rounded up to a
    power of two (the sample buffers of the estimators written in Python)."""
    keep = n - start
    size = 1 << math.ceil(math.log2(2 * (keep + more)))
    out = buf if size <= len(buf) else np.empty((size, *buf.shape[1:]))
    out[:keep] = buf[start:n]
    return out


#: counter names, in the order of :mod:`vib_estimator.core.kernel`'s counter array
COUNTER_NAMES = INPUT_COUNTERS + (
    'rejected_at_rest',
    'rejected_fit',
    'rejected_nyquist',
    'max_window_resets',
    'estimates',
    'rejected_damping',
    'rejected_inconsistent',
    'gaps',
    'samples_lost',
    'skipped_outlier',
)


#: the attributes :meth:`FrequencyEstimator._bind` derives (not pickled: compiled code, views)
_BOUND = ('_feed', '_p', '_row', '_s', '_seg')


def as_series(
    t: Sequence[float], y: Sequence[float], channels: Sequence[str] = ()
) -> Tuple[np.ndarray, np.ndarray]:
    """``t``, ``y`` as contiguous, writeable float64 arrays of one length (``ValueError``
    otherwise): ``y`` samples, or samples x 1 (one channel, as a joint estimator's input);
    with several named ``channels``, samples x that many.

    Writeable: numba compiles a kernel once more for a read-only array (another type), so a
    CSV's read-only time column (pyarrow's) cost ``analyze`` a compile of 10-20 s that
    ``vib-estimator warmup`` had paid already for writeable arrays; a read-only block is copied.
    """
    t = np.require(t, np.float64, ('C', 'W'))
    y = np.require(y, np.float64, ('C', 'W'))
    m = len(channels)
    if m and (y.ndim != 2 or y.shape[1] != m):
        raise ValueError(f'y must be samples x {m} channels, got {y.shape}')
    if not m and y.ndim == 2 and y.shape[1:] == (1,):
        y = y[:, 0]
    if t.shape != y.shape[: 1 if m else None] or t.ndim != 1:
        raise ValueError(f't and y must be 1-D arrays of one length, got {t.shape}, {y.shape}')
    return t, y


#: the fewest channels of a joint estimator (one channel is a one-channel estimator's)
MIN_CHANNELS = 2


def channel_names(channels: Sequence[str], what: str, hint: str = '') -> Tuple[str, ...]:
    """``channels`` as names; ValueError if they are fewer than :data:`MIN_CHANNELS` (``what``
    needs them; ``hint``: what to do instead)."""
    names = tuple(str(c) for c in channels)
    if len(names) < MIN_CHANNELS:
        raise ValueError(f'{what} needs at least {MIN_CHANNELS} channels, got {len(names)}{hint}')
    return names


@dataclass(frozen=True)
class Estimate:
    """One published estimate.

    Attributes:
        t: stamp of the converging sample (same time base as the input), s.
        frequency_hz: estimated natural frequency, Hz.
        convergence_time: time from the last reset to convergence, s.
        samples: samples used by this estimate (segment length).
        fit: R^2 of the sinusoid at this frequency over the segment (quality gate).
        amplitude: amplitude of that sinusoid, signal units.
        damping: damping ratio (``damped-sinusoid`` model; NaN for the others).
        frequency_std_hz: predicted standard deviation of ``frequency_hz`` (NaN if not computed).
        damping_std: predicted standard deviation of ``damping`` (NaN if not computed).
        mode: the mode it belongs to, 1 = the lowest (``modes`` >= 1); 0 with ``modes`` = 0.
        shape: a joint estimator's mode shape, normalised, complex, one entry per channel
            (None with one channel; :mod:`.ambient`, :mod:`.multichannel_free`).
        shape_std: its uncertainty per channel (None with one channel).
        mac: the MAC of ``shape`` with the same mode's previous one (NaN at its first and with
            one channel).

    ``as_dict`` (the published fields) leaves the shape fields out; they take no part in
    equality.
    """

    t: float
    frequency_hz: float
    convergence_time: float
    samples: int
    fit: float
    amplitude: float
    damping: float = math.nan
    frequency_std_hz: float = math.nan
    damping_std: float = math.nan
    mode: int = 0
    shape: Optional[np.ndarray] = field(default=None, compare=False, repr=False)
    shape_std: Optional[np.ndarray] = field(default=None, compare=False, repr=False)
    mac: float = field(default=math.nan, compare=False, repr=False)

    @property
    def omega(self) -> float:
        """Estimated angular frequency, rad/s."""
        return 2 * math.pi * self.frequency_hz

    @classmethod
    def of_row(cls, row: np.ndarray) -> 'Estimate':
        """An estimate from a kernel's row: the fields in order (:mod:`.kernel`'s ``O_*``), a
        mode after them (the mode tracker's) or none (0)."""
        ints = (K.O_SAMPLES, K.N_OUT)
        return cls(*(int(v) if i in ints else float(v) for i, v in enumerate(row)))

    def as_dict(self) -> Dict[str, float]:
        return {
            't': self.t,
            'frequency_hz': self.frequency_hz,
            'omega_rad_s': self.omega,
            'convergence_time_s': self.convergence_time,
            'samples': self.samples,
            'fit': self.fit,
            'amplitude': self.amplitude,
            'damping': self.damping,
            'frequency_std_hz': self.frequency_std_hz,
            'damping_std': self.damping_std,
            'mode': self.mode,
        }


class Estimator(Protocol):
    """What every estimator is (:mod:`.factory` builds the one of a configuration).

    - ``update(t, y)``: one sample (``y``: one value, or with several :attr:`channels` one per
      channel); the estimates it completes, a sequence (empty, usually).
    - ``process(t, y)``: arrays of samples (``y``: samples, or samples x channels), continuing
      the stream; the estimates as columns (:class:`EstimateArrays`; a joint estimator's
      :class:`JointEstimates` add the shapes). Streaming equals batch.
    - ``reset()``: a new segment or window at the last sample; ``restart()``: forget the
      signal; both keep the counters.
    - ``config``; ``channels``: the channel names of a joint estimator, () for one channel.
    - ``mode_counters()``: each numbered mode's own counters ({} where there are none);
      ``segment_samples``: samples of the open segment, not yet in an estimate (None where the
      estimator has no segment).
    - ``counters``: name -> count since construction, one vocabulary for all: the
      :data:`INPUT_COUNTERS` first, with ``received = used + skipped_non_finite +
      skipped_duplicate + skipped_out_of_order + skipped_outlier`` (the last only where an
      outlier rule exists); ``estimates``, those published; ``rejected_<why>``, candidates held
      back and why; the others are named in the estimator's module.

    The estimators subclass it, for the defaults of ``channels``, ``segment_samples``,
    ``interpreted`` and ``mode_counters``, and an estimator whose step is a module's compiled
    functions (:attr:`_module`) for :attr:`_k` and :meth:`compiled`.
    """

    channels: Tuple[str, ...] = ()
    segment_samples: Optional[int] = None
    #: True while it runs its kernels uncompiled (:func:`.factory.create_uncompiled`)
    interpreted: bool = False
    #: the module whose compiled functions are its step (None: none)
    _module = None

    @property
    def config(self) -> EstimatorConfig:
        return self._config

    @property
    def _k(self):
        """:attr:`_module`'s compiled functions, or while :attr:`interpreted` their uncompiled
        code (:func:`.jit.interpreted`: the same state, the same floats, estimating at once while
        they compile)."""
        return interpreted(self._module) if self.interpreted else self._module

    def compiled(self) -> None:
        """Run the compiled functions from the next sample on (the state is in the arrays both
        read). Their first call compiles them, unless compiled already (the node compiles them in
        the background: :mod:`vib_estimator.nodes.stream`)."""
        self.interpreted = False

    @property
    def counters(self) -> Dict[str, int]: ...

    def mode_counters(self) -> Dict[int, Dict[str, int]]:
        return {}

    def update(self, t: float, y) -> Sequence[Estimate]: ...

    def process(self, t: Sequence[float], y): ...

    def reset(self) -> None: ...

    def restart(self) -> None: ...


@dataclass
class EstimateArrays:
    """Estimates of a batch run as columns (same fields as :class:`Estimate`)."""

    t: np.ndarray
    frequency_hz: np.ndarray
    convergence_time: np.ndarray
    samples: np.ndarray
    fit: np.ndarray
    amplitude: np.ndarray
    damping: np.ndarray
    frequency_std_hz: np.ndarray
    damping_std: np.ndarray
    mode: np.ndarray

    @classmethod
    def from_rows(cls, rows: np.ndarray) -> 'EstimateArrays':
        """Columns of a kernel's estimate rows (:meth:`Estimate.of_row`)."""
        mode = rows[:, K.N_OUT] if rows.shape[1] > K.N_OUT else np.zeros(len(rows))
        return cls(
            *(
                rows[:, i].astype(np.int64) if i == K.O_SAMPLES else rows[:, i].copy()
                for i in range(K.N_OUT)
            ),
            mode.astype(np.int64),
        )

    def where(self, keep: np.ndarray) -> 'EstimateArrays':
        """The estimates ``keep`` (a mask or indices) selects, in their order."""
        return EstimateArrays(**{n: getattr(self, n)[keep] for n in self.__dataclass_fields__})

    @classmethod
    def concatenate(
        cls, parts: Sequence['EstimateArrays'], by_time: bool = True
    ) -> 'EstimateArrays':
        """One set of columns from several, sorted by time (stable: ties keep their order), or
        with ``by_time`` False in the order of the parts (a stream whose time went back)."""
        names = list(cls.__dataclass_fields__)
        if not parts:
            return cls.from_rows(np.empty((0, K.N_OUT)))
        cols = {n: np.concatenate([getattr(p, n) for p in parts]) for n in names}
        if not by_time:
            return cls(**cols)
        order = np.argsort(cols['t'], kind='stable')
        return cls(**{n: c[order] for n, c in cols.items()})

    @classmethod
    def of(cls, estimates: Sequence[Estimate]) -> 'EstimateArrays':
        """The columns of ``estimates`` (the inverse of :meth:`to_list`)."""
        ints = ('samples', 'mode')
        return cls(
            **{
                name: np.array(
                    [getattr(e, name) for e in estimates],
                    dtype=np.int64 if name in ints else np.float64,
                )
                for name in cls.__dataclass_fields__
            }
        )

    def __len__(self) -> int:
        return len(self.t)

    def to_list(self) -> List[Estimate]:
        """The estimates one by one (Python floats and ints)."""
        ints = {K.O_SAMPLES, K.N_OUT}
        columns = (getattr(self, name) for name in self.__dataclass_fields__)
        return [
            Estimate(*(int(v) if i in ints else float(v) for i, v in enumerate(row)))
            for row in zip(*columns)
        ]


@dataclass
class JointEstimates:
    """Estimates of a joint (several channels) batch run: the columns of
    :class:`EstimateArrays`, the shapes (estimates x channels, complex), their stds and the MACs,
    in the estimates' order."""

    estimates: EstimateArrays
    shapes: np.ndarray
    shape_std: np.ndarray
    mac: np.ndarray
    channels: Tuple[str, ...]

    def __len__(self) -> int:
        return len(self.estimates)

    @classmethod
    def of(cls, out: Sequence[Estimate], channels: Tuple[str, ...]) -> 'JointEstimates':
        """The columns of the estimates ``out`` (with shapes) of ``channels``, in their order."""
        m = len(channels)
        return cls(
            EstimateArrays.of(out),
            np.array([e.shape for e in out], dtype=complex).reshape(-1, m),
            np.array([e.shape_std for e in out]).reshape(-1, m),
            np.array([e.mac for e in out]),
            channels,
        )


class FrequencyEstimator(Estimator):
    """Streaming algebraic frequency estimator; see the module docstring.

    Bad samples never raise: a non-finite value, a duplicate or an out-of-order stamp, or an
    outlier (``outlier_ratio``) is skipped and counted; a gap or a backward jump longer than
    ``max_gap``, or a gap of more than ``gap_intervals`` running sample intervals, restarts the
    estimator (counted, with the samples lost). An estimate with a non-finite frequency, fit or
    amplitude, or an infinite std, is never published (counted as ``rejected_fit``).
    ``counters`` tells how many samples went where and why estimates were held back.
    """

    _module = K

    def __init__(self, config: EstimatorConfig = EstimatorConfig(), interpret: bool = False):
        config.validate()
        self._config = config
        self.interpreted = interpret  # (:meth:`~Estimator.compiled`)
        self._n_state = K.N_STATE_FIXED + 2 * config.window + 1
        self._f = K.feed_buffer(config.as_params(), self._n_state, config.buffer_samples)
        self._c = np.zeros(K.N_COUNTERS, dtype=np.int64)
        self._bind()
        self._optional = K.optional_features(self._p)
        self.restart()

    def _bind(self) -> None:
        """The parts derived from the buffer ``_f`` (not pickled): its views ``_p``, ``_row``,
        ``_s``, ``_seg`` (:func:`core.kernel.feed_buffer`'s layout) and the streaming path's
        compiled code, looked up at the first :meth:`update`."""
        self._p, self._row, self._s, self._seg = python_of(K.feed_views)(self._f, self._n_state)
        self._feed = None

    def kernels_available(self) -> bool:
        """Whether the compiled batch kernel is in memory or numba's cache
        (:func:`core.jit.available`: running it compiles nothing)."""
        one = np.zeros(1)
        args = (self._p, self._s, self._c, self._seg, one, one, self._row, 0, self._optional)
        return available(K.run, args)

    def __getstate__(self) -> dict:
        return {k: v for k, v in self.__dict__.items() if k not in _BOUND}

    def __setstate__(self, state: dict) -> None:
        self.__dict__.update(state)
        self._bind()

    def restart(self) -> None:
        """Forget the signal entirely (prefilter, history, running interval and scale too);
        counters are kept."""
        self._k.forget_stream(self._s, self._c)

    def reset(self) -> None:
        """Start a new estimation segment at the last sample, as after a convergence."""
        if self._c[K.C_HIST_N] >= K.NH:
            self._k.reset_segment(
                self._s, self._c, self._seg, self._s[K.S_TLAST], self._s[K.S_HY + K.NH - 1]
            )

    @property
    def counters(self) -> Dict[str, int]:
        return {name: int(self._c[i]) for i, name in enumerate(COUNTER_NAMES)}

    @property
    def segment_samples(self) -> int:
        """Samples of the open segment: taken since the last reset, not (yet) in an estimate."""
        return int(self._c[K.C_SEG_N])

    @property
    def omega_squared(self) -> float:
        """Eq. 12's current value n_f / d_f (rad^2/s^2) of the running segment; NaN if undefined.

        For plotting the estimate's trajectory (Fig. 1); published estimates come from ``update``.
        """
        df = self._s[K.S_DF]
        return self._s[K.S_NF] / df if df != 0.0 and self._c[K.C_SEG_N] > 1 else math.nan

    def update(self, t: float, y: float) -> Sequence[Estimate]:
        """Feed one sample (time in s, any origin); the estimate it publishes, if any (a
        sequence of none or one, as every :class:`Estimator`'s).

        :func:`core.kernel.feed` (the step on one sample, as the batch kernel over a one-sample
        array), called through its compiled code for these argument types
        (:func:`core.jit.entry`): numba's dispatch resolves the types of its arguments at each
        call otherwise.
        """
        feed = self._feed
        if feed is None:
            if self.interpreted:  # (not kept: compiled() switches)
                feed = self._k.feed
            else:
                args = (self._f, self._c, self._n_state, 0.0, 0.0, self._optional)
                feed = self._feed = entry(K.feed, args)
        if feed(self._f, self._c, self._n_state, t, y, self._optional):
            return (Estimate.of_row(self._row[0]),)
        return ()

    def process(self, t: Sequence[float], y: Sequence[float]) -> EstimateArrays:
        """Feed arrays of samples (continuing the stream); return the estimates as columns."""
        t, y = as_series(t, y)
        chunks = []
        start = 0
        size = max(16, len(t) // 100)
        while True:
            out = np.empty((size, K.N_OUT))
            n, start = self._k.run(
                self._p, self._s, self._c, self._seg, t, y, out, start, self._optional
            )
            chunks.append(out[:n])
            if start >= len(t):
                break
            size *= 2
        rows = np.concatenate(chunks) if chunks else np.empty((0, K.N_OUT))
        return EstimateArrays.from_rows(rows)


#: a batch run whose compiled kernels are neither in memory nor in numba's cache runs this many
#: samples uncompiled before it compiles them (:func:`run_batch`): about 5 CPU s of the
#: algebraic estimator (~100 us a sample), 5-10 of the mode tracker, less than their compile
#: (20-25 CPU s on a 2-core machine, docs/startup.md), so a newcomer's first ``analyze`` of a
#: record of a few minutes answers in seconds, and a longer record pays the compile once. The
#: budget is the process's (:data:`UNCOMPILED`): a survey's worker that runs record after short
#: record compiles once they add up to it (a survey of 48 records of 11 s on a cold cache: 66 s
#: each time until 7 Dec 2026, the cache never filled; now 45 s, then 2.5 s: docs/startup.md)
UNCOMPILED_SAMPLES = 50_000


class UncompiledBudget:
    """The samples this process has run uncompiled in batch (:func:`run_batch`), of the
    :data:`UNCOMPILED_SAMPLES` it may run before it compiles the kernels it runs."""

    def __init__(self) -> None:
        self.spent = 0

    def left(self) -> int:
        """Samples still to run uncompiled."""
        return max(UNCOMPILED_SAMPLES - self.spent, 0)


#: this process's budget of uncompiled batch samples
UNCOMPILED = UncompiledBudget()


def batch_start(estimator) -> None:
    """Make ``estimator`` (one built uncompiled: ``interpret``) compiled at once if its compiled
    kernels cost nothing to run (in memory or numba's cache: ``kernels_available``) or this
    process has spent its uncompiled samples (:data:`UNCOMPILED`); else it starts uncompiled,
    and :func:`run_batch` compiles them once the process has run :data:`UNCOMPILED_SAMPLES`."""
    if estimator.kernels_available() or not UNCOMPILED.left():
        estimator.compiled()


def run_batch(estimator, t, y) -> EstimateArrays:
    """``estimator.process(t, y)`` (continuing its record), switched to its compiled kernels once
    this process has run :data:`UNCOMPILED_SAMPLES` uncompiled (:data:`UNCOMPILED`: this
    record's earlier blocks among them) if it still runs uncompiled (:func:`batch_start`). The
    switch is between two samples, on the same state; the algebraic estimator's floats are the
    same either way, the mode tracker's within ~1e-9 relative (:class:`~.modes.ModeTracker`)."""
    if not estimator.interpreted:
        return estimator.process(t, y)
    k = UNCOMPILED.left()
    if k >= len(t):
        UNCOMPILED.spent += len(t)
        return estimator.process(t, y)
    t, y = np.asarray(t), np.asarray(y)
    first = estimator.process(t[:k], y[:k])
    UNCOMPILED.spent += k
    estimator.compiled()
    return EstimateArrays.concatenate([first, estimator.process(t[k:], y[k:])])
