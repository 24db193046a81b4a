# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""Configuration of the estimator: every parameter with its description and range, validated.

One source for :meth:`EstimatorConfig.validate`, the nodes' ``ParameterDescriptor``, the command
line and the documentation (:meth:`EstimatorConfig.describe`); :meth:`EstimatorConfig.as_params`
lays the values out as the compiled kernel's parameter array (:mod:`vib_estimator.core.kernel`).
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field, fields
from typing import List, Optional, Tuple

import numpy as np

from . import kernel as K

MODELS = ('sinusoid', 'biased-sinusoid', 'damped-sinusoid')
#: what drives the structure: ``free`` (it rings freely after a pluck: the paper's estimators) or
#: ``ambient`` (unmeasured broadband forces: output-only identification, :mod:`.ambient`) or
#: ``auto`` (decided per stretch of signal from its envelope, :mod:`.auto`)
EXCITATIONS = ('free', 'ambient', 'auto')

INF = math.inf

#: the fields in which the paper's configuration differs from the default: Eq. 1's model (no
#: offset) over half-period windows, each estimate judged alone (``EstimatorConfig.paper``)
PAPER = {'model': 'sinusoid', 'min_periods': 0.5, 'consistency': 0.0}


def _param(default, doc: str, lo=None, hi=None, open_lo=False, open_hi=False):
    """A configuration field with its description and its range [lo, hi] (bounds open if asked).

    One source for :meth:`EstimatorConfig.validate`, the node's ``ParameterDescriptor`` and the
    documentation (:meth:`EstimatorConfig.describe`).
    """
    return field(
        default=default,
        metadata={'doc': doc, 'range': None if lo is None else (lo, hi, open_lo, open_hi)},
    )


@dataclass(frozen=True)
class EstimatorConfig:
    """Parameters of the estimator. The filter and test settings are those of Section 5.3 of the
    paper; the model, the window and the consistency gate are chosen for real sensors (an offset,
    a waveform with harmonics, coarse quantisation: ``docs/real_arm.md``), and :meth:`paper` sets
    them back to the paper's (:data:`PAPER`). Each field's description and range: :meth:`describe`.
    """

    model: str = _param(
        'biased-sinusoid',
        'sinusoid (Eq. 1, the paper), biased-sinusoid '
        '(y = A sin(wt+phi) + B, the offset eliminated algebraically) or '
        'damped-sinusoid (natural frequency and damping of a decaying sine)',
    )
    lowpass_cutoff_hz: float = _param(
        3.0,
        'cut-off of the invariant low-pass filter of Eqs. '
        '9-11, Hz (3 Hz = 6 pi rad/s, Section 5.3)',
        0.0,
        INF,
        open_lo=True,
        open_hi=True,
    )
    lowpass_damping: float = _param(
        0.707,
        'damping ratio of the invariant low-pass filter',
        0.0,
        INF,
        open_lo=True,
        open_hi=True,
    )
    window: int = _param(3, 'M of the moving-average convergence test (Eqs. 16-17)', 1, 10_000)
    tolerance: float = _param(
        1e-3,
        'relative tolerance of the convergence test (Eq. 16)',
        0.0,
        1.0,
        open_lo=True,
        open_hi=True,
    )
    min_time: float = _param(
        0.01,
        'eps of Eq. 12: no estimate is formed during the first eps seconds after a reset',
        0.0,
        INF,
        open_hi=True,
    )
    min_samples: int = _param(16, 'samples a segment must hold before the test may fire', 1, 10**8)
    min_periods: float = _param(
        1.25,
        'the test may fire only once the segment spans this '
        'many periods of the frequency it estimates (0 = off)',
        0.0,
        50.0,
    )
    invariant_filter: bool = _param(True, 'false computes n/d unfiltered (Fig. 1, lower trace)')
    one_sided_test: bool = _param(
        False,
        'Eq. 16 exactly as printed, (MA(k) - MA(k-M))/MA(k) < '
        'tolerance, which accepts any falling estimate',
    )
    rule_points: int = _param(
        K.NH,
        'samples of the interpolating polynomial the moments are '
        'integrated over (2 = trapezoid, for comparison)',
        2,
        K.NH,
    )
    max_window: float = _param(
        0.0,
        'seconds without convergence after which the estimator '
        'resets without publishing (0 = automatic: 10 s, or min_periods '
        '+ 2 periods of the running estimate if longer)',
        0.0,
        INF,
        open_hi=True,
    )
    refine: int = _param(
        4,
        'Gauss-Newton (maximum-likelihood) steps of the model over the '
        "segment, started from the algebraic estimate (0 = the paper's "
        'algebraic estimate as it is)',
        0,
        50,
    )
    band_hz: Optional[Tuple[float, float]] = _param(
        None,
        'band-pass prefilter [f_lo, f_hi] Hz on the signal (4th-order Butterworth '
        'low-pass at f_hi, 2nd-order high-pass at f_lo), never reset; none = off',
    )
    min_amplitude: float = _param(
        0.0,
        'quality gate: a segment whose half range is at or below this is at rest (signal units)',
        0.0,
        INF,
        open_hi=True,
    )
    min_fit: float = _param(
        0.9,
        'quality gate: R^2 the refined model (with refine = 0: a '
        'sinusoid at the estimated frequency) must reach over the segment for '
        'the estimate to be published',
        0.0,
        1.0,
    )
    max_damping: float = _param(
        0.1,
        'quality gate of the damped-sinusoid model: an estimate '
        'whose |damping ratio| exceeds this is a transient, not published',
        0.0,
        1.0,
        open_lo=True,
    )
    consistency: float = _param(
        0.03,
        'quality gate: an estimate is published only if it lies '
        'within this fraction of the estimate of the segment just before '
        'it (none after a restart, a timeout or a rejected segment): two '
        'consecutive estimates of one mode that differ more cannot both '
        'be right (0 = off, the paper; modes >= 1 have their own rule)',
        0.0,
        1.0,
    )
    max_gap: float = _param(
        0.5,
        'a gap, or a backward jump, between stamps longer than this '
        '(s) restarts the estimator; a smaller step back is skipped',
        0.0,
        INF,
        open_lo=True,
        open_hi=True,
    )
    gap_intervals: float = _param(
        10.0,
        'a step between stamps longer than this many running '
        'sample intervals (yet within max_gap) is a gap: the estimator '
        'restarts, never fitting across it; counted in gaps and '
        'samples_lost (0 = off, else >= 2)',
        0.0,
        1e6,
    )
    outlier_ratio: float = _param(
        1000.0,
        "a sample farther from the signal's running centre "
        'than this many times its running peak deviation is skipped '
        f'(skipped_outlier); {K.OUTLIER_RUN} in a row are a real change '
        'of level, taken (the estimator restarts) (0 = off, else >= 2)',
        0.0,
        1e12,
    )
    target_std_rel: float = _param(
        0.0,
        'publish as soon as the predicted relative standard '
        'deviation of the frequency is at or below this, whatever the '
        'period fraction (0 = off)',
        0.0,
        1.0,
    )
    early_std_rel: float = _param(
        0.0,
        'with a long window (min_periods >= '
        f'{K.LONG_WINDOW_PERIODS:g} and refine), an estimate whose predicted relative '
        'standard deviation of the frequency exceeds this waits until its segment spans '
        f'{K.HELD_PERIODS:g} periods (0 = off)',
        0.0,
        1.0,
    )
    modes: int = _param(
        0,
        'modes to find and track by a multi-scale subspace fit, each '
        'numbered by ascending frequency (0 = one estimator on the whole, '
        'optionally band-limited, signal)',
        0,
        8,
    )
    excitation: str = _param(
        'free',
        'free (free decays: the algebraic estimator, or the mode '
        'tracker with modes >= 1) or ambient (driven by unmeasured broadband '
        'forces: covariance-driven subspace identification over a sliding '
        'window of ambient_window_s, every mode numbered as the mode '
        "tracker's, "
        'at most modes of them if modes >= 1) or auto (both, each publishing in '
        'the stretches its envelope says: a decay after an onset is free, a '
        'stationary one driven; docs/operation.md)',
    )
    ambient_window_s: float = _param(
        30.0,
        'excitation ambient: the sliding window, s (the '
        'frequency std falls as its square root; docs/operation.md)',
        2.0,
        3600.0,
    )
    buffer_samples: int = _param(
        200_000, 'segment buffer of the quality gate; a longer segment resets', 1, 10**8
    )
    lines_hz: Optional[Tuple[float, ...]] = _param(
        None,
        'excitation ambient or auto: the lines of a periodic drive, Hz (a '
        "cycle's harmonics, sinusoids, not modes): the identifier drops a mode "
        'within 1 % of one (the default sets them where it reads a periodic '
        'drive); none = off',
    )

    @classmethod
    def paper(cls, **changes) -> 'EstimatorConfig':
        """The paper's configuration (:data:`PAPER`: its sinusoid model over half-period windows,
        no consistency gate), validated, with ``changes`` applied."""
        return cls().replace(**{**PAPER, **changes})

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
            if kind is int and (
                isinstance(value, bool) or not isinstance(value, (int, np.integer))
            ):
                raise ValueError(f'{f.name} must be an integer, got {value!r}')
            if kind is float and (
                isinstance(value, bool) or not isinstance(value, (int, float)) or math.isnan(value)
            ):
                raise ValueError(f'{f.name} must be a number, got {value!r}')
            bounds = f.metadata['range']
            if bounds is not None:
                lo, hi, open_lo, open_hi = bounds
                if (
                    value < lo
                    or value > hi
                    or (open_lo and value == lo)
                    or (open_hi and value == hi)
                ):
                    raise ValueError(
                        f'{f.name} must be in {"(" if open_lo else "["}{lo}, '
                        f'{hi}{")" if open_hi else "]"}, got {value!r}'
                    )
        if self.excitation not in EXCITATIONS:
            raise ValueError(
                f'excitation must be one of {", ".join(EXCITATIONS)}, got {self.excitation!r}'
            )
        for name in ('gap_intervals', 'outlier_ratio'):
            if 0 < getattr(self, name) < 2:
                raise ValueError(
                    f'{name} must be 0 (off) or at least 2, got {getattr(self, name)!r}'
                )
        if self.model not in MODELS:
            raise ValueError(f'model must be one of {", ".join(MODELS)}, got {self.model!r}')
        window = self.max_window or K.AUTO_WINDOW_S
        if self.min_time >= window:
            raise ValueError(
                f'min_time ({self.min_time}) must be below max_window '
                f'({window}{" when automatic" if not self.max_window else ""})'
            )
        if self.band_hz is not None:
            band = tuple(self.band_hz)
            if (
                len(band) != 2
                or not all(isinstance(b, (int, float)) and math.isfinite(b) for b in band)
                or not 0 < band[0] < band[1]
            ):
                raise ValueError(
                    f'band_hz must be [f_lo, f_hi] with 0 < f_lo < f_hi, got {self.band_hz!r}'
                )
        if self.lines_hz is not None and not all(
            isinstance(f, (int, float)) and math.isfinite(f) and f > 0 for f in self.lines_hz
        ):
            raise ValueError(f'lines_hz must hold frequencies > 0 Hz, got {self.lines_hz!r}')

    def replace(self, **changes) -> 'EstimatorConfig':
        """A validated copy with ``changes`` applied."""
        data = asdict(self)
        data.update(changes)
        for name in ('band_hz', 'lines_hz'):
            if data.get(name) is not None:  # (none: [] or ())
                data[name] = tuple(data[name]) or None
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
        p[K.P_REFINE] = self.refine
        p[K.P_TARGET] = self.target_std_rel
        p[K.P_CONSIST] = self.consistency
        p[K.P_GAPN] = self.gap_intervals
        p[K.P_OUTLIER] = self.outlier_ratio
        p[K.P_EARLY] = self.early_std_rel
        return p
