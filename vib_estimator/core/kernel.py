# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""Compiled per-sample step of the algebraic estimator (numba; no rclpy, no Python objects).

This module holds the arithmetic of :mod:`vib_estimator.core.estimator` as one function,
:func:`step`, that both the streaming API (one call per sample) and the batch API (:func:`run`, a
compiled loop over arrays) execute, so the two give the same floats. The state lives in three flat
arrays whose layout is the constants below;
:class:`vib_estimator.core.estimator.FrequencyEstimator` owns them.

Mathematics (equation numbers are those of Trapero, Sira-Ramirez & Feliu):

* Eq. 7 written with the moments ``M_k(tau) = int_0^tau s^k y(s) ds`` of the segment since the last
  reset (``int int y = tau*M0 - M1``, ``int int s^2 y = tau*M2 - M3``)::

      n = -(tau^2 y + 2 tau M0 - 6 M1),     d = tau M2 - M3,      omega^2 = n / d

  This is Eq. 8 with the corrected sign (``dx1/dt = x2 - 4 t y``; the paper prints ``+``).
* ``damped-sinusoid`` (y'' + 2 sigma y' + w_n^2 y = 0): differentiating
  ``(s^2 + 2 sigma s + w_n^2) Y = s y0 + y1 + 2 sigma y0`` twice in s and multiplying by s^-2 gives
  ``n = 2 sigma q + w_n^2 d`` at every instant, with n and d as above and ``q = 3 M2 - 2 tau M1``;
  the invariant filter (F1) and its running integral (F2) give two such equations, solved for
  w_n^2 and 2 sigma (so the natural frequency and the damping ratio, exactly, for a damped sine).
* ``biased-sinusoid`` (y = A sin(wt+phi) + B): the offset is eliminated by a third derivation in s
  of ``s (s^2 + w^2) Y(s) = s^2 y0 + s y1 + B (s^2 + w^2)``, multiplied by ``s^-3``::

      N = -tau^3 y + 3 tau^2 M0 - 24 tau M1 + 30 M2,   D = -1.5 tau^2 M2 + 4 tau M3 - 2.5 M4

* The moments are integrated interval by interval, exactly, over the degree-7 polynomial that
  interpolates the last NH = 8 samples (a causal Adams-Moulton-type rule, local error O(h^9),
  valid for irregular steps). A trapezoid makes early estimates of a clean sine percent-wrong
  because ``n`` is a difference of terms that cancel to O(tau^4); this rule makes them exact to
  ~1e-8 at 100 samples per period (see :mod:`vib_estimator.core.estimator` for the error budget).
* Invariant filtering (Eqs. 9-11): ``n`` and ``d`` pass through the same second-order low-pass,
  discretised exactly for a first-order-hold input over each real sampling interval, so irregular
  sampling is handled and ``n_f / d_f`` stays exactly ``w^2`` for a pure sinusoid.
* Eq. 12: no estimate for ``tau <= eps``; Eqs. 16-17: moving-average convergence test, by default
  on the absolute value of the relative change. The test as printed is one-sided: any falling
  estimate passes it at once, which is how Fig. 2's convergence time can fall as damping grows;
  ``one_sided_test`` reproduces it.
* Refinement and uncertainty (:mod:`vib_estimator.core.uncertainty`): a published estimate is the
  starting point of ``refine`` Gauss-Newton (maximum-likelihood) steps of its model over the
  segment's samples, and gets its standard deviation from the Fisher information of the model
  over those samples with the segment's residual variance (``refine`` = 0: the paper's estimate
  as it is, with its std). ``target_std_rel`` replaces the convergence test by that std; with
  ``refine`` and ``min_periods`` >= :data:`LONG_WINDOW_PERIODS` the window is set by
  ``min_periods`` alone (the test of Eqs.
  16-17 watches the algebraic estimate, which wanders over many periods while the refined one
  keeps improving).
* The optional band-pass prefilter is a 4th-order Butterworth low-pass at ``f_hi`` (steep, against
  higher modes) followed by a 2nd-order Butterworth high-pass at ``f_lo`` (offset and drift), all
  with the same exact discretisation; it is never reset by an estimate.
"""

from __future__ import annotations

import math

import numpy as np
from numba.core import types
from numba.extending import overload

from . import uncertainty as U
from .jit import borrowed, jit
from .uncertainty import MODEL_BIASED, MODEL_DAMPED, MODEL_SINUSOID, TWO_PI

# ---- parameter array layout (float64) -------------------------------------------------------
(
    P_MODEL,
    P_WC,
    P_ZC,
    P_M,
    P_TOL,
    P_EPS,
    P_MAXWIN,
    P_BAND,
    P_WLO,
    P_WHI,
    P_MINAMP,
    P_MINFIT,
    P_MAXGAP,
    P_MINSAMP,
    P_MINPER,
    P_FILTER,
    P_ONESIDED,
    P_RULE,
    P_MAXDAMP,
    P_REFINE,
    P_TARGET,
    P_CONSIST,
    P_GAPN,
    P_OUTLIER,
    P_EARLY,
    N_PARAMS,
) = range(26)  # N_*: the slots' number

# ---- counter array layout (int64) -----------------------------------------------------------
(
    C_RECEIVED,
    C_USED,
    C_NONFINITE,
    C_DUPLICATE,
    C_OUT_OF_ORDER,
    C_TIME_JUMP,
    C_GAP,
    C_REST,
    C_FIT,
    C_NYQUIST,
    C_MAX_WINDOW,
    C_ESTIMATES,
    C_DAMPING,
    C_INCONSISTENT,
    C_GAPS,
    C_LOST,
    C_OUTLIER,
    C_SEG_N,
    C_HIST_N,
    C_MA_N,
    C_OUTLIER_RUN,
    C_SCALE_N,
    C_ONSET,
    N_COUNTERS,
) = range(24)

# ---- state array layout (float64) -----------------------------------------------------------
NH = 8  # samples in the interpolation stencil (degree-7 rule)
S_T0 = 0  # time origin of the current segment
S_TLAST = 1  # time of the last accepted sample
S_HRUN = 2  # running sample interval (kept across restarts: it describes the stream)
S_YC = 3  # running centre of the raw signal (outlier test), kept across restarts
S_YR = 4  # running (decaying) peak of |y - centre|, kept across restarts
S_YO = 5  # ... the same decaying within PEAK_TAU_S at least: the onset test's, kept too
S_HT = 6  # NH last sample times (oldest first)
S_HY = S_HT + NH  # NH last (prefiltered) sample values
S_MOM = S_HY + NH  # moments M0..M4
S_NF = S_MOM + 5  # low-pass state of n: x5, x6 (Eq. 11)
S_DF = S_NF + 2  # low-pass state of d: x7, x8
S_NPREV = S_DF + 2  # n, d at the previous sample (first-order hold)
S_DPREV = S_NPREV + 1
S_QF = S_DPREV + 1  # damped model: low-pass state of q (2) and q at the previous sample
S_QPREV = S_QF + 2
S_INT = S_QPREV + 1  # damped model: running integrals of n_f, q_f, d_f (the second equation)
S_BAND = S_INT + 3  # band-pass: 3 sections x (2 states, previous input)
S_CACHE_H = S_BAND + 9  # step for which the discretisations below were computed
S_DISC = S_CACHE_H + 1  # 4 sections x 8 numbers (Phi 2x2, G0 2, G1 2): Eq. 11, then band
S_SCR = S_DISC + 32  # scratch for the interval rule: nodes, differences, coefficients
S_IM = S_SCR + 3 * NH  # the rule's integrals I_0..I_4 of the newest interval
S_W = S_IM + 5  # cached weights of the rule on a uniform stencil (5 x NH)
S_WH = S_W + 5 * NH  # step of the cached weights (-1: none)
S_UNIT = S_WH + 1  # scratch unit vector
S_FLAST = S_UNIT + NH  # long windows: the segment's first converged half-period estimate
S_DLAST = S_FLAST + 1  # ... and its damping ratio (damped model), where the fit starts
S_NEXT = S_DLAST + 1  # segment length at which target_std_rel is checked next
S_HELD = S_NEXT + 1  # long windows: 1 once ``early_std_rel`` held the segment to HELD_PERIODS
S_RES = S_HELD + 1  # result of the refinement (core.uncertainty's layout)
S_WORK = S_RES + U.N_RESULT  # the refinement's scratch
NBJ = 4  # band std: prefilter states of the Jacobian's 4 columns
S_BANDJ = S_WORK + U.N_WORK  # ... (3 sections x (2 states, previous input) each)
S_JROW = S_BANDJ + 9 * NBJ  # ... the inputs of one step
S_TAILW = S_JROW + NBJ  # ... the Gramian of the prefilter's free response (9 x 9)
S_TAILH = S_TAILW + 81  # ... the step it was computed for, and rho(0) = sum g^2
S_FPREV = S_TAILH + 2  # ``consistency``: the estimate of the segment just before (0: none)
S_XSIGN = S_FPREV + 1  # the signal's side of its centre (+-1, 0: none yet; half cycles)
S_XING = S_XSIGN + 1  # half cycles of the signal since the segment began (a stalled segment)
S_CHAINED = S_XING + 1  # 1: the segment began at the estimate before (0: an onset, a restart,
#: a timeout, a rejection)
S_RUN = S_CHAINED + 1  # time of the signal's last half cycle (the current run on one side began)
S_EXT = S_RUN + 1  # the run's farthest deviation from the centre (|d|) ...
S_TEXT = S_EXT + 1  # ... its time
S_PEXT = S_TEXT + 1  # the run before's farthest deviation
S_RELEASE = S_PEXT + 1  # 1: a release seen (:func:`_half_cycle`), for step to restart at
S_MA = S_RELEASE + 1  # moving-average ring (2M+1 values) starts here
N_STATE_FIXED = S_MA

# ---- estimate row layout --------------------------------------------------------------------
O_T, O_F, O_CONV, O_SAMPLES, O_FIT, O_AMP, O_DAMP, O_FSTD, O_DSTD, N_OUT = range(10)
#: with ``refine``, a ``min_periods`` from this many on sets the window alone (the long window,
#: :func:`_long_window_spanned`); below it (the paper's 0.5) the convergence test of Eqs. 16-17
#: publishes, as printed. (At 0.9 periods the long window converges in 0.90-0.92 periods on the
#: real beams, the convergence test in 0.95-0.98, bench_first_estimate.py.)
LONG_WINDOW_PERIODS = 0.75
#: ``early_std_rel``: a long-window estimate less precise than that is held until the segment
#: spans this many periods (the default window's; the noisy decays of bench_first_estimate.py
#: then keep that window's accuracy in their tails and publish earlier where they are precise)
HELD_PERIODS = 1.25
#: automatic max_window: this long at least (s), and min_periods + this many periods
AUTO_WINDOW_S = 10.0
AUTO_WINDOW_PERIODS = 2.0
#: the damped model's segment that has seen min_periods + :data:`AUTO_WINDOW_PERIODS` periods of
#: the signal (its half cycles: crossings of its running centre by this share of its running
#: peak deviation, ``S_YR``, either way) without an estimate is stalled and restarts
#: (:func:`_stalled`): one that began before a pluck's release, holding the pull (no free
#: vibration, no offset term in that model to absorb it), never converged until the automatic
#: 10 s: a 9.4 Hz pluck pulled over 0.02-0.2 s after 1-5 s of rest gave its first estimate
#: 24-88 periods after the release on 5 of 18 records (``bench_hard_records.py --pulled``; now
#: 2.2-4.6), a real 40 cm beam after 5 s of rest 4.2 s after its pluck (until 6 Dec 2026; the
#: biased sinusoid's offset term absorbs the pull: 2.6-3.7 periods). Only segments not begun at
#: a published estimate: a decay's noisy tail keeps its own (all of them: 20 dB decays lost a
#: tenth of their estimates within 2 %)
HALF_CYCLE_LEVEL = 0.25
#: a pluck's release (:func:`_half_cycle`): a run of the signal on one side of its centre that
#: rose beyond :data:`RELEASE_GROWTH` times the run before's farthest deviation (from rest: a
#: noise run's farthest is at least HALF_CYCLE_LEVEL of the running peak, so noise alone cannot),
#: took more than :data:`RELEASE_RATIO` times longer (and more than NH sample intervals) to reach
#: its farthest than to come back across the centre (a free vibration: 1; a hand's pull: its
#: length over a quarter period) and began no segment at an onset: a segment not begun at a
#: published estimate restarts at that crossing, a quarter period after the release. The segment
#: that held the pull (no model of it) gave the first estimate 2.6-4.6 periods after a 9.4 Hz
#: pluck pulled over 0.1-0.2 s (``bench_hard_records.py --pulled``; now 2.07-2.09)
RELEASE_RATIO = 1.5
RELEASE_GROWTH = 8.0
#: the quality gate's limit on how far the refinement may move the algebraic estimate: this many
#: of its stds, and never less than this fraction of f (a clean or coarsely sampled signal:
#: std ~ 0, the algebraic estimate's discretisation error up to ~1e-3)
MAX_REFINE_MOVE, MIN_REFINE_MOVE_REL = 8.0, 0.02
#: running sample interval: weight of the newest interval in its exponential average
HRUN_WEIGHT = 1.0 / 16.0
#: outlier test: the signal's centre and decaying peak deviation follow it with this weight per
#: sample; the test starts once this many samples set them; this many consecutive outliers are a
#: real change of level (accepted: the estimator and the scale restart)
SCALE_WEIGHT = 1.0 / 1024.0
SCALE_WARMUP = 64
OUTLIER_RUN = 4
#: the onset test's peak deviation (``S_YO``) decays by the same weight a sample, or over this
#: time constant (s) where that is faster (below 1024 samples a second): a pluck after the last one
#: rang down into the noise is an onset (:data:`ONSET_RATIO`) once that peak has followed the
#: decay down. With the 1024 samples alone (3.4 s at 300 Hz), two 10 Hz plucks 7 s apart, the
#: second half as strong: the peak still 0.13 of the first one's, the second no onset on 1 of 12
#: seeds, nothing estimated for its 5 s, the others' first estimates 2.3-5.2 periods after it
#: (now 2.1-2.2, as on the record cut at it; ``bench_first_estimate.py --second``). Only the
#: onset's: the outlier test's and the half cycles' peak (``S_YR``) keeps its 1024 samples
PEAK_TAU_S = 1.0
#: a sample farther from the running centre than this many times the running peak of the
#: deviation (``S_YO``: the last ~1000 samples, or second) is an onset, a pluck after rest: the
#: segment then running, begun in the rest before it, restarts (:func:`step`): the interpolation
#: stencil refills from that sample and the new segment begins once it is full, as a record's
#: first does (until 7 Dec 2026 it began at the sample before, its stencil across the jump: the
#: first intervals integrated wrongly, the first estimate 2.7 periods after a 10 Hz pluck at
#: 300 Hz where the record cut at the pluck gives 2.1; bench_first_estimate.py --onset: now as
#: cut at 10-500 samples a period). Else
#: that segment's integrals hold the rest and the pluck's first samples, and it converges only
#: seconds later: a 10 Hz pluck after 1 s of noise gave its first estimate 12.9 periods after the
#: pluck at 5 kHz and none at all at 300 Hz and below (bench_first_estimate.py --onset)
ONSET_RATIO = 5.0
#: a sample value beyond this magnitude is always an outlier (keeps every product of the moments,
#: t^4 y, and every square of the fit finite)
MAX_ABS_VALUE = 1e100
#: band std: most steps of the prefilter's free response summed in its Gramian
MAX_BAND_TAIL = 1 << 22

#: band-pass prefilter: 4th-order Butterworth low-pass at f_hi (two sections), then a 2nd-order
#: Butterworth high-pass at f_lo
BAND_DAMPING = (math.cos(math.pi / 8), math.cos(3 * math.pi / 8), math.sqrt(0.5))
#: C(k, j) for the moments M_0..M_4 (a table: no division per sample)
BINOMIAL = (
    (1.0, 0.0, 0.0, 0.0, 0.0),
    (1.0, 1.0, 0.0, 0.0, 0.0),
    (1.0, 2.0, 1.0, 0.0, 0.0),
    (1.0, 3.0, 3.0, 1.0, 0.0),
    (1.0, 4.0, 6.0, 4.0, 1.0),
)


@jit
def discretise(w, z, h, out, off):
    """Exact first-order-hold discretisation of the unit-gain low-pass w^2/(s^2 + 2 z w s + w^2).

    Writes Phi (row-major), G0, G1 so that x(h) = Phi x(0) + G0 u(0) + G1 u(h).
    """
    a = z * w
    b2 = w * w * (1.0 - z * z)
    if b2 > 0.0:
        b = math.sqrt(b2)
        c = math.cos(b * h)
        s = math.sin(b * h) / b
    elif b2 < 0.0:
        b = math.sqrt(-b2)
        c = math.cosh(b * h)
        s = math.sinh(b * h) / b
    else:
        c = 1.0
        s = h
    e = math.exp(-a * h)
    p00 = e * (c + a * s)
    p01 = e * s
    p10 = -e * w * w * s
    p11 = e * (c - a * s)
    # constant-input part (Phi - I) A^-1 B with A^-1 B = (-1, 0)
    ga0 = 1.0 - p00
    ga1 = -p10
    # ramp part: ((Phi - I) (2z/w, -1)) / h + (1, 0)
    v0 = 2.0 * z / w
    gb0 = ((p00 - 1.0) * v0 - p01) / h + 1.0
    gb1 = (p10 * v0 - (p11 - 1.0)) / h
    out[off + 0] = p00
    out[off + 1] = p01
    out[off + 2] = p10
    out[off + 3] = p11
    out[off + 4] = ga0 - gb0
    out[off + 5] = ga1 - gb1
    out[off + 6] = gb0
    out[off + 7] = gb1


@jit(inline='always')
def advance(s, xo, d, u0, u1):
    """Advance the 2-state section stored at s[xo:xo+2] with the discretisation at s[d:d+8]."""
    x0 = s[xo]
    x1 = s[xo + 1]
    s[xo] = s[d] * x0 + s[d + 1] * x1 + s[d + 4] * u0 + s[d + 6] * u1
    s[xo + 1] = s[d + 2] * x0 + s[d + 3] * x1 + s[d + 5] * u0 + s[d + 7] * u1


@jit
def _restart(s, c):
    """Forget everything, the prefilter and interpolation history included (start, gap, jump)."""
    s[S_HT:] = 0.0
    s[S_CACHE_H] = -1.0
    s[S_WH] = -1.0
    c[C_SEG_N] = 0
    c[C_HIST_N] = 0
    c[C_MA_N] = 0


@jit
def reset_segment(s, c, seg, t0, y0):
    """Start a new estimation segment at time ``t0`` (after an estimate, a timeout or a rejection).

    The band-pass prefilter and the interpolation history are kept: they describe the signal, not
    the segment.
    """
    s[S_T0] = t0
    seg[0, 0] = 0.0
    seg[1, 0] = y0
    s[S_MOM : S_MOM + 5] = 0.0
    s[S_NF : S_INT + 3] = 0.0
    s[S_FLAST] = 0.0
    s[S_DLAST] = 0.0
    s[S_NEXT] = 0.0
    s[S_HELD] = 0.0
    s[S_XING] = 0.0
    s[S_CHAINED] = 0.0
    c[C_SEG_N] = 1
    c[C_MA_N] = 0


@jit
def _newton_integrals(s, kmax, yoff, q):
    """I_m = int_0^h u^m p(u) du, m = 0..kmax, for the polynomial p through the q newest samples.

    ``p`` has degree q-1 and passes through the q newest sample times (held in ``s``) with values
    ``s[yoff:yoff + NH]`` (oldest first); u = s - (left end of the newest interval), h = newest
    interval. Newton divided differences, then monomial coefficients by Horner. Results go to
    ``s[S_IM:S_IM + kmax + 1]``. (Index arithmetic only: slicing would cost reference counting.)
    """
    t_left = s[S_HT + NH - 2]
    z = S_SCR
    dd = S_SCR + NH
    coef = S_SCR + 2 * NH
    # node order: newest-but-one (u = 0), newest (u = h), then older ones
    s[z] = 0.0
    s[dd] = s[yoff + NH - 2]
    s[z + 1] = s[S_HT + NH - 1] - t_left
    s[dd + 1] = s[yoff + NH - 1]
    for j in range(2, q):
        s[z + j] = s[S_HT + NH - 1 - j] - t_left
        s[dd + j] = s[yoff + NH - 1 - j]
    for lev in range(1, q):
        for j in range(q - 1, lev - 1, -1):
            s[dd + j] = (s[dd + j] - s[dd + j - 1]) / (s[z + j] - s[z + j - lev])
    for i in range(q):
        s[coef + i] = 0.0
    s[coef] = s[dd + q - 1]
    for j in range(q - 2, -1, -1):
        # coef <- coef * (u - z[j]) + dd[j]
        zj = s[z + j]
        for i in range(q - 1, 0, -1):
            s[coef + i] = s[coef + i - 1] - zj * s[coef + i]
        s[coef] = s[dd + j] - zj * s[coef]
    h = s[z + 1]
    hp = h
    for m in range(kmax + 1):
        acc = 0.0
        hq = hp
        for i in range(q):
            acc += s[coef + i] * hq / (m + i + 1)
            hq *= h
        s[S_IM + m] = acc
        hp *= h


@jit
def _interval_moments(s, kmax, a, h, npts):
    """Add to M_0..M_kmax the exact integral over the newest interval of s^k p(s).

    ``p`` is the polynomial of degree npts-1 through the npts (default NH) newest samples and ``a``
    the interval's left end in segment time (npts = 2 is the trapezoid, kept for comparison). The
    rule is causal (the interval is the newest of its stencil) and holds for any spacing; its local
    error is O(h^(NH+1)). On a uniform stencil the rule is a fixed set of weights, cached (``S_W``)
    until the step changes. On an irregular stencil, older samples are used only while their
    intervals are at least h/4 long: after a gap (a long newest interval next to closely spaced
    older samples) a high-degree polynomial would swing wildly across the gap, so the rule falls
    back towards the trapezoid for that interval.
    """
    uniform = True
    for j in range(NH - 1):
        if abs(s[S_HT + j + 1] - s[S_HT + j] - h) > 1e-9 * h:
            uniform = False
            break
    if uniform:
        if not abs(h - s[S_WH]) <= 1e-9 * h:
            for j in range(NH):
                for i in range(NH):
                    s[S_UNIT + i] = 0.0
                s[S_UNIT + j] = 1.0
                _newton_integrals(s, 4, S_UNIT, npts)
                for m in range(5):
                    s[S_W + m * NH + j] = s[S_IM + m]
            s[S_WH] = h
        for m in range(kmax + 1):
            acc = 0.0
            for j in range(NH):
                acc += s[S_W + m * NH + j] * s[S_HY + j]
            s[S_IM + m] = acc
    else:
        q = 2
        while q < npts and s[S_HT + NH - q] - s[S_HT + NH - q - 1] >= 0.25 * h:
            q += 1
        _newton_integrals(s, kmax, S_HY, q)
    # M_k += sum_m C(k, m) a^(k-m) I_m
    for k in range(kmax + 1):
        acc = 0.0
        ap = 1.0
        for j in range(k + 1):
            acc += BINOMIAL[k][j] * ap * s[S_IM + k - j]
            ap = ap * a
        s[S_MOM + k] += acc


@jit
def _spread(seg, n):
    """Half the peak-to-peak range of the segment's values (0 for a flat line)."""
    lo = seg[1, 0]
    hi = seg[1, 0]
    for i in range(1, n):
        lo = min(lo, seg[1, i])
        hi = max(hi, seg[1, i])
    return 0.5 * (hi - lo)


@jit
def _fit(seg, n, omega):
    """Least-squares fit y ~ a sin(w tau) + b cos(w tau) + c over the segment.

    Returns (R^2, amplitude); R^2 = -1 when the segment has no variance.
    """
    s11 = s12 = s13 = s22 = s23 = s33 = 0.0
    r1 = r2 = r3 = sstot = 0.0
    ymean = 0.0
    for i in range(n):
        ymean += seg[1, i]
    ymean /= n
    for i in range(n):
        sn = math.sin(omega * seg[0, i])
        cs = math.cos(omega * seg[0, i])
        y = seg[1, i] - ymean
        s11 += sn * sn
        s12 += sn * cs
        s13 += sn
        s22 += cs * cs
        s23 += cs
        s33 += 1.0
        r1 += sn * y
        r2 += cs * y
        r3 += y
        sstot += y * y
    if sstot <= 0.0:
        return -1.0, 0.0
    # Cramer's rule on the 3x3 normal equations
    det = (
        s11 * (s22 * s33 - s23 * s23)
        - s12 * (s12 * s33 - s23 * s13)
        + s13 * (s12 * s23 - s22 * s13)
    )
    if abs(det) <= 1e-12 * s33 * s33 * s33:
        return 0.0, 0.0
    ca = (
        r1 * (s22 * s33 - s23 * s23) - s12 * (r2 * s33 - s23 * r3) + s13 * (r2 * s23 - s22 * r3)
    ) / det
    cb = (
        s11 * (r2 * s33 - r3 * s23) - r1 * (s12 * s33 - s23 * s13) + s13 * (s12 * r3 - r2 * s13)
    ) / det
    cc = (
        s11 * (s22 * r3 - s23 * r2) - s12 * (s12 * r3 - r2 * s13) + r1 * (s12 * s23 - s22 * s13)
    ) / det
    # least squares: residual sum of squares = y'y - beta' X'y (y centred, so y'y = sstot)
    ssres = sstot - (ca * r1 + cb * r2 + cc * r3)
    return 1.0 - ssres / sstot, math.sqrt(ca * ca + cb * cb)


@jit
def _prefilter(p, s, y, xb):
    """Band-pass one sample through the prefilter whose states are at s[xb:xb+9]; returns the
    filtered value (the signal's prefilter, at S_BAND, is never reset by an estimate)."""
    u = y
    for k in range(3):
        x = xb + 3 * k
        advance(s, x, S_DISC + 8 * (k + 1), s[x + 2], u)
        s[x + 2] = u
        if k < 2:
            u = s[x]
    # high-pass output from the internal low-pass states: u - x - (2 zeta / w) x'
    x = xb + 6
    return u - s[x] - (2.0 * BAND_DAMPING[2] / p[P_WLO]) * s[x + 1]


@jit
def _first_sample(p, s, c, t, y):
    """Initialise the prefilter at its steady state for a constant input and prime the history."""
    if p[P_BAND] > 0.0:
        for k in range(3):
            s[S_BAND + 3 * k] = y
            s[S_BAND + 3 * k + 2] = y
        y = 0.0
    s[S_HT + NH - 1] = t
    s[S_HY + NH - 1] = y
    c[C_HIST_N] = 1
    return y


@jit(inline='always')
def _half_cycle(s, t, d):
    """Count a half cycle of the signal (``S_XING``) where its deviation ``d`` from the running
    centre crosses to the other side by :data:`HALF_CYCLE_LEVEL` of its running peak deviation
    (``S_YR``; the side ``S_XSIGN`` kept across segments); at the crossing, a release
    (``S_RELEASE``, :data:`RELEASE_RATIO`) ends the run on the side left."""
    level = HALF_CYCLE_LEVEL * s[S_YR]
    if (d > level and s[S_XSIGN] <= 0.0) or (d < -level and s[S_XSIGN] >= 0.0):
        rise, fall = s[S_TEXT] - s[S_RUN], t - s[S_TEXT]
        grew = s[S_EXT] > RELEASE_GROWTH * s[S_PEXT] > 0.0  # (a run before it: the rest's)
        if grew and rise > RELEASE_RATIO * fall and rise > NH * s[S_HRUN]:
            s[S_RELEASE] = 1.0
        s[S_XSIGN] = 1.0 if d > 0.0 else -1.0
        s[S_XING] += 1.0
        s[S_RUN], s[S_PEXT], s[S_EXT], s[S_TEXT] = t, s[S_EXT], abs(d), t
    elif abs(d) > s[S_EXT] and d * s[S_XSIGN] > 0.0:  # the run's farthest so far
        s[S_EXT] = abs(d)
        s[S_TEXT] = t


@jit(inline='always')
def _stalled(p, s, c) -> bool:
    """True if the damped model's segment, begun at an onset, a restart, a timeout or a rejected
    estimate (not at a published one: ``S_CHAINED``; a decay's tail keeps its segments), has seen
    min_periods + :data:`AUTO_WINDOW_PERIODS` periods of the signal (``S_XING`` half cycles)
    without an estimate: it began before a free vibration did and holds what came before it
    (:data:`HALF_CYCLE_LEVEL`)."""
    if int(p[P_MODEL]) != MODEL_DAMPED or c[C_HIST_N] != NH or s[S_CHAINED] != 0.0:
        return False
    return s[S_XING] > 2.0 * (p[P_MINPER] + AUTO_WINDOW_PERIODS)


@jit(inline='always')
def _restarts(p, s, c) -> bool:
    """Whether the segment restarts at this sample (from the sample before it; at an onset once
    the stencil refilled, :func:`step`): at an onset
    (``C_ONSET``, :data:`ONSET_RATIO`; its run is then no pull's), a stalled segment
    (:func:`_stalled`) or a release (``S_RELEASE``, :func:`_half_cycle`) in a segment not begun at
    a published estimate (a decay's own segments are kept)."""
    onset = c[C_ONSET] != 0
    if onset:
        s[S_PEXT] = MAX_ABS_VALUE
    released = s[S_RELEASE] != 0.0 and s[S_CHAINED] == 0.0
    s[S_RELEASE] = 0.0
    c[C_ONSET] = 0
    return onset or _stalled(p, s, c) or released


@jit(inline='always')
def _peak(peak, dev, weight):
    """A running peak of the deviation: ``dev`` if it rises above ``peak`` decayed by ``weight``
    (a share a sample), else the decayed peak."""
    decayed = (1.0 - weight) * peak
    return dev if dev > decayed else decayed


@jit(inline='always')
def _outlier(p, s, c, t, y):
    """True if the value ``y`` is an outlier, to skip (counted ``skipped_outlier``).

    The signal's running centre ``S_YC`` (exponential average, weight :data:`SCALE_WEIGHT`) and
    scale ``S_YR`` (the peak of |y - centre|, decaying by the same weight per sample) describe the
    stream, so they survive restarts, as does the onset test's peak ``S_YO`` (decaying within
    :data:`PEAK_TAU_S` at least). A value more than ``outlier_ratio`` scales from the centre,
    or beyond :data:`MAX_ABS_VALUE`, is an outlier once :data:`SCALE_WARMUP` samples set the
    scale; :data:`OUTLIER_RUN` outliers in a row are a real change of level: that one is taken,
    the scale restarts from it and the estimator restarts.
    """
    if abs(y) > MAX_ABS_VALUE:
        c[C_OUTLIER] += 1
        return True
    yc = s[S_YC] if c[C_SCALE_N] > 0 else y
    dev = abs(y - yc)
    if dev > p[P_OUTLIER] * s[S_YR] and p[P_OUTLIER] > 0.0 and c[C_SCALE_N] >= SCALE_WARMUP:
        c[C_OUTLIER_RUN] += 1
        if c[C_OUTLIER_RUN] < OUTLIER_RUN:
            c[C_OUTLIER] += 1
            return True
        s[S_YC] = y
        s[S_YR] = s[S_YO] = dev
        c[C_SCALE_N] = 1
        c[C_OUTLIER_RUN] = 0
        _restart(s, c)
        return False
    if c[C_SCALE_N] < SCALE_WARMUP:
        c[C_SCALE_N] += 1
    elif dev > ONSET_RATIO * s[S_YO]:
        c[C_ONSET] = 1  # taken by step
    s[S_YC] = yc + SCALE_WEIGHT * (y - yc)
    s[S_YR] = _peak(s[S_YR], dev, SCALE_WEIGHT)
    s[S_YO] = _peak(s[S_YO], dev, max(SCALE_WEIGHT, s[S_HRUN] / PEAK_TAU_S))
    _half_cycle(s, t, y - yc)
    if c[C_OUTLIER_RUN] != 0:
        c[C_OUTLIER_RUN] = 0
    return False


@jit(inline='always')
def _gap(p, s, c, h):
    """True if the step ``h`` (within ``max_gap``) is a gap: longer than ``gap_intervals`` running
    sample intervals. Counts it (``gaps``) and the samples it lost (``samples_lost``, at the
    running interval); the caller restarts the estimator, so no fit spans it. The running interval
    ``S_HRUN`` (exponential average of the steps, weight :data:`HRUN_WEIGHT`) is learnt again from
    the next step, so a lasting change of rate costs one restart.
    """
    hrun = s[S_HRUN]
    if hrun <= 0.0:
        s[S_HRUN] = h
        return False
    if p[P_GAPN] > 0.0 and h > p[P_GAPN] * hrun:
        c[C_GAPS] += 1
        c[C_LOST] += max(0, int(round(h / hrun)) - 1)
        s[S_HRUN] = 0.0
        return True
    s[S_HRUN] = hrun + HRUN_WEIGHT * (h - hrun)
    return False


@jit(inline='always')
def _accept_time(p, s, c, t, y):
    """Time handling: True if the sample is used, False if it is skipped (counted either way).

    A non-finite sample, a duplicate stamp, a small step back or an outlier (:func:`_outlier`) is
    skipped; a gap, or a backward jump, longer than ``max_gap`` restarts the estimator (counted),
    which then takes the sample as its first; so does a shorter gap (:func:`_gap`).
    """
    c[C_RECEIVED] += 1
    if not (math.isfinite(t) and math.isfinite(y)):
        c[C_NONFINITE] += 1
        return False
    max_gap = p[P_MAXGAP]
    if c[C_HIST_N] > 0:
        h = t - s[S_TLAST]
        if h == 0.0:
            c[C_DUPLICATE] += 1
            return False
        if h < 0.0 and -h <= max_gap:
            c[C_OUT_OF_ORDER] += 1
            return False
    if _outlier(p, s, c, t, y):
        return False
    if c[C_HIST_N] > 0:
        h = t - s[S_TLAST]
        if h < 0.0:
            c[C_TIME_JUMP] += 1
            _restart(s, c)
            s[S_HRUN] = 0.0
        elif h > max_gap:
            c[C_GAP] += 1
            if s[S_HRUN] > 0.0:
                c[C_LOST] += max(0, int(round(min(h / s[S_HRUN], 1e15))) - 1)
            s[S_HRUN] = 0.0
            _restart(s, c)
        elif _gap(p, s, c, h):
            _restart(s, c)
    c[C_USED] += 1
    s[S_TLAST] = t
    return True


@jit(inline='always')
def _update_discretisations(p, s, h):
    """Exact discretisations of the invariant filter (Eq. 11) and the prefilter for the step h.

    Called only when the step changes by more than rounding (a uniform stream's stamps differ in
    the last bits), see :func:`step`.
    """
    discretise(p[P_WC], p[P_ZC], h, s, S_DISC)
    if p[P_BAND] > 0.0:
        for k in range(3):
            discretise(
                p[P_WHI] if k < 2 else p[P_WLO], BAND_DAMPING[k], h, s, S_DISC + 8 * (k + 1)
            )
    s[S_CACHE_H] = h


@jit(inline='always')
def _push_history(s, c, seg, t, y):
    """Shift (t, y) into the interpolation stencil; True once the stencil holds NH samples.

    The first segment after a (re)start begins when the stencil is full, so every interval of it is
    integrated with the full-order rule.
    """
    for i in range(NH - 1):
        s[S_HT + i] = s[S_HT + i + 1]
        s[S_HY + i] = s[S_HY + i + 1]
    s[S_HT + NH - 1] = t
    s[S_HY + NH - 1] = y
    if c[C_HIST_N] < NH:
        c[C_HIST_N] += 1
        if c[C_HIST_N] == NH:
            reset_segment(s, c, seg, t, y)
        return False
    return True


@jit(inline='always')
def _numerator_denominator(model, tau, y, m0, m1, m2, m3, m4):
    """Eq. 7 (with Eq. 8's corrected sign) in moments: n and d of omega^2 = n / d at time tau.

    ``sinusoid`` / ``damped-sinusoid``: n = -(tau^2 y + 2 tau M0 - 6 M1), d = tau M2 - M3;
    ``biased-sinusoid`` (offset eliminated by a third derivation in s): N = -tau^3 y + 3 tau^2 M0
    - 24 tau M1 + 30 M2, D = -1.5 tau^2 M2 + 4 tau M3 - 2.5 M4 (moments as scalars: arrays
    passed to an inlined helper cost reference counting per sample).
    """
    if model == MODEL_BIASED:
        num = -tau * tau * tau * y + 3.0 * tau * tau * m0 - 24.0 * tau * m1 + 30.0 * m2
        den = -1.5 * tau * tau * m2 + 4.0 * tau * m3 - 2.5 * m4
    else:
        num = -(tau * tau * y + 2.0 * tau * m0 - 6.0 * m1)
        den = tau * m2 - m3
    return num, den


@jit(inline='always')
def _invariant_filter(filtered, s, model, num, den, tau, h):
    """Invariant filtering, Eqs. 9-11: n and d (and q of the damped model) through one low-pass.

    The same exactly discretised second-order filter acts on every term, so n_f / d_f stays w^2
    for a pure sine. The damped model also forms q = 3 M2 - 2 tau M1 and the running integrals of
    n_f, q_f, d_f (its second equation).
    """
    if filtered:
        advance(s, S_NF, S_DISC, s[S_NPREV], num)
        advance(s, S_DF, S_DISC, s[S_DPREV], den)
    else:
        s[S_NF] = num
        s[S_DF] = den
    s[S_NPREV] = num
    s[S_DPREV] = den
    if model == MODEL_DAMPED:
        q = 3.0 * s[S_MOM + 2] - 2.0 * tau * s[S_MOM + 1]
        if filtered:
            advance(s, S_QF, S_DISC, s[S_QPREV], q)
        else:
            s[S_QF] = q
        s[S_QPREV] = q
        s[S_INT] += h * s[S_NF]
        s[S_INT + 1] += h * s[S_QF]
        s[S_INT + 2] += h * s[S_DF]


@jit(inline='always')
def _ratio(model, nf, df, qf, i_n, i_q, i_d):
    """Eq. 12: (omega^2, damping ratio) from the filtered terms; omega^2 <= 0 when undefined.

    ``damped-sinusoid``: n = 2 sigma q + w_n^2 d holds at every instant; filtered (F1) and then
    integrated (F2) it gives two equations in (2 sigma, w_n^2), solved by Cramer's rule. The other
    models: omega^2 = n_f / d_f (damping NaN).
    """
    damping = math.nan
    if model == MODEL_DAMPED:
        det = qf * i_d - df * i_q
        w2 = (qf * i_n - nf * i_q) / det if det != 0.0 else -1.0
        if w2 > 0.0:
            damping = 0.5 * (nf * i_d - df * i_n) / det / math.sqrt(w2)
    else:
        w2 = nf / df if df != 0.0 else -1.0
    return w2, damping


@jit(inline='always')
def _converged(m, one_sided, tol, s, c, f):
    """Eqs. 16-17: the moving average of the last M+1 estimates against the one M samples earlier.

    Pushes f into the ring of the last 2M+1 estimates; True when the relative change (its absolute
    value unless ``one_sided_test``) is below the tolerance.
    """
    size = 2 * m + 1
    k = c[C_MA_N]
    newest = k % size  # ring positions by wrapping, not by a modulo per term
    s[S_MA + newest] = f
    c[C_MA_N] = k + 1
    if k + 1 < size:
        return False
    ma_now = 0.0
    ma_then = 0.0
    i_now = newest
    i_then = newest - m if newest >= m else newest - m + size
    for _ in range(m + 1):
        ma_now += s[S_MA + i_now]
        ma_then += s[S_MA + i_then]
        i_now = i_now - 1 if i_now > 0 else size - 1
        i_then = i_then - 1 if i_then > 0 else size - 1
    change = ma_now - ma_then
    if not one_sided:
        change = abs(change)
    return change < tol * ma_now


@jit(inline='always')
def _quality_gate(p, c, model, f, damping, h, r2, amp, consistent, spread, confirmed):
    """True if the converged estimate may be published; else count why it is held back.

    At rest (no variance, or amplitude, or the segment's half range ``spread``, at or below
    ``min_amplitude``: a flat, quantised segment is at rest whatever its fit), above Nyquist, a
    fit R^2 below ``min_fit`` (of the refined model; with ``refine`` = 0 of a sinusoid and offset
    at f) or not ``consistent`` (the refinement moved the segment's own algebraic estimate by more
    than ``MAX_REFINE_MOVE`` stds and ``MIN_REFINE_MOVE_REL``: both fit one model to the same
    samples, so on data the model describes they differ by about one std; a forced motion, not a
    free vibration; counted with the fit), or (damped model) |damping ratio| above
    ``max_damping``: a "lightly damped vibration" with more damping is a transient, not a mode;
    last, not ``confirmed`` by the estimate of the segment just before (``consistency``,
    :func:`_confirmed`; counted as inconsistent).
    """
    if r2 < 0.0 or amp <= p[P_MINAMP] or spread <= p[P_MINAMP]:
        c[C_REST] += 1
    elif f * 2.0 * h >= 1.0:
        c[C_NYQUIST] += 1
    elif r2 < p[P_MINFIT] or not consistent:
        c[C_FIT] += 1
    elif model == MODEL_DAMPED and not abs(damping) <= p[P_MAXDAMP]:
        c[C_DAMPING] += 1
    elif not confirmed:
        c[C_INCONSISTENT] += 1
    else:
        return True
    return False


@jit(inline='always')
def _confirmed(p, s, f):
    """``consistency`` (0 = off): True if f lies within that fraction of the estimate of the
    segment just before (``S_FPREV``; none after a restart, a timeout or a rejected segment).

    Two consecutive estimates of one mode that differ by more cannot both be right: a model that
    misses the signal's offset or waveform fits each half-period lobe with its own frequency
    (1.43 / 2.59 Hz on a 1.81 Hz limit cycle with an offset of half its amplitude), each with a
    high R^2, so a segment is judged against its neighbour, not alone.
    """
    tol = p[P_CONSIST]
    return tol <= 0.0 or (s[S_FPREV] > 0.0 and abs(f - s[S_FPREV]) <= tol * s[S_FPREV])


@jit(inline='always')
def _chain(s, c, f, published, inconsistent_before):
    """Keep f as the next segment's predecessor if this one was published or held back only by
    :func:`_confirmed`; forget it (0) if the gate rejected it for any other reason."""
    s[S_FPREV] = f if published or c[C_INCONSISTENT] > inconsistent_before else 0.0


@jit(inline='always')
def _finite_estimate(c, f, r2, amp, res):
    """True if the estimate's numbers may be published: frequency, fit and amplitude finite,
    the stds and damping finite or NaN (not computed, not applicable), never infinite. Else
    the estimate is held back, counted with the fit (``rejected_fit``): a NaN R^2 compares
    false against ``min_fit`` and would pass the quality gate.
    """
    if (
        math.isfinite(f)
        and math.isfinite(r2)
        and math.isfinite(amp)
        and not math.isinf(res[U.R_FSTD])
        and not math.isinf(res[U.R_DSTD])
        and not math.isinf(res[U.R_DAMP])
    ):
        return True
    c[C_FIT] += 1
    return False


@jit
def forget_stream(s, c):
    """:func:`_restart`, and forget the stream's running interval and scale too."""
    _restart(s, c)
    s[S_HRUN] = 0.0
    s[S_YC] = 0.0
    s[S_YR] = 0.0
    s[S_YO] = 0.0
    c[C_SCALE_N] = 0
    c[C_OUTLIER_RUN] = 0


@jit(inline='always')
def _store_sample(p, s, c, seg, t, tau, y):
    """Keep (tau, y) in the segment buffer; True if the segment ran out (``max_window`` or buffer).

    A segment that runs out resets without publishing, counted as at rest or as not converged.
    ``max_window`` = 0 is automatic: 10 s, or min_periods + 2 periods of the segment's first
    converged half-period estimate when that is longer (so long windows are never cut short).
    """
    nseg = c[C_SEG_N]
    cap = seg.shape[1]
    if nseg < cap:
        seg[0, nseg] = tau
        seg[1, nseg] = y
    c[C_SEG_N] = nseg + 1
    limit = p[P_MAXWIN]
    if limit <= 0.0:
        limit = AUTO_WINDOW_S
        if s[S_FLAST] > 0.0:
            limit = max(limit, (p[P_MINPER] + AUTO_WINDOW_PERIODS) / s[S_FLAST])
    if tau > limit or nseg + 1 >= cap:
        if _spread(seg, min(nseg + 1, cap)) <= p[P_MINAMP]:
            c[C_REST] += 1
        else:
            c[C_MAX_WINDOW] += 1
        reset_segment(s, c, seg, t, y)
        s[S_FPREV] = 0.0
        return True
    return False


@jit
def _long_window_spanned(p, s, c, m, one_sided, model, tau, f, damping):
    """Long window (``refine`` and ``min_periods`` >= :data:`LONG_WINDOW_PERIODS`): True once
    the segment spans ``min_periods`` periods of its first converged half-period estimate.

    That estimate (what the default configuration publishes; the algebraic estimate wanders over
    many periods) is kept in ``S_FLAST``, with its damping ratio (damped model, clipped to
    ``max_damping``) in ``S_DLAST``: the refinement starts from both. The algebraic damping of a
    long segment is meaningless (|zeta| ~ 0.5): started there, a fit once settled in a wrong
    minimum 27 stds off.
    """
    if s[S_FLAST] == 0.0:
        if _converged(m, one_sided, p[P_TOL], s, c, f) and tau * f >= 0.5:
            s[S_FLAST] = f
            s[S_DLAST] = (
                min(max(damping, -p[P_MAXDAMP]), p[P_MAXDAMP]) if model == MODEL_DAMPED else 0.0
            )
        elif _early_start(p, s, tau, f):
            s[S_FLAST] = s[S_FPREV]
            s[S_DLAST] = 0.0
            return True
        return False
    return tau * s[S_FLAST] >= (max(p[P_MINPER], HELD_PERIODS) if s[S_HELD] else p[P_MINPER])


@jit(inline='always')
def _early_start(p, s, tau, f):
    """``early_std_rel``: True when a segment whose algebraic estimate ``f`` has not passed the
    convergence test spans ``min_periods`` periods of the previous segment's estimate and ``f``
    agrees with it within ``consistency`` (off with that gate off): the same mode, so the fit may
    start there. Not once the segment is held (:func:`_held`)."""
    prev = s[S_FPREV]
    if p[P_EARLY] <= 0.0 or prev <= 0.0 or s[S_HELD] or tau * prev < p[P_MINPER]:
        return False
    return abs(f - prev) <= p[P_CONSIST] * prev


@jit(inline='always')
def _held(p, s, tau, res):
    """``early_std_rel``: True (and the segment held to :data:`HELD_PERIODS`, see
    :func:`_long_window_spanned`) when a long-window estimate short of that span has a predicted
    relative std of f above ``early_std_rel``: a decay ringing into its noise is estimated over
    the longer window there, and over ``min_periods`` where it is precise."""
    if p[P_EARLY] <= 0.0 or s[S_HELD] or tau * s[S_FLAST] >= HELD_PERIODS:
        return False
    if res[U.R_FSTD] <= p[P_EARLY] * res[U.R_F]:  # False for a NaN std: held
        return False
    s[S_HELD] = 1.0
    s[S_FLAST] = 0.0  # from here the segment is the default long window's
    return True


@jit(inline='always')
def _publishable(p, s, c, seg, n, model, f, h, r2, amp, consistent, res):
    """The gates, in order: finite numbers (:func:`_finite_estimate`), then the quality gate
    (:func:`_quality_gate`, with the segment's spread and :func:`_confirmed`); the segment is then
    chained to the next (:func:`_chain`). True if the estimate is published."""
    inconsistent_before = c[C_INCONSISTENT]
    published = _finite_estimate(c, f, r2, amp, res) and _quality_gate(
        p, c, model, f, res[U.R_DAMP], h, r2, amp, consistent, _spread(seg, n), _confirmed(p, s, f)
    )
    _chain(s, c, f, published, inconsistent_before)
    return published


@jit(inline='always')
def _write_estimate(out, row, t, f, tau, samples, r2, amp, res):
    """The published estimate into ``out[row]`` (the O_* layout of :class:`EstimateArrays`)."""
    out[row, O_T] = t
    out[row, O_F] = f
    out[row, O_CONV] = tau
    out[row, O_SAMPLES] = samples
    out[row, O_FIT] = r2
    out[row, O_AMP] = amp
    out[row, O_DAMP] = res[U.R_DAMP]
    out[row, O_FSTD] = res[U.R_FSTD]
    out[row, O_DSTD] = res[U.R_DSTD]


@jit(inline='always')
def step(p, s, c, seg, t, y, out, row, optional=None):
    """Feed one sample; return 1 and fill ``out[row]`` when an estimate is published, else 0.

    (The row index rather than a view of it: a view per sample costs its reference counting.)
    ``optional``: :func:`optional_features` of ``p`` (None for a configuration without band std,
    ``target_std_rel`` or long windows: their code is then not compiled, :func:`_band_std_if`).
    """
    if not _accept_time(p, s, c, t, y):
        return 0
    if c[C_HIST_N] == 0:
        _first_sample(p, s, c, t, y)
        return 0
    onset = c[C_ONSET] != 0
    if _restarts(p, s, c) and c[C_HIST_N] == NH:
        if onset:  # the stencil refills from this sample (none straddles the jump)
            c[C_HIST_N] = 0
        else:  # a segment from the sample before it
            reset_segment(s, c, seg, s[S_HT + NH - 1], s[S_HY + NH - 1])
    h = t - s[S_HT + NH - 1]  # the newest sample of the stencil is the previous one
    if abs(h - s[S_CACHE_H]) > 1e-9 * h:
        _update_discretisations(p, s, h)
    if p[P_BAND] > 0.0:
        y = _prefilter(p, s, y, S_BAND)
    if not _push_history(s, c, seg, t, y):
        return 0
    tau = t - s[S_T0]
    model = int(p[P_MODEL])
    _interval_moments(
        s, 4 if model == MODEL_BIASED else 3, s[S_HT + NH - 2] - s[S_T0], h, int(p[P_RULE])
    )
    num, den = _numerator_denominator(
        model, tau, y, s[S_MOM], s[S_MOM + 1], s[S_MOM + 2], s[S_MOM + 3], s[S_MOM + 4]
    )
    _invariant_filter(p[P_FILTER] > 0.0, s, model, num, den, tau, h)
    nseg = c[C_SEG_N]
    if _store_sample(p, s, c, seg, t, tau, y):
        return 0
    if tau <= p[P_EPS] or nseg + 1 < p[P_MINSAMP]:
        return 0
    w2, damping = _ratio(model, s[S_NF], s[S_DF], s[S_QF], s[S_INT], s[S_INT + 1], s[S_INT + 2])
    if not (w2 > 0.0 and math.isfinite(w2)):
        c[C_MA_N] = 0
        return 0
    f = math.sqrt(w2) / TWO_PI
    m = int(p[P_M])
    one_sided = p[P_ONESIDED] != 0.0
    n_fit = min(nseg + 1, seg.shape[1])
    local_start = True  # the refinement starts at this segment's own algebraic estimate
    if p[P_TARGET] > 0.0:
        if tau * f < p[P_MINPER] or not _target_reached_if(
            optional, p, s, seg, n_fit, model, f, damping
        ):
            return 0
    elif p[P_REFINE] > 0.0 and p[P_MINPER] >= LONG_WINDOW_PERIODS:
        if not _long_window_if(optional, p, s, c, m, one_sided, model, tau, f, damping):
            return 0
        f, damping, local_start = s[S_FLAST], s[S_DLAST], False
    # the segment must span a fraction of the period it estimates
    elif not _converged(m, one_sided, p[P_TOL], s, c, f) or tau * f < p[P_MINPER]:
        return 0
    res = s[S_RES : S_RES + U.N_RESULT]
    _refine(p, s, seg, n_fit, model, f, damping, res, optional)
    if not local_start and _held(p, s, tau, res):
        return 0
    start, f = f, res[U.R_F]
    consistent = True
    if p[P_REFINE] > 0.0 and math.isfinite(res[U.R_FIT]):
        r2, amp = res[U.R_FIT], res[U.R_AMP]  # the refined model's own residual
        allowed = max(MAX_REFINE_MOVE * res[U.R_FSTD], MIN_REFINE_MOVE_REL * f)
        consistent = not local_start or abs(f - start) <= allowed
    else:
        r2, amp = _fit(seg, n_fit, TWO_PI * f)
    published = _publishable(p, s, c, seg, n_fit, model, f, h, r2, amp, consistent, res)
    if published:
        _write_estimate(out, row, t, f, tau, nseg + 1, r2, amp, res)
        c[C_ESTIMATES] += 1
    reset_segment(s, c, seg, t, y)
    s[S_CHAINED] = 1.0 if published else 0.0
    return 1 if published else 0


@jit
def _tail_gramian(p, s):
    """W = sum_(k>=1) (C A^k)^T C A^k of the prefilter's free response, and rho(0) = sum g^2.

    The prefilter's 9 states (3 sections x (2 states, previous input)) evolve as X' = A X with
    output C X' once its input is zero; A and CA are probed with unit states through
    :func:`_prefilter` itself. Cached for the step of the current discretisation.
    """
    if s[S_TAILH] == s[S_CACHE_H]:
        return
    base = S_BANDJ
    a = np.empty((9, 9))
    v = np.empty(9)
    for k in range(9):
        s[base : base + 9] = 0.0
        s[base + k] = 1.0
        v[k] = _prefilter(p, s, 0.0, base)
        for i in range(9):
            a[i, k] = s[base + i]
    w = s[S_TAILW : S_TAILW + 81].reshape((9, 9))
    w[:, :] = 0.0
    peak = 0.0
    nxt = np.empty(9)
    for _ in range(MAX_BAND_TAIL):
        energy = 0.0
        for i in range(9):
            energy += v[i] * v[i]
            for j in range(9):
                w[i, j] += v[i] * v[j]
        peak = max(peak, energy)
        if energy <= 1e-16 * peak:
            break
        for j in range(9):
            acc = 0.0
            for i in range(9):
                acc += v[i] * a[i, j]
            nxt[j] = acc
        for i in range(9):
            v[i] = nxt[i]
    s[base : base + 9] = 0.0
    g0 = _prefilter(p, s, 1.0, base)
    s[S_TAILH] = s[S_CACHE_H]
    s[S_TAILH + 1] = g0 * g0 + _quadratic(w, s, base, base)


@jit
def _quadratic(w, s, xi, xj):
    """s[xi:xi+9]^T w s[xj:xj+9]."""
    acc = 0.0
    for i in range(9):
        for j in range(9):
            acc += s[xi + i] * w[i, j] * s[xj + j]
    return acc


@jit
def _band_std(p, s, seg, n, model, res):
    """With ``band_hz``: the std of the fit under the prefilter's coloured noise (sandwich).

    J^T R J = sum over m of q_m q_m^T with q_m = sum_i g_(i - m) J_i (g: the prefilter's impulse
    response): the columns of J, time-reversed, filtered by the prefilter from rest, summed over
    the window, plus the filter's free response after it in closed form (X_i^T W X_j,
    :func:`_tail_gramian`). Exact on uniform sampling (the prefilter's discretisation at the
    latest step); :func:`core.uncertainty.coloured_std`.
    """
    _tail_gramian(p, s)
    work = s[S_WORK : S_WORK + U.N_WORK]
    th, _, _, gram, _, _, _, _ = U._workspace(work)  # J^T J's scratch, free after the fit
    npar = 3 if model == MODEL_SINUSOID else 4
    s[S_BANDJ : S_JROW + NBJ] = 0.0
    gram[:, :] = 0.0
    tc = 0.5 * (seg[0, 0] + seg[0, n - 1])
    for r in range(n):
        U.jacobian_row(model, th, seg[0, n - 1 - r] - tc, s[S_JROW : S_JROW + 4])
        for col in range(npar):
            s[S_JROW + col] = _prefilter(p, s, s[S_JROW + col], S_BANDJ + 9 * col)
        for i in range(npar):
            for j in range(npar):
                gram[i, j] += s[S_JROW + i] * s[S_JROW + j]
    w = s[S_TAILW : S_TAILW + 81].reshape((9, 9))
    for i in range(npar):
        for j in range(npar):
            gram[i, j] += _quadratic(w, s, S_BANDJ + 9 * i, S_BANDJ + 9 * j)
    U.coloured_std(model, n, gram, s[S_TAILH + 1], res, work)


def optional_features(p):
    """The ``optional`` argument of :func:`step` and :func:`run` for the parameters ``p``: None
    unless the configuration uses the band std, ``target_std_rel`` or long windows (the
    conditions under which :func:`step` calls them), else True."""
    long_window = p[P_REFINE] > 0.0 and p[P_MINPER] >= LONG_WINDOW_PERIODS
    return True if p[P_BAND] > 0.0 or p[P_TARGET] > 0.0 or long_window else None


def _unused(optional):
    """Whether ``optional`` (a numba type) is None: the optional features are then not compiled."""
    return isinstance(optional, (types.NoneType, types.Omitted))


@jit
def _missing_optional():
    """A configuration's optional feature reached with ``optional`` None (a caller's error)."""
    raise ValueError('kernel: run/step need optional=optional_features(p) for this p')


def _only_with_optional(python, missing=None):
    """Compile ``python`` (a function whose first argument is ``optional``) only where its
    caller passes ``optional`` (:func:`optional_features`): numba's overload of it is its own body,
    or, with ``optional`` None, a function of the same arguments that raises
    (:func:`_missing_optional`) and returns ``missing`` (its result's type); the optional
    features' code is then not compiled. ``python`` runs as it is uncompiled
    (:func:`core.jit.interpreted`)."""
    code = python.__code__
    names = ', '.join(code.co_varnames[: code.co_argcount])
    scope = {'_missing_optional': _missing_optional, '_unused': _unused, 'python': python}
    exec(
        f'def absent({names}):\n    _missing_optional()\n    return {missing!r}\n\n'
        f'def typed({names}):\n    return absent if _unused(optional) else python\n',
        scope,
    )
    overload(python, inline='always')(scope['typed'])


def _band_std_if(optional, p, s, seg, n, model, res):
    """:func:`_band_std`, compiled only for a configuration with optional features."""
    _band_std(p, s, seg, n, model, res)


def _target_reached_if(optional, p, s, seg, n, model, f, damping):
    """:func:`_target_reached`, compiled only with optional features."""
    return _target_reached(p, s, seg, n, model, f, damping, optional)


def _long_window_if(optional, p, s, c, m, one_sided, model, tau, f, damping):
    """:func:`_long_window_spanned`, compiled only with optional features."""
    return _long_window_spanned(p, s, c, m, one_sided, model, tau, f, damping)


_only_with_optional(_band_std_if)
_only_with_optional(_target_reached_if, False)
_only_with_optional(_long_window_if, False)


@jit(inline='always')
def _start(model, f, damping):
    """Start of the refinement: (w, sigma) = (w_d, zeta w_n) from the algebraic (w_n, zeta)."""
    wn = TWO_PI * f
    if model == MODEL_DAMPED and abs(damping) < 1.0:
        return wn * math.sqrt(1.0 - damping * damping), damping * wn
    return wn, 0.0


@jit(inline='always')
def _fit_with_std(p, s, seg, n, model, f, damping, iterations, res, optional):
    """``iterations`` Gauss-Newton steps of the model over the segment from the algebraic (f,
    damping) and the std of the result (:func:`core.uncertainty.refine`; with ``band_hz`` the
    coloured-noise std, :func:`_band_std`) into ``res``; False if no fit is possible."""
    w0, sigma0 = _start(model, f, damping)
    res[:] = math.nan
    if not U.refine(model, seg, n, w0, sigma0, iterations, res, s[S_WORK : S_WORK + U.N_WORK]):
        return False
    if p[P_BAND] > 0.0:
        _band_std_if(optional, p, s, seg, n, model, res)
    return True


@jit(inline='always')
def _refine(p, s, seg, n, model, f, damping, res, optional):
    """The estimate to gate and publish: ``res`` = (f, damping, their std), core.uncertainty.

    ``refine`` = 0 keeps the paper's algebraic (f, damping) and adds their std; otherwise up to
    ``refine`` Gauss-Newton steps of the model over the segment replace them (the quality gate
    then judges the refined frequency).
    """
    iterations = int(p[P_REFINE])
    if (
        not _fit_with_std(p, s, seg, n, model, f, damping, iterations, res, optional)
        or iterations == 0
    ):
        res[U.R_F] = f
        res[U.R_DAMP] = damping


@jit(inline='always')
def _target_reached(p, s, seg, n, model, f, damping, optional):
    """``target_std_rel``: True once the predicted relative std of f is at or below the target.

    The std (the Fisher information of the model over the segment at the algebraic estimate, with
    the residual variance) costs a pass over the segment, so it is checked at every sample up to
    64 and then each time the segment has grown by 1/16 (an amortised 16 passes per sample).
    """
    if n < s[S_NEXT]:
        return False
    s[S_NEXT] = max(n + 1.0, n * (1.0 + 1.0 / 16.0)) if n >= 64 else n + 1.0
    res = s[S_RES : S_RES + U.N_RESULT]
    return (
        _fit_with_std(p, s, seg, n, model, f, damping, 0, res, optional)
        and res[U.R_FSTD] <= p[P_TARGET] * f
    )


@jit
def run(p, s, c, seg, t, y, out, start, optional=None):
    """Feed ``t[start:]``, ``y[start:]``; write estimates to ``out`` rows (``optional``:
    :func:`step`).

    Returns (number of estimates written, index of the next sample to feed). Stops early when
    ``out`` is full so the caller can grow it and continue. The arrays are used through
    :func:`core.jit.borrowed` views (no reference counting per sample).
    """
    p, s, c, seg = borrowed(p), borrowed(s), borrowed(c), borrowed(seg)
    t, y, out = borrowed(t), borrowed(y), borrowed(out)
    n_out = 0
    i = start
    n = t.shape[0]
    while i < n:
        if n_out >= out.shape[0]:
            return n_out, i
        if step(p, s, c, seg, t[i], y[i], out, n_out, optional):
            n_out += 1
        i += 1
    return n_out, i


#: the streaming buffer's layout (:func:`feed`): the parameters, then the published row, the
#: sample (t, y), the state and the segment buffer (its length is the rest)
F_ROW = N_PARAMS
F_SAMPLE = F_ROW + N_OUT
F_STATE = F_SAMPLE + 2


def feed_buffer(p, n_state, buffer_samples):
    """One float64 buffer holding ``p``, the published row, the sample slots, a zeroed state of
    ``n_state`` and a segment buffer of ``buffer_samples``: :func:`feed`'s argument (its views:
    :func:`feed_views`)."""
    f = np.zeros(F_STATE + n_state + 2 * buffer_samples)
    f[:F_ROW] = p
    return f


@jit(inline='always')
def feed_views(f, n_state):
    """The views ``(p, row, s, seg)`` of :func:`feed_buffer`'s ``f``: :func:`run`'s arguments
    (from Python: ``feed_views.py_func``)."""
    n_buf = (f.shape[0] - F_STATE - n_state) // 2
    return (
        f[:F_ROW],
        f[F_ROW:F_SAMPLE].reshape((1, N_OUT)),
        f[F_STATE : F_STATE + n_state],
        f[F_STATE + n_state :].reshape((2, n_buf)),
    )


@jit
def feed(f, c, n_state, t, y, optional=None):
    """Feed one sample ``t``, ``y`` to the estimator whose parameters, row, state and segment
    live in ``f`` (:func:`feed_buffer`); return 1 when ``f``'s row holds a published estimate.

    The streaming path: :func:`run` over the one-sample arrays of ``f``'s sample slots (the same
    compiled code as the batch path: only this wrapper is compiled on top, about 1 s cold), with
    two array arguments to unbox from Python instead of seven (each costs about as much as a
    step).
    """
    f = borrowed(f)
    p, row, s, seg = feed_views(f, n_state)
    f[F_SAMPLE] = t
    f[F_SAMPLE + 1] = y
    sample_t, sample_y = f[F_SAMPLE : F_SAMPLE + 1], f[F_SAMPLE + 1 : F_STATE]
    return run(p, s, borrowed(c), seg, sample_t, sample_y, row, 0, optional)[0]
