# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""What a record needs, decided from the record itself: the default of ``vib-estimator analyze``
(no ``--excitation``, no ``--paper``), where the whole record is at hand (pure numpy/scipy).

A newcomer passes no option; a plucked beam, a machine driven without rest and a building under
wind each need another estimator and, when driven, a window sized to the structure. From the
first :data:`DECIDE_S` seconds of the record (all channels):

1. **The spectrum** (Welch, segments of :data:`SEGMENT_S` s): its peaks standing
   :data:`PEAK_DB` above their surroundings (prominence) and holding at least
   :data:`PEAK_SHARE` of the strongest one's power; the strongest is the **dominant** frequency,
   the lowest the **fundamental**.
2. **Free or driven**, by the envelope of :mod:`.auto` (:class:`.auto.Envelope`) over the record's
   first principal component (one channel: the signal), its block :data:`.auto.BLOCK_PERIODS`
   x :data:`.auto.BLOCK_MARGIN` periods of the dominant frequency (a 1 s block of a 0.8 Hz
   decay jitters by more than the envelope tests): the share of the record's energy in what it
   reads as driven (the envelope starts free and needs a few blocks to tell: a record driven
   throughout shows 80-98 %; the noise a decay rings down into weighs nothing).
   Below :data:`FREE_BELOW`: ``free`` (the algebraic estimator, exactly as ``--excitation free``);
   above :data:`DRIVEN_ABOVE`: ``ambient`` (output-only identification); between, one channel:
   ``auto`` (per stretch), several: the larger share's (the joint estimators take free or
   ambient).
3. **Several modes** in a free decay: peaks that are modes of their own (:func:`separate_modes`:
   holding :data:`MODE_SHARE` of the strongest's power, or weaker and ringing freely,
   :func:`rings_freely`) send it to the mode tracker (``modes`` :data:`TRACKED_MODES`), each
   mode numbered.
4. **The window** of a driven record: :data:`WINDOW_PERIODS` periods of the fundamental
   (about 15 correlation times ``1 / (2 pi zeta f)`` of a mode at zeta = 2 %: the frequency of a
   lightly damped mode scatters by more than 2 % across windows of a few correlation times, and
   the identifier drops it), at least the configured ``ambient_window_s`` and at most
   :data:`MAX_WINDOW_S`, and no longer than the record allows :data:`MIN_ANALYSES` analyses of;
   a record shorter than :data:`SHORT_WINDOWS` configured windows gets windows of that share of
   it.

5. **A periodic drive** (a move cycle, a machine's harmonics): spectral peaks whose band-passed
   response is a sinusoid of steady amplitude (kurtosis under :data:`LINE_KURTOSIS`, Brincker et
   al. 2000), at least :data:`PERIODIC_LINES` of them on the harmonics of one fundamental
   (:func:`drive_lines`), are lines, not modes: a record the envelope reads driven, or one with
   a peak apart from them, goes to the identifier with the drive's harmonics as ``lines_hz``
   (it drops its modes there) and a window sized from the lowest peak apart from the lines; the
   lines never count as a free decay's separate modes.

Each decision carries its reasons in words (:attr:`Decision.reason`), which ``analyze`` prints.

A stream cannot be seen ahead: :class:`DrivenWatch` keeps the same envelope over
``estimator_node``'s input and tells, over the last :data:`WATCH_S` s, when a free-decay
estimator is fed a response driven throughout (its ``/diagnostics`` then say so, and which
``excitation`` helps), or, for the node's own decision, driven now and in part of them.
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass, field, replace
from functools import cache
from typing import Optional

import numpy as np

from .ambient import LINE_TOL
from .auto import (
    BLOCK_MARGIN,
    BLOCK_PERIODS,
    DRIVEN,
    FREE,
    MIN_BLOCK_S,
    TEST_PERIODS,
    Envelope,
    decay_verdict,
    is_free_decay,
)
from .modes import MAX_FILL
from .ssi import NU_MAX

#: the first seconds of a record the decision reads
DECIDE_S = 600.0
#: samples stamped beyond this many seconds are not read (an absurd stamp)
MAX_STAMP_S = 1e12
#: ... nor values farther from the median than this many median absolute deviations (a pluck of
#: 1 in a long record of 1e-4 noise stands at ~1e4)
ABSURD = 1e6
#: stamps whose steps differ from their median by more than this share of it are irregular: the
#: decision reads the record resampled onto a uniform grid (:func:`regular`; a real beam recorded
#: at 4 kHz by a software clock, steps 0.19-0.25 ms and 19 gaps of 2-6 ms: read at its mean rate,
#: its 16.33 Hz decay showed 19 "peaks" from 6.3 to 30.6 Hz and its strongest at 16.13 Hz; on the
#: grid one peak, at 16.33 Hz)
JITTER = 0.01
#: Welch segment, s (0.05 Hz resolution: a 1.2 Hz building mode's peak stands apart)
SEGMENT_S = 20.0
#: a record whose Welch segment centred on its first sample (half a segment of rest, its mean,
#: before it) holds this many times the power of its segments' mean is read with that segment
#: (:func:`spectrum`): a decay ringing down in a small part of the record from its first sample,
#: which the first segment's taper (~1e-2 over its first 0.3 s) weighs as nothing. Such records
#: give 60-400 (a 50 Hz decay at zeta 1 % in 10-600 s at 40 dB: 400; 12 Hz at 5 % in 37 dB:
#: 110), the real beams (plucked 0.1-0.5 s in) 3.4-37, decays ringing through their record 1-45,
#: a stationary record 0.5. Read tapered, the noise's chance peaks beside the decay read as
#: "33 separate modes" (the mode tracker: a median of 2.4 periods), as a 214 Hz mode, or as no
#: peak at all; read so always, the 50 cm beam (3.4), whose brief 39 Hz second mode the taper
#: hides, went to the mode tracker (a median of 1.65 periods, not 0.90)
START_RATIO = 10.0
#: a spectral peak's prominence over its surroundings, dB
PEAK_DB = 10.0
#: ... and its power at least this share of the strongest peak's
PEAK_SHARE = 1e-3
#: ... and above what the spectrum's noise reaches by chance in one of its bins with this
#: probability (:func:`chance_level`)
CHANCE = 0.01
#: ... its floor the median of this many bins around (odd; 2.5 Hz either side at 0.05 Hz)
FLOOR_BINS = 101
#: a free decay's brief higher modes are looked for over this many periods of its dominant mode
#: from its largest sample (:func:`onset_peaks`) too
ONSET_PERIODS = 10.0
#: a record whose envelope reads driven for less than this share of its time is a free decay
FREE_BELOW = 0.1
#: ... and one read driven for more than this share is driven throughout (the envelope's first
#: blocks of a driven record read free: 80-98 % measured, a 1.2 Hz mode's 3 s blocks the least)
DRIVEN_ABOVE = 0.7
#: a free decay whose spectrum holds several separate modes (:func:`separate_modes`) goes to the
#: mode tracker with this many modes (on bench_modes' records, modes 3 has every mode within 2 %
#: from 0.7-2 periods, where the one estimator reports the strongest alone, or a mixture)
TRACKED_MODES = 3
#: ... a separate mode: a peak holding at least this share of the strongest's power (the
#: simulated arm's moves leave peaks of 1-3 %, a second mode at 30 % amplitude 4-16 %)
MODE_SHARE = 0.02
#: ... or a weaker peak that rings freely (:func:`rings_freely`): a spectral peak (above what
#: the noise reaches by chance: :func:`chance_level`; until 6 Dec 2026 also 25 dB above its
#: surroundings, which the noise's chance peaks no longer reach) ...
#: ... and its band-passed response decaying by at least this many dB from its most energetic
#: block (the 17.3 Hz mode: 16-19 dB over 10 s; the arm's moves' 2.3-2.4 Hz peaks, bursts at
#: each move: 2-5 dB; a line: none)
RING_DB = 10.0
#: ... at least this far (relative) from every stronger mode (the arm's three tip masses'
#: 1.33 / 1.56 Hz, 17 %, are one mode that moved)
MODE_GAP = 0.25
#: ... or closer, when it rings with the stronger one (:func:`coexistence` at least this: their
#: band-passed energies over time share this much): two modes 20-25 % apart plucked together
#: read 0.87-0.94 (a 10 Hz mode and a 12 or 12.5 Hz one at 1:0.2-0.8, 30 dB), whose beating the
#: one-mode estimator read as one frequency between them (at 1:0.8, 5-13 estimates, every one
#: > 3 % off, 4 seeds of 6; at 1:0.2-0.3, 32-80 % within 2 %; the mode tracker 80-100 %); a mode
#: that moved 0.01-0.04 (10 Hz, then 12 Hz plucked 10 s later), the arm's (bags/arm_5_5, whose
#: 18 s hold few of the narrow bands' time resolution) 0.73
COEXIST = 0.8
#: ... and not within this of a harmonic (2-7 x) of one, between the peaks' interpolated
#: frequencies (:func:`peak_frequencies`): a clipped decay's harmonics lie 0.001-0.12 % from n x
#: its mode (12, 5 and 1.3 Hz at 40 dB, clipped at 60 %), a second mode near an integer ratio --
#: 6.01 / 23.86, 4.00 / 15.86, 3.57 / 10.81, 21.07 / 63.92 Hz -- 0.76-1.8 % (until 7 Dec 2026
#: 2 % between the bins: read as harmonics, the decay as one mode, its first estimate 15 periods
#: late and its second mode lost)
HARMONIC_FINE = 0.004
#: a periodic drive's lines: within this of the harmonics of one fundamental, between the bins
#: (:func:`harmonic_series`)
HARMONIC_TOL = 0.02
#: a driven record's window, in periods of its fundamental (~15 correlation times at zeta 2 %)
WINDOW_PERIODS = 120.0
#: the longest window the decision chooses, s
MAX_WINDOW_S = 300.0
#: the free estimator reads the strongest of several modes (:func:`dominant_window`) in place
#: of the mode tracker only where its estimates lie this close (median relative deviation) to
#: the tracker's median of that mode: the real beams after rest 0.24 %, random 2-3-mode decays
#: whose others ring on beside it 0.17-0.28 % where it is right, 0.43-2.4 % where the others
#: bias its one-mode window (a 12.5 Hz mode beside 16.7 Hz at 1:0.13: 41 % within 2 %; the
#: tracker 100 %)
DOMINANT_AGREE = 0.003
#: a free decay of one mode whose spectrum is pure (:func:`fast_window`) is estimated over this
#: window (the long window, ``min_periods``) rather than the default 1.25 periods, where its
#: estimates are precise (:data:`FAST_STD`): the real beams 0.90-0.92 periods to an estimate,
#: 99-100 % within 2 % (bench_first_estimate.py)
FAST_PERIODS = 0.9
#: ... pure: at most this share of the power within :data:`IMPURITY_SPAN` of the mode lies
#: farther than :data:`PEAK_WIDTH` from it (:func:`impurity`: free decays 0.000-0.03, 0.066 in
#: 20 dB of noise; the real arm's closed-loop limit cycle 0.30, which a window of one period
#: reads 2 % high while its predicted std says 0.2 %; a record whose frequency moved,
#: bags/arm_5_5, 0.047: its 1.25-period fits across the moves fail where the shorter window's
#: estimates are held, 2 estimates in its last stretch against 3). In the segment centred on a
#: record's start (:data:`START_RATIO`) the decay's own spectrum is not counted
#: (:func:`decay_tails`: a decay seen from its abrupt start spreads 3.3 % of its power there at
#: zeta 1 %, 10 % at 3 %). A decay after rest spreads it too, and is not spared it: decays at
#: 2-8 % after 1 s of rest, read pure so, went from the mode tracker to the damped model over
#: 0.9 periods, with a third fewer estimates and the first later (bench_hard_records.py --heavy)
IMPURE = 0.04
#: ... the span around the mode (a factor each way: an octave) and the peak's half width
#: (relative)
IMPURITY_SPAN = 2.0
PEAK_WIDTH = 0.15
#: ... precise: an estimate over :data:`FAST_PERIODS` whose predicted relative frequency std
#: exceeds this waits for the default window (``early_std_rel``, core.kernel.HELD_PERIODS): 2 %
#: is then ~3 stds; a decay's tail in its noise (1.4-3.2 % at 0.9 periods in 20-30 dB) keeps the
#: default's accuracy there (bench_first_estimate.py: 95-100 % within 2 %; at 0.01 a 2 Hz decay
#: in 20 dB fell to 87 %)
FAST_STD = 0.007
#: ... and this (2 % at 2 stds) for a clean record, its signal-to-noise ratio (:func:`snr_db`) at
#: least :data:`CLEAN_SNR_DB`: lightly damped decays at 35-45 dB, 6 seeds each (5 Dec): 0.007
#: left the 35-40 dB ones at a median of 1.11-1.26 periods, 0.01 gives 0.90-1.04 at 93-99 %
#: within 2 % (mean 97-99 %)
FAST_STD_CLEAN = 0.01
CLEAN_SNR_DB = 33.0
#: ... and only for a decay no more damped than this (damping ratio, :func:`decay_zeta`): over
#: 0.9 periods a decay at 3 % falls by 16 %, which the biased sinusoid reads as a shift of the
#: frequency its std does not hold (a 5 Hz decay at 3 %, 40 dB: 44-100 % within 2 % against
#: 88-100 % over 1.25 periods; 10 Hz at 5 %: 43-100 % against 100 %; a 2 Hz decay at 2 %, 40 dB:
#: 85-88 % against 100 %, at 1.5 % 94-97 %, at 1.2 % 100 %: 3 seeds each). Such a decay, given
#: no fast window (its offset not known, or its peak impure), goes to the mode tracker
#: (:func:`heavily_damped`), whose subspace fits hold the decay in their model: the free
#: estimator's estimates of a decay that falls by a quarter a period are few, late and held back
#: by its fit gate. 2, 5 and 20 Hz decays after 1 s of rest, 30 and 45 dB, 2-4 seeds each
#: (``bench_hard_records.py --heavy``, 6 Dec): at 2 % the free estimator's first estimate came
#: after a median of 4.1 periods (86-100 % within 2 %), the tracker's after 1.4 (94-100 %); at 5 %
#: the free estimator gave nothing on 4 of 12 records, at 8 % on 11 of 12, the tracker 96-100 %
#: within 2 % on every one
FAST_ZETA = 0.015
#: the envelope blocks of :func:`decay_zeta`, in periods
DECAY_BLOCK_PERIODS = 2.0
#: a free decay of one mode sampled at fewer than this many samples a period of its dominant
#: mode goes to the mode tracker (``modes`` :data:`TRACKED_MODES`, :func:`few_samples`), whose
#: subspace fits need no integrals of the samples: the free estimator's convergence test (Eqs.
#: 16-17: estimates 3 samples apart within 0.1 %) rarely passes there, its algebraic estimate
#: swinging by 1-5 % from one sample to the next (its ratio's denominator crosses zero twice a
#: period). 10 Hz decays, zeta 0.2-5 %, 37 dB, 3 seeds each (``bench_first_estimate.py
#: --low-rate``, 6 Dec): the free estimator gave no estimate on 13, 10, 9 and 4 of 15 records at
#: 6, 8, 10 and 12 samples a period, 1 of 15 at 15; the tracker none, every record 100 % within
#: 2 %. A pluck after 1 s of rest (``--onset``): the free estimator none on 4 of 6 at 12 and 2 of 6
#: at 13 samples, the tracker 100 % within 2 % on all, its first estimate after 4.2-5.2 periods.
#: Its windows are 48 samples or more (3.4 periods at 14 samples), the free estimator's a period:
#: at 15 samples and more the free estimator keeps the decay
TRACKER_SAMPLES = 14.0
#: a free decay whose offset is known (:func:`known_offset`) is estimated with that offset removed
#: by the damped-sinusoid model, whose frequency holds the decay (no :data:`FAST_ZETA` limit) and,
#: with no offset to fit, is more precise over a short window: 6 seeds each (5 Dec), 0.9 periods,
#: ``early_std_rel`` 0.01 -- 5 Hz at zeta 1 %, 30 dB: median 1.27 -> 0.92 periods, 94-100 % within
#: 2 %; 2 Hz at 3 %, 40 dB: 1.28 -> 0.92, 60-100 % -> 94-100 %; the real beams' median error
#: 0.22-0.37 -> 0.16-0.24 %; in 20 dB at 200-2500 samples a period 1.23-1.25 -> 0.90-0.91 periods,
#: RMS error 0.44-0.80 -> 0.20-0.61 %, and in 13-15 dB too (no signal-to-noise limit: where the
#: noise hides the offset it is not known). The offset is known when the record's last
#: quarter's halves (means over whole blocks of :data:`DECAY_BLOCK_PERIODS` periods, where a
#: sinusoid averages out) agree within this share of the decay's amplitude and the noise allows
#: that precision: the damped model is unhurt by an offset of 0.1-0.3 % of the amplitude and
#: loses 10-35 % of its estimates within 2 % at 1 %. At 0.1 % (until 5 Dec) a decay damped at
#: 2-5 % ringing 10-25 periods in 30 dB did not give its offset: it kept the biased sinusoid's
#: 1.25 periods, its worst seed 0 % within 2 % at 3-5 % (now 83-90 %, bench_first_estimate.py
#: --sweep), the 12 Hz decay at 2 % a median of 1.27 periods (now 0.94)
OFFSET_TOL = 3e-3
#: ... and every block's mean lies within this share of the block's own amplitude of it (a
#: sinusoid decaying at zeta averages to ~zeta of its amplitude over whole periods): an offset
#: that moved (an arm's hub stepping, a beam held deflected before its release) is not known
OFFSET_MOVE = 0.1
#: the damping ratio :func:`window_advice` assumes of the lowest mode (:data:`WINDOW_PERIODS`
#: is ~15 correlation times at it)
ASSUMED_ZETA = 0.02
#: ... unless the record is noise: its strongest spectral peak stands under this many dB above
#: the spectrum's median (white noise 6-12 dB, a random walk 14; a mode driven by noise in as
#: much measurement noise 20-27 dB, the Heritage Court Tower 20.5, the shear frame 35)
FLAT_DB = 15.0
#: the window leaves the record room for at least this many analyses (one per second)
MIN_ANALYSES = 60
#: ... and a record shorter than this many configured windows is analysed in windows of that
#: share of it (a 20 s driven record: 10 s windows, 6 analyses; with the configured 30 s it gave
#: no analysis at all)
SHORT_WINDOWS = 2.0
#: a spectral peak whose response, band-passed within :data:`LINE_BAND` of it, has a kurtosis
#: below this is a sinusoid of steady amplitude -- a line of a periodic drive -- not a mode
#: driven by noise (:func:`peak_kurtosis`; Brincker, Andersen and Moeller 2000, "An indicator
#: for separation of structural and harmonic modes in output-only modal testing": a sinusoid
#: reads 1.5, Gaussian noise 3). Measured (5 Dec): the simulated arm's move cycles' harmonics
#: 1.50-1.57, 1.68-1.72 beside a mode's flank; noise-driven modes 2.06-3.4 (the lightest, zeta
#: 0.2 % over 180 s, the lowest: bench_defaults' and 2 / 4 / 6 Hz, 3 seeds), the Heritage Court
#: Tower's 2.5-7, the shear frame's 2.6-3.3; a line in noise reads 1.76 at 10 dB in its band,
#: so weak lines are missed, never modes taken
LINE_KURTOSIS = 1.8
#: ... and a line alone (no periodic drive: :func:`steady_lines`) only in a record of at least
#: this many of its periods: 10 correlation times of a mode at zeta 0.2 %, which over fewer rings
#: as steadily (noise-driven modes of 0.5-30 Hz, zeta 0.1-2 %, 2 seeds of 20-600 s: 35 of 576
#: records read a mode as a line without this, all under it)
LINE_PERIODS = 800.0
#: ... the band's half width (relative, around the record's strongest FFT bin within the Welch
#: peak's): narrow, so that a mode's flank beside a line weighs little (at 0.1 a line 20 % below
#: a mode read 2.2, at 0.03 1.7), and still several bins (a mode at zeta 5 %: its half-power band)
LINE_BAND = 0.03
#: a driven record's peaks under this share of the strongest's power that lie below
#: :data:`LOW_GAP` x the lowest peak holding more are the drive's slow content, not a mode: the
#: identifier's band starts there (:func:`slow_content`). The arm moved back and forth at random
#: times (bench_periodic's jittered 1.5 s): its motion's 0.32-0.35 Hz bump holds 0.4 % of the
#: mode's power, sized a 240 s window and was published as a mode of zeta 3.5 % (73.7 % within
#: 2 %); the lowest peaks of bench_defaults' driven records, the frame and the Heritage Court
#: Tower hold 90-100 % (their weakest peak anywhere: 3.4 %)
LOW_SHARE = 0.03
#: ... an octave
LOW_GAP = 0.5
#: a periodic drive: at least this many lines on the harmonics of one fundamental (within
#: :data:`HARMONIC_TOL`); a free decay ringing through its record (a sinusoid of steady
#: amplitude too) or a limit cycle is one line, or one with its harmonics below it
PERIODIC_LINES = 3
#: a periodic drive's lines beside a free decay (a machine running nearby: a motor's 30, 60, 90
#: Hz beside a beam's 5 Hz pluck) when the lowest lies this many times above the decay's modes
#: or more (:func:`beside_decay`: a band leaves them out); the identifier gave such a pluck 5
#: estimates in 30 s, the free estimator 130
LINES_ABOVE = 2.0
#: a record the envelope reads driven is a train of free decays -- plucks or impacts that come
#: before the last has rung down (an impact test, a hammer every 3 s on a 7 Hz mode at zeta 1 %:
#: each rise ~6 x, not the envelope's onset; read 77-99 % driven, and its response, at the
#: impacts' harmonics only, a periodic drive's lines: no estimate at all) -- when at least this
#: share of its stretches of ``TEST_PERIODS`` periods pass the free-decay test cleanly
#: (:func:`decay_train`; ``bench_hard_records.py --impacts``' trains 85-100 %, but 69-71 % at
#: 20 dB with 14 periods between impacts; bench_defaults' driven records 0-2 %, a building's
#: response in 10 dB of noise 33 %)
TRAIN_SHARE = 0.75
#: ... cleanly: the one-period blocks' amplitude this many dB over their noise (the trains
#: 28-58 dB; a building's passing stretches, whose other modes are that noise, 6-17)
TRAIN_SNR_DB = 20.0
#: ... of at most this many stretches, evenly spaced (~1 ms each)
TRAIN_TESTS = 48
#: a record read free of one mode is a steady oscillation, not a decay -- the mode tracker's --
#: when under this share of the stretches the free-decay test tells are clean free decays
#: (:func:`steady_oscillation`; the real arm's limit cycles (flex1, flex5, flex8) 0 of 1, the
#: beams' and synthetic decays' 100 %): free windows under a period, on an oscillation whose
#: amplitude and phase wander in 1 mm steps, were 2-4 % off (flex1: 6 of 9 within 2 % of the
#: cycles' local rate; the tracker: 96 %)
STEADY_SHARE = 0.25
#: ... and its band (``band_hz``) this factor either side of it: a quantiser's staircase on its
#: slow stretches (1 mm steps every 15 ms: a 65 Hz "mode" on flex1) and its harmonics left out
STEADY_BAND = 2.0
#: ... and the mode tracker there takes a pole damped beyond this for the transient before the
#: oscillation, not the oscillation (``max_damping``): the real arm's step response rings at
#: zeta 3.5-8 % into its limit cycle (flex8: 1.66, 1.67, 1.72 Hz at 4.7-5.1 s, 5-8 % below the
#: cycle), its cycles read -0.8 to 2.3 % (a 2-period window on a wandering amplitude; flex5
#: once 4.1 %, held back)
STEADY_ZETA = 0.03


@dataclass(frozen=True)
class Decision:
    """The excitation a record needs, the ambient window (s) for a driven one, what the decision
    saw and why, in words."""

    excitation: str
    window_s: float
    driven_share: float
    dominant_hz: float
    fundamental_hz: float
    peaks_hz: tuple = field(default=())
    reason: str = ''
    #: the seconds and the mean sampling rate of what was read
    span_s: float = math.nan
    rate_hz: float = math.nan
    #: a free decay of several separate modes: the modes to track (0: one estimator)
    modes: int = 0
    #: a free decay of one mode: the window it allows (:func:`fast_window`; NaN: the configured)
    min_periods: float = math.nan
    #: ... and the precision an estimate over it needs (``early_std_rel``; 0: the configured)
    early_std_rel: float = 0.0
    #: ... the model it needs ('': the configured) and the offset to remove first (NaN: none;
    #: :func:`known_offset`), for ``analyze``, which sees the whole record
    model: str = ''
    offset: float = math.nan
    #: a periodic drive's lines (Hz, :func:`drive_lines`) beside a mode of the structure: the
    #: identifier drops its modes there (``lines_hz``)
    lines_hz: tuple = ()
    #: a driven record's band, Hz (:func:`slow_content`; (): none)
    band_hz: tuple = ()
    #: the share of its stretches that are clean free decays (:func:`decay_train`; NaN: not
    #: asked): a record read driven that is a train of plucks is free
    train: float = math.nan
    #: a steady oscillation (:func:`steady_oscillation`): the damping beyond which the mode
    #: tracker's pole is the transient before it, not it (``max_damping``; NaN: the configured)
    max_damping: float = math.nan
    #: a stream's way from the identifier to ``auto``: only the excitation changes (the window,
    #: the lines and the band its driven decision set stay)
    keeps: bool = False
    #: how far (dB) the strongest spectral peak stands above the spectrum's median (NaN: no
    #: peak): under :data:`FLAT_DB`, noise
    peak_db: float = math.nan
    #: a free decay of several separate modes tracked (:attr:`modes`) whose strongest mode is
    #: the lowest, rings purely and holds the others under :data:`MODE_SHARE` of its power: the
    #: free estimator's ``(min_periods, early_std_rel, model, offset)`` for it
    #: (:func:`fast_window`; ``analyze`` reads that mode so, the mode tracker the others); ()
    dominant_window: tuple = ()
    #: a free decay of one mode: the periods it rings above its noise in the record
    #: (:func:`ringing_periods`; NaN: not read), for ``analyze``'s rescue
    ringing_periods: float = math.nan

    @property
    def plucks_in_a_row(self) -> bool:
        """Read driven, but a train of free decays (:attr:`train` at least
        :data:`TRAIN_SHARE`): free."""
        return self.train >= TRAIN_SHARE

    def changes(self) -> dict:
        """The configuration fields a stream switching to this decision sets (the node's
        parameters): the excitation, a driven one's window, a free decay's modes (when
        several) or window (when decided)."""
        if self.excitation == 'free':
            out: dict = {'excitation': 'free'}
            if self.modes:
                out['modes'] = self.modes
            if math.isfinite(self.max_damping):
                out['max_damping'] = self.max_damping
            if math.isfinite(self.min_periods):
                out.update(min_periods=self.min_periods, early_std_rel=self.early_std_rel)
            return out
        if self.keeps:
            return {'excitation': self.excitation}
        out = {
            'excitation': self.excitation,
            'ambient_window_s': float(self.window_s),
            'lines_hz': list(self.lines_hz),  # ([]: none, those of an earlier decision gone)
        }
        if self.band_hz:  # (else the configured band stays)
            out['band_hz'] = list(self.band_hz)
        return out


def principal_component(y: np.ndarray) -> np.ndarray:
    """One signal from ``y`` (samples, or samples x channels): the projection of the centred
    channels on their covariance's leading eigenvector (one channel: the signal centred)."""
    y = np.asarray(y, dtype=np.float64)
    y = y - np.mean(y, axis=0)
    if y.ndim == 1 or y.shape[1] == 1:
        return y.reshape(-1)
    _, vectors = np.linalg.eigh(y.T @ y)
    return y @ vectors[:, -1]


def spectrum(t: np.ndarray, y: np.ndarray) -> tuple:
    """Welch's spectrum of ``(t, y)`` (segments of :data:`SEGMENT_S` s), summed over the channels
    of ``y``: ``(frequencies, powers, the lowest frequency it resolves, the powers without the
    start's segment, the segments averaged)`` -- a segment centred on the first sample (half a
    segment of rest before it), added where it holds :data:`START_RATIO` times the segments' mean
    power (a decay ringing down from that sample; else the fourth is None)."""
    from .spectra import welch  # scipy.signal's, in numpy (.spectra: its import cost)

    fs = (len(t) - 1) / float(t[-1] - t[0])
    y = np.asarray(y, dtype=np.float64).reshape(len(t), -1)
    nper = int(min(len(t), max(64, round(SEGMENT_S * fs))))
    freq, psd = welch(y, fs, nper)
    plain, n = None, len(y)
    rest = np.broadcast_to(np.mean(y, axis=0), (nper // 2, y.shape[1]))
    start = np.concatenate([rest, y[: nper - nper // 2]])  # the segment centred on the start
    if np.sum(welch(start, fs, nper)[1]) > START_RATIO * np.sum(psd):  # its start tapered
        plain, n = np.sum(psd, axis=1), n + len(rest)
        freq, psd = welch(np.concatenate([rest, y]), fs, nper)
    segments = (n - nper) // (nper - nper // 2) + 1
    return freq, np.sum(psd, axis=1), 2 * fs / nper, plain, segments


def peak_frequencies(spec, peaks: np.ndarray) -> np.ndarray:
    """The frequencies of the spectrum ``spec``'s (:func:`spectrum`) peaks at the bins
    ``peaks`` (Hz), each interpolated by a parabola through the log powers of its bin and its
    neighbours (:func:`strongest_bin`): within a small share of a bin of a clean peak."""
    freq, psd = spec[0], spec[1]
    at = np.clip(np.searchsorted(freq, peaks), 1, len(freq) - 2)
    return np.array([strongest_bin(freq[i - 1 : i + 2], psd[i - 1 : i + 2]) for i in at])


def spectral_peaks(t: np.ndarray, y: np.ndarray, spec=None) -> tuple[np.ndarray, np.ndarray]:
    """``(frequencies, powers)`` of the spectrum's peaks (module docstring, 1), strongest first,
    summed over the channels of ``y`` (``spec``: its :func:`spectrum`, if computed already);
    each but the strongest above what the noise reaches by chance (:func:`chance_level`; the
    strongest, a short decay's in a long record among them, is judged by :data:`FLAT_DB`)."""
    from .spectra import peaks_by_prominence  # scipy.signal's find_peaks (prominence only)

    freq, psd, lowest, _, segments = spectrum(t, y) if spec is None else spec
    level = 10 * np.log10(np.maximum(psd, 1e-300 + 1e-12 * float(np.max(psd))))
    idx = peaks_by_prominence(level, PEAK_DB)
    idx = idx[freq[idx] > lowest]  # above the segment's own lowest bins (a drift)
    if not len(idx):
        return np.empty(0), np.empty(0)
    order = idx[np.argsort(psd[idx])[::-1]]
    level = chance_level(psd, order[1:], segments, int(np.sum(freq > lowest)))
    order = np.r_[order[:1], order[1:][psd[order[1:]] >= level]]  # the strongest: FLAT_DB
    order = order[psd[order] >= PEAK_SHARE * psd[order[0]]]
    return freq[order], psd[order]


def onset_peaks(t: np.ndarray, signal: np.ndarray, dominant: float) -> tuple:
    """``(frequencies, interpolated frequencies)`` of the spectral peaks (:func:`spectral_peaks`)
    of a free decay's first :data:`ONSET_PERIODS` periods of its ``dominant`` mode (Hz) from
    its largest sample on, strongest first: a brief higher mode, which holds its energy there
    but peaks under :data:`PEAK_SHARE` of the whole record's strongest (a 90.5 Hz mode at
    zeta 0.4 % beside an 8.2 Hz one at 1:0.82: 1.8e-4 over 11 s, 4 % over its first 10 periods)."""
    if not dominant > 0:
        return np.empty(0), np.empty(0)
    start = int(np.argmax(np.abs(signal - np.median(signal))))
    rate = (len(t) - 1) / float(t[-1] - t[0])
    stop = start + int(round(ONSET_PERIODS / dominant * rate))
    if stop > len(t) or stop - start < 64:  # (a decay cut short; too few samples, as decide)
        return np.empty(0), np.empty(0)
    cut = t[start:stop], signal[start:stop]
    spec = spectrum(*cut)
    peaks = spectral_peaks(*cut, spec)[0]
    return peaks, peak_frequencies(spec, peaks)


def chance_level(psd: np.ndarray, at: np.ndarray, segments: int, bins: int) -> np.ndarray:
    """At the bins ``at``, the power the noise alone reaches by chance in one of ``bins`` bins with
    probability :data:`CHANCE` (a spectral peak must reach it): the local floor (the median of
    the :data:`FLOOR_BINS` bins around) times the ratio of the (1 - CHANCE / bins) quantile of a
    Welch average of ``segments`` segments (chi-square, 2 ``segments`` degrees of freedom:
    Wilson-Hilferty; the normal quantile by Abramowitz & Stegun 26.2.23) to its median. One
    20 s segment of 57 000 bins: 14 dB over the floor (a noisy decay's record of 20 s, read with
    prominence alone, showed 2 445 peaks, "lines" of a "periodic drive" among them); 30
    segments: 3.5 dB."""
    from numpy.lib.stride_tricks import sliding_window_view

    half = min(FLOOR_BINS // 2, (len(psd) - 1) // 2)
    padded = np.pad(psd, half, mode='reflect') if half else psd
    floor = np.median(sliding_window_view(padded, 2 * half + 1)[at], axis=1)
    tail = math.sqrt(-2.0 * math.log(min(CHANCE / max(bins, 1), 0.5)))
    z = tail - (2.515517 + 0.802853 * tail + 0.010328 * tail**2) / (
        1 + 1.432788 * tail + 0.189269 * tail**2 + 0.001308 * tail**3
    )
    spread = 2.0 / (9.0 * 2 * max(segments, 1))
    ratio = ((1 - spread + z * math.sqrt(spread)) / (1 - spread)) ** 3
    return floor * ratio


def driven_share(t: np.ndarray, signal: np.ndarray, dominant_hz: float) -> float:
    """The share of the record's energy (the envelope's block variances, :class:`.auto.Envelope`,
    its block fitted to ``dominant_hz``) in the blocks it reads as driven, each block in the state
    decided at its own end: the noise a free decay rings down into (a stationary tail the envelope
    reads as driven) weighs nothing beside the decay, and neither does a rest before a pluck read
    as driven (at 10-12 samples a period its 37-sample blocks of noise wander by 1.5 x), whose
    block with the pluck is the pluck's (a sample's state, the one after the block before, gave
    that block -- the decay's strongest quarter second, 15 % of its energy -- to the rest: 4 of
    32 such records at 10 samples a period read ``auto``, none at 20)."""
    block = MIN_BLOCK_S
    if dominant_hz > 0:
        block = max(MIN_BLOCK_S, BLOCK_MARGIN * BLOCK_PERIODS / dominant_hz)
    envelope = Envelope(block)
    envelope.feed(t, signal)
    total = envelope.energy[FREE] + envelope.energy[DRIVEN]
    return envelope.energy[DRIVEN] / total if total > 0 else 0.0


def band_responses(t: np.ndarray, signal: np.ndarray, peaks):
    """``(centre, response)`` for each of ``peaks`` (Hz): ``signal`` band-passed (ideally, by FFT)
    within :data:`LINE_BAND` of the centre, the record's strongest FFT bin (interpolated) within
    the Welch peak's (whose resolution, 1 / :data:`SEGMENT_S`, is too coarse to tell a
    harmonic)."""
    n = len(signal)
    size = 1 << max(n - 1, 1).bit_length()  # a power of two: the FFT's fast length
    fs = (n - 1) / float(t[-1] - t[0])
    spec = np.fft.rfft(signal - np.mean(signal), size)
    freq = np.fft.rfftfreq(size, 1.0 / fs)
    magnitude = np.abs(spec)
    for f in peaks:
        f = strongest_bin(freq, magnitude * (np.abs(freq - f) <= 1.0 / SEGMENT_S))  # Welch's bin
        band = np.abs(freq - f) <= LINE_BAND * f  # (none at 0 Hz)
        yield f, np.fft.irfft(np.where(band, spec, 0), size)[:n]


def peak_kurtosis(t: np.ndarray, signal: np.ndarray, peaks) -> tuple[np.ndarray, np.ndarray]:
    """``(kurtosis, frequency)`` of ``signal`` band-passed around each of ``peaks`` (Hz,
    :func:`band_responses`), the record's ends (a twentieth each) left out -- 1.5 for a sinusoid
    of steady amplitude, 3 for a mode driven by noise (:data:`LINE_KURTOSIS`) -- and the band's
    centre."""
    edge = len(signal) // 20
    kurtosis, where = [], []
    for f, x in band_responses(t, signal, peaks):
        x = x[edge : len(signal) - edge]
        power = float(np.mean(x * x))
        kurtosis.append(float(np.mean(x**4)) / power**2 if power > 0 else math.nan)
        where.append(f)
    return np.array(kurtosis), np.array(where)


def strongest_bin(freq: np.ndarray, magnitude: np.ndarray) -> float:
    """The frequency of ``magnitude``'s largest bin, interpolated by a parabola through the log
    magnitudes of it and its neighbours."""
    i = int(np.argmax(magnitude))
    if not 0 < i < len(freq) - 1 or np.min(magnitude[i - 1 : i + 2]) <= 0:
        return float(freq[i])
    a, b, c = np.log(magnitude[i - 1 : i + 2])
    shift = 0.5 * (a - c) / (a - 2 * b + c) if a - 2 * b + c < 0 else 0.0
    return float(freq[i] + shift * (freq[1] - freq[0]))


def harmonic_series(lines: np.ndarray) -> tuple[np.ndarray, float]:
    """``(indices, fundamental)``: the largest subset of ``lines`` (Hz) on the harmonics of one
    fundamental (each within :data:`HARMONIC_TOL` of a multiple of it), the fundamental tried
    the lowest line, the closest two lines' spacing or half of it (a cycle's odd harmonics lie
    two apart), then fitted to them (least squares)."""
    best, f0 = np.arange(min(len(lines), 1)), float(np.min(lines)) if len(lines) else math.nan
    if len(lines) < 2:
        return best, f0
    spacing = float(np.min(np.diff(np.sort(lines))))
    for trial in (f0, spacing, spacing / 2):
        if trial <= 0:
            continue
        k = np.maximum(np.round(lines / trial), 1)
        on = np.flatnonzero(np.abs(lines / (k * trial) - 1) <= HARMONIC_TOL)
        if len(on) > len(best):
            best = on
            f0 = float(np.sum(lines[on] * k[on]) / np.sum(k[on] ** 2))
    return best, f0


def drive_lines(kurtosis: np.ndarray, where: np.ndarray) -> tuple[np.ndarray, list]:
    """The spectral peaks (read by :func:`peak_kurtosis`: ``kurtosis`` and ``where``, each
    one's band centre) that are lines of a periodic drive -- sinusoids of steady amplitude
    (below :data:`LINE_KURTOSIS`) on the harmonics of one fundamental, at least
    :data:`PERIODIC_LINES` of them, else none --: ``(whether each peak is one, the drive's
    harmonics up to its highest line, Hz: the odd ones where the lines are all odd, a cycle
    there and back)``. A harmonic beside a mode reads as neither (a mixture), so every harmonic
    is listed."""
    is_line = np.zeros(len(where), bool)
    if len(where) < PERIODIC_LINES:
        return is_line, []
    candidates = np.flatnonzero(kurtosis < LINE_KURTOSIS)
    on, f0 = harmonic_series(where[candidates])
    if len(on) < PERIODIC_LINES:
        return is_line, []
    is_line[candidates[on]] = True
    k = np.round(where[candidates[on]] / f0).astype(int)
    step = 2 if np.all(k % 2 == 1) else 1
    # up to where the lines' neighbourhoods (core.ambient.LINE_TOL) would cover half the axis
    top = max(int(np.max(k)), int(step / (4 * LINE_TOL)))
    return is_line, [n * f0 for n in range(1, top + 1, step)]


def slow_content(peaks: np.ndarray, powers: np.ndarray, rate_hz: float) -> tuple:
    """``(band, the lowest peak in it, in words)`` of a driven record whose spectral ``peaks``
    under :data:`LOW_SHARE` of the strongest's power lie below :data:`LOW_GAP` x the lowest
    stronger one (the drive's slow content): the band from that edge to :data:`.ssi.NU_MAX` x
    ``rate_hz``; ``((), nan, '')`` for none."""
    strong = peaks[powers >= LOW_SHARE * np.max(powers)] if len(peaks) else peaks
    edge = LOW_GAP * float(np.min(strong)) if len(strong) else 0.0
    if not np.any(peaks < edge):
        return (), math.nan, ''
    above = peaks[peaks >= edge]
    said = (
        f'; the peaks at {", ".join(f"{f:.3g}" for f in np.sort(peaks[peaks < edge]))} Hz hold '
        f'under {100 * LOW_SHARE:g} % of the power, an octave below the lowest strong one: the '
        f"drive's slow content, not sized for, its band from {edge:.3g} Hz (band_hz)"
    )
    return (edge, NU_MAX * rate_hz), float(np.min(above)) if len(above) else math.nan, said


def readable(t, y) -> tuple[np.ndarray, np.ndarray]:
    """The samples of ``(t, y)`` a decision reads: finite, at sane times (an absurd stamp,
    1e300 s, would overflow the block index), no absurd value (1e300: the estimator skips it as
    an outlier), the first :data:`DECIDE_S` s."""
    t = np.asarray(t, dtype=np.float64)
    y = np.asarray(y, dtype=np.float64)
    keep = (np.abs(t) < MAX_STAMP_S) & np.all(np.isfinite(y.reshape(len(t), -1)), axis=1)
    t, y = t[keep], y[keep]
    if len(t):
        dev = np.abs(y - np.median(y, axis=0)).reshape(len(t), -1)
        mad = np.median(dev, axis=0)
        keep = np.all(dev <= ABSURD * np.maximum(mad, np.max(mad) + 1e-300), axis=1)
        t, y = t[keep], y[keep]
    if len(t) > 1:
        n = int(np.searchsorted(t, t[0] + DECIDE_S, 'right'))
        t, y = t[:n], y[:n]
    return regular(t, y)


def regular(t: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(t, y)`` as they are if their stamps step evenly (within :data:`JITTER` of their median
    step, gaps of over ``MAX_FILL`` steps aside) or do not rise throughout (left to the
    estimators' own time rules); else ``y`` (samples, or samples x channels) linearly
    interpolated onto a uniform grid at the median step, stretch by stretch between those gaps
    (the mode tracker bridges the same: :data:`.modes.MAX_FILL`): a spectrum read at the mean rate
    of jittered stamps, or across short gaps, smears every peak."""
    if len(t) < 3:
        return t, y
    steps = np.diff(t)
    h = float(np.median(steps))
    if not (h > 0.0 and np.all(steps > 0.0)):
        return t, y
    gaps = steps > MAX_FILL * h
    if np.max(np.abs(steps[~gaps] - h)) <= JITTER * h:
        return t, y
    cut = np.flatnonzero(gaps)
    grid = np.concatenate(
        [
            t[a] + h * np.arange(int((t[b] - t[a]) / h) + 1)
            for a, b in zip(np.r_[0, cut + 1], np.r_[cut, len(t) - 1])
        ]
    )
    if y.ndim == 1:
        return grid, np.interp(grid, t, y)
    return grid, np.stack([np.interp(grid, t, column) for column in y.T], axis=1)


def steady_lines(span: float, kurtosis: np.ndarray, where: np.ndarray) -> tuple:
    """For a record of ``span`` s with no periodic drive (:func:`drive_lines`): its spectral
    peaks (read by :func:`peak_kurtosis`: ``kurtosis``, ``where``) that are sinusoids of steady
    amplitude (below :data:`LINE_KURTOSIS`),
    each a line however alone -- a machine's rotation, mains --, where another peak is no line
    (a record of one steady sinusoid, a limit cycle, keeps it): ``(whether each peak is one,
    their frequencies, Hz, and the strongest peak's where it rings as steadily in a record shorter
    than`` :data:`LINE_PERIODS` ``of its periods: its envelope the record's, told in words; a
    weaker mode of a short decay rings as steadily)``. Alone, such a line beside modes driven by
    noise was identified as a mode at zeta 0.0-0.2 % (a 12 Hz line at twice the response's RMS
    beside 8 and 40 Hz modes: 7 of 49 estimates; 9.5 Hz beside 8 Hz: 22 of 75, "zeta 0.13 %")."""
    is_line = np.zeros(len(where), bool)
    ringing = kurtosis < LINE_KURTOSIS
    if len(where) < 2 or np.all(ringing):
        return is_line, [], []
    told = span * where >= LINE_PERIODS
    untold = where[:1][ringing[:1] & ~told[:1]].tolist()
    return ringing & told, where[ringing & told].tolist(), untold


def less_lines(t: np.ndarray, signal: np.ndarray, modal: np.ndarray, lines: list) -> tuple:
    """A record with lines alone (:func:`steady_lines`) read as its modes': ``(the strongest
    mode, the lowest, Hz, the signal less the lines' band-passed responses)`` -- a line three
    times the response's RMS held the envelope steady: 8 and 40 Hz modes driven by noise read
    0 % driven beside it, a free decay of "separate modes" 8, 40 and the 50 Hz line."""
    less = signal - sum(x for _, x in band_responses(t, signal, lines))
    return float(modal[0]), float(np.min(modal)), less


def by_share(share: float, channels: int) -> str:
    """The excitation of a record whose envelope reads ``share`` of its energy driven (no
    periodic drive, no train of impacts): free under :data:`FREE_BELOW`, ambient over
    :data:`DRIVEN_ABOVE` (or several channels, half of it driven), else auto."""
    if share < FREE_BELOW:
        return 'free'
    if share > DRIVEN_ABOVE or channels > 1:
        return 'ambient' if share >= 0.5 else 'free'
    return 'auto'


def lines_read(t: np.ndarray, signal: np.ndarray, peaks: np.ndarray, given=()) -> tuple:
    """The spectral ``peaks`` that are lines, not modes: ``(whether each is one, the lines' or
    the periodic drive's harmonics, Hz, whether a periodic drive, words)`` -- a periodic drive's
    (:func:`drive_lines`), else lines alone (:func:`steady_lines`) and the lines ``given``
    (Hz: ``--lines-hz``; a peak within :data:`.ambient.LINE_TOL` or a Welch bin of one)."""
    unread = (np.full(len(peaks), math.nan), np.asarray(peaks, dtype=float))  # (one peak: no line)
    reading = peak_kurtosis(t, signal, peaks) if len(peaks) > 1 else unread
    is_line, lines = drive_lines(*reading)
    if lines:
        return is_line, lines, True, drive_said(is_line, lines, peaks[~is_line])
    is_line, lines, untold = steady_lines(float(t[-1] - t[0]), *reading)

    def known(f: float) -> bool:
        return any(abs(f - g) <= max(LINE_TOL * g, 1 / SEGMENT_S) for g in given)

    said = ''.join(
        f'; the peak at {f:.4g} Hz rings as steadily as a line (a machine running: --lines-hz '
        f"{f:.4g} reads it as one) or a mode too lightly damped for the record's "
        f'{float(t[-1] - t[0]) * f:.0f} periods of it to tell ({LINE_PERIODS:.0f} do)'
        for f in sorted(untold)
        if not known(f)
    )
    if lines:
        listed = ', '.join(f'{f:.4g}' for f in sorted(lines))
        said += (
            f'; the peak{"s" if len(lines) > 1 else ""} at {listed} Hz: steady, a line (a '
            'machine running, mains), not a mode'
        )
    if len(given):
        is_line = is_line | np.array([known(f) for f in peaks.tolist()], dtype=bool)
        lines = sorted({*lines, *map(float, given)})
        said += '; the lines given (lines_hz) read as lines'
    return is_line, lines, False, said


def drive_said(is_line: np.ndarray, lines: list, modal: np.ndarray) -> str:
    """What :func:`drive_lines` found, in words ('' for no periodic drive)."""
    if not lines:
        return ''
    return (
        f'; a periodic drive: {int(np.sum(is_line))} lines at the harmonics of {lines[0]:.4g} Hz '
        '(sinusoids of steady amplitude, not modes), '
        + (
            f'modes at {", ".join(f"{f:.3g}" for f in np.sort(modal))} Hz apart from them'
            if len(modal)
            else 'no spectral peak apart from them'
        )
    )


def decide(
    t,
    y,
    channels: int = 1,
    window_s: float = 30.0,
    stream: bool = False,
    offset_ok: bool = True,
    given: tuple = (),
) -> Decision:
    """The :class:`Decision` for the record ``(t, y)`` (its first :data:`DECIDE_S` s are read;
    ``y`` samples or samples x ``channels``), ``window_s`` the shortest window (the configured
    one; a record shorter than :data:`SHORT_WINDOWS` of them: that share of it). ``stream``: the
    record is the last seconds of a stream that goes on (the window is not bounded by the room
    for :data:`MIN_ANALYSES` analyses, and a free decay's window is not decided: the node cannot
    see a spectrum ahead, and a stream's default stays ``free``'s).
    ``offset_ok``: the caller can remove a known offset from the samples (:attr:`Decision.offset`;
    :func:`fast_window`). ``given``: lines the caller knows (``lines_hz``, Hz), read as lines."""
    t, y = readable(t, y)
    if len(t) < 64 or not t[-1] > t[0]:
        return Decision('free', window_s, 0.0, math.nan, math.nan, (), 'too short to tell: free')
    spec = spectrum(t, y)  # once: the peaks and a free decay's fast_window read it
    peaks, powers = spectral_peaks(t, y, spec)
    dominant = float(peaks[0]) if len(peaks) else math.nan
    fundamental = float(np.min(peaks)) if len(peaks) else math.nan
    signal = principal_component(y)
    is_line, lines, periodic, lined = lines_read(t, signal, peaks, given)
    modal = peaks[~is_line]
    if alone := bool(lines) and not periodic and len(modal) > 0:  # (a periodic drive: driven)
        dominant, fundamental, signal = less_lines(t, signal, modal, lines)
    share = driven_share(t, signal, dominant if len(peaks) else 0.0)
    span = float(t[-1] - t[0])
    seen = (
        f'{100 * share:.0f} % of the energy of {span:.0f} s read driven by the envelope; spectral '
        'peaks at '
        + (', '.join(f'{f:.3g}' for f in sorted(peaks[:8])) + ' Hz' if len(peaks) else 'none')
    )
    seen += lined
    at = float(modal[0]) if len(modal) else dominant  # (the strongest mode)
    train, said, crowded = impacts_read(t, signal, share, at, bool(lines) and not len(modal))
    seen += said
    beside: list = []  # a machine's lines beside a free decay (banded out)
    if train >= TRAIN_SHARE or crowded:  # the mode: the strongest peak near it (the impacts'
        near = peaks[(peaks > at / LINES_ABOVE) & (peaks < at * LINES_ABOVE)]  # are its response)
        dominant = float(near[0]) if len(near) else at
        excitation, beside, lines = 'free', [f for f in lines if f >= LINES_ABOVE * at], []
    elif periodic and len(modal):  # the structure's modes, not the lines
        dominant, fundamental = at, float(np.min(modal))
        excitation = 'ambient'  # the modes between a periodic drive's lines
        if beside_decay(t, signal, modal, lines):  # (however loud the lines)
            excitation, beside, lines = 'free', lines, []
            seen += f'; the {dominant:.4g} Hz mode rings down freely beside them: a free decay'
    else:
        excitation = by_share(share, channels)
    if alone and excitation == 'free':  # lines beside a free decay: banded out where above it
        beside, lines = lines, []
    band, lowest, said = slow_content(modal, powers[~is_line], (len(t) - 1) / span)
    if excitation == 'ambient' and band:
        seen, fundamental = seen + said, (lowest if math.isfinite(lowest) else fundamental)
    else:
        band = ()
    window = window_s
    if excitation != 'free' and math.isfinite(fundamental):
        window, said = driven_window(window_s, fundamental, span, stream)
        seen += said
    modes, rate = 0, (len(t) - 1) / span
    free, cap = (math.nan, 0.0, '', math.nan), math.nan  # a free decay's window, precision,
    lowest: tuple = ()  # (its lowest mode's, several tracked)
    if excitation == 'free':  # model, offset; a steady oscillation's max_damping
        decay = (t, y, signal, spec, dominant, channels)  # the free decay
        chosen = (modal, powers[~is_line], beside, offset_ok, stream, train, crowded)
        modes, free, band, said, cap, lowest = free_choice(*decay, *chosen)
        seen += said
    if lines and excitation != 'free':
        seen += '; the identifier drops its modes at the lines (lines_hz)'
    seen_at = (tuple(peaks), seen, span, rate)  # what was read, at what rate
    found = (modes, *free, tuple(lines) if excitation != 'free' else (), band, train, cap)
    read = (excitation, window, share, dominant, fundamental, *seen_at, *found)
    one = excitation == 'free' and not (modes or stream) and dominant > 0  # (a free decay's)
    more = dict(ringing_periods=ringing_periods(t, signal, dominant) if one else math.nan)
    return Decision(*read, peak_db=standing(spec, powers), dominant_window=lowest, **more)


def standing(spec, powers: np.ndarray) -> float:
    """How far (dB) the strongest of the spectral peaks ``powers`` stands above the median of
    the spectrum ``spec`` (:func:`spectrum`) above its lowest resolved frequency; NaN without."""
    freq, psd, lowest = spec[:3]
    floor = float(np.median(psd[freq > lowest])) if np.any(freq > lowest) else 0.0
    if not (len(powers) and floor > 0):
        return math.nan
    return 10 * math.log10(float(powers[0]) / floor)


def impacts_read(t: np.ndarray, signal: np.ndarray, share: float, at: float, lined: bool):
    """For a record whose envelope holds ``share`` of its energy driven, its strongest mode at
    ``at`` Hz: ``(train, words, crowded)`` -- the share :func:`decay_train` reads (NaN: not
    asked, the record read free), the words, and whether it is a train of impacts too close
    together for :data:`TRAIN_SHARE` of clean stretches: ``lined`` (every spectral peak a line
    of a periodic drive, none apart: the mode's response at the impacts' harmonics, which the
    identifier drops) and at least :data:`STEADY_SHARE` clean (no steady oscillation). Impacts
    every 1-3 s on a 7 Hz mode in 20-30 dB read 0.69-0.73 (their stretches of 8 periods straddle
    an impact): the identifier gave nothing, the mode tracker 100 % within 2 %."""
    if not (share >= FREE_BELOW and at > 0):
        return math.nan, '', False
    train, said = decay_train(t, signal, at)
    crowded = lined and STEADY_SHARE <= train < TRAIN_SHARE
    if crowded:
        said += (
            f'; every peak a line of a periodic drive, and {100 * train:.0f} % of its stretches '
            f'of {TEST_PERIODS} periods of {at:.4g} Hz clean free decays: a train of impacts, free'
        )
    return train, said, crowded


def driven_window(window_s: float, fundamental: float, span: float, stream: bool) -> tuple:
    """A driven record's window (s) and the words: :data:`WINDOW_PERIODS` periods of its
    ``fundamental`` (Hz), at least the configured ``window_s``, at most :data:`MAX_WINDOW_S`,
    and (not a ``stream``) leaving a record of ``span`` s :data:`MIN_ANALYSES` analyses, or,
    shorter than :data:`SHORT_WINDOWS` configured windows, that share of it."""
    room = math.inf if stream else max(min(window_s, span / SHORT_WINDOWS), span - MIN_ANALYSES)
    window = min(max(window_s, WINDOW_PERIODS / fundamental), MAX_WINDOW_S, room)
    return window, (
        f'; window {window:.0f} s ({window * fundamental:.0f} periods of {fundamental:.3g} Hz)'
    )


def free_choice(
    t,
    y,
    signal,
    spec,
    dominant,
    channels,
    modal,
    powers,
    beside,
    offset_ok,
    stream,
    train,
    crowded,
) -> tuple:
    """A free decay's ``(modes, window, band, words, max_damping, lowest)``: several separate
    modes among its ``modal`` peaks (``powers``; :func:`free_modes`, the lines ``beside`` it
    banded out; ``lowest``: the free estimator's window for the strongest,
    :func:`dominant_window`, one channel, no band, where it is the lowest and the others minor,
    else ()), few samples a period (:func:`few_samples`), several channels beside a line, a
    steady oscillation (:func:`steady_oscillation`; not a stream, nor a train of decays: ``train``,
    the share :func:`decay_train` read; its band :func:`steady_band`, its ``max_damping``
    :data:`STEADY_ZETA`, else NaN): the mode tracker; else one mode at ``dominant`` Hz and its
    window (:func:`free_window`: its precision, model and offset; NaN window: the configured).
    A ``crowded`` train of impacts (:func:`impacts_read`): the mode tracker, whose windows need
    no stretch free of an impact."""
    if crowded:
        modes, said = to_tracker('impacts closer than its stretches')
        return modes, (math.nan, 0.0, '', math.nan), (), said, math.nan, ()
    modes, said, band, minor = free_modes(t, signal, spec, modal, powers, beside)
    lowest = ()  # (its strongest mode the lowest, the others minor: the free estimator's too)
    if modes and minor and not (stream or band) and channels == 1:
        lowest = dominant_window(t, y, dominant, spec, offset_ok)
    if not modes:
        modes, fewer = few_samples((len(t) - 1) / float(t[-1] - t[0]), dominant)
        said += fewer
    if not modes and band and channels > 1:  # each channel's tail, band-passed: the tracker
        modes, tracked = to_tracker('several channels')
        said += tracked
    asked = not (modes or stream or train >= TRAIN_SHARE) and dominant > 0
    steady = steady_oscillation(t, signal, dominant) if asked else ''
    if steady:  # (the node: StreamChoice's own rule, over the estimates it held back)
        band = band or steady_band(dominant, (len(t) - 1) / float(t[-1] - t[0]))
        if band:
            steady += f' (band_hz {band[0]:.3g}-{band[1]:.3g} Hz)'
        modes, tracked = to_tracker(steady)
        said += tracked
    free, cap = (math.nan, 0.0, '', math.nan), (STEADY_ZETA if steady else math.nan)
    if not modes and dominant > 0:
        modes, free, more = free_window(t, y, signal, dominant, spec, offset_ok, stream, channels)
        said += more
    return modes, free, band, said, cap, lowest


def dominant_window(t, y, dominant: float, spec, offset_ok: bool) -> tuple:
    """For a free decay of several separate modes whose strongest, at ``dominant`` Hz, is the
    lowest and holds the others under :data:`MODE_SHARE` of its power: the free estimator's
    window for that mode (:func:`fast_window`: ``(min_periods, early_std_rel, model, offset)``;
    () where its peak is impure; ``analyze`` says it where it applies it). The mode tracker's
    windows are 1.4 periods or more (a brief higher mode of a real beam, plucked after 5 s of
    rest, sent its 6 Hz mode there: a median of 1.65 periods, where the free estimator gives
    0.90)."""
    *window, _ = fast_window(t, y, dominant, spec, offset_ok)
    return tuple(window) if math.isfinite(window[0]) else ()


def beside_decay(t: np.ndarray, signal: np.ndarray, modal, lines) -> bool:
    """Whether a periodic drive's ``lines`` (Hz) run beside a free decay -- a machine nearby --
    rather than drive the structure: its strongest ``modal`` peak rings freely
    (:func:`rings_freely`) and every line lies :data:`LINES_ABOVE`
    times above every modal peak or more, so that a band leaves them out (:func:`line_band`).
    A structure moved periodically has lines at and below its mode (the simulated arm moved
    every 0.8 s: 0.625 Hz and its harmonics about its 1.35 Hz, whose start rang down)."""
    if min(lines) < LINES_ABOVE * float(np.max(modal)):
        return False
    return rings_freely(t, signal, float(modal[0]))


def decay_stretches(t: np.ndarray, signal: np.ndarray, f: float) -> tuple[int, int, int]:
    """Of the record ``(t, signal)``'s stretches of ``TEST_PERIODS`` periods of ``f`` Hz (at most
    :data:`TRAIN_TESTS`, evenly spaced): how many are clean free decays -- passing the free-decay
    test (:func:`.auto.decay_verdict`, which starts after an impact within them) with blocks
    :data:`TRAIN_SNR_DB` over their noise (the misfit it read; a pass under it is not told: a
    decay rung down, or a mode among others) --, how many it tells, and how many it tested. A
    stretch in a gap of the record (a stream's kept samples across a source's restart) tells
    nothing."""
    reach = (TEST_PERIODS + 2) / f
    count = min(TRAIN_TESTS, int((t[-1] - t[0]) / reach))
    clean = told = 0
    for end in np.linspace(t[0] + reach, t[-1], count):
        k = int(np.searchsorted(t, end, 'right'))
        part = slice(int(np.searchsorted(t, end - reach, 'left')), k)
        verdict, misfit = decay_verdict(t[part], signal[part], f)
        if verdict is True:  # clean, or a mode among others (a building's): not told
            ratio, rms = misfit  # err / noise, err / power
            snr = 10 * math.log10(max(ratio, 1e-300) / max(rms * rms, 1e-300))
            verdict = True if snr >= TRAIN_SNR_DB else None
        clean += verdict is True
        told += verdict is not None
    return clean, told, count


def decay_train(t: np.ndarray, signal: np.ndarray, f: float) -> tuple[float, str]:
    """The share of the record ``(t, signal)``'s stretches that are clean free decays among those
    :func:`decay_stretches` tells, or that it tells among those it tests if fewer (NaN: none
    told), and, when it is :data:`TRAIN_SHARE` or more, the words. A train rings loud after each
    impact (told 44-48 of 48: ``bench_hard_records.py --impacts``); a lightly damped mode driven
    by noise in 10 dB of measurement noise passes the test quietly, the noise hiding its wander
    over 8 periods (told 4-17 of 23-48, of those 4-15 clean: read as a train until 6 Dec 2026,
    the free estimator gave 50-84 % within 2 % and missed a 15 Hz mode; in 20 dB it fails)."""
    clean, told, tested = decay_stretches(t, signal, f)
    share = min(clean / told, told / tested) if told else math.nan  # (quiet: driven in noise)
    if not share >= TRAIN_SHARE:
        return share, ''
    return share, (
        f'; but {clean} of {told} stretches of {TEST_PERIODS} periods of {f:.4g} Hz are '
        'clean free decays (each one damped sinusoid, none driven): plucks or impacts that come '
        'before the last has rung down, or an oscillation growing freely, free'
    )


def steady_oscillation(t: np.ndarray, signal: np.ndarray, f: float) -> str:
    """For a record read free (its envelope steady or falling) of one mode at ``f`` Hz: the
    words when it is a steady oscillation, not a decay -- under :data:`STEADY_SHARE` of the
    stretches :func:`decay_stretches` tells are clean free decays (a limit cycle, a machine
    running steadily: the amplitude and phase wander, the waveform has a quantiser's steps and
    harmonics, which sub-period free windows misread) --, else ''."""
    clean, told, _ = decay_stretches(t, signal, f)
    if not told or clean / told >= STEADY_SHARE:
        return ''
    return (
        f'{told - clean} of {told} stretches of {TEST_PERIODS} periods of {f:.4g} Hz fail the '
        'free-decay test (their amplitude and phase wander): a steady oscillation (a limit '
        'cycle, a machine running), not a decay'
    )


def steady_band(f: float, rate: float) -> tuple:
    """A steady oscillation's band (``band_hz``) at ``f`` Hz, ``rate`` samples a second:
    :data:`STEADY_BAND` either way of it, () where that reaches half the Nyquist frequency (the
    low-pass then too close to it to be made; the tracker's own decimation filters take the
    rest)."""
    high = f * STEADY_BAND
    return (f / STEADY_BAND, high) if high < rate / 4 else ()


def free_modes(
    t, signal, spec, peaks: np.ndarray, powers: np.ndarray, beside: list = ()
) -> tuple[int, str, tuple, bool]:
    """A free decay's modes to track -- :data:`TRACKED_MODES` when its spectral peaks (``spec``:
    :func:`spectrum`) hold several separate modes (:func:`separate_modes`, with
    :func:`rings_freely`, :func:`coexistence` and :func:`steady_line`), else 0 --, the reason in
    words, the band that leaves out the steady lines above them (:func:`line_band`) and a
    periodic drive's lines ``beside`` the decay (Hz: a machine running nearby), and whether the
    strongest is the lowest and every other holds under :data:`MODE_SHARE` of its power (each
    admitted by :func:`rings_freely`: a beam's brief higher modes)."""
    lines: list[float] = []
    dominant_fall = None  # read once, at the first candidate

    def steady(f: float) -> bool:
        nonlocal dominant_fall
        if dominant_fall is None:
            dominant_fall = fall_db(t, signal, float(peaks[0]))
        line = steady_line(t, signal, f, dominant_fall)
        if line:
            lines.append(f)
        return line

    fine = peak_frequencies(spec, peaks)
    rings = cache(lambda f: rings_freely(t, signal, f))  # (read again for brief modes)
    together = cache(lambda f, g: coexistence(t, signal, f, g))
    separate = separate_modes(peaks, powers, fine, rings, together, steady)
    listed = ', '.join(f'{f:.4g}' for f in sorted(lines))
    said = (
        f'; the peak{"s" if len(lines) > 1 else ""} at {listed} Hz: steady, a line (mains, a '
        'machine running nearby), not a mode of the decay'
        if lines
        else ''
    )
    band = line_band(separate, lines + list(beside))
    if band:
        said += f' (band_hz {band[0]:.3g}-{band[1]:.3g} Hz)'
    if len(separate) < 2:
        return 0, said + brief_said(t, signal, (peaks, powers, fine), rings, together), band, False
    listed = ', '.join(f'{f:.3g}' for f in sorted(separate))
    modes, tracked = to_tracker(f'{len(separate)} separate modes ({listed} Hz)')
    power = dict(zip(peaks.tolist(), powers.tolist()))
    minor = all(f > separate[0] and power[f] < MODE_SHARE * powers[0] for f in separate[1:])
    return modes, said + tracked, band, minor


def brief_said(t, signal, read: tuple, rings, together) -> str:
    """Words for a free decay read as one mode whose first periods hold brief higher modes
    (:func:`onset_peaks`, each :data:`MODE_GAP` from every peak of the record's spectrum --
    ``read``: their frequencies, powers and interpolated frequencies -- and a separate mode by
    :func:`separate_modes`, with its ``rings`` and ``together``: ringing freely, no harmonic),
    which ``--modes`` tracks; '' where none. Words only: the one-mode estimator keeps reading the
    strongest (a real beam's brief second mode, 39.3 Hz beside the 50 cm beam's 6.05 Hz, sent
    it to the mode tracker: the first mode's estimates a minority, each higher mode's windows
    several of its own periods; random decays of 2-3 modes, ``bench_modes.py --random``,
    45 -> 51 of 80 meeting every goal of issue 10)."""
    peaks, powers, fine = read
    dominant = float(peaks[0]) if len(peaks) else math.nan
    brief, brief_fine = onset_peaks(t, signal, dominant)
    new = np.array(
        [f > dominant and not np.any(np.abs(peaks / f - 1) < MODE_GAP) for f in brief], dtype=bool
    )
    if not np.any(new):
        return ''
    found = separate_modes(
        np.r_[peaks, brief[new]],
        np.r_[powers, np.zeros(int(np.sum(new)))],  # (weak over the record: they must ring)
        np.r_[fine, brief_fine[new]],
        rings,
        together,
    )
    listed = ', '.join(f'{f:.4g}' for f in sorted(found) if f in brief[new])
    if not listed:
        return ''
    return (
        f'; brief higher modes in its first {ONSET_PERIODS:g} periods ({listed} Hz), rung down '
        f'since: one mode estimated, the strongest (--modes {TRACKED_MODES} tracks them all)'
    )


def to_tracker(why: str) -> tuple[int, str]:
    """The mode tracker's ``modes`` (:data:`TRACKED_MODES`) and the words that send a free decay
    to it, ``why`` first (every route: several modes, few samples a period, heavy damping,
    several channels beside a line, a one-mode decay left silent)."""
    return TRACKED_MODES, f'; {why}: the mode tracker, modes {TRACKED_MODES}'


def line_band(modes: list, lines: list) -> tuple:
    """The band (``band_hz``) that leaves the steady ``lines`` above a free decay's ``modes``
    (Hz) out: up to the geometric mean of the highest mode and the lowest line above it (its
    4th-order low-pass 40 dB down at a line 10 x above the mode), from as far below the lowest
    mode (its 2nd-order high-pass, which keeps a slow drift out too); () with no line above them
    (a line below or between them stays)."""
    above = [f for f in lines if modes and f > max(modes)]
    if not above:
        return ()
    high = math.sqrt(max(modes) * min(above))
    return (min(modes) ** 2 / high, high)


def few_samples(rate: float, dominant: float) -> tuple[int, str]:
    """For a free decay of one mode, ``rate`` samples a second, its dominant mode at ``dominant``
    Hz: the modes to track and the reason in words -- the mode tracker (``modes``
    :data:`TRACKED_MODES`) under :data:`TRACKER_SAMPLES` samples a period, else ``(0, '')``."""
    per = rate / dominant if dominant > 0 else math.inf
    if per < TRACKER_SAMPLES:
        return to_tracker(f'{per:.3g} samples a period, too few for the free estimator')
    return 0, ''


def free_window(t, y, signal, dominant: float, spec, offset_ok: bool, stream: bool, channels=1):
    """A free decay of one mode at ``dominant`` Hz (``signal``: the principal component of
    ``y``): the modes to track, the window, precision, model and offset of :func:`fast_window`
    (a stream, the node, keeps its window; several channels are judged on ``signal``, no offset
    removed: their joint fit's channels over 0.9 periods, 96-100 % within 2 %, a median of
    0.90-0.95 periods where 1.25 gave 1.23-1.28) and the reason in words -- the mode tracker
    (:func:`heavily_damped`; with several channels, each channel's, whose events the joint fit
    refines) where no fast window is given to a heavily damped decay."""
    free = (math.nan, 0.0, '', math.nan)
    why = ''
    if not stream:
        one = channels == 1
        *free, why = fast_window(t, y if one else signal, dominant, spec, offset_ok and one)
        why = f'; {why}'
    if math.isfinite(free[0]):
        return 0, tuple(free), why
    modes, said = heavily_damped(t, signal, dominant)
    return modes, tuple(free), (said or why)


def heavily_damped(t: np.ndarray, signal: np.ndarray, dominant: float) -> tuple[int, str]:
    """For a free decay of one mode, ``signal`` its principal component, its dominant mode at
    ``dominant`` Hz: the modes to track and the reason in words -- the mode tracker (``modes``
    :data:`TRACKED_MODES`) when its envelope (:func:`decay_zeta`) is damped at more than
    :data:`FAST_ZETA`, else ``(0, '')``."""
    zeta = decay_zeta(t, signal, dominant) if dominant > 0 else math.nan
    if zeta > FAST_ZETA:
        why = f'a decay damped at {100 * zeta:.1f} % (its envelope), beyond the free estimator'
        return to_tracker(why)
    return 0, ''


def impurity(t: np.ndarray, y: np.ndarray, f: float, spec=None, zeta: float = math.nan) -> float:
    """The share of the power of ``(t, y)`` within :data:`IMPURITY_SPAN` of ``f`` (either way)
    that lies farther than :data:`PEAK_WIDTH` (relative) from it (Welch, :func:`spectrum`); with
    the start's segment (:data:`START_RATIO`), the lesser of that without it and, with it, the
    share of what is not the decay's own spectrum there -- its abrupt start, damped at ``zeta``,
    centred in that segment (:func:`decay_tails` ``T``: ``(share - T) / (1 - T)``, the power of a
    decay plus a spread beside it). That segment shows a short decay the taper hides, but also
    the start of one that rings through a short record (and its falling half shortens it)."""
    freq, psd, _, plain = (spectrum(t, y) if spec is None else spec)[:4]
    near = (freq > f / IMPURITY_SPAN) & (freq < f * IMPURITY_SPAN)
    off = near & (np.abs(freq / f - 1) > PEAK_WIDTH)
    views = [(np.sum(p[off]), np.sum(p[near])) for p in (psd, plain) if p is not None]
    shares = [float(a / b) for a, b in views if b > 0]
    if len(shares) == 2:
        tails = decay_tails(zeta) if zeta > 0 else 0.0
        shares[0] = (shares[0] - tails) / (1 - tails)
    return min(shares) if shares else math.nan


def decay_tails(zeta: float) -> float:
    """The share of a free decay's own power, damped at ``zeta`` from an abrupt start, that
    :func:`impurity` counts off its peak: its spectrum's Lorentzian (half width ``zeta f``) over
    :data:`IMPURITY_SPAN` either way beyond :data:`PEAK_WIDTH`."""
    total = math.atan((IMPURITY_SPAN - 1) / zeta) + math.atan((1 - 1 / IMPURITY_SPAN) / zeta)
    return 1.0 - 2 * math.atan(PEAK_WIDTH / zeta) / total


def decay_blocks(t: np.ndarray, y: np.ndarray, f: float) -> tuple[np.ndarray, float]:
    """``y`` in consecutive blocks of :data:`DECAY_BLOCK_PERIODS` periods of ``f`` Hz (rows; the
    samples beyond the last whole block left out) and the blocks' length in seconds; no rows
    when a block would hold fewer than 4 samples."""
    fs = (len(t) - 1) / float(t[-1] - t[0]) if len(t) > 1 else math.nan
    n = int(round(DECAY_BLOCK_PERIODS * fs / f)) if f > 0 and math.isfinite(fs) else 0
    m = len(y) // n if n >= 4 else 0
    return np.reshape(y[: m * n], (m, max(n, 1))), (n / fs if m else math.nan)


def decay_zeta(t: np.ndarray, y: np.ndarray, f: float) -> float:
    """The damping ratio of a free decay at ``f`` Hz from its envelope: the variance of blocks of
    :data:`DECAY_BLOCK_PERIODS` periods, from the block after the most energetic one on while
    they fall (none rising 1.5 x: a next pluck) and stand 10 x above the noise (the last quarter's
    median block, when flat: a decay that rang down), fitted by ``exp(-2 zeta 2 pi f t)`` over
    the noise; NaN with fewer than 3 such blocks."""
    blocks, block_s = decay_blocks(t, y, f)
    m = len(blocks)
    if m < 4:
        return math.nan
    energy = blocks.var(axis=1)
    peak = int(np.argmax(energy))
    tail = energy[-max(2, m // 4) :]
    half = len(tail) // 2
    # the noise the decay rang down into: the last quarter, if flat and 10 dB below the peak
    # (else it still decays)
    level = float(np.median(tail))
    flat = np.mean(tail[:half]) <= 1.2 * np.mean(tail[half:]) and level <= 0.1 * energy.max()
    floor = level if flat else 0.0
    k = peak + 1
    while k < m and energy[k] > 10 * floor and (k == peak + 1 or energy[k] <= 1.5 * energy[k - 1]):
        k += 1
    if k - peak - 1 < 3:
        return math.nan
    centres = (np.arange(peak + 1, k) + 0.5) * block_s
    slope = np.polyfit(centres, np.log(energy[peak + 1 : k] - floor), 1)[0]
    return float(-slope / 2 / (2 * math.pi * f))


def coexistence(t: np.ndarray, signal: np.ndarray, f: float, g: float) -> float:
    """How much the modes at ``f`` and ``g`` Hz ring at the same time: ``signal`` band-passed
    around each (:func:`band_responses`), its energy in blocks of :data:`DECAY_BLOCK_PERIODS`
    periods of the lower (:func:`decay_blocks`), each normalised to a unit sum; the sum over the
    blocks of the smaller share (1: one envelope, 0: one after the other)."""
    low = min(f, g)
    a, b = (decay_blocks(t, x, low)[0].var(axis=1) for _, x in band_responses(t, signal, [f, g]))
    if not (len(a) and a.sum() > 0 and b.sum() > 0):
        return 0.0
    return float(np.minimum(a / a.sum(), b / b.sum()).sum())


def rings_freely(t: np.ndarray, signal: np.ndarray, f: float) -> bool:
    """Whether the spectral peak at ``f`` Hz is a mode ringing freely: the energy of ``signal``
    band-passed around it (:func:`band_responses`), in blocks of :data:`DECAY_BLOCK_PERIODS`
    periods (:func:`decay_blocks`), falls from its most energetic block to the record's end by
    at least :data:`RING_DB` along its least-squares line (in dB) -- not a move's broadband
    content (a band-passed burst that comes and goes) nor a line (steady); the noise's chance
    peaks are no spectral peaks (:func:`chance_level`)."""
    return fall_db(t, signal, f) >= RING_DB


def fall_db(t: np.ndarray, signal: np.ndarray, f: float) -> float:
    """How far (dB) the energy of ``signal`` band-passed around ``f`` Hz
    (:func:`band_responses`), in blocks of :data:`DECAY_BLOCK_PERIODS` periods
    (:func:`decay_blocks`), falls from its most energetic block to the record's end along its
    least-squares line; NaN with fewer than 4 blocks from that one on."""
    _, x = next(band_responses(t, signal, [f]))
    energy = decay_blocks(t, x, f)[0].var(axis=1)
    peak = int(np.argmax(energy)) if len(energy) else 0
    if len(energy) - peak < 4 or not energy[peak] > 0:
        return math.nan
    level = 10 * np.log10(np.maximum(energy[peak:], 1e-300 * energy[peak]))
    slope = np.polyfit(np.arange(len(level)), level, 1)[0]
    return float(-slope * (len(level) - 1))


def steady_line(t: np.ndarray, signal: np.ndarray, f: float, dominant_fall: float) -> bool:
    """Whether the spectral peak at ``f`` Hz of a free decay ``signal`` whose dominant mode falls
    by ``dominant_fall`` dB (:func:`fall_db`) is a line -- a sinusoid of steady amplitude beside
    the decay (mains hum, a machine running nearby), not a mode --: while the dominant mode decays
    by at least twice :data:`RING_DB` (a decay's first seconds show its modes alike steady), the
    peak's band-passed response reads as a sinusoid (:func:`peak_kurtosis` below
    :data:`LINE_KURTOSIS`) that does not decay (:func:`fall_db` under :data:`RING_DB`, or too
    few blocks after its most energetic one: steady to the record's end)."""
    if not dominant_fall >= 2 * RING_DB:
        return False
    kurtosis = peak_kurtosis(t, signal, [f])[0]
    return bool(kurtosis[0] < LINE_KURTOSIS) and not fall_db(t, signal, f) >= RING_DB


def block_noise(blocks: np.ndarray) -> float:
    """The white noise's variance in ``blocks`` (:func:`decay_blocks`): the least of the blocks'
    second differences' variance / 6 (a sinusoid's second difference is ``(2 pi f / fs)^2`` of
    it, and the least block is where the decay has rung down)."""
    return float(np.min(np.diff(blocks, 2, axis=1).var(axis=1))) / 6


def ringing_periods(t: np.ndarray, signal: np.ndarray, f: float) -> float:
    """The periods of ``f`` Hz a free decay rings above its noise in the record ``(t, signal)``:
    its signal-to-noise ratio (:func:`snr_db`) over the dB its envelope falls a period (54.6
    zeta, :func:`decay_zeta`), at most the record's periods; NaN where either is not read."""
    zeta, snr = decay_zeta(t, signal, f), snr_db(t, signal, f)
    if not (zeta > 0 and snr > 0):
        return math.nan
    fall = 20 * math.log10(math.e) * 2 * math.pi * zeta  # dB a period
    return min(snr / fall, float(t[-1] - t[0]) * f)


def snr_db(t: np.ndarray, y: np.ndarray, f: float) -> float:
    """The signal-to-noise ratio of a free decay at ``f`` Hz, dB: its most energetic block of
    :data:`DECAY_BLOCK_PERIODS` periods (variance) over the noise's variance (:func:`block_noise`);
    NaN when the record holds fewer than 2 blocks."""
    blocks, _ = decay_blocks(t, y, f)
    if len(blocks) < 2:
        return math.nan
    noise = block_noise(blocks)
    peak = float(np.max(blocks.var(axis=1)))
    return 10 * math.log10(peak / noise) if noise > 0 else math.inf


def known_offset(t: np.ndarray, y: np.ndarray, f: float) -> float:
    """The offset of a free decay at ``f`` Hz, or NaN when the record does not give it to
    :data:`OFFSET_TOL` of the decay's amplitude. Each block of :data:`DECAY_BLOCK_PERIODS`
    periods is averaged with a triangle's weights (two one-period means convolved: a sinusoid,
    decaying or a little off ``f``, averages out to second order); the offset is the mean of the
    last quarter's blocks (at least two), known when its two halves agree within that tolerance
    (no drift) and the noise (:func:`block_noise`) allows it, and
    every block lies within :data:`OFFSET_MOVE` of its amplitude of it (it never moved)."""
    blocks, _ = decay_blocks(t, y, f)
    m = len(blocks)
    if m < 4:
        return math.nan
    k = max(2, m // 4)
    half = k // 2
    weights = np.bartlett(blocks.shape[1] + 2)[1:-1]
    weights /= np.sum(weights)
    means = blocks @ weights
    amplitudes = np.sqrt(2 * blocks.var(axis=1))
    noise = math.sqrt(block_noise(blocks) * float(np.sum(weights**2)))  # of one block's mean
    tol = OFFSET_TOL * float(np.max(amplitudes))
    tail = means[-k:]
    spread = 3 * noise * math.sqrt(1 / half + 1 / (k - half))
    if abs(np.mean(tail[:half]) - np.mean(tail[half:])) > tol + spread or noise > tol * math.sqrt(
        k
    ):
        return math.nan
    offset = float(np.mean(tail))
    moved = np.abs(means - offset) > OFFSET_MOVE * amplitudes + 3 * noise + tol
    return math.nan if np.any(moved) else offset


def fast_window(
    t: np.ndarray, y: np.ndarray, f: float, spec=None, offset_ok: bool = True
) -> tuple[float, float, str, float, str]:
    """The window (``min_periods``), the precision its estimates need (``early_std_rel``), the
    model ('': the configured), the offset to remove (NaN: none) and the reason in words for a
    free decay of one mode at ``f`` Hz, when its spectrum is pure (:func:`impurity` below
    :data:`IMPURE`): :data:`FAST_PERIODS`, and
    :data:`FAST_STD` (:data:`FAST_STD_CLEAN` at :data:`CLEAN_SNR_DB` and above) -- with
    ``offset_ok`` and the offset known (:func:`known_offset`), the damped-sinusoid model on the
    record less its offset (:data:`FAST_STD_CLEAN` while lightly damped); else only when lightly
    damped (:func:`decay_zeta` at most :data:`FAST_ZETA`, or unknown). Otherwise (NaN, 0: the
    configured window). ``spec``: the :func:`spectrum` of ``(t, y)``, if computed already."""
    zeta = decay_zeta(t, y, f)
    spread = impurity(t, y, f, spec, zeta)
    if not spread <= IMPURE:
        why = f'{100 * spread:.0f} % of the power near {f:.3g} Hz off its peak'
        return math.nan, 0.0, '', math.nan, why
    snr = snr_db(t, y, f)
    light = not zeta > FAST_ZETA
    offset = known_offset(t, y, f) if offset_ok else math.nan
    if not (light or math.isfinite(offset)):
        return math.nan, 0.0, '', math.nan, f'a decay damped at {100 * zeta:.1f} % (its envelope)'
    damped = math.isfinite(offset)
    precision = FAST_STD_CLEAN if light and (damped or snr >= CLEAN_SNR_DB) else FAST_STD
    what = (
        f'a pure peak ({100 * spread:.1f} % off it, {snr:.0f} dB) whose offset {offset:.4g} '
        'its last quarter gives: the damped-sinusoid model on the record less that offset'
        if damped
        else f'a pure, lightly damped peak ({100 * spread:.1f} % off it, {snr:.0f} dB)'
    )
    why = (
        f'{what}, min_periods {FAST_PERIODS:g} where the estimate is within '
        f'{100 * precision:.2g} % (1 std), else 1.25'
    )
    return FAST_PERIODS, precision, 'damped-sinusoid' if damped else '', offset, why


def is_noise(d: Optional[Decision]) -> bool:
    """Whether the record ``d`` decided is noise: its strongest spectral peak stands under
    :data:`FLAT_DB` above the spectrum's median (the others under what noise reaches by chance)."""
    return d is not None and d.peak_db < FLAT_DB


def window_advice(window_s: float, d: Optional[Decision], option: str) -> str:
    """Why a ``window_s`` window gave no mode, from the record's lowest spectral peak: how many
    correlation times ``1 / (2 pi zeta f)`` (at :data:`ASSUMED_ZETA`) of it the window holds,
    and ``option`` with the window that holds :data:`WINDOW_PERIODS` periods of it (at most
    :data:`MAX_WINDOW_S`); '' without a peak, or when the window holds them. A spectrum whose
    strongest peak stands under :data:`FLAT_DB` above its median is noise: the words say so."""
    if is_noise(d):
        return (
            f'the spectrum is flat (its strongest peak {d.peak_db:.0f} dB above its median; a '
            f'mode stands {FLAT_DB:g} dB and more): noise, no mode to estimate'
        )
    if d is None or not math.isfinite(d.fundamental_hz):
        return ''
    return peak_window_advice(window_s, d.fundamental_hz, option)


def peak_window_advice(window_s: float, f: float, option: str) -> str:
    """How many correlation times of a peak at ``f`` Hz a ``window_s`` window holds, and
    ``option`` with the window that holds :data:`WINDOW_PERIODS` periods of it (at most
    :data:`MAX_WINDOW_S`); '' when the window holds them (:func:`window_advice`)."""
    times = window_s * 2 * math.pi * ASSUMED_ZETA * f
    want = min(WINDOW_PERIODS / f, MAX_WINDOW_S)
    if window_s >= want:
        return ''
    return (
        f'the {window_s:.4g} s window holds {times:.1f} correlation times of the {f:.3g} Hz peak '
        f'(at zeta {100 * ASSUMED_ZETA:g} %): {option}{math.ceil(want)}'
    )


def separate_modes(
    peaks: np.ndarray, powers: np.ndarray, fine, rings=None, together=None, steady=None
) -> list[float]:
    """The spectral peaks (strongest first) that are modes of their own: at least
    :data:`MODE_SHARE` of the strongest's power -- or, weaker, ringing freely (``rings``: a
    function of the frequency, :func:`rings_freely`; None: none does) --, :data:`MODE_GAP`
    (relative) from every stronger one kept -- or closer, ringing with it (``together``: a
    function of both frequencies, :func:`coexistence`; None: never) --, and no harmonic of one
    (a clipped or non-sinusoidal response: within :data:`HARMONIC_FINE` of it between the
    peaks' interpolated frequencies ``fine``, :func:`peak_frequencies`), nor, beside the
    strongest, a line (``steady``: a function of the frequency, :func:`steady_line`; None: none
    is)."""
    kept: list[float] = []
    at = dict(zip(peaks.tolist(), np.asarray(fine, dtype=float).tolist()))
    for f, p in zip(peaks.tolist(), powers.tolist()):
        near = [k for k in kept if abs(f / k - 1) < MODE_GAP]
        if near and not (together is not None and all(together(k, f) >= COEXIST for k in near)):
            continue
        if any(abs(at[f] / (at[k] * n) - 1) < HARMONIC_FINE for k in kept for n in range(2, 8)):
            continue
        if p < MODE_SHARE * powers[0] and (rings is None or not rings(f)):
            continue
        if kept and steady is not None and steady(f):
            continue
        kept.append(f)
    return kept


#: the seconds of a stream :class:`DrivenWatch` judges
WATCH_S = 120.0
#: ... of which it needs this many before it reads the stream driven (the node's first
#: decision, then asked again this often while it keeps ``free``): a driven machine's modes
#: then come after this and a window, not after half the span and a window (60 s: a 5 Hz mode
#: driven by noise published nothing for a minute); the first blocks, a start's transient (the
#: simulated arm's first move), would be decided on alone; back to free still needs half the span
EARLY_S = 20.0
#: ... and a driven decision so early is taken once the seconds it read are this share of the
#: window it chose (:meth:`StreamChoice._looked_long_enough`): 60 of its 120 periods
LOOK_SHARE = 0.5
#: ... and the least mean variance they must hold, relative to the stream's largest block's
#: (not the noise a decay rang down into): the simulated arm driven at its tip after its start's
#: ramp holds ~0.5 % of the ramp's largest block (at 1e-2 it was read driven at 309 s of
#: stream, not 193), the same arm at rest 3.5e-4, the test's decay into noise 2e-4
LIVE_LEVEL = 1e-3
#: the most samples the node keeps for its decision (15 MB with 6 channels; 262 s at 1 kHz)
MAX_KEPT = 2**18
#: a stream whose free-decay estimator has published nothing for this many seconds, while it
#: rings after an onset, is asked whether it is a decay of several modes (their beating fails
#: the one-mode fits: a 10 and a 13 Hz mode gave no estimate at all); again this often
SILENT_S = 3.0
#: ... and a decay of one mode whose free estimator has published nothing since its onset for
#: this many periods of it (and :data:`SILENT_S` s) goes to the mode tracker: where its
#: convergence test passes at all its first estimate comes a median of 4.4-12 periods after the
#: pluck in 20-30 dB (``bench_hard_records.py --silent --base``), and a slow mode's first seconds
#: are not silence (a 0.5 Hz decay's 3 s are 1.5 periods: test_stream.py)
SILENT_PERIODS = 20.0
#: a free decay of one mode whose free estimator gives fewer estimates than this is read again by
#: the mode tracker (``analyze``: :func:`..analysis.choosing.rescue`; the node: those since the
#: onset, then silent for :data:`SILENT_PERIODS`, :meth:`StreamChoice._silent_decay`): one or two
#: estimates, late in the decay's tail, are not a reading of it (a 5 Hz decay at zeta 4 % in
#: 20 dB: one estimate 4.7 periods in, 4.7 % off, the tracker 19, all within 2 %; at 20 samples
#: a period in 30 dB 1-2 estimates 20-29 periods in, the tracker 55; the node on a 5 Hz pluck in
#: 20 dB at 20 samples a period: 1-2 estimates in 40 s on 5 of 8 seeds); the simulated arm of
#: Section 5.3 gives 10
RESCUE_BELOW = 3
#: free estimates running that the free-decay test held back (:meth:`StreamChoice.free_decay`)
#: in a stream the watch reads free and live over half its span: a steady oscillation that is no
#: decay (a limit cycle: the real arm's, whose amplitude and phase wander and whose harmonics and
#: 1 mm steps misfit the decay model -- 5 estimates in 10 s of ``flex5``, none published), sent
#: to the mode tracker (:meth:`StreamChoice._steady`); a driven stream's held estimates are the
#: watch's to judge (before it has, the tracker read a 5 Hz mode driven by noise at 64 % within
#: 2 %, 13 estimates beyond 5 %)
HELD_RUN = 3
#: the most times a decay's window is read (a decision a second) while it shows several modes
WINDOW_READS = 5
#: ... each read that shows several modes reads again this last share of the decay since its
#: onset: several modes there too (they ring on) send the stream to the mode tracker
#: (:meth:`StreamChoice._lasting_modes`)
LASTING_SHARE = 0.5
#: free-decay tests passed running in a stretch (no onset, no block read driven between) after
#: which its later free estimates are trusted untested (:meth:`StreamChoice.free_decay`)
TRUSTED_PASSES = 3


class DrivenWatch:
    """Whether a stream's last :data:`WATCH_S` s look driven throughout: the share of their energy
    in the blocks auto's envelope (:class:`.auto.Envelope`, its block following the free
    estimates' frequency) read as driven above :data:`DRIVEN_ABOVE`, their mean level at least
    :data:`LIVE_LEVEL` of the largest block's (not the noise a decay rang down into) and the
    envelope driven now. Fed in batches (:meth:`feed`, which marks the energies every 1 % of
    :data:`WATCH_S` of stream time, however fast it is fed), asked at any pace (:meth:`driven`)."""

    def __init__(self):
        self._envelope = Envelope(4 * MIN_BLOCK_S, MAX_WINDOW_S / 10)
        self._marks: deque = deque()  # (stream time, free energy, driven energy)
        self._last_t = math.nan
        #: the stream time the last onset was seen at (the end of the batch it closed in; the
        #: stream's start is the first), the onsets so far, and the frequency of the last free
        #: estimate
        self.onset_t = math.nan
        self.onsets = 0
        self.followed_hz = math.nan

    def feed(self, t: np.ndarray, y: np.ndarray) -> None:
        """Samples ``(t, y)`` (arrays), in a few numpy passes: the energies are marked at the
        first sample and then every 1 % of :data:`WATCH_S` of stream time, however fast the
        stream is fed, so any batching gives the same marks. The envelope is fed the batch at
        once; each mark takes the energies after the blocks closed before it (those its part of
        the batch fed alone would leave: the same marks and onsets, one envelope pass a batch)."""
        n = len(t)
        if not n:
            return
        env = self._envelope
        state = (env.energy[FREE], env.energy[DRIVEN], env.changes['onsets'])
        closes: list = []
        with np.errstate(over='ignore', invalid='ignore'):  # a huge sample: inf energy
            env.feed(t, y, closes)
        k = 0
        for end in self._mark_ends(t):
            while k < len(closes) and closes[k][0] < end:  # the blocks closed before it
                state = closes[k][1:]
                k += 1
            self._last_t = float(t[min(end, n) - 1])
            if state[2] + 1 != self.onsets:
                self.onsets = state[2] + 1
                self.onset_t = self._last_t if self.onsets > 1 else float(t[0])
            if end <= n:
                self._mark(self._last_t, state[0], state[1])

    def _mark_ends(self, t: np.ndarray) -> list[int]:
        """The parts of a batch ``t`` (their ends, exclusive) each ending at a sample to mark
        (:meth:`feed`); the last ends at ``len(t) + 1`` when no mark ends it."""
        ends, start, n = [], 0, len(t)
        at = self._marks[-1][0] if self._marks else None
        while start < n:
            end = start + 1  # the first sample is marked
            if at is not None:  # else up to the next sample to mark at
                later = t[start:] - at >= WATCH_S / 100
                first = int(np.argmax(later))
                end = start + first + 1 if later[first] else n + 1
            if end <= n:
                at = float(t[end - 1])
            ends.append(end)
            start = end
        return ends

    def _mark(self, t: float, free: float, driven: float) -> None:
        """Mark the energies ``free`` and ``driven`` at stream time ``t``; forget marks beyond
        the span."""
        marks = self._marks
        marks.append((t, free, driven))
        while len(marks) > 2 and t - marks[1][0] >= WATCH_S:
            marks.popleft()

    def follow(self, f: float) -> None:
        """A free estimate of ``f`` Hz: the block holds a few of its periods."""
        self._envelope.follow(f)
        self.followed_hz = f

    def driven(self, above: float = DRIVEN_ABOVE) -> Optional[float]:
        """The driven share of the last :data:`WATCH_S` s' energy (from :data:`EARLY_S` s of
        stream on) when they look driven throughout (see the class doc; ``above``: the least
        share, :data:`FREE_BELOW` for driven in part: a mixed stream), else None."""
        share, live = self._watched_share(EARLY_S)
        if share is None or self._envelope.state != DRIVEN:
            return None
        return share if share > above and live else None

    @property
    def driven_blocks(self) -> int:
        """The envelope's blocks read driven so far."""
        return self._envelope.blocks[DRIVEN]

    def ringing(self) -> bool:
        """Whether the stream rings freely now: the envelope's stretch free, begun by an onset
        (a pluck, not the rest or noise the stream started with), and its last block at least
        :data:`LIVE_LEVEL` of the largest block's."""
        return self._envelope.changes['onsets'] > 0 and self.live()

    def live(self) -> bool:
        """Whether the envelope's stretch is free and its last block at least :data:`LIVE_LEVEL`
        of the largest block's (not the noise a decay rang down into)."""
        env = self._envelope
        last = env.last_energy
        return env.state == FREE and last is not None and last >= LIVE_LEVEL * env.peak

    def freed(self) -> bool:
        """Whether the last :data:`WATCH_S` s look free (from half of them on): their driven
        share below :data:`FREE_BELOW` (what :func:`decide` calls a free decay)."""
        share, _ = self._watched_share(WATCH_S / 2)
        return share is not None and share < FREE_BELOW

    @property
    def span(self) -> float:
        """The seconds of stream watched (at most :data:`WATCH_S` and a mark; 0 before any)."""
        marks = self._marks
        return self._last_t - marks[0][0] if marks and math.isfinite(self._last_t) else 0.0

    def _watched_share(self, least_s: float) -> tuple[Optional[float], bool]:
        """The driven share of the last :data:`WATCH_S` s (None before ``least_s`` of them are
        in) and whether they are live (see the class doc)."""
        env, span = self._envelope, self.span
        if not (span > 0 and span >= least_s):
            return None, False
        free = env.energy[FREE] - self._marks[0][1]
        driven = env.energy[DRIVEN] - self._marks[0][2]
        if not free + driven > 0:
            return None, False
        return driven / (free + driven), (free + driven) / span >= LIVE_LEVEL * env.peak


class StreamChoice:
    """``estimator_node``'s default (``decide_excitation``): :func:`decide` over the last
    :data:`WATCH_S` s of the stream (all channels), taken once :class:`DrivenWatch` reads the
    stream driven now and in part of them (:meth:`driven` above :data:`FREE_BELOW`: ``decide``
    tells ambient from auto) while the estimator is the free-decay one; and, once a stream it
    sent to ``ambient`` reads free, ``auto`` (which follows free and driven stretches itself).

    Fed sample by sample (:meth:`update`, a value or a tuple of the channels' values: two list
    appends; the watch is fed in numpy batches when asked, or every :data:`MAX_KEPT`), asked at
    any pace (:meth:`driven`, then :meth:`decision`; the node: once a second). What it keeps
    (:meth:`kept`) is the last :data:`WATCH_S` s, at most :data:`MAX_KEPT` samples (a fast
    stream's decision reads fewer seconds); a stamp going back by more than 1 % of
    :data:`WATCH_S` starts it afresh (another time base). A driven decision is taken once the
    seconds it read are :data:`LOOK_SHARE` of the window it chooses (or half the span); one not
    taken, or that keeps ``free``, is not asked again before :data:`EARLY_S` s of stream (its
    spectrum costs ~10 ms).
    """

    def __init__(self, channels: int = 1):
        self.watch = DrivenWatch()
        self.channels = channels
        self._pending_t: list = []
        self._pending_y: list = []
        self._kept: deque = deque()  # (t, y) arrays of the last WATCH_S s, oldest first
        self._kept_n = 0
        self._retry_at = -math.inf
        self._share: Optional[float] = None
        self._estimated_at = -math.inf  # stream time of the last free estimate (follow)
        self._since_onset = (math.nan, 0)  # (the watch's onset, free estimates since it)
        self._silent_retry = -math.inf
        self._held = 0  # free estimates held back running ...
        self._held_hz: list = []  # ... the last HELD_RUN of them (Hz)
        self._window_onset = 0  # the onset whose decay is read for its window
        self._window_reads = 0  # ... how many times (WINDOW_READS: done)
        #: ((onsets, driven blocks) of the stretch, free-decay tests passed running in it)
        self._passed: tuple = ((-1, -1), 0)

    def update(self, t: float, value) -> None:
        self._pending_t.append(t)
        self._pending_y.append(value)
        if len(self._pending_t) >= MAX_KEPT:
            self._flush()

    def _flush(self) -> None:
        """Feed the pending samples to the watch (its first channel) and keep them."""
        if not self._pending_t:
            return
        t = np.array(self._pending_t, dtype=np.float64)
        y = np.array(self._pending_y, dtype=np.float64)
        self._pending_t, self._pending_y = [], []
        # a stamp going back (within the batch too): what follows is a stream of its own
        last, i = (self._kept[-1][0][-1] if self._kept else -math.inf), 0
        if t[0] >= last and (t[1:] >= t[:-1]).all():  # none goes back (nor is NaN): one batch
            self._keep(t, y)
            return
        while i < len(t):
            ahead = np.maximum.accumulate(np.append(last, t[i:-1]))  # the latest before each
            back = np.flatnonzero(t[i:] < ahead - WATCH_S / 100)
            if len(back) and back[0] == 0:
                self._afresh()
                last = -math.inf
                continue
            j = i + int(back[0]) if len(back) else len(t)
            self._keep(t[i:j], y[i:j])
            last, i = (ahead[j - i] if j < len(t) else last), j

    def _afresh(self) -> None:
        """Forget the stream (its stamps went back: a source restarted, a bag looping): the
        samples, the watch and the times kept in the old time base."""
        self._kept.clear()
        self._kept_n = 0
        self._estimated_at = self._silent_retry = self._retry_at = -math.inf
        self._since_onset = (math.nan, 0)
        self._held, self._held_hz = 0, []
        self.watch = DrivenWatch()
        self._share = None
        self._window_onset = self._window_reads = 0
        self._passed = ((-1, -1), 0)

    def _keep(self, t: np.ndarray, y: np.ndarray) -> None:
        """Feed samples of one time base to the watch (its first channel) and keep them."""
        if not len(t):
            return
        self.watch.feed(t, y if y.ndim == 1 else y[:, 0])
        kept = self._kept
        kept.append((t, y))
        self._kept_n += len(t)
        while len(kept) > 1 and t[-1] - kept[1][0][0] >= WATCH_S:
            self._kept_n -= len(kept.popleft()[0])
        excess = self._kept_n - MAX_KEPT
        while excess > 0:  # the oldest samples go (a copy: the rest of the array is freed)
            old_t, old_y = kept[0]
            if len(old_t) <= excess:
                kept.popleft()
            else:
                kept[0] = (old_t[excess:].copy(), old_y[excess:].copy())
            gone = min(len(old_t), excess)
            self._kept_n -= gone
            excess -= gone

    def follow(self, f: float) -> None:
        """An estimate of ``f`` Hz (:meth:`DrivenWatch.follow`), after the samples before it."""
        self._flush()
        self.watch.follow(f)
        if self._kept:
            self._estimated_at = float(self._kept[-1][0][-1])
        onset, n = self._since_onset
        self._since_onset = (self.watch.onset_t, n + 1 if onset == self.watch.onset_t else 1)

    def kept(self) -> tuple[np.ndarray, np.ndarray]:
        """``(t, y)`` of the kept samples (y: samples, or samples x channels), oldest first."""
        self._flush()
        if not self._kept:
            return np.empty(0), np.empty(0)
        return (
            np.concatenate([c[0] for c in self._kept]),
            np.concatenate([c[1] for c in self._kept]),
        )

    def _several_modes(self, now: float, window_s: float) -> Optional[Decision]:
        """:func:`decide`'s free decay over the kept samples when it takes the mode tracker
        (several modes, heavy damping, few samples a period; or one mode silent since its onset:
        :meth:`_silent_decay`), asked (at most every :data:`SILENT_S` s) when no free estimate
        came for that long while the stream rings (:meth:`DrivenWatch.ringing`); else None."""
        if now - max(self._estimated_at, self._silent_retry) < SILENT_S:
            return None
        self._silent_retry = now
        if not self.watch.ringing():
            return None
        return self._kept_decision(window_s, lambda chosen: self._silent_decay(now, chosen))

    def _kept_decision(self, window_s: float, one_mode) -> Optional[Decision]:
        """:func:`decide` over the kept samples: None unless it reads a free decay; its decision
        when that takes the mode tracker, else ``one_mode(decision)``."""
        chosen = decide(*self.kept(), self.channels, window_s, stream=True)
        if chosen.excitation != 'free':
            return None
        return chosen if chosen.modes else one_mode(chosen)

    def _silent_decay(self, now: float, chosen: Decision) -> Optional[Decision]:
        """The mode tracker for a free decay of one mode (``chosen``, :func:`decide` over the
        kept samples) whose free estimator has published fewer than :data:`RESCUE_BELOW`
        estimates since the onset and nothing for :data:`SILENT_PERIODS` periods of its dominant
        mode (the node's form of ``analyze``'s rescue: its convergence test seldom passing in
        the noise, or its fit gate holding the estimates back; a decay it estimated and whose
        tail it leaves is not silent); else None."""
        f = chosen.dominant_hz
        onset = self.watch.onset_t
        counted, n = self._since_onset
        n = n if counted == onset else 0
        quiet = now - max(onset, self._estimated_at)
        if n >= RESCUE_BELOW or not f > 0 or not quiet * f >= SILENT_PERIODS:
            return None
        gave = f'only {n} free estimate{"s" if n > 1 else ""} since the onset, ' if n else ''
        modes, said = to_tracker(
            f'{gave}no free estimate for {quiet:.3g} s ({quiet * f:.0f} periods of {f:.4g} Hz) '
            'while the decay rings'
        )
        return replace(chosen, modes=modes, reason=chosen.reason + said)

    def _steady(self, now: float, window_s: float) -> Optional[Decision]:
        """The mode tracker for a steady oscillation that is no decay: the last :data:`HELD_RUN`
        free estimates held back by the free-decay test (:meth:`free_decay`) while the watch
        reads the stream free and live over half its span (:meth:`DrivenWatch.freed`, as long as
        a driven stream takes to be read driven), and :func:`decide` over the kept samples reads
        a free decay of one mode: a limit cycle, a machine running steadily, whose wandering
        amplitude and waveform (harmonics, a quantiser's steps) the decay model misfits, so that
        the node would stay silent; asked at most every :data:`SILENT_S` s; else None."""
        if self._held < HELD_RUN or now - self._silent_retry < SILENT_S:
            return None
        if not (self.watch.live() and self.watch.freed()):
            return None
        self._silent_retry = now
        return self._kept_decision(window_s, self._steady_tracker)

    def _steady_tracker(self, chosen: Decision) -> Decision:
        """:func:`decide`'s free decision of one mode ``chosen``, given the mode tracker for a
        steady oscillation (a pole damped beyond :data:`STEADY_ZETA` the transient before it,
        as ``analyze`` has it), with the held free estimates' words."""
        held = self._held_hz or [chosen.dominant_hz]
        modes, said = to_tracker(
            f'{self._held} free estimates running ({min(held):.4g}-{max(held):.4g} Hz) '
            'failed the free-decay test while the stream rang steadily: a steady oscillation '
            '(a limit cycle, a machine running), not a decay'
        )
        reason = chosen.reason + said
        return replace(chosen, modes=modes, reason=reason, max_damping=STEADY_ZETA)

    def _decay_window(self, now: float) -> Optional[Decision]:
        """:func:`decide`'s window for the decay since the last onset, read once per onset when
        its free stretch has shown a decay at the last free estimate's frequency
        (:func:`decay_zeta`: at least 8 periods, three blocks of two falling; asked again until
        it has; and again, up to :data:`WINDOW_READS` times, while it shows several modes); None
        if it allows none (an impure or heavily damped decay) or not yet. A decay of several
        modes that ring on (:meth:`_lasting_modes`) gets the mode tracker instead."""
        watch = self.watch
        f = watch.followed_hz
        if watch.onsets != self._window_onset:  # a new onset: its decay not read yet
            self._window_onset, self._window_reads = watch.onsets, 0
        if self._window_reads >= WINDOW_READS or not f > 0 or not watch.live():
            return None
        t, y = self.recent(now - watch.onset_t)
        if not decay_zeta(t, y, f) > 0:  # no decay seen yet (a driven response's wandering)
            return None
        chosen = decide(t, y, offset_ok=False)  # the node estimates the samples as they come
        lasting = self._lasting_modes(t, y, f) if chosen.modes else None
        if lasting is not None:
            self._window_reads = WINDOW_READS
            return lasting
        # several modes this early may be a pluck's higher modes not yet rung down (a beam's
        # 39 Hz beside its 6 Hz for 2 s): read again, a second later, up to WINDOW_READS times
        self._window_reads = self._window_reads + 1 if chosen.modes else WINDOW_READS
        ok = chosen.excitation == 'free' and not chosen.modes
        return chosen if ok and math.isfinite(chosen.min_periods) else None

    def _lasting_modes(self, t: np.ndarray, y: np.ndarray, f: float) -> Optional[Decision]:
        """:func:`decide`'s free decay of several modes over the last :data:`LASTING_SHARE` of
        the decay ``(t, y)`` (since its onset), when that part still shows them and is a free
        decay at the followed ``f`` Hz (:func:`.auto.is_free_decay`, which fits the strongest
        other mode too): modes that ring on (an 8 / 21 / 55 Hz decay, whose one-mode estimator
        follows 8 Hz alone), not a pluck's higher modes rung down since (a beam's), nor a
        structure moved again meanwhile (the arm moved at random times, its moves' content
        read as a 2.33 Hz mode beside its 1.33 Hz: the mode tracker published estimates up to
        24 % off); else None."""
        late = t >= t[-1] - LASTING_SHARE * (t[-1] - t[0])
        if is_free_decay(t[late], y[late], f) is False:
            return None
        chosen = decide(t[late], y[late], offset_ok=False)
        return chosen if chosen.excitation == 'free' and chosen.modes else None

    def _looked_long_enough(self, chosen: Decision) -> bool:
        """Whether a driven decision ``chosen`` read enough of the stream to be taken: at least
        :data:`LOOK_SHARE` of the window it asks for (periods of the fundamental that sized it)
        or half the watched span. Under it the fundamental came from one or two Welch segments:
        an arm moved at random times, read after 40 s, asked for a 300-s window (a slow
        content's peak), after 60 s 89 s; the decision is asked again :data:`EARLY_S` s later."""
        need = min(LOOK_SHARE * chosen.window_s, WATCH_S / 2)
        return self.watch.span >= need

    def recent(self, seconds: float) -> tuple[np.ndarray, np.ndarray]:
        """``(t, y)`` of the kept samples of the last ``seconds`` s (at least; y: the first
        channel), oldest first."""
        self._flush()
        parts: list = []
        for t, y in reversed(self._kept):
            parts.append((t, y if y.ndim == 1 else y[:, 0]))
            if parts[0][0][-1] - t[0] >= seconds:
                break
        if not parts:
            return np.empty(0), np.empty(0)
        return np.concatenate([p[0] for p in parts[::-1]]), np.concatenate(
            [p[1] for p in parts[::-1]]
        )

    def free_decay(self, f: float) -> Optional[bool]:
        """:func:`.auto.is_free_decay` of a free estimate of ``f`` Hz that the last sample
        completed, over the samples before it (the first channel): False when the signal is no
        free decay (a driven response: the estimate is of no mode), None when too short to tell.
        Once :data:`TRUSTED_PASSES` estimates running have passed since the last onset, with no
        block read driven meanwhile, the stretch is a free decay: True without a test (the test
        costs ~1 ms, about 4 us a sample at one estimate a period)."""
        if not f > 0:
            return None
        watch = self.watch
        stretch = (watch.onsets, watch.driven_blocks)
        if self._passed[0] == stretch and self._passed[1] >= TRUSTED_PASSES:
            return True  # a free stretch that passed: not tested again until it changes
        verdict = is_free_decay(*self.recent((TEST_PERIODS + 2) / f), f)
        passes = self._passed[1] if self._passed[0] == stretch else 0
        self._passed = (stretch, passes + 1 if verdict is True else 0)
        held = verdict is False
        self._held = self._held + 1 if held else 0
        self._held_hz = (self._held_hz + [f])[-max(HELD_RUN, 1) :] if held else []
        return verdict

    def driven(self, above: float = DRIVEN_ABOVE) -> Optional[float]:
        """:meth:`DrivenWatch.driven`, kept for :meth:`decision` (which :func:`decide` then
        tells ``ambient`` from ``auto``)."""
        self._flush()
        self._share = self.watch.driven(above)
        return self._share

    def decision(
        self,
        excitation: str,
        decided: bool,
        window_s: float,
        modes: int = 0,
        windowed: bool = False,
    ) -> Optional[Decision]:
        """The decision to switch to, or None: from ``free`` (when the watch read the stream driven
        at the last :meth:`driven`), :func:`decide` over the kept samples, if not ``free`` and
        once they are :data:`LOOK_SHARE` of its window (:meth:`_looked_long_enough`); from
        ``free`` with ``modes`` 0 whose estimator has been silent for :data:`SILENT_S` s while the
        stream rings after an onset, a free decay of several modes (the mode tracker); from
        ``free`` on the default window (``windowed`` False), once per onset when it has shown
        a decay, the window that decay allows (:func:`fast_window`, as ``analyze`` decides it),
        or, when that decay and its last :data:`LASTING_SHARE` show several modes, the mode
        tracker (:meth:`_lasting_modes`); from an
        ``ambient`` this choice ``decided``, ``auto`` once the stream reads free.
        ``window_s``: the configured ambient window (the shortest the decision gives)."""
        self._flush()
        if not self._kept:
            return None
        now = float(self._kept[-1][0][-1])
        if excitation == 'free' and modes == 0 and self.channels == 1:
            several = self._several_modes(now, window_s) or self._steady(now, window_s)
            if several is not None:
                return several
            if not windowed:
                window = self._decay_window(now)
                if window is not None:
                    return window
        if excitation == 'ambient' and decided:
            if not self.watch.freed():
                return None
            reason = (
                f'under {100 * FREE_BELOW:.0f} % of the energy of the last {WATCH_S:g} s read '
                'driven by the envelope: free decays now, a structure that was driven (auto: '
                "the free-decay estimator's estimates in its free stretches, the identifier's in "
                'driven ones, without waiting for the watch)'
            )
            return Decision('auto', window_s, 0.0, math.nan, math.nan, (), reason, keeps=True)
        if excitation != 'free' or self._share is None or now < self._retry_at:
            return None
        self._retry_at = now + EARLY_S
        chosen = decide(*self.kept(), self.channels, window_s, stream=True)
        if chosen.excitation != 'free':
            return chosen if self._looked_long_enough(chosen) else None
        # read driven by the watch (a steady level after a ringing's peak), free by decide (one
        # mode or, the ringing in its envelope, a damped one), its free estimates held: a steady
        # oscillation after a transient (a step into a limit cycle) -- once half the span is in
        # (under it, an arm moved at random times read as one mode: the tracker, 79 % within 2 %)
        steady = self._held >= HELD_RUN and chosen.dominant_hz > 0
        if not steady or self.watch.span < WATCH_S / 2:
            return None
        return self._steady_tracker(chosen)
