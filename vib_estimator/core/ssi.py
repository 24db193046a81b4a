# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""Covariance-driven stochastic subspace identification (SSI-cov) of one window of any number of
channels: the modes of a structure driven by broadband, unmeasured forces, each with its
frequency, damping ratio, variance, shape and standard deviations. One channel is the case
m = 1 (a 1 x 1 correlation matrix, a shape of one entry); there is no other SSI path.

In this module's order (:mod:`.ambient` streams windows through it and tracks the modes):

1. **SSI-cov** (B. Peeters, G. De Roeck, "Reference-based stochastic subspace identification for
   output-only modal analysis", Mechanical Systems and Signal Processing 13 (1999) 855-878): the
   unbiased output correlation matrices ``R_k = E[y_t+k y_t^T]`` (m x m, k = 0 .. 2 p; kept by
   :mod:`.correlations`), their block Hankel matrix ``H = [R_{i+j+1}]`` (p = :func:`block_rows`
   block rows, every channel a reference), its SVD ``H = U S V^T``; at each model order n =
   :data:`ORDERS` the observability matrix ``O = U_n S_n^1/2``, the state matrix
   ``A = O_up^+ O_down``, ``C`` = the first block row of ``O`` and ``G`` = the first block column
   of ``S_n^1/2 V_n^T`` (:func:`ssi_poles`). Each eigenvalue ``lambda`` (eigenvector ``v``) of
   ``A`` gives a pole ``s = ln(lambda) fs``: frequency ``|s| / 2 pi``, damping ratio
   ``-Re s / |s|``, shape ``phi = C v`` and, from the modal decomposition
   ``R_k = sum_m phi_m g_m^T lambda_m^(k-1)`` (``g = v^-1 G``), its share of channel c's
   variance ``2 Re(phi_c g_c / lambda)``.
2. **Physical or spurious** (automated OMA with a stabilisation diagram: E. Reynders,
   J. Houbrechts, G. De Roeck, "Fully automated (operational) modal analysis", Mechanical
   Systems and Signal Processing 29 (2012) 228-250): poles with a damping ratio outside
   (0, ``max_damping``], above :data:`NU_MAX` fs or outside ``band_hz`` are dropped
   (``rejected_damping``); the others are clustered in frequency (neighbours within
   :data:`CLUSTER_TOL`, a cluster no wider than :data:`CLUSTER_SPAN`); a cluster is a mode when it
   holds a pole at :data:`MIN_SUPPORT` of the orders (``rejected_unstable``)
   (:func:`stable_clusters`). Its frequency, damping and variances are the medians over its
   poles; its shape the mean of its poles' shapes, each rotated onto the strongest pole's,
   normalised to unit length with its largest entry real and positive, with the per-channel RMS
   spread as its uncertainty (:func:`modes_at`). Two clusters within :data:`MERGE_TOL` are one
   mode if their shapes agree (MAC >= :data:`MAC_SAME`). A mode must stand
   :data:`MIN_PEAK_RATIO` above the noise on at least one channel (``rejected_weak``;
   :func:`strong`).
3. **The passes** (:func:`identify`): a first pass at the input rate (or, if it finds none, at
   the first of the rates halved in turn that does) finds the highest mode; a second pass at the
   rate that puts it at :data:`TOP_NU` (:func:`decimation_level`) resolves close modes over its
   lags. A window constant to rounding holds no vibration (``flat_windows``).
4. **Frequency refinement and standard deviations** (:mod:`.whittle`): on the channel where a
   mode stands highest above its noise, each mode a noise-driven SDOF plus white noise of the
   variance left over, the Whittle bound of its frequency and damping over the window's samples
   (with the modes within :data:`NEIGHBOURS` of it), then its frequency moved to the Whittle
   likelihood's maximum near it (:func:`.whittle.whittle_frequencies`). A mode whose relative
   frequency std exceeds :data:`MAX_STD_REL` is too weak to tell (``rejected_uncertain``).
"""

from __future__ import annotations

import math
from collections import Counter
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from .correlations import BLOCK_ROWS, CorrelationCascade
from .shapes import mac, normalise_shape
from .whittle import sdof_density, whittle_frequencies, whittle_std

#: with several channels fewer block rows: ``rows x channels`` at most about this (above the
#: highest model order, ``ORDERS``' 28; one channel: :data:`BLOCK_ROWS`, two: 20). Measured on
#: the 5-storey frame (5 channels, 10 seeds, RMS frequency error of every estimate, modes 1-5;
#: benchmarks/bench_channels.py): 100 (20 rows) 0.94/0.63/0.52/0.47/0.41 %, 60 (12)
#: 0.93/0.60/0.48/0.41/0.41, 40 (8) 0.84/0.58/0.45/0.39/0.39; 150 (30) and 200 (40) worse than
#: 100: a shorter Hankel matrix averages more of the window's correlation estimates per entry.
#: The SVD's cost grows as its cube.
JOINT_HANKEL = 40
#: ... but never fewer block rows than this: the Heritage Court Tower's 6 channels with 7 rows lose
#: its 3.85 Hz mode (5 of 6 published modes, 1.7 % of estimates off), with 8, 9, 10 or 17 rows
#: find all 6 (none off)
JOINT_MIN_ROWS = 8
#: model orders of the stabilisation diagram
ORDERS = tuple(range(4, 31, 4))
#: neighbouring poles within this relative frequency join one cluster
CLUSTER_TOL = 0.004
#: a cluster spans at most this relative frequency range
CLUSTER_SPAN = 0.02
#: fraction of the model orders at which a cluster must hold a pole to be a mode
MIN_SUPPORT = 0.5
#: highest pole frequency kept, in units of the sampling rate
NU_MAX = 0.45
#: two clusters closer than this (relative) are one mode ...
MERGE_TOL = 0.02
#: ... if their shapes' MAC is at least this (close modes with different shapes stay two)
MAC_SAME = 0.9
#: a mode's spectral peak must stand this far above the noise's density (else ``rejected_weak``)
MIN_PEAK_RATIO = 4.0
#: the second pass's rate puts the highest mode of the first at or below this fraction of it
TOP_NU = 0.4
#: a mode's Whittle bound counts the modes within this relative frequency of it (farther
#: ones' skirts carry no information on it, and each bound then costs a few modes, not all)
NEIGHBOURS = 0.2
#: a mode whose predicted relative frequency std exceeds this is not published
MAX_STD_REL = 0.02


def block_rows(channels: int) -> int:
    """Block rows of the Hankel matrix of ``channels`` channels: :data:`BLOCK_ROWS` for one,
    fewer when that would make it larger than :data:`JOINT_HANKEL` (at least
    :data:`JOINT_MIN_ROWS`)."""
    return max(JOINT_MIN_ROWS, min(BLOCK_ROWS, -(-JOINT_HANKEL // channels)))


# ---- 1. SSI-cov: the poles of each model order --------------------------------------------------
def hankel_svd(h: np.ndarray, top: int, m: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The leading ``top`` singular values ``s`` of a (square) block Hankel matrix ``h``, their
    left singular vectors ``u`` and the first ``m`` columns of the right ones ``vt``, from the
    eigendecomposition of ``h h^T`` (a third of the cost of an SVD; the signal's singular values
    lie decades above the rounding of the squares)."""
    lam, vec = np.linalg.eigh(h @ h.T)
    lam, u = lam[::-1][:top], vec[:, ::-1][:, :top]
    s = np.sqrt(np.maximum(lam, 1e-30 * max(lam[0], 1e-300)))
    return u, s, (u.T @ h[:, :m]) / s[:, None]


def state_matrices(u: np.ndarray, s: np.ndarray, m: int, orders: Sequence[int]) -> list:
    """The state matrices ``A = O_up^+ O_down`` of each model order from the SVD ``u``, ``s`` of
    a block Hankel matrix of ``m`` rows a block (``O = U_n S_n^1/2``): with ``U``'s columns
    orthonormal, ``O_up^T O_up = S^1/2 (I - W^T W) S^1/2`` (``W``: the last block row of
    ``U_n``), so ``A = S^-1/2 (I + W^T (I - W W^T)^-1 W) U_up^T U_down S^1/2`` (Woodbury): one
    ``m x m`` solve per order. None for an order where that is singular."""
    top = max(orders)
    shift = u[:-m, :top].T @ u[m:, :top]
    eye = np.eye(m)
    root = np.sqrt(s[:top])
    scale = root[None, :] / root[:, None]  # (each order's: its leading block)
    out = []
    for order in orders:
        w = u[-m:, :order]
        b = shift[:order, :order]
        wb = w @ b
        if m == 1:  # (a scalar: no LAPACK call)
            gap = 1.0 - float(w[0] @ w[0])
            if gap <= 0.0:
                out.append(None)
                continue
            b = b + w.T @ (wb / gap)
        else:
            try:
                b = b + w.T @ np.linalg.solve(eye - w @ w.T, wb)
            except np.linalg.LinAlgError:
                out.append(None)
                continue
        out.append(b * scale[:order, :order])
    return out


def ssi_poles(r: np.ndarray, fs: float, orders: Sequence[int] = ORDERS) -> list[np.ndarray]:
    """SSI-cov poles of correlation matrices ``r`` (:mod:`.correlations`,
    lags 0 .. 2 p: p block rows) at each model order: per order an array with a row per complex
    pair (upper half plane): frequency Hz, damping ratio, variance summed over channels, each
    channel's variance, the real then the imaginary parts of the (unnormalised) shape."""
    m, rows = r.shape[1], (len(r) - 1) // 2
    idx = 1 + np.add.outer(np.arange(rows), np.arange(rows))
    hankel = r[idx].transpose(0, 2, 1, 3).reshape(rows * m, rows * m)
    u, s, vt = hankel_svd(hankel, max(orders), m)
    roots = np.sqrt(s)
    obs = u[:m, : len(s)] * roots  # C, the first block row of O (each order's: its columns)
    g = roots[:, None] * vt[:, :m]  # G (each order's: its rows)
    lams, phis, gs = [], [], []
    for order, a in zip(orders, state_matrices(u, s, m, orders)):
        try:
            if a is None:
                raise np.linalg.LinAlgError
            lam, vec = np.linalg.eig(a)
            g_modal = np.linalg.solve(vec, g[:order])
        except np.linalg.LinAlgError:
            lam, vec, g_modal = np.empty(0, complex), np.empty((order, 0)), np.empty((0, m))
        keep = lam.imag > 1e-12
        lams.append(lam[keep])
        phis.append(obs[:, :order] @ vec[:, keep])  # channels x poles
        gs.append(g_modal[keep])
    return pole_rows(np.concatenate(lams), np.hstack(phis), np.vstack(gs), fs, lams)


def pole_rows(lam, phi, g_modal, fs, orders) -> list[np.ndarray]:
    """:func:`ssi_poles`' rows of all orders' poles at once (eigenvalues ``lam``, shapes
    ``phi``: channels x poles, ``g_modal``: poles x channels), split into one array per order
    (``orders``: each order's eigenvalues; element-wise arithmetic: the same floats as order
    by order)."""
    m = phi.shape[0]
    share = 2.0 * (phi * g_modal.T / lam).real  # each channel's variance
    pole = np.log(lam) * fs
    size = np.abs(pole)
    row = np.empty((len(lam), 3 + 3 * m))
    row[:, 0] = size / (2 * math.pi)
    row[:, 1] = -pole.real / size
    row[:, 2] = share.sum(axis=0)
    row[:, 3 : 3 + m] = share.T
    row[:, 3 + m : 3 + 2 * m] = phi.real.T
    row[:, 3 + 2 * m :] = phi.imag.T
    ends = np.cumsum([len(k) for k in orders]).tolist()
    return [row[a:b] for a, b in zip([0, *ends], ends)]


# ---- 2. physical or spurious: stable clusters, shapes, strong modes -----------------------------
@dataclass
class WindowModes:
    """The modes of one window, ascending: columns frequency, damping, summed variance, each
    channel's variance (``variances``), stds; shapes (modes x channels, complex, normalised) and
    their per-channel uncertainty."""

    frequency: np.ndarray
    damping: np.ndarray
    variances: np.ndarray
    frequency_std: np.ndarray
    damping_std: np.ndarray
    shapes: np.ndarray
    shape_std: np.ndarray

    def __len__(self) -> int:
        return len(self.frequency)

    def take(self, keep) -> 'WindowModes':
        return WindowModes(*(getattr(self, f)[keep] for f in self.__dataclass_fields__))


def order_support(group: np.ndarray) -> int:
    """The model orders at which a cluster of :func:`stable_clusters` holds a pole."""
    return len(set(group[:, -2].tolist()))


def stable_clusters(
    poles: list[np.ndarray],
    fs: float,
    max_damping: float,
    band: tuple[float, float],
    counts: dict[str, int],
) -> list[np.ndarray]:
    """The stable clusters of a stabilisation diagram ``poles`` (one array per model order whose
    first three columns are frequency, damping, variance; further columns ride along): poles with
    a damping ratio in (0, ``max_damping``], below :data:`NU_MAX` fs and in ``band``, grouped in
    frequency (neighbours within :data:`CLUSTER_TOL`, a group no wider than :data:`CLUSTER_SPAN`);
    a group is kept when it holds a pole at :data:`MIN_SUPPORT` of the orders. Each cluster: its
    poles' rows with two columns appended, the order's index and the row's index in that order;
    ascending frequency. Counts the rejected poles/clusters."""
    width = (poles[0].shape[1] if poles else 3) + 2
    allp = np.empty((0, width))
    if poles:  # all orders' rows at once (in order: the same rows as order by order)
        p = np.concatenate(poles)
        sizes = [len(q) for q in poles]
        k = np.repeat(np.arange(len(poles)), sizes)
        row = np.arange(len(p)) - np.repeat(np.cumsum([0] + sizes[:-1]), sizes)
        ok = (
            (p[:, 1] > 0)
            & (p[:, 1] <= max_damping)
            & (p[:, 0] < NU_MAX * fs)
            & (p[:, 0] >= band[0])
            & (p[:, 0] <= band[1])
        )
        counts['rejected_damping'] += int(np.count_nonzero(~ok))
        allp = np.column_stack((p, k, row))[ok]
    allp = allp[np.argsort(allp[:, 0])]
    clusters = []
    start = 0
    n_orders = len(poles)
    f = allp[:, 0].tolist()  # (Python floats: the same comparisons, without numpy's scalars)
    for i in range(1, len(f) + 1):
        if (
            i < len(f)
            and f[i] <= f[i - 1] * (1 + CLUSTER_TOL)
            and f[i] <= f[start] * (1 + CLUSTER_SPAN)
        ):
            continue
        group = allp[start:i]
        start = i
        if order_support(group) / n_orders < MIN_SUPPORT:
            counts['rejected_unstable'] += 1
            continue
        clusters.append(group)
    return clusters


def _cluster_shape(group: np.ndarray, m: int) -> tuple[np.ndarray, np.ndarray]:
    """The cluster's shape and its per-channel uncertainty (see the module doc, step 2)."""
    if m == 1:  # (what the arithmetic below gives, to rounding: a one-entry shape is 1)
        return np.ones(1, dtype=complex), np.zeros(1)
    phis = group[:, 3 + m : 3 + 2 * m] + 1j * group[:, 3 + 2 * m : 3 + 3 * m]
    big = phis[np.arange(len(phis)), np.argmax(np.abs(phis), axis=1)]
    size = np.abs(big)
    unit = np.divide(big, size, out=np.ones_like(big), where=size > 0)
    norm = np.where(size > 0, np.sqrt(np.sum(np.abs(phis) ** 2, axis=1)), 1.0)
    phis = phis / (unit * norm)[:, None]  # each normalise_shape'd
    ref = phis[int(np.argmax(group[:, 2]))]
    rot = phis.conj() @ ref
    phis = phis * (rot / np.maximum(np.abs(rot), 1e-300))[:, None]
    mean = phis.mean(axis=0)
    spread = np.sqrt(np.mean(np.abs(phis - mean) ** 2, axis=0))
    return normalise_shape(mean), spread


def medians(a: np.ndarray) -> np.ndarray:
    """``numpy.median(a, axis=0)``, the same floats (its partition, then the middle row or the
    two middle ones' mean; a column's NaN, which the partition puts last, where it holds one),
    in a few array calls, not its ~20 us of them (twice a cluster)."""
    half = len(a) // 2
    part = np.partition(a, [half, -1] if len(a) % 2 else [half - 1, half, -1], axis=0)
    # (numpy's mean sums from +0.0: a median of -0.0 reads +0.0)
    mid = 0.0 + part[half] if len(a) % 2 else (0.0 + part[half - 1] + part[half]) / 2
    return np.where(np.isnan(part[-1]), part[-1], mid)


def modes_at(
    r: np.ndarray, fs: float, max_damping: float, band: tuple[float, float], counts: dict
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The clustered modes of correlation matrices ``r`` (lags 0 .. 2 :func:`block_rows`) at
    ``fs``: (rows of frequency, damping, each channel's variance; shapes; shape stds), close
    clusters merged when their shapes agree."""
    m = r.shape[1]
    clusters = stable_clusters(
        ssi_poles(r, fs), fs, max_damping, (band[0], min(band[1], NU_MAX * fs)), counts
    )
    rows, shapes, stds, support = [], [], [], []
    for group in clusters:
        shape, spread = _cluster_shape(group, m)
        med = medians(group[:, : 3 + m])
        row = np.concatenate((med[:2], np.maximum(med[3:], 0.0)))
        sup = order_support(group)
        if rows and row[0] <= rows[-1][0] * (1 + MERGE_TOL) and mac(shape, shapes[-1]) >= MAC_SAME:
            if sup > support[-1]:
                rows[-1], shapes[-1], stds[-1], support[-1] = row, shape, spread, sup
            continue
        rows.append(row)
        shapes.append(shape)
        stds.append(spread)
        support.append(sup)
    return (
        np.array(rows).reshape(-1, 2 + m),
        np.array(shapes, dtype=complex).reshape(-1, m),
        np.array(stds).reshape(-1, m),
    )


def _densities(rows: np.ndarray, fs: float) -> np.ndarray:
    """Each mode's density at each mode's frequency on each channel: (at, modes, channels)."""
    dt = 1.0 / fs
    c = np.cos(2 * math.pi * rows[:, 0] * dt)
    m = rows.shape[1] - 2
    out = np.zeros((len(rows), len(rows), m))
    for j, (f, z) in enumerate(rows[:, :2]):
        unit = sdof_density(c, f, z, 1.0, dt)  # linear in the variance
        out[:, j, :] = unit[:, None] * rows[j, 2:][None, :]
    return out


def strong(rows, shapes, stds, totals, fs, counts):
    """The modes that stand :data:`MIN_PEAK_RATIO` above everything else at their
    frequency on at least one channel (the weakest dropped first, then the others judged again);
    with each channel's noise variance and each mode's best channel's peak ratio."""
    while True:
        noise = np.maximum(totals - rows[:, 2:].sum(axis=0), 1e-3 * totals)
        if not len(rows):
            return rows, shapes, stds, noise, np.empty(0, dtype=int)
        dens = _densities(rows, fs)
        k = np.arange(len(rows))
        own = dens[k, k, :]  # modes x channels
        rest = noise[None, :] + dens.sum(axis=1) - own
        # a channel constant over the window (an IMU axis at rest) has no density: ratio 0
        ratio = np.divide(own, rest, out=np.zeros_like(own), where=rest > 0)
        best = ratio.max(axis=1)
        if np.all(best >= MIN_PEAK_RATIO):
            return rows, shapes, stds, noise, np.argmax(ratio, axis=1)
        worst = int(np.argmin(best))
        counts['rejected_weak'] += 1
        rows, shapes, stds = (np.delete(x, worst, axis=0) for x in (rows, shapes, stds))


# ---- 3. the passes, 4. refinement and standard deviations ---------------------------------------
def decimation_level(cascade: CorrelationCascade, fs: float, top_hz: float) -> int:
    """The level of the lowest rate fs / 2^j that keeps ``top_hz`` at or below :data:`TOP_NU`
    of it and :data:`MIN_SAMPLES` samples in the window."""
    j = 0
    while top_hz <= 0.5 * TOP_NU * fs / 2**j and cascade.can_halve(j):
        j += 1
    return j


def identify(
    cascade: CorrelationCascade,
    fs: float,
    max_damping: float = 0.1,
    band: tuple[float, float] = (0.0, math.inf),
    counts: dict[str, int] | None = None,
    top_hz: float = 0.0,
    search: bool = True,
) -> tuple[WindowModes, float]:
    """Modes of one window (its :class:`.correlations.CorrelationCascade` of lags 0 .. 2
    :func:`block_rows`; ``fs`` the input rate): (:class:`WindowModes`, the summed variance).
    A first pass at ``fs`` (or, if it finds none, at the first of the rates halved in turn that
    does) finds the highest mode (or ``top_hz``, the highest mode known, if higher; with
    ``search`` false and ``top_hz`` given, no first pass); when it lies low enough, the modes
    come from a second pass at the rate :func:`decimation_level` gives, over whose lags close
    modes are resolved. Then each mode's bound and refined frequency on its best channel
    (:func:`refine`). ``counts``: the rejections are added to it."""
    counts = Counter() if counts is None else counts
    m = cascade.channels
    flat = cascade.flat()  # constant channels: no density (their halvings: rounding only)
    totals = np.where(flat, 0.0, cascade.variance())

    def passed(level):
        r = cascade.correlations(level)
        found = modes_at(r, fs / 2**level, max_damping, band, counts)
        return (*strong(*found, totals, fs, counts), level)

    found = (np.empty((0, 2 + m)), np.empty((0, m), complex), np.empty((0, m)))
    out = (*found, totals, np.empty(0, dtype=int), 0)
    if np.all(flat):  # nothing to identify
        counts['flat_windows'] += 1
        search, top_hz = False, 0.0
    elif search or top_hz <= 0:
        # the search: from the full rate down by halvings until a level finds a mode (a low
        # mode spans too few periods of the full rate's lags to be stable there)
        level = 0
        while True:
            out = passed(level)
            if len(out[0]) or not cascade.can_halve(level):
                break
            level += 1
    top = max(float(np.max(out[0][:, 0])) if len(out[0]) else 0.0, top_hz)
    if top > 0:
        level = decimation_level(cascade, fs, top)
        if level > 0 or not (search or top_hz <= 0):  # (no search pass ran at fs)
            out = passed(level)
    rows, shapes, spread, noise, best, level = out
    if np.any(flat) and len(shapes):
        # a constant channel does not move: its entries are the eigenvectors' rounding (1e-12)
        shapes = shapes.copy()
        shapes[:, flat] = 0.0
        shapes = np.array([normalise_shape(phi) for phi in shapes]).reshape(shapes.shape)
    freq, std = refine(cascade, fs, level, rows, shapes, noise, best)
    modes = WindowModes(freq, rows[:, 1], rows[:, 2:], std[:, 0], std[:, 1], shapes, spread)
    weak = ~(modes.frequency_std <= MAX_STD_REL * modes.frequency)
    counts['rejected_uncertain'] += int(np.count_nonzero(weak))
    return modes.take(~weak), float(np.sum(totals))


def refine(cascade, fs, level, rows, shapes, noise, best) -> tuple[np.ndarray, np.ndarray]:
    """Each mode's frequency and its (frequency, damping) stds (``rows``: frequency, damping, each
    channel's variance; ``shapes``: normalised; ``noise``: each channel's noise variance at
    ``fs``; ``best``: each mode's best channel). The stds: the Whittle bound
    (:func:`.whittle.whittle_std`) on the best channel over the window's samples at ``fs``, with
    the modes there within :data:`NEIGHBOURS` of it. The frequency: refined to the maximum of
    the Whittle likelihood of every channel of the window at the level ``level`` the modes came
    from (:func:`.whittle.whittle_frequencies`; each mode of its real unit shape and its
    variance summed over channels; the noise's over ``2^level`` there). Refined on the best
    channel alone instead (tried on the shear frame, ``bench_channels.py``, 3 seeds) every
    mode's RMS error was 0.01-0.06 % worse than the joint SSI's: one channel's information
    where the SSI has all of them."""
    std = np.full((len(rows), 2), math.nan)
    bounds = {}  # (channel, the modes counted) -> their stds (close modes share one)
    for j, c in enumerate(best):
        near = np.flatnonzero(
            (rows[:, 2 + c] > 0) & (np.abs(rows[:, 0] / rows[j, 0] - 1) <= NEIGHBOURS)
        )
        key = (int(c), tuple(near.tolist()))
        if key not in bounds:
            triples = [(rows[i, 0], rows[i, 1], rows[i, 2 + c]) for i in near]
            bounds[key] = whittle_std(triples, noise[c], fs, cascade.samples(0))
        std[j] = bounds[key][int(np.flatnonzero(near == j)[0])]
    if not len(rows):
        return rows[:, 0].copy(), std
    live = noise > 0  # (a channel constant over the window has neither noise nor modes)
    real = shapes.real[:, live]
    real = real / np.linalg.norm(real, axis=1, keepdims=True)
    modal = np.column_stack((rows[:, :2], rows[:, 2:].sum(axis=1)))
    x, rate = cascade.window(level)[:, live], fs / 2**level
    freq = whittle_frequencies(x, rate, modal, noise[live] / 2**level, std[:, 0], shapes=real)
    return freq, std
