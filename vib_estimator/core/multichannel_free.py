# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""Several channels, free decays: one joint maximum-likelihood fit of every channel's samples.

``excitation = free`` with two or more channels (the axes of a tip IMU, a strain gauge per link,
accelerometers on a beam) after a pluck: each estimate is fitted to all channels at once, with the
mode's **shape** -- how much, and in which phase, each channel moves in it. One channel is not
routed here: it stays the one-channel estimator of :func:`..factory.create_estimator`, bit for bit.

Interface (that of :class:`..ambient.AmbientEstimator` of several channels):
:class:`JointFreeEstimator` ``(config, channels, single)`` ``.process(t, Y) ->``
:class:`..estimator.JointEstimates` (``Y``:
samples x channels), ``.update(t, y) -> list[Estimate]``, ``.counters``, ``.reset()``,
``.restart()``, ``.config``, ``.channels``; :func:`..factory.create_estimator` picks it for
``excitation`` free and several channels.

Method:

1. **When, and from where.** Each channel runs the single-channel estimator of ``config`` (the
   algebraic estimator, or the mode tracker with ``modes``) on its own samples. Each estimate it
   publishes is an *event*: a time, a frequency (and damping) to start from, and the samples it
   used. The estimate is thus as early as the earliest channel's: a fraction of a period after a
   pluck on the channel that sees the mode best.
2. **Joint fit** over the event's samples (the last ``samples`` rows up to its time, all channels,
   cut at a gap longer than ``max_gap``): every channel is a damped sinusoid
   ``exp(-sigma u) (a_c sin(w u) + b_c cos(w u))`` (+ ``d_c`` for ``model`` biased-sinusoid) on
   the window's centred time ``u``, with the frequency and decay **shared** and the amplitudes
   per channel (and a cubic on the channels that carry a slower mode with less than a cycle
   in the window). The decay is fitted whatever ``model`` says: a free decay decays, and the
   undamped model shared by several channels biased the joint estimate (a 5 Hz, 1 % decay on 3
   channels, 10 seeds: RMS error 0.57 % undamped, 0.40 % damped, the best channel alone 0.50 %),
   so the damping ratio is published with every joint estimate. With ``modes``, the other modes
   any channel estimated within :data:`CONTEXT_S` (with at least :data:`MIN_CONTEXT_CYCLES` in
   the window, and :data:`MIN_SEPARATION` cycles apart from the others) are further terms of
   the same fit, so they do not bias it. Variable projection: the amplitudes are the
   least-squares solution at each (w, sigma); Gauss-Newton steps on the shared parameters with
   the projected Jacobian ``J_c = (I - P_c) dmu_c/dtheta`` (P_c the projection onto channel c's
   model columns), each channel weighted by its residual variance at
   the start; a step is kept only if it lowers the weighted residual (else halved, up to
   :data:`HALVINGS` times), at most :data:`ITERATIONS` steps.
3. **Standard deviations: the exact Cramer-Rao bound** of the joint model over those samples,
   ``cov(theta) = (sum_c J_c^T J_c / s_c^2)^-1`` (``J_c^T J_c`` is the Schur complement of the
   channel's amplitudes in its Fisher information; ``s_c^2 = RSS_c / (n - L)`` its residual
   variance, L linear parameters), then the delta method to ``f_n = sqrt(w^2 + sigma^2) / 2 pi``
   and ``zeta = sigma / w_n``. Information adds over channels: the joint std is below every single
   channel's, and a mode invisible on some channels is estimated from the others.
4. **Shape**: ``phi_c = b_c - i a_c`` (``y_c = Re(phi_c e^((-sigma + i w) u))``), normalised
   (:func:`.shapes.normalise_shape`); its std per channel ``s_c sqrt(var a_c + var b_c)``
   from the amplitudes' least-squares covariance, scaled as the shape.
5. **Identity over time** (:mod:`.identity`, the rule every estimator shares): an estimate
   continues the known mode nearest in frequency (within :data:`.identity.MATCH_TOL`) whose last
   shape it matches (MAC >= :data:`.identity.MAC_MATCH`); else it is a new mode (at most
   :data:`.identity.MAX_TRACKS`, the least recent forgotten). ``mode`` = its rank by frequency
   among the known modes, 1 = the lowest (also with ``modes`` = 0: the node's
   ``vibration/mode<k>/shape`` needs k >= 1). Several channels converge on one mode at about the
   same time: an event within half its window of that mode's last estimate is merged into it
   (``merged_events``), not published again.

A fit is published only if it is finite, within :data:`MAX_MOVE` of its start and
``|zeta| <= max_damping``; else counted (``rejected_joint``). Bad samples never raise: a
row with a non-finite stamp or channel is skipped (``skipped_non_finite``), a repeated or earlier
stamp within ``max_gap`` too (``skipped_duplicate``, ``skipped_out_of_order``); a jump back or a
gap beyond it restarts (``time_jump_resets``, ``gap_resets``: :func:`.estimator.accept_sample`,
the input policy every estimator written in Python shares); the channels' estimators see only the
rows kept, so their gaps and jumps are handled as with one channel.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from .config import EstimatorConfig
from .estimator import (
    INPUT_COUNTERS,
    Estimate,
    Estimator,
    JointEstimates,
    accept_rows,
    accept_sample,
    as_series,
    channel_names,
    make_room,
)
from .identity import ModeRegister
from .shapes import normalise_shape
from .threads import single_blas_thread

#: other modes estimated within this many seconds before an event are terms of its fit
CONTEXT_S = 2.0
#: ... if at least this many cycles apart over the event's window (else not resolvable there)
MIN_SEPARATION = 0.5
#: ... and if the window holds at least this many of its cycles. A slower one is smooth there: a
#: term for it cost a 17 Hz estimate over 48 samples twice the variance of the one channel that
#: sees it (its amplitudes and decay poorly determined), and left out it bent the 17 Hz shape on
#: the channels that carry it (median MAC 0.68); it is a polynomial of this degree on those (on
#: all channels, the polynomial cost the clean channel's 17 Hz estimates their precision)
MIN_CONTEXT_CYCLES = 1.0
SLOW_DEGREE = 3
#: Gauss-Newton steps of a joint fit at most, and the halvings of a step that does not help
ITERATIONS = 8
HALVINGS = 4
#: a step of the frequency below this fraction of its std ends the iterations
STEP_TOL = 1e-3
#: a joint fit further than this (relative) from its start is not published
MAX_MOVE = 0.1
#: the joint identifier's own counters, after the input counters
JOINT_COUNTERS = ('events', 'joint_fits', 'merged_events', 'rejected_joint', 'estimates')


# ---- the joint fit ------------------------------------------------------------------------------
@dataclass(frozen=True)
class JointFit:
    """A joint fit's result for its first term: ``omega`` (rad/s, damped), ``sigma`` (1/s),
    their 2 x 2 covariance ``cov``, the complex ``amplitudes`` (one per channel) and their stds,
    the R^2 over all channels."""

    omega: float
    sigma: float
    cov: np.ndarray
    amplitudes: np.ndarray
    amplitude_std: np.ndarray
    fit: float


def _basis(u: np.ndarray, omega: np.ndarray, sigma: np.ndarray):
    """The terms' columns (n x 2k: per term ``e sin``, ``e cos``) and each term's ``e sin``,
    ``e cos`` (n x k) for the derivatives."""
    arg = np.outer(u, omega)
    env = np.exp(-np.outer(u, sigma))
    es, ec = env * np.sin(arg), env * np.cos(arg)
    return np.stack((es, ec), axis=-1).reshape(len(u), -1), es, ec


def _powers(u: np.ndarray, degree: int) -> np.ndarray:
    """The powers 0 .. ``degree`` of ``u`` scaled to [-1, 1] (n x (degree + 1); none for -1)."""
    half = float(np.max(np.abs(u))) or 1.0
    return np.vander(u / half, degree + 1, increasing=True)


@dataclass
class _Projection:
    """The least-squares solution at one (omega, sigma): per group of channels with the same
    polynomial degree its channels, orthonormal basis ``q`` and ``(Phi^T Phi)^-1``; the terms'
    amplitudes (2k x channels) and the residual (n x channels)."""

    groups: list
    amp: np.ndarray
    res: np.ndarray


def _project(terms: np.ndarray, powers: dict, degrees: np.ndarray, y: np.ndarray) -> _Projection:
    """Each channel's model: the terms' columns and its polynomial's (module doc, step 2)."""
    amp = np.empty((terms.shape[1], y.shape[1]))
    res = np.empty_like(y)
    groups = []
    for degree in np.unique(degrees):
        ch = np.flatnonzero(degrees == degree)
        phi = np.hstack((terms, powers[int(degree)]))
        q, r = np.linalg.qr(phi)
        a = np.linalg.solve(r, q.T @ y[:, ch])
        amp[:, ch] = a[: terms.shape[1]]
        res[:, ch] = y[:, ch] - phi @ a
        r_inv = np.linalg.inv(r)
        groups.append((ch, q, r_inv @ r_inv.T))
    return _Projection(groups, amp, res)


def _jacobian(u, es, ec, fit: _Projection) -> np.ndarray:
    """The projected Jacobians ``(I - P_c) dmu_c / dtheta``: channels x n x parameters (theta =
    the terms' omegas, then their sigmas)."""
    k, amp = es.shape[1], fit.amp
    cols = []
    for j in range(k):  # d/d omega_j of es a + ec b: u (ec a - es b)
        a, b = amp[2 * j], amp[2 * j + 1]
        cols.append(u[:, None] * (ec[:, j, None] * a - es[:, j, None] * b))
    for j in range(k):  # d/d sigma_j: -u (es a + ec b)
        a, b = amp[2 * j], amp[2 * j + 1]
        cols.append(-u[:, None] * (es[:, j, None] * a + ec[:, j, None] * b))
    d = np.moveaxis(np.stack(cols, axis=-1), 1, 0)  # channels x n x P
    for ch, q, _ in fit.groups:
        d[ch] -= q[None] @ (q.T[None] @ d[ch])
    return d


def _weights(residual: np.ndarray, dof: np.ndarray) -> np.ndarray:
    """Each channel's residual variance (a channel fitted exactly -- constant, or noiseless --
    gets the smallest of the others', or 1 if all are exact)."""
    s2 = np.sum(residual**2, axis=0) / np.maximum(dof, 1)
    positive = s2[s2 > 0]
    floor = float(np.min(positive)) if len(positive) else 1.0
    return np.maximum(s2, floor)


def _scaled(u, es, ec, fit: _Projection, s2: np.ndarray) -> np.ndarray:
    """The weighted projected Jacobian, all channels stacked ((channels n) x P)."""
    jac = _jacobian(u, es, ec, fit) / np.sqrt(s2)[:, None, None]
    return jac.reshape(-1, jac.shape[-1])


def joint_fit(
    u: np.ndarray,
    y: np.ndarray,
    omega: Sequence[float],
    sigma: Sequence[float],
    degrees: Sequence[int] | int = -1,
) -> JointFit | None:
    """The joint maximum-likelihood fit of the samples ``y`` (n x channels) at centred times
    ``u`` from the terms' start values ``omega``, ``sigma``, with a polynomial of ``degrees``
    (per channel, or one for all; -1: none) on each channel (module doc, steps 2-4); None if it
    is not finite."""
    omega = np.array(omega, dtype=float)
    sigma = np.array(sigma, dtype=float)
    k, n = len(omega), len(u)
    degrees = np.broadcast_to(np.asarray(degrees, dtype=int), (y.shape[1],))
    dof = n - (2 * k + degrees + 1)
    if np.any(dof <= 2 * k):
        return None
    powers = {int(d): _powers(u, int(d)) for d in np.unique(degrees)}

    def evaluate(w, s):
        terms, es, ec = _basis(u, w, s)
        return es, ec, _project(terms, powers, degrees, y)

    es, ec, fit = evaluate(omega, sigma)
    s2 = _weights(fit.res, dof)
    cost = float(np.sum(fit.res**2 / s2))
    for _ in range(ITERATIONS):
        jac = _scaled(u, es, ec, fit, s2)
        r = (fit.res / np.sqrt(s2)).T.reshape(-1)
        step, *_ = np.linalg.lstsq(jac, r, rcond=None)
        for _ in range(HALVINGS + 1):
            w, s = omega + step[:k], sigma + step[k:]
            trial = evaluate(w, s)
            trial_cost = float(np.sum(trial[2].res ** 2 / s2))
            if np.isfinite(trial_cost) and trial_cost < cost:
                break
            step = step / 2
        else:
            break
        omega, sigma, cost = w, s, trial_cost
        es, ec, fit = trial
        fisher = jac.T @ jac
        if abs(step[0]) < STEP_TOL * math.sqrt(max(float(np.linalg.pinv(fisher)[0, 0]), 0.0)):
            break
    s2 = _weights(fit.res, dof)
    jac = _scaled(u, es, ec, fit, s2)
    try:
        cov_all = np.linalg.inv(jac.T @ jac)
    except np.linalg.LinAlgError:
        return None
    cov = cov_all[np.ix_((0, k), (0, k))]
    amp_var = np.empty(y.shape[1])
    for ch, _, gram in fit.groups:
        amp_var[ch] = gram[0, 0] + gram[1, 1]
    amp_std = np.sqrt(s2 * amp_var)
    centred = y - np.mean(y, axis=0)
    total = float(np.sum(centred**2))
    r2 = 1.0 - float(np.sum(fit.res**2)) / total if total > 0 else 0.0
    amp = fit.amp
    out = JointFit(float(omega[0]), float(sigma[0]), cov, amp[1] - 1j * amp[0], amp_std, r2)
    values = (out.omega, out.sigma, *out.cov.ravel(), *out.amplitudes.view(float), *amp_std)
    return out if np.all(np.isfinite(values)) else None


def natural(fit: JointFit) -> tuple[float, float, float, float]:
    """``(f_n Hz, zeta, std f_n, std zeta)`` of a fit (the delta method)."""
    w, s = fit.omega, fit.sigma
    wn = math.hypot(w, s)
    g_f = np.array([w / wn, s / wn]) / (2 * math.pi)
    g_z = np.array([-s * w, w * w]) / wn**3
    return (
        wn / (2 * math.pi),
        s / wn,
        math.sqrt(max(float(g_f @ fit.cov @ g_f), 0.0)),
        math.sqrt(max(float(g_z @ fit.cov @ g_z), 0.0)),
    )


# ---- the identifier -----------------------------------------------------------------------------
class JointFreeEstimator(Estimator):
    """Joint free-decay estimation of several channels; see the module docstring.

    ``channels``: the channel names (their count is the number of columns fed); ``single``: makes
    one channel's estimator (:func:`..factory.create_estimator` of ``config``, one channel)."""

    def __init__(
        self,
        config: EstimatorConfig,
        channels: Sequence[str],
        single: Callable[[], Estimator],
    ):
        config.validate()
        if config.excitation != 'free':
            raise ValueError(f'JointFreeEstimator needs excitation free, got {config.excitation}')
        self._config = config
        self.channels = channel_names(channels, 'a joint estimation')
        self._room = int(config.buffer_samples)
        self._single = single
        self._c = dict.fromkeys(INPUT_COUNTERS + JOINT_COUNTERS, 0)
        self._retired: dict[str, int] = {}  # the counters of the channels' estimators restarted
        self._estimators: list = []
        self.restart()

    @property
    def counters(self) -> dict[str, int]:
        """The input and joint counters, and the channels' estimators' others summed."""
        total = dict(self._c)
        for name, value in self._channel_counters().items():
            total[name] = total.get(name, 0) + value
        return total

    def _channel_counters(self) -> dict[str, int]:
        """The channels' estimators' counters summed, those restarted included (their input
        counters and estimates left out: the joint identifier counts its own)."""
        total = dict(self._retired)
        for est in self._estimators:
            for name, value in est.counters.items():
                if name not in INPUT_COUNTERS and name != 'estimates':
                    total[name] = total.get(name, 0) + int(value)
        return total

    def restart(self) -> None:
        """Forget the signal and the known modes; counters are kept."""
        self._retired = self._channel_counters()
        m = len(self.channels)
        self._estimators = [self._single() for _ in range(m)]
        self._rows = np.empty((2 * self._room, 1 + m))  # t, channels: the last rows kept
        self._n = 0
        self._last = -math.inf
        self._modes = ModeRegister(replace=True)
        self._recent: dict[tuple[int, int], tuple[float, float, float]] = {}

    def reset(self) -> None:
        """Start a new segment of every channel's estimator at the last sample."""
        for est in self._estimators:
            est.reset()

    # ---- input --------------------------------------------------------------------------------
    def _forget_signal(self) -> None:
        """After a restart (a jump back or a gap beyond ``max_gap``): the row store emptied, the
        channels' recent estimates forgotten, the known modes kept by frequency and shape but not
        by time (a stream whose time went back would otherwise merge every event into them)."""
        self._n = 0
        self._recent.clear()
        for mode in self._modes.modes:
            mode.last_t = -math.inf

    def _row_of(self, times: np.ndarray) -> np.ndarray:
        """The store index of the row nearest each of ``times`` (an estimate's stamp is its
        sample's, computed: it may differ from it in the last bits)."""
        stamps = self._rows[: self._n, 0]
        right = np.clip(np.searchsorted(stamps, times), 1, max(self._n - 1, 1))
        left = right - 1
        nearer = np.abs(stamps[left] - times) <= np.abs(stamps[right] - times)
        return np.where(nearer, left, right)

    def _append(self, t: np.ndarray, y: np.ndarray) -> None:
        """Append kept rows to the row store (the last ``buffer_samples`` rows are held)."""
        if self._n + len(t) > len(self._rows):  # keep the last `room` rows (and make space)
            keep = min(self._n, self._room)
            self._rows = make_room(self._rows, self._n - keep, self._n, len(t))
            self._n = keep
        self._rows[self._n : self._n + len(t), 0] = t
        self._rows[self._n : self._n + len(t), 1:] = y
        self._n += len(t)

    # ---- streaming and batch ------------------------------------------------------------------
    def update(self, t: float, y: Sequence[float]) -> list[Estimate]:
        """Feed one sample (one value per channel); the estimates it completes."""
        values = [float(v) for v in y]
        if len(values) != len(self.channels):
            raise ValueError(f'expected {len(self.channels)} channel values, got {len(values)}')
        t, finite = float(t), all(map(math.isfinite, values))
        gap = self._config.max_gap
        if not accept_sample(self._c, self._last, t, finite, gap, self._forget_signal):
            return []
        self._last = t
        self._append(np.array((t,)), np.array((values,)))
        events = []
        for c, est in enumerate(self._estimators):
            for e in est.update(t, values[c]):
                events.append((int(self._row_of(np.array((e.t,)))[0]), c, e))
        return self._events(events) if events else []  # (no BLAS-thread switch per sample)

    def process(self, t: Sequence[float], y: np.ndarray) -> JointEstimates:
        """Feed arrays (``y``: samples x channels; continuing the stream); the estimates by
        time."""
        t, y = as_series(t, y, self.channels)
        finite = np.isfinite(t) & np.all(np.isfinite(y), axis=1)
        keep, runs, self._last = accept_rows(self._c, self._last, t, finite, self._config.max_gap)
        t, y = t[keep], y[keep]
        out: list[Estimate] = []
        for a, b, restart in runs:  # a restart empties the row store: each run appended alone
            if restart:
                self._forget_signal()
            out += self._process_rows(t[a:b], y[a:b])
        return JointEstimates.of(out, self.channels)

    def _process_rows(self, t: np.ndarray, y: np.ndarray) -> list[Estimate]:
        """Kept rows, increasing, without a restart among them: their joint estimates."""
        out: list[Estimate] = []
        # in blocks of the row store's room: each event's window is still held when it is fitted
        for lo in range(0, len(t), self._room):
            tb, yb = t[lo : lo + self._room], y[lo : lo + self._room]
            self._append(tb, yb)
            events = []
            for c, est in enumerate(self._estimators):
                cols = est.process(tb, np.ascontiguousarray(yb[:, c]))
                index = self._row_of(cols.t)
                events += [(int(i), c, e) for i, e in zip(index, cols.to_list())]
            events.sort(key=lambda ev: ev[0])  # stable: by time, then channel, then order
            out += self._events(events)
        return out

    # ---- events ---------------------------------------------------------------------------------
    @single_blas_thread
    def _events(self, events) -> list[Estimate]:
        out = []
        for index, c, e in events:
            self._c['events'] += 1
            joint = self._event(index, c, e)
            if joint is not None:
                out.append(joint)
        self._c['estimates'] += len(out)
        return out

    def _window(self, index: int, samples: int) -> np.ndarray:
        """The rows of an event's window: the last ``samples`` up to ``index`` (the store holds
        no gap longer than ``max_gap``: one empties it, :meth:`_forget_signal`)."""
        lo = max(0, index + 1 - min(samples, self._room))
        return self._rows[lo : index + 1]

    def _terms(self, c: int, e: Estimate, span: float):
        """``(omega, sigma, degrees)``: the fit's start values, the event's mode first (its
        estimate, recorded by :meth:`_event`), then
        (``modes``) the others estimated within ``CONTEXT_S`` that the window resolves; each
        channel's polynomial degree (:data:`SLOW_DEGREE` where the channel's own estimator saw
        a slower mode the window does not resolve, else 0 for biased-sinusoid, -1)."""
        omega = [self._recent[(c, e.mode)][1]]
        sigma = [self._recent[(c, e.mode)][2]]
        degrees = np.full(len(self.channels), 0 if self._config.model == 'biased-sinusoid' else -1)
        if self._config.modes:
            for (ch, _), (t, w, s) in sorted(self._recent.items()):
                if e.t - t > CONTEXT_S:
                    continue
                cycles = w * span / (2 * math.pi)
                apart = all(abs(w - w0) * span / (2 * math.pi) >= MIN_SEPARATION for w0 in omega)
                if cycles >= MIN_CONTEXT_CYCLES and apart:
                    omega.append(w)
                    sigma.append(s)
                elif cycles < MIN_CONTEXT_CYCLES:
                    degrees[ch] = SLOW_DEGREE
        return omega, sigma, degrees

    def _event(self, index: int, c: int, e: Estimate) -> Estimate | None:
        rows = self._window(index, int(e.samples))
        t = rows[:, 0]
        span = float(t[-1] - t[0]) if len(t) > 1 else 0.0
        zeta = _zeta(e)  # the channel's estimate: a start value of its mode's later events
        self._recent[(c, e.mode)] = (e.t, e.omega * math.sqrt(1 - zeta**2), e.omega * zeta)
        mode = self._modes.match([e.frequency_hz]).get(0)  # by frequency alone
        if mode is not None and e.t - mode.last_t < span / 2:
            self._c['merged_events'] += 1
            return None
        omega, sigma, degrees = self._terms(c, e, span)
        self._c['joint_fits'] += 1
        fit = joint_fit(t - 0.5 * (t[0] + t[-1]), rows[:, 1:], omega, sigma, degrees)
        if fit is None:
            self._c['rejected_joint'] += 1
            return None
        f, z, fstd, zstd = natural(fit)
        if not (abs(f / e.frequency_hz - 1) <= MAX_MOVE and abs(z) <= self._config.max_damping):
            self._c['rejected_joint'] += 1
            return None
        shape = normalise_shape(fit.amplitudes)
        shape_std = fit.amplitude_std / float(np.linalg.norm(fit.amplitudes))
        mode = self._modes.observe_one(f, e.t, shape)
        similarity, k = mode.mac, self._modes.number(mode)
        amplitude = float(np.sqrt(np.mean(np.abs(fit.amplitudes) ** 2)))
        return Estimate(
            e.t,
            f,
            e.convergence_time,
            len(t),
            fit.fit,
            amplitude,
            z,
            fstd,
            zstd,
            k,
            shape,
            shape_std,
            similarity,
        )


def _zeta(e: Estimate) -> float:
    """An estimate's damping ratio, 0 when it has none (undamped models)."""
    return e.damping if math.isfinite(e.damping) and abs(e.damping) < 1 else 0.0
