# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""One recording's frequency (or damping) from its estimates, with an honest 95 % interval.

``survey``'s default summary (:func:`combine`). Each estimate i says its value ``x_i``, its
standard deviation ``s_i`` and the stretch of signal it used, ``[t_i - T_i, t_i]`` (the stamp and
the window of the estimate). The recording's value is the inverse-variance weighted mean
``m = sum w_i x_i / W`` (``w_i = 1 / s_i^2``, ``W = sum w_i``) of the estimates left after a
robust screen (farther than :data:`SCREEN` x ``sqrt(s_i^2 + MAD-std^2)`` from the median: spurious
estimates).

Estimates over overlapping windows share their noise (the ``ambient`` estimator slides a 30 s
window by 1 s: some 30 consecutive estimates hold the same samples), so their errors are taken as
correlated by the share of the window they have in common, ``rho_ij = overlap_ij / sqrt(T_i T_j)``.
Its variance from the stds is then ``V_std = sum_ij w_i w_j s_i s_j rho_ij / W^2``, and
``n_eff = (sum s_i w_i)^2 / sum_ij w_i w_j s_i s_j rho_ij`` is the number of independent
estimates it is worth. The actual scatter checks the stds: the same sum over the residuals,
``V_res = sum_ij w_i w_j r_i r_j rho_ij / W^2`` (``r_i = x_i - m``, scaled by
``n_eff / (n_eff - 1)`` for the fitted mean), has the expectation ``kappa V_std`` if the stds are
right (``kappa = sum w w s s rho^2 / sum w w s s rho``), so ``B = V_res / (kappa V_std)`` (a
Birge ratio) says by how much the stds understate the scatter. The interval is
``m +- q sqrt(V_std max(1, B))``, ``q`` Student's 97.5 % point at ``n_eff - 1`` degrees of freedom
(B is measured from ``n_eff`` values; the stds are a floor, never trusted to be smaller than the
scatter: the ambient estimator's are right only to within 0.7-1.5x). Below two windows' worth
(``n_eff`` < 1 + 1e-9: all estimates over one stretch of signal) the stds alone, with the normal
97.5 % point. Without stds (none finite) the weights are equal and the interval is the scatter's
alone.
"""

from __future__ import annotations

import math
from typing import NamedTuple, Optional

import numpy as np

from .summary import MAD_TO_STD

#: two-sided confidence of the interval
CONFIDENCE = 0.95
#: an estimate farther from the median than this many of its (std, robust scatter) is screened out
SCREEN = 5.0


class Combined(NamedTuple):
    """A recording's value, its 95 % interval and standard deviation, the estimates it kept and
    the independent estimates they are worth, and the Birge ratio of their scatter."""

    value: float
    lo: float
    hi: float
    std: float
    kept: int
    n_eff: float
    birge: float


NOTHING = Combined(math.nan, math.nan, math.nan, math.nan, 0, 0.0, math.nan)


def _overlap_sums(start: np.ndarray, end: np.ndarray, a: np.ndarray):
    """``(sum_ij a_i a_j rho_ij, sum_ij a_i a_j rho_ij^2)`` over the windows [start, end] (sorted
    by end), ``rho_ij`` their overlap over the geometric mean of their lengths (1 on i = j)."""
    span = end - start
    s1 = s2 = float(np.sum(a * a))
    if len(a) < 2:
        return s1, s2
    # pairs (i, i + k) can overlap only while the later one ends within the longest window
    reach = np.searchsorted(end, end + span.max(), side='right') - np.arange(len(end)) - 1
    for k in range(1, int(reach.max()) + 1):
        common = np.minimum(end[:-k], end[k:]) - np.maximum(start[:-k], start[k:])
        norm = np.sqrt(span[:-k] * span[k:])
        rho = np.where((common > 0) & (norm > 0), common / np.where(norm > 0, norm, 1.0), 0.0)
        rho = np.minimum(rho, 1.0)
        pair = a[:-k] * a[k:]
        s1 += 2.0 * float(np.sum(pair * rho))
        s2 += 2.0 * float(np.sum(pair * rho * rho))
    return s1, s2


def combine(
    value: np.ndarray, std: np.ndarray, t: np.ndarray, span: Optional[np.ndarray] = None
) -> Combined:
    """The weighted value of estimates ``value`` (stds ``std``, stamps ``t``, windows ``span``
    s; none: disjoint) and its interval (module doc). NaN values are ignored; the interval is NaN
    with fewer than 2 estimates."""
    value, std, t = (np.asarray(a, dtype=float) for a in (value, std, t))
    span = np.zeros_like(t) if span is None else np.asarray(span, dtype=float)
    ok = np.isfinite(value) & np.isfinite(t)
    value, std, t, span = value[ok], std[ok], t[ok], np.nan_to_num(span[ok])
    if len(value) == 0:
        return NOTHING
    with_std = np.isfinite(std) & (std > 0)
    median = float(np.median(value))
    robust = MAD_TO_STD * float(np.median(np.abs(value - median)))
    if not with_std.any():
        std = np.full_like(value, robust if robust > 0 else 1.0)
    elif not with_std.all():  # a few without a std: kept, as the least precise of the others
        std = np.where(with_std, std, np.max(std[with_std]))
    near = np.abs(value - median) <= SCREEN * np.hypot(std, robust)
    value, std, t, span = value[near], std[near], t[near], span[near]
    order = np.argsort(t, kind='stable')
    value, std, t, span = value[order], std[order], t[order], span[order]
    w = 1.0 / std**2
    total = float(np.sum(w))
    mean = float(np.sum(w * value) / total)
    n = len(value)
    if n < 2:
        return Combined(mean, math.nan, math.nan, math.nan, n, float(n), math.nan)
    start = t - np.maximum(span, 0.0)
    ws = w * std
    corr, corr2 = _overlap_sums(start, t, ws)
    v_std = corr / total**2
    n_eff = float(np.sum(ws)) ** 2 / corr
    kappa = corr2 / corr
    resid = _overlap_sums(start, t, w * (value - mean))[0] / total**2
    birge = math.nan
    if n_eff > 1.0 + 1e-9:
        birge = resid * n_eff / (n_eff - 1.0) / (kappa * v_std)
    from scipy.stats import norm
    from scipy.stats import t as student

    tail = 0.5 + CONFIDENCE / 2
    if not math.isfinite(birge):  # one window's worth: the stds alone
        if not with_std.any():
            return Combined(mean, math.nan, math.nan, math.nan, n, n_eff, birge)
        q, var = float(norm.ppf(tail)), v_std
    else:
        q = float(student.ppf(tail, max(n_eff - 1.0, 1.0)))
        var = v_std * (max(1.0, birge) if with_std.any() else birge)
    half = q * math.sqrt(var)
    return Combined(mean, mean - half, mean + half, math.sqrt(var), n, n_eff, birge)
