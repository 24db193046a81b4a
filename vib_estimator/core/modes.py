# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""Several modes at once (``modes`` >= 1): find up to K modes and track each, no frequency given.

Interface:

* :func:`..factory.create_estimator` builds a :class:`ModeTracker` for ``excitation`` free with
  ``modes`` >= 1 (a :class:`FrequencyEstimator` with ``modes`` = 0).
* ``ModeTracker.update(t, y) -> List[Estimate]`` (each with ``mode`` >= 1, 1 = the lowest
  frequency), ``process(t, y) -> EstimateArrays`` (with the ``mode`` column, sorted by time),
  ``counters`` (aggregate: the names of ``COUNTER_NAMES`` plus the finder's own),
  ``mode_counters() -> Dict[int, Dict[str, int]]``, ``status() -> List[ModeStatus]``, ``reset()``,
  ``restart()``, ``config``.

How the modes are found and estimated (everything compiled, one call per sample):

* **Scales**: the input is decimated by 2 per level (``NLEV`` levels, each behind a 4th-order
  Butterworth anti-alias low-pass at 0.12 of the previous rate) and each level keeps its last
  samples; scale s looks at the last ``M_A`` (even s) or ``M_B`` (odd s) samples of level s // 2,
  so the scales' windows grow by ~sqrt(2) from 48 input samples to 68 * 2^7. A scale's window is
  analysed by :func:`vib_estimator.core.subspace.analyse` (a subspace / ESPRIT fit of damped
  sinusoids whose order comes from the eigenvalue gap above the noise) every ``HOP`` of its
  samples when a mode publishes from it, or will as soon as the mode is old enough (its start,
  below), and every scale so while a candidate waits for confirmation and for ``WAKE_N``
  samples after a block of the input jumps in energy (a mode excited: :func:`_wake`); else every
  ``HOP_IDLE`` samples (the search for new modes), ``HOP_TOP`` at level 0 (only it counts poles
  above 0.1 fs). The frequencies work in cycles per sample, converted to Hz with the measured
  mean interval; gaps up to ``MAX_FILL`` steps are bridged by interpolation.
* **A pole counts** at a scale when it has ``C_TRACK`` cycles in the window, lies below ``NU_HI``
  cycles per (decimated) sample (the anti-alias edge: ``rejected_band_edge`` otherwise), is damped
  within ``max_damping`` and its energy in the window is ``SIG_TRACK`` above the fit's residual
  variance (the noise rule).
* **Finding**: a counted pole no mode explains (none within ``MATCH_TOL``) with ``C_DETECT`` cycles
  and ``SIG_DETECT`` of energy is a candidate, unless it is a harmonic (within ``HARMONIC_TOL`` of
  2..9 times a pole or mode ``HARMONIC_RATIO`` stronger in amplitude, or, seen over c <
  ``SUSPECT_CYCLES`` cycles, within ``SUSPECT_TOL`` / c of one ``SUSPECT_RATIO`` stronger, when
  its frequency is too rough to tell: ``rejected_harmonic``) or
  within ``DUPLICATE_TOL`` of a mode (``rejected_unresolved``); a candidate seen again within
  ``PENDING_TOL`` by a later analysis becomes a mode (``modes_found``), one not seen again within
  a period is ``rejected_noise``. With K modes a new one replaces the weakest only if twice as
  strong. A mode no analysis sees for ``LOSE_PERIODS`` periods is lost (``modes_lost``), and so
  is one that published its first estimate only and nothing in ``LOSE_PERIODS`` of its periods
  since, or that, published once at most, a window as long as its estimate's does not see while
  it sees poles within ``CLOSE_RATIO`` on both sides (:func:`_unresolved`): a merged pole of the
  first short windows after an excitation, which would hide the mode near it, as unresolved, or
  at twice it, as a harmonic. A mode not yet published matches poles within ``DUPLICATE_TOL``
  (the poles it would reject as unresolved), published ones within ``MATCH_TOL``.
* **Publishing**: each mode publishes from one scale, the longest window that (a) holds no more
  than ``C_CAP`` periods of the lowest mode (``C_CAP_CLOSE`` when two modes lie within
  ``CLOSE_RATIO``: resolving them takes longer windows, which react later to a change), (b) keeps
  the mode below ``NU_HI`` and (c) starts after the window in which the mode was first seen (so
  that no published window straddles the excitation); every analysis of that scale publishes the
  mode's pole if its window fit's R^2 is ``min_fit`` (``rejected_fit``), it is no harmonic of a
  stronger pole within ``HARMONIC_TOL`` (``rejected_harmonic``; the rough poles' ``SUSPECT_TOL``
  is the finding's: publishing windows of 2 periods of the lowest mode hold a mode near twice it
  under ``SUSPECT_CYCLES`` cycles for ever) and within ``CONSISTENCY`` of the mode's previous pole
  (``rejected_inconsistent``). The pole that confirms a new mode is its first estimate when its
  window starts after the candidate's first one and it lies within ``CONSISTENCY`` of it. Modes are
  numbered by ascending frequency among the modes that have published.
* **The fast scale**: once a mode has published, its fast scale (the longest window of at most
  ``C_FAST`` periods of the lowest mode, ``C_CAP`` when two modes lie within ``CLOSE_RATIO``: a
  close pair is not resolved in a period, and ``C_TRACK`` cycles of its own) is analysed beside
  its publishing one, and the relative deviation of its pole from the publishing window's is kept
  (a running mean of its square over ``DEV_N`` analyses); while that RMS is ``DEV_MAX`` or less
  (2 % is then 4 of it) the mode publishes from the fast scale, its longer window still analysed
  as the reference (clean decays' dominant modes: 0.77 periods to an estimate instead of 1.54,
  a close pair's 1.92 instead of 2.72; a noisy one, or a mode ringing down into the noise, keeps
  or returns to its longer window). The fast scale's window is analysed less its reference's
  level (:func:`_level`: the offset and slow trend the longer window fitted): over a period or
  less an offset and a sinusoid are nearly collinear, and fitting both there scattered a
  2.7 %-damped mode's poles by 1.5-3 % on an offset of 0.3 (0.2 % with the level removed).
* **First estimates**: until its first estimate a mode publishes under ``C_CAP`` even in a close
  pair, and while the scales are fast after an excitation or the analysed scale is such a mode's,
  the analysis refines its close pairs as undamped
  (:func:`vib_estimator.core.subspace.refine_undamped`: with their dampings free, windows under
  ~1.6 periods cannot tell them apart within 2 %); a first estimate from such a pair needs only
  ``CONSISTENCY_FIRST``.

Streaming and batch run the same compiled step, so they give the same floats.
"""

from __future__ import annotations

import math
import sys
from dataclasses import dataclass
from typing import Dict, List, Sequence

import numpy as np

from .config import EstimatorConfig
from .estimator import (
    COUNTER_NAMES,
    INPUT_COUNTERS,
    Estimate,
    EstimateArrays,
    Estimator,
    as_series,
)
from .jit import available, borrowed, jit, python_of
from .kernel import BAND_DAMPING, advance, discretise
from .subspace import (
    N_R,
    R_AMP,
    R_ENERGY,
    R_NU,
    R_ZETA,
    analyse,
    descending,
    init_subspace,  # noqa: F401 (ModeTracker.restart: self._k.init_subspace)
)

KMAX = 8  # most modes a tracker follows (the range of ``modes``)
NLEV = 8  # decimation levels: rates fs .. fs / 128
NS = 2 * NLEV  # scales
M_A, M_B = 48, 68  # window lengths of the even and odd scales (level samples)
NQ = M_B // 3 + 1  # rows of a scale's subspace
PCOL = 14  # most subspace columns
HOP = 12  # level samples between two analyses of a scale a mode publishes from,
HOP_IDLE = 96  # ... of the others at levels >= 1,
HOP_TOP = 384  # ... of the others at level 0 (above 0.1 fs only level 0 counts a pole)
DEC_CUTOFF = 0.12  # anti-alias low-pass before each decimation by 2, cycles per sample
EIG_RATIO = 6.0  # signal eigenvalues: this factor above the noise's
NU_HI = 0.2  # highest pole counted at a scale, cycles per level sample
C_TRACK = 0.7  # cycles in the window for a pole to count ...
C_DETECT = 1.0  # ... for it to become a candidate
C_CAP = 2.0  # publishing windows hold at most this many periods of the lowest mode,
C_CAP_CLOSE = 2.8  # ... this many when two modes lie within CLOSE_RATIO (to resolve them)
CLOSE_RATIO = 1.5
SIG_TRACK = 100.0  # energy / residual variance of a counted pole (20 dB) ...
SIG_DETECT = 300.0  # ... and of a candidate (25 dB)
MIN_DAMPING = -0.02  # poles growing faster than this are not modes
MATCH_TOL = 0.06  # a pole within this of a mode is the mode's
DUPLICATE_TOL = 0.12  # a candidate this close to a mode is not a mode of its own
PENDING_TOL = 0.02  # a candidate seen again within this is confirmed
# relative distance to n f of a stronger pole or mode (n = 2..9): at 0.5 % a clipped mode's
# harmonics are still no modes (bench_modes' 12 Hz clipped at 60 %: 0 % spurious estimates;
# test_harmonics_of_a_clipped_mode_are_no_modes); at 1.5 % modes near an integer ratio were
# dropped as harmonics (4.00 / 15.86 Hz at 1:0.3, 0.9 % off 4 x: 7 estimates; 21.07 / 63.92 Hz
# at 1:0.37, 1.1 % off 3 x: none)
HARMONIC_TOL = 0.005
MAX_HARMONIC = 9
HARMONIC_RATIO = 2.0  # a harmonic's parent is at least this much stronger (amplitude)
# a pole seen over c cycles within SUSPECT_TOL / c (what c cycles resolve) of n f of a pole
# SUSPECT_RATIO times stronger is a harmonic unless seen over SUSPECT_CYCLES: at 0.16 the clipped
# 12 Hz decay's spurious estimates are as at 0.08 at any c (0-6 a seed of ~420); at 0.08 / c its
# harmonics are modes (17-28); 8 % at any c delayed a 17 Hz mode beside 8 Hz (6 % from twice
# it) to 0.49-0.6 s after the pluck, now 0.26 s (bench_modes.py --random 40: 19 -> 20 records
# meet every goal, seed 7)
SUSPECT_TOL = 0.16
SUSPECT_RATIO = 3.0
SUSPECT_CYCLES = 5.0
CONSISTENCY = 0.01  # a published pole lies this close to the mode's previous pole,
CONSISTENCY_FIRST = 0.03  # ... a close pair's first one (undamped refinement) this close
LOSE_PERIODS = 3.0  # a mode unseen (or published once and since not) this many periods is lost
C_FAST = 1.0  # a mode's fast scale: the longest window of at most this many periods of the
#: lowest mode (and C_TRACK of its own); it publishes from it once the RMS of its poles' relative
#: deviations from the publishing window's (a running mean over DEV_N analyses) is DEV_MAX or less
DEV_MAX = 0.005
DEV_N = 8.0
N_STEP = 15  # intervals whose median is the grid step
MAX_FILL = 64  # grid steps interpolated between two samples at most (else a restart)
NPEND = 16  # candidates kept
WAKE_BLOCK = 32  # an input block WAKE_RATIO times more energetic than the largest of the
WAKE_RATIO = 8.0  # previous ones (fading by WAKE_FADE per block) ...
WAKE_FADE = 0.97
WAKE_N = M_B << 3  # ... makes every scale fast for this many samples
BLOCK = 1 << 15  # samples per block of the batch path

# ---- float array b: decimators, level rings, time base -------------------------------------
DEC_N = 22  # per level: two sections' Phi G0 G1 (16), states (2 + 2), inputs (2)
B_DEC = 0
B_RING = B_DEC + DEC_N * NLEV
B_DT = B_RING + M_B * NLEV  # step of the uniform grid, s
B_TLAST = B_DT + 1
B_Y = B_TLAST + 1  # last accepted input
B_TG = B_Y + 1  # time of the last grid sample
B_HBUF = B_TG + 1  # the first N_STEP intervals (their median is the grid step)
B_E = B_HBUF + 16  # energy of the current WAKE_BLOCK samples, the reference
N_B = B_E + 2
# ---- int array ic ------------------------------------------------------------------------------
(
    I_N,
    I_NDT,
    I_NB,
    I_RECEIVED,
    I_USED,
    I_NONFINITE,
    I_DUPLICATE,
    I_OUT_OF_ORDER,
    I_TIME_JUMP,
    I_GAP,
    I_FOUND,
    I_LOST,
    I_REJ_HARM,
    I_REJ_NOISE,
    I_REJ_UNRES,
    I_REJ_EDGE,
    I_NPEND,
    I_UID,
    I_NOUT,
    I_LEV,
) = range(20)  # I_LEV on: NLEV samples since the (re)start, per level
I_RET = I_LEV + NLEV  # the lost modes' counters (MODE_COUNTERS, in order)
I_BUSY = I_RET + 4  # NS flags: a mode publishes from the scale (or soon will)
I_WAKE = I_BUSY + NS  # input samples of fast analyses left (a change in the signal)
N_I = I_WAKE + 1
#: input counters, named as the estimator's
STAGE_COUNTERS = dict(zip(INPUT_COUNTERS, range(I_RECEIVED, I_GAP + 1)))
#: the finder's counters (the candidates' rules)
FINDER_COUNTERS = {
    'modes_found': I_FOUND,
    'modes_lost': I_LOST,
    'rejected_harmonic': I_REJ_HARM,
    'rejected_noise': I_REJ_NOISE,
    'rejected_unresolved': I_REJ_UNRES,
    'rejected_band_edge': I_REJ_EDGE,
}
# ---- modes sl[k] -------------------------------------------------------------------------------
(
    SL_ACTIVE,
    SL_UID,
    SL_F,
    SL_AMP,
    SL_SEEN,
    SL_START,
    SL_FIRST,
    SL_LAST_F,
    SL_LAST_T,
    SL_PREV,
    SL_EST,
    SL_INCONS,
    SL_HARM,
    SL_FIT,
    SL_REF,
    SL_DEV,
    SL_NDEV,
    SL_WIN,
    SL_LEVEL,
    N_SL,
) = range(20)  # N_*: the slots' number
#: per-mode counters: name -> column of sl (and, for the lost modes' sums, of ic after I_RET)
MODE_COUNTERS = {
    'estimates': SL_EST,
    'rejected_inconsistent': SL_INCONS,
    'rejected_harmonic': SL_HARM,
    'rejected_fit': SL_FIT,
}
# ---- candidates pd[i]: frequency (Hz), start of the first window, last seen ---------------------
PD_F, PD_START, PD_SEEN = range(3)
# ---- parameters pa -----------------------------------------------------------------------------
PA_MAXGAP, PA_K, PA_BLO, PA_BHI, PA_MAXDAMP, PA_MINFIT, PA_P, PA_FAST = range(8)
# ---- output rows: the estimate's fields (EstimateArrays order), then the mode -------------------
(O_T, O_F, O_CONV, O_SAMPLES, O_FIT, O_AMP, O_DAMP, O_FSTD, O_DSTD, O_MODE, N_O) = range(11)


# ---- decimation ------------------------------------------------------------------------------
@jit
def _levels_init(b):
    """Discretise each level's anti-alias low-pass (two Butterworth sections)."""
    for k in range(2):
        for d in range(NLEV):
            discretise(
                2.0 * math.pi * DEC_CUTOFF, BAND_DAMPING[k], 1.0, b, B_DEC + DEC_N * d + 8 * k
            )


@jit
def _levels_settle(b, ic, y):
    """Every filter at rest on a constant input y; the rings start empty."""
    for d in range(NLEV):
        o = B_DEC + DEC_N * d
        b[o + 16 : o + 22] = y
        b[o + 17] = 0.0
        b[o + 19] = 0.0
        ic[I_LEV + d] = 0
    b[B_E : B_E + 2] = 0.0
    ic[I_WAKE] = 0


@jit
def _levels_step(b, ic, y):
    """Input sample y through the levels; returns the highest level that got a sample."""
    n = ic[I_NB]
    ic[I_NB] += 1
    u = y
    top = 0
    for d in range(NLEV):
        if d > 0:
            if n % (1 << (d - 1)) != 0:
                break
            o = B_DEC + DEC_N * d
            advance(b, o + 16, o, b[o + 20], u)
            b[o + 20] = u
            advance(b, o + 18, o + 8, b[o + 21], b[o + 16])
            b[o + 21] = b[o + 16]
            if n % (1 << d) != 0:
                break
            u = b[o + 18]
        b[B_RING + M_B * d + ic[I_LEV + d] % M_B] = u
        ic[I_LEV + d] += 1
        top = d
    return top


@jit
def _window(b, ic, d, m, level):
    """The last m samples of level d, oldest first, less level."""
    x = np.empty(m)
    n = ic[I_LEV + d]
    for i in range(m):
        x[i] = b[B_RING + M_B * d + (n - m + i) % M_B] - level
    return x


# ---- one analysis ------------------------------------------------------------------------------
@jit
def _scale_len(s):
    """Window of scale s in input samples."""
    return (M_A if s % 2 == 0 else M_B) << (s // 2)


@jit(inline='always')
def _poles(b, ic, qs, lams, pa, s, pp, undamped, level):
    """Analyse scale s's window less level (its light pairs refined as undamped if
    ``undamped``); the poles that count (module docstring) as rows of pp: frequency (Hz),
    amplitude, damping, cycles in the window, energy / residual variance, frequency std (Hz).
    Returns (count, R^2, the window's level: its offset and slow trend at its end)."""
    d = s // 2
    m = M_A if s % 2 == 0 else M_B
    npc = int(pa[PA_P])
    rows = np.empty((PCOL, N_R))
    k, var, r2, rest = analyse(
        _window(b, ic, d, m, level),
        qs[s, : m // 3 + 1, :npc],
        lams[s, 0, :npc],
        lams[s, 1:],
        EIG_RATIO,
        rows,
        undamped,
    )
    h = b[B_DT] * (1 << d)
    n = 0
    for i in range(k):
        nu = rows[i, R_NU]
        z = rows[i, R_ZETA]
        sig = rows[i, R_ENERGY] / max(var, 1e-300)
        f = nu / h
        if (
            nu * m < C_TRACK
            or z > pa[PA_MAXDAMP]
            or z < MIN_DAMPING
            or sig < SIG_TRACK
            or f < pa[PA_BLO]
            or f > pa[PA_BHI]
        ):
            continue
        if nu > NU_HI:  # a pole that would count, on the level's anti-alias edge
            ic[I_REJ_EDGE] += 1
            continue
        pp[n, 0] = f
        pp[n, 1] = rows[i, R_AMP]
        pp[n, 2] = z
        pp[n, 3] = nu * m
        pp[n, 4] = sig
        # the Cramer-Rao bound of a sinusoid's frequency over m samples of residual variance var
        pp[n, 5] = math.sqrt(24.0 * var / (rows[i, R_AMP] ** 2 * m**3)) / (2.0 * math.pi * h)
        n += 1
    return n, r2, level + rest


@jit
def _harmonic(f, amp, cycles, pp, n, sl):
    """Whether f lies within HARMONIC_TOL of 2..9 times a pole of pp[:n] or an active mode
    HARMONIC_RATIO times stronger than amp, or, seen over ``cycles`` < ``SUSPECT_CYCLES``,
    within ``SUSPECT_TOL`` / ``cycles`` of such a multiple of one ``SUSPECT_RATIO`` times
    stronger (a found mode's poles: ``cycles`` inf, the first rule alone)."""
    for i in range(n + KMAX):
        if i < n:
            g, a = pp[i, 0], pp[i, 1]
        elif sl[i - n, SL_ACTIVE] != 0.0:
            g, a = sl[i - n, SL_F], sl[i - n, SL_AMP]
        else:
            continue
        r = round(f / g)
        if 2 <= r <= MAX_HARMONIC:
            off = abs(f / (r * g) - 1.0)
            if (a >= HARMONIC_RATIO * amp and off < HARMONIC_TOL) or (
                a >= SUSPECT_RATIO * amp and off * cycles < SUSPECT_TOL and cycles < SUSPECT_CYCLES
            ):
                return True
    return False


@jit
def _cap(sl):
    """(lowest active mode's frequency, longest publishing window in its periods): ``C_CAP``, or
    ``C_CAP_CLOSE`` when two active modes lie within ``CLOSE_RATIO``."""
    fmin = math.inf
    cap = C_CAP
    for j in range(KMAX):
        if sl[j, SL_ACTIVE] != 0.0:
            fmin = min(fmin, sl[j, SL_F])
            for i in range(j):
                if (
                    sl[i, SL_ACTIVE] != 0.0
                    and max(sl[i, SL_F] / sl[j, SL_F], sl[j, SL_F] / sl[i, SL_F]) < CLOSE_RATIO
                ):
                    cap = C_CAP_CLOSE
    return fmin, cap


@jit
def _first_tol(undamped, pp, n, i):
    """Consistency a first estimate (pole i of pp[:n]) needs: ``CONSISTENCY_FIRST`` from an
    undamped refinement (:func:`vib_estimator.core.subspace.refine_undamped`) when another pole
    lies within ``CLOSE_RATIO`` (a close pair), else ``CONSISTENCY``."""
    for j in range(n if undamped else 0):
        if j != i and max(pp[i, 0] / pp[j, 0], pp[j, 0] / pp[i, 0]) < CLOSE_RATIO:
            return CONSISTENCY_FIRST
    return CONSISTENCY


@jit
def _mode_cap(sl, k, cap):
    """Mode k's publishing cap: ``C_CAP`` until its first estimate (a close pair's first estimates
    come from the undamped refinement of a shorter window), then cap (:func:`_cap`)."""
    return min(cap, C_CAP) if sl[k, SL_FIRST] == math.inf else cap


@jit
def _owner(b, sl, k, t, fmin, cap):
    """(the scale mode k publishes from (module docstring), the next longer one if only its start
    keeps it from publishing: the owner soon), -1 for none; fmin, cap from :func:`_cap`. The
    shortest scale is under no cap: when the lowest mode lies above ``cap`` / ``M_A`` cycles per
    sample (fs / 24 with ``C_CAP``: 97 Hz at 1 kHz, 25 Hz at 500 Hz) even its window holds more
    periods of it, and the modes publish from there rather than not at all."""
    f = sl[k, SL_F]
    best = -1
    for s in range(NS):
        w = _scale_len(s) * b[B_DT]
        if (s > 0 and fmin * w > cap) or f * b[B_DT] * (1 << (s // 2)) > NU_HI:
            break
        if t - w < sl[k, SL_START]:
            return best, s
        if f * w >= C_DETECT:
            best = s
    return best, -1


@jit
def _fast(b, sl, k, t, fmin, long, cap):
    """Mode k's fast scale (``C_FAST``): the longest window shorter than scale ``long``'s of at
    most ``C_FAST`` periods of the lowest mode, ``C_TRACK`` of its own, starting after the mode's
    start; -1 for none."""
    f = sl[k, SL_F]
    best = -1
    for s in range(max(long, 0)):
        w = _scale_len(s) * b[B_DT]
        if fmin * w > cap or t - w < sl[k, SL_START]:
            break
        if f * w >= C_TRACK:
            best = s
    return best


@jit
def _publisher(b, sl, pa, k, t, fmin, cap):
    """(the scale mode k publishes from, its window of reference, its fast scale): the fast scale
    (:func:`_fast`) once its poles kept within ``DEV_MAX`` (RMS over ``DEV_N`` analyses) of the
    reference's, the reference (:func:`_owner`) else."""
    long = _owner(b, sl, k, t, fmin, _mode_cap(sl, k, cap))[0]
    fast = -1
    if sl[k, SL_FIRST] < math.inf and pa[PA_FAST] != 0.0:  # a close pair: C_CAP (module doc)
        fast = _fast(b, sl, k, t, fmin, long, C_FAST if cap == C_CAP else C_CAP)
    if fast >= 0 and sl[k, SL_NDEV] >= DEV_N and sl[k, SL_DEV] <= DEV_MAX**2:
        return fast, long, fast
    return long, long, fast


@jit
def _publishers(b, sl, pa, t, fmin, cap):
    """:func:`_publisher` of every active mode (rows; -1 for the others), once per analysis: a
    mode's row depends on its own slots only, which the analysis changes after reading it."""
    pubs = np.full((KMAX, 3), -1, dtype=np.int64)
    for k in range(KMAX):
        if sl[k, SL_ACTIVE] != 0.0:
            pubs[k, 0], pubs[k, 1], pubs[k, 2] = _publisher(b, sl, pa, k, t, fmin, cap)
    return pubs


@jit
def _level(sl, pubs, s):
    """What scale s's window is analysed less: the level (offset and slow trend) of the window of
    reference of the mode whose fast scale s is (the longest such reference; ``pubs``:
    :func:`_publishers`), 0 for none. Over a
    period or less an offset and a sinusoid are nearly collinear, so a window that fits both
    scatters its frequency by several times what one with the offset known does (a 2.7 %-damped
    mode ringing down onto an offset of 0.3: its fast scale's poles 1.5-3 % RMS from the
    reference's, against 0.2 % with the reference's level removed)."""
    level = 0.0
    longest = -1
    for k in range(KMAX):
        if (
            sl[k, SL_ACTIVE] != 0.0
            and sl[k, SL_REF] > 0.0
            and math.isfinite(sl[k, SL_LEVEL])
            and pubs[k, 2] == s
            and pubs[k, 1] > longest
        ):
            level = sl[k, SL_LEVEL]
            longest = pubs[k, 1]
    return level


@jit
def _unresolved(b, sl, pa, pp, n, k, s, t):
    """Whether mode k, published once at most, is a merged pole that scale s's analysis at t
    resolved: a pole of pp[:n] lies within ``CLOSE_RATIO`` below it and another within it above,
    none is the mode's, and the window is no shorter than that of its estimate (``SL_WIN``, 0
    before it), holds ``C_DETECT`` of its cycles and keeps it below ``NU_HI`` and in the band (the
    first short windows after an excitation read 6 and 9 Hz as one 6.9 Hz pole; a longer one sees
    6.0 and 9.0). Such a mode is lost at once, not ``LOSE_PERIODS`` later: meanwhile it would
    hold a mode's place and hide its neighbours (as unresolved) or its double (as a harmonic)."""
    f = sl[k, SL_F]
    w = _scale_len(s)
    if not (
        sl[k, SL_EST] <= 1.0
        and sl[k, SL_SEEN] < t
        and w >= sl[k, SL_WIN]
        and f * b[B_DT] * w >= C_DETECT
        and f * b[B_DT] * (1 << (s // 2)) <= NU_HI
        and pa[PA_BLO] <= f <= pa[PA_BHI]
    ):
        return False
    below = above = False
    for i in range(n):
        below = below or (pp[i, 0] < f and f < CLOSE_RATIO * pp[i, 0])
        above = above or (pp[i, 0] > f and pp[i, 0] < CLOSE_RATIO * f)
    return below and above


@jit
def _remove(ic, sl, k):
    """Mode k is lost: its counters go to the lost modes' sums."""
    sl[k, SL_ACTIVE] = 0.0
    ic[I_LOST] += 1
    for j, col in enumerate((SL_EST, SL_INCONS, SL_HARM, SL_FIT)):
        ic[I_RET + j] += int(sl[k, col])


@jit
def _publish(b, ic, sl, k, s, t, pp, i, r2, out):
    """One estimate of mode k (pole i of scale s's analysis at t) into the next row of out (its
    mode number: :func:`_number`, once the analysis has published all it publishes)."""
    f = pp[i, 0]
    w = _scale_len(s)
    row = out[ic[I_NOUT]]
    ic[I_NOUT] += 1
    row[O_T] = t
    row[O_F] = f
    row[O_CONV] = w * b[B_DT]
    row[O_SAMPLES] = w
    row[O_FIT] = r2
    row[O_AMP] = pp[i, 1]
    row[O_DAMP] = pp[i, 2]
    row[O_FSTD] = pp[i, 5]
    row[O_DSTD] = math.nan
    row[O_MODE] = 0.0
    sl[k, SL_FIRST] = min(sl[k, SL_FIRST], t)
    sl[k, SL_LAST_F] = f
    sl[k, SL_LAST_T] = t
    sl[k, SL_EST] += 1
    sl[k, SL_WIN] = w


@jit
def _number(sl, out, first, last):
    """The mode numbers of rows first..last-1 of out, published by one analysis: 1 + the active
    modes that have published (this analysis included) at lower frequencies. Numbered after the
    analysis, so that two modes' first estimates in one analysis (a higher one published before
    the lower) do not both read 1."""
    for r in range(first, last):
        mode = 1
        for j in range(KMAX):
            published = sl[j, SL_ACTIVE] != 0.0 and sl[j, SL_FIRST] < math.inf
            if published and sl[j, SL_F] < out[r, O_F]:
                mode += 1
        out[r, O_MODE] = mode


@jit
def _admit(ic, sl, pa, f, amp, start, t):
    """A new mode at f if there is room, or in place of the weakest if twice as strong."""
    free = -1
    weakest = -1
    count = 0
    for k in range(KMAX):
        if sl[k, SL_ACTIVE] == 0.0:
            free = k if free < 0 else free
        else:
            count += 1
            weakest = k if weakest < 0 or sl[k, SL_AMP] < sl[weakest, SL_AMP] else weakest
    if count >= pa[PA_K]:
        if amp < HARMONIC_RATIO * sl[weakest, SL_AMP]:
            return -1
        _remove(ic, sl, weakest)
        free = weakest
    ic[I_UID] += 1
    ic[I_FOUND] += 1
    sl[free, :] = 0.0
    sl[free, SL_ACTIVE] = 1.0
    sl[free, SL_UID] = ic[I_UID]
    sl[free, SL_F] = f
    sl[free, SL_AMP] = amp
    sl[free, SL_SEEN] = t
    sl[free, SL_START] = start
    sl[free, SL_FIRST] = math.inf
    sl[free, SL_LAST_F] = math.nan
    sl[free, SL_LAST_T] = math.nan
    sl[free, SL_PREV] = f
    return free


@jit
def _candidates(b, ic, sl, pd, pa, pp, n, used, t, s, r2, undamped, out):
    """The poles no mode explains (module docstring): candidates, confirmed or expired. A
    confirming pole whose window starts after the candidate's first one and lies within
    ``CONSISTENCY`` of it is the new mode's first estimate."""
    start = t - _scale_len(s) * b[B_DT]
    for i in range(n):
        f = pp[i, 0]
        if used[i] or pp[i, 3] < C_DETECT or pp[i, 4] < SIG_DETECT:
            continue
        if _harmonic(f, pp[i, 1], pp[i, 3], pp, n, sl):
            ic[I_REJ_HARM] += 1
            continue
        near = False
        for k in range(KMAX):
            near = near or (sl[k, SL_ACTIVE] != 0.0 and abs(f / sl[k, SL_F] - 1.0) < DUPLICATE_TOL)
        if near:
            ic[I_REJ_UNRES] += 1
            continue
        j = 0
        while j < ic[I_NPEND] and abs(f / pd[j, PD_F] - 1.0) >= PENDING_TOL:
            j += 1
        if j < ic[I_NPEND]:
            if pd[j, PD_SEEN] < t:
                k = _admit(ic, sl, pa, f, pp[i, 1], pd[j, PD_START], t)
                if (
                    k >= 0
                    and start >= pd[j, PD_START]
                    and r2 >= pa[PA_MINFIT]
                    and abs(f / pd[j, PD_F] - 1.0) < _first_tol(undamped, pp, n, i)
                ):
                    _publish(b, ic, sl, k, s, t, pp, i, r2, out)
                pd[j, PD_SEEN] = -math.inf  # taken: dropped below, not as noise
            continue
        if j < NPEND:
            pd[j, PD_F] = f
            pd[j, PD_START] = start
            pd[j, PD_SEEN] = t
            ic[I_NPEND] += 1
    kept = 0
    for j in range(ic[I_NPEND]):
        if pd[j, PD_SEEN] == -math.inf:
            continue
        if (t - pd[j, PD_SEEN]) * pd[j, PD_F] > 1.0:
            ic[I_REJ_NOISE] += 1
            continue
        pd[kept] = pd[j]
        kept += 1
    ic[I_NPEND] = kept


@jit
def _analysis(b, ic, sl, pd, qs, lams, pa, s, t, out):
    """Scale s's analysis at t: match the modes, publish those it owns, find, lose."""
    pp = np.empty((PCOL, 6))
    fmin, cap = _cap(sl)
    undamped = ic[I_WAKE] > 0
    for k in range(KMAX):
        undamped = undamped or (
            sl[k, SL_ACTIVE] != 0.0
            and sl[k, SL_FIRST] == math.inf
            and _owner(b, sl, k, t, fmin, C_CAP)[0] == s
        )
    pubs = _publishers(b, sl, pa, t, fmin, cap)
    n, r2, level = _poles(b, ic, qs, lams, pa, s, pp, undamped, _level(sl, pubs, s))
    used = np.zeros(n, dtype=np.int64)
    for k in range(KMAX):
        if sl[k, SL_ACTIVE] == 0.0:
            continue
        best = -1
        # an unpublished mode claims the poles it would reject as unresolved
        tol = DUPLICATE_TOL if sl[k, SL_EST] == 0.0 else MATCH_TOL
        for i in range(n):
            if (
                not used[i]
                and abs(pp[i, 0] / sl[k, SL_F] - 1.0) < tol
                and (
                    best < 0
                    or abs(pp[i, 0] / sl[k, SL_F] - 1.0) < abs(pp[best, 0] / sl[k, SL_F] - 1.0)
                )
            ):
                best = i
        if best < 0:
            continue
        used[best] = 1
        sl[k, SL_SEEN] = t
        f = pp[best, 0]
        owner, long, fast = pubs[k, 0], pubs[k, 1], pubs[k, 2]
        if s == long:
            sl[k, SL_REF] = f
            sl[k, SL_LEVEL] = level
        elif s == fast and sl[k, SL_REF] > 0.0:
            # the fast scale's deviation from the reference: a running mean over DEV_N
            sl[k, SL_DEV] += ((f / sl[k, SL_REF] - 1.0) ** 2 - sl[k, SL_DEV]) / min(
                sl[k, SL_NDEV] + 1.0, DEV_N
            )
            sl[k, SL_NDEV] += 1.0
        if owner != s:
            continue
        prev = sl[k, SL_PREV]
        sl[k, SL_PREV] = f
        sl[k, SL_F] = f
        sl[k, SL_AMP] = pp[best, 1]
        if not r2 >= pa[PA_MINFIT]:
            sl[k, SL_FIT] += 1
        elif _harmonic(f, pp[best, 1], math.inf, pp, n, sl):  # found: no suspect (docstring)
            sl[k, SL_HARM] += 1
        elif not abs(f / prev - 1.0) < (
            CONSISTENCY if sl[k, SL_FIRST] < math.inf else _first_tol(undamped, pp, n, best)
        ):
            sl[k, SL_INCONS] += 1
        else:
            _publish(b, ic, sl, k, s, t, pp, best, r2, out)
    _candidates(b, ic, sl, pd, pa, pp, n, used, t, s, r2, undamped, out)
    ic[I_BUSY : I_BUSY + NS] = 0
    fmin, cap = _cap(sl)
    for k in range(KMAX):
        if sl[k, SL_ACTIVE] != 0.0 and (
            (t - sl[k, SL_SEEN]) * sl[k, SL_F] > LOSE_PERIODS
            or (sl[k, SL_EST] == 1.0 and (t - sl[k, SL_LAST_T]) * sl[k, SL_F] > LOSE_PERIODS)
            or _unresolved(b, sl, pa, pp, n, k, s, t)
        ):
            _remove(ic, sl, k)
        elif sl[k, SL_ACTIVE] != 0.0:
            for o in _owner(b, sl, k, t, fmin, _mode_cap(sl, k, cap)):
                if o >= 0:
                    ic[I_BUSY + o] = 1
            o = _publisher(b, sl, pa, k, t, fmin, cap)[2]
            if o >= 0:
                ic[I_BUSY + o] = 1


# ---- input, one sample, a run of samples --------------------------------------------------
@jit
def _input_ok(b, ic, pa, t, y):
    """Count the sample as the estimator does; 1 = it advances the levels, 2 = it restarts them."""
    ic[I_RECEIVED] += 1
    if not (math.isfinite(t) and math.isfinite(y)):
        ic[I_NONFINITE] += 1
        return 0
    if ic[I_N] == 0:
        return 2
    h = t - b[B_TLAST]
    if h == 0.0:
        ic[I_DUPLICATE] += 1
        return 0
    if h < 0.0 and -h <= pa[PA_MAXGAP]:
        ic[I_OUT_OF_ORDER] += 1
        return 0
    if h < 0.0:
        ic[I_TIME_JUMP] += 1
        return 2
    if h > pa[PA_MAXGAP]:
        ic[I_GAP] += 1
        return 2
    if ic[I_NDT] < N_STEP:
        b[B_HBUF + ic[I_NDT]] = h
        ic[I_NDT] += 1
    return 1


@jit
def _wake(b, ic, y):
    """The energy of the input's blocks of WAKE_BLOCK samples against a reference (the largest
    block's, fading by WAKE_FADE per block, so that the blocks of a slow sine, a fraction of its
    period, do not count): a block WAKE_RATIO times above it (a mode excited) makes every scale
    fast for the next WAKE_N samples."""
    b[B_E] += y * y
    ic[I_WAKE] = max(ic[I_WAKE] - 1, 0)
    if ic[I_LEV] % WAKE_BLOCK == 0:
        if b[B_E] > WAKE_RATIO * b[B_E + 1]:
            ic[I_WAKE] = WAKE_N
        b[B_E + 1] = max(b[B_E + 1] * WAKE_FADE, b[B_E])
        b[B_E] = 0.0


@jit(inline='always')
def _feed(b, ic, sl, pd, qs, lams, pa, t, y, out):
    """One (possibly interpolated) sample through the levels and the analyses it completes."""
    top = _levels_step(b, ic, y)
    _wake(b, ic, y)
    fast = ic[I_NPEND] > 0 or ic[I_WAKE] > 0
    for d in range(top + 1):
        n = ic[I_LEV + d]
        for half in range(2):
            hop = HOP if fast or ic[I_BUSY + 2 * d + half] else HOP_IDLE if d > 0 else HOP_TOP
            if n >= (M_A, M_B)[half] and (n + half * (HOP // 2)) % hop == 0:
                first = ic[I_NOUT]
                _analysis(b, ic, sl, pd, qs, lams, pa, 2 * d + half, t, out)
                _number(sl, out, first, ic[I_NOUT])


@jit(inline='always')
def _step(b, ic, sl, pd, qs, lams, pa, t, y, out):
    """One input sample (counted; restarting the levels, or resampled onto the uniform grid by
    linear interpolation); estimates into out."""
    kind = _input_ok(b, ic, pa, t, y)
    if kind == 0:
        return
    ic[I_USED] += 1
    if kind == 2:
        ic[I_NDT] = 0
    elif ic[I_NDT] == N_STEP and b[B_DT] == 0.0:
        # the grid: the median of the first intervals (N_STEP, odd) as its step, from this
        # sample on (an insertion sort: np.median's costs more to compile than this runs)
        h = b[B_HBUF : B_HBUF + N_STEP]
        b[B_DT] = h[descending(h)[N_STEP // 2]]
        _levels_settle(b, ic, y)
        b[B_TG] = t
        _feed(b, ic, sl, pd, qs, lams, pa, t, y, out)
    elif b[B_DT] > 0.0:
        h = b[B_DT]
        if (t - b[B_TG]) / h > MAX_FILL:
            _levels_settle(b, ic, y)
            b[B_TG] = t - h
        t0 = b[B_TLAST]
        while b[B_TG] + h <= t + 1e-9 * h:
            tg = b[B_TG] + h
            b[B_TG] = tg
            _feed(
                b, ic, sl, pd, qs, lams, pa, tg, b[B_Y] + (y - b[B_Y]) * (tg - t0) / (t - t0), out
            )
    b[B_TLAST] = t
    b[B_Y] = y
    ic[I_N] += 1
    if kind == 2:
        b[B_DT] = 0.0


#: rows one sample can publish at most (a bridged gap of MAX_FILL steps completes fewer than
#: NS + 2 MAX_FILL analyses, each publishing at most KMAX modes)
ROOM = KMAX * (NS + 2 * MAX_FILL)
# ---- the float state in one array (one argument per call: numba's dispatch costs per argument)
F_SL = N_B
F_PD = F_SL + KMAX * N_SL
F_LAM = F_PD + NPEND * 3
F_PA = F_LAM + NS * 3 * PCOL  # per scale: eigenvalues, poles (re, im) of its last analysis
N_F = F_PA + 8


@jit
def _unpack(fs):
    """The views b, sl, pd, lams, pa of the float state."""
    return (
        fs[:N_B],
        fs[F_SL:F_PD].reshape((KMAX, N_SL)),
        fs[F_PD:F_LAM].reshape((NPEND, 3)),
        fs[F_LAM:F_PA].reshape((NS, 3, PCOL)),
        fs[F_PA:N_F],
    )


@jit
def _run(fs, ic, qs, t, y, out, start):
    """Feed t[start:] until out may not hold another sample's estimates; returns the next index
    to feed (the batch path, and the streaming one over one sample: one compiled entry point).
    The arrays are used through :func:`core.jit.borrowed` views (no reference counting per
    sample)."""
    fs, ic, qs, t, y, out = (
        borrowed(fs),
        borrowed(ic),
        borrowed(qs),
        borrowed(t),
        borrowed(y),
        borrowed(out),
    )
    b, sl, pd, lams, pa = _unpack(fs)
    ic[I_NOUT] = 0
    i = start
    while i < len(t) and ic[I_NOUT] + ROOM <= len(out):
        _step(b, ic, sl, pd, qs, lams, pa, t[i], y[i], out)
        i += 1
    return i


@dataclass(frozen=True)
class ModeStatus:
    """What the tracker knows of one mode now."""

    mode: int
    frequency_hz: float  # last published frequency (NaN before the first)
    last_t: float  # stamp of that estimate (NaN before the first)
    band_hz: tuple  # the frequencies whose poles are this mode's


class ModeTracker(Estimator):
    """Find and track up to ``config.modes`` modes; see the module docstring.

    ``fast`` False: no fast scale (each mode publishes from its long window: the joint free
    estimator's events, whose joint fits over a fast scale's window of under a period scatter).
    ``interpret``: run this module's functions uncompiled (:func:`core.jit.interpreted`) until
    :meth:`compiled`: estimates at once while they compile, about 0.1 ms a sample (1 ms while
    the scales are fast after an excitation). Not the compiled floats exactly: the subspace fit's
    sums are reassociated when compiled (``subspace.FAST``), so the two differ by ~1e-9 relative,
    as the compiled tracker does from one CPU to another (test/core/test_kernel_reference.py).
    """

    _module = sys.modules[__name__]  # (:attr:`~.estimator.Estimator._k`)

    def __init__(self, config: EstimatorConfig, fast: bool = True, interpret: bool = False):
        config.validate()
        self.interpreted = interpret
        if config.modes < 1:
            raise ValueError('ModeTracker needs modes >= 1 (FrequencyEstimator for modes = 0)')
        self._config = config
        self._fs = np.zeros(N_F)
        self._b, self._sl, self._pd, self._lams, pa = python_of(_unpack)(self._fs)
        self._ic = np.zeros(N_I, dtype=np.int64)
        self._qs = np.zeros((NS, NQ, PCOL))
        band = config.band_hz or (0.0, math.inf)
        # subspace columns: a pair per mode, an offset, a noise column (at least 6, at most PCOL)
        self._npc = min(max(2 * config.modes + 2, 6), M_A // 3 + 1 - 3)
        pa[:] = (
            config.max_gap,
            config.modes,
            band[0],
            band[1],
            config.max_damping,
            config.min_fit,
            self._npc,
            float(fast),
        )
        self._out = np.empty((ROOM, N_O))
        self._t1 = np.zeros(1)  # the streaming path's sample, fed to the batch kernel
        self._y1 = np.zeros(1)
        self._k._levels_init(self._b)
        self.restart()

    def kernels_available(self) -> bool:
        """Whether the compiled batch step is in memory or numba's cache
        (:func:`core.jit.available`: running it compiles nothing)."""
        return available(_run, (self._fs, self._ic, self._qs, self._t1, self._y1, self._out, 0))

    # ---- streaming and batch ---------------------------------------------------------------
    def update(self, t: float, y: float) -> List[Estimate]:
        """Feed one sample; return the estimates published at it (ascending mode)."""
        self._t1[0] = t
        self._y1[0] = y
        self._k._run(self._fs, self._ic, self._qs, self._t1, self._y1, self._out, 0)
        n = self._ic[I_NOUT]
        if n == 0:
            return []
        rows = self._out[:n]
        return [Estimate.of_row(row) for row in rows[np.lexsort((rows[:, O_MODE], rows[:, O_T]))]]

    def process(self, t: Sequence[float], y: Sequence[float]) -> EstimateArrays:
        """Feed arrays of samples (continuing the stream); the estimates as columns, by time."""
        t, y = as_series(t, y)
        out = np.empty((max(ROOM, min(len(t), BLOCK) * KMAX // 4), N_O))
        parts = []
        i = 0
        while i < len(t):
            i = self._k._run(self._fs, self._ic, self._qs, t, y, out, i)
            parts.append(out[: self._ic[I_NOUT]].copy())
        rows = np.concatenate(parts) if parts else np.empty((0, N_O))
        return EstimateArrays.from_rows(rows[np.lexsort((rows[:, O_MODE], rows[:, O_T]))])

    # ---- what it knows -----------------------------------------------------------------------
    def _active(self) -> List[int]:
        """The slots of the modes that have published, by ascending frequency."""
        sl = self._sl
        return sorted(
            (k for k in range(KMAX) if sl[k, SL_ACTIVE] and sl[k, SL_FIRST] < math.inf),
            key=lambda k: sl[k, SL_F],
        )

    @property
    def counters(self) -> Dict[str, int]:
        """The input counters, the modes' publishing rule summed over the modes (lost ones
        included) and the finder's counters."""
        total = dict.fromkeys(COUNTER_NAMES, 0)
        for j, (name, col) in enumerate(MODE_COUNTERS.items()):
            live = int(np.sum(self._sl[:, col] * (self._sl[:, SL_ACTIVE] != 0)))
            total[name] = live + int(self._ic[I_RET + j])
        for name, i in {**STAGE_COUNTERS, **FINDER_COUNTERS}.items():
            total[name] = total.get(name, 0) + int(self._ic[i])
        return total

    def mode_counters(self) -> Dict[int, Dict[str, int]]:
        """Each current mode's counters (its publishing rule)."""
        return {
            mode: {name: int(self._sl[k, col]) for name, col in MODE_COUNTERS.items()}
            for mode, k in enumerate(self._active(), 1)
        }

    def status(self) -> List[ModeStatus]:
        """The tracked modes that have published, ascending."""
        out = []
        for mode, k in enumerate(self._active(), 1):
            f = float(self._sl[k, SL_F])
            out.append(
                ModeStatus(
                    mode,
                    float(self._sl[k, SL_LAST_F]),
                    float(self._sl[k, SL_LAST_T]),
                    (f / (1 + MATCH_TOL), f * (1 + MATCH_TOL)),
                )
            )
        return out

    def reset(self) -> None:
        """Start a new estimation segment of every mode at the last sample: each publishes again
        from windows that begin after it."""
        self._sl[:, SL_START] = np.maximum(self._sl[:, SL_START], self._b[B_TLAST])

    def restart(self) -> None:
        """Forget the signal entirely (levels, modes, candidates); counters are kept."""
        for k in range(KMAX):
            if self._sl[k, SL_ACTIVE]:
                self._k._remove(self._ic, self._sl, k)
                self._ic[I_LOST] -= 1
        keep = {
            i: self._ic[i]
            for i in (*STAGE_COUNTERS.values(), *FINDER_COUNTERS.values(), *range(I_RET, N_I))
        }
        self._ic[:] = 0
        for i, v in keep.items():
            self._ic[i] = v
        self._sl[:] = 0.0
        self._pd[:] = 0.0
        self._b[B_RING:] = 0.0
        self._k._levels_settle(self._b, self._ic, 0.0)
        for s in range(NS):
            m = M_A if s % 2 == 0 else M_B
            self._k.init_subspace(self._qs[s, : m // 3 + 1, : self._npc])
        self._lams[:, 0] = 0.0
        self._lams[:, 1:] = math.nan
