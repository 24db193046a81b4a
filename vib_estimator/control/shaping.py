# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""Input shapers for one lightly damped mode (f, zeta), their sensitivity, and a streaming shaper.

An input shaper is a sequence of impulses ``A_i`` at times ``t_i`` (``sum A_i = 1``, ``t_1 = 0``);
convolving a reference with it gives a command that leaves (nearly) no residual vibration of the
mode it was designed for. With ``K = exp(-zeta pi / sqrt(1 - zeta^2))`` and the damped period
``Td = 1 / (f sqrt(1 - zeta^2))``:

* ZV (Singer & Seering 1990): ``A = [1, K] / (1 + K)`` at ``[0, Td/2]``;
* ZVD (Singer & Seering 1990): ``A = [1, 2K, K^2] / (1 + K)^2`` at ``[0, Td/2, Td]``;
* ZVDD: ``A = [1, 3K, 3K^2, K^3] / (1 + K)^3`` at ``[0, Td/2, Td, 3Td/2]``;
* EI, extra-insensitive (Singhose, Seering & Singer 1994/1997): three impulses whose residual
  vibration is ``Vtol`` (5 %) at the design frequency, a local maximum there, and zero at one
  frequency below and one above; undamped ``A = [(1+V)/4, (1-V)/2, (1+V)/4]`` at ``[0, T/2, T]``,
  damped solved numerically from those conditions (:func:`ei`).

The residual vibration (Singer & Seering's percentage vibration) of a shaper on a mode
``(f, zeta)`` is the amplitude of the vibration it leaves relative to that of a single unit
impulse (:func:`residual_vibration`); as a function of the frequency error it is the shaper's
sensitivity curve (:func:`sensitivity`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable, Dict, Optional, Sequence

import numpy as np

#: EI shaper's vibration tolerance at the design frequency (Singhose's usual 5 %)
EI_VTOL = 0.05
#: largest damping ratio a shaper is designed for
MAX_DAMPING = 0.5


@dataclass(frozen=True)
class Shaper:
    """Impulse times (s, from 0) and amplitudes (sum 1), designed for a mode."""

    name: str
    times: np.ndarray
    amplitudes: np.ndarray
    frequency_hz: float = math.nan
    damping: float = math.nan

    @property
    def duration(self) -> float:
        """Time of the last impulse: how much the shaper lengthens a move, s."""
        return float(self.times[-1])

    def describe(self) -> str:
        """One line: name, design, impulses."""
        if self.name == 'none':
            return 'none (pass-through)'
        pairs = ', '.join(f'{a:.4f}@{t:.4f}s' for t, a in zip(self.times, self.amplitudes))
        return f'{self.name} for {self.frequency_hz:.4f} Hz, zeta {self.damping:.4f}: {pairs}'


def _check_mode(frequency_hz: float, damping: float) -> None:
    if not (math.isfinite(frequency_hz) and frequency_hz > 0):
        raise ValueError(f'frequency must be finite and > 0 Hz, got {frequency_hz!r}')
    if not (math.isfinite(damping) and 0 <= damping <= MAX_DAMPING):
        raise ValueError(f'damping ratio must be in [0, {MAX_DAMPING}], got {damping!r}')


def damped_period(frequency_hz: float, damping: float) -> float:
    """``Td = 1 / (f sqrt(1 - zeta^2))``, s."""
    return 1.0 / (frequency_hz * math.sqrt(1.0 - damping**2))


def k_factor(damping: float) -> float:
    """``K = exp(-zeta pi / sqrt(1 - zeta^2))``: the mode's decay over half a damped period."""
    return math.exp(-damping * math.pi / math.sqrt(1.0 - damping**2))


def _binomial(name: str, order: int, frequency_hz: float, damping: float) -> Shaper:
    """ZV (order 1), ZVD (2), ZVDD (3): ``(1 + K z)^order / (1 + K)^order`` at half periods."""
    _check_mode(frequency_hz, damping)
    k = k_factor(damping)
    amps = np.array([math.comb(order, i) * k**i for i in range(order + 1)]) / (1 + k) ** order
    times = 0.5 * damped_period(frequency_hz, damping) * np.arange(order + 1)
    return Shaper(name, times, amps, frequency_hz, damping)


def zv(frequency_hz: float, damping: float = 0.0) -> Shaper:
    """Zero vibration: two impulses (Singer & Seering)."""
    return _binomial('zv', 1, frequency_hz, damping)


def zvd(frequency_hz: float, damping: float = 0.0) -> Shaper:
    """Zero vibration and derivative: three impulses, flat at the design frequency."""
    return _binomial('zvd', 2, frequency_hz, damping)


def zvdd(frequency_hz: float, damping: float = 0.0) -> Shaper:
    """Zero vibration, first and second derivatives: four impulses."""
    return _binomial('zvdd', 3, frequency_hz, damping)


def none(frequency_hz: float = math.nan, damping: float = math.nan) -> Shaper:
    """The identity: one unit impulse at 0 (the reference passes through)."""
    return Shaper('none', np.zeros(1), np.ones(1), frequency_hz, damping)


def residual_vibration(
    times: Sequence[float], amplitudes: Sequence[float], frequency_hz, damping: float = 0.0
):
    """Residual vibration of impulses on the mode ``(frequency_hz, damping)``, relative to one
    unit impulse (Singer & Seering)::

        V = exp(-zeta w t_n) sqrt( (sum A_i e^{zeta w t_i} cos(wd t_i))^2
                                 + (sum A_i e^{zeta w t_i} sin(wd t_i))^2 )

    ``frequency_hz`` may be an array (the result is then one); ``w = 2 pi f``,
    ``wd = w sqrt(1 - zeta^2)``.
    """
    if not 0 <= damping < 1:
        raise ValueError(f'damping ratio must be in [0, 1), got {damping!r}')
    t = np.asarray(times, dtype=float)
    a = np.asarray(amplitudes, dtype=float)
    w = 2 * np.pi * np.asarray(frequency_hz, dtype=float)[..., None]
    wd = w * math.sqrt(1.0 - damping**2)
    weight = a * np.exp(damping * w * (t - t[-1]))
    return np.abs(np.sum(weight * np.exp(1j * wd * t), axis=-1))


def sensitivity(shaper: Shaper, frequency_ratio, damping: Optional[float] = None):
    """The sensitivity curve: residual vibration when the mode's true frequency is
    ``frequency_ratio`` times the design frequency (damping: the design's unless given)."""
    zeta = shaper.damping if damping is None else damping
    return residual_vibration(
        shaper.times,
        shaper.amplitudes,
        shaper.frequency_hz * np.asarray(frequency_ratio, dtype=float),
        zeta,
    )


#: largest step in sigma = zeta / sqrt(1 - zeta^2) between two solves of the EI continuation
EI_SIGMA_STEP = 0.05


def _ei_equations(x: np.ndarray, sigma: float, vtol: float) -> np.ndarray:
    """EI conditions on ``x = [A1, A2, t2, t3, rl, rh]`` (A3 = 1 - A1 - A2, times in damped
    periods, frequencies as ratios to the design): V(1) = Vtol, dV/dr(1) = 0, and the residual
    phasor zero at rl and rh.

    In these units the mode enters only through ``sigma = zeta / sqrt(1 - zeta^2)``: the residual
    phasor is ``P(r) = sum A_i exp(2 pi r (sigma + i) (t_i - t3))`` and ``V = |P|``, so
    ``dV/dr = Re(conj(P) P') / V``, in closed form (no finite difference)."""
    a1, a2, t2, t3, rl, rh = x
    lag = np.array([-t3, t2 - t3, 0.0])
    amps = np.array([a1, a2, 1.0 - a1 - a2])
    s = 2 * np.pi * (sigma + 1j)
    p1 = np.sum(amps * np.exp(s * lag))
    dp1 = np.sum(amps * s * lag * np.exp(s * lag))
    zl, zh = np.sum(amps * np.exp(s * rl * lag)), np.sum(amps * np.exp(s * rh * lag))
    return np.array(
        [abs(p1) - vtol, (p1.conjugate() * dp1).real, zl.real, zl.imag, zh.real, zh.imag]
    )


def ei(frequency_hz: float, damping: float = 0.0, vtol: float = EI_VTOL) -> Shaper:
    """Extra-insensitive shaper: residual ``vtol`` at the design frequency, a maximum there, and
    zero at two frequencies around it (Singhose, Seering & Singer).

    Undamped it is the closed form ``A = [(1+V)/4, (1-V)/2, (1+V)/4]`` at ``[0, T/2, T]``; damped,
    the six conditions (dimensionless: :func:`_ei_equations`) are solved by Powell's hybrid method
    (scipy's ``fsolve``) along a continuation in damping from the undamped solution, each step at
    most :data:`EI_SIGMA_STEP`: a single solve from the undamped solution diverged beyond zeta
    ~0.18 (and at other dampings under each scipy version), each short step converges to 1e-15.
    """
    from scipy.optimize import fsolve

    _check_mode(frequency_hz, damping)
    if not 0 < vtol < 1:
        raise ValueError(f'vtol must be in (0, 1), got {vtol!r}')
    period = damped_period(frequency_hz, damping)
    a = (1 + vtol) / 4
    if damping == 0:
        return Shaper(
            'ei',
            np.array([0.0, period / 2, period]),
            np.array([a, (1 - vtol) / 2, a]),
            frequency_hz,
            0.0,
        )
    zero = math.acos(-(1 - vtol) / (1 + vtol)) / math.pi  # undamped zeros at r and 2 - r
    x = np.array([a, (1 - vtol) / 2, 0.5, 1.0, zero, 2 - zero])
    sigma = damping / math.sqrt(1 - damping**2)
    steps = math.ceil(sigma / EI_SIGMA_STEP)
    for k in range(1, steps + 1):
        x, _, _, msg = fsolve(
            _ei_equations, x, args=(sigma * k / steps, vtol), full_output=True, xtol=1e-13
        )
    a1, a2, t2, t3, rl, rh = x
    if not (0 < t2 < t3 and rl < 1 < rh) or np.max(np.abs(_ei_equations(x, sigma, vtol))) > 1e-12:
        raise ValueError(f'EI design for zeta {damping} did not converge: {msg}')
    return Shaper(
        'ei',
        np.array([0.0, t2, t3]) * period,
        np.array([a1, a2, 1 - a1 - a2]),
        frequency_hz,
        damping,
    )


#: the shapers by name (``shaper`` parameter of shaper_node)
SHAPERS: Dict[str, Callable[[float, float], Shaper]] = {
    'none': none,
    'zv': zv,
    'zvd': zvd,
    'zvdd': zvdd,
    'ei': ei,
}


def design(name: str, frequency_hz: float, damping: float = 0.0) -> Shaper:
    """The shaper ``name`` (one of :data:`SHAPERS`) for the mode; ``ValueError`` if unknown."""
    if name not in SHAPERS:
        raise ValueError(f'shaper must be one of {", ".join(SHAPERS)}, got {name!r}')
    return SHAPERS[name](frequency_hz, damping)


def discrete_kernel(shaper: Shaper, rate_hz: float) -> np.ndarray:
    """The shaper as an FIR kernel at ``rate_hz``: each impulse split between the two samples
    around its time in proportion to its distance from them (a linear-interpolation fractional
    delay), so the kernel sums to 1 and its centroid is the shaper's."""
    if not (math.isfinite(rate_hz) and rate_hz > 0):
        raise ValueError(f'rate_hz must be > 0, got {rate_hz!r}')
    pos = np.asarray(shaper.times) * rate_hz
    kernel = np.zeros(int(math.floor(pos[-1])) + 2)
    for p, a in zip(pos, shaper.amplitudes):
        i = int(math.floor(p))
        frac = p - i
        kernel[i] += a * (1 - frac)
        kernel[i + 1] += a * frac
    return np.trim_zeros(kernel, 'b')


class StreamingShaper:
    """Convolves a reference sampled at ``rate_hz`` with a shaper, one sample at a time.

    Before the first sample the reference is taken to have rested at that sample's value, so a
    reference at rest passes through unchanged. :meth:`request` asks for another shaper; it is
    switched in only while the reference is at rest (it has stayed within ``rest_tolerance`` of one
    value for the whole length of the current kernel: the output is then at rest too, and any
    kernel summing to 1 continues it without a jump).
    """

    def __init__(self, shaper: Shaper, rate_hz: float, rest_tolerance: float = 0.0):
        if not (math.isfinite(rest_tolerance) and rest_tolerance >= 0):
            raise ValueError(f'rest_tolerance must be >= 0, got {rest_tolerance!r}')
        self.rate_hz = float(rate_hz)
        self.rest_tolerance = float(rest_tolerance)
        self.pending: Optional[Shaper] = None
        self.retunes = 0
        self._rest_value = math.nan
        self._rest_count = 0
        self._install(shaper, math.nan)

    def _install(self, shaper: Shaper, value: float) -> None:
        self.shaper = shaper
        self._kernel = discrete_kernel(shaper, self.rate_hz)
        self._taps = np.flatnonzero(self._kernel)
        self._weights = self._kernel[self._taps]
        self._history = np.full(len(self._kernel), value)  # circular, newest at self._head
        self._head = 0

    @property
    def at_rest(self) -> bool:
        """Whether the reference has rested for the whole current kernel."""
        return self._rest_count >= len(self._kernel)

    def request(self, shaper: Shaper) -> None:
        """Use ``shaper`` from the next sample before which the reference was at rest (that
        sample may be a move's first: a move requested with its shaper, no sample between them,
        is shaped by it)."""
        self.pending = shaper

    def update(self, x: float) -> float:
        """Feed one reference sample, return the shaped command for it."""
        x = float(x)
        if math.isnan(self._history[0]):  # first sample: it has rested there
            self._history[:] = x
            self._rest_value, self._rest_count = x, len(self._kernel)
        if self.pending is not None and self.at_rest:  # at rest up to this sample
            self._install(self.pending, self._rest_value)
            self.pending = None
            self.retunes += 1
        if abs(x - self._rest_value) <= self.rest_tolerance:
            self._rest_count += 1
        else:
            self._rest_value, self._rest_count = x, 1
        n = len(self._history)
        self._head = (self._head + 1) % n
        self._history[self._head] = x
        return float(np.dot(self._weights, self._history[(self._head - self._taps) % n]))

    def process(self, x: Sequence[float]) -> np.ndarray:
        """:meth:`update` over an array."""
        return np.array([self.update(v) for v in x])
