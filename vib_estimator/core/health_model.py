# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""A learned health baseline (pure numpy/scipy, no rclpy): what a structure's modes normally do
as the weather changes, and when they do something else.

Per mode, a linear regression of the frequency on the covariates (temperature, load, ...), fitted
by ordinary least squares with an intercept over a training period of ``n`` recordings::

    f = b0 + b . (x - x_mean) + e,     e ~ N(0, s^2)

``s`` is the residual standard deviation (``n - p - 1`` degrees of freedom, ``p`` covariates).
A new recording with covariates ``x0`` is predicted ``f_hat = b0 + b . (x0 - x_mean)`` and its
prediction error ``r = f - f_hat`` has the standard deviation ``se = s sqrt(1 + h)``,
``h = u' (U'U)^-1 u`` (``u = [1, x0 - x_mean]``: the leverage, the parameters' own uncertainty,
growing as ``x0`` leaves the training range). For Gaussian errors ``z = r / se`` follows Student's
t with ``n - p - 1`` degrees of freedom exactly, so the alarm ``|z| > t_(1 - P/2)`` has the false
alarm probability ``P`` per recording per mode (:data:`DEFAULT_FALSE_ALARM`). The compensated
change is ``f / f_hat - 1`` and its 95 % interval ``(r -+ t_0.975 se) / f_hat``.

A sequential test (by default on beside it) accumulates persistent shifts, and keeps the alarm
on while a shift lasts: the two-sided CUSUM of the standardised residuals in recording order,
``S+ = max(0, S+ + z - k)``, ``S- = max(0, S- - z - k)``, alarm while either exceeds ``h``. The
reference value :data:`CUSUM_K` = 0.5 tunes it to a shift of one ``se``; the threshold ``h`` is
set by the same ``P`` (:func:`cusum_threshold`): an in-control average run length (Siegmund's
approximation, :func:`cusum_arl`) of ``2/P`` recordings per side, ``1/P`` for the two-sided test
-- one false excursion in ``1/P`` recordings of an undamaged mode on average (P = 0.001:
h = 5.75; a shift of 1 ``se`` is found after ~12 recordings, of 2 after ~4, of 5 after ~2).

Modes are matched across recordings by frequency (relative distance below :data:`MATCH_REL` of
the frequency the baseline predicts) and, with several channels, by the MAC of the shapes (at
least :data:`MATCH_MAC`). The baseline is saved as plain YAML (:func:`save`, :data:`VERSION`).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Dict, List, Optional, Sequence, Tuple

import numpy as np

from .shapes import mac

#: version of the saved baseline's layout (``version:`` in the YAML file)
VERSION = 1
#: false-alarm probability of the per-recording test, per recording per mode
DEFAULT_FALSE_ALARM = 0.001
#: confidence of the compensated change's interval
CHANGE_CONFIDENCE = 0.95
#: CUSUM reference value (allowance), in prediction standard deviations
CUSUM_K = 0.5
#: the CUSUM's allowance grows by this many of the regression's own share of the std of z
CUSUM_SHARED = 2.0
#: a recording's mode is a baseline mode when its frequency is within this relative distance of
#: the frequency the baseline predicts (and training rows within it of each other form a mode)
MATCH_REL = 0.05
#: farther than MATCH_REL, a recording's mode is still its nearest baseline mode if it is within
#: half the distance to the next baseline mode and this relative distance
MATCH_FAR = 0.2
#: ... and, with shapes on both sides, their MAC is at least this
MATCH_MAC = 0.8
#: a training cluster is a mode when at least this share of the training recordings has it
MODE_PRESENCE = 0.5


@functools.lru_cache(maxsize=256)
def student_quantile(q: float, dof: int) -> float:
    """Student's t quantile ``q`` at ``dof`` degrees of freedom (cached: asked per estimate)."""
    from scipy.stats import t as student

    return float(student.ppf(q, dof))


def cusum_arl(h: float, shift: float = 0.0, k: float = CUSUM_K) -> float:
    """Average run length of a one-sided CUSUM of threshold ``h`` on unit-variance normal data of
    mean ``shift`` (Siegmund's approximation, ``h + 1.166``)."""
    d = shift - k
    b = h + 1.166
    if abs(d) < 1e-9:
        return b * b
    return (math.exp(-2 * d * b) + 2 * d * b - 1) / (2 * d * d)


def cusum_threshold(false_alarm: float, k: float = CUSUM_K) -> float:
    """The threshold ``h`` whose one-sided in-control run length is ``2 / false_alarm`` (the
    two-sided test's ``1 / false_alarm``), by bisection of :func:`cusum_arl`."""
    target, lo, hi = 2.0 / false_alarm, 0.0, 50.0
    for _ in range(100):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if cusum_arl(mid, 0.0, k) < target else (lo, mid)
    return 0.5 * (lo + hi)


@dataclass
class ModeBaseline:
    """One mode's learned normal behaviour (see the module doc); fields as saved."""

    topic: str
    component: str
    #: 1, 2, ... by ascending frequency within (topic, component)
    mode: int
    #: the mode's mean training frequency, Hz
    frequency_hz: float
    #: regression coefficients ``[b0, b_1 ... b_p]`` (Hz; Hz per covariate unit)
    coef: List[float]
    #: covariate means of the training period (the regression's centre)
    x_mean: List[float]
    #: ``(U'U)^-1`` of the centred design (p+1 x p+1)
    xtx_inv: List[List[float]]
    #: residual standard deviation, Hz, and its degrees of freedom (n - p - 1)
    residual_std_hz: float
    dof: int
    #: training recordings
    n: int
    #: each covariate's training range [min, max]
    x_range: List[List[float]] = field(default_factory=list)
    #: the mean training shape (several channels), else empty
    shape: List[float] = field(default_factory=list)

    def predict(self, x: Sequence[float]) -> Tuple[float, float]:
        """``(f_hat, se)``: the predicted frequency at covariates ``x`` and the standard deviation
        of a new recording's prediction error (parameter uncertainty included)."""
        u = np.concatenate(([1.0], np.asarray(x, dtype=float) - np.asarray(self.x_mean)))
        f_hat = float(np.dot(self.coef, u))
        return f_hat, self.residual_std_hz * math.sqrt(1.0 + self.leverage(x))

    def leverage(self, x: Sequence[float]) -> float:
        """``h = u' (U'U)^-1 u`` at covariates ``x`` (module doc)."""
        u = np.concatenate(([1.0], np.asarray(x, dtype=float) - np.asarray(self.x_mean)))
        return float(u @ np.asarray(self.xtx_inv) @ u)

    def extrapolated(self, x: Sequence[float]) -> bool:
        """Whether a covariate lies outside its training range."""
        return any(not lo <= v <= hi for v, (lo, hi) in zip(x, self.x_range))

    def to_dict(self) -> Dict:
        return {
            'topic': self.topic,
            'component': self.component,
            'mode': self.mode,
            'frequency_hz': float(self.frequency_hz),
            'coef': [float(c) for c in self.coef],
            'x_mean': [float(c) for c in self.x_mean],
            'xtx_inv': [[float(c) for c in row] for row in self.xtx_inv],
            'residual_std_hz': float(self.residual_std_hz),
            'dof': int(self.dof),
            'n': int(self.n),
            'x_range': [[float(a), float(b)] for a, b in self.x_range],
            'shape': [float(c) for c in self.shape],
        }


@dataclass
class Change:
    """A recording's mode against its baseline."""

    predicted_hz: float
    change_rel: float
    change_lo: float
    change_hi: float
    #: standardised residual r / se
    z: float
    #: the relative change beyond which the recording alarms, at the false-alarm probability
    limit_rel: float
    alarm: bool
    extrapolated: bool
    #: the std of ``z`` due to the regression's own error, ``sqrt(h / (1 + h))``: shared by the
    #: recordings near these covariates, so the CUSUM must not accumulate it (:class:`Cusum`)
    shared: float = 0.0


@dataclass
class Baseline:
    """Every mode's :class:`ModeBaseline`, the covariates' names, the false-alarm probability."""

    covariates: List[str]
    modes: List[ModeBaseline]
    false_alarm: float = DEFAULT_FALSE_ALARM
    #: what the baseline was learned from (free text: recordings, dates)
    trained_on: str = ''

    def cusum_h(self) -> float:
        """The CUSUM threshold of the false-alarm probability (:func:`cusum_threshold`)."""
        return cusum_threshold(self.false_alarm)

    def threshold(self, mode: ModeBaseline, false_alarm: Optional[float] = None) -> float:
        """``t_(1 - P/2)`` at the mode's degrees of freedom."""
        p = self.false_alarm if false_alarm is None else false_alarm
        return student_quantile(1 - p / 2, mode.dof)

    def change(
        self,
        mode: ModeBaseline,
        frequency_hz: float,
        x: Sequence[float],
        false_alarm: Optional[float] = None,
    ) -> Change:
        """The compensated change of ``frequency_hz`` at covariates ``x`` (module doc)."""
        f_hat, se = mode.predict(x)
        r = frequency_hz - f_hat
        q95 = student_quantile(0.5 + CHANGE_CONFIDENCE / 2, mode.dof)
        q = self.threshold(mode, false_alarm)
        z = r / se if se > 0 else math.copysign(math.inf, r) if r else 0.0
        return Change(
            f_hat,
            r / f_hat,
            (r - q95 * se) / f_hat,
            (r + q95 * se) / f_hat,
            z,
            q * se / f_hat,
            bool(abs(z) > q),
            mode.extrapolated(x),
            math.sqrt(mode.leverage(x) / (1.0 + mode.leverage(x))),
        )

    def match(
        self,
        topic: Optional[str],
        component: Optional[str],
        frequency_hz: float,
        x: Sequence[float],
        shape: Optional[np.ndarray] = None,
    ) -> Optional[ModeBaseline]:
        """The baseline mode of (topic, component) nearest ``frequency_hz`` (relative to its
        prediction at ``x``): within :data:`MATCH_REL`, or farther (a large change must not go
        unmatched) up to half the distance to the next baseline mode's prediction and at most
        :data:`MATCH_FAR`; with a MAC of at least :data:`MATCH_MAC` where both have shapes; None
        if none. ``topic`` None: any mode (the node's topic may be named otherwise than the bags
        the baseline was learned from)."""
        near = []
        for m in self.modes:
            if topic is not None and (m.topic, m.component) != (topic, component):
                continue
            if (
                shape is not None
                and len(m.shape) == len(shape)
                and mac(shape, m.shape) < MATCH_MAC
            ):
                continue
            near.append((abs(math.log(frequency_hz / m.predict(x)[0])), m))
        if not near:
            return None
        near.sort(key=lambda item: item[0])
        d, best = near[0]
        if d < MATCH_REL:
            return best
        f_best = best.predict(x)[0]
        gaps = [abs(math.log(m.predict(x)[0] / f_best)) for _, m in near[1:]]
        return best if d < min([MATCH_FAR] + [g / 2 for g in gaps]) else None

    def to_dict(self) -> Dict:
        return {
            'version': VERSION,
            'kind': 'vib_estimator health baseline',
            'covariates': list(self.covariates),
            'false_alarm': float(self.false_alarm),
            'trained_on': self.trained_on,
            'modes': [m.to_dict() for m in self.modes],
        }


def fit_mode(
    topic: str,
    component: str,
    mode: int,
    frequency_hz: Sequence[float],
    x: np.ndarray,
    shape: Sequence[float] = (),
) -> ModeBaseline:
    """Ordinary least squares of ``frequency_hz`` (n) on ``x`` (n x p) with an intercept;
    ValueError if fewer than p + 3 recordings (two residual degrees of freedom) or a covariate
    that does not vary."""
    f = np.asarray(frequency_hz, dtype=float)
    x = np.asarray(x, dtype=float).reshape(len(f), -1)
    n, p = x.shape
    if n < p + 3:
        raise ValueError(
            f'mode {mode} of {topic or "the recordings"} {component}: {n} training recording(s), '
            f'need at least {p + 3} to learn a baseline of {p} covariate(s)'
        )
    x_mean = x.mean(axis=0)
    u = np.column_stack([np.ones(n), x - x_mean])
    if np.linalg.matrix_rank(u) < p + 1:
        raise ValueError(
            f'mode {mode} of {topic or "the recordings"} {component}: a covariate does not vary '
            'over the training recordings (or two move together); a baseline cannot separate them'
        )
    xtx_inv = np.linalg.inv(u.T @ u)
    coef = xtx_inv @ u.T @ f
    resid = f - u @ coef
    dof = n - p - 1
    s = math.sqrt(float(resid @ resid) / dof)
    return ModeBaseline(
        topic,
        component,
        mode,
        float(f.mean()),
        coef.tolist(),
        x_mean.tolist(),
        xtx_inv.tolist(),
        s,
        dof,
        n,
        [[float(a), float(b)] for a, b in zip(x.min(axis=0), x.max(axis=0))],
        [float(v) for v in shape],
    )


def group_modes(frequencies: Sequence[float], recordings: Sequence[int]) -> List[List[int]]:
    """Indices of training rows grouped into modes: sorted by frequency and split where the gap
    between neighbours exceeds :data:`MATCH_REL` (relative); a group is kept when at least
    :data:`MODE_PRESENCE` of the recordings have a row in it, one row per recording (the nearest
    the group's median). Groups in ascending frequency."""
    f = np.asarray(frequencies, dtype=float)
    rec = np.asarray(recordings)
    order = np.argsort(f)
    groups, current = [], [int(order[0])] if len(order) else []
    for a, b in zip(order[:-1], order[1:]):
        if math.log(f[b] / f[a]) > MATCH_REL:
            groups.append(current)
            current = []
        current.append(int(b))
    if current:
        groups.append(current)
    total = len(set(rec.tolist()))
    kept = []
    for g in groups:
        median = float(np.median(f[g]))
        best: Dict[int, int] = {}
        for i in g:
            r = int(rec[i])
            if r not in best or abs(f[i] - median) < abs(f[best[r]] - median):
                best[r] = i
        if len(best) >= MODE_PRESENCE * total:
            kept.append(sorted(best.values()))
    return kept


def learn(
    rows: Sequence[Dict],
    covariates: Sequence[str],
    x_of,
    shape_of=lambda row: None,
    false_alarm: float = DEFAULT_FALSE_ALARM,
    trained_on: str = '',
) -> Baseline:
    """A :class:`Baseline` from training rows (dicts with ``recording``, ``topic``,
    ``component``, ``frequency_hz``): per (topic, component), the rows grouped into modes
    (:func:`group_modes`), each mode fitted (:func:`fit_mode`) on ``x_of(row)`` (the row's
    covariate values); ``shape_of(row)``: its mode shape or None. ValueError if no mode."""
    usable = [
        r
        for r in rows
        if np.isfinite(r['frequency_hz'])
        and r['frequency_hz'] > 0
        and np.all(np.isfinite(x_of(r)))
    ]
    modes: List[ModeBaseline] = []
    for topic, component in sorted({(r['topic'], r['component']) for r in usable}):
        mine = [r for r in usable if (r['topic'], r['component']) == (topic, component)]
        names = sorted({r['recording'] for r in mine})
        groups = group_modes(
            [r['frequency_hz'] for r in mine], [names.index(r['recording']) for r in mine]
        )
        for k, g in enumerate(groups, 1):
            shapes = [shape_of(mine[i]) for i in g]
            shape = _mean_shape([s for s in shapes if s is not None])
            modes.append(
                fit_mode(
                    topic,
                    component,
                    k,
                    [mine[i]['frequency_hz'] for i in g],
                    np.array([x_of(mine[i]) for i in g], dtype=float).reshape(len(g), -1),
                    shape,
                )
            )
    if not modes:
        raise ValueError(
            'no mode to learn a baseline from: no training recording gave a frequency (and every '
            'covariate)'
        )
    return Baseline(list(covariates), modes, false_alarm, trained_on)


def _mean_shape(shapes: List[np.ndarray]) -> List[float]:
    """The mean of unit shapes, each signed as the first (shapes' sign is arbitrary)."""
    if not shapes:
        return []
    ref = np.asarray(shapes[0], dtype=float)
    acc = np.zeros_like(ref)
    for s in shapes:
        s = np.asarray(s, dtype=float)
        s = s / (np.linalg.norm(s) or 1.0)
        acc += s if np.dot(s, ref) >= 0 else -s
    return (acc / (np.linalg.norm(acc) or 1.0)).tolist()


class Cusum:
    """Two-sided CUSUM of standardised residuals (module doc): :meth:`update` with each ``z``."""

    def __init__(self, h: float, k: float = CUSUM_K) -> None:
        self.k, self.h = k, h
        self.high = self.low = 0.0

    def update(self, z: float, shared: float = 0.0) -> bool:
        """Add one standardised residual; True while either side is above ``h``. ``shared``: the
        part of ``z``'s std that is the regression's own error (:attr:`Change.shared`), common to
        neighbouring recordings: the allowance grows by :data:`CUSUM_SHARED` of it, so that an
        error of the fitted relation (larger where it extrapolates) is not accumulated as a
        shift."""
        if not math.isfinite(z):
            return self.alarm
        k = self.k + CUSUM_SHARED * shared
        self.high = max(0.0, self.high + z - k)
        self.low = max(0.0, self.low - z - k)
        return self.alarm

    @property
    def alarm(self) -> bool:
        return self.high > self.h or self.low > self.h

    @property
    def value(self) -> float:
        """The larger side, signed (negative: the frequency fell)."""
        return self.high if self.high >= self.low else -self.low


# ------------------------------------------------------------------------------ live (the node)


@dataclass
class WindowResult:
    """A closed window's verdict for one baseline mode."""

    mode: int
    frequency_hz: float
    change: Change
    alarm: bool
    #: stream time (s) of the start of the window the current alarm began in (NaN: no alarm)
    since: float


class LiveHealth:
    """The node's side of a baseline (no rclpy). Estimates are summarised over windows of stream
    time ``[k window_s, (k + 1) window_s)``, each standing for one recording of the training
    (``window_s``: the recordings' length); the covariates are averaged over the same window
    (by their stamps). At each window's end every matched baseline mode gets the change and
    alarm :meth:`Baseline.change` gives ``survey`` (optionally the CUSUM), and since when. While
    learning, closed windows are kept and :meth:`learned` fits a new baseline from them.
    ``summarise(values, stds, t, spans)``: a window's frequency (default: the mean)."""

    def __init__(
        self,
        baseline: Optional[Baseline],
        covariates: Sequence[str],
        window_s: float,
        cusum: bool = True,
        summarise=None,
    ) -> None:
        self.baseline = baseline
        self.covariates = list(covariates)
        self.window_s = window_s
        self.cusum = cusum
        self.summarise = summarise or (lambda f, s, t, span: float(np.mean(f)))
        self.learning = False
        self.windows: List[Dict] = []  # closed windows kept while learning
        self._cusums: Dict[int, Cusum] = {}
        self._since: Dict[int, float] = {}
        self.last: List[WindowResult] = []
        self._start: Optional[float] = None
        self._new_window(None)

    def _new_window(self, start: Optional[float]) -> None:
        self._start = start
        self._est: Dict[int, List[Tuple[float, float, float, float]]] = {}
        ahead = getattr(self, '_ahead', {})
        self._cov = ahead.pop(start, None) or [[0.0, 0] for _ in self.covariates]
        #: covariate samples stamped in later windows, by window start
        self._ahead = {k: v for k, v in ahead.items() if start is None or k > start}

    def covariate(self, index: int, value: float, t: Optional[float] = None) -> None:
        """A covariate sample, averaged over the window of its stream time ``t`` (None: the
        current window): one stamped after the current window waits for its own."""
        if not math.isfinite(value):
            return
        acc = self._cov
        if t is not None and self._start is not None:
            start = math.floor(t / self.window_s) * self.window_s
            if start > self._start:
                acc = self._ahead.setdefault(start, [[0.0, 0] for _ in self.covariates])
        acc[index][0] += value
        acc[index][1] += 1

    def x(self) -> List[float]:
        """The current window's covariate means (NaN for one not yet received)."""
        return [a / n if n else math.nan for a, n in self._cov]

    def estimate(
        self, t: float, mode: int, frequency_hz: float, std: float = math.nan, span: float = 0.0
    ) -> Optional[List[WindowResult]]:
        """Add a mode's estimate at stream time ``t``; at a window's end (this estimate opens
        the next one) the closed window's results, else None."""
        closed = None
        start = math.floor(t / self.window_s) * self.window_s  # windows on the stream's grid
        if self._start is None:
            self._start = start
        elif start > self._start:
            closed = self.close()
            self._new_window(start)
        self._est.setdefault(mode, []).append((frequency_hz, std, t, span))
        return closed

    def running_change(self, mode: int) -> Optional[Tuple[int, float]]:
        """``(baseline mode, change)`` of the current window's estimates of ``mode`` so far."""
        window = self._summary()
        if self.baseline is None or mode not in window:
            return None
        x = self.x()
        if not all(math.isfinite(v) for v in x):
            return None
        m = self.baseline.match(None, None, window[mode], x)
        if m is None:
            return None
        return m.mode, self.baseline.change(m, window[mode], x).change_rel

    def _summary(self) -> Dict[int, float]:
        out = {}
        for mode, items in self._est.items():
            f, s, t, span = (np.array(v, dtype=float) for v in zip(*items))
            out[mode] = self.summarise(f, s, t, span)
        return out

    def close(self, restart: bool = False) -> List[WindowResult]:
        """Close the current window: its results (and, learning, keep it); ``restart``: the next
        estimate opens a new one."""
        window, x = self._summary(), self.x()
        if restart:
            self._new_window(None)
        if self.learning and window and all(math.isfinite(v) for v in x):
            self.windows.extend(
                {
                    'recording': f'window {len(self.windows)}',
                    'topic': '',
                    'component': '',
                    'frequency_hz': f,
                    'x': x,
                }
                for f in window.values()
            )
        results: List[WindowResult] = []
        if self.baseline is None or not all(math.isfinite(v) for v in x):
            self.last = results
            return results
        chosen: Dict[int, Tuple[float, ModeBaseline, float]] = {}
        for f in window.values():
            m = self.baseline.match(None, None, f, x)
            if m is None:
                continue
            d = abs(math.log(f / m.predict(x)[0]))
            if m.mode not in chosen or d < chosen[m.mode][0]:
                chosen[m.mode] = (d, m, f)
        for k, (_, m, f) in sorted(chosen.items()):
            change = self.baseline.change(m, f, x)
            alarm = change.alarm
            if self.cusum:
                c = self._cusums.setdefault(k, Cusum(self.baseline.cusum_h()))
                alarm = c.update(change.z, change.shared) or alarm
            if alarm:
                self._since.setdefault(k, self._start)
            else:
                self._since.pop(k, None)
            results.append(WindowResult(k, f, change, alarm, self._since.get(k, math.nan)))
        self.last = results
        return results

    def start_learning(self) -> None:
        self.learning, self.windows = True, []

    def learned(self, false_alarm: float = DEFAULT_FALSE_ALARM) -> Baseline:
        """Stop learning; the baseline of the kept windows (ValueError if too few)."""
        self.learning = False
        rows = [dict(r, recording=r['recording']) for r in self.windows]
        return learn(
            rows,
            self.covariates,
            lambda r: r['x'],
            false_alarm=false_alarm,
            trained_on=f'{len({r["recording"] for r in rows})} windows on line',
        )


# ------------------------------------------------------------------------------ the YAML file


def from_dict(data: Dict) -> Baseline:
    """A :class:`Baseline` from its :meth:`Baseline.to_dict` (ValueError naming what is wrong)."""
    if not isinstance(data, dict) or 'version' not in data:
        raise ValueError('not a health baseline (no version:)')
    if data['version'] != VERSION:
        raise ValueError(
            f'health baseline version {data["version"]}, this program reads {VERSION}'
        )
    try:
        modes = [ModeBaseline(**m) for m in data['modes']]
        baseline = Baseline(
            [str(c) for c in data['covariates']],
            modes,
            float(data.get('false_alarm', DEFAULT_FALSE_ALARM)),
            str(data.get('trained_on', '')),
        )
    except (KeyError, TypeError) as err:
        raise ValueError(f'health baseline: bad or missing field ({err})') from None
    p = len(baseline.covariates)
    for m in modes:
        if len(m.coef) != p + 1 or len(m.x_mean) != p or np.shape(m.xtx_inv) != (p + 1, p + 1):
            raise ValueError(f'health baseline: mode {m.mode} does not have {p} covariate(s)')
        if not (m.residual_std_hz >= 0 and m.dof >= 1):
            raise ValueError(f'health baseline: mode {m.mode} has no residual spread')
    if not 0 < baseline.false_alarm < 1:
        raise ValueError(
            f'health baseline: false_alarm must be in (0, 1), got {baseline.false_alarm}'
        )
    return baseline


def save(baseline: Baseline, path) -> None:
    """Write ``baseline`` as plain YAML (``version: 1``; fields: docs/health.md)."""
    import yaml

    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(yaml.safe_dump(baseline.to_dict(), sort_keys=False))


def load(path) -> Baseline:
    """Read a baseline written by :func:`save` (ValueError if it is not one)."""
    import yaml

    try:
        data = yaml.safe_load(Path(path).read_text())
    except (OSError, yaml.YAMLError) as err:
        raise ValueError(f'cannot read health baseline {path}: {err}') from None
    try:
        return from_dict(data)
    except ValueError as err:
        raise ValueError(f'{path}: {err}') from None


def is_baseline_file(path) -> bool:
    """Whether ``path`` is a file named ``*.yaml``/``*.yml`` (a saved baseline, not a bag)."""
    path = Path(path)
    return path.is_file() and path.suffix.lower() in ('.yaml', '.yml')
