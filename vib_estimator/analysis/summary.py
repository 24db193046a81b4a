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
"""

from __future__ import annotations

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


def summarise_modes(frequency_hz, damping, mode=None) -> List[ModeSummary]:
    """Per mode (lowest frequency first), the statistics of its finite estimates."""
    frequency_hz = np.asarray(frequency_hz, dtype=float)
    damping = np.asarray(damping, dtype=float)
    mode = np.zeros(len(frequency_hz), dtype=int) if mode is None else np.asarray(mode)
    out = []
    for k in np.unique(mode):
        sel = (mode == k) & np.isfinite(frequency_hz)
        if not sel.any():
            continue
        f = frequency_hz[sel]
        median = float(np.median(f))
        std = MAD_TO_STD * float(np.median(np.abs(f - median)))
        zeta = damping[sel]
        zeta = zeta[np.isfinite(zeta)]
        out.append(
            ModeSummary(
                int(k),
                int(sel.sum()),
                median,
                std,
                SPREAD_STDS * std / median,
                float(np.median(zeta)) if len(zeta) else math.nan,
                int(np.sum(np.abs(f - median) > OUTLIER_STDS * std)) if std else 0,
            )
        )
    return sorted(out, key=lambda m: m.frequency_hz)


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


def summary_lines(modes: List[ModeSummary]) -> List[str]:
    """The lines of the summary: one per mode, then the recommended shaper and its command."""
    if not modes:
        return []
    lines = ['modes found:']
    for m in modes:
        name = f'mode {m.mode}' if m.mode else 'mode'
        zeta = (
            'damping not estimated (--model damped-sinusoid estimates it)'
            if not math.isfinite(m.damping)
            else f'damping ratio {m.damping:.4f}'
        )
        odd = f', {m.outliers} outlier(s) beyond {OUTLIER_STDS:g} std' if m.outliers else ''
        lines.append(
            f'  {name}: f = {m.frequency_hz:.4f} ± {m.frequency_std_hz:.2g} Hz '
            f'(robust std of {m.count} estimates{odd}), ' + zeta
        )
    low = modes[0]
    shaper = recommend_shaper(low)
    spread = f'±{SPREAD_STDS:g} std = ±{100 * low.spread_rel:.2g} %'
    why = (
        f"over the estimates' spread, {spread}, ZVD would leave more than "
        f'{100 * EI_VTOL:g} % residual vibration'
        if shaper == 'ei'
        else f'ZVD leaves under {100 * EI_VTOL:g} % residual vibration over the '
        f"estimates' spread, {spread}"
    )
    lines.append(
        f'recommended input shaper: {shaper.upper()} for {low.frequency_hz:.4g} Hz '
        f'({why}' + ('; shaper_node shapes one mode: the lowest' if len(modes) > 1 else '') + '):'
    )
    lines.append('  ' + shaper_command(low, shaper))
    return lines
