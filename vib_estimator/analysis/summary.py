# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""The short summary ``vib-estimator analyze`` ends with: the modes found and the input shaper to
use for them, as ``shaper_node`` parameters.

A mode's frequency is the median of its estimates, ``±`` their robust standard deviation
(:data:`MAD_TO_STD` x the median absolute deviation: an estimate the mode tracker labelled before
it separated the modes does not inflate it; such estimates, farther than :data:`OUTLIER_STDS`
robust stds, are counted and named).

Shaper rule: ZVD (``shaper_node``'s default) unless the spread of the frequency estimates would
leave ZVD more residual vibration than EI's tolerance: with ``s`` = 2 robust stds / median (the
95 % half-width of the estimates, relative), ZVD's worst residual over ``f (1 +- s)``
(:func:`..control.shaping.sensitivity`, at the mode's damping) above ``EI_VTOL`` (5 %) recommends
EI, which stays within ``EI_VTOL`` over a wider band. ``shaper_node`` shapes one
mode: the recommendation is for the lowest one.

Never a confident wrong answer:

- **A frequency that moved** (a tip mass changed, a structure stiffened): with the estimates'
  times, each mode's estimates are cut into *stretches* (:func:`stretches`: a new one starts where
  :data:`STRETCH_RUN` estimates running lie more than :data:`STRETCH_REL` from the stretch's
  median); a mode of several stretches is summarised per stretch, said to have moved, and the
  shaper is designed for its last stretch (the structure as it is now).
- **A mode on too few estimates** (fewer than :data:`MIN_ESTIMATES`) is listed as tentative and no
  shaper is designed for it: the lowest mode that is not tentative gets the recommendation, or the
  summary says why there is none.
- **An undamped line** among an identifier's modes (``identified``: its median damping ratio under
  :data:`UNDAMPED`): a periodic drive's harmonic, which output-only identification takes for a
  mode of damping ~0 (docs/known_limits.md, *A periodic motion*), is listed as such and never
  shaped for.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import List, Optional

import numpy as np

from ..control.shaping import EI_VTOL, MAX_DAMPING, design, sensitivity

#: the standard deviation of a normal sample per unit of its median absolute deviation
MAD_TO_STD = 1.4826
#: an estimate farther than this many robust stds from its mode's median is an outlier
OUTLIER_STDS = 5.0
#: the spread of a mode's estimates, in robust stds each side of the median (~95 %)
SPREAD_STDS = 2.0
#: a new stretch of a mode starts where its estimates move by more than this, relative, from the
#: stretch's median (a mode's estimates scatter by 0.1-1 %; the tracker's and the identifier's
#: own match tolerance is 3 %: a smaller move is the same structure)
STRETCH_REL = 0.05
#: ... for this many estimates running (one estimate off is an outlier, not a move)
STRETCH_RUN = 2
#: a mode with fewer estimates than this is tentative: listed, but no shaper is designed for it
MIN_ESTIMATES = 3
#: an identifier's mode whose median damping ratio is under this is an undamped line, not a
#: structural mode: the harmonics of the simulated arm's periodic moves read 4e-6 to 1.5e-4
#: (benchmarks/bench_periodic.py), driven modes at zeta 0.2 % medians of 1.2e-3 to 5.9e-3 over
#: 60-180 s windows, the Heritage Court Tower's 0.7-2 %
UNDAMPED = 3e-4


@dataclass(frozen=True)
class ModeSummary:
    """One mode: its number (0: the single-mode estimator), how many estimates, their median
    frequency and robust standard deviation (Hz), relative spread (:data:`SPREAD_STDS` robust
    stds / median), median damping ratio (NaN when the model estimates none) and the number of
    outliers (:data:`OUTLIER_STDS`)."""

    mode: int
    count: int
    frequency_hz: float
    frequency_std_hz: float
    spread_rel: float
    damping: float
    outliers: int = 0
    #: the times of the stretch's first and last estimates (NaN without times)
    t_first: float = math.nan
    t_last: float = math.nan
    #: the stretch's number within its mode (1 = the first) and how many the mode has
    stretch: int = 1
    stretches: int = 1

    @property
    def tentative(self) -> bool:
        """Fewer than :data:`MIN_ESTIMATES` estimates: listed, never shaped for."""
        return self.count < MIN_ESTIMATES

    @property
    def undamped(self) -> bool:
        """A median damping ratio under :data:`UNDAMPED` (an identifier's: a line, module doc)."""
        return math.isfinite(self.damping) and self.damping < UNDAMPED


def stretches(f: np.ndarray) -> List[np.ndarray]:
    """The stretches of one mode's estimates ``f`` (in time order) as index arrays: a new one
    starts at the first of :data:`STRETCH_RUN` estimates running that lie more than
    :data:`STRETCH_REL` from the median of the stretch so far."""
    bounds, start = [0], 0
    i = 1
    while i + STRETCH_RUN <= len(f):
        centre = float(np.median(f[start:i]))
        run = f[i : i + STRETCH_RUN]
        if np.all(np.abs(run / centre - 1) > STRETCH_REL) and (
            np.all(run > centre) or np.all(run < centre)
        ):
            bounds.append(i)
            start = i
            i += STRETCH_RUN
        else:
            i += 1
    bounds.append(len(f))
    return [np.arange(a, b) for a, b in zip(bounds[:-1], bounds[1:])]


def renumber(frequency_hz, mode, t) -> np.ndarray:
    """The modes of estimates numbered by identity, 1 = the lowest: an estimator numbers its
    published modes by frequency, so a mode found below known ones renumbers them (a 20 s record
    of 5 + 17 Hz: the 17 Hz mode is 1 until the 5 Hz one publishes, then 2). Each number's
    estimates are cut into stretches (:func:`stretches`); in time order, a stretch continues the
    mode of an earlier one within :data:`STRETCH_REL` of it whose stretches all lie apart from
    it in time (of its own number first, else the nearest), else it begins a mode; then two modes
    holding consecutive stretches of one number, the first over before the second begins, are one
    mode that moved (a tip mass changed). Numbers <= 0 (the single-mode estimator) and
    non-finite frequencies are kept as they are."""
    f = np.asarray(frequency_hz, dtype=float)
    mode = np.asarray(mode).astype(int)
    out = mode.copy()
    live = (mode > 0) & np.isfinite(f)
    if len(np.unique(mode[live])) < 2:
        return out
    times = np.asarray(t, dtype=float)
    units = []  # (number, median, first t, last t, estimates), in time order
    for k in np.unique(mode[live]):
        sel = np.flatnonzero(live & (mode == k))
        sel = sel[np.argsort(times[sel], kind='stable')]
        for part in stretches(f[sel]):
            idx = sel[part]
            units.append((int(k), float(np.median(f[idx])), times[idx[0]], times[idx[-1]], idx))
    units.sort(key=lambda u: u[2])
    groups: list = []  # each mode: its units

    def apart(group, u):
        return all(v[3] < u[2] or u[3] < v[2] for v in group)

    for u in units:
        near = [g for g in groups if abs(u[1] / g[-1][1] - 1) <= STRETCH_REL and apart(g, u)]
        if near:
            min(near, key=lambda g: (g[-1][0] != u[0], abs(u[1] - g[-1][1]))).append(u)
        else:
            groups.append([u])
    for k in np.unique(mode[live]):  # the moves: a number's stretch after its previous one's
        mine = [u for u in units if u[0] == k]  # (in time order)
        for u, v in zip(mine, mine[1:]):
            before = next(g for g in groups if any(w is u for w in g))
            after = next(g for g in groups if any(w is v for w in g))
            if before is not after and max(w[3] for w in before) < min(w[2] for w in after):
                before.extend(after)  # two modes never seen at once: one, moved
                after.clear()
    groups = [g for g in groups if g]
    key = [float(np.median(f[np.concatenate([u[4] for u in g])])) for g in groups]
    for number, i in enumerate(np.argsort(key, kind='stable'), 1):
        for u in groups[i]:
            out[u[4]] = number
    return out


def _summary(k: int, f: np.ndarray, zeta: np.ndarray, t: Optional[np.ndarray]) -> ModeSummary:
    median = float(np.median(f))
    std = MAD_TO_STD * float(np.median(np.abs(f - median)))
    zeta = zeta[np.isfinite(zeta)]
    return ModeSummary(
        int(k),
        len(f),
        median,
        std,
        SPREAD_STDS * std / median,
        float(np.median(zeta)) if len(zeta) else math.nan,
        int(np.sum(np.abs(f - median) > OUTLIER_STDS * std)) if std else 0,
        float(t[0]) if t is not None else math.nan,
        float(t[-1]) if t is not None else math.nan,
    )


def summarise_modes(frequency_hz, damping, mode=None, t=None) -> List[ModeSummary]:
    """Per mode (lowest frequency first), the statistics of its finite estimates; with their
    times ``t``, per stretch of each mode (:func:`stretches`; in time order within a mode)."""
    frequency_hz = np.asarray(frequency_hz, dtype=float)
    damping = np.asarray(damping, dtype=float)
    mode = np.zeros(len(frequency_hz), dtype=int) if mode is None else np.asarray(mode)
    times = None if t is None else np.asarray(t, dtype=float)
    if times is not None:
        mode = renumber(frequency_hz, mode, times)
    groups = []  # per mode: (the median of its estimates, its summaries in time order)
    for k in np.unique(mode):
        sel = np.flatnonzero((mode == k) & np.isfinite(frequency_hz))
        if not len(sel):
            continue
        key = float(np.median(frequency_hz[sel]))
        if times is None:
            parts = [np.arange(len(sel))]
        else:
            sel = sel[np.argsort(times[sel], kind='stable')]
            parts = stretches(frequency_hz[sel])
        summaries = []
        for j, part in enumerate(parts, 1):
            idx = sel[part]
            m = _summary(k, frequency_hz[idx], damping[idx], None if times is None else times[idx])
            summaries.append(dataclasses.replace(m, stretch=j, stretches=len(parts)))
        groups.append((key, summaries))
    return [m for _, ms in sorted(groups, key=lambda g: g[0]) for m in ms]


def recommend_shaper(mode: ModeSummary) -> str:
    """``zvd`` or ``ei`` for the mode, by the rule of the module docstring."""
    zeta = 0.0 if not math.isfinite(mode.damping) else min(max(mode.damping, 0.0), MAX_DAMPING)
    s = min(mode.spread_rel, 0.99)
    worst = float(np.max(sensitivity(design('zvd', 1.0, zeta), [1 - s, 1 + s])))
    return 'ei' if worst > EI_VTOL else 'zvd'


def ros_double(value: float, decimals: int) -> str:
    """``value`` as a ROS 2 parameter literal that parses as a double (``0.0``, never ``0`` or
    ``1e-05``: an integer would not set a double parameter)."""
    text = f'{value:.{decimals}f}'.rstrip('0')
    return text + '0' if text.endswith('.') else text


def shaper_command(mode: ModeSummary, shaper: Optional[str] = None) -> str:
    """The ``ros2 run`` line starting ``shaper_node`` designed for the mode."""
    zeta = 0.0 if not math.isfinite(mode.damping) else min(max(mode.damping, 0.0), MAX_DAMPING)
    return (
        'ros2 run vib_estimator shaper_node --ros-args '
        f'-p shaper:={shaper or recommend_shaper(mode)} '
        f'-p initial_frequency_hz:={ros_double(mode.frequency_hz, 4)} '
        f'-p damping_ratio:={ros_double(zeta, 4)}'
    )


def _mode_line(m: ModeSummary) -> str:
    zeta = (
        'damping not estimated (--model damped-sinusoid estimates it)'
        if not math.isfinite(m.damping)
        else f'damping ratio {m.damping:.4f}'
    )
    odd = f', {m.outliers} outlier(s) beyond {OUTLIER_STDS:g} std' if m.outliers else ''
    when = f't {m.t_first:.4g}-{m.t_last:.4g} s: ' if m.stretches > 1 else ''
    weak = (
        f'; tentative: {m.count} estimate{"s" if m.count > 1 else ""}, fewer than {MIN_ESTIMATES}'
        if m.tentative
        else ''
    )
    return (
        f'{when}f = {m.frequency_hz:.4f} ± {m.frequency_std_hz:.2g} Hz '
        f'(robust std of {m.count} estimates{odd}{weak}), ' + zeta
    )


def shaped_mode(modes: List[ModeSummary], identified: bool = False) -> Optional[ModeSummary]:
    """The summary a shaper is designed for: the last stretch of the lowest mode whose last
    stretch is not tentative (nor, ``identified``, an undamped line); None if every mode is."""
    last = {}
    for m in modes:  # per mode in ascending frequency, its stretches in time order
        last[m.mode] = m
    usable = (m for m in last.values() if not (m.tentative or (identified and m.undamped)))
    return next(usable, None)


def summary_lines(modes: List[ModeSummary], identified: bool = False) -> List[str]:
    """The lines of the summary: one per mode (per stretch of a mode whose frequency moved), then
    the recommended shaper and its command, or why there is none. ``identified``: the modes are
    an output-only identifier's (an undamped one is a line, module doc)."""
    if not modes:
        return []
    lines = ['modes found:']
    for m in modes:
        name = f'mode {m.mode}' if m.mode else 'mode'
        if m.stretches > 1 and m.stretch == 1:
            lines.append(
                f'  {name}: the frequency moved during the record ({m.stretches} stretches, each '
                f'more than {100 * STRETCH_REL:g} % from the one before): summarised per stretch'
            )
        line = f'  {"  " if m.stretches > 1 else name + ": "}{_mode_line(m)}'
        if identified and m.undamped:
            line += (
                ": undamped, a line of the drive (a periodic motion's harmonic), not a mode of "
                'the structure; no shaper is designed for it'
            )
        lines.append(line)
    low = shaped_mode(modes, identified)
    if low is None:
        lines.append(
            f'no input shaper recommended: every mode rests on fewer than {MIN_ESTIMATES} '
            'estimates (a longer record, or the options the lines above suggest, give more)'
            + (' or is an undamped line' if identified else '')
        )
        return lines
    shaper = recommend_shaper(low)
    spread = f'±{SPREAD_STDS:g} std = ±{100 * low.spread_rel:.2g} %'
    why = (
        f"over the estimates' spread, {spread}, ZVD would leave more than "
        f'{100 * EI_VTOL:g} % residual vibration'
        if shaper == 'ei'
        else f'ZVD leaves under {100 * EI_VTOL:g} % residual vibration over the '
        f"estimates' spread, {spread}"
    )
    notes = []
    if low.stretches > 1:
        notes.append(f'for the last stretch, from t = {low.t_first:.4g} s')
    if low.mode != modes[0].mode:
        notes.append(
            'the modes below it are tentative'
            + (' or undamped lines' if identified else '')
            + '; shaper_node shapes one mode'
        )
    elif len({m.mode for m in modes}) > 1:
        notes.append('shaper_node shapes one mode: the lowest')
    lines.append(
        f'recommended input shaper: {shaper.upper()} for {low.frequency_hz:.4g} Hz '
        f'({why}' + ''.join('; ' + n for n in notes) + '):'
    )
    lines.append('  ' + shaper_command(low, shaper))
    return lines
