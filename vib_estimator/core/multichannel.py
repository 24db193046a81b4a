# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""Several channels, one set of modes: multi-channel covariance-driven SSI with mode shapes.

``excitation = ambient`` with two or more channels (several accelerometers, the three axes of an
IMU, the joints of an arm): the modes are identified jointly from all channels' output
correlations, each with its **shape** -- how much, and in which phase, each channel moves in it.
One channel is not routed here: it stays :class:`..ambient.AmbientEstimator`, bit for bit.

Interface: :class:`JointAmbientEstimator` ``(config, channels)`` ``.process(t, Y) ->``
:class:`JointEstimates` (``Y``: samples x channels), ``.update(t, y) -> list[Estimate]``,
``.counters``, ``.reset()``, ``.restart()``, ``.config``, ``.channels``.

Method, per analysis (every :data:`..ambient.HOP_S` of input once ``ambient_window_s`` of samples
are in), as the single-channel identifier (:mod:`..ambient`, whose stabilisation and clustering
are reused) with matrices in place of scalars:

1. **Joint SSI-cov**: the correlation matrices ``R_k = E[y_t+k y_t^T]`` (channels x channels,
   k = 0 .. 2 p, unbiased), their block Hankel matrix ``H = [R_{i+j+1}]`` (p =
   :func:`joint_rows` block rows, every channel a reference), its SVD; at each model
   order ``O = U_n S_n^1/2``, ``A = O_up^+ O_down``, ``C`` = the first block row of ``O``, ``G``
   = the first block column of ``S_n^1/2 V_n^T``. Each eigenvalue ``lambda`` (eigenvector
   ``v``) of ``A`` is a pole of every channel at once; its **shape** is ``phi = C v``, its share
   of channel c's variance ``2 Re(phi_c g_c / lambda)`` (``g = v^-1 G``).
2. **Physical or spurious**: the poles of all orders go through
   :func:`..ambient.stable_clusters` (damping, band, frequency clusters stable over the orders),
   their shapes riding along. A cluster's shape is the mean of its poles' shapes, each first
   rotated onto the cluster's strongest pole's (complex scale), normalised to unit length with
   its largest entry real and positive; its **uncertainty** the per-channel RMS deviation of the
   poles' shapes from that mean (the spread over the stable model orders). Two clusters within
   :data:`..ambient.MERGE_TOL` are one mode only if their shapes agree (MAC >=
   :data:`MAC_SAME`): close modes with different shapes stay two. A mode must stand
   :data:`..ambient.MIN_PEAK_RATIO` above the noise on **at least one** channel (a mode
   invisible on some channels is still found on the others).
3. **Standard deviations**: the Whittle bound (:func:`..ambient.whittle_std`) on the channel where
   the mode stands highest above its noise (with the modes there within :data:`NEIGHBOURS`),
   calibrated across windows as the single-channel identifier's (:class:`..ambient.ModeTrack`).
4. **Identity over time**: a window's mode continues the tracked mode nearest in frequency (within
   :data:`..ambient.MATCH_TOL`) whose last shape it matches (MAC >= :data:`MAC_MATCH`); the MAC
   between the two is published with the estimate (``mac``, NaN for a mode's first window).
   Confirmation, loss and numbering are the single-channel identifier's.

Each estimate: an :class:`..estimator.Estimate` (``amplitude`` = the RMS over channels of the
modal response summed in quadrature, ``fit`` = share of the summed channel variances the modes
explain) with its ``shape``, ``shape_std`` and ``mac``.

Bad samples never raise: a sample with any non-finite channel is skipped (``skipped_non_finite``);
stamps are handled as the single-channel identifier's (duplicates, out of order, gaps and jumps).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from .ambient import (
    BLOCK_ROWS,
    COUNTER_NAMES,
    MATCH_TOL,
    MAX_STD_REL,
    MAX_TRACKS,
    MERGE_TOL,
    MIN_PEAK_RATIO,
    NU_MAX,
    ORDERS,
    ModeTrack,
    SlidingWindowIdentifier,
    decimation_level,
    estimate_columns,
    hankel_svd,
    order_support,
    sdof_psd,
    stable_clusters,
    state_matrices,
    whittle_std,
)
from .config import EstimatorConfig
from .estimator import Estimate, EstimateArrays

#: two clusters closer than ``MERGE_TOL`` are one mode only if their shapes' MAC is at least this
MAC_SAME = 0.9
#: a window's mode continues a tracked one only if their shapes' MAC is at least this
MAC_MATCH = 0.5
#: block rows of the joint Hankel matrix: half the single channel's (the model orders need only
#: ``rows x channels`` above the highest order; the SVD costs 8 times less; on the shear frame,
#: two seeds, as accurate as 40 rows)
JOINT_BLOCK_ROWS = BLOCK_ROWS // 2
#: with many channels fewer block rows: ``rows x channels`` at most about this (above the
#: highest model order, ``ORDERS``' 28). Measured on the 5-storey frame (5 channels, 10 seeds,
#: RMS frequency error of every estimate, modes 1-5; benchmarks/bench_channels.py): 100 (20
#: rows) 0.94/0.63/0.52/0.47/0.41 %, 60 (12) 0.93/0.60/0.48/0.41/0.41, 40 (8)
#: 0.84/0.58/0.45/0.39/0.39; 150 (30) and 200 (40) worse than 100: a shorter Hankel matrix
#: averages more of the window's correlation estimates per entry. The SVD's cost grows as its
#: cube.
JOINT_HANKEL = 40
#: ... but never fewer block rows than this: the Heritage Court Tower's 6 channels with 7 rows lose
#: its 3.85 Hz mode (5 of 6 published modes, 1.7 % of estimates off), with 8, 9, 10 or 17 rows
#: find all 6 (none off)
JOINT_MIN_ROWS = 8
#: a mode's Whittle bound counts the modes within this relative frequency of it (farther
#: ones' skirts carry no information on it, and each bound then costs a few modes, not all)
NEIGHBOURS = 0.2
#: the fewest channels of a joint identification (one channel is the single-channel identifier's)
MIN_CHANNELS = 2


def mac(a: np.ndarray, b: np.ndarray) -> float:
    """Modal assurance criterion ``|a^H b|^2 / (|a|^2 |b|^2)`` of two (complex) shapes: 1 for
    shapes equal up to a complex scale, 0 for orthogonal ones."""
    a, b = np.asarray(a), np.asarray(b)
    den = float(np.vdot(a, a).real * np.vdot(b, b).real)
    return float(abs(np.vdot(a, b)) ** 2 / den) if den > 0 else 0.0


def continues(f: float, shape: np.ndarray, frequency: float, last_shape: np.ndarray):
    """The relative frequency distance of a mode (``f``, ``shape``) from a tracked one
    (``frequency``, ``last_shape``) if it continues it -- within :data:`..ambient.MATCH_TOL` and
    with a MAC of at least :data:`MAC_MATCH` --, else None."""
    dist = abs(f / frequency - 1)
    return dist if dist <= MATCH_TOL and mac(shape, last_shape) >= MAC_MATCH else None


def normalise_shape(phi: np.ndarray) -> np.ndarray:
    """``phi`` scaled to unit length with its largest entry real and positive."""
    k = int(np.argmax(np.abs(phi)))
    scale = phi[k] / abs(phi[k]) * np.linalg.norm(phi) if abs(phi[k]) > 0 else 1.0
    return phi / scale


# ---- one window ---------------------------------------------------------------------------------
def joint_rows(channels: int) -> int:
    """Block rows of the joint Hankel matrix of ``channels`` channels: :data:`JOINT_BLOCK_ROWS`,
    fewer when that would make it larger than :data:`JOINT_HANKEL` (at least
    :data:`JOINT_MIN_ROWS`)."""
    return max(JOINT_MIN_ROWS, min(JOINT_BLOCK_ROWS, -(-JOINT_HANKEL // channels)))


def joint_poles(r: np.ndarray, fs: float, orders: Sequence[int] = ORDERS) -> list[np.ndarray]:
    """Joint SSI-cov poles of correlation matrices ``r`` (:func:`correlation_matrices`, lags 0 ..
    2 p: p block rows) at each model order: per order an array with a row per complex pair
    (upper half plane): frequency Hz, damping ratio, variance summed over channels, each
    channel's variance, the real then the imaginary parts of the (unnormalised) shape."""
    m, rows = r.shape[1], (len(r) - 1) // 2
    idx = 1 + np.add.outer(np.arange(rows), np.arange(rows))
    hankel = r[idx].transpose(0, 2, 1, 3).reshape(rows * m, rows * m)
    u, s, vt = hankel_svd(hankel, max(orders), m)
    width = 3 + 3 * m
    out = []
    for order, a in zip(orders, state_matrices(u, s, m, orders)):
        root = np.sqrt(s[:order])
        obs = u[:m, :order] * root  # C, the first block row of O
        try:
            if a is None:
                raise np.linalg.LinAlgError
            lam, vec = np.linalg.eig(a)
            g_modal = np.linalg.solve(vec, root[:, None] * vt[:order, :m])
        except np.linalg.LinAlgError:
            out.append(np.empty((0, width)))
            continue
        keep = lam.imag > 1e-12
        lam_k = lam[keep]
        phi = (obs[:m] @ vec)[:, keep]  # channels x poles
        share = 2.0 * (phi * g_modal[keep].T / lam_k).real  # each channel's variance
        pole = np.log(lam_k) * fs
        freq = np.abs(pole) / (2 * math.pi)
        zeta = -pole.real / np.abs(pole)
        out.append(
            np.column_stack((freq, zeta, share.sum(axis=0), share.T, phi.real.T, phi.imag.T))
        )
    return out


@dataclass
class JointModes:
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

    def take(self, keep) -> 'JointModes':
        return JointModes(*(getattr(self, f)[keep] for f in self.__dataclass_fields__))


def _cluster_shape(group: np.ndarray, m: int) -> tuple[np.ndarray, np.ndarray]:
    """The cluster's shape and its per-channel uncertainty (see the module doc, step 2)."""
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


def joint_modes_at(
    r: np.ndarray, fs: float, max_damping: float, band: tuple[float, float], counts: dict
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The clustered modes of correlation matrices ``r`` (:func:`correlation_matrices`, lags 0 ..
    2 :func:`joint_rows`) at ``fs``: (rows of frequency, damping, each channel's variance;
    shapes; shape stds), close clusters merged when their shapes agree."""
    m = r.shape[1]
    clusters = stable_clusters(
        joint_poles(r, fs), fs, max_damping, (band[0], min(band[1], NU_MAX * fs)), counts
    )
    rows, shapes, stds, support = [], [], [], []
    for group in clusters:
        shape, spread = _cluster_shape(group, m)
        row = np.concatenate(
            (
                np.median(group[:, :2], axis=0),
                np.maximum(np.median(group[:, 3 : 3 + m], axis=0), 0.0),
            )
        )
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
    w = 2 * math.pi * rows[:, 0] * dt
    m = rows.shape[1] - 2
    out = np.zeros((len(rows), len(rows), m))
    for j, (f, z) in enumerate(rows[:, :2]):
        unit = sdof_psd(w, f, z, 1.0, dt)  # linear in the variance
        out[:, j, :] = unit[:, None] * rows[j, 2:][None, :]
    return out


def strong_joint(rows, shapes, stds, totals, fs, counts):
    """The modes that stand :data:`..ambient.MIN_PEAK_RATIO` above everything else at their
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


def identify_joint(
    cascade,
    fs: float,
    max_damping: float = 0.1,
    band: tuple[float, float] = (0.0, math.inf),
    counts: dict[str, int] | None = None,
    top_hz: float = 0.0,
    search: bool = True,
) -> tuple[JointModes, float]:
    """Modes of one window (its :class:`..ambient.CorrelationCascade` of lags 0 .. 2
    :func:`joint_rows`; ``fs`` the input rate), the passes of :func:`..ambient.identify` (a search
    from the full rate down, then the rate that puts the highest mode at
    :data:`..ambient.TOP_NU`): (:class:`JointModes`, the summed variance)."""
    counts = dict.fromkeys(COUNTER_NAMES, 0) if counts is None else counts
    m = cascade.channels
    flat = cascade.flat()  # constant channels: no density (their halvings: rounding only)
    totals = np.where(flat, 0.0, cascade.variance())

    def modes_at(level):
        r = cascade.correlations(level)
        found = joint_modes_at(r, fs / 2**level, max_damping, band, counts)
        return strong_joint(*found, totals, fs, counts)

    found = (np.empty((0, 2 + m)), np.empty((0, m), complex), np.empty((0, m)))
    strong = (*found, totals, np.empty(0, dtype=int))
    if np.all(flat):  # nothing to identify
        counts['flat_windows'] += 1
        search, top_hz = False, 0.0
    elif search or top_hz <= 0:
        level = 0
        while True:
            strong = modes_at(level)
            if len(strong[0]) or not cascade.can_halve(level):
                break
            level += 1
    top = max(float(np.max(strong[0][:, 0])) if len(strong[0]) else 0.0, top_hz)
    if top > 0:
        level = decimation_level(cascade, fs, top)
        if level > 0 or not (search or top_hz <= 0):  # (no search pass ran at fs)
            strong = modes_at(level)
    rows, shapes, spread, noise, best = strong
    if np.any(flat) and len(shapes):
        # a constant channel does not move: its entries are the eigenvectors' rounding (1e-12)
        shapes = shapes.copy()
        shapes[:, flat] = 0.0
        shapes = np.array([normalise_shape(phi) for phi in shapes]).reshape(shapes.shape)
    std = np.full((len(rows), 2), math.nan)
    for j, c in enumerate(best):
        # the bound on the mode's best channel, with the modes there within NEIGHBOURS of it
        near = np.flatnonzero(
            (rows[:, 2 + c] > 0) & (np.abs(rows[:, 0] / rows[j, 0] - 1) <= NEIGHBOURS)
        )
        triples = [(rows[i, 0], rows[i, 1], rows[i, 2 + c]) for i in near]
        cstd = np.array(whittle_std(triples, noise[c], fs, cascade.samples(0))).reshape(-1, 2)
        std[j] = cstd[int(np.flatnonzero(near == j)[0])]
    modes = JointModes(rows[:, 0], rows[:, 1], rows[:, 2:], std[:, 0], std[:, 1], shapes, spread)
    weak = ~(modes.frequency_std <= MAX_STD_REL * modes.frequency)
    counts['rejected_uncertain'] += int(np.count_nonzero(weak))
    return modes.take(~weak), float(np.sum(totals))


# ---- streaming ----------------------------------------------------------------------------------
@dataclass
class JointEstimates:
    """Estimates of a batch run: the columns of :class:`..estimator.EstimateArrays`, the shapes
    (estimates x channels, complex), their stds and the MACs, in the estimates' order."""

    estimates: EstimateArrays
    shapes: np.ndarray
    shape_std: np.ndarray
    mac: np.ndarray
    channels: tuple[str, ...]

    def __len__(self) -> int:
        return len(self.estimates)

    @classmethod
    def of(cls, out: Sequence[Estimate], channels: tuple[str, ...]) -> 'JointEstimates':
        """The columns of the estimates ``out`` (with shapes) of ``channels``, in their order."""
        m = len(channels)
        return cls(
            estimate_columns(out),
            np.array([e.shape for e in out], dtype=complex).reshape(-1, m),
            np.array([e.shape_std for e in out]).reshape(-1, m),
            np.array([e.mac for e in out]),
            channels,
        )


def as_channels(t: Sequence[float], y: np.ndarray, channels: int) -> tuple[np.ndarray, np.ndarray]:
    """``t``, ``y`` as contiguous float64 arrays, ``y`` samples x ``channels`` (ValueError
    otherwise)."""
    t = np.ascontiguousarray(t, dtype=np.float64)
    y = np.ascontiguousarray(y, dtype=np.float64)
    if t.ndim != 1 or y.shape != (len(t), channels):
        raise ValueError(
            f't must be 1-D and y samples x {channels} channels, got {t.shape}, {y.shape}'
        )
    return t, y


class _ShapeTrack(ModeTrack):
    """A tracked mode with its last shape."""

    __slots__ = ('shape',)


class JointAmbientEstimator(SlidingWindowIdentifier):
    """Sliding-window joint output-only identification; see the module docstring.

    ``channels``: the channel names (their count is the number of columns fed)."""

    def __init__(self, config: EstimatorConfig, channels: Sequence[str]):
        channels = tuple(str(c) for c in channels)
        if len(channels) < MIN_CHANNELS:
            raise ValueError(
                f'a joint identification needs at least {MIN_CHANNELS} channels, '
                f'got {len(channels)} (one channel: excitation ambient, one column)'
            )
        self._channels = channels
        super().__init__(config, len(channels), 2 * joint_rows(len(channels)))

    @property
    def channels(self) -> tuple[str, ...]:
        return self._channels

    def update(self, t: float, y: Sequence[float]) -> list[Estimate]:
        """Feed one sample (one value per channel); the estimates of an analysis it completes."""
        y = np.asarray(y, dtype=np.float64).reshape(-1)
        if len(y) != len(self._channels):
            raise ValueError(f'expected {len(self._channels)} channel values, got {len(y)}')
        t = float(t)
        if not self._accept(t, bool(np.all(np.isfinite(y)))):
            return []
        self._append(np.array((t,)), y[None, :])
        if t >= self._next:
            return self._analysis()
        return []

    def process(self, t: Sequence[float], y: np.ndarray) -> JointEstimates:
        """Feed arrays (``y``: samples x channels; continuing the stream); the estimates by
        time."""
        t, y = as_channels(t, y, len(self._channels))
        out = self._feed(t, y, np.isfinite(y).all(axis=1) & np.isfinite(t))
        return JointEstimates.of(out, self._channels)

    # ---- analysis -----------------------------------------------------------------------------
    def _analyse(self) -> list[Estimate]:
        window = self._next_window()
        if window is None:
            return []
        ts, cascade, fs, span, known, search = window
        modes, total = identify_joint(
            cascade, fs, self._config.max_damping, self._band, self._c, known, search
        )
        return self._track(modes, total, float(ts[-1]), span, len(ts))

    def _match(self, modes: JointModes) -> dict[int, int]:
        """Each window mode's track: nearest in frequency within ``MATCH_TOL`` among those whose
        shape it matches (published tracks first)."""
        tracks = self._tracks
        pairs = []
        for i in range(len(modes)):
            for j, tr in enumerate(tracks):
                dist = continues(modes.frequency[i], modes.shapes[i], tr.frequency, tr.shape)
                if dist is not None:
                    pairs.append((not tr.published, dist, i, j))
        match: dict[int, int] = {}
        used = set()
        for _, _, i, j in sorted(pairs):
            if i not in match and j not in used:
                match[i] = j
                used.add(j)
        return match

    def _track(
        self, modes: JointModes, total: float, t: float, span: float, n: int
    ) -> list[Estimate]:
        """Match the window's modes to the tracked ones, publish the confirmed ones."""
        tracks = self._tracks
        match = self._match(modes)
        seen: dict[int, tuple[int, float]] = {}
        for i in range(len(modes)):
            if i in match:
                tr = tracks[match[i]]
                tr.seen += 1
                similarity = mac(modes.shapes[i], tr.shape)
            elif len(tracks) < MAX_TRACKS:
                tr = _ShapeTrack(float(modes.frequency[i]), t)
                tracks.append(tr)
                similarity = math.nan
            else:
                continue
            tr.frequency, tr.last_t = float(modes.frequency[i]), t
            tr.amplitude = math.sqrt(float(np.sum(modes.variances[i])))
            tr.shape = modes.shapes[i]
            seen[id(tr)] = (i, similarity)
        ready, numbered = self._confirm(seen, t)
        explained = min(1.0, float(np.sum(modes.variances)) / total) if total > 0 else 0.0
        out = []
        for k, tr in enumerate(numbered, 1):
            if tr not in ready:
                continue
            i, similarity = seen[id(tr)]
            f, z = float(modes.frequency[i]), float(modes.damping[i])
            fstd, zstd = float(modes.frequency_std[i]), float(modes.damping_std[i])
            scale = tr.calibration(t, f, fstd, z, zstd, self._window)
            tr.estimates += 1
            est = Estimate(
                t,
                f,
                span,
                n,
                explained,
                tr.amplitude,
                z,
                fstd * scale,
                zstd * scale,
                k,
                modes.shapes[i],
                modes.shape_std[i],
                similarity,
            )
            out.append(est)
        self._c['estimates'] += len(out)
        return out
