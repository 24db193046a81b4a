"""Algebraic on-line frequency estimator of Trapero, Sira-Ramirez & Feliu (pure numpy/numba core).

Streaming: ``FrequencyEstimator.update(t, y)`` takes one timestamped sample and returns an
:class:`Estimate` when the convergence test (Eqs. 16-17) fires; the estimator then resets and starts
again, giving the consecutive estimates of Section 5.3. Batch: ``FrequencyEstimator.process(t, y)``
runs the same compiled step over arrays and returns the same floats.

The arithmetic lives in :mod:`vib_estimator.kernel` (its docstring derives Eqs. 7-12 and the
corrected sign of Eq. 8). This module holds the configuration, its validation, and the Python API.

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
from dataclasses import asdict, dataclass, field, fields
from typing import Dict, List, Optional, Sequence, Tuple

import numpy as np

from . import kernel as K

MODELS = ('sinusoid', 'biased-sinusoid', 'damped-sinusoid')

#: counter names, in the order of :mod:`vib_estimator.kernel`'s counter array
COUNTER_NAMES = ('received', 'used', 'skipped_non_finite', 'skipped_duplicate',
                 'skipped_out_of_order', 'time_jump_resets', 'gap_resets', 'rejected_at_rest',
                 'rejected_fit', 'rejected_nyquist', 'max_window_resets', 'estimates',
                 'rejected_damping')


INF = math.inf


def _param(default, doc: str, lo=None, hi=None, open_lo=False, open_hi=False):
    """A configuration field with its description and its range [lo, hi] (bounds open if asked).

    One source for :meth:`EstimatorConfig.validate`, the node's ``ParameterDescriptor`` and the
    documentation (:meth:`EstimatorConfig.describe`).
    """
    return field(default=default, metadata={'doc': doc, 'range': None if lo is None else
                                            (lo, hi, open_lo, open_hi)})


@dataclass(frozen=True)
class EstimatorConfig:
    """Parameters of the estimator; defaults are those of Section 5.3 of the paper where it gives
    them. Each field's description and range: :meth:`describe`."""

    model: str = _param('sinusoid', 'sinusoid (Eq. 1, the paper), biased-sinusoid '
                        '(y = A sin(wt+phi) + B, the offset eliminated algebraically) or '
                        'damped-sinusoid (natural frequency and damping of a decaying sine)')
    lowpass_cutoff_hz: float = _param(3.0, 'cut-off of the invariant low-pass filter of Eqs. '
                                      '9-11, Hz (3 Hz = 6 pi rad/s, Section 5.3)',
                                      0.0, INF, open_lo=True, open_hi=True)
    lowpass_damping: float = _param(0.707, 'damping ratio of the invariant low-pass filter',
                                    0.0, INF, open_lo=True, open_hi=True)
    window: int = _param(3, 'M of the moving-average convergence test (Eqs. 16-17)', 1, 10_000)
    tolerance: float = _param(1e-3, 'relative tolerance of the convergence test (Eq. 16)',
                              0.0, 1.0, open_lo=True, open_hi=True)
    min_time: float = _param(0.01, 'eps of Eq. 12: no estimate is formed during the first eps '
                             'seconds after a reset', 0.0, INF, open_hi=True)
    min_samples: int = _param(16, 'samples a segment must hold before the test may fire',
                              1, 10 ** 8)
    min_periods: float = _param(0.5, 'the test may fire only once the segment spans this '
                                'fraction of the period it estimates (0 = off)', 0.0, 10.0)
    invariant_filter: bool = _param(True, 'false computes n/d unfiltered (Fig. 1, lower trace)')
    one_sided_test: bool = _param(False, 'Eq. 16 exactly as printed, (MA(k) - MA(k-M))/MA(k) < '
                                  'tolerance, which accepts any falling estimate')
    rule_points: int = _param(K.NH, 'samples of the interpolating polynomial the moments are '
                              'integrated over (2 = trapezoid, for comparison)', 2, K.NH)
    max_window: float = _param(10.0, 'seconds without convergence after which the estimator '
                               'resets without publishing', 0.0, INF, open_lo=True, open_hi=True)
    band_hz: Optional[Tuple[float, float]] = _param(
        None, 'band-pass prefilter [f_lo, f_hi] Hz on the signal (4th-order Butterworth '
        'low-pass at f_hi, 2nd-order high-pass at f_lo), never reset; none = off')
    min_amplitude: float = _param(0.0, 'quality gate: a segment whose half range is at or '
                                  'below this is at rest (signal units)', 0.0, INF, open_hi=True)
    min_fit: float = _param(0.9, 'quality gate: R^2 a sinusoid at the estimated frequency must '
                            'reach over the segment for the estimate to be published', 0.0, 1.0)
    max_damping: float = _param(0.1, 'quality gate of the damped-sinusoid model: an estimate '
                                'whose |damping ratio| exceeds this is a transient, not published',
                                0.0, 1.0, open_lo=True)
    max_gap: float = _param(0.5, 'a gap, or a backward jump, between stamps longer than this '
                            '(s) restarts the estimator; a smaller step back is skipped',
                            0.0, INF, open_lo=True, open_hi=True)
    buffer_samples: int = _param(200_000, 'segment buffer of the quality gate; a longer segment '
                                 'resets', 1, 10 ** 8)

    @classmethod
    def describe(cls, name: str) -> Tuple[str, Optional[tuple]]:
        """(description, range) of a field; range = (lo, hi, open_lo, open_hi) or None."""
        meta = next(f for f in fields(cls) if f.name == name).metadata
        return meta['doc'], meta['range']

    def validate(self) -> None:
        """Raise ``ValueError`` naming the first invalid parameter and why."""
        for f in fields(self):
            value = getattr(self, f.name)
            kind = type(f.default) if f.default is not None else None
            if kind is bool and not isinstance(value, bool):
                raise ValueError(f'{f.name} must be true or false, got {value!r}')
            if kind is int and (isinstance(value, bool)
                                or not isinstance(value, (int, np.integer))):
                raise ValueError(f'{f.name} must be an integer, got {value!r}')
            if kind is float and (isinstance(value, bool) or not isinstance(value, (int, float))
                                  or math.isnan(value)):
                raise ValueError(f'{f.name} must be a number, got {value!r}')
            bounds = f.metadata['range']
            if bounds is not None:
                lo, hi, open_lo, open_hi = bounds
                if value < lo or value > hi or (open_lo and value == lo) or \
                        (open_hi and value == hi):
                    raise ValueError(f'{f.name} must be in {"(" if open_lo else "["}{lo}, '
                                     f'{hi}{")" if open_hi else "]"}, got {value!r}')
        if self.model not in MODELS:
            raise ValueError(f'model must be one of {", ".join(MODELS)}, got {self.model!r}')
        if self.min_time >= self.max_window:
            raise ValueError(f'min_time ({self.min_time}) must be below max_window '
                             f'({self.max_window})')
        if self.band_hz is not None:
            band = tuple(self.band_hz)
            if len(band) != 2 or not all(isinstance(b, (int, float)) and math.isfinite(b)
                                         for b in band) or not 0 < band[0] < band[1]:
                raise ValueError(f'band_hz must be [f_lo, f_hi] with 0 < f_lo < f_hi, '
                                 f'got {self.band_hz!r}')

    def replace(self, **changes) -> 'EstimatorConfig':
        """A validated copy with ``changes`` applied."""
        data = asdict(self)
        data.update(changes)
        if data.get('band_hz') is not None:
            data['band_hz'] = tuple(data['band_hz'])
        cfg = EstimatorConfig(**data)
        cfg.validate()
        return cfg

    @classmethod
    def names(cls) -> List[str]:
        return [f.name for f in fields(cls)]

    def as_params(self) -> np.ndarray:
        """The kernel's parameter array."""
        p = np.zeros(K.N_PARAMS)
        p[K.P_MODEL] = MODELS.index(self.model)
        p[K.P_WC] = 2 * math.pi * self.lowpass_cutoff_hz
        p[K.P_ZC] = self.lowpass_damping
        p[K.P_M] = self.window
        p[K.P_TOL] = self.tolerance
        p[K.P_EPS] = self.min_time
        p[K.P_MAXWIN] = self.max_window
        p[K.P_BAND] = 1.0 if self.band_hz is not None else 0.0
        if self.band_hz is not None:
            p[K.P_WLO] = 2 * math.pi * self.band_hz[0]
            p[K.P_WHI] = 2 * math.pi * self.band_hz[1]
        p[K.P_MINAMP] = self.min_amplitude
        p[K.P_MINFIT] = self.min_fit
        p[K.P_MAXGAP] = self.max_gap
        p[K.P_MINSAMP] = self.min_samples
        p[K.P_MINPER] = self.min_periods
        p[K.P_FILTER] = 1.0 if self.invariant_filter else 0.0
        p[K.P_ONESIDED] = 1.0 if self.one_sided_test else 0.0
        p[K.P_RULE] = self.rule_points
        p[K.P_MAXDAMP] = self.max_damping
        return p


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
    """

    t: float
    frequency_hz: float
    convergence_time: float
    samples: int
    fit: float
    amplitude: float
    damping: float = math.nan

    @property
    def omega(self) -> float:
        """Estimated angular frequency, rad/s."""
        return 2 * math.pi * self.frequency_hz

    def as_dict(self) -> Dict[str, float]:
        return {'t': self.t, 'frequency_hz': self.frequency_hz, 'omega_rad_s': self.omega,
                'convergence_time_s': self.convergence_time, 'samples': self.samples,
                'fit': self.fit, 'amplitude': self.amplitude, 'damping': self.damping}


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

    @classmethod
    def from_rows(cls, rows: np.ndarray) -> 'EstimateArrays':
        """Columns of the kernel's estimate rows."""
        return cls(*(rows[:, i].astype(np.int64) if i == K.O_SAMPLES else rows[:, i].copy()
                     for i in range(K.N_OUT)))

    def __len__(self) -> int:
        return len(self.t)

    def to_list(self) -> List[Estimate]:
        return [Estimate(*(int(v) if i == K.O_SAMPLES else float(v) for i, v in enumerate(row)))
                for row in zip(self.t, self.frequency_hz, self.convergence_time, self.samples,
                               self.fit, self.amplitude, self.damping)]


class FrequencyEstimator:
    """Streaming algebraic frequency estimator; see the module docstring.

    Bad samples never raise: a non-finite value, a duplicate or an out-of-order stamp is skipped
    and counted; a gap or a backward jump longer than ``max_gap`` restarts the estimator (counted).
    ``counters`` tells how many samples went where and why estimates were held back.
    """

    def __init__(self, config: EstimatorConfig = EstimatorConfig()):
        config.validate()
        self._config = config
        self._p = config.as_params()
        self._s = np.zeros(K.N_STATE_FIXED + 2 * config.window + 1)
        self._c = np.zeros(K.N_COUNTERS, dtype=np.int64)
        self._seg = np.zeros((2, config.buffer_samples))
        self._row = np.zeros(K.N_OUT)
        self.restart()

    @property
    def config(self) -> EstimatorConfig:
        return self._config

    def restart(self) -> None:
        """Forget the signal entirely (prefilter and history too); counters are kept."""
        K._restart(self._s, self._c)

    def reset(self) -> None:
        """Start a new estimation segment at the last sample, as after a convergence."""
        if self._c[K.C_HIST_N] >= K.NH:
            K.reset_segment(self._s, self._c, self._seg, self._s[K.S_TLAST],
                            self._s[K.S_HY + K.NH - 1])

    @property
    def counters(self) -> Dict[str, int]:
        return {name: int(self._c[i]) for i, name in enumerate(COUNTER_NAMES)}

    @property
    def omega_squared(self) -> float:
        """Eq. 12's current value n_f / d_f (rad^2/s^2) of the running segment; NaN if undefined.

        For plotting the estimate's trajectory (Fig. 1); published estimates come from ``update``.
        """
        df = self._s[K.S_DF]
        return self._s[K.S_NF] / df if df != 0.0 and self._c[K.C_SEG_N] > 1 else math.nan

    def update(self, t: float, y: float) -> Optional[Estimate]:
        """Feed one sample (time in s, any origin); return an estimate when one is published."""
        if K.step(self._p, self._s, self._c, self._seg, float(t), float(y), self._row):
            return Estimate(*(int(v) if i == K.O_SAMPLES else float(v)
                              for i, v in enumerate(self._row)))
        return None

    def process(self, t: Sequence[float], y: Sequence[float]) -> EstimateArrays:
        """Feed arrays of samples (continuing the stream); return the estimates as columns."""
        t = np.ascontiguousarray(t, dtype=np.float64)
        y = np.ascontiguousarray(y, dtype=np.float64)
        if t.shape != y.shape or t.ndim != 1:
            raise ValueError(f't and y must be 1-D arrays of one length, got {t.shape}, {y.shape}')
        chunks = []
        start = 0
        size = max(16, len(t) // 100)
        while True:
            out = np.empty((size, K.N_OUT))
            n, start = K.run(self._p, self._s, self._c, self._seg, t, y, out, start)
            chunks.append(out[:n])
            if start >= len(t):
                break
            size *= 2
        rows = np.concatenate(chunks) if chunks else np.empty((0, K.N_OUT))
        return EstimateArrays.from_rows(rows)


def estimate(t: Sequence[float], y: Sequence[float],
             config: EstimatorConfig = EstimatorConfig()) -> EstimateArrays:
    """Batch convenience: run a fresh estimator over a whole record."""
    return FrequencyEstimator(config).process(t, y)
