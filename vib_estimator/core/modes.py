"""Several modes at once (``modes`` >= 1): find up to K modes and track each with its own estimator.

Interface:

* ``create_estimator(config)`` -- a :class:`FrequencyEstimator` when ``config.modes == 0``, else a
  :class:`ModeTracker`.
* ``ModeTracker.update(t, y) -> List[Estimate]`` (each with ``mode`` >= 1, 1 = the lowest
  frequency), ``process(t, y) -> EstimateArrays`` (with the ``mode`` column, sorted by time),
  ``counters`` (aggregate, the names of ``COUNTER_NAMES`` plus the mode finder's own),
  ``mode_counters() -> Dict[int, Dict[str, int]]``, ``status() -> List[ModeStatus]``, ``reset()``,
  ``restart()``, ``config``.

How the modes are found (no frequency from the user):

* **Spectral stage** (compiled, one call per sample): a constant-Q bank of ``NC`` = 48 channels, 6
  per octave from fs/6 down to fs/1536, each two cascaded resonators (Q = 5 each: -18 dB at 30 %,
  -40 dB at 2.3x from the centre) followed by an energy average over one period of its centre
  frequency. The bank is multi-rate (each octave runs on a stream decimated by 2 behind a
  4th-order Butterworth anti-alias filter) and works in cycles per sample, converted to Hz with
  the measured mean sampling interval; gaps are bridged by interpolation. Every 16 samples the
  levels (energy / centre frequency: flat for white noise) are analysed.
* **Noise-floor rule** for a peak (a channel above its two neighbours each side): its level must
  be ``KEEP_DB`` (a mode stays) or ``DETECT_DB`` (a new mode) above the highest of the global
  floor (10th percentile of the levels), the local floor (the lower of the median levels 2-4x
  below and 2-4x above it: coloured noise) and ``DYNAMIC_RANGE_DB`` below the strongest channel.
  Peaks that dip less than ``PROMINENCE_DB`` towards a stronger one are its shoulders.
* **Tracker** (compiled, after each analysis): a mode takes the strongest peak inside its band
  (its centre follows it); a peak no mode explains is a candidate, confirmed as a new mode once it
  has persisted ``CONFIRM_PERIODS`` of its period, unless it is a harmonic (within
  ``HARMONIC_TOL`` of 2..5 times a peak ``HARMONIC_RATIO`` stronger: ``rejected_harmonic``) or
  wider than one mode's peak (the channels 2 away not ``SINGLE_DB`` below:
  ``rejected_unresolved``); candidates that vanish before are ``rejected_noise``. A mode without a
  peak for ``LOSE_PERIODS`` of its period is lost (``modes_lost``) and stops publishing; with K
  modes tracked a new one replaces the weakest only if 6 dB stronger. Bands: [f/1.5, 1.5 f]
  narrowed to the geometric means with the neighbours; re-placed (``band_replacements``, same
  mode identity) when the centre comes within ``REPLACE_MARGIN`` of an edge or a wanted edge moves
  by more than ``REPLACE_CHANGE``. Each mode's stream has notches at the other modes' centres.
* **Estimators**: each mode has a :class:`FrequencyEstimator` of the configured model on its band
  (``config.replace(modes=0, band_hz=band)``), warmed up on the last period of raw samples when
  (re)placed. Python only acts when the set of modes or a band changes (an event of the stage).
* **Quality rule for an estimate** (after its estimator's own gate): it is published only if it
  lies ``EDGE_MARGIN`` inside its band's edges (``rejected_band_edge``), is not within 1 % of 2..5
  times a stronger mode's last estimate (``rejected_harmonic``), is within ``CONSISTENCY`` of its
  estimator's previous estimate (``rejected_inconsistent``), within ``CENTRE_TOL`` of the centre of
  its mode's peak in the bank (``rejected_off_peak``) and the mode's peak is single
  (``rejected_unresolved``). Modes are numbered by ascending frequency among the modes that have
  published, from their first published estimate on.

Streaming and batch give the same floats: the batch path runs the compiled stage until the next
tick, then each mode's estimator's own batch path over that stretch, then the same tick.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Dict, List, Optional, Sequence, Union

import numpy as np
from numba import njit

from .config import EstimatorConfig
from .estimator import COUNTER_NAMES, Estimate, EstimateArrays, FrequencyEstimator, as_series
from .kernel import BAND_DAMPING, NH, _advance, _discretise

KMAX = 8                 # most modes a tracker follows (the range of ``modes``)
NPO = 6                  # bank channels per octave
NOCT = 8                 # octaves: fs/6 down to fs/1536
NC = NPO * NOCT
BANK_TOP = 1.0 / 6.0     # highest channel, cycles per sample
BANK_Q = 5.0             # quality factor of each of a channel's two resonators
DEC_CUTOFF = 0.12        # anti-alias low-pass before each decimation by 2, cycles per sample
ANALYSIS_EVERY = 16      # samples between two analyses of the bank
FLOOR_PERCENTILE = 0.1   # noise floor: this quantile of the ready channels' levels
READY_PERIODS = 2.0      # a channel joins the analysis once its resonators have rung this long
MIN_READY = 12           # channels needed for a floor
KEEP_DB = 8.0            # a peak this far above the floor keeps a mode alive
DETECT_DB = 15.0         # ... and this far above it may become a new mode
DYNAMIC_RANGE_DB = 40.0  # ... and no more than this below the strongest channel
SINGLE_DB = 6.0          # a single mode's peak: the channels 2 away on both sides this far below
SINGLE_HYSTERESIS = 1.0  # ... a mode's peak stays single until it is this much wider
PROMINENCE_DB = 3.0      # dip needed between a peak and a stronger one
HARMONIC_TOL = 0.02      # relative distance of a peak to n f of a stronger peak (n = 2..5)
HARMONIC_TOL_EST = 0.01  # same for an estimate against a stronger mode's last estimate
MAX_HARMONIC = 5
HARMONIC_RATIO = 4.0     # a harmonic is at least this much weaker (energy) than its parent
DUPLICATE_TOL = 0.1      # two modes closer than this are one
PENDING_TOL = 0.25       # a candidate is the same peak from one analysis to the next within this
BAND_RATIO = 1.5         # widest band of a mode: [f / 1.5, 1.5 f]
MAX_BAND_NU = 0.4        # highest band edge, cycles per sample
EDGE_MARGIN = 1.05       # estimates must lie this factor inside the band's edges
CONSISTENCY = 0.01       # ... and within this of the mode's previous estimate
REPLACE_MARGIN = 1.15    # a centre this close to an edge re-places the band
REPLACE_CHANGE = 0.15    # ... and so does a wanted edge this far (log) from the placed one
CONFIRM_PERIODS = 0.5
LOSE_PERIODS = 1.5
CENTRE_GAIN = 0.25       # a mode's centre follows its peak with this gain per analysis
CENTRE_EVENT = 0.02      # ... and is handed to the estimates' rule when it moved this much
CENTRE_TOL = 0.05        # an estimate must lie this close to its mode's centre
NOTCH_Q = 2.0
NOTCH_REDESIGN = 0.005   # a notch is redesigned when its frequency moved this much
PMAX = 16                # peaks kept per analysis
HIST = 4096              # raw samples kept to warm a new estimator up
WARM_PERIODS = 1.0
GAP_STEPS = 1.5          # an interval this many mean intervals long is a gap for the bank ...
MAX_FILL = 64            # ... bridged by at most this many interpolated steps

# ---- stage layout: float array b ----------------------------------------------------------------
CH_N = 18                # per channel: Phi G0 G1 (8), x1 (2), u1, x2 (2), u2, energy, alpha,
                         # gain, nu
CH_X1, CH_U1, CH_X2, CH_U2, CH_E, CH_ALPHA, CH_GAIN, CH_NU = 8, 10, 11, 13, 14, 15, 16, 17
DEC_N = 22               # per decimator: two sections' Phi G0 G1 (16), states (2 + 2), inputs (2)
B_CH = 0
B_DEC = B_CH + CH_N * NC
B_LEVEL = B_DEC + DEC_N * NOCT   # NC levels of the last analysis (energy / frequency)
B_PEAK = B_LEVEL + NC            # PMAX x 3: frequency (cycles/sample), dB above floor, energy
B_NARROW = B_PEAK + 3 * PMAX    # PMAX: dB of the peak above the channels 2 away (``SINGLE_DB``)
B_TLAST = B_NARROW + PMAX
B_DT = B_TLAST + 1               # mean sampling interval, s
B_FLOOR = B_DT + 1
B_TAN = B_FLOOR + 1              # time of the last analysis
B_Y = B_TAN + 1                  # last accepted input
B_HT = B_Y + 1                   # ring of the last HIST times
B_HY = B_HT + HIST               # ... and values
N_B = B_HY + HIST
# ---- int array ic -------------------------------------------------------------------------------
(I_N, I_NB, I_NDT, I_NPEAK, I_NAN, I_EVENT, I_NPEND, I_UID, I_RECEIVED, I_USED, I_NONFINITE,
 I_DUPLICATE, I_OUT_OF_ORDER, I_TIME_JUMP, I_GAP, I_FOUND, I_LOST, I_REJ_HARM, I_REJ_NOISE,
 I_REPLACED, I_REJ_UNRES) = range(21)
N_I = 21
#: input counters of the stage, named as the estimator's
STAGE_COUNTERS = {'received': I_RECEIVED, 'used': I_USED, 'skipped_non_finite': I_NONFINITE,
                  'skipped_duplicate': I_DUPLICATE, 'skipped_out_of_order': I_OUT_OF_ORDER,
                  'time_jump_resets': I_TIME_JUMP, 'gap_resets': I_GAP}
#: the finder's counters kept by the stage
FINDER_COUNTERS = {'modes_found': I_FOUND, 'modes_lost': I_LOST, 'rejected_harmonic': I_REJ_HARM,
                   'rejected_noise': I_REJ_NOISE, 'band_replacements': I_REPLACED,
                   'rejected_unresolved': I_REJ_UNRES}
# ---- modes sl[k]: active, identity, centre (Hz), energy, seconds without a peak, placed band ----
SL_ACTIVE, SL_UID, SL_F, SL_E, SL_MISS, SL_LO, SL_HI, SL_SINGLE, SL_FSYNC = range(9)
N_SL = 9
# ---- candidates pd[i]: frequency (Hz), age (s), rejected as a harmonic ---------------------------
PD_F, PD_AGE, PD_REJ = range(3)
# ---- parameters pa ------------------------------------------------------------------------------
PA_MAXGAP, PA_K, PA_BLO, PA_BHI = range(4)
# ---- notch sections nt[k, j] (mode k's notch at mode j): Phi G0 G1 (8), x (2), u, gain, nu, on --
NT_X, NT_U, NT_GAIN, NT_NU, NT_ON = 8, 10, 11, 12, 13
NSEC = 14
BLOCK = 1 << 16          # samples per block of the batch path


@njit(cache=True)
def _bank_init(b):
    """Discretise the channels (two resonators each, in their octave's samples) and decimators."""
    z = 0.5 / BANK_Q
    for c in range(NC):
        o = B_CH + CH_N * c
        nu = BANK_TOP * 2.0 ** (-(c % NPO) / NPO)      # in the samples of its octave
        w = 2.0 * math.pi * nu
        _discretise(w, z, 1.0, b, o)
        b[o + CH_ALPHA] = 1.0 - math.exp(-nu)           # energy average over one period
        b[o + CH_GAIN] = 2.0 * z / w
        b[o + CH_NU] = nu * 2.0 ** (-(c // NPO))        # in input samples
    for k in range(2):
        for d in range(NOCT):
            _discretise(2.0 * math.pi * DEC_CUTOFF, BAND_DAMPING[k], 1.0, b,
                        B_DEC + DEC_N * d + 8 * k)


@njit(cache=True)
def _channel(b, o, u):
    """One sample u through a channel: two resonators 2 z w s / (s^2 + 2 z w s + w^2), energy."""
    _advance(b, o + CH_X1, o, b[o + CH_U1], u)
    b[o + CH_U1] = u
    v = b[o + CH_GAIN] * b[o + CH_X1 + 1]
    _advance(b, o + CH_X2, o, b[o + CH_U2], v)
    b[o + CH_U2] = v
    v = b[o + CH_GAIN] * b[o + CH_X2 + 1]
    b[o + CH_E] += b[o + CH_ALPHA] * (v * v - b[o + CH_E])


@njit(cache=True)
def _bank_step(b, n, y):
    """Input sample number n: the octaves whose (decimated) stream has a sample now."""
    u = y
    for d in range(NOCT):
        if d > 0:
            if n % (1 << (d - 1)) != 0:
                return
            # 4th-order Butterworth low-pass at DEC_CUTOFF of octave d-1's rate, then keep 1 in 2
            o = B_DEC + DEC_N * d
            _advance(b, o + 16, o, b[o + 20], u)
            b[o + 20] = u
            _advance(b, o + 18, o + 8, b[o + 21], b[o + 16])
            b[o + 21] = b[o + 16]
            if n % (1 << d) != 0:
                return
            u = b[o + 18]
        for c in range(NPO * d, NPO * (d + 1)):
            _channel(b, B_CH + CH_N * c, u)


@njit(cache=True)
def _bank_settle(b, y):
    """Every state at rest for a constant input y (a band-pass passes nothing of it)."""
    for c in range(NC):
        o = B_CH + CH_N * c
        b[o + CH_X1] = y
        b[o + CH_X1 + 1] = 0.0
        b[o + CH_U1] = y
        b[o + CH_X2:o + CH_U2 + 1] = 0.0
    for d in range(NOCT):
        o = B_DEC + DEC_N * d
        b[o + 16:o + 22] = y
        b[o + 17] = 0.0
        b[o + 19] = 0.0


@njit(cache=True)
def _analyse(b, ic):
    """Noise floor and peaks of the bank (see the module docstring).

    Levels are energy / frequency (flat for white noise), each channel's energy average corrected
    for its start (divided by 1 - (1 - alpha)^n); the floor and the peaks are taken over the
    channels that have rung ``READY_PERIODS`` periods.
    """
    ready = 0
    for c in range(NC):
        o = B_CH + CH_N * c
        periods = ic[I_NB] * b[o + CH_NU]
        e = b[o + CH_E]
        if periods < 40.0:
            n = (ic[I_NB] >> (c // NPO)) + 1
            e /= 1.0 - math.exp(n * math.log(1.0 - b[o + CH_ALPHA]))
        b[B_LEVEL + c] = max(e, 1e-300) / b[o + CH_NU]
        if periods >= READY_PERIODS:
            ready += 1
    ic[I_NPEAK] = 0
    if ready < MIN_READY:
        return
    floor = np.sort(b[B_LEVEL:B_LEVEL + ready])[int(FLOOR_PERCENTILE * ready)]
    b[B_FLOOR] = 10.0 * math.log10(floor)
    top = np.max(b[B_LEVEL:B_LEVEL + ready])
    npk = 0
    for c in range(2, ready - 2):
        lv = b[B_LEVEL + c]
        if not (lv > b[B_LEVEL + c - 1] and lv >= b[B_LEVEL + c + 1]
                and lv >= b[B_LEVEL + c - 2] and lv >= b[B_LEVEL + c + 2]) or npk >= PMAX:
            continue
        ref = max(_local_floor(b, c, ready, floor), top * 10.0 ** (-DYNAMIC_RANGE_DB / 10.0))
        if lv < ref * 10.0 ** (KEEP_DB / 10.0):
            continue
        lm = math.log10(b[B_LEVEL + c - 1])
        l0 = math.log10(lv)
        lp = math.log10(b[B_LEVEL + c + 1])
        den = lm - 2.0 * l0 + lp
        delta = 0.5 * (lm - lp) / den if den < 0.0 else 0.0
        o = B_PEAK + 3 * npk
        b[o] = BANK_TOP * 2.0 ** (-(c + delta) / NPO)
        b[o + 1] = 10.0 * (l0 - math.log10(ref))
        b[o + 2] = lv * b[B_CH + CH_N * c + CH_NU]
        b[B_NARROW + npk] = 10.0 * math.log10(lv / max(b[B_LEVEL + c - 2], b[B_LEVEL + c + 2]))
        npk += 1
    ic[I_NPEAK] = npk


@njit(cache=True)
def _local_floor(b, c, ready, floor):
    """The floor of coloured noise around channel c, beyond its own skirts: the lower of the median
    levels of the channels 6 to 12 away (a factor 2 to 4) below and above it (a side beyond the
    bank counts as the global floor), and never below the global floor."""
    out = math.inf
    vals = np.empty(7)
    for side in (-1, 1):
        n = 0
        for d in range(6, 13):
            cc = c + side * d
            if 0 <= cc < ready:
                vals[n] = b[B_LEVEL + cc]
                n += 1
        out = min(out, np.median(vals[:n]) if n > 0 else floor)
    return max(out, floor)


@njit(cache=True)
def _peaks(b, ic, pa, pf, pe, pdb, pn):
    """The analysis' peaks in Hz that are neither shoulders of a stronger peak (less than
    ``PROMINENCE_DB`` of dip between them) nor outside the searched band; returns their count."""
    rate = 1.0 / b[B_DT]
    n = 0
    for i in range(ic[I_NPEAK]):
        pi = B_PEAK + 3 * i
        ci = int(round(NPO * math.log2(BANK_TOP / b[pi])))
        li = b[B_LEVEL + ci]
        shoulder = False
        for j in range(ic[I_NPEAK]):
            cj = int(round(NPO * math.log2(BANK_TOP / b[B_PEAK + 3 * j])))
            if b[B_LEVEL + cj] > li:
                lo, hi = min(ci, cj), max(ci, cj)
                dip = 10.0 * math.log10(li / np.min(b[B_LEVEL + lo:B_LEVEL + hi + 1]))
                shoulder = shoulder or dip < PROMINENCE_DB
        f = b[pi] * rate
        if shoulder or f < pa[PA_BLO] or f > pa[PA_BHI] or b[pi] > MAX_BAND_NU:
            continue
        pf[n] = f
        pn[n] = b[B_NARROW + i]
        pdb[n] = b[pi + 1]
        pe[n] = b[pi + 2]
        n += 1
    return n


@njit(cache=True)
def _harmonic(f, e, fs, es, n, tol):
    """Whether f lies within tol of 2..MAX_HARMONIC times one of fs[:n] with ``HARMONIC_RATIO``
    times the energy e."""
    for i in range(n):
        if es[i] > HARMONIC_RATIO * e:
            m = round(f / fs[i])
            if 2 <= m <= MAX_HARMONIC and abs(f / (m * fs[i]) - 1.0) < tol:
                return True
    return False


@njit(cache=True)
def _remove(ic, sl, k):
    sl[k, SL_ACTIVE] = 0.0
    ic[I_LOST] += 1
    ic[I_EVENT] = 1


@njit(cache=True)
def _follow(ic, sl, pf, pe, pn, npk, used, dt):
    """Each mode takes the strongest free peak inside its band (and whether it is a single mode's
    peak: a change is an event); one without is lost after ``LOSE_PERIODS`` of its period."""
    for k in range(KMAX):
        if sl[k, SL_ACTIVE] == 0.0:
            continue
        best = -1
        for i in range(npk):
            if used[i] == 0 and sl[k, SL_LO] <= pf[i] <= sl[k, SL_HI] and \
                    (best < 0 or pe[i] > pe[best]):
                best = i
        if best < 0:
            sl[k, SL_MISS] += dt
            if sl[k, SL_MISS] * sl[k, SL_F] > LOSE_PERIODS:
                _remove(ic, sl, k)
            continue
        used[best] = 1
        sl[k, SL_MISS] = 0.0
        sl[k, SL_F] += CENTRE_GAIN * (pf[best] - sl[k, SL_F])
        sl[k, SL_E] = pe[best]
        if abs(sl[k, SL_F] / sl[k, SL_FSYNC] - 1.0) > CENTRE_EVENT:
            ic[I_EVENT] = 1         # the tracker's copy of the centre (``SL_FSYNC``) is refreshed
        single = pn[best] >= SINGLE_DB - (SINGLE_HYSTERESIS if sl[k, SL_SINGLE] else 0.0)
        if sl[k, SL_SINGLE] != single:
            sl[k, SL_SINGLE] = single
            ic[I_EVENT] = 1


@njit(cache=True)
def _admit(ic, sl, pa, f, e, single):
    """A new mode at f if there is room, or if it is 6 dB stronger than the weakest mode."""
    free = -1
    weakest = -1
    count = 0
    for k in range(KMAX):
        if sl[k, SL_ACTIVE] == 0.0:
            free = k if free < 0 else free
        else:
            count += 1
            weakest = k if weakest < 0 or sl[k, SL_E] < sl[weakest, SL_E] else weakest
    if count >= pa[PA_K]:
        if e < 4.0 * sl[weakest, SL_E]:
            return False
        _remove(ic, sl, weakest)
        free = weakest
    ic[I_UID] += 1
    sl[free, :] = 0.0
    sl[free, SL_ACTIVE] = 1.0
    sl[free, SL_UID] = ic[I_UID]
    sl[free, SL_F] = f
    sl[free, SL_E] = e
    sl[free, SL_SINGLE] = single
    ic[I_FOUND] += 1
    ic[I_EVENT] = 1
    return True


@njit(cache=True)
def _candidates(ic, sl, pd, pa, pf, pe, pdb, pn, npk, used, dt):
    """Peaks no mode explains: age them, confirm those that persisted ``CONFIRM_PERIODS``
    (unless harmonics, or wider than one mode's peak), count those that vanished before (noise)."""
    new = np.zeros((PMAX, 3))
    matched = np.zeros(PMAX, dtype=np.int64)
    nnew = 0
    for i in range(npk):
        if used[i] or pdb[i] < DETECT_DB:
            continue
        age = 0.0
        rej = 0.0
        for j in range(ic[I_NPEND]):
            if matched[j] == 0 and abs(pf[i] / pd[j, PD_F] - 1.0) < PENDING_TOL:
                matched[j] = 1
                age = pd[j, PD_AGE] + dt
                rej = pd[j, PD_REJ]
                break
        if age * pf[i] >= CONFIRM_PERIODS and rej == 0.0:
            if _harmonic(pf[i], pe[i], pf, pe, npk, HARMONIC_TOL):
                ic[I_REJ_HARM] += 1
                rej = 1.0
            elif pn[i] < SINGLE_DB:
                ic[I_REJ_UNRES] += 1
            elif _admit(ic, sl, pa, pf[i], pe[i], 1.0):
                continue
        new[nnew, PD_F] = pf[i]
        new[nnew, PD_AGE] = age
        new[nnew, PD_REJ] = rej
        nnew += 1
    for j in range(ic[I_NPEND]):
        if matched[j] == 0 and pd[j, PD_REJ] == 0.0:
            ic[I_REJ_NOISE] += 1
    pd[:, :] = new
    ic[I_NPEND] = nnew


@njit(cache=True)
def _neighbours(sl, k):
    """Centres of the nearest modes below and above mode k (0 and inf when none)."""
    below = 0.0
    above = math.inf
    f = sl[k, SL_F]
    for j in range(KMAX):
        if j != k and sl[j, SL_ACTIVE] != 0.0:
            g = sl[j, SL_F]
            if below < g <= f:
                below = g
            elif f < g < above:
                above = g
    return below, above


@njit(cache=True)
def _arrange(b, ic, sl, pa):
    """Drop modes that are harmonics or duplicates of stronger ones; (re)place the bands:
    [f / 1.5, 1.5 f] narrowed to the geometric means with the neighbours."""
    es = sl[:, SL_E] * sl[:, SL_ACTIVE]
    for k in range(KMAX):
        if sl[k, SL_ACTIVE] == 0.0:
            continue
        f = sl[k, SL_F]
        dup = False
        for j in range(KMAX):
            dup = dup or (j != k and es[j] > es[k] and abs(f / sl[j, SL_F] - 1) < DUPLICATE_TOL)
        if dup or _harmonic(f, es[k], sl[:, SL_F], es, KMAX, HARMONIC_TOL):
            _remove(ic, sl, k)
            es[k] = 0.0
    for k in range(KMAX):
        if sl[k, SL_ACTIVE] == 0.0:
            continue
        f = sl[k, SL_F]
        below, above = _neighbours(sl, k)
        lo = max(f / BAND_RATIO, math.sqrt(f * below), pa[PA_BLO])
        hi = min(f * BAND_RATIO, math.sqrt(f * above), pa[PA_BHI], MAX_BAND_NU / b[B_DT])
        if not lo < hi:
            _remove(ic, sl, k)
            continue
        placed = sl[k, SL_LO] > 0.0
        if placed and sl[k, SL_LO] * REPLACE_MARGIN <= f <= sl[k, SL_HI] / REPLACE_MARGIN and \
                abs(math.log(lo / sl[k, SL_LO])) <= REPLACE_CHANGE and \
                abs(math.log(hi / sl[k, SL_HI])) <= REPLACE_CHANGE:
            continue
        if placed:
            ic[I_REPLACED] += 1
        sl[k, SL_LO] = lo
        sl[k, SL_HI] = hi
        ic[I_EVENT] = 1


@njit(cache=True)
def _set_notches(b, sl, nt):
    """Mode k's notches at the other modes' centres (a new one starts at rest on the last input;
    one whose mode moved is redesigned, its state kept)."""
    z = 0.5 / NOTCH_Q
    for k in range(KMAX):
        for j in range(KMAX):
            sec = nt[k, j]
            if j == k or sl[k, SL_ACTIVE] == 0.0 or sl[j, SL_ACTIVE] == 0.0:
                sec[NT_ON] = 0.0
                continue
            nu = sl[j, SL_F] * b[B_DT]
            if sec[NT_ON] == 0.0:
                sec[NT_X] = b[B_Y]
                sec[NT_X + 1] = 0.0
                sec[NT_U] = b[B_Y]
            elif abs(nu / sec[NT_NU] - 1.0) <= NOTCH_REDESIGN:
                continue
            w = 2.0 * math.pi * nu
            _discretise(w, z, 1.0, sec, 0)
            sec[NT_GAIN] = 2.0 * z / w
            sec[NT_NU] = nu
            sec[NT_ON] = 1.0


@njit(cache=True)
def _track(b, ic, sl, pd, nt, pa, t):
    """The tracker, after each analysis: follow, find, arrange, notch (module docstring)."""
    dt = t - b[B_TAN] if ic[I_NAN] > 0 else 0.0
    b[B_TAN] = t
    ic[I_NAN] += 1
    if ic[I_NPEAK] == 0 and ic[I_NPEND] == 0 and not np.any(sl[:, SL_ACTIVE]):
        return
    pf = np.empty(PMAX)
    pe = np.empty(PMAX)
    pdb = np.empty(PMAX)
    pn = np.empty(PMAX)
    used = np.zeros(PMAX, dtype=np.int64)
    npk = _peaks(b, ic, pa, pf, pe, pdb, pn)
    _follow(ic, sl, pf, pe, pn, npk, used, dt)
    _candidates(ic, sl, pd, pa, pf, pe, pdb, pn, npk, used, dt)
    _arrange(b, ic, sl, pa)
    _set_notches(b, sl, nt)


@njit(cache=True)
def _notch(nt, k, y):
    """y through mode k's notches (s^2 + w^2) / (s^2 + 2 z w s + w^2) at the other modes."""
    u = y
    for j in range(KMAX):
        sec = nt[k, j]
        if sec[NT_ON] != 0.0:
            _advance(sec, NT_X, 0, sec[NT_U], u)
            sec[NT_U] = u
            u = u - sec[NT_GAIN] * sec[NT_X + 1]
    return u


@njit(cache=True)
def _input_ok(b, ic, pa, t, y):
    """Count the sample as the estimator does; 1 = it advances the bank, 2 = it restarts it."""
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
    # the bank's step: the mean interval (a running mean over the first 4096 intervals, then an
    # average of that length) of the intervals that are not gaps
    if ic[I_NDT] < 4 or h < GAP_STEPS * b[B_DT]:
        m = min(ic[I_NDT], 4095)
        b[B_DT] = (b[B_DT] * m + h) / (m + 1)
        ic[I_NDT] += 1
    return 1


@njit(cache=True)
def _stage_step(b, ic, sl, pd, nt, pa, t, y, out, col):
    """One sample through the bank and the modes' notches (``out[k, col]`` for mode k), the
    tracker every ``ANALYSIS_EVERY`` samples; returns 1 when the set of modes or a band changed."""
    kind = _input_ok(b, ic, pa, t, y)
    if kind == 0:
        for k in range(KMAX):
            out[k, col] = y          # the modes' estimators skip and count it too
        return 0
    ic[I_USED] += 1
    if kind == 2:
        _bank_settle(b, y)
        for k in range(KMAX):
            for j in range(KMAX):
                nt[k, j, NT_X] = y
                nt[k, j, NT_X + 1] = 0.0
                nt[k, j, NT_U] = y
    else:
        # a gap of m bank steps is bridged by linear interpolation (the bank assumes uniform steps)
        m = min(int(round((t - b[B_TLAST]) / b[B_DT])), MAX_FILL) if ic[I_NDT] >= 4 else 1
        for i in range(1, m):
            _bank_step(b, ic[I_NB], b[B_Y] + (y - b[B_Y]) * i / m)
            ic[I_NB] += 1
        _bank_step(b, ic[I_NB], y)
    ic[I_NB] += 1
    b[B_TLAST] = t
    b[B_Y] = y
    r = ic[I_N] % HIST
    b[B_HT + r] = t
    b[B_HY + r] = y
    ic[I_N] += 1
    for k in range(KMAX):
        if sl[k, SL_ACTIVE] != 0.0:
            out[k, col] = _notch(nt, k, y)
    if ic[I_N] % ANALYSIS_EVERY == 0 and ic[I_NDT] > 0:
        _analyse(b, ic)
        _track(b, ic, sl, pd, nt, pa, t)
    event = ic[I_EVENT]
    ic[I_EVENT] = 0
    return event


@njit(cache=True)
def _stage_run(b, ic, sl, pd, nt, pa, t, y, out, start, stop):
    """Feed t[start:stop] (out column = index - start) until the modes change.

    Returns (next index to feed, 1 if the modes changed at the last sample fed)."""
    i = start
    while i < stop:
        event = _stage_step(b, ic, sl, pd, nt, pa, t[i], y[i], out, i - start)
        i += 1
        if event:
            return i, 1
    return i, 0


@dataclass(frozen=True)
class ModeStatus:
    """What the tracker knows of one mode now."""

    mode: int
    frequency_hz: float       # last published frequency (NaN before the first)
    last_t: float             # stamp of that estimate (NaN before the first)
    band_hz: tuple            # the band its estimator runs on


class _Slot:
    """One tracked mode: its estimator, band and counters (its identity is ``uid``)."""

    def __init__(self, uid: int):
        self.uid = uid
        self.band = (math.nan, math.nan)
        self.est: Optional[FrequencyEstimator] = None
        self.counts: Dict[str, int] = {'estimates': 0, 'rejected_band_edge': 0,
                                       'rejected_harmonic': 0, 'rejected_inconsistent': 0,
                                       'rejected_unresolved': 0, 'rejected_off_peak': 0}
        self.centre = math.nan                   # the stage's centre of its peak (Hz)
        self.single = True                       # its peak is one mode's (else: not published)
        self.prev_f = math.nan                   # its estimator's previous estimate
        self.retired: Dict[str, int] = {}        # counters of its replaced estimators
        self.last = (math.nan, math.nan)          # last published (frequency, t)
        self.first_t = math.inf                   # stamp of its first published estimate
        self.stronger = np.empty(0)               # frequencies of stronger modes (harmonic rule)

    def published(self, f: float, t_first: float, t_last: Optional[float] = None) -> None:
        """Note published estimates: the last frequency, the stamps of the first and last."""
        self.first_t = min(self.first_t, t_first)
        self.last = (f, t_first if t_last is None else t_last)

    def frequency(self, centre: float) -> float:
        """Its last published frequency, else the stage's centre."""
        return centre if math.isnan(self.last[0]) else self.last[0]

    def counters(self) -> Dict[str, int]:
        out = _add(self.retired, self.est.counters if self.est is not None else {})
        out.update(self.counts)
        return out

    def gate(self, f: np.ndarray) -> np.ndarray:
        """Which of the estimates ``f`` the tracker publishes (the others are counted)."""
        lo, hi = self.band
        inside = (f >= lo * EDGE_MARGIN) & (f <= hi / EDGE_MARGIN)
        r = f[:, None] / self.stronger[None, :]
        n = np.round(r)
        harmonic = inside & np.any((n >= 2) & (n <= MAX_HARMONIC)
                                   & (np.abs(r / np.maximum(n, 1) - 1) < HARMONIC_TOL_EST), axis=1)
        prev = np.concatenate(([self.prev_f], f[:-1]))
        near = np.abs(f / self.centre - 1) < CENTRE_TOL
        keep = inside & ~harmonic & near & (np.abs(f / prev - 1) < CONSISTENCY) & self.single
        if not self.single:
            self.counts['rejected_unresolved'] += len(f)
        if len(f):
            self.prev_f = float(f[-1])
        self.counts['rejected_band_edge'] += int(np.count_nonzero(~inside))
        self.counts['rejected_harmonic'] += int(np.count_nonzero(harmonic))
        self.counts['rejected_off_peak'] += int(np.count_nonzero(inside & ~harmonic & ~near)) \
            if self.single else 0
        self.counts['rejected_inconsistent'] += int(np.count_nonzero(inside & ~harmonic & near
                                                                     & ~keep)) if self.single else 0
        self.counts['estimates'] += int(np.count_nonzero(keep))
        return keep


def _add(a: Dict[str, int], b: Dict[str, int]) -> Dict[str, int]:
    return {k: a.get(k, 0) + b.get(k, 0) for k in {**a, **b}}


class ModeTracker:
    """Find and track up to ``config.modes`` modes; see the module docstring."""

    def __init__(self, config: EstimatorConfig):
        config.validate()
        if config.modes < 1:
            raise ValueError('ModeTracker needs modes >= 1 (FrequencyEstimator for modes = 0)')
        self._config = config
        self._b = np.zeros(N_B)
        self._ic = np.zeros(N_I, dtype=np.int64)
        self._sl = np.zeros((KMAX, N_SL))
        self._pd = np.zeros((PMAX, 3))
        self._nt = np.zeros((KMAX, KMAX, NSEC))
        band = config.band_hz or (0.0, math.inf)
        self._pa = np.array([config.max_gap, config.modes, band[0], band[1]], dtype=np.float64)
        self._col = np.zeros((KMAX, 1))
        self._retired: Dict[str, int] = {}
        self._rejected = {'rejected_band_edge': 0, 'rejected_harmonic': 0}
        self._slots: Dict[int, _Slot] = {}      # by position in the stage's arrays
        self._order: List[tuple] = []            # (position, slot), ascending mode
        _bank_init(self._b)
        self.restart()

    @property
    def config(self) -> EstimatorConfig:
        return self._config

    # ---- streaming and batch ---------------------------------------------------------------
    def update(self, t: float, y: float) -> List[Estimate]:
        """Feed one sample; return the estimates published at it (ascending mode)."""
        t = float(t)
        event = _stage_step(self._b, self._ic, self._sl, self._pd, self._nt, self._pa, t,
                            float(y), self._col, 0)
        accepted = []
        for i, (k, slot) in enumerate(self._order):
            e = slot.est.update(t, self._col[k, 0])
            if e is not None and slot.gate(np.array([e.frequency_hz]))[0]:
                slot.published(e.frequency_hz, e.t)
                accepted.append((i, e))
        out = [replace(e, mode=int(self._label(i, e.t))) for i, e in accepted]
        if event:
            self._sync()
        return out

    def process(self, t: Sequence[float], y: Sequence[float]) -> EstimateArrays:
        """Feed arrays of samples (continuing the stream); the estimates as columns, by time."""
        t, y = as_series(t, y)
        out = np.empty((KMAX, min(BLOCK, len(t))))
        parts = []
        i = 0
        while i < len(t):
            j, event = _stage_run(self._b, self._ic, self._sl, self._pd, self._nt, self._pa,
                                  t, y, out, i, min(len(t), i + BLOCK))
            accepted = []
            for n, (k, slot) in enumerate(self._order):
                arrays = slot.est.process(t[i:j], out[k, :j - i])
                keep = slot.gate(arrays.frequency_hz)
                if np.any(keep):
                    slot.published(float(arrays.frequency_hz[keep][-1]), float(arrays.t[keep][0]),
                                   float(arrays.t[keep][-1]))
                    accepted.append((n, arrays, keep))
            parts += [_select(a, keep, self._label(n, a.t[keep])) for n, a, keep in accepted]
            if event:
                self._sync()
            i = j
        return EstimateArrays.concatenate(parts)

    def _label(self, n: int, t):
        """Mode number of the n-th lowest tracked mode's estimates at t: 1 + the lower modes that
        had published by then (a mode is numbered from its first published estimate on)."""
        return 1 + sum(np.asarray(s.first_t <= t, dtype=np.int64) for _, s in self._order[:n])

    # ---- what it knows -----------------------------------------------------------------------
    @property
    def counters(self) -> Dict[str, int]:
        """The stage's input counters, the modes' estimators' gates and the tracker's rule
        summed over the modes (lost ones included), the finder's own counters."""
        total = _add(dict.fromkeys(COUNTER_NAMES, 0), self._retired)
        for slot in self._slots.values():
            total = _add(total, slot.counters())
        for name, i in {**STAGE_COUNTERS, **FINDER_COUNTERS}.items():
            total[name] = int(self._ic[i])
        return total

    def _numbered(self) -> List[tuple]:
        """(mode number, slot) of the tracked modes that have published."""
        published = [s for _, s in self._order if s.first_t < math.inf]
        return list(enumerate(published, 1))

    def mode_counters(self) -> Dict[int, Dict[str, int]]:
        """Each current mode's counters (its estimators' and the tracker's rule)."""
        return {mode: slot.counters() for mode, slot in self._numbered()}

    def status(self) -> List[ModeStatus]:
        """The tracked modes that have published, ascending."""
        return [ModeStatus(mode, s.last[0], s.last[1], s.band) for mode, s in self._numbered()]

    def reset(self) -> None:
        """Start a new estimation segment of every mode at the last sample."""
        for _, slot in self._order:
            slot.est.reset()

    def restart(self) -> None:
        """Forget the signal entirely (bank, modes, history); counters are kept."""
        for slot in self._slots.values():
            self._retired = _add(self._retired, slot.counters())
        self._slots = {}
        self._order = []
        keep = {i: self._ic[i] for i in (*STAGE_COUNTERS.values(), *FINDER_COUNTERS.values())}
        self._ic[:] = 0
        for i, v in keep.items():
            self._ic[i] = v
        self._sl[:] = 0.0
        self._pd[:] = 0.0
        self._nt[:] = 0.0
        self._b[B_LEVEL:] = 0.0
        _bank_settle(self._b, 0.0)
        for c in range(NC):
            self._b[B_CH + CH_N * c + CH_E] = 0.0

    # ---- the modes' estimators ---------------------------------------------------------------
    def _sync(self) -> None:
        """After the stage changed the modes: new, lost and re-placed estimators, numbering."""
        for k in range(KMAX):
            slot = self._slots.get(k)
            uid = int(self._sl[k, SL_UID]) if self._sl[k, SL_ACTIVE] else 0
            if slot is not None and slot.uid != uid:
                self._retired = _add(self._retired, slot.counters())
                del self._slots[k]
                slot = None
            if uid and slot is None:
                slot = self._slots[k] = _Slot(uid)
            band = (float(self._sl[k, SL_LO]), float(self._sl[k, SL_HI]))
            if slot is not None and band != slot.band:
                self._place(slot, band)
        active = sorted(self._slots, key=lambda k: self._sl[k, SL_F])
        self._order = [(k, self._slots[k]) for k in active]
        for k, slot in self._order:
            slot.single = bool(self._sl[k, SL_SINGLE])
            slot.centre = self._sl[k, SL_FSYNC] = self._sl[k, SL_F]
            slot.stronger = np.array([self._slots[j].frequency(self._sl[j, SL_F]) for j in active
                                      if self._sl[j, SL_E] > HARMONIC_RATIO * self._sl[k, SL_E]])

    def _place(self, slot: _Slot, band: tuple) -> None:
        """(Re)place a mode's band: a new estimator, warmed up on the last raw samples so that its
        band filter has settled when its first segment starts."""
        if slot.est is not None:
            slot.retired = _add(slot.retired, slot.est.counters)
        slot.band = band
        slot.est = FrequencyEstimator(self._config.replace(modes=0, band_hz=band))
        n = int(self._ic[I_N])
        m = min(n, HIST, int(WARM_PERIODS / (band[0] * self._b[B_DT])) + 1)
        if m > NH:
            idx = np.arange(n - m, n) % HIST
            slot.est.process(self._b[B_HT + idx], self._b[B_HY + idx])
            slot.est.reset()
            # the warm-up is not the mode's: its counts are taken off again
            slot.retired = _add(slot.retired, {k: -v for k, v in slot.est.counters.items()})


def _select(arrays: EstimateArrays, keep: np.ndarray, mode) -> EstimateArrays:
    """The rows ``keep`` of ``arrays``, labelled ``mode`` (one number or one per kept row)."""
    cols = {n: getattr(arrays, n)[keep] for n in EstimateArrays.__dataclass_fields__}
    cols['mode'] = np.broadcast_to(np.asarray(mode, dtype=np.int64),
                                   (int(np.count_nonzero(keep)),)).copy()
    return EstimateArrays(**cols)


def create_estimator(config: EstimatorConfig) -> Union[FrequencyEstimator, ModeTracker]:
    """The estimator of a configuration: one estimator (``modes`` = 0) or a mode tracker."""
    return FrequencyEstimator(config) if config.modes == 0 else ModeTracker(config)
